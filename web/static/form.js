// The new-campaign form: its fields (with units), checks in the page before anything is sent
// (in the form's words, beside the input at fault), the server's own plan errors mapped back to
// the input its `field` names, and a preview of the plan (duration, nodes, peak speed and force)
// from POST /api/plans/preview as the form changes.
import { api, post } from './api.js';
import { el, num, round2, count, duration } from './fmt.js';

// The inputs come from the daemon (GET /api/plans/form): the plan parser's own table of fields
// (protocols/domain/src/plan_fields.cpp) with where each goes in the plan, its words and unit,
// what it accepts and what the form proposes. A field given an input there appears here and is
// sent at its path; the page has no list of its own.
function inputsOf(table) {
  return table.fields.filter(f => f.group).map(f => ({
    name: f.input, group: f.group, label: f.label || f.words, unit: f.unit, value: f.value, placeholder: f.placeholder, optional: f.optional,
    min: f.min, max: f.max, plan: f.path, kind: f.type, int: f.type === 'integer', list: f.type === 'list', text: f.type === 'text',
    textarea: f.type === 'text' && f.max > 1000, maxlength: f.type === 'text' ? f.max : null,
    options: f.type === 'choice' ? f.choices.map(c => [c, c]) : null, sweep: f.path.startsWith('sweep.'),
  }));
}
const GROUP_TITLES = { fot: null, sine: null, common: null, limits: 'Limits (blank: the rig’s own)', record: 'Record (optional)' };
// The server's field names, as the form says them (for its messages): every field's words, the
// longest names first (settle_cycles before settle).
let WORDS = [];
function wordsOf(table) {
  const pairs = [['range_mm', 'δmin … δmax'], ['limits.displacement_mm', 'displacement limits']];
  for (const f of table.fields) if (!f.path.includes('[')) pairs.push([f.path, f.words]);
  return pairs.sort((a, b) => b[0].length - a[0].length);
}
const base = path => path.replace(/\[\d+\]$/, '');
// Sets plan[a][b]... at "a.b" (or "a[1]": one end of a pair).
function setPath(plan, path, value) {
  const keys = path.split('.');
  let o = plan;
  for (const k of keys.slice(0, -1)) o = (o[k] = o[k] || {});
  const last = keys[keys.length - 1], m = /^(.*)\[(\d+)\]$/.exec(last);
  if (m) { o[m[1]] = o[m[1]] || []; o[m[1]][Number(m[2])] = value; } else o[last] = value;
}

export function humanize(text) {
  let s = String(text || '').replace(/^plan: /, '');
  for (const [key, words] of WORDS) s = s.split(key).join(words);
  return s;
}

