// An adaptive FOT campaign's design (issue 41), beside the Preisach triangle: the table's
// estimated held-out error against rig time after every row, and each row the daemon chose with
// why (which term of which band), or why the design stopped. GET /api/campaigns/ID: design.
/* global uPlot */
import { el, num, round2 } from './fmt.js';
import { tickLabels, axisSize, onWidth } from './plots.js';

export class DesignPanel {
  constructor(fig, caption, plotBox, list) {
    Object.assign(this, { fig, caption, list });
    this.data = [[], []];
    this.u = new uPlot({
      width: Math.max(200, plotBox.clientWidth), height: 200, legend: { show: false },
      scales: { x: { time: false }, y: { range: (u, lo, hi) => [0, hi > 0 ? hi * 1.05 : 1] } },
      axes: [{ label: 'rig time (s)' }, { label: 'est. held-out RMS (N)', values: tickLabels, size: axisSize }],
      series: [{}, { stroke: '#1565c0', width: 2, points: { show: true, size: 6 } }],
    }, this.data, plotBox);
    onWidth(plotBox, w => this.u.setSize({ width: Math.max(200, w), height: 200 }));
  }
  // design: {budget_s, target_rms_N, steps: [design events]} or absent (not an adaptive campaign).
  show(design) {
    const steps = design && Array.isArray(design.steps) ? design.steps : [];
    this.fig.hidden = !design;
    if (!design) return;
    this.data = [steps.map(s => s.rig_s), steps.map(s => s.estimated_rms_N)];
    this.u.setData(this.data);
    const last = steps[steps.length - 1];
    const target = design.target_rms_N > 0 ? `, target ${round2(design.target_rms_N)} N` : '';
    this.caption.textContent = !last ? `Adaptive design: the coarse rows first (budget ${num(design.budget_s)} s${target})`
      : `Adaptive design: ${last.rows} rows, estimated held-out RMS ${round2(last.estimated_rms_N)} N (noise ${round2(last.noise_N)} N), ` +
        `${num(last.spent_s)} of ${num(design.budget_s)} s${target}` + (last.stopped ? ' — stopped' : '');
    const items = steps.filter(s => !s.stopped).map(s => el('li', { text: `${num(s.alpha_mm)} mm: ${s.why}` }));
    if (last && last.stopped) items.push(el('li', { class: 'stopped', text: `stopped: ${last.stopped}` }));
    this.list.replaceChildren(...items);
  }
  points() { return this.data[0].length; }  // for the tests
  rows() { return this.list.querySelectorAll('li').length; }
}
