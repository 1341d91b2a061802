// A campaign's events in words (the page's event list) and its running time from them.
import { describeSweepEvent } from './shaker.js';
import { num, round2 } from './fmt.js';

// One event's detail in a lab user's words; a kind this page does not know, its fields in words.
export function describeEvent(e) {
  const d = e.detail;
  if (typeof d === 'string') return d;
  if (!d) return '';
  if (e.kind === 'fit' && d.accuracy) return `partial table of ${d.nodes}/${d.required} nodes: RMS ${round2(d.accuracy.overall.rms_N)} N over the samples so far`;
  const sweepText = describeSweepEvent(e);
  if (sweepText) return sweepText;
  if (e.kind === 'gaps') return `${d.count} holes in the time axis, ${num(d.total_ms / 1000, 2)} s in all, the longest ${num(d.longest_ms / 1000, 2)} s`;
  if (e.kind === 'quality') return `run #${d.run}: ${d.samples} samples at ${num(d.rate_hz, 3)} Hz of rig time, ${d.missed_deadlines} missed deadlines, ` +
    `${d.lost_samples} lost samples, ${d.io_errors} I/O errors, ${d.gaps} gaps`;
  if (e.kind === 'validation') return `validation run #${d.run}: ${d.reversals} random reversals (seed ${d.seed}), not used to build any table`;
  if (e.kind === 'recommendation' || e.kind === 'training') return d.why;
  if (e.kind === 'shakedown') return `cycle ${d.cycle}: E_d ${num(d.energy_Nmm)} N·mm` + (d.energy_change_pct != null ? ` (${num(d.energy_change_pct, 2)} %)` : '') +
    `, peak ${round2(d.peak_force_N)} N` + (d.peak_change_pct != null ? ` (${num(d.peak_change_pct, 2)} %)` : '') + (d.stable ? ': stable' : '');
  if (e.kind === 'record') return `the record changed: specimen ${d.specimen ? `"${d.specimen}"` : 'none'}, notes ${d.notes ? `"${d.notes}"` : 'none'}`;
  if (e.kind === 'limits' || e.kind === 'envelope') return Object.entries(d).map(([k, v]) => `${k.replace(/_/g, ' ')} ${Array.isArray(v) ? v.map(x => num(x)).join('…') : num(v)}`).join(', ');
  // A kind this page does not know: its fields in words, never raw JSON.
  return Object.entries(d).map(([k, v]) => `${k.replace(/_/g, ' ')} ${typeof v === 'number' ? num(v) : typeof v === 'object' ? JSON.stringify(v) : v}`).join(', ');
}

// Seconds the campaign has spent running, from its state events: paused (or held) time does
// not count, so the ETA does not jump after a pause.
export function activeSeconds(events, now) {
  let total = 0, since = null;
  for (const e of Array.isArray(events) ? events : []) {  // a failed events request leaves no list
    if (e.kind !== 'state' && e.kind !== 'campaign') continue;
    const t = Date.parse(e.at);
    if (!Number.isFinite(t)) continue;
    if (e.to === 'running') { if (since == null) since = t; } else if (since != null) { total += t - since; since = null; }
  }
  if (since != null) total += Math.max(0, now - since);
  return total / 1000;
}
