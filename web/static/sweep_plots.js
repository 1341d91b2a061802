// A sine sweep's transmissibility: mass / base amplitude on log–log axes and the phase (degrees)
// under it, on the same logarithmic frequency axis. One curve per amplitude and direction: a
// colour per amplitude, up solid, down dashed; measured as points joined by lines, the isolator
// model's prediction (when the campaign has one) as a thin line. The legend is ours (HTML under
// the plots): uPlot's would list every series of both plots, with no room for the dashes.
/* global uPlot */
import { el, num } from './fmt.js';
import { onWidth } from './plots.js';

export const PALETTE = ['#1565c0', '#c62828', '#2e7d32', '#6a1b9a', '#ef6c00', '#00838f', '#5d4037', '#ad1457'];
const DASH = [7, 4];
const AXIS_SIZE = 64;  // both plots' y axes are this wide, so their frequencies line up

// Colours set through the CSSOM: the daemon's Content-Security-Policy refuses style attributes.
export const styled = (e, props) => { Object.assign(e.style, props); return e; };
export const curveLabel = c => `${num(c.amplitude_mm)} mm ${c.direction}`;
const sameFrequency = f => Number(f).toPrecision(9);

// The points as curves: one per amplitude and direction, ordered by amplitude, up before down,
// each by frequency. A frequency measured twice on a curve (a step taken again after a resume)
// keeps its newest point.
export function sweepCurves(points) {
  const byKey = new Map();
  for (const p of points || []) {
    if (!(p.frequency_hz > 0) || !(p.ratio > 0)) continue;
    const direction = p.direction === 'down' ? 'down' : 'up', key = `${p.amplitude_mm}|${direction}`;
    if (!byKey.has(key)) byKey.set(key, { amplitude_mm: p.amplitude_mm, direction, byF: new Map() });
    byKey.get(key).byF.set(sameFrequency(p.frequency_hz), p);
  }
  const list = [...byKey.values()].sort((a, b) => a.amplitude_mm - b.amplitude_mm || (a.direction === 'up' ? -1 : 1));
  const amplitudes = [...new Set(list.map(c => c.amplitude_mm))];
  return list.map(c => ({
    amplitude_mm: c.amplitude_mm, direction: c.direction, label: curveLabel(c),
    color: PALETTE[amplitudes.indexOf(c.amplitude_mm) % PALETTE.length],
    points: [...c.byF.values()].sort((p, q) => p.frequency_hz - q.frequency_hz),
  }));
}

// Degrees, unwrapped along the curve: the mass lags the base from 0 through −90° at resonance
// towards −180°, and the server's phase (−180°, 180°] would flip to +180° past it.
export function unwrapDegrees(radians) {
  let prev;
  return radians.map(r => {
    if (!Number.isFinite(r)) return null;
    let d = r * 180 / Math.PI;
    if (prev === undefined) { if (d > 90) d -= 360; } else { while (d - prev > 180) d -= 360; while (prev - d > 180) d += 360; }
    return (prev = d);
  });
}

