// The module library as hypermedia: every module of the running chimera with its ports,
// parameters and documentation; searched by name or by port ("produces x_d", "consumes tau_r").
// Each entry is dragged onto the canvas to add a task of it.

import { el, clear } from './dom.js';

const PRODUCES = new Set(['out-var', 'out-const']);

function portsOf(module, produced) {
  return module.ports.filter((p) => PRODUCES.has(p.kind) === produced).map((p) => p.name);
}

/** Why `module` matches `query`, or null: "", or the ports that matched. */
export function matchModule(module, query) {
  const q = query.trim().toLowerCase();
  if (!q) return '';
  const words = q.split(/\s+/);
  if ((words[0] === 'produces' || words[0] === 'consumes') && words.length > 1) {
    const ports = portsOf(module, words[0] === 'produces').filter((p) => p.toLowerCase() === words[1]);
    return ports.length ? `${words[0]} ${ports[0]}` : null;
  }
  if (module.name.toLowerCase().includes(q) || module.summary.toLowerCase().includes(q)) return '';
  const port = module.ports.find((p) => p.name.toLowerCase() === q);
  if (port) return `${PRODUCES.has(port.kind) ? 'produces' : 'consumes'} ${port.name}`;
  return null;
}

export class Library {
  constructor(root, { onShow }) {
    this.root = root;
    this.onShow = onShow;
    this.modules = [];
    this.search = el('input', {
      type: 'search',
      id: 'library-search',
      placeholder: 'module, port, "produces x_d"',
      'aria-label': 'search the module library',
    });
    this.list = el('ul', { id: 'library-list', class: 'library-list' });
    this.search.addEventListener('input', () => this.render());
    root.append(el('h2', {}, 'Module library'), this.search, this.list);
  }

  set(modules) {
    this.modules = modules;
    this.render();
  }

  find(name) {
    return this.modules.find((m) => m.name === name);
  }

  render() {
    clear(this.list);
    for (const m of this.modules) {
      const why = matchModule(m, this.search.value);
      if (why === null) continue;
      const item = el(
        'li',
        { class: 'module', draggable: 'true', 'data-module': m.name, title: 'drag onto the canvas to add a task' },
        el('span', { class: 'module-name' }, m.name),
        el('span', { class: 'module-summary' }, why || m.summary),
      );
      item.addEventListener('dragstart', (event) => {
        event.dataTransfer.setData('application/x-chimera-module', m.name);
        event.dataTransfer.setData('text/plain', m.name);
        event.dataTransfer.effectAllowed = 'copy';
      });
      item.addEventListener('click', () => this.onShow(m));
      this.list.append(item);
    }
  }
}

/** A module's page: what it computes, its ports and its parameters. */
export function modulePage(m) {
  const ports = el(
    'table',
    { class: 'ports' },
    el('tr', {}, ...['kind', 'port', 'type', 'size', ''].map((h) => el('th', {}, h))),
    ...m.ports.map((p) =>
      el(
        'tr',
        { class: `port-${p.kind}` },
        el('td', {}, p.kind),
        el('td', { class: 'mono' }, p.name),
        el('td', {}, p.type),
        el('td', {}, p.value ? `${p.size} = [${p.value.join(', ')}]` : p.size),
        el('td', {}, p.doc),
      ),
    ),
  );
  const params = m.params.length
    ? el(
        'table',
        { class: 'params' },
        el('tr', {}, ...['param', 'type', 'default', 'accepts', 'unit', ''].map((h) => el('th', {}, h))),
        ...m.params.map((p) =>
          el(
            'tr',
            {},
            el('td', { class: 'mono' }, p.name),
            el('td', {}, p.type),
            el('td', { class: 'mono' }, p.default),
            el('td', {}, p.accepts),
            el('td', {}, p.unit),
            el('td', {}, p.doc),
          ),
        ),
      )
    : el('p', {}, 'No parameters.');
  return el(
    'article',
    { class: 'module-page', 'data-module': m.name },
    el('h3', {}, m.name),
    el('p', { class: 'summary' }, m.summary),
    m.library ? el('p', { class: 'muted' }, `from ${m.library}`) : '',
    m.resource ? el('p', {}, `Resource: ${m.resource}`) : '',
    el('h4', {}, 'Ports'),
    ports,
    el('h4', {}, 'Parameters'),
    params,
    m.doc ? el('pre', { class: 'doc' }, m.doc) : '',
  );
}
