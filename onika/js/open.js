// Opening a subsystem file: an example of the tree (GET /api/examples) or a file of the user's,
// shown and editable before it is opened. Opening replaces the running subsystem (POST /api/open,
// docs/control-api.md): every task is turned off and killed, then the file's start configuration
// is turned on, as chimera run FILE starts it. A file the loader refuses changes nothing, and its
// message names the line and the key, as chimera verify's does.

import { api } from './api.js';
import { el, clear } from './dom.js';

export class OpenDialog {
  /** `onOpened(reply)` after a file was opened. */
  constructor(dialog, { onOpened }) {
    this.dialog = dialog;
    this.onOpened = onOpened;
    this.examples = null;
    this.$ = (id) => dialog.querySelector(`#${id}`);
    this.$('open-file').addEventListener('change', (event) => this.fromFile(event.target.files[0]));
    this.$('open-cancel').addEventListener('click', () => dialog.close());
    this.$('open-ok').addEventListener('click', () => this.open());
    // A message is about the text it was given: an edit makes it old.
    this.$('open-text').addEventListener('input', () => (this.$('open-error').textContent = ''));
  }

  async show() {
    this.$('open-error').textContent = '';
    if (!this.examples) {
      try {
        this.examples = await api.examples();
      } catch (e) {
        this.$('open-error').textContent = `the examples: ${e.message}`;
        this.examples = [];
      }
      this.drawExamples();
    }
    this.dialog.showModal();
  }

  drawExamples() {
    const list = this.$('open-examples');
    clear(list);
    for (const example of this.examples) {
      const button = el('button', { type: 'button', 'data-example': example.name }, example.name);
      button.addEventListener('click', () => this.choose(example.name, example.text));
      list.append(el('li', {}, button, ' ', el('span', { class: 'muted' }, example.title)));
    }
  }

  choose(name, text) {
    this.$('open-name').value = name;
    this.$('open-text').value = text;
    this.$('open-error').textContent = '';
    for (const b of this.$('open-examples').querySelectorAll('button'))
      b.classList.toggle('selected', b.dataset.example === name);
  }

  async fromFile(file) {
    if (!file) return;
    try {
      this.choose(file.name, await file.text());
    } catch (e) {
      this.$('open-error').textContent = `${file.name}: ${e.message}`;
    }
  }

  async open() {
    const file = this.$('open-name').value.trim();
    const text = this.$('open-text').value;
    if (!file || !text.trim()) {
      this.$('open-error').textContent = 'choose an example or a file first';
      return;
    }
    const button = this.$('open-ok');
    button.disabled = true;
    try {
      const reply = await api.open(file, text);
      this.dialog.close();
      this.onOpened(reply);
    } catch (e) {
      this.$('open-error').textContent = e.message;
    } finally {
      button.disabled = false;
    }
  }
}
