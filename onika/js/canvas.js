// One configuration drawn as the paper draws it (Figures 4, 8 and 9): each task a box with its
// input ports on the left and its outputs on the right, and a link wherever an output and an
// input are bound to the same state variable. Nobody draws a wire: the links follow from the
// port names and the renames, which is the methodology's point. Fan-out is one output drawn to
// several inputs; a variable with no producer, or with two, is drawn in red with the reason.

import { svg, clear, durationText } from './dom.js';

const PRODUCES = new Set(['out-var', 'out-const']);
const BOX_WIDTH = 190;
const COLUMN = 290;
const HEADER = 34;
const ROW = 18;
const GAP = 36;
const MARGIN = 40;

/** The links of a configuration: output to input of the same variable, and what has no end. */
export function linksOf(tasks) {
  const producers = new Map();
  for (const t of tasks)
    for (const p of t.ports) if (PRODUCES.has(p.kind)) producers.set(p.variable, [...(producers.get(p.variable) || []), { task: t, port: p }]);
  const links = [];
  const unproduced = [];
  for (const t of tasks)
    for (const p of t.ports) {
      if (PRODUCES.has(p.kind)) continue;
      const from = producers.get(p.variable);
      if (!from) unproduced.push({ task: t, port: p });
      else for (const f of from) links.push({ from: f.task, out: f.port, to: t, in: p, variable: p.variable });
    }
  return { links, unproduced, producers };
}

/** Columns from the data flow: a task one column right of what it reads, loops cut where met. */
export function layers(tasks, links) {
  const index = new Map(tasks.map((t, i) => [t.name, i]));
  const next = tasks.map(() => []);
  // Constants (ndof) size ports but carry no data flow: they do not place a task.
  for (const l of links) if (l.from !== l.to && l.in.kind !== 'in-const') next[index.get(l.from.name)].push(index.get(l.to.name));
  const mark = tasks.map(() => 0); // 0 new, 1 on the path, 2 done
  const forward = tasks.map(() => []);
  const visit = (u) => {
    mark[u] = 1;
    for (const v of next[u]) {
      if (mark[v] === 1) continue; // a back edge: the loop is closed by it, not laid out by it
      if (!forward[u].includes(v)) forward[u].push(v);
      if (mark[v] === 0) visit(v);
    }
    mark[u] = 2;
  };
  // Sources first (tasks nothing in the configuration feeds), then the rest in file order.
  const fed = new Set(links.filter((l) => l.from !== l.to && l.in.kind !== 'in-const').map((l) => l.to.name));
  tasks.forEach((t, i) => !fed.has(t.name) && mark[i] === 0 && visit(i));
  tasks.forEach((t, i) => mark[i] === 0 && visit(i));
  const column = tasks.map(() => 0);
  for (let round = 0; round < tasks.length; ++round)
    forward.forEach((vs, u) => vs.forEach((v) => (column[v] = Math.max(column[v], column[u] + 1))));
  return column;
}

export class Canvas {
  constructor(root, { onDrop, onPort, onTask, label }) {
    this.root = root;
    this.onDrop = onDrop;
    this.onPort = onPort;
    this.onTask = onTask;
    this.svg = svg('svg', { class: 'canvas', role: 'img', 'aria-label': label || 'configuration' });
    root.append(this.svg);
    root.addEventListener('dragover', (event) => {
      event.preventDefault();
      event.dataTransfer.dropEffect = 'copy';
      root.classList.add('drop-target');
    });
    root.addEventListener('dragleave', () => root.classList.remove('drop-target'));
    root.addEventListener('drop', (event) => {
      event.preventDefault();
      root.classList.remove('drop-target');
      const module = event.dataTransfer.getData('application/x-chimera-module') || event.dataTransfer.getData('text/plain');
      if (module && this.onDrop) this.onDrop(module);
    });
  }

