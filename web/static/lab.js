// The lab view (docs/LAB.md): every daemon and rig of the lab with its live state (the broker's),
// every campaign and table (the lab's database). Read-only: it sends no command; each rig's own
// daemon is a link away.
const $ = (id) => document.getElementById(id);
const text = (v) => (v === null || v === undefined || v === '' ? '—' : String(v));
const when = (iso) => (iso ? String(iso).replace('T', ' ').replace(/\.\d+/, '').replace(/\+00(:00)?$|Z$/, ' UTC') : '—');
const fixed = (v, d) => (typeof v === 'number' && isFinite(v) ? v.toFixed(d) : '—');

async function get(path) {
  const r = await fetch(path, { headers: { Accept: 'application/json' } });
  const body = await r.json().catch(() => ({}));
  if (!r.ok) throw new Error(body.detail || body.error || `HTTP ${r.status}`);
  return body;
}

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k === 'onclick') e.addEventListener('click', v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c instanceof Node ? c : document.createTextNode(text(c)));
  return e;
}

function link(up, node, what) {
  node.className = `link ${up ? 'up' : 'down'}`;
  node.textContent = `${what} ${up ? 'connected' : 'down'}`;
}

function rigCard(r, daemons) {
  const live = r.live;
  const d = daemons.get(r.daemon);
  const offline = d && d.online === false;
  const state = live ? live.state : r.last_campaign_state ? `last campaign ${r.last_campaign_state}` : 'no live state';
  const card = el('div', { class: `lab-rig${live && live.latched ? ' latched' : ''}${offline ? ' offline' : ''}`, 'data-rig': `${r.daemon}/${r.rig}` });
  card.append(el('div', { class: 'lab-rig-head' }, el('b', {}, r.rig), el('span', { class: 'muted' }, ` on ${r.daemon}`)));
  card.append(el('div', {}, el('span', { class: `state ${live ? live.state : ''}` }, offline ? 'daemon offline' : state)));
  if (live && live.latched) card.append(el('div', { class: 'lab-latch' }, `latched: ${text(live.latch_reason)}`));
  if (live && live.fault && (live.fault.code || live.fault.latched_code)) card.append(el('div', { class: 'lab-latch' }, `fault ${live.fault.code || live.fault.latched_code}: ${text(live.fault.text)}`));
  if (live && live.campaign) {
    const p = live.campaign.progress || {};
    const nodes = p.nodes !== undefined ? ` · ${p.nodes} nodes` : '';
    card.append(el('div', { class: 'muted' }, `campaign ${live.campaign.id} · ${text(p.phase)}${nodes}`));
  }
  if (live) card.append(el('div', { class: 'muted small' }, `as of ${when(live.changed_at || live.received_at)}`));
  if (d && d.url) card.append(el('a', { href: d.url, class: 'lab-open' }, 'open its page'));
  return card;
}

async function refreshLab() {
  try {
    const lab = await get('/api/lab');
    $('lab-name').textContent = lab.lab;
    document.title = `hystlab · ${lab.lab}`;
    link(true, $('pg-link'), 'database');
    if (lab.mqtt) link(lab.mqtt.connected, $('mqtt-link'), 'broker');
    else $('mqtt-link').hidden = true;
    const daemons = new Map(lab.daemons.map((d) => [d.name, d]));
    $('lab-rigs').replaceChildren(...(lab.rigs.length ? lab.rigs.map((r) => rigCard(r, daemons)) : [el('p', { class: 'muted' }, 'no rig has reported yet')]));
    $('lab-daemons').tBodies[0].replaceChildren(
      ...lab.daemons.map((d) =>
        el('tr', { class: d.online === false ? 'offline' : '' }, el('td', {}, d.name),
          el('td', {}, el('span', { class: `link ${d.online ? 'up' : 'down'}` }, d.online === null ? 'unknown' : d.online ? 'online' : 'offline')),
          el('td', {}, d.software), el('td', {}, when(d.last_seen)), el('td', {}, d.url ? el('a', { href: d.url }, d.url) : '—'))));
    $('lab-error').textContent = '';
  } catch (e) {
    link(false, $('pg-link'), 'database');
    $('lab-error').textContent = `The lab's database: ${e.message}`;
  }
}

async function refreshCampaigns() {
  const q = new URLSearchParams();
  for (const f of ['specimen', 'daemon']) if ($(`lab-${f}`).value.trim()) q.set(f, $(`lab-${f}`).value.trim());
  try {
    const rows = await get(`/api/lab/campaigns?${q}`);
    $('lab-campaigns').tBodies[0].replaceChildren(
      ...rows.map((c) =>
        el('tr', { class: 'pick', tabindex: '0', onclick: () => showCampaign(c.daemon, c.id) }, el('td', {}, c.daemon), el('td', {}, c.rig), el('td', {}, c.id),
          el('td', {}, c.kind), el('td', {}, el('span', { class: `state ${c.state}` }, c.state)), el('td', {}, c.specimen), el('td', {}, when(c.updated_at)))));
  } catch (e) {
    $('lab-error').textContent = `Campaigns: ${e.message}`;
  }
}

