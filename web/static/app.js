// hystlab's page: follows the daemon over its API and its event stream (docs/API.md).
// The pieces: the rig panel (rigs.js), the form (form.js), data quality (quality.js), the
// plots (plots.js), a shaker's sine sweep (shaker.js); this file holds the campaign being shown
// and the live stream.
import { api, post, token, href, ARCHIVE } from './api.js';
import { XYPlot, TimePlot, TriangleHeatmap, LOOP_SHARE, relayout } from './plots.js';
import { parseRoute, setRoute, routeHref } from './route.js';
import { RecordView } from './record.js';
import { SweepView } from './shaker.js';
import { RigPanel } from './rigs.js';
import { PlanForm } from './form.js';
import { showQuality } from './quality.js';
import { tableLines, ShakedownPlot, shakedownCaption, loopRows } from './identification.js';
import { DesignPanel } from './design.js';
import { describeEvent, activeSeconds } from './event_text.js';
import { count, roughly, localTime, el, plural } from './fmt.js';

const $ = id => document.getElementById(id);
const KEEP = 20000;         // live samples kept per plot
const LOOP_POINTS = 2000;   // the completed loop, from the server (shape-preserving)
const SHAKER_LOOP_KEEP = 4000;  // a shaker's live loop: its newest cycles (the stream brings up to 1000 samples/s)
const FRAME_RATE = 50;      // samples/s asked of the stream for a load frame
const SINE_EVENTS = ['sine_step', 'control_warning', 'control_abort', 'control_unreached', 'unsettled', 'resonance_unresolved', 'retake', 'gap', 'gaps', 'quality', 'sweep_done'];

const S = {
  campaigns: [], selected: null, follow: true, detail: null, runId: null, events: [],
  lastEventId: '', es: null, streamRate: FRAME_RATE, online: false, warnings: [], loopInfo: null,
};

const loop = new XYPlot($('loop-plot'), 'displacement (mm)', 'force (N)',
  [{ label: 'measured', color: '#1565c0', width: 1.2 }, { label: 'identified model', color: '#ef6c00', width: 2 }], { share: LOOP_SHARE, minHeight: 200 });
const heat = new TriangleHeatmap($('heatmap-plot'));
const timeplot = new TimePlot($('time-plot'), ['displacement (mm)', 'force (N)']);
const sweep = new SweepView({ trans: $('trans-plot'), time: $('shaker-time-plot'), table: $('resonance'), status: $('sweep-status'), backbone: $('backbone') });
$('time-mode').addEventListener('change', e => { sweep.time.setMode(e.target.value); sweep.time.redraw(); });
const isSine = () => !!S.detail && S.detail.kind === 'sine';
const shakedown = new ShakedownPlot($('shakedown-plot'));
const design = new DesignPanel($('design-fig'), $('design-caption'), $('design-plot'), $('design-rows'));
const rigPanel = ARCHIVE ? null : new RigPanel($('rigs'), { onChange: rigs => planForm.setRigs(rigs) });
// In the chain with the stream's handlers: a select() running beside them would reset what
// they just added (a sweep's first transmissibility point, say).
const planForm = ARCHIVE ? null : new PlanForm($('plan-form'), { rigPanel, onSubmitted: c => serial(async () => { S.follow = true; await refreshList(); if (S.selected !== c.id) await select(c.id); })() });

