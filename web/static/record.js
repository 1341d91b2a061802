// What the lab records with a campaign: the specimen and the operator's notes, shown under the
// plots and changed there at any time (POST /api/campaigns/ID/record; each change is kept in
// the campaign's events). A refused value is shown beside its input, in the server's words.
import { post } from './api.js';
import { el } from './fmt.js';

export class RecordView {
  constructor(box, { onSaved, readOnly = false }) { this.box = box; this.onSaved = onSaved; this.readOnly = readOnly; this.editing = null; }

  show(d) {
    if (this.editing === d.id) return;  // never wipe what the operator is typing
    this.editing = null;
    const edit = el('button', { type: 'button', class: 'edit-record', text: d.specimen || d.notes ? 'Edit' : 'Add specimen and notes' });
    edit.addEventListener('click', () => this.form(d));
    // (replaceChildren would write a null as the text "null")
    this.box.replaceChildren(...[d.specimen ? el('span', {}, el('b', { text: 'specimen ' }), d.specimen) : null,
      d.notes ? el('span', { class: 'notes', text: d.notes }) : null, this.readOnly ? null : edit].filter(Boolean));
  }

  form(d) {
    this.editing = d.id;
    const specimen = el('input', { name: 'specimen', value: d.specimen || '', maxlength: 200, 'aria-describedby': 'record-msg' });
    const notes = el('textarea', { name: 'notes', rows: 3 });
    notes.value = d.notes || '';
    const msg = el('p', { id: 'record-msg', class: 'error', role: 'alert' });
    const cancel = el('button', { type: 'button', text: 'Cancel' });
    const form = el('form', { class: 'record-form' },
      el('label', { for: 'r-specimen', text: 'specimen' }), specimen, el('label', { text: 'notes' }), notes,
      el('span'), el('span', {}, el('button', { type: 'submit', text: 'Save' }), ' ', cancel), msg);
    specimen.id = 'r-specimen';
    cancel.addEventListener('click', () => { this.editing = null; this.show(d); });
    form.addEventListener('submit', async e => {
      e.preventDefault();
      for (const i of [specimen, notes]) i.removeAttribute('aria-invalid');
      try {
        await post(`/api/campaigns/${d.id}/record`, { specimen: specimen.value.trim(), notes: notes.value });
        this.editing = null;
        await this.onSaved();
      } catch (err) {
        msg.textContent = err.message;
        const bad = err.body && err.body.field === 'notes' ? notes : err.body && err.body.field === 'specimen' ? specimen : null;
        if (bad) { bad.setAttribute('aria-invalid', 'true'); bad.focus(); }
      }
    });
    this.box.replaceChildren(form);
    specimen.focus();
  }
}
