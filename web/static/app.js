// hystlab's page: follows the daemon over its API and its event stream (docs/API.md).
// The pieces: the rig panel (rigs.js), the form (form.js), data quality (quality.js), the
// plots (plots.js); this file holds the campaign being shown and the live stream.
import { api, post, token } from './api.js';
import { XYPlot, TimePlot, TriangleHeatmap } from './plots.js';
import { RigPanel } from './rigs.js';
import { PlanForm } from './form.js';
import { showQuality } from './quality.js';
import { tableLines, ShakedownPlot, shakedownCaption, loopRows } from './identification.js';
import { count, num, round2, roughly, localTime, el } from './fmt.js';

const $ = id => document.getElementById(id);
const KEEP = 20000;         // live samples kept per plot
const LOOP_POINTS = 2000;   // the completed loop, from the server (shape-preserving)

const S = {
  campaigns: [], selected: null, follow: true, detail: null, runId: null, events: [],
  trans: [], lastEventId: '', es: null, online: false, warnings: [], loopInfo: null,
};

const loop = new XYPlot($('loop-plot'), 'displacement (mm)', 'force (N)',
  [{ label: 'measured', color: '#1565c0', width: 1.2 }, { label: 'identified model', color: '#ef6c00', width: 2 }]);
const heat = new TriangleHeatmap($('heatmap-plot'));
const timeplot = new TimePlot($('time-plot'), ['displacement (mm)', 'force (N)']);
const trans = new XYPlot($('trans-plot'), 'frequency (Hz)', 'mass / base amplitude', [{ label: 'transmissibility', color: '#6a1b9a', points: true }],
  { aspect: 0.5, maxHeight: 420 });
const shakedown = new ShakedownPlot($('shakedown-plot'));
const rigPanel = new RigPanel($('rigs'), { onChange: rigs => planForm.setRigs(rigs) });
// In the chain with the stream's handlers: a select() running beside them would reset what
// they just added (a sweep's first transmissibility point, say).
const planForm = new PlanForm($('plan-form'), { rigPanel, onSubmitted: c => serial(async () => { S.follow = true; await refreshList(); if (S.selected !== c.id) await select(c.id); })() });

// For tests and the curious: what the page shows, as numbers.
window.hystlab = {
  state: () => S.detail && S.detail.state, selected: () => S.selected,
  loopPoints: () => loop.points(0), modelPoints: () => loop.points(1),
  loopPath: () => loop.path(0), modelPath: () => loop.path(1), loopInfo: () => S.loopInfo,
  loadLoop: points => new Promise((resolve, reject) => serial(() => loadLoop(points).then(resolve, reject))()),
  heatmapIdentified: () => heat.identified(), heatmapRequired: () => heat.required(), heatmapLimits: () => heat.limits(),
  transmissibilityPoints: () => trans.points(0), online: () => S.online,
  rigs: () => rigPanel.rigs(), warnings: () => S.warnings.slice(),
  shakedownPoints: () => shakedown.points(), loopRows: () => $('loops').querySelectorAll('tbody tr').length,
  heldOut: () => [...document.querySelectorAll('#accuracy .heldout')].map(e => e.textContent),
  recommended: () => { const r = document.querySelector('#accuracy .recommended'); return r ? Number(r.dataset.table) : null; },
};

// ---- the campaign list and the selected campaign ----
async function refreshList() {
  S.campaigns = await api('/api/campaigns');
  $('campaigns').replaceChildren(...S.campaigns.slice().reverse().map(c => {
    const li = el('li', { 'data-id': c.id, class: c.id === S.selected ? 'selected' : '',
                          text: `#${c.id} ${c.kind} — ${c.state}` + (c.tables ? ` · ${c.tables} table${c.tables > 1 ? 's' : ''}` : '') });
    li.addEventListener('click', serial(() => { S.follow = false; return select(c.id); }));
    return li;
  }));
  if (S.follow) {
    const live = S.campaigns.find(c => c.active);
    const pick = live || S.campaigns[S.campaigns.length - 1];
    if (pick && pick.id !== S.selected) await select(pick.id);
  }
}