// For tests and the curious: what the page shows, as numbers.
window.hystlab = {
  state: () => S.detail && S.detail.state, selected: () => S.selected,
  loopPoints: () => loop.points(0), shownRun: () => S.runId, loopTicks: () => loop.ticks(), modelPoints: () => loop.points(1),
  loopPath: () => loop.path(0), modelPath: () => loop.path(1), loopInfo: () => S.loopInfo,
  loadLoop: points => new Promise((resolve, reject) => serial(() => loadLoop(points).then(resolve, reject))()),
  heatmapIdentified: () => heat.identified(), heatmapRequired: () => heat.required(), heatmapLimits: () => heat.limits(),
  // A sweep: the first curve's points (as the one curve of before), every curve, the scales.
  transmissibilityPoints: () => sweep.plot.firstCurvePoints(), online: () => S.online,
  transmissibilityCurves: () => sweep.plot.curves(), transmissibilityScales: () => sweep.plot.scales(),
  sineStatus: () => (isSine() ? sweep.status(S.detail) : null), streamRate: () => S.streamRate,
  resonanceRows: () => [...document.querySelectorAll('#resonance tbody tr')].map(tr => [...tr.cells].map(c => c.textContent)),
  jumps: () => [...document.querySelectorAll('#resonance .jumps li')].map(li => li.textContent),
  backbone: () => sweep.backbone.shown(),
  timeAxes: () => (isSine() ? sweep.time.axes() : timeplot.axes()),
  rigs: () => (rigPanel ? rigPanel.rigs() : []), archive: () => ARCHIVE, warnings: () => S.warnings.slice(),
  shakedownPoints: () => shakedown.points(), designPoints: () => design.points(), designRows: () => design.rows(), shakedownTicks: () => shakedown.ticks(), loopRows: () => $('loops').querySelectorAll('tbody tr').length,
  heldOut: () => [...document.querySelectorAll('#accuracy .heldout')].map(e => e.textContent),
  recommended: () => { const r = document.querySelector('#accuracy .recommended'); return r ? Number(r.dataset.table) : null; },
};

// ---- the campaign list and the selected campaign ----
async function refreshList() {
  S.campaigns = await api('/api/campaigns');
  $('campaigns').replaceChildren(...S.campaigns.slice().reverse().map(c => {
    const li = el('li', { 'data-id': c.id, class: c.id === S.selected ? 'selected' : '',
                          // why it ended (or waits) beside the state, unless it simply finished
                          text: `#${c.id} ${c.kind} — ${c.state}` + (c.reason && c.state !== 'completed' && !c.active && c.state !== 'queued' ? ` (${c.reason})` : '') +
                                (c.tables ? ` · ${c.tables} table${c.tables > 1 ? 's' : ''}` : '') +
                                (c.specimen ? ` · ${c.specimen}` : ''),
                          title: c.reason ? `${c.state}: ${c.reason}` : '' });
    li.addEventListener('click', serial(() => { S.follow = false; return select(c.id, null, true); }));
    return li;
  }));
  if (S.follow) {
    const live = S.campaigns.find(c => c.active);
    const pick = live || S.campaigns[S.campaigns.length - 1];
    if (pick && pick.id !== S.selected) await select(pick.id);
  }
}

// Shows campaign id (and run `run` of it in the plots; null: its own run), with its address.
async function select(id, run = null, remember = false) {
  S.selected = id;
  S.wantRun = run;
  setRoute(id, run, remember);
  for (const li of $('campaigns').children) li.className = Number(li.dataset.id) === id ? 'selected' : '';
  S.loopInfo = null;
  loop.set(0, [], []); loop.set(1, [], []); timeplot.clear();
  sweep.reset(id);
  heat.setGrid(null);
  await refreshDetail();  // for a FOT campaign, with its nodes; for a sweep, its points
  if (S.runId) await loadRunAndLoop();
  redraw();
}