// A log scale's minimum on a "round" value (a whole multiple of a power of ten): uPlot starts its
// log ticks there, so 4.3 would tick 4.3, 5.3, ... Its maximum may be anything (a rounded one
// left 12 to 20 Hz empty on a sweep that ended at 12 Hz).
function roundDown(v) { const p = 10 ** Math.floor(Math.log10(v)); return Math.floor(v / p + 1e-9) * p; }
export function logRange(lo, hi, pad, fallback) {
  if (!(lo > 0) || !(hi >= lo)) return fallback;
  return [roundDown(lo / pad), hi * pad];
}
function degreeRange(lo, hi) {
  // 8° beyond the ticks: a curve at −180° must not vanish into the frame.
  if (lo == null || !Number.isFinite(lo)) return [-188, 8];
  return [Math.min(-180, Math.floor(lo / 45) * 45) - 8, Math.max(0, Math.ceil(hi / 45) * 45) + 8];
}
// Which log ticks are labelled: 1s first, then 2s and 5s, then 3s, then the rest, each only
// `gap` px clear of the labels placed (uPlot's own filter keeps only the 1s of a narrow decade,
// which left a 5–60 Hz sweep with the one label "10").
function logLabels(gap) {
  return (u, splits, axisIdx) => {
    const scale = u.axes[axisIdx].scale, pos = splits.map(v => u.valToPos(v, scale));
    const mantissa = v => Math.round(v / 10 ** Math.floor(Math.log10(v) + 1e-9));
    const keep = splits.map(() => false), placed = [];
    for (const set of [[1], [2, 5], [3], [4, 6, 7, 8, 9]])
      splits.forEach((v, i) => {
        if (v > 0 && set.includes(mantissa(v)) && placed.every(p => Math.abs(p - pos[i]) >= gap)) { keep[i] = true; placed.push(pos[i]); }
      });
    return splits.map((v, i) => (keep[i] ? v : null));
  };
}

export class TransmissibilityPlot {
  constructor(box) {
    this.box = box;
    this.ratioEl = el('div', { class: 'trans-ratio' });
    this.phaseEl = el('div', { class: 'trans-phase' });
    this.legendEl = el('div', { class: 'sweep-legend' });
    this.readout = el('div', { class: 'readout', text: 'hover over the plot for the values at a frequency' });
    box.append(this.ratioEl, this.phaseEl, this.legendEl, this.readout);
    this.list = []; this.xs = []; this.xRange = [1, 100]; this.signature = null; this.u = null; this.p = null;
    this.build([]);
    onWidth(box, w => this.resize(w));
  }
  sizes(w = this.box.clientWidth) {
    const width = Math.max(200, w);
    return [{ width, height: Math.round(Math.min(420, Math.max(240, width * 0.45))) },
            { width, height: Math.round(Math.min(220, Math.max(150, width * 0.2))) }];
  }
  resize(w) { const [a, b] = this.sizes(w); this.u.setSize(a); this.p.setSize(b); }