async function refreshTables() {
  try {
    const rows = await get('/api/lab/tables');
    const rms = (a, part) => (a && a[part] && a[part].overall ? a[part].overall.rms_N : a && part === 'training' && a.overall ? a.overall.rms_N : undefined);
    $('lab-tables').tBodies[0].replaceChildren(
      ...rows.map((t) =>
        el('tr', {}, el('td', {}, t.daemon), el('td', {}, t.id), el('td', {}, t.specimen), el('td', {}, t.method), el('td', {}, t.n),
          el('td', {}, `${fixed(rms(t.accuracy, 'held_out'), 3)} N`), el('td', {}, `${fixed(rms(t.accuracy, 'training'), 3)} N`), el('td', {}, when(t.created_at)))));
  } catch (e) {
    $('lab-error').textContent = `Tables: ${e.message}`;
  }
}

let plot = null;
function drawOverview(o, shaker) {
  if (plot) plot.destroy();
  plot = null;
  const t = o.min.t || [];
  if (!t.length) return $('lab-plot').replaceChildren(el('p', { class: 'muted' }, 'no samples in the lab database yet'));
  const [a, b] = shaker ? ['base_displacement_mm', 'mass_displacement_mm'] : ['disp', 'force'];
  const width = Math.max(320, $('lab-plot').clientWidth || 600);
  $('lab-plot').replaceChildren();
  plot = new uPlot({
    width, height: 260,
    scales: { x: { time: false }, y2: {} },
    axes: [{ label: 't (s, rig time)' }, { label: shaker ? 'base (mm)' : 'displacement (mm)' }, { scale: 'y2', side: 1, label: shaker ? 'mass (mm)' : 'force (N)', grid: { show: false } }],
    series: [{}, { label: `${a} max`, stroke: '#1565c0' }, { label: `${a} min`, stroke: '#90caf9' },
      { label: `${b} max`, stroke: '#c62828', scale: 'y2' }, { label: `${b} min`, stroke: '#ef9a9a', scale: 'y2' }],
  }, [t, o.max[a], o.min[a], o.max[b], o.min[b]], $('lab-plot'));
}

async function showCampaign(daemon, id) {
  try {
    const c = await get(`/api/lab/campaigns/${encodeURIComponent(daemon)}/${id}`);
    $('lab-campaign').hidden = false;
    $('lab-campaign-title').textContent = `${c.daemon} · campaign ${c.id} (${c.kind}) · ${c.state}`;
    // The rig's own page over this daemon's records in the lab database (the same read endpoints).
    $('lab-campaign-open').href = `/daemons/${encodeURIComponent(c.daemon)}/#campaign/${c.id}`;
    $('lab-campaign-line').textContent = `rig ${c.rig} · specimen ${text(c.specimen)} · ${when(c.created_at)} to ${when(c.updated_at)} · ${c.tables.length} table(s)`;
    $('lab-runs').tBodies[0].replaceChildren(...c.runs.map((r) => el('tr', {}, el('td', {}, r.id), el('td', {}, r.role), el('td', {}, r.state), el('td', {}, r.samples))));
    $('lab-events').replaceChildren(...c.events.slice(-30).map((e) => el('li', {}, `${when(e.at)} ${e.kind}${e.to ? ` → ${e.to}` : ''}`)));
    const run = c.runs.find((r) => r.role === 'campaign') || c.runs[0];
    if (run) drawOverview(await get(`/api/lab/runs/${encodeURIComponent(daemon)}/${run.id}/overview?buckets=600${run.signals === 'shaker' ? '&shaker=1' : ''}`), run.signals === 'shaker');
    $('lab-campaign').scrollIntoView({ block: 'nearest' });
  } catch (e) {
    $('lab-error').textContent = `Campaign ${daemon}/${id}: ${e.message}`;
  }
}

// The plot follows the page's width (a window resized, a phone turned).
window.addEventListener('resize', () => {
  if (plot) plot.setSize({ width: Math.max(320, $('lab-plot').clientWidth), height: 260 });
});

$('lab-filter').addEventListener('submit', (ev) => {
  ev.preventDefault();
  refreshCampaigns();
});
refreshLab();
refreshCampaigns();
refreshTables();
setInterval(refreshLab, 1000);
setInterval(() => { refreshCampaigns(); refreshTables(); }, 5000);
