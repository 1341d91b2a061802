// Data quality in view: per run, what the acquisition lost (missed deadlines, lost samples,
// I/O errors, holes in the samples) and the rate actually stored in rig time against the one
// the plan asked for; and a warning box with every warning of the campaign's runs and tables.
// An older daemon sends no `quality`: the run line then says only what it knows.
import { el, count, num, plural } from './fmt.js';

function rateText(q) {
  if (!Number.isFinite(q.rate_hz)) return null;
  const asked = q.requested_rate_hz, scale = q.time_scale > 1 ? q.time_scale : 1;
  // What the rig can give: the plan's rate, or, on a simulator faster than real time, the plan's
  // rate in wall time (time_scale times less in rig time). Within 5 % of it: kept.
  const expected = Number.isFinite(q.expected_rate_hz) ? q.expected_rate_hz : asked;
  const scaled = scale > 1 ? ` of rig time (the plan's ${num(asked)} Hz in wall time: a simulator ${num(scale)}× faster than real time)` : '';
  if (Number.isFinite(expected) && Math.abs(q.rate_hz - expected) > 0.05 * expected)
    return el('span', { class: 'bad', text: `stored ${num(q.rate_hz)} Hz of rig time (plan asked ${num(asked)} Hz${scale > 1 ? `, ${num(expected)} Hz at this time scale` : ''})` });
  return `${num(q.rate_hz)} Hz${scaled}`;
}
const figure = (n, one, many) => el('span', { class: n ? 'bad' : '', text: plural(n || 0, one, many) });

// A run's line: its figures, and which run the plots show (a link shows another).
function runLine(r, show) {
  const q = r.quality;
  const li = el('li', { 'data-run': r.id }, `run #${r.id}` + (r.role === 'validation' ? ' (validation)' : '') + ': ');
  if (show && (r.samples || 0) > 0)
    li.append(show.run === r.id ? el('span', { class: 'shown-run', text: '(in the plots) ' }) : el('a', { href: show.href(r.id), class: 'show-run', text: 'show' }), ' ');
  // A run that stored nothing (a campaign stopped before it started): no rate, no figures to judge.
  if (!(r.samples > 0) && !(q && q.samples > 0)) { li.append(r.state === 'running' ? 'no samples yet' : 'no samples stored (it stopped before sampling)'); return li; }
  // A run's figures are stored at its end; before that, only its samples.
  if (!q) { li.append(`${plural(r.samples || 0, 'sample')}` + (r.state === 'running' ? ' so far (its quality figures come at its end)' : ' (this daemon gives no quality figures)')); return li; }
  const parts = [plural(q.samples ?? r.samples ?? 0, 'sample'), rateText(q),
    figure(q.missed_deadlines, 'missed deadline'), figure(q.lost_samples, 'lost sample'), figure(q.io_errors, 'I/O error')];
  const gaps = q.gaps || 0;
  parts.push(gaps ? el('span', { class: 'bad', text: `${plural(gaps, 'gap')} (${num(q.gap_total_s, 2)} s in all, longest ${num(q.longest_gap_s, 2)} s)` }) : 'no gaps');
  if (q.late_wakeups) parts.push(plural(q.late_wakeups, 'late wake-up'));
  parts.filter(p => p != null).forEach((p, k) => { if (k) li.append(' · '); li.append(p); });
  return li;
}

// Fills the quality list and the warning box; returns the warnings shown. `extra`: the
// campaign's own warnings in words (a sweep's control warnings, say), after the runs' and tables'.
// show: {run, href(run)}: the run in the plots and the address of another.
export function showQuality(d, listEl, boxEl, extra = [], show = null) {
  const runs = (d && d.runs) || [], tables = (d && d.tables) || [];
  listEl.replaceChildren(...runs.map(r => runLine(r, show)));
  const warnings = [];
  for (const r of runs) for (const w of (r.quality && r.quality.warnings) || []) warnings.push(`run #${r.id}: ${w}`);
  for (const t of tables) for (const w of t.warnings || []) warnings.push(`table #${t.id}: ${w}`);
  warnings.push(...extra);
  // The first few in view, the rest one click away: a starved run's dozen warnings would push
  // the plots off the screen.
  const SHOWN = 2, item = w => el('li', { text: w });
  const rest = warnings.length > SHOWN + 1 ? warnings.slice(SHOWN) : [];
  boxEl.replaceChildren(...(warnings.length ? [el('strong', { text: `Check before trusting this campaign (${plural(warnings.length, 'warning')}):` }),
    el('ul', {}, ...warnings.slice(0, warnings.length - rest.length).map(item)),
    rest.length ? el('details', {}, el('summary', { text: `${plural(rest.length, 'more warning')}` }), el('ul', {}, ...rest.map(item))) : null].filter(Boolean) : []));
  boxEl.hidden = warnings.length === 0;
  return warnings;
}
