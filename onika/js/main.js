// Onika: the page that assembles, verifies, runs and watches a Chimera subsystem (paper 3.3,
// "a hypermedia user interface"). Everything it does is a command of the control API, the same
// commands the shell takes (docs/control-api.md); the page keeps no state the subsystem lacks,
// except configurations being drawn that have no task yet.

import { api, token, setToken, Stream } from './api.js';
import { Canvas } from './canvas.js';
import { el, clear, durationText } from './dom.js';
import { EventList } from './events.js';
import { Library, modulePage } from './library.js';
import { OpenDialog } from './open.js';
import { Plot, parseLog } from './plots.js';
import { TaskTable, timingPage } from './tasks.js';

const $ = (id) => document.getElementById(id);
// The status is read again at once when an event says something changed; the poll catches what
// no event names (a task's figures, the model after another user's edit).
const POLL_MS = 1000;
const TIMING_HZ = 2;

const page = {
  model: null,
  status: null,
  role: 'viewer',
  editing: '', // the configuration the canvas shows and edits
  compare: '', // the one shown beside it
  drafts: [], // configurations named on the page that have no task yet
  stateKey: '',
  timingTask: '', // the task whose timing the details show, redrawn at each timing frame
};

function say(text, kind = 'info') {
  const item = el('li', { class: kind }, `${new Date().toLocaleTimeString()} ${text}`);
  $('messages').prepend(item);
  while ($('messages').children.length > 200) $('messages').lastChild.remove();
}

/** One command; its text (or its one-line reason) goes to the messages. null if refused. */
async function run(command, args) {
  try {
    const reply = args ? await api.verb(command, args) : await api.command(command);
    const text = (reply.text || '').trim();
    say(`${command}${text ? `: ${text.split('\n').slice(-3).join(' / ')}` : ''}`);
    return reply;
  } catch (e) {
    say(`${args ? command : command.split(' ')[0]}: ${e.message}`, 'error');
    return null;
  } finally {
    await refresh(true);
  }
}

function configurationNames() {
  const names = page.model ? page.model.configurations.map((c) => c.name) : [];
  return [...names, ...page.drafts.filter((d) => !names.includes(d))];
}

function configuration(name) {
  const found = page.model && page.model.configurations.find((c) => c.name === name);
  return found || (page.drafts.includes(name) ? { name, tasks: [], legal: false, violations: [], draft: true } : null);
}

function verdictText(c) {
  if (!c) return '';
  if (c.draft || !c.tasks.length) return 'no task yet';
  if (c.legal) return 'legal';
  return `not legal: ${c.violations.map((v) => v.reason).join('; ')}`;
}

function states() {
  return new Map((page.status ? page.status.tasks : []).map((t) => [t.name, t.state]));
}

// ---- drawing ---------------------------------------------------------------------------------

// Where boxes were moved on the canvas: the browser's, per subsystem and configuration (a subsystem
// file holds no layout; `save` writes none). Anyone may move boxes: it changes only this view.
const layout = {
  key: (configuration) => `onika-layout:${page.status ? page.status.subsystem : ''}:${configuration}`,
  get(configuration) {
    try {
      return JSON.parse(localStorage.getItem(this.key(configuration))) || {};
    } catch {
      return {};
    }
  },
  set(configuration, task, at) {
    localStorage.setItem(this.key(configuration), JSON.stringify({ ...this.get(configuration), [task]: at }));
  },
  reset(configuration) {
    localStorage.removeItem(this.key(configuration));
  },
};
const canvas = new Canvas($('canvas'), { onDrop: (m) => openAdd(m), onPort: renamePort, onTask: showTask, label: 'configuration being edited', layout });
const compareCanvas = new Canvas($('compare-canvas'), { onDrop: null, onPort: renamePort, onTask: showTask, label: 'configuration beside', layout });

function drawHeader() {
  const s = page.status;
  if (!s) return;
  $('subsystem-name').textContent = s.subsystem;
  $('clock').textContent = `${s.clock} clock · ${(s.now_ns / 1e9).toFixed(1)} s`;
  $('configuration-on').textContent = `on: ${s.configuration}`;
  $('illegal-flag').hidden = !s.illegal_configuration;
  $('role').textContent = page.role;
}

