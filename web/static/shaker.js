// The shaker's sine sweep: where it is (step k of N, frequency, amplitude, direction, control
// error, ETA), the transmissibility as it builds (sweep_plots.js), the resonance of each curve
// and the jumps between up and down (GET /api/campaigns/ID/sweep), the signals against time
// (shaker_time.js), and the sweep's warnings in words. Everything comes from the campaign's
// stored events and /sweep, so a reload shows what was there; the stream only brings it sooner.
import { api } from './api.js';
import { el, num, duration, roughly, plural } from './fmt.js';
import { TransmissibilityPlot } from './sweep_plots.js';
import { ShakerTimePlot } from './shaker_time.js';
import { BackbonePlot } from './backbone.js';

const MAX_LISTED = 8;  // of a kind of warning, the steps named before "…"
const pct = v => (Number.isFinite(v) ? `${v > 0 ? '+' : v < 0 ? '−' : ''}${num(Math.abs(v), 2)} %` : '–');
const hz = v => `${num(v)} Hz`;

// Each warning event of a sweep (details: daemon/src/sine_strategy.cpp) in a sentence, when it is
// the only one of its kind, else as an item of one line per kind: a sweep near its resonance can
// warn at every step, and a line each would push the plots off the screen.
const SAY = {
  control_warning: d => `control: at ${hz(d.frequency_hz)} the base amplitude was ${num(d.base_mm)} mm against ${num(d.demand_mm)} mm (${pct(d.error_pct)}, beyond the ${d.band === 'abort' ? 'abort' : 'warning'} band)`,
  control_abort: d => `control abort at ${hz(d.frequency_hz)}: base ${num(d.base_mm)} mm against ${num(d.demand_mm)} mm (${pct(d.error_pct)}) with a drive of ${num(d.drive_mm)} mm`,
  control_unreached: d => `control: at ${hz(d.frequency_hz)}, ${num(d.demand_mm)} mm was not reached in ${plural(d.windows, 'window')} (${pct(d.error_pct)}` +
    `${d.limited ? ', the drive at its limit' : ''}): measured anyway`,
  unsettled: d => `${hz(d.frequency_hz)}: the response had not settled after ${plural(d.cycles, 'cycle')} (last change ${num(d.change_pct, 2)} %): measured anyway`,
  retake: d => `${hz(d.frequency_hz)}: the measurement was taken again (attempt ${d.attempt}: ${d.why})`,
  resonance_unresolved: d => `the resonance near ${hz(d.frequency_hz)} (pass ${d.pass}) was not resolved: ${d.band_points} of ${d.wanted} points in its half-power band after ${plural(d.added, 'added step')} (${d.why})`,
  gap: d => `no samples for ${num(d.length_ms / 1000, 2)} s of rig time (from ${num(d.from_s)} s)`,
};
const SHORT = {
  control_warning: d => `${hz(d.frequency_hz)} at ${num(d.demand_mm)} mm ${pct(d.error_pct)}`,
  control_abort: d => `${hz(d.frequency_hz)} ${pct(d.error_pct)}`,
  control_unreached: d => `${hz(d.frequency_hz)} at ${num(d.demand_mm)} mm ${pct(d.error_pct)}`,
  unsettled: d => `${hz(d.frequency_hz)} (${num(d.change_pct, 2)} % after ${d.cycles} cycles)`,
  retake: d => `${hz(d.frequency_hz)} (${d.why})`,
  resonance_unresolved: d => `${hz(d.frequency_hz)} (${d.band_points} of ${d.wanted} points: ${d.why})`,
  gap: d => `${num(d.length_ms / 1000, 2)} s at ${num(d.from_s)} s`,
};
const KIND_WORDS = {
  control_warning: 'control warnings (the base amplitude beyond the warning band in a control window)',
  control_abort: 'control aborts', control_unreached: 'steps whose base amplitude control did not reach (measured anyway)',
  unsettled: 'steps measured before their response settled', retake: 'measurements taken again',
  resonance_unresolved: 'resonances not resolved by the steps added', gap: 'holes in the time axis',
};

