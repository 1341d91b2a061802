// hystlab's page: follows the daemon over its API and its event stream (docs/API.md).
import { XYPlot, TimePlot, TriangleHeatmap } from './plots.js';

const $ = id => document.getElementById(id);
const KEEP = 20000;  // samples kept per plot

const S = {
  campaigns: [], selected: null, follow: true, detail: null, runId: null,
  loopX: [], loopY: [], modelTable: null, trans: [], lastEventId: '', es: null, online: false,
};

const loop = new XYPlot($('loop-plot'), 'displacement (mm)', 'force (N)',
  [{ label: 'measured', color: '#1565c0' }, { label: 'identified model', color: '#ef6c00', width: 2 }]);
const heat = new TriangleHeatmap($('heatmap-plot'));
const timeplot = new TimePlot($('time-plot'), ['displacement (mm)', 'force (N)']);
const trans = new XYPlot($('trans-plot'), 'frequency (Hz)', 'mass / base amplitude', [{ label: 'transmissibility', color: '#6a1b9a', points: true }]);

// For tests and the curious: what the page shows, as numbers.
window.hystlab = {
  state: () => S.detail && S.detail.state, selected: () => S.selected,
  loopPoints: () => loop.points(0), modelPoints: () => loop.points(1),
  heatmapIdentified: () => heat.identified(), heatmapRequired: () => heat.required(),
  transmissibilityPoints: () => trans.points(0), online: () => S.online,
};

// ---- API ----
const API_TIMEOUT_MS = 20000;  // a request that never ends must not stall every later update
async function api(path, options = {}) {
  const headers = Object.assign({}, options.body ? { 'Content-Type': 'application/json' } : {}, options.headers || {});
  const token = sessionStorage.getItem('hystlab-token');
  if (token && options.method && options.method !== 'GET') headers.Authorization = 'Bearer ' + token;
  const res = await fetch(path, Object.assign({ signal: AbortSignal.timeout(API_TIMEOUT_MS) }, options, { headers }));
  const body = res.headers.get('Content-Type')?.includes('json') ? await res.json() : await res.text();
  if (res.status === 401 && !options.retried) {
    const t = window.prompt('This daemon needs its token for changes:');
    if (t) { sessionStorage.setItem('hystlab-token', t); return api(path, Object.assign({}, options, { retried: true })); }
  }
  if (!res.ok) throw new Error(body && body.error ? `${body.error}: ${body.detail}` : `HTTP ${res.status}`);
  return body;
}

// ---- the campaign list and the selected campaign ----
async function refreshList() {
  S.campaigns = await api('/api/campaigns');
  const ul = $('campaigns');
  ul.replaceChildren(...S.campaigns.slice().reverse().map(c => {
    const li = document.createElement('li');
    li.textContent = `#${c.id} ${c.kind} — ${c.state}` + (c.tables ? ` · ${c.tables} table${c.tables > 1 ? 's' : ''}` : '');
    li.dataset.id = c.id;
    li.className = c.id === S.selected ? 'selected' : '';
    li.addEventListener('click', serial(() => { S.follow = false; return select(c.id); }));
    return li;
  }));
  if (S.follow) {
    const live = S.campaigns.find(c => ['running', 'paused', 'arming'].includes(c.state));
    const pick = live || S.campaigns[S.campaigns.length - 1];
    if (pick && pick.id !== S.selected) await select(pick.id);
  }
}

async function select(id) {
  S.selected = id;
  for (const li of $('campaigns').children) li.className = Number(li.dataset.id) === id ? 'selected' : '';
  S.loopX = []; S.loopY = []; S.modelTable = null; S.trans = [];
  loop.set(0, [], []); loop.set(1, [], []); timeplot.clear();
  heat.setGrid(null);
  await refreshDetail();  // for a FOT campaign, with its nodes
  const d = S.detail;
  if (d.kind === 'sine') { S.trans = await api(`/api/campaigns/${id}/transmissibility`); drawTrans(); }
  if (S.runId) await loadRun(S.runId);
  await overlayModel();
  redraw();
}

async function loadNodes(id) {
  const nodes = await api(`/api/campaigns/${id}/nodes`);
  if (id !== S.selected) return;
  heat.setGrid(nodes.grid);
  for (const n of nodes.nodes) heat.add(n.alpha, n.beta, n.F);
  heat.redraw();
}

