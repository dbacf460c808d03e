// Run control: every task with its lifecycle state by colour, its figures (cycles, missed
// deadlines, overruns), its last error, and the signals its state allows (paper 3.3: spawn, on,
// off, kill, and clear for a task in ERROR).

import { el, clear, durationText } from './dom.js';

// The signals each state takes (docs/lifecycle.md).
const ACTIONS = {
  'NOT-CREATED': ['spawn'],
  OFF: ['on', 'kill'],
  ON: ['off', 'kill'],
  ERROR: ['clear', 'kill'],
};

export class TaskTable {
  constructor(root, { onSignal, onStats }) {
    this.root = root;
    this.onSignal = onSignal;
    this.onStats = onStats;
    this.canWrite = true;
  }

  draw(status) {
    clear(this.root);
    const head = el(
      'tr',
      {},
      ...['task', 'module', 'state', 'period', 'cpu', 'cycles', 'missed', 'overruns', 'last error', ''].map((h) => el('th', {}, h)),
    );
    const rows = status.tasks.map((t) => {
      const buttons = el('td', { class: 'actions' });
      if (this.canWrite)
        for (const action of ACTIONS[t.state] || []) {
          const b = el('button', { type: 'button', 'data-action': action, title: `${action} ${t.name}` }, action);
          b.addEventListener('click', () => this.onSignal(action, t.name));
          buttons.append(b);
        }
      const stats = el('button', { type: 'button', 'data-action': 'stats', title: `timing of ${t.name}` }, 'timing');
      stats.addEventListener('click', () => this.onStats(t.name));
      buttons.append(stats);
      return el(
        'tr',
        { 'data-task': t.name, 'data-state': t.state },
        el('td', { class: 'mono' }, t.name),
        el('td', {}, t.module),
        el('td', {}, el('span', { class: `state state-${t.state}` }, t.state)),
        el('td', {}, durationText(t.period_ns || null)),
        el('td', {}, t.cpu),
        el('td', { class: 'num' }, t.cycles),
        el('td', { class: `num${t.missed ? ' warn' : ''}` }, t.missed),
        el('td', { class: 'num' }, t.overruns),
        el('td', { class: 'error-text' }, t.last_error),
        buttons,
      );
    });
    this.root.append(el('table', { class: 'tasks' }, head, ...rows));
  }
}

/** One task's release latency and execution time histograms, from `stats TASK`. */
export function timingPage(name, stats) {
  const t = stats.tasks[name] || {};
  const histogram = (title, buckets) => {
    if (!buckets || !buckets.length) return el('p', {}, `${title}: no records yet`);
    const most = Math.max(...buckets.map(([, n]) => n));
    return el(
      'figure',
      { class: 'histogram' },
      el('figcaption', {}, title),
      ...buckets.map(([upper, n]) =>
        el(
          'div',
          { class: 'bar-row' },
          el('span', { class: 'bar-label' }, `≤ ${nsText(upper)}`),
          el('meter', { min: 0, max: most, value: n }),
          el('span', { class: 'num' }, n),
        ),
      ),
    );
  };
  const figure = (label, value) => el('tr', {}, el('th', {}, label), el('td', { class: 'num' }, value));
  const lat = t.latency_ns || {};
  const exec = t.exec_ns || {};
  return el(
    'article',
    { class: 'timing', 'data-task': name, 'data-cycles': t.cycles },
    el('h3', {}, `Timing of ${name}`),
    el(
      'table',
      {},
      figure('cycles', t.cycles),
      figure('missed deadlines', t.missed),
      figure('overruns', t.overruns),
      figure('skipped releases', t.skipped),
      figure('release latency p50 / p99 / max', `${nsText(lat.p50)} / ${nsText(lat.p99)} / ${nsText(lat.max)}`),
      figure(`execution time (${t.exec_clock}) p50 / p99 / max`, `${nsText(exec.p50)} / ${nsText(exec.p99)} / ${nsText(exec.max)}`),
    ),
    histogram('release latency', (t.histograms || {}).latency_ns),
    histogram('execution time', (t.histograms || {}).exec_ns),
  );
}

function nsText(ns) {
  if (ns === undefined || ns === null) return '–';
  if (ns >= 1e6) return `${(ns / 1e6).toPrecision(3)} ms`;
  if (ns >= 1e3) return `${(ns / 1e3).toPrecision(3)} µs`;
  return `${ns} ns`;
}