export class PlanForm {
  constructor(form, { rigPanel, onSubmitted }) {
    this.form = form; this.rigPanel = rigPanel; this.onSubmitted = onSubmitted;
    this.previewSeq = 0; this.previewTimer = null;
    this.fields = [];
    this.error = form.querySelector('#form-error');
    this.preview = form.querySelector('#preview');
    this.why = form.querySelector('#submit-why');
    this.submit = form.querySelector('#submit');
    form.kind.addEventListener('change', () => { this.showKind(); this.pickRigFor(form.kind.value); });
    form.rig.addEventListener('change', () => this.updateLatch());
    form.addEventListener('input', e => { this.clearField(e.target.name); this.error.textContent = ''; this.schedulePreview(); });
    form.addEventListener('change', () => this.schedulePreview());
    form.addEventListener('submit', e => { e.preventDefault(); this.send(); });
    this.ready = this.load();
  }
  // The daemon's table of plan fields, then the inputs; again after a failure (a daemon starting).
  async load() {
    for (let wait = 500; ; wait = Math.min(2 * wait, 5000)) {
      try {
        const table = await api('/api/plans/form');
        this.fields = inputsOf(table); WORDS = wordsOf(table);
        break;
      } catch (err) {
        this.error.textContent = `the form's fields could not be read from the daemon (${err.message}); trying again`;
        await new Promise(r => setTimeout(r, wait));
      }
    }
    this.error.textContent = '';
    this.build();
    this.showKind();
    this.schedulePreview();
  }
  // The inputs, from the fields: label with unit, input, and the message slot beside it.
  build() {
    for (const g of Object.keys(GROUP_TITLES)) {
      const box = this.form.querySelector(`fieldset.${g}`);
      if (GROUP_TITLES[g]) box.append(el('legend', { text: GROUP_TITLES[g] }));
      for (const f of this.fields.filter(x => x.group === g)) {
        const id = 'f-' + f.name;
        const input = f.options ? el('select', { id, name: f.name, 'aria-describedby': id + '-msg' }, ...f.options.map(([v, text]) => el('option', { value: v, text })))
          : f.textarea ? el('textarea', { id, name: f.name, rows: 2, maxlength: f.maxlength, placeholder: f.placeholder, 'aria-describedby': id + '-msg' })
          : el('input', { id, name: f.name, type: 'text', inputmode: f.list || f.text ? null : 'decimal',
                          value: f.value, placeholder: f.placeholder || null, 'aria-describedby': id + '-msg', autocomplete: 'off', maxlength: f.maxlength || null });
        if (f.options) input.value = f.value;
        box.append(el('div', { class: 'field' + (f.text ? ' text' : '') },
          el('label', { for: id, text: f.label + (f.unit ? ` (${f.unit})` : '') }), input,
          el('span', { class: 'msg', id: id + '-msg', 'aria-live': 'polite' })));
      }
    }
  }
  showKind() {
    const sine = this.form.kind.value === 'sine';
    this.form.querySelector('fieldset.fot').hidden = sine;
    this.form.querySelector('fieldset.limits').hidden = sine;
    this.form.querySelector('fieldset.sine').hidden = !sine;
    this.clearAll();
  }
  // The first rig that can run this kind of plan (a sine sweep needs a shaker).
  pickRigFor(kind) {
    const want = kind === 'sine' ? 'shaker' : 'load_frame';
    const o = [...this.form.rig.options].find(x => x.dataset.kind === want);
    if (o) this.form.rig.value = o.value;
    this.updateLatch();
  }
  setRigs(rigs) {
    const chosen = this.form.rig.value;
    const names = rigs.map(r => r.name).join('\n');
    if (names !== this.rigNames) {
      this.rigNames = names;
      this.form.rig.replaceChildren(...rigs.map(r => el('option', { value: r.name, 'data-kind': r.kind, text: `${r.name} (${r.kind === 'shaker' ? 'shaker' : 'load frame'})` })));
      // Rigs of one kind only (a daemon with a shaker alone): the form offers what they can run.
      const kinds = new Set(rigs.map(r => (r.kind === 'shaker' ? 'sine' : 'fot')));
      if (kinds.size === 1 && !kinds.has(this.form.kind.value)) { this.form.kind.value = [...kinds][0]; this.showKind(); }
      if (chosen && rigs.some(r => r.name === chosen)) this.form.rig.value = chosen; else this.pickRigFor(this.form.kind.value);
      this.schedulePreview();
    }
    this.updateLatch();
  }
  // No campaign on a latched rig: Submit is off, and says why.
  updateLatch() {
    const r = this.rigPanel.rig(this.form.rig.value);
    const latched = !!(r && r.latched);
    this.submit.disabled = latched;
    this.why.textContent = latched ? `${r.name} is latched (${r.latch_reason || 'e-stop or fault'}): reset it first` : '';
  }