async function refreshDetail() {
  if (S.selected == null) return;
  const d = S.detail = await api(`/api/campaigns/${S.selected}`);
  // The stored count is the truth: a node missed on the stream (or a failed load) is fetched again.
  if (d.kind === 'fot' && d.progress && (heat.grid ? d.progress.nodes !== heat.identified() : true)) await loadNodes(d.id);
  S.runId = d.runs.length ? d.runs[d.runs.length - 1].id : null;
  $('title').textContent = `Campaign #${d.id}: ${d.kind} on ${d.rig}`;
  $('state').textContent = d.state;
  $('state').className = 'state ' + d.state;
  const active = ['running', 'paused', 'arming'].includes(d.state);
  $('pause').disabled = d.state !== 'running';
  $('resume').disabled = !(d.state === 'paused' || d.state === 'interrupted');
  $('abort').disabled = !(active || d.state === 'queued');
  document.querySelector('.fot-only').hidden = d.kind !== 'fot';
  document.querySelector('.sine-only').hidden = d.kind !== 'sine';
  const shaker = d.kind === 'sine';
  timeplot.setLabels(shaker ? ['base displacement (mm)', 'mass displacement (mm)'] : ['displacement (mm)', 'force (N)']);
  $('loop-caption').textContent = shaker ? 'Mass against base displacement' : 'Force–displacement';
  $('time-caption').textContent = shaker ? 'Base and mass displacement against time' : 'Displacement and force against time';
  loop.relabel(shaker ? 'base displacement (mm)' : 'displacement (mm)', shaker ? 'mass displacement (mm)' : 'force (N)');
  showProgress(d);
  showAccuracy(d);
  showDownloads(d);
  const events = await api(`/api/campaigns/${d.id}/events`);
  $('events').replaceChildren(...events.slice(-50).reverse().map(e => {
    const li = document.createElement('li');
    li.textContent = `${e.at} ${e.kind}${e.to ? ' → ' + e.to : ''}: ${describe(e)}`;
    return li;
  }));
}

function describe(e) {
  const d = e.detail;
  if (typeof d === 'string') return d;
  if (e.kind === 'fit' && d && d.accuracy) return `partial table of ${d.nodes}/${d.required} nodes: RMS ${d.accuracy.overall.rms_N.toFixed(2)} N over the samples so far`;
  if (e.kind === 'transmissibility' && d) return `${d.frequency_hz.toFixed(2)} Hz: ratio ${d.ratio.toFixed(3)}`;
  return JSON.stringify(d);
}

function showProgress(d) {
  if (!d.progress) { $('progress').textContent = ''; $('eta').textContent = ''; return; }
  const k = d.progress.nodes, n = d.progress.required;
  $('progress').textContent = `node ${k} of ${n}`;
  const run = d.runs[d.runs.length - 1];
  if (d.state === 'running' && run && k > 0 && k < n) {
    const elapsed = (Date.now() - Date.parse(run.started_at)) / 1000;
    $('eta').textContent = `ETA ${Math.round(elapsed / k * (n - k))} s`;
  } else $('eta').textContent = '';
  $('coverage').textContent = `— ${k} of ${n} nodes identified`;
}

function showAccuracy(d) {
  const parts = [];
  if (d.fit && d.fit.accuracy) parts.push(`partial table (${d.fit.nodes}/${d.fit.required} nodes): RMS ${d.fit.accuracy.overall.rms_N.toFixed(2)} N`);
  for (const t of d.tables) {
    const a = t.accuracy && t.accuracy.overall;
    if (a) parts.push(`table #${t.id} (${t.method}, n=${t.n}): RMS ${a.rms_N.toFixed(2)} N, max ${a.max_N.toFixed(2)} N (${(100 * a.rms_norm).toFixed(1)} % of range)`);
  }
  $('accuracy').textContent = parts.join(' · ');
}

function link(href, text) { const a = document.createElement('a'); a.href = href; a.textContent = text; a.setAttribute('download', ''); return a; }
function showDownloads(d) {
  const links = [];
  for (const t of d.tables)
    for (const f of ['json', 'csv', 'm']) links.push(link(`/api/tables/${t.id}/export?format=${f}`, `table #${t.id} (${t.method}) .${f}`));
  for (const r of d.runs) links.push(link(`/api/runs/${r.id}/samples.csv`, `run #${r.id} samples .csv`));
  $('downloads').replaceChildren(...links);
}

