// A sweep over several amplitudes read as an amplitude-dependent isolator is read: its backbone,
// the resonance frequency and the peak transmissibility against the base amplitude, and the
// equivalent damping there (ζ eq, from the steps' hysteresis loops: the loop's area against the
// elastic energy). Measured as points joined by lines (up solid, down dashed), the isolator
// model's prediction as a thin grey line. From GET /api/campaigns/ID/sweep's `backbone` lists
// (measured and predicted); shown once the measured one holds two amplitudes.
/* global uPlot */
import { el, num } from './fmt.js';
import { onWidth } from './plots.js';
import { logRange, styled } from './sweep_plots.js';

const MEASURED = '#1565c0', PREDICTED = '#757575', DASH = [7, 4];
const FIGURES = [
  { key: 'frequency_hz', label: 'resonance (Hz)' },
  { key: 'peak_ratio', label: 'peak T' },
  { key: 'equivalent_damping', label: 'ζ eq' },
];
const sameAmplitude = a => Number(a).toPrecision(9);

export class BackbonePlot {
  constructor(box) {
    this.box = box;
    this.row = el('div', { class: 'backbone-row' });
    this.legendEl = el('div', { class: 'sweep-legend' });
    this.readout = el('div', { class: 'readout', text: 'hover over a plot for the values at an amplitude' });
    box.append(this.row, this.legendEl, this.readout);
    this.plots = []; this.series = []; this.xs = []; this.signature = null;
    onWidth(box, w => { for (const u of this.plots) u.setSize(this.size(w)); });
  }
  // Three side by side where they fit 268 px each, else one under another, lower.
  size(w = this.box.clientWidth) {
    if (w < 3 * 268) return { width: Math.max(200, w), height: 190 };
    const per = Math.floor(w / 3) - 8;
    return { width: per, height: Math.round(Math.min(280, Math.max(200, per * 0.7))) };
  }

  // report: GET /api/campaigns/ID/sweep's answer (or null).
  set(report) {
    const measured = (report && report.measured && report.measured.backbone) || [];
    const predicted = (report && report.predicted && report.predicted.backbone) || [];
    const amplitudes = new Set(measured.map(b => sameAmplitude(b.amplitude_mm)));
    this.box.hidden = amplitudes.size < 2;
    if (this.box.hidden) return;
    this.series = [];
    for (const [list, which] of [[measured, 'measured'], [predicted, 'predicted']])
      for (const direction of ['up', 'down']) {
        const rows = list.filter(b => b.direction === direction).sort((a, b) => a.amplitude_mm - b.amplitude_mm);
        if (rows.length) this.series.push({ which, direction, rows, label: `${which} ${direction}` });
      }
    const xs = new Map();
    for (const s of this.series) for (const b of s.rows) xs.set(sameAmplitude(b.amplitude_mm), b.amplitude_mm);
    this.xs = [...xs.values()].sort((a, b) => a - b);
    const signature = this.series.map(s => s.label).join('\n');
    if (signature !== this.signature) { this.signature = signature; this.build(); return; }
    this.plots.forEach((u, k) => u.setData(this.data(FIGURES[k].key)));
  }
  opts(s) {
    const predicted = s.which === 'predicted', dash = s.direction === 'down' ? DASH : undefined, c = predicted ? PREDICTED : MEASURED;
    return { label: s.label, stroke: c, width: predicted ? 1 : 1.6, dash, spanGaps: true,
      points: predicted ? { show: false } : { show: true, size: 6, width: 1.5, stroke: c, fill: s.direction === 'down' ? '#fff' : c } };
  }
  build() {
    for (const u of this.plots) u.destroy();
    this.row.replaceChildren();
    // The amplitudes read at each redraw: a sweep's next level arrives after the plots are built.
    const xRange = () => logRange(this.xs[0], this.xs[this.xs.length - 1], 1.3, [0.001, 1]);
    const cursor = { sync: { key: 'hystlab-backbone' }, drag: { x: false, y: false, setScale: false }, points: { show: false } };
    this.plots = FIGURES.map(f => {
      const box = el('div', { class: 'backbone-plot' });
      this.row.append(box);
      return new uPlot({
        ...this.size(), legend: { show: false }, cursor,
        scales: { x: { time: false, distr: 3, log: 10, range: xRange }, y: { range: (u, lo, hi) => padded(lo, hi) } },
        axes: [{ label: 'base amplitude (mm)', space: 30, filter: oneTwoFive }, { label: f.label, size: 60, space: 24 }],
        series: [{}, ...this.series.map(s => this.opts(s))],
        hooks: { setCursor: [u => this.hover(u)] },
      }, this.data(f.key), box);
    });
    this.legendEl.replaceChildren(...this.series.map(s => {
      const o = this.opts(s);
      return el('span', { class: 'item' + (s.which === 'predicted' ? ' predicted' : '') },
        styled(el('span', { class: 'swatch' + (o.dash ? ' dashed' : '') }), { borderTopColor: o.stroke }), s.label);
    }));
  }
  data(key) {
    const at = new Map(this.xs.map((a, i) => [sameAmplitude(a), i]));
    return [this.xs, ...this.series.map(s => {
      const col = new Array(this.xs.length).fill(null);
      for (const b of s.rows) if (Number.isFinite(b[key])) col[at.get(sameAmplitude(b.amplitude_mm))] = b[key];
      return col;
    })];
  }
  hover(u) {
    const i = u.cursor.idx;
    if (i == null || !this.xs.length) return;
    const parts = this.series.map((s, k) => {
      const v = FIGURES.map((f, j) => this.plots[j] && this.plots[j].data[k + 1][i]);
      return v[0] == null ? null : `${s.label}: ${num(v[0], 4)} Hz, T ${num(v[1], 3)}, ζ ${v[2] == null ? '–' : num(v[2], 3)}`;
    }).filter(Boolean);
    this.readout.textContent = `${num(this.xs[i])} mm — ${parts.join(' · ') || 'no resonance'}`;
  }
  // For the tests: what is drawn.
  shown() {
    if (this.box.hidden) return null;
    return { plots: this.plots.length, amplitudes: this.xs.length, series: this.series.map(s => s.label),
      values: Object.fromEntries(FIGURES.map((f, k) => [f.key, this.series.map((s, j) => this.plots[k].data[j + 1])])),
      widths: this.plots.map(u => u.width) };
  }
}

// Log ticks labelled at 1, 2 and 5 of each decade (uPlot's own keep only the 1s: 0.01 alone).
function oneTwoFive(u, splits) {
  return splits.map(v => ([1, 2, 5].includes(Math.round(v / 10 ** Math.floor(Math.log10(v) + 1e-9))) ? v : null));
}

// A linear axis 8 % beyond the values (a flat backbone gets ±5 % of its value).
function padded(lo, hi) {
  if (lo == null || !Number.isFinite(lo)) return [0, 1];
  const span = hi - lo || Math.abs(hi) * 0.1 || 1;
  return [lo - 0.08 * span, hi + 0.08 * span];
}
