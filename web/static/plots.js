// The page's plots, all drawn by uPlot (served from npm's package by the daemon): the
// force-displacement loop and the transmissibility as x-y plots, signals against time, and the
// Preisach triangle as a heatmap drawn in a uPlot plot's own coordinates.
/* global uPlot */

const W = 460, H = 320;

// Range of a set of arrays with a margin; a fallback when empty.
function extent(arrays, fallback) {
  let lo = Infinity, hi = -Infinity;
  for (const a of arrays) for (const v of a) if (Number.isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; }
  if (!(hi >= lo)) return fallback;
  const pad = (hi - lo) * 0.05 || Math.abs(hi) * 0.05 || 1;
  return [lo - pad, hi + pad];
}

// An x-y plot (uPlot's mode 2): series of [xs, ys] drawn as lines in the order given.
export class XYPlot {
  constructor(el, xLabel, yLabel, series) {
    this.el = el; this.series = series;
    this.data = series.map(() => [[], []]);
    this.build(xLabel, yLabel);
  }
  build(xLabel, yLabel) {
    const series = this.series;
    this.labels = [xLabel, yLabel];
    const opts = {
      mode: 2, width: W, height: H, legend: { live: false },
      scales: { x: { time: false, auto: false }, y: { auto: false } },
      axes: [{ label: xLabel }, { label: yLabel }],
      series: [{}, ...series.map(s => ({ label: s.label, stroke: s.color, width: s.width || 1.5, points: { show: !!s.points, size: 5, fill: s.color },
                                         facets: [{ scale: 'x', auto: true }, { scale: 'y', auto: true }] }))],
    };
    this.u = new uPlot(opts, [null, ...this.data], this.el);
  }
  // uPlot draws axis labels once: new labels, new plot.
  relabel(xLabel, yLabel) {
    if (this.labels[0] === xLabel && this.labels[1] === yLabel) return;
    this.u.destroy();
    this.build(xLabel, yLabel);
  }
  set(k, xs, ys) { this.data[k] = [xs, ys]; }
  points(k) { return this.data[k][0].length; }
  // uPlot's x-y mode does not range its scales from the data: we do.
  redraw() {
    const [x0, x1] = extent(this.data.map(d => d[0]), [0, 1]), [y0, y1] = extent(this.data.map(d => d[1]), [0, 1]);
    this.u.batch(() => {
      this.u.setData([null, ...this.data], false);
      this.u.setScale('x', { min: x0, max: x1 });
      this.u.setScale('y', { min: y0, max: y1 });
    });
  }
}

// Signals against time (uPlot's mode 1), two y scales.
export class TimePlot {
  constructor(el, labels) {
    this.el = el;
    this.t = []; this.a = []; this.b = [];
    this.build(labels);
  }
  build(labels) {
    this.labels = labels;
    this.u = new uPlot({
      width: W * 2 + 20, height: 240, legend: { live: false },
      scales: { x: { time: false }, a: {}, b: {} },
      axes: [{ label: 'rig time (s)' }, { scale: 'a', label: labels[0], stroke: '#1565c0' },
             { scale: 'b', side: 1, label: labels[1], stroke: '#c62828', grid: { show: false } }],
      series: [{}, { label: labels[0], scale: 'a', stroke: '#1565c0' }, { label: labels[1], scale: 'b', stroke: '#c62828' }],
    }, [this.t, this.a, this.b], this.el);
  }
  setLabels(labels) {
    if (this.labels[0] === labels[0] && this.labels[1] === labels[1]) return;
    this.u.destroy();
    this.build(labels);
  }
  clear() { this.t = []; this.a = []; this.b = []; }
  push(t, a, b, keep) {
    for (let k = 0; k < t.length; k++) {
      if (this.t.length && t[k] < this.t[this.t.length - 1]) this.clear();  // a new run: its clock restarts
      this.t.push(t[k]); this.a.push(a[k]); this.b.push(b[k]);
    }
    if (this.t.length > keep) { const d = this.t.length - keep; this.t.splice(0, d); this.a.splice(0, d); this.b.splice(0, d); }
  }
  redraw() { this.u.setData([this.t, this.a, this.b]); }
}