function drawConfigurations() {
  const tabs = $('configuration-tabs');
  clear(tabs);
  const on = page.status ? page.status.configuration : '';
  for (const name of configurationNames()) {
    const c = configuration(name);
    const tab = el(
      'button',
      {
        type: 'button',
        role: 'tab',
        class: `tab${name === page.editing ? ' selected' : ''}${c && !c.draft && c.tasks.length && !c.legal ? ' illegal' : ''}`,
        'aria-selected': name === page.editing ? 'true' : 'false',
        'data-configuration': name,
      },
      name,
      name === on ? el('span', { class: 'on-mark', title: 'on now' }, ' ●') : '',
    );
    tab.addEventListener('click', () => {
      page.editing = name;
      drawAll();
    });
    tabs.append(tab);
  }
  const select = $('compare-with');
  const keep = page.compare;
  clear(select);
  select.append(el('option', { value: '' }, '—'));
  for (const name of configurationNames()) if (name !== page.editing) select.append(el('option', { value: name }, name));
  select.value = configurationNames().includes(keep) && keep !== page.editing ? keep : '';
  page.compare = select.value;
}

function drawCanvas(view, name, verdictId, nameId, switchId) {
  const c = configuration(name);
  view.draw(page.model, c, states());
  $(nameId).textContent = name;
  const verdict = $(verdictId);
  verdict.textContent = verdictText(c);
  verdict.className = `verdict ${c && c.legal ? 'legal' : 'not-legal'}`;
  const on = page.status && page.status.configuration === name;
  const button = $(switchId);
  button.hidden = page.role !== 'operator';
  button.disabled = !c || on || !c.legal;
  button.textContent = on ? 'on now' : 'Switch to it';
}

function drawAll() {
  if (!page.model || !page.status) return;
  if (!configurationNames().includes(page.editing)) page.editing = page.status.configuration;
  drawHeader();
  drawConfigurations();
  drawCanvas(canvas, page.editing, 'verdict', 'editing-name', 'switch');
  $('compare-view').hidden = !page.compare;
  if (page.compare) drawCanvas(compareCanvas, page.compare, 'compare-verdict', 'compare-name', 'compare-switch');
  tasks.canWrite = page.role === 'operator';
  tasks.draw(page.status);
  drawVariables();
}

function drawVariables() {
  const select = $('plot-variables');
  const chosen = new Set([...select.selectedOptions].map((o) => o.value));
  const names = new Set();
  for (const t of page.model.tasks) for (const p of t.ports) names.add(p.variable);
  const sorted = [...names].sort();
  if (sorted.join(',') === [...select.options].map((o) => o.value).join(',')) return;
  clear(select);
  for (const n of sorted) select.append(el('option', { value: n, selected: chosen.has(n) }, n));
}

// Replies may come back out of order (a poll started before a command, answered after it): only
// the newest request's answer is drawn, and every answer carries the model with the status, so
// that the page never shows a model older than its status.
let asked = 0;
let drawn = 0;

async function refresh(force) {
  const ticket = ++asked;
  try {
    const [status, model] = await Promise.all([api.status(), api.model()]);
    if (ticket < drawn) return;
    drawn = ticket;
    page.status = status;
    page.model = model;
    $('connection').textContent = '';
    const key = JSON.stringify([status.tasks.map((t) => [t.name, t.state, t.cycles, t.missed, t.last_error]), status.configuration, model]);
    if (force || key !== page.stateKey) {
      page.stateKey = key;
      drawAll();
    } else {
      drawHeader();
    }
  } catch (e) {
    $('connection').textContent = e.message;
  }
}

// ---- assembly --------------------------------------------------------------------------------

function uniqueName(base) {
  const taken = new Set(page.model.tasks.map((t) => t.name));
  if (!taken.has(base)) return base;
  for (let i = 2; ; ++i) if (!taken.has(`${base}${i}`)) return `${base}${i}`;
}

function openAdd(module) {
  if (page.role !== 'operator') return say('adding a task needs an operator token', 'error');
  const on = page.status.configuration;
  if (page.editing === on && configuration(on).tasks.length === 0) {
    // The configuration on now is never redefined: the first task starts a new one.
    const name = uniqueName('assembly');
    page.drafts.push(name);
    page.editing = name;
    drawAll();
  } else if (page.editing === on) {
    return say(`configuration ${on} is on: make a new configuration (+ configuration) to change it`, 'error');
  }
  $('add-module').textContent = module;
  $('add-name').value = uniqueName(module.split('_')[0]);
  $('add-error').textContent = '';
  $('add-dialog').dataset.module = module;
  $('add-dialog').showModal();
}

