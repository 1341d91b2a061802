// A shaker's signals against time: base and mass displacement on ONE axis (they are the same
// quantity; two scales would make a transmissibility of 1 look like anything), or the mass's
// acceleration in g (live only: the stored run's summary holds displacements).
// No aliased trace: where a cycle of the drive frequency has fewer than 20 samples of what the
// stream brings, each cycle is drawn as its min–max band instead of a line through the samples;
// the stored run (from GET /api/runs/ID/samples, min and max per bucket) is such a band too.
/* global uPlot */
import { el, num } from './fmt.js';
import { onWidth } from './plots.js';
import { styled } from './sweep_plots.js';

const WINDOW_S = 10;              // live: the newest 10 s of rig time
const MIN_POINTS_PER_CYCLE = 20;  // fewer: the cycle's envelope instead of the trace
const G = 9.80665;
const BASE = '#1565c0', MASS = '#c62828';
const HEIGHT = 280;

export class ShakerTimePlot {
  constructor(box) {
    this.box = box; this.mode = 'disp';
    this.plotEl = el('div');
    this.legendEl = el('div', { class: 'sweep-legend' });
    box.append(this.plotEl, this.legendEl);
    this.clear();
    this.build();
    onWidth(box, w => this.u.setSize({ width: Math.max(200, w), height: HEIGHT }));
  }
  clear() {
    this.raw = { t: [], base: [], mass: [], acc: [] };
    this.hist = null;
    this.steps = [];   // [{t, f}]: the drive frequency from rig time t on
    this.rate = null;  // samples per second of rig time the stream brings
  }
  build() {
    if (this.u) this.u.destroy();
    const band = (stroke, label) => ({ label, stroke, width: 0.8, spanGaps: false, points: { show: false } });
    this.u = new uPlot({
      width: Math.max(200, this.box.clientWidth), height: HEIGHT, legend: { show: false },
      cursor: { drag: { x: true, y: false, setScale: false }, points: { show: false } },
      scales: { x: { time: false } },
      axes: [{ label: 'rig time (s)' }, { label: this.mode === 'accel' ? 'mass acceleration (g)' : 'displacement (mm)', size: 70 }],
      series: [{}, { label: 'base', stroke: BASE, width: 1.2, points: { show: false } }, { label: 'mass', stroke: MASS, width: 1.2, points: { show: false } },
        band(BASE, 'base max'), band(BASE, 'base min'), band(MASS, 'mass max'), band(MASS, 'mass min')],
      bands: [{ series: [3, 4], fill: 'rgba(21,101,192,0.25)' }, { series: [5, 6], fill: 'rgba(198,40,40,0.22)' }],
    }, this.data(), this.plotEl);
    this.drawLegend();
  }
  setMode(mode) { if (mode !== this.mode) { this.mode = mode; this.build(); } }

  // The step's drive frequency, from the newest sample on (sine_step events).
  setFrequency(f) {
    if (!(f > 0)) return;
    const t = this.raw.t.length ? this.raw.t[this.raw.t.length - 1] : -Infinity;
    const last = this.steps[this.steps.length - 1];
    if (!last || last.f !== f) this.steps.push({ t, f });
  }
  // Live samples (the stream's `t`, `cmd` = base, `disp` = mass, `force` = mass acceleration).
  push(t, base, mass, acc) {
    let r = this.raw;
    for (let k = 0; k < t.length; k++) {
      if (r.t.length && t[k] < r.t[r.t.length - 1]) { this.clear(); r = this.raw; }  // a new run: its clock restarts
      r.t.push(t[k]); r.base.push(base[k]); r.mass.push(mass[k]); r.acc.push(acc[k]);
    }
    // The median step: a hole in the samples must not pass for a lower rate.
    if (t.length > 2) { const dt = t.slice(1).map((v, k) => v - t[k]).sort((a, b) => a - b)[t.length >> 1]; if (dt > 0) this.rate = 1 / dt; }
    const from = r.t[r.t.length - 1] - WINDOW_S;
    let drop = 0;
    while (drop < r.t.length && r.t[drop] < from) drop++;
    if (drop > 0) for (const a of Object.values(r)) a.splice(0, drop);
    while (this.steps.length > 1 && this.steps[1].t <= from) this.steps.shift();
  }
  // The stored run, min and max per bucket (GET /api/runs/ID/samples).
  setHistory(s) {
    this.hist = s && s.buckets ? s : null;
  }
  frequencyAt(t) {
    let f = null;
    for (const s of this.steps) if (s.t <= t) f = s.f; else break;
    return f == null && this.steps.length ? this.steps[0].f : f;
  }
  // Too few samples a cycle at this frequency for a trace?
  coarse(f) { return f > 0 && this.rate > 0 && this.rate / f < MIN_POINTS_PER_CYCLE; }

