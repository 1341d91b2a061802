// What an identification campaign says about its tables and its specimen: each table's error on
// its own samples and on the validation run (held out: no table was built from it), the table the
// campaign recommends and why, the shakedown curve of training (each cycle's dissipated energy
// and peak force), and the figures of every closed cycle (GET /api/campaigns/ID/loops).
/* global uPlot */
import { el, num, round2, count } from './fmt.js';
import { tickLabels, axisSize } from './plots.js';

const accuracyLine = a => `RMS ${round2(a.rms_N)} N (${num(100 * a.rms_norm, 2)} % of range) · max ${round2(a.max_N)} N`;

// One block per table: own samples, held-out, recommended.
export function tableLines(d) {
  const out = [];
  if (d.fit && d.fit.accuracy && !d.tables.length)
    out.push(el('div', { text: `partial table (${d.fit.nodes}/${d.fit.required} nodes, samples so far): ${accuracyLine(d.fit.accuracy.overall)}` }));
  for (const t of d.tables) {
    const a = t.accuracy || {};
    if (!a.overall) continue;
    const held = a.held_out && a.held_out.overall;
    out.push(el('div', { class: 'table-line' + (a.recommended ? ' recommended' : ''), 'data-table': t.id },
      el('strong', { text: `table #${t.id} (${t.method}, n = ${t.n})` }),
      a.recommended ? el('span', { class: 'badge', text: 'recommended' }) : null,
      // A least-squares table's prior as a field of its own, the reason in its tooltip.
      t.prior ? el('div', { class: 'prior', title: t.prior_reason || '', text: `prior: ${t.prior}` + (t.lambda != null ? ` · λ ${num(t.lambda)}` : '') +
        ' (chosen on held-out blocks of the record)' }) : null,
      el('div', { class: 'muted', text: `own samples: ${accuracyLine(a.overall)}` }),
      held ? el('div', { class: 'heldout', text: `held-out (validation run): ${accuracyLine(held)}` +
        (a.held_out.loop_energy_rel_error != null ? ` · loop energy ${num(100 * a.held_out.loop_energy_rel_error, 2)} %` : '') }) : null));
  }
  if (d.recommendation && d.recommendation.why) out.push(el('p', { class: 'why', text: `Recommended: table #${d.recommendation.table}: ${d.recommendation.why}.` }));
  if (d.training && d.training.why) out.push(el('p', { class: 'why', text: `Training: ${d.training.why}.` }));
  return out;
}

// Training's shakedown curve: energy per cycle (left axis) and peak force (right), cycle by cycle.
export class ShakedownPlot {
  constructor(box) {
    this.box = box;
    this.x = []; this.e = []; this.p = [];
    this.u = new uPlot({
      width: Math.max(200, box.clientWidth), height: 240, legend: { live: false },
      scales: { x: { time: false }, e: {}, p: {} },
      // Whole cycles only on x (no "1.5"); each y axis as wide as its labels, so titles never overlap them.
      axes: [{ label: 'training cycle', incrs: [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000], values: (u, s) => s.map(v => String(Math.round(v))) },
             { scale: 'e', label: 'dissipated energy (N·mm)', stroke: '#2e7d32', values: tickLabels, size: axisSize },
             { scale: 'p', side: 1, label: 'peak force (N)', stroke: '#c62828', grid: { show: false }, values: tickLabels, size: axisSize }],
      series: [{}, { label: 'energy', scale: 'e', stroke: '#2e7d32', width: 2, points: { show: true, size: 6 } },
               { label: 'peak force', scale: 'p', stroke: '#c62828', width: 1.5, points: { show: true, size: 5 } }],
    }, [this.x, this.e, this.p], box);
    new ResizeObserver(en => { const w = Math.floor(en[0].contentRect.width); if (w > 0) this.u.setSize({ width: w, height: 240 }); }).observe(box);
  }
  set(cycles) {
    this.x = cycles.map(c => c.cycle); this.e = cycles.map(c => c.energy_Nmm); this.p = cycles.map(c => c.peak_force_N);
    this.u.setData([this.x, this.e, this.p]);
  }
  points() { return this.x.length; }
  ticks() { return (this.u.axes[0]._values || []).map(String); }  // what the cycle axis says (for the tests)
}

export function shakedownCaption(d) {
  const c = d.shakedown || [];
  if (!c.length) return 'Training';
  const last = c[c.length - 1];
  const change = last.energy_change_pct != null ? `, last change ${num(last.energy_change_pct, 2)} % energy, ${num(last.peak_change_pct, 2)} % peak force` : '';
  const outcome = !d.training ? ' — in progress' : !d.training.until ? ' — as planned' : d.training.stable ? ' — settled' : ' — did not settle';
  return `Training: ${count(c.length)} cycle${c.length > 1 ? 's' : ''}${change}${outcome}`;
}

const point = p => (p ? `${num(p.displacement_mm)} mm, ${round2(p.force_N)} N` : '–');

// The figures of every closed cycle, one row each, grouped by where it was taken.
export function loopRows(loops) {
  const head = el('tr', {}, ...['phase', '#', 'δ range (mm)', 'peak (N)', 'E_d (N·mm)', 'k_sec (N/mm)', 'ζ', 'return (N)', 'residual (mm)', 'Ms', 'Mf', 'As', 'Af', 'plateaus (load / unload N)']
    .map(h => el('th', { text: h })));
  const rows = loops.map(l => {
    const t = l.transformation || {};
    const plateaus = (l.plateaus || []).map(p => `${num(p.at_mm)} mm: ${round2(p.loading_N)} / ${round2(p.unloading_N)}`).join('; ');
    return el('tr', { class: l.phase },
      ...[l.phase, String(l.k + 1), `${num(l.min_mm)}–${num(l.max_mm)}`, round2(l.peak_force_N), num(l.energy_Nmm), num(l.secant_stiffness_N_mm),
        num(l.damping_ratio, 2), round2(l.return_N), num(l.residual_mm), point(t.Ms), point(t.Mf), point(t.As), point(t.Af), plateaus || '–'].map(v => el('td', { text: v })));
  });
  return [el('thead', {}, head), el('tbody', {}, ...rows)];
}