async function loadNodes(id) {
  const nodes = await api(`/api/campaigns/${id}/nodes`);
  if (id !== S.selected) return;
  heat.setGrid(nodes.grid);
  for (const n of nodes.nodes) heat.add(n.alpha, n.beta, n.F);
  heat.fitScale();
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
  else if (d.final) heat.fitScale();
  // The campaign's own run (the newest, after a resume), not the validation run beside it.
  // A run named in the address (#campaign/ID/run/R), when it is one of this campaign's.
  const own = d.runs.filter(r => r.role !== 'validation');
  const wanted = d.runs.find(r => r.id === S.wantRun);
  S.runId = wanted ? wanted.id : own.length ? own[own.length - 1].id : null;
  $('title').textContent = `Campaign #${d.id}: ${d.kind} on ${d.rig}` + (d.specimen ? ` · ${d.specimen}` : '');
  $('title').href = routeHref(d.id, wanted ? wanted.id : null);
  record.show(d);
  $('state').textContent = d.state;
  $('state').className = 'state ' + d.state;
  // Why it is in that state, beside it (an aborted or failed campaign's reason, not at the bottom of the events).
  $('state-reason').textContent = $('state-reason').title = d.reason && (d.final || d.state === 'held' || d.state === 'interrupted' || d.state === 'paused') ? d.reason : '';
  // The server says which commands apply in this state (GET /api/campaigns/ID: commands).
  const can = cmd => (d.commands || []).includes(cmd);
  $('pause').disabled = !can('pause');
  $('resume').disabled = !can('resume');
  $('abort').disabled = !can('abort');
  document.querySelector('.fot-only').hidden = d.kind !== 'fot';
  const cycles = d.shakedown || [];
  $('shakedown-fig').hidden = !cycles.length;
  if (cycles.length) { shakedown.set(cycles); $('shakedown-caption').textContent = shakedownCaption(d); }
  design.show(d.design);
  const shaker = d.kind === 'sine';
  for (const e of document.querySelectorAll('.sine-only')) e.hidden = !shaker;
  $('time-fig').hidden = shaker;  // a shaker's signals have a plot of their own (one displacement axis)
  // A sweep's mass-base loop is its newest cycles, live: the whole run's would pile up every
  // frequency and amplitude into one unreadable knot.
  $('loop-fig').hidden = shaker && d.final;
  $('shaker-time-fig').classList.toggle('wide', !!d.final);  // alone on its row then
  // The stored run's overview keeps displacements only: acceleration is a live view (and in samples.csv).
  const accel = $('time-mode').querySelector('option[value=accel]');
  accel.disabled = !!d.final;
  accel.title = d.final ? "live only: a finished run's acceleration is in its samples .csv" : '';
  if (d.final && $('time-mode').value === 'accel') { $('time-mode').value = 'disp'; sweep.time.setMode('disp'); }
  loop.relabel(shaker ? 'base displacement (mm)' : 'displacement (mm)', shaker ? 'mass displacement (mm)' : 'force (N)');
  loop.offer(1, !shaker);  // a shaker has no identified model to draw
  showLoopCaption();
  showAccuracy(d);
  S.events = await api(`/api/campaigns/${d.id}/events`);
  if (S.selected !== d.id) return;
  if (shaker) { sweep.setEvents(S.events); useStreamRate(sineStreamRate(d)); await sweep.refresh(d); } else useStreamRate(FRAME_RATE);
  const warned = $('warnings').hidden ? 0 : $('warnings').offsetHeight;
  S.warnings = showQuality(d, $('quality'), $('warnings'), shaker ? sweepWarnings(d) : [], { run: S.runId, href: r => routeHref(d.id, r) });
  if (($('warnings').hidden ? 0 : $('warnings').offsetHeight) !== warned) relayout();  // the plots share what the box leaves
  showDownloads(d);
  await showLoops(d);
  showProgress(d);
  $('events').replaceChildren(...S.events.slice(-50).reverse().map(e =>
    el('li', { text: `${localTime(e.at)} ${e.kind}${e.to ? ' → ' + e.to : ''}: ${describeEvent(e)}` })));
}