function entryOf(task, rename) {
  const entry = { name: task.name, module: task.module, criticality: task.criticality };
  if (task.period_ns !== null) entry.period = durationText(task.period_ns);
  if (task.cpu !== null) entry.cpu = task.cpu;
  if (task.process && task.process !== 'main') entry.process = task.process;
  if (Object.keys(task.params).length) entry.params = task.params;
  if (Object.keys(rename).length) entry.rename = rename;
  return entry;
}

/** Sends `add` for `entry`; `params`, when given, is the file's YAML text of its params. */
function addTaskCommand(entry, params) {
  if (!params) return api.verb('add', [entry]);
  const yaml = params.startsWith('{') ? params : `{${params}}`;
  // Params come as the file's YAML: sent on the shell's line, the rest as JSON (a YAML flow map).
  return api.command(`add ${JSON.stringify({ ...entry, params: undefined }).replace(/}$/, `, "params": ${yaml}}`)}`);
}

async function addTask(event) {
  event.preventDefault();
  const module = $('add-dialog').dataset.module;
  const entry = { name: $('add-name').value.trim(), module, criticality: $('add-criticality').value };
  if ($('add-period').value.trim()) entry.period = $('add-period').value.trim();
  let reply;
  try {
    reply = await addTaskCommand(entry, $('add-params').value.trim());
  } catch (e) {
    $('add-error').textContent = e.message;
    return;
  }
  $('add-dialog').close();
  say(`add ${entry.name}: ${(reply.text || '').trim()}`);
  const c = configuration(page.editing);
  await define(page.editing, [...c.tasks, reply.task]);
}

async function define(name, taskNames) {
  const reply = await run(`define ${name} ${taskNames.join(' ')}`.trim());
  if (reply) page.drafts = page.drafts.filter((d) => d !== name);
  return reply;
}

/**
 * Task `task` as `entry` says (params as YAML text when `params` is given): a task is added whole,
 * so the configurations that hold it are defined without it, it is removed and added anew, and
 * they are defined as they were. An entry the subsystem refuses (a parameter out of its range)
 * puts the task back as it was. Returns the refusal's reason, or '' when it was changed.
 */
async function replaceTask(task, entry, params) {
  const holders = page.model.configurations.filter((c) => c.tasks.includes(task.name));
  const on = page.status.configuration;
  if (holders.some((c) => c.name === on))
    return `${task.name} is in ${on}, which is on: it can be changed in another configuration, or once ${on} is not on`;
  // The subsystem adds a task only while every task is NOT-CREATED (docs/control-api.md, add):
  // asked now, the remove would go through and the add would not.
  const created = page.status.tasks.find((t) => t.state !== 'NOT-CREATED');
  if (created) return `a task is changed while every task is NOT-CREATED, and ${created.name} is ${created.state}`;
  for (const c of holders) if (!(await define(c.name, c.tasks.filter((n) => n !== task.name)))) return 'refused';
  let refusal = '';
  if (await run(`remove ${task.name}`)) {
    try {
      const reply = await addTaskCommand(entry, params);
      say(`add ${task.name}: ${(reply.text || '').trim()}`);
    } catch (e) {
      refusal = e.message;
      say(`add ${task.name}: ${refusal}`, 'error');
      await run('add', [entryOf(task, task.rename)]);
    }
  } else {
    refusal = 'refused';
  }
  for (const c of holders) await define(c.name, c.tasks);
  return refusal;
}

async function renamePort(task, port) {
  if (page.role !== 'operator') return;
  const variable = window.prompt(`Bind port ${port.port} of ${task.name} to the variable`, port.variable);
  if (variable === null || variable.trim() === port.variable) return;
  const rename = { ...task.rename };
  if (variable.trim() === port.port) delete rename[port.port];
  else rename[port.port] = variable.trim();
  const refusal = await replaceTask(task, entryOf(task, rename));
  if (refusal) say(`rename ${port.port} of ${task.name}: ${refusal}`, 'error');
}