// A blue-to-yellow scale (viridis endpoints, interpolated through three stops).
function colour(v) {
  const stops = [[68, 1, 84], [33, 145, 140], [253, 231, 37]];
  const x = Math.min(1, Math.max(0, v)) * 2, k = Math.min(1, Math.floor(x)), f = x - k;
  const c = stops[k].map((s, i) => Math.round(s + (stops[k + 1][i] - s) * f));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

// The Preisach triangle: one square per node (δ_j, δ_i), j ≤ i, coloured by F(δ_i, δ_j);
// nodes not yet identified are grey with a cross. α up, β across (the paper's Fig. 13).
export class TriangleHeatmap {
  constructor(el) {
    this.grid = null;      // {n, lo_mm, hi_mm}
    this.values = new Map(); // "i,j" -> F
    const self = this;
    this.u = new uPlot({
      width: W, height: H, legend: { show: false }, cursor: { show: false },
      scales: { x: { time: false, auto: false }, y: { auto: false } },
      axes: [{ label: 'β (mm)' }, { label: 'α (mm)' }],
      series: [{}, { stroke: 'transparent' }],
      hooks: { draw: [u => self.draw(u)] },
    }, [[0, 1], [null, null]], el);
  }
  range() {
    if (!this.grid) return [0, 1];
    const h = (this.grid.hi_mm - this.grid.lo_mm) / this.grid.n;
    return [this.grid.lo_mm - h / 2, this.grid.hi_mm + h / 2];
  }
  // The grid of a campaign, with the nodes measured so far (they replace what was shown).
  setGrid(grid) {
    this.grid = grid;
    this.values.clear();
    this.u.setData([[grid ? grid.lo_mm : 0, grid ? grid.hi_mm : 1], [null, null]]);
  }
  node(i) { return this.grid.lo_mm + (this.grid.hi_mm - this.grid.lo_mm) * i / this.grid.n; }
  // A measured node: its (α, β) snapped to the grid.
  add(alpha, beta, F) {
    if (!this.grid) return;
    const h = (this.grid.hi_mm - this.grid.lo_mm) / this.grid.n;
    const i = Math.round((alpha - this.grid.lo_mm) / h), j = Math.round((beta - this.grid.lo_mm) / h);
    if (i < 1 || i > this.grid.n || j < 0 || j >= i) return;
    this.values.set(`${i},${j}`, F);
  }
  identified() { return this.values.size; }
  required() { return this.grid ? this.grid.n * (this.grid.n + 1) / 2 : 0; }
  redraw() {
    const [lo, hi] = this.range();
    this.u.batch(() => { this.u.setScale('x', { min: lo, max: hi }); this.u.setScale('y', { min: lo, max: hi }); });
    this.u.redraw();
  }
  draw(u) {
    if (!this.grid) return;
    const ctx = u.ctx, n = this.grid.n, h = (this.grid.hi_mm - this.grid.lo_mm) / n;
    let fmax = 0;
    for (const v of this.values.values()) fmax = Math.max(fmax, Math.abs(v));
    ctx.save();
    for (let i = 0; i <= n; i++) {
      for (let j = 0; j <= i; j++) {
        const a = this.node(i), b = this.node(j);
        const x0 = u.valToPos(b - h / 2, 'x', true), x1 = u.valToPos(b + h / 2, 'x', true);
        const y0 = u.valToPos(a + h / 2, 'y', true), y1 = u.valToPos(a - h / 2, 'y', true);
        const key = `${i},${j}`;
        const known = i === j || this.values.has(key);  // F(δ_i, δ_i) = 0 by definition
        ctx.fillStyle = known ? colour(i === j ? 0 : this.values.get(key) / (fmax || 1)) : '#cfd8dc';
        ctx.fillRect(x0, y0, x1 - x0 - 1, y1 - y0 - 1);
        if (!known) {
          ctx.strokeStyle = '#90a4ae';
          ctx.beginPath(); ctx.moveTo(x0 + 3, y0 + 3); ctx.lineTo(x1 - 4, y1 - 4); ctx.moveTo(x1 - 4, y0 + 3); ctx.lineTo(x0 + 3, y1 - 4); ctx.stroke();
        }
      }
    }
    ctx.restore();
  }
}