export class SweepView {
  constructor({ trans, time, table, status, backbone }) {
    this.plot = new TransmissibilityPlot(trans);
    this.backbone = new BackbonePlot(backbone);
    this.time = new ShakerTimePlot(time);
    this.tableEl = table; this.statusEl = status;
    this.reset(null);
  }
  reset(id) {
    this.id = id; this.points = []; this.report = null; this.loadedKey = null;
    this.step = null; this.point = null; this.warning = null; this.done = null; this.events = [];
    this.plot.set([]);
    this.backbone.set(null);
    this.time.clear(); this.time.redraw();
    this.renderTable();
  }

  // ---- from the campaign's events (stored, or just streamed) ----
  setEvents(events) {
    this.events = Array.isArray(events) ? events : [];
    this.step = this.point = this.warning = this.done = null;
    for (const e of this.events) this.note(e);
    if (this.step) this.time.setFrequency(this.step.frequency_hz);
  }
  note(e) {
    const d = e.detail && typeof e.detail === 'object' ? { ...e.detail, at: e.at } : null;
    if (!d) return;
    if (e.kind === 'sine_step') { this.step = d; this.warning = null; }
    else if (e.kind === 'transmissibility') this.point = d;
    else if (e.kind === 'control_warning') this.warning = d;
    else if (e.kind === 'sweep_done') this.done = d;
  }
  // A record from the stream: noted at once (the next GET of the events replaces the list).
  onRecord(kind, r) {
    if (r.campaign !== this.id || this.events.some(e => e.id === r.id)) return;
    const e = { id: r.id, at: r.at, kind, detail: r.detail };
    this.events.push(e);
    this.note(e);
    if (kind === 'sine_step') this.time.setFrequency(this.step.frequency_hz);  // the time plot's envelope or trace from here on
    if (kind === 'transmissibility' && r.detail && typeof r.detail === 'object') {
      this.points.push(r.detail);
      this.plot.set(this.points);
    }
  }

  // ---- the points and the report ----
  // Fetched again when the store holds points not shown yet, and once the campaign has ended
  // (the isolator model's predictions are stored with its end).
  async refresh(d) {
    const stored = this.events.filter(e => e.kind === 'transmissibility').length;
    const key = `${d.id}:${stored}:${d.final}`;
    if (key === this.loadedKey) return;
    const sweep = await api(`/api/campaigns/${d.id}/sweep`).catch(async e => {
      if (e.status !== 404) throw e;  // an older daemon: its points, without the report
      return { points: await api(`/api/campaigns/${d.id}/transmissibility`) };
    });
    if (this.id !== d.id) return;
    this.loadedKey = key;
    this.report = sweep;
    this.points = Array.isArray(sweep.points) ? sweep.points : [];
    this.plot.set(this.points);
    this.backbone.set(sweep);
    this.renderTable();
  }