/** The form that edits a task's period, criticality and parameters (added anew with them). */
function taskEditor(task) {
  const criticality = el('select', { id: 'edit-criticality' }, ...['hard', 'soft'].map((c) => el('option', { selected: c === task.criticality }, c)));
  const params = el('textarea', { id: 'edit-params', rows: 4, cols: 34, class: 'mono', spellcheck: 'false' });
  // JSON is a YAML flow map: the params as the model holds them, to be edited as in a file.
  params.value = Object.keys(task.params).length ? JSON.stringify(task.params) : '';
  const period = el('input', { id: 'edit-period', value: task.period_ns === null ? '' : durationText(task.period_ns), size: 8 });
  const error = el('p', { id: 'edit-error', class: 'error-text' });
  const form = el(
    'form',
    { id: 'edit-task', class: 'edit-task', 'data-task': task.name },
    el('h4', {}, 'Edit'),
    el('label', {}, 'period ', period),
    el('label', {}, 'criticality ', criticality),
    el('label', {}, 'params ', params),
    error,
    el('button', { type: 'submit', id: 'edit-apply' }, 'Apply'),
  );
  form.addEventListener('submit', async (event) => {
    event.preventDefault();
    const entry = { ...entryOf(task, task.rename), criticality: criticality.value, params: undefined };
    if (period.value.trim()) entry.period = period.value.trim();
    else delete entry.period;
    error.textContent = '';
    const refusal = await replaceTask(task, entry, params.value.trim());
    if (refusal) {
      error.textContent = refusal;
      return;
    }
    const now = page.model.tasks.find((t) => t.name === task.name);
    if (now) showTask(now);
  });
  return form;
}

function showTask(task) {
  if (page.timingTask) watchTiming('');
  const details = $('details');
  clear(details);
  const c = configuration(page.editing);
  const remove = el('button', { type: 'button', id: 'remove-task' }, `Take ${task.name} out of ${page.editing}`);
  remove.addEventListener('click', async () => {
    const left = c.tasks.filter((n) => n !== task.name);
    if (!(await define(page.editing, left))) return;
    if (!page.model.configurations.some((k) => k.tasks.includes(task.name))) await run(`remove ${task.name}`);
  });
  details.append(
    el('h3', {}, task.name),
    el('p', {}, `${task.module} · ${durationText(task.period_ns)} · ${task.criticality}`),
    el(
      'table',
      { class: 'ports' },
      el('tr', {}, el('th', {}, 'kind'), el('th', {}, 'port'), el('th', {}, 'variable'), el('th', {}, 'shape')),
      ...task.ports.map((p) => el('tr', {}, el('td', {}, p.kind), el('td', { class: 'mono' }, p.port), el('td', { class: 'mono' }, p.variable), el('td', {}, p.shape))),
    ),
    page.role === 'operator' && c && c.tasks.includes(task.name) ? remove : '',
    page.role === 'operator' ? taskEditor(task) : '',
  );
}

// ---- run control, plots ---------------------------------------------------------------------

const tasks = new TaskTable($('tasks'), {
  onSignal: (action, name) => run(`${action} ${name}`),
  onStats: async (name) => {
    try {
      const reply = await api.command(`stats ${name}`);
      watchTiming(name);
      showTiming(reply.stats);
    } catch (e) {
      say(`stats ${name}: ${e.message}`, 'error');
    }
  },
});

/** The timing of page.timingTask in the details, while they show it. */
function showTiming(stats) {
  if (!page.timingTask) return;
  clear($('details'));
  $('details').append(timingPage(page.timingTask, stats));
}

/** Follows `name`'s timing on the watch stream ('' for none: events only). */
function watchTiming(name) {
  page.timingTask = name;
  watch.subscribe(name ? { events: true, timing_hz: TIMING_HZ, tasks: [name] } : { events: true });
}

// What happens, and the tasks' figures, on one stream of their own: state changes redraw the
// page at once, and the timing in the details follows the task as it runs.
const events = new EventList($('events'));
const watch = new Stream(
  (frame) => {
    if (frame.kind === 'timing') {
      if (frame.stats.tasks[page.timingTask]) showTiming(frame.stats);
      return;
    }
    events.add(frame);
    if (frame.kind === 'missed' || frame.event.type !== 'log') refresh(false);
  },
  (text) => ($('events-state').textContent = text === 'streaming' ? '' : text),
  { reconnect: true },
);