  // ---- messages beside the inputs ----
  inputsFor(field) {
    const key = String(field || '').replace(/^plan\./, '').replace(/\[\d+\]$/, '');
    if (key === 'range_mm') return ['lo', 'hi'];
    if (key === 'limits.displacement_mm' || key === 'limits.safe_position_mm') return ['dlo', 'dhi'];
    const f = this.fields.find(x => base(x.plan) === key && !this.inputOf(x.name).closest('fieldset').hidden);
    if (f) return [f.name];
    // Fields without an input of their own: the nearest input that sets them.
    if (key === 'sweep' || key.startsWith('sweep.')) return [this.inputOf('freqs').value.trim() ? 'freqs' : 'fromhz'];
    if (key === 'amplitude_mm') return ['amps'];
    if (key.startsWith('settle')) return ['settlechange'];
    if (key.startsWith('control')) return ['tol'];
    if (key === 'limits') return ['force'];
    if (key.startsWith('training.until')) return ['stable'];
    if (key.startsWith('training')) return ['training'];
    if (key.startsWith('validation')) return ['reversals'];
    return [];
  }
  inputOf(name) { return this.form.querySelector(`#f-${name}`); }
  // A pasted plan replaces the form's fields: its errors belong to the text box, not to them.
  pasted() { return this.form.json.value.trim() !== ''; }
  mark(name, message) {
    const input = this.inputOf(name);
    if (!input) return;
    input.setAttribute('aria-invalid', 'true');
    const box = input.closest('details');
    if (box) box.open = true;  // the pasted plan's box: its message must be seen
    const msg = this.form.querySelector(`#f-${name}-msg`);
    if (message) msg.textContent = message;
  }
  clearField(name) {
    const input = name && this.inputOf(name);
    if (!input || input.getAttribute('aria-invalid') !== 'true') return;
    // A message shared by a pair (δmin … δmax, the displacement limits) goes with either.
    const pair = [['lo', 'hi'], ['dlo', 'dhi'], ['rate', 'ratelim']].find(p => p.includes(name)) || [name];
    for (const n of pair) { this.inputOf(n).removeAttribute('aria-invalid'); this.form.querySelector(`#f-${n}-msg`).textContent = ''; }
  }
  clearAll() {
    for (const f of [...this.fields, { name: 'json' }]) { this.inputOf(f.name).removeAttribute('aria-invalid'); this.form.querySelector(`#f-${f.name}-msg`).textContent = ''; }
    if (this.error) this.error.textContent = '';
  }
  // A 400 from the server: its `field` (or the "plan: FIELD ..." of its detail) marks the input.
  showServerError(err) {
    const b = err.body || {};
    const field = b.field || (/^plan: ([a-z_.]+(?:\[\d+\])?) /.exec(b.detail || '') || [])[1];
    const names = field ? this.inputsFor(field) : [];
    const message = humanize(b.detail || err.message);
    if (this.pasted()) { this.mark('json', `in the pasted plan: ${message}`); return; }
    if (!names.length) { this.error.textContent = message; return; }
    names.forEach((n, k) => this.mark(n, k === 0 ? message : ''));
  }