  // Each curve's series: measured, then predicted when it has any.
  seriesOf(list) {
    const out = [];
    for (const c of list) {
      const dash = c.direction === 'down' ? DASH : undefined;
      out.push({ curve: c, predicted: false, opts: { label: c.label, stroke: c.color, width: 1.6, dash, spanGaps: true,
        points: { show: true, size: 6, width: 1.5, stroke: c.color, fill: c.direction === 'down' ? '#fff' : c.color } } });
      if (c.points.some(p => Number.isFinite(p.predicted_ratio)))
        out.push({ curve: c, predicted: true, opts: { label: `${c.label} (predicted)`, stroke: c.color, width: 0.9, dash, spanGaps: true,
          alpha: 0.75, points: { show: false } } });
    }
    return out;
  }
  build(series) {
    if (this.u) { this.u.destroy(); this.p.destroy(); }
    this.series = series;
    const [a, b] = this.sizes();
    const sync = { key: 'hystlab-trans' };
    const x = { time: false, distr: 3, log: 10, range: () => this.xRange };
    const cursor = { sync, drag: { x: false, y: false, setScale: false }, points: { show: false } };
    const xAxis = label => ({ scale: 'x', label, space: 40, filter: logLabels(36) });
    this.u = new uPlot({
      ...a, legend: { show: false }, cursor,
      scales: { x, y: { distr: 3, log: 10, range: (u, lo, hi) => logRange(lo, hi, 1.25, [0.1, 10]) } },
      axes: [xAxis(null), { label: 'transmissibility (mass / base)', size: AXIS_SIZE, space: 24, filter: logLabels(20) }],
      series: [{}, ...series.map(s => s.opts)],
      hooks: { setCursor: [u => this.hover(u)] },
    }, this.data('ratio'), this.ratioEl);
    this.p = new uPlot({
      ...b, legend: { show: false }, cursor,
      scales: { x, y: { range: (u, lo, hi) => degreeRange(lo, hi) } },
      axes: [xAxis('frequency (Hz)'), { label: 'phase (°)', size: AXIS_SIZE, incrs: [45, 90, 180], space: 18 }],
      series: [{}, ...series.map(s => ({ ...s.opts, points: s.predicted ? s.opts.points : { ...s.opts.points, size: 5 } }))],
    }, this.data('phase'), this.phaseEl);
    this.drawLegend();
  }
  // uPlot's mode 1 wants one x for all: the union of the curves' frequencies, null where a curve has none.
  data(kind) {
    const at = new Map(this.xs.map((f, i) => [sameFrequency(f), i]));
    const out = [this.xs];
    for (const s of this.series) {
      const col = new Array(this.xs.length).fill(null);
      const pts = s.curve.points;
      const values = kind === 'ratio' ? pts.map(p => (s.predicted ? p.predicted_ratio : p.ratio))
        : unwrapDegrees(pts.map(p => (s.predicted ? p.predicted_phase_rad : p.phase_rad)));
      pts.forEach((p, k) => { const v = values[k]; col[at.get(sameFrequency(p.frequency_hz))] = Number.isFinite(v) && (kind !== 'ratio' || v > 0) ? v : null; });
      out.push(col);
    }
    return out;
  }
  // Every point of the campaign so far (GET /api/campaigns/ID/sweep's, or the stream's).
  set(points) {
    this.list = sweepCurves(points);
    const fs = new Map();
    for (const c of this.list) for (const p of c.points) fs.set(sameFrequency(p.frequency_hz), p.frequency_hz);
    this.xs = [...fs.values()].sort((a, b) => a - b);
    this.xRange = logRange(this.xs[0], this.xs[this.xs.length - 1], 1.08, [1, 100]);
    const series = this.seriesOf(this.list);
    const signature = series.map(s => s.opts.label).join('\n');
    if (signature !== this.signature) { this.signature = signature; this.build(series); return; }
    this.series = series;  // the same labels, new points
    this.u.setData(this.data('ratio'));
    this.p.setData(this.data('phase'));
  }
  drawLegend() {
    const items = this.series.map(s => {
      const c = s.curve.color, down = s.curve.direction === 'down';
      return el('span', { class: 'item' + (s.predicted ? ' predicted' : '') },
        styled(el('span', { class: 'swatch' + (down ? ' dashed' : '') }), { borderTopColor: c }),
        s.predicted ? null : styled(el('span', { class: 'marker' }), { borderColor: c, background: down ? '#fff' : c }), s.opts.label);
    });
    this.legendEl.replaceChildren(...(items.length ? items : [el('span', { class: 'muted', text: 'no point measured yet' })]));
  }
  // The values at the frequency under the pointer, under the legend.
  hover(u) {
    const i = u.cursor.idx;
    if (i == null || !this.xs.length) return;
    const phase = this.p.data;
    const parts = this.series.filter(s => !s.predicted).map(s => {
      const k = this.series.indexOf(s) + 1, r = u.data[k][i];
      return r == null ? null : `${s.opts.label}: ${num(r)} (${num(phase[k][i], 3)}°)`;
    }).filter(Boolean);
    this.readout.textContent = `${num(this.xs[i])} Hz — ${parts.join(' · ') || 'no point'}`;
  }
  // For the tests: what is drawn.
  curves() {
    return this.list.map(c => ({ label: c.label, amplitude_mm: c.amplitude_mm, direction: c.direction, color: c.color, points: c.points.length,
      predicted: c.points.filter(p => Number.isFinite(p.predicted_ratio)).length }));
  }
  scales() {
    const d = u => ({ x: u.scales.x.distr, y: u.scales.y.distr, width: u.width, height: u.height, series: u.series.length - 1 });
    return { ratio: d(this.u), phase: d(this.p), legend: [...this.legendEl.querySelectorAll('.item')].map(e => e.textContent) };
  }
  firstCurvePoints() { return this.list.length ? this.list[0].points.length : 0; }
}
