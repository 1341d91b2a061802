// The rig panel: every rig, always in view (it sits in the sticky header), polled from
// GET /api/rigs: its supervision state, live position and force, status bits, link health and
// envelope, and a large E-STOP that needs no confirmation. A latched rig shows why, and a Reset
// that does ask (docs/API.md, "Status and rigs").
import { api, post } from './api.js';
import { el, num, round2, count } from './fmt.js';

const POLL_MS = 750;
const BITS = ['ready', 'enabled', 'holding', 'moving', 'estop', 'limit_tripped', 'fault'];
const BAD_BITS = new Set(['estop', 'limit_tripped', 'fault']);
const UNITS = { mm: 'mm', N: 'N', mm_s: 'mm/s', mm_s2: 'mm/s²', g: 'g', hz: 'Hz', s: 's' };

// "stroke_mm": [-10, 10] -> "stroke −10…10 mm"; "speed_mm_s": 20 -> "speed 20 mm/s".
function envelopeItem(key, v) {
  const m = /^([a-z]+?)_((?:mm_s2|mm_s|mm|N|g|hz|s))$/.exec(key);
  const name = (m ? m[1] : key).replace(/_/g, ' '), unit = m ? UNITS[m[2]] : '';
  const value = Array.isArray(v) ? `${num(v[0])}…${num(v[1])}` : typeof v === 'number' ? num(v) : String(v);
  return `${name} ${value}${unit ? ' ' + unit : ''}`;
}

// Live position and force (load frame) or base and mass displacement (shaker).
function liveText(r) {
  const s = r.sample || {};
  if (r.kind === 'shaker') return `base ${fixed(s.base_displacement_mm, 3)} mm · mass ${fixed(s.mass_displacement_mm, 3)} mm`;
  return `x ${fixed(s.displacement_mm, 3)} mm · F ${fixed(s.force_N, 1)} N`;
}
// Fixed decimals (the numbers must not jump about), without a "-0.0" for noise around zero.
const fixed = (v, d) => (Number.isFinite(v) ? (Math.abs(v) < 0.5 * 10 ** -d ? 0 : v).toFixed(d) : '–');