  // ---- the plan ----
  // Reads and checks every visible field; returns {plan} or {errors: [[name, message]]}.
  read() {
    const form = this.form;
    if (form.json.value.trim()) {
      try { return { plan: JSON.parse(form.json.value) }; } catch (e) { return { errors: [['json', `the pasted plan is not valid JSON (${e.message})`]] }; }
    }
    if (!this.fields.length) return { errors: [[null, 'the form is still being read from the daemon']] };
    const sine = form.kind.value === 'sine';
    const groups = sine ? ['sine', 'common', 'record'] : ['fot', 'common', 'limits', 'record'];
    const errors = [], v = {};
    const list = sine && this.inputOf('freqs').value.trim() !== '';  // a list of frequencies: the steps' fields are not used
    for (const f of this.fields.filter(x => groups.includes(x.group) && !(list && x.sweep))) {
      const raw = this.inputOf(f.name).value.trim();
      const what = f.label;
      if (f.options) { v[f.name] = raw; continue; }
      if (f.text) { if (raw) v[f.name] = f.textarea ? this.inputOf(f.name).value : raw; continue; }
      if (raw === '') { if (!f.optional) errors.push([f.name, `${what} is required`]); continue; }
      const parts = f.list ? raw.split(/[,;\s]+/).filter(Boolean) : [raw];
      const vals = parts.map(p => Number(p.replace(',', '.')));
      const unit = f.unit ? ' ' + f.unit : '';
      if (vals.some(x => !Number.isFinite(x))) errors.push([f.name, f.list ? `${what}: each must be a number (separate them with commas)` : `${what} must be a number`]);
      else if (f.int && vals.some(x => !Number.isInteger(x))) errors.push([f.name, `${what} must be a whole number`]);
      else if (f.kind === 'percent' && vals.some(x => !(x > f.min) || x > f.max)) errors.push([f.name, `${what} must be above ${num(f.min)} and at most ${num(f.max)}${unit}`]);
      else if (vals.some(x => x < (f.plan === 'validation.reversals' ? 0 : f.min) || x > f.max)) errors.push([f.name, `${what} must be from ${num(f.min)} to ${num(f.max)}${unit}`]);
      else v[f.name] = f.list ? vals : vals[0];
    }
    if (!sine) {
      if (v.lo != null && v.hi != null && !(v.hi > v.lo)) errors.push(['hi', 'δmax must be above δmin']);
      if (v.rate != null && v.ratelim != null && v.rate > v.ratelim) errors.push(['rate', `ramp rate must not be above the rate limit (${num(v.ratelim)} mm/s)`]);
      if (v.dlo != null && v.lo != null && v.dlo > v.lo) errors.push(['dlo', 'the lower displacement limit must be at or below δmin']);
      if (v.dhi != null && v.hi != null && v.dhi < v.hi) errors.push(['dhi', 'the upper displacement limit must be at or above δmax']);
      if ((v.dlo == null) !== (v.dhi == null)) errors.push([v.dlo == null ? 'dlo' : 'dhi', 'give both displacement limits, or neither']);
    }
    if (sine) errors.push(...sineErrors(v));
    if (v.specimen && v.specimen.includes('\n')) errors.push(['specimen', 'specimen must be one line']);
    if (v.reversals === 1) errors.push(['reversals', 'at least 2 reversals, or 0 for no validation run']);
    if (errors.length) return { errors };
    // Each input's value at its field's path; then what chooses between fields.
    const plan = { kind: sine ? 'sine' : 'fot' };
    const own = new Set(sine ? (v.settle != null ? ['settlechange'] : []) : ['training', 'stable', 'reversals']);
    for (const f of this.fields.filter(x => groups.includes(x.group) && !(list && x.sweep) && v[x.name] != null && !own.has(x.name)))
      setPath(plan, f.plan, f.kind === 'percent' ? `${v[f.name]} %` : v[f.name]);
    if (plan.sweep) plan.sweep.spacing = 'log';
    if (!sine && v.training) {
      // Until stable: the energy's change per cycle below the given %, the peak force's below 0.5 %, 3 cycles in a row.
      if (v.stable != null) plan.training = { max_cycles: v.training, until: { energy_change: v.stable, peak_force_change: 0.5, consecutive: Math.min(3, Math.max(1, v.training - 1)) } };
      else plan.training_cycles = v.training;
    }
    if (!sine && v.reversals === 0) plan.validation = false;
    else if (!sine && v.reversals !== 12) plan.validation = { reversals: v.reversals };
    return { plan };
  }
  body(plan) { const b = { plan }; if (this.form.rig.value) b.rig = this.form.rig.value; return b; }
  showErrors(errors) {
    for (const [name, message] of errors) { if (name) this.mark(name, message); else this.error.textContent = message; }
    const first = errors.find(e => e[0]);
    return first ? this.inputOf(first[0]) : null;
  }

  async send() {
    this.clearAll();
    const r = this.read();
    if (r.errors) { const input = this.showErrors(r.errors); if (input) input.focus(); return; }
    this.submit.disabled = true;
    try {
      const c = await post('/api/campaigns', this.body(r.plan));
      await this.onSubmitted(c);
    } catch (err) {
      if (err.status === 400) this.showServerError(err); else this.error.textContent = humanize(err.message);
    } finally { this.updateLatch(); }
  }

