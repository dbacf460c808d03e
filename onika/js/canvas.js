// One configuration drawn as the paper draws it (Figures 4, 8 and 9): each task a box with its
// input ports on the left and its outputs on the right, and a link wherever an output and an
// input are bound to the same state variable. Nobody draws a wire: the links follow from the
// port names and the renames, which is the methodology's point. Fan-out is one output drawn to
// several inputs; a join connector (Figure 3: several producers of one quantity, renamed apart,
// merged into one output) is drawn as a funnel whose inputs converge on its one output; a
// variable with no producer, or with two, is drawn in red with the reason.
// Boxes are placed from the data flow; one dragged elsewhere stays where it was put (the
// `layout` the page keeps per configuration), and the links follow it.

import { svg, clear, durationText } from './dom.js';

const PRODUCES = new Set(['out-var', 'out-const']);
const BOX_WIDTH = 190;
const COLUMN = 290;
const HEADER = 34;
const ROW = 18;
const GAP = 36;
const MARGIN = 40;
const SNAP = 10; // a moved box lands on this grid
const DRAG_START = 4; // a press that moves less is a click
const FUNNEL = 28; // a join connector's pointed end, where its inputs meet

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

/**
 * Columns from the data flow: a task one column right of what it reads, loops cut. The tasks are
 * ordered as in Eades, Lin and Smyth's greedy heuristic (1993): sinks to the end, sources to the
 * front, and when neither is left the first task of the file (where they choose the one that
 * feeds the most more than it is fed: files list their tasks in data-flow order, and the file's
 * choice reads as the paper's figures do). A link against that order closes a loop and does not
 * place a task. So a loop with no source (Figure 3's cameras read the pose the arm's kinematics
 * measure) is cut where the file begins it, and both cameras stand in the first column; a depth-
 * first walk from the first camera went round the loop and put the second one last.
 */
export function layers(tasks, links) {
  const index = new Map(tasks.map((t, i) => [t.name, i]));
  const next = tasks.map(() => new Set());
  const prev = tasks.map(() => new Set());
  // Constants (ndof) size ports but carry no data flow: they do not place a task.
  for (const l of links)
    if (l.from !== l.to && l.in.kind !== 'in-const') {
      const u = index.get(l.from.name);
      const v = index.get(l.to.name);
      next[u].add(v);
      prev[v].add(u);
    }
  const left = new Set(tasks.map((t, i) => i));
  const count = (set) => [...set].filter((x) => left.has(x)).length;
  const front = [];
  const back = [];
  const first = (wanted) => [...left].sort((a, b) => a - b).find(wanted);
  while (left.size > 0) {
    let u = first((x) => count(next[x]) === 0 && count(prev[x]) > 0);
    if (u !== undefined) {
      back.unshift(u);
    } else {
      u = first((x) => count(prev[x]) === 0);
      if (u === undefined) u = first(() => true);
      front.push(u);
    }
    left.delete(u);
  }
  const order = front.concat(back);
  const position = tasks.map(() => 0);
  order.forEach((u, p) => (position[u] = p));
  const column = tasks.map(() => 0);
  for (const u of order) for (const v of next[u]) if (position[v] > position[u]) column[v] = Math.max(column[v], column[u] + 1);
  return column;
}