async function select(id) {
  S.selected = id;
  for (const li of $('campaigns').children) li.className = Number(li.dataset.id) === id ? 'selected' : '';
  S.trans = []; S.loopInfo = null;
  loop.set(0, [], []); loop.set(1, [], []); timeplot.clear();
  heat.setGrid(null);
  await refreshDetail();  // for a FOT campaign, with its nodes
  const d = S.detail;
  if (d.kind === 'sine') { S.trans = await api(`/api/campaigns/${id}/transmissibility`); drawTrans(); }
  if (S.runId) { await loadRun(S.runId); await loadLoop(LOOP_POINTS); }
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
  // The list follows too: a state change the stream did not bring (a starved machine) would
  // leave "running" in the list beside "completed" in the header.
  const listed = S.campaigns.find(c => c.id === d.id);
  if (listed && listed.state !== d.state) {
    await refreshList();
    if (S.selected !== d.id) return;  // the list moved the page to another campaign
  }
  // The stored count is the truth: a node missed on the stream (or a failed load) is fetched again.
  if (d.kind === 'fot' && d.progress && (heat.grid ? d.progress.nodes !== heat.identified() : true)) await loadNodes(d.id);
  // The campaign's own run (the newest, after a resume), not the validation run beside it.
  const own = d.runs.filter(r => r.role !== 'validation');
  S.runId = own.length ? own[own.length - 1].id : null;
  $('title').textContent = `Campaign #${d.id}: ${d.kind} on ${d.rig}`;
  $('state').textContent = d.state;
  $('state').className = 'state ' + d.state;
  // The server says which commands apply in this state (GET /api/campaigns/ID: commands).
  const can = cmd => (d.commands || []).includes(cmd);
  $('pause').disabled = !can('pause');
  $('resume').disabled = !can('resume');
  $('abort').disabled = !can('abort');
  document.querySelector('.fot-only').hidden = d.kind !== 'fot';
  const cycles = d.shakedown || [];
  $('shakedown-fig').hidden = !cycles.length;
  if (cycles.length) { shakedown.set(cycles); $('shakedown-caption').textContent = shakedownCaption(d); }
  document.querySelector('.sine-only').hidden = d.kind !== 'sine';
  const shaker = d.kind === 'sine';
  timeplot.setLabels(shaker ? ['base displacement (mm)', 'mass displacement (mm)'] : ['displacement (mm)', 'force (N)']);
  $('time-caption').textContent = shaker ? 'Base and mass displacement against time' : 'Displacement and force against time';
  loop.relabel(shaker ? 'base displacement (mm)' : 'displacement (mm)', shaker ? 'mass displacement (mm)' : 'force (N)');
  showLoopCaption();
  showAccuracy(d);
  S.warnings = showQuality(d, $('quality'), $('warnings'));
  showDownloads(d);
  await showLoops(d);
  S.events = await api(`/api/campaigns/${d.id}/events`);
  showProgress(d);
  $('events').replaceChildren(...S.events.slice(-50).reverse().map(e =>
    el('li', { text: `${localTime(e.at)} ${e.kind}${e.to ? ' → ' + e.to : ''}: ${describe(e)}` })));
}

function describe(e) {
  const d = e.detail;
  if (typeof d === 'string') return d;
  if (!d) return '';
  if (e.kind === 'fit' && d.accuracy) return `partial table of ${d.nodes}/${d.required} nodes: RMS ${round2(d.accuracy.overall.rms_N)} N over the samples so far`;
  if (e.kind === 'transmissibility') return `${num(d.frequency_hz)} Hz: ratio ${num(d.ratio)}`;
  if (e.kind === 'gap') return `no samples for ${num(d.length_ms / 1000, 2)} s of rig time (from ${num(d.from_s)} s)`;
  if (e.kind === 'gaps') return `${d.count} holes in the time axis, ${num(d.total_ms / 1000, 2)} s in all, the longest ${num(d.longest_ms / 1000, 2)} s`;
  if (e.kind === 'quality') return `run #${d.run}: ${d.samples} samples at ${num(d.rate_hz, 3)} Hz of rig time, ${d.missed_deadlines} missed deadlines, ` +
    `${d.lost_samples} lost samples, ${d.io_errors} I/O errors, ${d.gaps} gaps`;
  if (e.kind === 'validation') return `validation run #${d.run}: ${d.reversals} random reversals (seed ${d.seed}), not used to build any table`;
  if (e.kind === 'recommendation' || e.kind === 'training') return d.why;
  if (e.kind === 'shakedown') return `cycle ${d.cycle}: E_d ${num(d.energy_Nmm)} N·mm` + (d.energy_change_pct != null ? ` (${num(d.energy_change_pct, 2)} %)` : '') +
    `, peak ${round2(d.peak_force_N)} N` + (d.peak_change_pct != null ? ` (${num(d.peak_change_pct, 2)} %)` : '') + (d.stable ? ': stable' : '');
  if (e.kind === 'limits') return Object.entries(d).map(([k, v]) => `${k.replace(/_/g, ' ')} ${Array.isArray(v) ? v.map(x => num(x)).join('…') : num(v)}`).join(', ');
  return JSON.stringify(d);
}

