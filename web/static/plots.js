// The page's plots, all drawn by uPlot (served from npm's package by the daemon): the
// force-displacement loop and the transmissibility as x-y plots, signals against time, and the
// Preisach triangle as a heatmap drawn in a uPlot plot's own coordinates. Every plot takes its
// width from its container and follows it (ResizeObserver), so a wide screen is used.
/* global uPlot */
import { num, round2 } from './fmt.js';

// Range of a set of arrays with a margin; a fallback when empty.
function extent(arrays, fallback) {
  let lo = Infinity, hi = -Infinity;
  for (const a of arrays) for (const v of a) if (Number.isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; }
  if (!(hi >= lo)) return fallback;
  const pad = (hi - lo) * 0.05 || Math.abs(hi) * 0.05 || 1;
  return [lo - pad, hi + pad];
}

// Calls fn(width) when the element's width changes (not its height: that is ours to set), and
// when the window's height does (the plots' heights follow the screen's: screenShare).
const sized = [];  // every plot's resize, for relayout()
export function onWidth(el, fn) {
  let last = 0;
  new ResizeObserver(entries => {
    const w = Math.floor(entries[0].contentRect.width);
    if (w > 0 && Math.abs(w - last) >= 2) { last = w; fn(w); }
  }).observe(el);
  let lastH = window.innerHeight;
  window.addEventListener('resize', () => { if (window.innerHeight !== lastH && last > 0) { lastH = window.innerHeight; fn(last); } });
  sized.push(() => { if (last > 0) fn(last); });
}
// What is above the plots changed (the warning box came or went): every plot sized again.
export function relayout() { for (const f of sized) f(); }

// Where the loop and the heatmap stand side by side (style.css: .plots from 1200 px), the work
// view is the loop, the heatmap and the time plot together on one screen: each plot's height is
// its share of what the sticky header leaves, less its caption, legend and the gaps (~190 px in
// all, measured at 1280x800). Narrower, the plots are stacked and keep their own aspect.
const SIDE_BY_SIDE = '(min-width: 1200px)';
const CHROME_PX = 190;
export function screenShare(share) {
  if (!window.matchMedia(SIDE_BY_SIDE).matches) return Infinity;
  const top = document.getElementById('top'), warn = document.getElementById('warnings');
  const above = (top ? top.offsetHeight : 0) + (warn && !warn.hidden ? warn.offsetHeight + 10 : 0);  // the warning box, when shown, is above them
  return Math.max(0, (window.innerHeight - above - CHROME_PX) * share);
}
export const LOOP_SHARE = 0.62, TIME_SHARE = 0.38;

// The x-y path in sample order, through every point. uPlot's own path builders thin points
// per pixel column assuming x only increases; a hysteresis loop goes back and forth in x, so
// they dropped the unloading branches. A break (NaN) lifts the pen.
function inOrder(u, si) {
  const [xs, ys] = u.data[si];
  const p = new Path2D();
  let pen = false;
  for (let i = 0; i < xs.length; i++) {
    const x = xs[i], y = ys[i];
    if (!Number.isFinite(x) || !Number.isFinite(y)) { pen = false; continue; }
    const px = u.valToPos(x, 'x', true), py = u.valToPos(y, 'y', true);
    if (pen) p.lineTo(px, py); else { p.moveTo(px, py); pen = true; }
  }
  return { stroke: p, fill: null, clip: null, band: null, gaps: null, flags: 0 };
}

// Ticks as numbers with the decimals their spacing needs.
export function tickLabels(u, splits) {
  const step = splits.length > 1 ? Math.abs(splits[1] - splits[0]) : 1;
  let decimals = 0;  // the fewest that write the step exactly (0.25: 2, 0.5: 1, 50: 0)
  while (decimals < 8 && step > 0 && Math.abs(Math.round(step * 10 ** decimals) - step * 10 ** decimals) > 1e-6 * step * 10 ** decimals) decimals++;
  return splits.map(v => (v == null ? '' : Number(v.toFixed(decimals)).toLocaleString('en', { minimumFractionDigits: decimals, maximumFractionDigits: decimals })));
}
// The y axis's width: its longest tick label, the gap and its title (px).
export function axisSize(u, values) {
  const longest = (values || []).reduce((m, v) => Math.max(m, String(v).length), 0);
  return Math.max(50, Math.ceil(longest * 7.5) + 30);
}