  data() {
    const cols = [[], [], [], [], [], [], []];
    const add = (...v) => v.forEach((x, k) => cols[k].push(x));
    const accel = this.mode === 'accel', r = this.raw;
    const newest = r.t.length ? r.t[r.t.length - 1] : null;
    this.enveloped = 0;  // live cycles drawn as their envelope
    this.stored = 0;     // buckets of the stored run drawn
    const h = this.hist;
    if (h && !accel) {
      for (let k = 0; k < h.buckets; k++) {
        if (newest != null && (h.t_max[k] < newest - WINDOW_S || h.t_min[k] >= r.t[0])) continue;  // live: the window only
        const t1 = h.t_max[k] > h.t_min[k] ? h.t_max[k] : h.t_min[k] + 1e-9;
        const v = [h.base_displacement_max_mm[k], h.base_displacement_min_mm[k], h.mass_displacement_max_mm[k], h.mass_displacement_min_mm[k]];
        add(h.t_min[k], null, null, ...v); add(t1, null, null, ...v);
        this.stored++;
      }
      if (cols[0].length && r.t.length) add(cols[0][cols[0].length - 1], null, null, null, null, null, null);  // lifts the pen before the live part
    }
    const mass = accel ? r.acc.map(a => a / G) : r.mass, base = accel ? r.acc.map(() => null) : r.base;
    for (let i = 0; i < r.t.length;) {
      const f = this.frequencyAt(r.t[i]);
      if (!this.coarse(f)) { add(r.t[i], base[i], mass[i], null, null, null, null); i++; continue; }
      // One cycle of the drive frequency: its min and max, at its first and last sample.
      this.enveloped++;
      const cycle = Math.floor(r.t[i] * f);
      let j = i, bl = Infinity, bh = -Infinity, ml = Infinity, mh = -Infinity;
      for (; j < r.t.length && Math.floor(r.t[j] * f) === cycle; j++) {
        if (!accel) { bl = Math.min(bl, base[j]); bh = Math.max(bh, base[j]); }
        ml = Math.min(ml, mass[j]); mh = Math.max(mh, mass[j]);
      }
      const b = accel ? [null, null] : [bh, bl];
      add(r.t[i], null, null, ...b, mh, ml); add(r.t[j - 1], null, null, ...b, mh, ml);
      i = j;
    }
    return cols;
  }
  redraw() {
    this.u.setData(this.data());
    const key = `${this.mode}:${this.stored > 0}:${this.enveloped > 0}:${this.enveloped ? Math.round(this.rate) : ''}`;
    if (key !== this.legendKey) { this.legendKey = key; this.drawLegend(); }
  }
  drawLegend() {
    const item = (color, text) => el('span', { class: 'item' }, styled(el('span', { class: 'swatch' }), { borderTopColor: color }), text);
    const notes = [];
    if (this.stored) notes.push('stored run: min–max per bucket');
    if (this.enveloped) notes.push(`min–max per cycle where a cycle has fewer than ${MIN_POINTS_PER_CYCLE} samples (${num(this.rate)} samples/s live)`);
    if (this.mode === 'accel') notes.push('live samples only');
    this.legendEl.replaceChildren(...(this.mode === 'accel' ? [] : [item(BASE, 'base')]), item(MASS, 'mass'),
      ...notes.map(n => el('span', { class: 'muted', text: n })));
  }
  // For the tests: the axes and what is drawn.
  axes() {
    const u = this.u, d = u.data;
    const filled = k => d[k].filter(v => v != null).length;
    return { yAxes: u.axes.filter(a => a.scale !== 'x').length, label: u.axes[1].label, mode: this.mode,
             legend: [...this.legendEl.querySelectorAll('.item')].map(e => e.textContent),
             trace: filled(1) + filled(2), envelope: filled(3) + filled(5), liveCycles: this.enveloped, points: d[0].length };
  }
}