// The run's history, decimated by the server (min and max per bucket: no peak is lost).
async function loadRun(runId) {
  const s = await api(`/api/runs/${runId}/samples?points=3000`);
  const x = [], y = [], t = [], a = [], b = [];
  for (let k = 0; k < s.buckets; k++) {
    x.push(s.displacement_min_mm[k], s.displacement_max_mm[k]);
    y.push(s.force_min_N[k], s.force_max_N[k]);
    t.push(s.t_min[k]); a.push(s.displacement_min_mm[k]); b.push(s.force_min_N[k]);
  }
  if (S.detail.kind !== 'sine') { S.loopX = x; S.loopY = y; timeplot.clear(); timeplot.push(t, a, b, KEEP); }
}

// The newest table of the campaign, evaluated on the measured displacement (Figs. 14-16).
async function overlayModel() {
  const d = S.detail;
  const table = d && d.tables.find(t => t.method === 'fot');
  if (!table || !S.loopX.length) return;
  const r = await api('/api/evaluate', { method: 'POST', body: JSON.stringify({ table_id: table.id, displacement_mm: S.loopX }) });
  S.modelTable = table.id;
  loop.set(1, S.loopX.slice(), r.force_N);
}

function drawTrans() {
  const pts = S.trans.slice().sort((p, q) => p.frequency_hz - q.frequency_hz);
  trans.set(0, pts.map(p => p.frequency_hz), pts.map(p => p.ratio));
  trans.redraw();
}

function redraw() {
  loop.set(0, S.loopX, S.loopY);
  loop.redraw(); timeplot.redraw(); heat.redraw();
}

// Handlers that refresh from the API run one after another, so an older answer never
// overwrites a newer one.
let chain = Promise.resolve();
const serial = fn => (...args) => { chain = chain.then(() => fn(...args)).catch(e => console.warn(e)); };

// ---- live: the event stream (reconnects by itself, resuming after the last record seen) ----
function connect() {
  const url = '/api/stream?rate=50' + (S.lastEventId ? '&last_event_id=' + encodeURIComponent(S.lastEventId) : '');
  const es = S.es = new EventSource(url);
  es.addEventListener('hello', serial(async () => {
    setOnline(true);
    await refreshStatus(); await refreshList(); if (S.selected != null) await refreshDetail();
  }));
  es.addEventListener('samples', e => onSamples(JSON.parse(e.data)));
  const on = (kind, handler) => es.addEventListener(kind, e => { S.lastEventId = e.lastEventId; handler(JSON.parse(e.data)); });
  on('campaign', serial(onCampaign));
  on('node', onNode);
  on('table', serial(onTable));
  for (const k of ['fit', 'transmissibility', 'command']) on(k, serial(r => onRecord(k, r)));
  es.onerror = () => {
    setOnline(false);
    if (es.readyState === EventSource.CLOSED) { es.close(); setTimeout(connect, 2000); }  // the browser gave up: start again
  };
}

function setOnline(on) {
  S.online = on;
  $('link').textContent = on ? 'live' : 'reconnecting…';
  $('link').className = 'link ' + (on ? 'up' : 'down');
}

async function refreshStatus() {
  const s = await api('/api/status');
  $('daemon').textContent = `hystlabd ${s.version} · ${s.rigs.map(r => r.name).join(', ')}`;
  const chosen = form.rig.value;
  form.rig.replaceChildren(...s.rigs.map(r => {
    const o = document.createElement('option');
    o.value = r.name; o.textContent = `${r.name} (${r.kind === 'shaker' ? 'shaker' : 'load frame'})`; o.dataset.kind = r.kind;
    return o;
  }));
  if (chosen) form.rig.value = chosen;
  else pickRigFor(form.kind.value);
}

// The first rig that can run this kind of plan (a sine sweep needs a shaker).
function pickRigFor(kind) {
  const want = kind === 'sine' ? 'shaker' : 'load_frame';
  const o = [...form.rig.options].find(x => x.dataset.kind === want);
  if (o) form.rig.value = o.value;
}