// Seconds the campaign has spent running, from its state events: paused (or held) time does
// not count, so the ETA does not jump after a pause.
function activeSeconds(events, now) {
  let total = 0, since = null;
  for (const e of Array.isArray(events) ? events : []) {  // a failed events request leaves no list
    if (e.kind !== 'state' && e.kind !== 'campaign') continue;
    const t = Date.parse(e.at);
    if (!Number.isFinite(t)) continue;
    if (e.to === 'running') { if (since == null) since = t; } else if (since != null) { total += t - since; since = null; }
  }
  if (since != null) total += Math.max(0, now - since);
  return total / 1000;
}

function showProgress(d) {
  if (!d.progress) { $('progress').textContent = ''; $('eta').textContent = ''; return; }
  const k = d.progress.nodes, n = d.progress.required;
  $('progress').textContent = `node ${k} of ${n}`;
  const active = activeSeconds(S.events, Date.now());
  $('eta').textContent = d.state === 'running' && k > 0 && k < n && active > 0 ? `ETA ${roughly(active / k * (n - k))}` : '';
  $('coverage').textContent = `— ${k} of ${n} nodes identified`;
}

// Each table's error on its own samples and on the validation run, and the recommended one.
function showAccuracy(d) { $('accuracy').replaceChildren(...tableLines(d)); }

// The figures of every closed cycle, once the campaign has stored them (at its end).
async function showLoops(d) {
  const key = `${d.id}:${d.state}:${d.tables.length}`;
  if (S.loopsKey === key) return;
  S.loopsKey = key;
  const loops = d.final || d.state === 'interrupted' ? await api(`/api/campaigns/${d.id}/loops`) : [];
  if (S.selected !== d.id) return;
  $('loops-box').hidden = !loops.length;
  $('loops').replaceChildren(...loopRows(loops));
  const phases = {};
  for (const l of loops) phases[l.phase] = (phases[l.phase] || 0) + 1;
  $('loops-summary').textContent = `Loop figures: ${count(loops.length)} closed cycles (` +
    Object.entries(phases).map(([k, v]) => `${v} ${k}`).join(', ') + ')';
}

function link(href, text) { return el('a', { href, download: true, text }); }
function showDownloads(d) {
  const links = [];
  for (const t of d.tables)
    for (const f of ['json', 'csv', 'm']) links.push(link(`/api/tables/${t.id}/export?format=${f}`, `table #${t.id} (${t.method}) .${f}`));
  for (const r of d.runs) links.push(link(`/api/runs/${r.id}/samples.csv`, `run #${r.id} samples .csv`));
  $('downloads').replaceChildren(...links);
}

// The run's history against time, decimated by the server (min and max per bucket, both drawn).
async function loadRun(runId) {
  if (S.detail.kind === 'sine') return;  // the sweep's signals come live; its history is the .csv
  const s = await api(`/api/runs/${runId}/samples?points=3000`);
  if (runId !== S.runId) return;
  timeplot.setBuckets(s, s.displacement_min_mm, s.displacement_max_mm, s.force_min_N, s.force_max_N);
}

// The run's loop from the server, in sample order with every reversal kept, and the identified
// model's force on the same x (computed there: no samples travel through the browser). An older
// daemon has no /loop: the loop is then what the stream brought, if anything.
async function loadLoop(points = LOOP_POINTS) {
  const runId = S.runId;
  if (!runId) return false;
  let l;
  // The first request for a long run reads it from SQLite (about 4-7 s per 10^6 samples on a
  // small machine): a longer wait than other requests, which must never stall the page.
  try { l = await api(`/api/runs/${runId}/loop?points=${points}`, { signal: AbortSignal.timeout(120000) }); } catch (e) {
    if (e.status === 404) return false;
    throw e;
  }
  if (runId !== S.runId || !l || !Array.isArray(l.x)) return false;
  if (l.x_label && l.y_label) loop.relabel(l.x_label, l.y_label);
  loop.set(0, l.x, l.y);
  const model = l.model && Array.isArray(l.model.force_N) ? l.model : null;
  loop.set(1, model ? l.x : [], model ? model.force_N : []);
  S.loopInfo = { samples: l.samples, reversals: l.reversals, points: l.x.length, table: model ? model.table : null };
  showLoopCaption();
  redraw();
  return true;
}