  // ---- where the sweep is ----
  // The control error to show: this step's own (its point, or a warning since it began), else
  // the last measured step's, named.
  controlError() {
    const s = this.step, p = this.point;
    if (p && p.k === s.k) return { pct: p.control_error_pct, step: null };
    if (this.warning) return { pct: this.warning.error_pct, step: null };
    return p ? { pct: p.control_error_pct, step: p.k } : null;
  }
  // Seconds to go: the newest estimate (a step's start, or its point), less the time since it
  // was made while the sweep runs.
  etaSeconds(d) {
    const s = this.step, p = this.point;
    const latest = p && Date.parse(p.at) > Date.parse(s.at) ? p : s;
    if (!Number.isFinite(latest.eta_s)) return null;
    const since = d.state === 'running' ? Math.max(0, (Date.now() - Date.parse(latest.at)) / 1000) : 0;
    return Math.max(0, latest.eta_s - since);
  }
  // {k, of, pass, passes, frequency_hz, amplitude_mm, direction, control_error_pct, eta_s, progress, eta}
  status(d) {
    const s = this.step;
    if (!s || !d) return { progress: d && d.final ? plural(this.points.length, 'point') : '', eta: '' };
    const e = this.controlError(), eta = this.etaSeconds(d);
    const out = { k: s.k, of: s.of, pass: s.pass, passes: s.passes, frequency_hz: s.frequency_hz, amplitude_mm: s.amplitude_mm,
                  direction: s.direction, control_error_pct: e ? e.pct : null, eta_s: eta, eta: '' };
    if (d.state === 'running' || d.state === 'paused') {
      out.progress = `step ${s.k} of ${s.of}: ${hz(s.frequency_hz)} · ${num(s.amplitude_mm)} mm ${s.direction}` +
        (e ? ` · control error ${pct(e.pct)}${e.step ? ` (step ${e.step})` : ''}` : '');
      if (eta != null && d.state === 'running') out.eta = `ETA ${roughly(eta)}`;
    } else {
      const n = this.done ? this.done.points : this.points.length, of = this.done ? this.done.of : s.of;
      out.progress = `${n} of ${plural(of, 'step')} measured` + (this.done ? ` in ${duration(this.done.seconds)} of rig time` : '');
    }
    return out;
  }
  showStatus(d) {
    const s = this.status(d);
    const running = d && (d.state === 'running' || d.state === 'paused') && this.step;
    const parts = [];
    if (running) {
      parts.push(el('strong', { text: s.progress }));
      parts.push(` · pass ${s.pass} of ${s.passes} · drive ${num(this.step.drive_mm)} mm`);
      if (this.point) parts.push(` · last point ${hz(this.point.frequency_hz)}: T = ${num(this.point.ratio)}`);
      if (s.eta) parts.push(` · ${s.eta}`);
    } else if (this.done) {
      parts.push(`${s.progress} (planned: ${duration(this.done.nominal_seconds)}), ${plural(this.done.warnings, 'warning')}` +
        (this.done.predicted_with ? `; predicted with ${this.done.predicted_with}` : ''));
    } else parts.push(s.progress);
    this.statusEl.replaceChildren(...parts);
    return s;
  }

  // The sweep's warnings, for the warning box: a line per kind.
  warnings() {
    const byKind = new Map();
    for (const e of this.events) {
      if (!SAY[e.kind] || !e.detail || typeof e.detail !== 'object') continue;
      if (!byKind.has(e.kind)) byKind.set(e.kind, []);
      byKind.get(e.kind).push(e.detail);
    }
    return [...byKind].map(([kind, list]) => (list.length === 1 ? SAY[kind](list[0]) :
      `${list.length} ${KIND_WORDS[kind]}: ${list.slice(0, MAX_LISTED).map(SHORT[kind]).join('; ')}${list.length > MAX_LISTED ? '; …' : ''}`));
  }

  // ---- the resonance table and the jumps ----
  rows() {
    const r = this.report, out = [];
    if (!r) return out;
    for (const [which, rep] of [['measured', r.measured], ['predicted', r.predicted]])
      for (const c of (rep && rep.curves) || []) out.push({ which, curve: c });
    return out;
  }
  renderTable() {
    const rows = this.rows(), r = this.report;
    // ζ eq: the equivalent damping at the resonance, from the steps' hysteresis loops (the loop's
    // area against the elastic energy): read down the amplitudes with the resonance, the backbone.
    const head = el('tr', {}, ...['curve', 'resonance (Hz)', 'peak T', 'half-power points (Hz)', 'bandwidth (Hz)', 'Q', 'ζ eq'].map(h => el('th', { text: h })));
    const body = rows.map(({ which, curve: c }) => {
      const res = c.resonance;
      const label = `${num(c.amplitude_mm)} mm ${c.direction}${which === 'predicted' ? ' (predicted)' : ''}`;
      const cells = !res ? ['–', '–', '–', '–', '–', '–'] : [
        res.at_edge ? 'beyond the sweep' : num(res.frequency_hz),
        (res.at_edge ? '≥ ' : '') + num(res.peak_ratio),
        // Steps coarser than the peak (resolved false): the bandwidth is at most, and Q at least, what is shown.
        halfPower(res), res.bandwidth_hz != null ? (res.resolved === false ? '≤ ' : '') + num(res.bandwidth_hz) : '–',
        res.q != null ? (res.resolved === false ? '≥ ' : '') + num(res.q) : '–',
        Number.isFinite(c.equivalent_damping) ? num(c.equivalent_damping, 3) : '–'];
      const why = res && res.at_edge ? `the highest point (${hz(res.frequency_hz)}) is at the sweep's end: the peak may lie beyond`
        : res && res.resolved === false ? 'the steps are coarser than the peak: its bandwidth is at most, and its Q at least, what is shown' : '';
      return el('tr', { class: which, title: why },
        el('td', { text: label }), ...cells.map(v => el('td', { text: v })));
    });
    const jumps = ((r && r.measured && r.measured.jumps) || []).map(j => el('li', { text: jumpText(j) }));
    if (r && r.measured && r.measured.compared && !jumps.length)
      jumps.push(el('li', { class: 'muted', text: `up and down agree within ${num(100 * r.jump_threshold, 2)} % at every frequency (${plural(r.measured.compared, 'amplitude')} swept both ways)` }));
    this.tableEl.replaceChildren(
      el('table', { class: 'figures resonance' }, el('thead', {}, head), el('tbody', {}, ...body)),
      el('ul', { class: 'jumps' }, ...jumps));
    this.tableEl.hidden = !rows.length && !jumps.length;
  }
}