function onSamples(m) {
  if (!S.detail || m.run !== S.runId) return;
  if (S.detail.kind === 'sine') {
    timeplot.push(m.t, m.cmd, m.disp, KEEP);
    for (let k = 0; k < m.t.length; k++) { S.loopX.push(m.cmd[k]); S.loopY.push(m.disp[k]); }
  } else {
    timeplot.push(m.t, m.disp, m.force, KEEP);
    for (let k = 0; k < m.t.length; k++) { S.loopX.push(m.disp[k]); S.loopY.push(m.force[k]); }
  }
  if (S.loopX.length > KEEP * 2) { S.loopX.splice(0, S.loopX.length - KEEP); S.loopY.splice(0, S.loopY.length - KEEP); }
  scheduleRedraw();
}

let redrawPending = false;
function scheduleRedraw() {
  if (redrawPending) return;
  redrawPending = true;
  requestAnimationFrame(() => { redrawPending = false; redraw(); });
}

async function onCampaign(ev) {
  await refreshList();
  if (ev.campaign === S.selected) { await refreshDetail(); if (ev.to === 'running' && !S.runId) await select(ev.campaign); }
  if (S.follow && ev.to === 'arming') await select(ev.campaign);
}
function onNode(n) {
  if (n.campaign !== S.selected) return;
  heat.add(n.alpha, n.beta, n.F);
  heat.redraw();
  if (S.detail && S.detail.progress) { S.detail.progress.nodes = heat.identified(); showProgress(S.detail); }
}
async function onTable(t) {
  if (t.campaign !== S.selected) return;
  await refreshDetail();
  if (S.runId) await loadRun(S.runId);  // the whole run at full detail, not the live decimation
  await overlayModel();
  redraw();
}
async function onRecord(kind, r) {
  if (r.campaign !== S.selected) return;
  if (kind === 'transmissibility') { S.trans.push({ frequency_hz: r.detail.frequency_hz, ratio: r.detail.ratio }); drawTrans(); }
  await refreshDetail();
}

// ---- controls ----
for (const verb of ['pause', 'resume', 'abort']) {
  $(verb).addEventListener('click', async () => {
    $('command-error').textContent = '';
    try { await api(`/api/campaigns/${S.selected}/${verb}`, { method: 'POST' }); } catch (e) { $('command-error').textContent = e.message; }
  });
}

const form = $('plan-form');
form.kind.addEventListener('change', () => {
  form.querySelector('.fot').hidden = form.kind.value !== 'fot';
  form.querySelector('.sine').hidden = form.kind.value !== 'sine';
  pickRigFor(form.kind.value);
});

function planFromForm() {
  if (form.json.value.trim()) return JSON.parse(form.json.value);
  const num = name => Number(form[name].value);
  if (form.kind.value === 'sine') {
    return { kind: 'sine', frequencies_hz: form.freqs.value.split(',').map(Number), amplitude_mm: num('amp'),
             settle_cycles: num('settle'), measured_cycles: num('measured'), sample_rate_hz: num('hz') };
  }
  const lo = num('lo'), hi = num('hi'), span = hi - lo;
  return { kind: 'fot', range_mm: [lo, hi], subdivisions: num('n'), ramp_rate_mm_s: num('rate'), dwell_s: num('dwell'),
           sample_rate_hz: num('hz'), limits: { displacement_mm: [lo - 0.1 * span, hi + 0.1 * span], force_N: num('force'), rate_mm_s: 20 * num('rate') } };
}

form.addEventListener('submit', e => {
  e.preventDefault();
  $('form-error').textContent = '';
  serial(async () => {
    try {
      const body = { plan: planFromForm() };
      if (form.rig.value) body.rig = form.rig.value;
      const c = await api('/api/campaigns', { method: 'POST', body: JSON.stringify(body) });
      S.follow = true;
      await refreshList();
      await select(c.id);
    } catch (err) { $('form-error').textContent = err.message; }
  })();
});

connect();
// Now and then, the selected campaign from the API, while it is live: a record the stream
// missed (or a request that failed) never leaves the page stale for long.
setInterval(() => {
  const d = S.detail;
  if (S.online && d && ['queued', 'arming', 'running', 'paused'].includes(d.state)) serial(refreshDetail)();
}, 5000);