function showLoopCaption() {
  const shaker = S.detail && S.detail.kind === 'sine', i = S.loopInfo;
  let text = shaker ? 'Mass against base displacement' : 'Force–displacement';
  if (i) text += ` — ${count(i.samples)} samples, ${count(i.reversals)} reversals (drawn with ${count(i.points)} points)` +
    (i.table ? `; orange: table #${i.table}` : '');
  $('loop-caption').textContent = text;
}

function drawTrans() {
  const pts = S.trans.slice().sort((p, q) => p.frequency_hz - q.frequency_hz);
  trans.set(0, pts.map(p => p.frequency_hz), pts.map(p => p.ratio));
  trans.redraw();
}

function redraw() { loop.redraw(); timeplot.redraw(); heat.redraw(); }

// Handlers that refresh from the API run one after another, so an older answer never
// overwrites a newer one.
let chain = Promise.resolve();
const serial = fn => (...args) => { chain = chain.then(() => fn(...args)).catch(e => console.warn(e)); return chain; };

// ---- live: the event stream (reconnects by itself, resuming after the last record seen) ----
function connect() {
  const t = token();
  const url = '/api/stream?rate=50' + (S.lastEventId ? '&last_event_id=' + encodeURIComponent(S.lastEventId) : '') +
    (t ? '&token=' + encodeURIComponent(t) : '');
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
  for (const k of ['fit', 'transmissibility', 'command', 'shakedown', 'training', 'validation']) on(k, serial(r => onRecord(k, r)));
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
  $('daemon').textContent = `hystlabd ${s.version}`;
  if (!rigPanel.rigs().length) planForm.setRigs(s.rigs);
}

function onSamples(m) {
  if (!S.detail || m.run !== S.runId) return;
  if (S.detail.kind === 'sine') { timeplot.push(m.t, m.cmd, m.disp, KEEP); loop.append(0, m.cmd, m.disp); }
  else { timeplot.push(m.t, m.disp, m.force, KEEP); loop.append(0, m.disp, m.force); }
  if (loop.points(0) > KEEP * 2) loop.trim(0, KEEP);
  scheduleRedraw();
}

let redrawPending = false;
function scheduleRedraw() {
  if (redrawPending) return;
  redrawPending = true;
  requestAnimationFrame(() => { redrawPending = false; loop.redraw(); timeplot.redraw(); });
}

async function onCampaign(ev) {
  await refreshList();
  if (ev.campaign === S.selected) {
    const before = S.runId;
    await refreshDetail();
    // A new run (started, or resumed after an interruption): show it from its start. Only
    // then: selecting again would throw away the live samples already drawn.
    if (S.runId !== before) await select(ev.campaign);
    // Ended: the whole run from the store (a sine sweep makes no table to trigger it).
    else if (ev.final && S.runId) { await loadRun(S.runId); await loadLoop(LOOP_POINTS); redraw(); }
  } else if (S.follow && ev.to === 'arming') await select(ev.campaign);
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
  if (S.runId) { await loadRun(S.runId); await loadLoop(LOOP_POINTS); }  // the whole run, with the model
  redraw();
}
async function onRecord(kind, r) {
  if (r.campaign !== S.selected) return;
  if (kind === 'transmissibility') { S.trans.push({ frequency_hz: r.detail.frequency_hz, ratio: r.detail.ratio }); drawTrans(); }
  await refreshDetail();
}

// ---- controls: no body (the server takes an empty POST) ----
for (const verb of ['pause', 'resume', 'abort']) {
  $(verb).addEventListener('click', async () => {
    $('command-error').textContent = '';
    try { await post(`/api/campaigns/${S.selected}/${verb}`); } catch (e) { $('command-error').textContent = `${verb}: ${e.message}`; }
  });
}

rigPanel.start();
connect();
// Now and then, the selected campaign from the API, while it is live: a record the stream
// missed (or a request that failed) never leaves the page stale for long; the ETA moves on.
setInterval(() => {
  const d = S.detail;
  if (S.online && d && !d.final) serial(refreshDetail)();
}, 5000);