  // ---- the preview, ~300 ms after the last change ----
  schedulePreview() {
    clearTimeout(this.previewTimer);
    ++this.previewSeq;  // an answer for the form as it was before this change is stale already
    this.previewTimer = setTimeout(() => this.runPreview(), 300);
  }
  async runPreview() {
    const seq = ++this.previewSeq;
    const r = this.read();
    if (r.errors || this.previewMissing) { this.preview.hidden = true; return; }
    try {
      const p = await post('/api/plans/preview', this.body(r.plan));
      if (seq !== this.previewSeq) return;  // an older answer must not replace a newer one
      this.preview.textContent = previewText(p);
      this.preview.hidden = false;
    } catch (err) {
      if (seq !== this.previewSeq) return;
      this.preview.hidden = true;
      if (err.status === 404 || err.status === 405) this.previewMissing = true;  // an older daemon: no preview, say nothing
      else if (err.status === 400) this.showServerError(err);
    }
  }
}

// A sine plan's own checks (the parser's, protocols/domain/src/sine_plan.cpp), in the form's words.
function sineErrors(v) {
  const errors = [], highest = v.freqs ? Math.max(...v.freqs) : v.tohz;
  if (!v.freqs && v.fromhz != null && v.tohz != null && !(v.tohz > v.fromhz)) errors.push(['tohz', 'sweep to must be above sweep from']);
  if (v.freqs && new Set(v.freqs).size !== v.freqs.length) errors.push(['freqs', 'frequencies must not repeat']);
  if (v.hz != null && highest > v.hz / 8)
    errors.push([v.freqs ? 'freqs' : 'tohz', `at most ${num(v.hz / 8)} Hz: 8 samples a cycle at the sample rate of ${num(v.hz)} Hz`]);
  if (v.amps && v.amps.length > 20) errors.push(['amps', 'at most 20 amplitudes']);
  if (v.warn != null && v.tol != null && v.warn < v.tol) errors.push(['warn', 'the control warning must be at least the tolerance']);
  if (v.abortpct != null && !(v.abortpct > Math.max(v.warn ?? 10, v.tol ?? 0))) errors.push(['abortpct', `the control abort must be above the warning (${num(v.warn ?? 10)} %)`]);
  return errors;
}

// "about 2 min 10 s · 45 nodes · peak speed 0.5 mm/s · peak force ≈ 380 N (from table #3)"; a sweep: steps and peak acceleration.
// On a simulator faster than real time, the wall time it takes and what it stores in rig time.
export function previewText(p) {
  const fast = p.time_scale > 1;
  const parts = [fast ? `about ${duration(p.wall_s)} (${duration(p.duration_s)} of rig time: the simulator runs ${num(p.time_scale)}× faster than real time)`
                      : `about ${duration(p.duration_s)}`];
  if (p.nodes != null) parts.push(`${count(p.nodes)} ${p.kind === 'sine' ? 'steps' : 'nodes'}`);
  if (p.peak_accel_m_s2 != null) parts.push(`peak acceleration ${num(p.peak_accel_m_s2, 2)} m/s² (${num(p.peak_accel_m_s2 / 9.80665, 2)} g)`);
  if (fast && p.stored_samples != null) parts.push(`${count(p.stored_samples)} samples (${num(p.stored_rate_hz)} Hz of rig time)`);
  else if (p.samples != null) parts.push(`${count(p.samples)} samples`);
  if (p.peak_speed_mm_s != null) parts.push(`peak speed ${num(p.peak_speed_mm_s, 2)} mm/s`);
  if (p.peak_force_N != null) parts.push(`peak force ≈ ${round2(p.peak_force_N)} N${p.force_source ? ` (from ${p.force_source})` : ''}`);
  // A limit looser than the rig's is not refused: the rig's applies, and the operator is told.
  for (const a of p.limits_applied || []) parts.push(a);
  return parts.join(' · ');
}