// An x-y plot (uPlot's mode 2): series of [xs, ys] drawn as paths in the order given.
export class XYPlot {
  constructor(el, xLabel, yLabel, series, { aspect = 0.62, maxHeight = 640, minHeight = 240, share = null } = {}) {
    this.el = el; this.series = series; this.aspect = aspect; this.maxHeight = maxHeight; this.minHeight = minHeight; this.share = share;
    this.data = series.map(() => [[], []]);
    this.build(xLabel, yLabel);
    onWidth(el, w => this.u.setSize(this.size(w)));
  }
  size(w = this.el.clientWidth) {
    const width = Math.max(200, w);
    const fit = this.share ? screenShare(this.share) : Infinity;
    return { width, height: Math.round(Math.min(this.maxHeight, Math.max(this.minHeight, Math.min(width * this.aspect, fit)))) };
  }
  build(xLabel, yLabel) {
    this.labels = [xLabel, yLabel];
    const opts = {
      mode: 2, ...this.size(), legend: { live: false },
      // No drag-zoom: the scales are ours (redraw), a zoom would be undone by the next sample.
      cursor: { drag: { x: false, y: false, setScale: false }, points: { show: false } },
      scales: { x: { time: false, auto: false }, y: { auto: false } },
      // Tick labels with as many decimals as their spacing needs (never "0.01, 0.01, 0.00" on a
      // 0.005 mm sine), and a y axis as wide as its longest label (the title never over them).
      axes: [{ label: xLabel, values: tickLabels }, { label: yLabel, values: tickLabels, size: axisSize }],
      series: [{}, ...this.series.map(s => ({
        label: s.label, stroke: s.color, width: s.width || 1.5, paths: s.points ? undefined : inOrder,
        points: { show: !!s.points, size: 5, fill: s.color },
        facets: [{ scale: 'x', auto: false }, { scale: 'y', auto: false }],
      }))],
      // A legend click hides that series only; the scales stay those of all the data, so the
      // other series is drawn as before (uPlot re-ranged from the hidden one, blanking it).
      hooks: { setSeries: [() => this.redraw()] },
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
  ticks() { return this.u.axes.map(a => (a._values || []).map(String)); }  // what the axes say (for the tests)
  // Series k offered (its legend entry shown) or not.
  offer(k, on) {  // (by its label: an x-y plot's legend has no row for x)
    const item = [...this.u.root.querySelectorAll('.u-legend .u-series')].find(e => e.textContent.trim() === this.series[k].label);
    if (item) item.style.display = on ? '' : 'none';
  }
  append(k, xs, ys) { const d = this.data[k]; for (let i = 0; i < xs.length; i++) { d[0].push(xs[i]); d[1].push(ys[i]); } }
  // Keep the newest `keep` points of series k (a live loop must not grow without end).
  trim(k, keep) { const d = this.data[k]; if (d[0].length > keep) { const n = d[0].length - keep; d[0].splice(0, n); d[1].splice(0, n); } }
  points(k) { return this.data[k][0].length; }
  path(k) { return { x: this.data[k][0].slice(), y: this.data[k][1].slice() }; }
  // uPlot's x-y mode does not range its scales from the data: we do, over every series.
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
    onWidth(el, w => this.u.setSize(this.size(w)));
  }
  size(w = this.el.clientWidth) { return { width: Math.max(200, w), height: Math.round(Math.max(150, Math.min(260, screenShare(TIME_SHARE)))) }; }
  build(labels) {
    this.labels = labels;
    this.u = new uPlot({
      ...this.size(), legend: { live: false },
      scales: { x: { time: false }, a: {}, b: {} },
      axes: [{ label: 'rig time (s)', values: tickLabels }, { scale: 'a', label: labels[0], stroke: '#1565c0', values: tickLabels, size: axisSize },
             { scale: 'b', side: 1, label: labels[1], stroke: '#c62828', grid: { show: false }, values: tickLabels, size: axisSize }],
      series: [{}, { label: labels[0], scale: 'a', stroke: '#1565c0' }, { label: labels[1], scale: 'b', stroke: '#c62828' }],
    }, [this.t, this.a, this.b], this.el);
  }
  // For the tests: its y axes (two: displacement and force) and what is drawn.
  axes() { return { yAxes: this.u.axes.filter(a => a.scale !== 'x').length, label: this.labels.join(' / '), legend: this.labels.slice(), points: this.t.length }; }
  clear() { this.t = []; this.a = []; this.b = []; }
  push(t, a, b, keep) {
    for (let k = 0; k < t.length; k++) {
      if (this.t.length && t[k] < this.t[this.t.length - 1]) this.clear();  // a new run: its clock restarts
      this.t.push(t[k]); this.a.push(a[k]); this.b.push(b[k]);
    }
    if (this.t.length > keep) { const d = this.t.length - keep; this.t.splice(0, d); this.a.splice(0, d); this.b.splice(0, d); }
  }
  // The server's history: the min and the max of each bucket. Both are drawn, as a zig-zag
  // (min at the bucket's start, max at its end), so no peak is lost to the decimation.
  setBuckets(s, aMin, aMax, bMin, bMax) {
    this.clear();
    for (let k = 0; k < s.buckets; k++) {
      this.t.push(s.t_min[k], s.t_max[k] > s.t_min[k] ? s.t_max[k] : s.t_min[k] + 1e-9);
      this.a.push(aMin[k], aMax[k]); this.b.push(bMin[k], bMax[k]);
    }
  }
  redraw() { this.u.setData([this.t, this.a, this.b]); }
}

// Viridis through five stops: readable in grey too.
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
export function colour(v) {
  const x = Math.min(1, Math.max(0, v)) * (VIRIDIS.length - 1), k = Math.min(VIRIDIS.length - 2, Math.floor(x)), f = x - k;
  const c = VIRIDIS[k].map((s, i) => Math.round(s + (VIRIDIS[k + 1][i] - s) * f));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}
// The next "round" number at or above v (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k).
function niceUp(v) {
  if (!(v > 0)) return 1;
  const p = 10 ** Math.floor(Math.log10(v));
  for (const m of [1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10]) if (m * p >= v * (1 - 1e-9)) return m * p;
  return 10 * p;
}

// The Preisach triangle: one square per node (δ_j, δ_i), j ≤ i, coloured by F(δ_i, δ_j);
// nodes not yet identified are grey with a cross. α up, β across (the paper's Fig. 13).
// The colour limits are fixed by the first nodes and only ever extend (to a round number), so
// the colours of the nodes already drawn do not shift as each new node arrives.
export class TriangleHeatmap {
  constructor(el) {
    this.grid = null;        // {n, lo_mm, hi_mm, nodes_mm (a grid of its own, when given)}
    this.values = new Map(); // "i,j" -> F
    this.lim = null;         // [lo, hi] of the colour scale (N)
    this.el = el;
    const plotEl = document.createElement('div');
    this.scaleEl = document.createElement('div'); this.scaleEl.className = 'colour-scale';
    this.readout = document.createElement('div'); this.readout.className = 'readout';
    this.readout.textContent = 'hover over a cell for its α, β and F';
    el.append(plotEl, this.scaleEl, this.readout);
    const self = this;
    this.u = new uPlot({
      ...this.size(), legend: { show: false },
      cursor: { x: false, y: false, points: { show: false }, drag: { x: false, y: false, setScale: false } },
      scales: { x: { time: false, auto: false }, y: { auto: false } },
      axes: [{ label: 'β (mm)' }, { label: 'α (mm)' }],
      series: [{}, { stroke: 'transparent' }],
      hooks: { draw: [u => self.draw(u)], setCursor: [u => self.hover(u)] },
    }, [[0, 1], [null, null]], plotEl);
    onWidth(el, w => this.u.setSize(this.size(w)));
    this.drawScale();
  }
  size(w = this.el.clientWidth) {
    const width = Math.max(200, w);
    return { width, height: Math.round(Math.min(560, Math.max(200, Math.min(width * 0.75, screenShare(LOOP_SHARE) - 40)))) };  // 40: its scale and read-out
  }
  range() {
    if (!this.grid) return [0, 1];
    return [this.lower(0), this.upper(this.grid.n)];
  }
  // Node i's square runs from halfway to its lower neighbour to halfway to its upper one (at the
  // ends, half its one cell): equal squares on a uniform grid, smaller where a grid is refined.
  lower(i) { return i > 0 ? (this.node(i - 1) + this.node(i)) / 2 : this.node(0) - (this.node(1) - this.node(0)) / 2; }
  upper(i) { const n = this.grid.n; return i < n ? (this.node(i) + this.node(i + 1)) / 2 : this.node(n) + (this.node(n) - this.node(n - 1)) / 2; }
  // The nearest node's index to x.
  nearest(x) {
    let best = 0;
    for (let i = 1; i <= this.grid.n; i++) if (Math.abs(this.node(i) - x) < Math.abs(this.node(best) - x)) best = i;
    return best;
  }
  // The grid of a campaign, with the nodes measured so far (they replace what was shown).
  setGrid(grid) {
    this.grid = grid;
    this.values.clear();
    this.lim = null;
    this.u.setData([[grid ? grid.lo_mm : 0, grid ? grid.hi_mm : 1], [null, null]]);
    this.drawScale();
  }
  node(i) {
    const g = this.grid;
    return Array.isArray(g.nodes_mm) && g.nodes_mm.length === g.n + 1 ? g.nodes_mm[i] : g.lo_mm + (g.hi_mm - g.lo_mm) * i / g.n;
  }
  // A measured node on the grid (an adaptive campaign measures between its rows too: those wait
  // for a row there, when the grid is set again).
  add(alpha, beta, F) {
    if (!this.grid) return;
    const i = this.nearest(alpha), j = this.nearest(beta), tol = 1e-6 * (this.grid.hi_mm - this.grid.lo_mm);
    if (i < 1 || i > this.grid.n || j < 0 || j >= i) return;
    if (Math.abs(this.node(i) - alpha) > tol || Math.abs(this.node(j) - beta) > tol) return;
    this.values.set(`${i},${j}`, F);
    this.extend(F);
  }
  extend(F) {
    if (!Number.isFinite(F)) return;
    if (!this.lim) {
      // The first node sets the scale, with head room: F grows with α − β.
      this.lim = [F < 0 ? -niceUp(-F * 1.25) : 0, F > 0 ? niceUp(F * 1.25) : 1];
    } else if (F > this.lim[1]) this.lim[1] = niceUp(F * 1.25);
    else if (F < this.lim[0]) this.lim[0] = -niceUp(-F * 1.25);
    else return;
    this.drawScale();
  }
  // Once every node is known (a stored campaign, an ended one): the scale fitted to the cells
  // (0 is in it: the diagonal's F), without the head room kept while nodes arrive.
  fitScale() {
    let lo = 0, hi = -Infinity;
    for (const F of this.values.values()) if (Number.isFinite(F)) { lo = Math.min(lo, F); hi = Math.max(hi, F); }
    if (!(hi > 0)) return;
    const up2 = v => { const p = 10 ** (Math.floor(Math.log10(v)) - 1); return Math.ceil(v / p - 1e-9) * p; };  // 157 -> 160
    const lim = [lo < 0 ? -up2(-lo) : 0, up2(hi)];
    if (this.lim && lim[0] === this.lim[0] && lim[1] === this.lim[1]) return;
    this.lim = lim;
    this.drawScale();
    this.u.redraw();
  }
  identified() { return this.values.size; }
  required() { return this.grid ? this.grid.n * (this.grid.n + 1) / 2 : 0; }
  limits() { return this.lim ? this.lim.slice() : null; }
  redraw() {
    const [lo, hi] = this.range();
    this.u.batch(() => { this.u.setScale('x', { min: lo, max: hi }); this.u.setScale('y', { min: lo, max: hi }); });
    this.u.redraw();
  }
  // The legend bar under the plot: the gradient with its limits in N, and what grey means.
  drawScale() {
    const lim = this.lim || [0, 1];
    const bar = document.createElement('span'); bar.className = 'bar';
    bar.style.background = `linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map(colour).join(', ')})`;
    const lo = document.createElement('span'); lo.textContent = this.lim ? `${round2(lim[0])} N` : '';
    const hi = document.createElement('span'); hi.textContent = this.lim ? `${round2(lim[1])} N` : '';
    const label = document.createElement('span'); label.textContent = 'F';
    const none = document.createElement('span'); none.className = 'untouched'; none.textContent = 'not measured yet';
    this.scaleEl.replaceChildren(label, lo, bar, hi, none);
  }
  // The cell under the pointer, read out below the plot.
  hover(u) {
    if (!this.grid || u.cursor.left == null || u.cursor.left < 0) return;
    const b = u.posToVal(u.cursor.left, 'x'), a = u.posToVal(u.cursor.top, 'y');
    const [lo, hi] = this.range();
    const i = this.nearest(a), j = this.nearest(b);
    if (a < lo || a > hi || b < lo || b > hi || j > i) { this.readout.textContent = 'hover over a cell for its α, β and F'; return; }
    const where = `α = ${num(this.node(i))} mm, β = ${num(this.node(j))} mm`;
    const F = i === j ? 0 : this.values.get(`${i},${j}`);
    this.readout.textContent = F === undefined ? `${where}: not measured yet` : `${where}: F = ${round2(F)} N${i === j ? ' (zero on the diagonal)' : ''}`;
  }
  draw(u) {
    if (!this.grid) return;
    const ctx = u.ctx, n = this.grid.n;
    const [flo, fhi] = this.lim || [0, 1];
    ctx.save();
    for (let i = 0; i <= n; i++) {
      for (let j = 0; j <= i; j++) {
        const x0 = u.valToPos(this.lower(j), 'x', true), x1 = u.valToPos(this.upper(j), 'x', true);
        const y0 = u.valToPos(this.upper(i), 'y', true), y1 = u.valToPos(this.lower(i), 'y', true);
        const key = `${i},${j}`;
        const known = i === j || this.values.has(key);  // F(δ_i, δ_i) = 0 by definition
        const F = i === j ? 0 : this.values.get(key);
        ctx.fillStyle = known ? colour((F - flo) / (fhi - flo || 1)) : '#cfd8dc';
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