export class RigPanel {
  constructor(root, { onChange } = {}) {
    this.root = root; this.onChange = onChange || (() => {});
    this.cards = new Map();  // name -> elements, built once so a click is never lost to a re-render
    this.last = [];
    this.errors = new Map(); // name -> the last command's error
  }
  start() { const tick = () => this.poll().finally(() => setTimeout(tick, POLL_MS)); tick(); }
  rigs() { return this.last; }
  rig(name) { return this.last.find(r => r.name === name); }
  async poll() {
    try {
      const rigs = await api('/api/rigs');
      this.last = Array.isArray(rigs) ? rigs : [];
      this.render();
      this.onChange(this.last);
    } catch (e) { console.warn('rigs:', e.message); }
  }
  async command(name, verb) {
    this.errors.delete(name);
    try { await post(`/api/rigs/${encodeURIComponent(name)}/${verb}`); } catch (e) { this.errors.set(name, `${verb}: ${e.message}`); }
    await this.poll();
  }
  card(r) {
    let c = this.cards.get(r.name);
    if (c) return c;
    c = {
      name: el('b', { text: r.name }), kind: el('span', { class: 'muted' }), state: el('span', { class: 'rstate' }),
      estop: el('button', { class: 'estop', type: 'button', title: `e-stop ${r.name} now (latched until Reset)`,
                            onclick: () => this.command(r.name, 'estop') }, 'E-STOP'),
      live: el('span', { class: 'live' }), bits: el('span', { class: 'bits' }), health: el('div', { class: 'health' }),
      envelope: el('div', { class: 'envelope muted' }), reason: el('strong'), refusal: el('div', { class: 'refusal' }),
      reset: el('button', { class: 'reset', type: 'button', onclick: () => {
        if (window.confirm(`Reset the e-stop of "${r.name}"? Make sure the rig and the specimen are safe first.`)) this.command(r.name, 'reset');
      } }, 'Reset…'),
      // A frame beyond its stroke (or idle outside it): back at the safe rate through the
      // controller's limit recovery; E-STOP stops it on the way.
      recover: el('button', { class: 'reset', type: 'button', onclick: () => {
        if (window.confirm(`Bring "${r.name}" back into its stroke at the safe rate? Make sure nothing is in the way; E-STOP stops it.`))
          this.command(r.name, 'recover');
      } }, 'Bring back into stroke…'),
      error: el('div', { class: 'error' }),
    };
    c.latch = el('div', { class: 'latch', role: 'alert' }, c.reason, ' ', c.reset, ' ', c.recover, c.refusal);
    // One line in the sticky header (name, state, live values, E-STOP); the status bits, the link's
    // health and the envelope below it when the operator opens the card (▸), so that the header
    // leaves the screen to the work. A latch always shows, whatever is open.
    c.more = el('button', { class: 'more', type: 'button', title: `status bits, link and envelope of ${r.name}`, 'aria-expanded': 'false',
                            onclick: () => { const open = c.root.classList.toggle('open'); c.more.setAttribute('aria-expanded', String(open)); c.more.textContent = open ? '▾' : '▸'; } }, '▸');
    c.root = el('div', { class: 'rig', 'data-rig': r.name },
      el('div', { class: 'rig-head' }, c.more, c.name, c.kind, c.state, c.live, c.estop),
      el('div', { class: 'rig-more' }, c.bits, c.health, c.envelope), c.latch, c.error);
    this.cards.set(r.name, c);
    this.root.append(c.root);
    return c;
  }
  render() {
    for (const r of this.last) {
      const c = this.card(r);
      c.kind.textContent = r.kind === 'shaker' ? 'shaker' : 'load frame';
      c.state.textContent = r.state || '?';
      c.state.className = 'rstate ' + (r.state || '');
      c.live.textContent = liveText(r);
      // A shaker's mass at rest away from 0 after a sweep: not a sensor offset, but where the
      // hysteretic springs' last cycles left it (at the weight's force their loop spans a band
      // of displacements; which one depends on the history). Said, with a mark, in the tooltip.
      const rest = r.kind === 'shaker' && r.state === 'idle' && r.sample ? r.sample.mass_displacement_mm : NaN;
      const offset = Number.isFinite(rest) && Math.abs(rest) >= 0.01;
      if (offset) c.live.textContent += ' ⓘ';
      c.live.title = offset ? `The mass rests at ${fixed(rest, 3)} mm: where the springs' last cycles left it. A hysteretic spring carries the same weight over a ` +
        'band of compressions, and which one it rests at depends on its history; it is not a sensor offset.' : '';
      const st = r.status || {};
      c.bits.replaceChildren(...(st.known === false ? [el('span', { class: 'bit', text: 'status unknown' })] :
        BITS.map(b => el('span', { class: 'bit' + (st[b] ? (BAD_BITS.has(b) ? ' bad' : ' on') : ''), text: b.replace('_', ' '),
                                   title: st[b] ? `${b}: set` : `${b}: clear` }))));
      const h = r.health || {}, errs = h.errors || {};
      const total = Object.values(errs).reduce((a, b) => a + (Number(b) || 0), 0);
      const others = Object.entries(errs).filter(([k, v]) => k !== 'timeout' && v).map(([k, v]) => `${count(v)} ${k.replace(/_/g, ' ')}`);
      c.health.textContent = `link: ${count(total)} errors (${count(errs.timeout || 0)} timeouts${others.length ? ', ' + others.join(', ') : ''})` +
        ` · ${count(h.reconnects || 0)} reconnects · ${count(h.lost_samples || 0)} lost samples · ${count(r.link_losses || 0)} link losses` +
        ` · ${count(r.missed_deadlines || 0)} missed deadlines`;
      c.health.className = 'health' + ((h.lost_samples || r.link_losses || r.missed_deadlines) ? ' warn' : '');
      c.health.title = `reads ${count(h.reads)}, writes ${count(h.writes)}, last transaction ${round2((h.last_transaction_us || 0) / 1000)} ms, ` +
        `longest ${round2((h.max_transaction_us || 0) / 1000)} ms, late wake-ups ${count(r.late_wakeups || 0)}`;
      const env = r.envelope || {};
      c.envelope.textContent = Object.keys(env).length ? 'envelope: ' + Object.entries(env).map(([k, v]) => envelopeItem(k, v)).join(' · ') : '';
      c.latch.hidden = !r.latched && !r.recoverable && !r.recovering;
      c.recover.hidden = !r.recoverable && !r.recovering;
      c.recover.disabled = !!r.recovering;
      c.recover.textContent = r.recovering ? 'bringing back…' : 'Bring back into stroke…';
      c.root.classList.toggle('latched', !!r.latched);
      c.reason.textContent = r.latched ? `LATCHED: ${r.latch_reason || 'e-stop or fault'}` + (r.fault && r.fault.text ? ` — fault ${r.fault.code}: ${r.fault.text}` : '') : '';
      c.reset.disabled = !!r.resetting;
      c.reset.textContent = r.resetting ? 'resetting…' : 'Reset…';
      const at = `${round2(r.sample ? r.sample.displacement_mm : NaN)} mm`, rate = (r.supervision || {}).safe_rate_mm_s;
      c.refusal.textContent = r.reset_refusal || (!r.recoverable ? '' : r.latched
        ? `The frame is beyond its stroke at ${at}: a reset cannot clear that. Bring it back at the safe rate${rate ? ` (${num(rate)} mm/s)` : ''}; E-STOP stops it.`
        : `The frame is outside its configured stroke at ${at}.`);
      c.error.textContent = this.errors.get(r.name) || '';
    }
    for (const [name, c] of this.cards) if (!this.rig(name)) { c.root.remove(); this.cards.delete(name); }
  }
}