const plot = new Plot($('plot'));
const stream = new Stream(
  (frame) => {
    if (frame.kind === 'sample') plot.addSample(frame);
    else if (frame.kind === 'samples') plot.addSamples(frame);
  },
  (text) => ($('plot-state').textContent = text),
);

$('plot-live').addEventListener('click', () => {
  const variables = [...$('plot-variables').selectedOptions].map((o) => o.value);
  if (!variables.length) return say('choose the variables to plot', 'error');
  plot.reset(true);
  // The samples in thirty frames a second: the page draws no more often, and a frame per sample
  // at 1 kHz would cost the machine the real-time tasks run on (docs/control-api.md, "Streams").
  stream.subscribe({ variables, rate_hz: Number($('plot-rate').value) || 100, batch_hz: 30 });
});
$('plot-stop').addEventListener('click', () => {
  stream.close();
  $('plot-state').textContent = 'stopped';
});
$('plot-file').addEventListener('change', async (event) => {
  const file = event.target.files[0];
  if (!file) return;
  try {
    stream.close();
    plot.showLog(parseLog(await file.text(), file.name));
    $('plot-state').textContent = `${file.name}`;
  } catch (e) {
    say(e.message, 'error');
  }
});

// ---- the rest of the wiring -----------------------------------------------------------------

$('add-form').addEventListener('submit', addTask);
$('add-cancel').addEventListener('click', () => $('add-dialog').close());
$('switch').addEventListener('click', () => run(`switch ${page.editing}`));
$('auto-layout').addEventListener('click', () => {
  layout.reset(page.editing);
  drawAll();
});
$('compare-switch').addEventListener('click', () => run(`switch ${page.compare}`));
$('compare-with').addEventListener('change', (event) => {
  page.compare = event.target.value;
  drawAll();
});
$('new-configuration').addEventListener('click', () => {
  const name = window.prompt('Name of the new configuration', uniqueName('configuration'));
  if (!name || !/^[A-Za-z_][A-Za-z0-9_]*$/.test(name)) return name && say(`'${name}' is not a name`, 'error');
  if (!configurationNames().includes(name)) page.drafts.push(name);
  page.editing = name;
  drawAll();
});
$('save').addEventListener('click', async () => {
  try {
    const reply = await api.command('save');
    $('save-text').value = reply.yaml;
    const link = $('save-download');
    URL.revokeObjectURL(link.href);
    link.href = URL.createObjectURL(new Blob([reply.yaml], { type: 'application/yaml' }));
    link.download = `${page.status.subsystem}.yaml`;
    $('save-dialog').showModal();
  } catch (e) {
    say(`save: ${e.message}`, 'error');
  }
});
$('save-close').addEventListener('click', () => $('save-dialog').close());

const opener = new OpenDialog($('open-dialog'), {
  onOpened: async (reply) => {
    // Another subsystem: nothing drawn for the one before is kept.
    page.drafts = [];
    page.editing = reply.configuration;
    page.compare = '';
    stream.close();
    plot.reset(false);
    if (page.timingTask) watchTiming('');
    say(`open ${reply.file}: ${reply.text.trim()}`);
    await refresh(true);
  },
});
$('open').addEventListener('click', () => opener.show());

const library = new Library($('library'), {
  onShow: (m) => {
    if (page.timingTask) watchTiming('');
    clear($('details'));
    $('details').append(modulePage(m));
  },
});

async function start() {
  try {
    page.role = await api.whoami();
  } catch (e) {
    $('login').hidden = false;
    $('app').hidden = true;
    if (token()) say(e.message, 'error');
    return;
  }
  $('login').hidden = true;
  $('app').hidden = false;
  $('save').hidden = false;
  $('open').hidden = page.role !== 'operator';
  document.body.dataset.role = page.role;
  library.set(await api.modules());
  await refresh(true);
  watchTiming('');
  document.body.dataset.ready = 'true';
  setInterval(() => refresh(false), POLL_MS);
}

$('login-form').addEventListener('submit', (event) => {
  event.preventDefault();
  setToken($('login-token').value);
  start();
});

start();