// A sweep's event for the event list (null: not a sweep's).
// How a step was reached from the one before (sine_step's change, docs/DAEMON.md).
function reached(d) {
  if (d.change === 'glide') return `, glided to over ${d.glide_cycles} frequencies`;
  if (d.change === 'burst') return `, the drive's phase moved ${num(d.shift_deg)}° across the resonance`;
  if (d.change === 'jump') return ', jumped to';
  return '';
}

export function describeSweepEvent(e) {
  const d = e.detail;
  if (!d || typeof d !== 'object') return null;
  if (e.kind === 'sine_step') return `step ${d.k} of ${d.of}: ${hz(d.frequency_hz)}, ${num(d.amplitude_mm)} mm ${d.direction} (pass ${d.pass} of ${d.passes}), drive ${num(d.drive_mm)} mm${reached(d)}`;
  if (e.kind === 'transmissibility') return `${hz(d.frequency_hz)}` + (d.amplitude_mm != null ? ` at ${num(d.amplitude_mm)} mm ${d.direction}` : '') +
    `: T = ${num(d.ratio)}, phase ${num(d.phase_rad * 180 / Math.PI)}°` + (d.control_error_pct != null ? `, control error ${pct(d.control_error_pct)}` : '');
  if (e.kind === 'pretest') return `loop check: ${plural(d.frequencies, 'frequency', 'frequencies')} at ${num(d.level_mm)} mm in ${duration(d.seconds)} of rig time, ${plural(d.windows, 'window')}` +
    ` (the table's response ${num(d.response_min, 3)}–${num(d.response_max, 3)} of the drive${d.unsettled ? `; ${d.unsettled} not settled` : ''})`;
  if (e.kind === 'sweep_done') return `${d.points} of ${plural(d.of, 'step')} in ${duration(d.seconds)} of rig time (planned ${duration(d.nominal_seconds)}), ${plural(d.warnings, 'warning')}`;
  // A load frame's retake has rows, not a frequency: not ours.
  return SAY[e.kind] && (e.kind === 'gap' || d.frequency_hz != null) ? SAY[e.kind](d) : null;
}

// "15.5 – 19.4"; a band whose edges are missing or out of order says so.
function halfPower(res) {
  const lo = res.lower_hz, hi = res.upper_hz;
  if (lo == null && hi == null) return '–';
  if (lo != null && hi != null && !(lo < hi)) return `? (${num(lo)} above ${num(hi)})`;
  return `${lo != null ? num(lo) : '…'} – ${hi != null ? num(hi) : '…'}`;
}

// "0.05 mm: up and down differ by 25 % between 14.7 and 16.5 Hz (jumps near 15.9 Hz up, 14.9 Hz down)"
export function jumpText(j) {
  const where = [j.up_jump_hz > 0 ? `${hz(j.up_jump_hz)} up` : null, j.down_jump_hz > 0 ? `${hz(j.down_jump_hz)} down` : null].filter(Boolean);
  const band = Math.abs(j.hi_hz - j.lo_hz) < 1e-9 * j.hi_hz ? `at ${hz(j.lo_hz)}` : `between ${num(j.lo_hz)} and ${hz(j.hi_hz)}`;
  return `${num(j.amplitude_mm)} mm: up and down differ by ${num(100 * j.max_difference, 2)} % ${band}` +
    (where.length ? ` (jumps near ${where.join(', ')})` : '');
}