  /** Draws `configuration` ({name, tasks, violations}) of `model`, states from `status`. */
  draw(model, configuration, states) {
    clear(this.svg);
    const tasks = configuration ? configuration.tasks.map((n) => model.tasks.find((t) => t.name === n)).filter(Boolean) : [];
    this.root.dataset.configuration = configuration ? configuration.name : '';
    if (!tasks.length) {
      this.svg.setAttribute('viewBox', '0 0 600 160');
      this.svg.append(svg('text', { x: 300, y: 80, class: 'empty-hint' }, 'Drag modules here from the library'));
      return;
    }
    const bad = new Set((configuration.violations || []).map((v) => v.variable).filter(Boolean));
    const { links, unproduced } = linksOf(tasks);
    const column = layers(tasks, links);
    const place = new Map();
    const heights = [];
    tasks.forEach((t, i) => {
      const ins = t.ports.filter((p) => !PRODUCES.has(p.kind));
      const outs = t.ports.filter((p) => PRODUCES.has(p.kind));
      const h = HEADER + Math.max(ins.length, outs.length, 1) * ROW + 8;
      const c = column[i];
      const y = heights[c] || MARGIN;
      heights[c] = y + h + GAP;
      place.set(t.name, { x: MARGIN + c * COLUMN, y, h, ins, outs });
    });
    const bottom = Math.max(...heights) - GAP;
    const portY = (box, list, p) => box.y + HEADER + list.indexOf(p) * ROW + ROW / 2;
    const linkLayer = svg('g', { class: 'links' });
    const boxLayer = svg('g', { class: 'boxes' });
    let loop = 0;
    for (const l of links) {
      const a = place.get(l.from.name);
      const b = place.get(l.to.name);
      const x1 = a.x + BOX_WIDTH;
      const y1 = portY(a, a.outs, l.out);
      const x2 = b.x;
      const y2 = portY(b, b.ins, l.in);
      let d;
      let lx;
      let ly;
      if (b.x > a.x) {
        const bend = Math.max(40, (x2 - x1) / 2);
        d = `M${x1},${y1} C${x1 + bend},${y1} ${x2 - bend},${y2} ${x2},${y2}`;
        lx = (x1 + x2) / 2;
        ly = (y1 + y2) / 2 - 4;
      } else {
        // A loop back (the robot's measurement to the controller): under every box.
        const under = bottom + 24 + 16 * loop++;
        d = `M${x1},${y1} H${x1 + 16} V${under} H${x2 - 16} V${y2} H${x2}`;
        lx = (x1 + x2) / 2;
        ly = under - 4;
      }
      const cls = `link${l.in.kind === 'in-const' ? ' const' : ''}${bad.has(l.variable) ? ' bad' : ''}`;
      linkLayer.append(
        svg('path', { d, class: cls, 'data-variable': l.variable, 'data-from': l.from.name, 'data-to': l.to.name }),
        svg('text', { x: lx, y: ly, class: `link-label${l.in.kind === 'in-const' ? ' const' : ''}${bad.has(l.variable) ? ' bad' : ''}` }, l.variable),
      );
    }
    for (const u of unproduced) {
      const b = place.get(u.task.name);
      const y = portY(b, b.ins, u.port);
      linkLayer.append(
        svg('path', { d: `M${b.x - 34},${y} H${b.x}`, class: `link dangling${bad.has(u.port.variable) ? ' bad' : ''}`, 'data-variable': u.port.variable }),
        svg('text', { x: b.x - 38, y: y + 4, class: `link-label end${bad.has(u.port.variable) ? ' bad' : ''}` }, u.port.variable),
      );
    }
    for (const t of tasks) boxLayer.append(this.box(t, place.get(t.name), states.get(t.name), bad));
    this.svg.append(linkLayer, boxLayer);
    const width = MARGIN * 2 + (Math.max(...column) + 1) * COLUMN - (COLUMN - BOX_WIDTH);
    const height = bottom + 40 + 16 * loop;
    this.svg.setAttribute('viewBox', `-40 0 ${width + 40} ${height}`);
  }

  box(task, at, state, bad) {
    const g = svg('g', { class: `task state-${(state || 'NOT-CREATED').replace(/\s/g, '-')}`, 'data-task': task.name });
    const period = task.period_ns === null ? 'aperiodic' : durationText(task.period_ns);
    g.append(
      svg('rect', { x: at.x, y: at.y, width: BOX_WIDTH, height: at.h, rx: 6, class: 'task-box' }),
      svg('text', { x: at.x + 10, y: at.y + 15, class: 'task-name' }, task.name),
      svg('text', { x: at.x + 10, y: at.y + 28, class: 'task-module' }, `${task.module} · ${period} · ${state || 'NOT-CREATED'}`),
    );
    g.querySelector('rect').addEventListener('click', () => this.onTask && this.onTask(task));
    const port = (p, i, left) => {
      const y = at.y + HEADER + i * ROW + ROW / 2;
      const x = left ? at.x : at.x + BOX_WIDTH;
      const cls = `port port-${p.kind}${bad.has(p.variable) ? ' bad' : ''}${p.renamed ? ' renamed' : ''}`;
      const label = p.renamed ? `${p.port} → ${p.variable}` : p.port;
      const node = svg(
        'g',
        { class: cls, 'data-port': p.port, 'data-variable': p.variable, tabindex: 0 },
        svg('circle', { cx: x, cy: y, r: 4 }),
        svg('text', { x: left ? x + 8 : x - 8, y: y + 4, class: left ? '' : 'end' }, label),
        svg('title', {}, `${p.kind} ${p.port}: ${p.shape}, bound to ${p.variable} (click to rename)`),
      );
      node.addEventListener('click', () => this.onPort && this.onPort(task, p));
      g.append(node);
    };
    at.ins.forEach((p, i) => port(p, i, true));
    at.outs.forEach((p, i) => port(p, i, false));
    return g;
  }
}