// The header's status line (reason, progress, ETA) may be cut at its end: its tooltip has it all.
function showProgress(d) {
  progressText(d);
  $('status-line').title = $('status-line').textContent.trim();
}
function progressText(d) {
  if (d.kind === 'sine') { const s = sweep.showStatus(d); $('progress').textContent = s.progress; $('eta').textContent = s.eta; return; }
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

function link(href, text, name = true) { return el('a', { href, download: name, text }); }
function showDownloads(d) {
  const links = [];
  for (const t of d.tables)
    for (const f of ['json', 'csv', 'm', 'h', 'fmu']) links.push(link(href(`/api/tables/${t.id}/export?format=${f}`), `table #${t.id} (${t.method}) .${f}`));
  if (d.kind === 'sine') {
    links.push(link(href(`/api/campaigns/${d.id}/sweep.csv`), 'sweep points .csv', `sweep-${d.id}.csv`));
    links.push(link(href(`/api/campaigns/${d.id}/sweep`), 'sweep points and resonances .json', `sweep-${d.id}.json`));
  }
  // A run's full samples and the report come from the rig's own daemon (or `hystlab runs export --pg`).
  if (ARCHIVE) return $('downloads').replaceChildren(...links);
  links.push(el('a', { href: `/api/campaigns/${d.id}/report.html`, target: '_blank', class: 'report', text: 'report (to print or file)' }));
  for (const r of d.runs) {
    if (!(r.samples > 0)) continue;  // nothing stored: nothing to download
    links.push(link(`/api/runs/${r.id}/samples.csv`, `run #${r.id} samples .csv`));
    links.push(link(`/api/runs/${r.id}/samples.h5`, `run #${r.id} .h5 (with the campaign)`));
  }
  $('downloads').replaceChildren(...links);
}

// The sweep's own warnings beside the runs' and tables': its events in words, and the
// acquisition's missed deadlines (each a sample taken late) when the run's quality has any.
function sweepWarnings(d) {
  const out = sweep.warnings();
  for (const r of d.runs) {
    const q = r.quality;
    if (q && q.missed_deadlines > 0 && !(q.warnings || []).some(w => /deadline/.test(w)))
      out.push(`run #${r.id}: ${plural(q.missed_deadlines, 'missed deadline')} of the acquisition (samples taken late)`);
  }
  return out;
}

// The run from the store: its history against time and, for a load frame, its whole loop.
async function loadRunAndLoop() {
  await loadRun(S.runId);
  if (!isSine()) await loadLoop(LOOP_POINTS);
}

// The run's history against time, decimated by the server (min and max per bucket, both drawn).
async function loadRun(runId) {
  if (S.detail.kind === 'sine') return loadShakerRun(runId, S.detail.final);
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
  let text = shaker ? 'Mass against base displacement: the newest cycles' : 'Force–displacement';
  // Live, the samples the stream brought (it updates as they come); at the end, the stored run's.
  const shown = S.runId != null && S.detail.runs.find(r => r.id === S.runId);
  if (shown) text += `, run #${shown.id}` + (shown.role === 'validation' ? ' (validation)' : '');
  const live = !ARCHIVE && !shaker && S.detail && !S.detail.final && shown && shown.state === 'running';
  if (live) text += ` — live: ${count(loop.points(0))} samples drawn (${S.streamRate}/s of the rig's)`;
  else if (i) text += ` — ${count(i.samples)} samples, ${count(i.reversals)} reversals (drawn with ${count(i.points)} points)` +
    (i.table ? `; orange: table #${i.table}` : '');
  $('loop-caption').textContent = text;
}

// A shaker run's history as an envelope: the whole run once it has ended (the live samples go),
// else its newest seconds, which the live samples then continue.
async function loadShakerRun(runId, whole) {
  let q = 'points=2000';
  if (!whole) {
    const span = await api(`/api/runs/${runId}/samples?points=1`);
    if (!(span.t1 > 0)) return;
    q = `t0=${Math.max(0, span.t1 - 10)}&t1=${span.t1}&points=600`;
  }
  const s = await api(`/api/runs/${runId}/samples?${q}`);
  if (runId !== S.runId) return;
  if (whole) sweep.time.clear();
  sweep.time.setHistory(s);
  sweep.time.redraw();
}

function redraw() { loop.redraw(); timeplot.redraw(); heat.redraw(); if (isSine()) sweep.time.redraw(); }

// The stream's sample rate: for a running sweep, 20 samples a cycle of its highest frequency
// (the time plot then draws a trace; above, each cycle's envelope), at most the plan's sample
// rate and the stream's 1000/s. The stream decimates by keeping every n-th sample (web/src/
// event_stream.cpp), so asking less than the rig samples would alias a fast sine.
function sineStreamRate(d) {
  if (d.final) return FRAME_RATE;
  const p = d.plan || {}, sw = p.sweep || {};
  const fmax = Math.max(Number(sw.to_hz) || 0, ...(Array.isArray(p.frequencies_hz) ? p.frequencies_hz : []).map(Number));
  const cap = Math.min(1000, Number(p.sample_rate_hz) || 1000);
  return Math.round(Math.min(cap, Math.max(FRAME_RATE, 20 * (fmax || 50))));
}
function useStreamRate(rate) {
  if (rate === S.streamRate) return;
  S.streamRate = rate;
  if (S.es) { S.es.close(); S.es = null; connect(); }  // resumes after the last record seen
}

// Handlers that refresh from the API run one after another, so an older answer never
// overwrites a newer one.
let chain = Promise.resolve();
const serial = fn => (...args) => { chain = chain.then(() => fn(...args)).catch(e => console.warn(e)); return chain; };

// ---- live: the event stream (reconnects by itself, resuming after the last record seen) ----
function connect() {
  const t = token();
  const url = `/api/stream?rate=${S.streamRate}` + (S.lastEventId ? '&last_event_id=' + encodeURIComponent(S.lastEventId) : '') +
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
  for (const k of ['fit', 'transmissibility', 'command', 'shakedown', 'training', 'validation', 'design', ...SINE_EVENTS]) on(k, serial(r => onRecord(k, r)));
  es.onerror = () => {
    if (S.es !== es) return;  // replaced (a new rate): not an outage
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
  showLab(s.lab);
  if (planForm && !rigPanel.rigs().length) planForm.setRigs(s.rigs);
}

// What this daemon shares with its lab (docs/LAB.md), when its config has a lab section: the
// replication's lag and backlog, the broker's link; the reason of a failure on hover.
function showLab(lab) {
  const el = $('lab-status');
  if (!lab) { el.hidden = true; return; }
  const pg = lab.postgresql, mq = lab.mqtt, parts = [];
  if (pg) parts.push(pg.connected ? `lab db lag ${pg.lag_s.toFixed(1)} s${pg.backlog_samples > 0 ? `, ${pg.backlog_samples} behind` : ''}` : 'lab db down');
  if (mq) parts.push(mq.connected ? 'broker up' : 'broker down');
  el.hidden = false;
  el.className = 'link ' + ((!pg || pg.connected) && (!mq || mq.connected) ? 'up' : 'down');
  el.textContent = parts.join(' · ');
  el.title = [pg && pg.error, mq && mq.error].filter(Boolean).join('\n') || `lab ${lab.name}, as ${lab.daemon}`;
}

function onSamples(m) {
  if (!S.detail || m.run !== S.runId) return;
  if (isSine()) {
    const base = signal(m, 'base_displacement_mm', 'cmd'), mass = signal(m, 'mass_displacement_mm', 'disp');
    sweep.time.push(m.t, base, mass, signal(m, 'mass_accel_m_s2', 'force'));
    loop.append(0, base, mass);
    if (loop.points(0) > SHAKER_LOOP_KEEP * 1.5) loop.trim(0, SHAKER_LOOP_KEEP);
  } else {
    timeplot.push(m.t, m.disp, m.force, KEEP);
    loop.append(0, m.disp, m.force);
    if (loop.points(0) > KEEP * 2) loop.trim(0, KEEP);
  }
  scheduleRedraw();
}

// A live signal by its name: the stream says what its cmd, disp and force hold (`signals`); an
// older daemon does not, and a shaker's are base, mass and mass acceleration there.
function signal(m, name, fallback) {
  const k = Array.isArray(m.signals) ? m.signals.indexOf(name) : -1;
  return k >= 0 ? m[['cmd', 'disp', 'force'][k]] : m[fallback];
}

let redrawPending = false;
function scheduleRedraw() {
  if (redrawPending) return;
  redrawPending = true;
  requestAnimationFrame(() => { redrawPending = false; loop.redraw(); if (isSine()) sweep.time.redraw(); else { timeplot.redraw(); showLoopCaption(); } });
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
    else if (ev.final && S.runId) { await loadRunAndLoop(); redraw(); }
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
  if (S.runId) await loadRunAndLoop();  // the whole run, with the model
  redraw();
}
async function onRecord(kind, r) {
  if (r.campaign !== S.selected) return;
  if (isSine()) {
    sweep.onRecord(kind, r);
    // A step begins: the header says so now; the next poll brings the rest.
    if (kind === 'sine_step') { showProgress(S.detail); return; }
  }
  await refreshDetail();
}

// ---- controls: no body (the server takes an empty POST) ----
for (const verb of ['pause', 'resume', 'abort']) {
  $(verb).addEventListener('click', async () => {
    $('command-error').textContent = '';
    try { await post(`/api/campaigns/${S.selected}/${verb}`); } catch (e) { $('command-error').textContent = `${verb}: ${e.message}`; }
  });
}

// Specimen and notes under the plots (serial: defined above with the stream's handlers).
const record = new RecordView($('record'), { readOnly: ARCHIVE, onSaved: serial(async () => { await refreshList(); await refreshDetail(); }) });

// The address names a campaign (and a run): shown, and the page does not follow the newest.
function followRoute() {
  const r = parseRoute();
  if (!r) return false;
  S.follow = false;
  if (r.campaign !== S.selected || r.run !== S.wantRun)
    serial(() => select(r.campaign, r.run).catch(e => {
      if (e.status !== 404) throw e;
      $('title').textContent = `There is no campaign #${r.campaign} in this daemon's database`;
      $('state').textContent = ''; $('state').className = 'state';
    }))();
  return true;
}
window.addEventListener('popstate', followRoute);
window.addEventListener('hashchange', followRoute);
followRoute();
if (ARCHIVE) startArchive();
else { rigPanel.start(); connect(); }
// Now and then, the selected campaign from the API, while it is live: a record the stream
// missed (or a request that failed) never leaves the page stale for long; the ETA moves on.
setInterval(() => {
  const d = S.detail;
  if (S.online && d && !d.final) serial(refreshDetail)();
  if (S.online && !$('lab-status').hidden) api('/api/status').then(s => showLab(s.lab), () => {});
}, 5000);

// A daemon's records in the lab view (api.js: ARCHIVE): what the lab database holds, read-only.
// No commands, no form, no live stream: the campaigns and the shown one are read again every 5 s
// (a campaign still replicating grows).
function startArchive() {
  document.body.classList.add('archive');
  for (const e of [$('plan-form').closest('section'), document.querySelector('#summary .controls'), $('rigs')]) e.hidden = true;
  $('link').textContent = 'lab database';
  $('link').className = 'link up';
  $('daemon').textContent = `${document.querySelector('meta[name="hystlab-base"]').dataset.daemon} (read-only, from the lab database)`;
  const tick = serial(async () => {
    try {
      await refreshList();  // the shown campaign's record, while not final: the interval above
      // Its plots too, from the store (there is no stream to grow them), until it is final.
      if (S.detail && !S.detail.final && S.runId) { await loadRunAndLoop(); redraw(); }
      setOnline(true);
      $('link').textContent = 'lab database';
    } catch (e) {
      setOnline(false);
      $('link').textContent = `lab database: ${e.message}`;
    }
  });
  tick();
  setInterval(tick, 5000);
}