export class Canvas {
  /**
   * `layout` ({get(configuration), set(configuration, task, {x, y})}) keeps where boxes were
   * moved; without it boxes stay where the data flow puts them.
   */
  constructor(root, { onDrop, onPort, onTask, label, layout }) {
    this.root = root;
    this.onDrop = onDrop;
    this.onPort = onPort;
    this.onTask = onTask;
    this.layout = layout;
    this.justMoved = false;
    this.last = null;
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
    this.last = [model, configuration, states];
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
      place.set(t.name, { x: MARGIN + c * COLUMN, y, h, ins, outs, join: t.connector === 'join' });
    });
    const moved = this.layout ? this.layout.get(configuration.name) : {};
    for (const [name, at] of place) {
      const to = moved[name];
      if (to && Number.isFinite(to.x) && Number.isFinite(to.y)) Object.assign(at, { x: to.x, y: to.y, moved: true });
    }
    const boxes = [...place.values()];
    const bottom = Math.max(...boxes.map((b) => b.y + b.h));
    // A join's one output is at its point, half-way down; every other port on its row.
    const portY = (box, list, p) =>
      box.join && list === box.outs && list.length === 1 ? box.y + box.h / 2 : box.y + HEADER + list.indexOf(p) * ROW + ROW / 2;
    this.portY = portY;
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
    for (const t of tasks) boxLayer.append(this.box(t, place.get(t.name), states.get(t.name), bad, configuration.name));
    this.svg.append(linkLayer, boxLayer);
    // Everything in view, boxes moved left or up of the grid too (dangling inputs' labels on the left).
    const left = Math.min(0, ...boxes.map((b) => b.x - MARGIN)) - 40;
    const top = Math.min(0, ...boxes.map((b) => b.y - MARGIN));
    const right = Math.max(...boxes.map((b) => b.x + BOX_WIDTH)) + MARGIN;
    const height = bottom + 40 + 16 * loop;
    this.svg.setAttribute('viewBox', `${left} ${top} ${right - left} ${height - top}`);
  }

  /** Draws again what it drew last (a box moved). */
  redraw() {
    if (this.last) this.draw(...this.last);
  }

  /** A pointer event's place in the drawing's coordinates. */
  point(event) {
    return new DOMPoint(event.clientX, event.clientY).matrixTransform(this.svg.getScreenCTM().inverse());
  }

  /** Lets box `g` be dragged (anywhere but by a port); where it is let go is kept in the layout. */
  draggable(g, task, at, configuration) {
    const handle = g;
    handle.addEventListener('pointerdown', (down) => {
      if (down.button !== 0 || down.target.closest('.port')) return;
      const origin = this.point(down);
      let moving = false;
      const move = (event) => {
        const p = this.point(event);
        if (!moving && Math.hypot(p.x - origin.x, p.y - origin.y) < DRAG_START) return;
        moving = true;
        g.classList.add('moving');
        g.setAttribute('transform', `translate(${p.x - origin.x},${p.y - origin.y})`);
      };
      const up = (event) => {
        handle.removeEventListener('pointermove', move);
        handle.removeEventListener('pointerup', up);
        if (!moving) return;
        // The click that follows the release is the drag's, not a click on the task.
        this.justMoved = true;
        setTimeout(() => (this.justMoved = false), 0);
        const p = this.point(event);
        const snap = (v) => Math.round(v / SNAP) * SNAP;
        this.layout.set(configuration, task.name, { x: snap(at.x + p.x - origin.x), y: snap(at.y + p.y - origin.y) });
        this.redraw();
      };
      handle.setPointerCapture(down.pointerId);
      handle.addEventListener('pointermove', move);
      handle.addEventListener('pointerup', up);
    });
  }

  box(task, at, state, bad, configuration) {
    const g = svg('g', {
      class: `task state-${(state || 'NOT-CREATED').replace(/\s/g, '-')}${at.moved ? ' moved' : ''}`,
      'data-task': task.name,
      'data-x': at.x,
      'data-y': at.y,
    });
    const period = task.period_ns === null ? 'aperiodic' : durationText(task.period_ns);
    const w = BOX_WIDTH;
    // A join connector: a funnel pointing at its output, as the paper's Figure 3 merges p' and p''.
    const body = at.join
      ? svg('polygon', {
          points: `${at.x},${at.y} ${at.x + w - FUNNEL},${at.y} ${at.x + w},${at.y + at.h / 2} ${at.x + w - FUNNEL},${at.y + at.h} ${at.x},${at.y + at.h}`,
          class: 'task-box join',
        })
      : svg('rect', { x: at.x, y: at.y, width: w, height: at.h, rx: 6, class: 'task-box' });
    if (at.join) g.classList.add('join');
    if (at.join) g.append(svg('title', {}, `${task.name}: a join connector, one value of the quantity from its ${at.ins.length} producers`));
    g.append(
      body,
      svg('text', { x: at.x + 10, y: at.y + 15, class: 'task-name' }, task.name),
      svg('text', { x: at.x + 10, y: at.y + 28, class: 'task-module' }, `${task.module} · ${period} · ${state || 'NOT-CREATED'}`),
    );
    // A click on the box, its name or its figures (a port's click is the port's: a rename).
    g.addEventListener('click', (event) => !event.target.closest('.port') && !this.justMoved && this.onTask && this.onTask(task));
    if (this.layout) this.draggable(g, task, at, configuration);
    const port = (p, i, left) => {
      const y = this.portY(at, left ? at.ins : at.outs, p);
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
