// What happened in the subsystem, as it happens: the events of the page's stream (state changes,
// switches, the illegal-configuration flag, a task's ERROR and why), newest first, each in the
// words the shell uses.

import { el } from './dom.js';

const MOST = 300; // the list keeps the latest; the subsystem's own history is its flight recorder

function seconds(ns) {
  return `${(ns / 1e9).toFixed(3)} s`;
}

/** One event of the stream (docs/control-api.md, "Streams") as a line of text. */
export function eventText(e) {
  switch (e.type) {
    case 'state':
      if (e.from === null) return `${e.task}: added (${e.to})`;
      if (e.to === null) return `${e.task}: removed`;
      return `${e.task}: ${e.from} → ${e.to}`;
    case 'switch': {
      const parts = [];
      if (e.off.length) parts.push(`off ${e.off.join(' ')}`);
      if (e.on.length) parts.push(`on ${e.on.join(' ')}`);
      const took = ((e.committed_ns - e.requested_ns) / 1e6).toFixed(2);
      return `switch ${e.from || '—'} → ${e.to} (${e.cause})${parts.length ? `: ${parts.join('; ')}` : ''}; committed after ${took} ms`;
    }
    case 'flag':
      return e.illegal_configuration ? 'illegal-configuration flag raised' : 'illegal-configuration flag lowered';
    case 'log':
      return e.task ? `${e.task}: ${e.text}` : e.text;
    default:
      return JSON.stringify(e);
  }
}

export class EventList {
  constructor(root) {
    this.root = root;
  }

  /** A frame of kind "event" or "missed". */
  add(frame) {
    let item;
    if (frame.kind === 'missed') {
      item = el('li', { class: 'error' }, `${frame.events} events missed (the page fell behind)`);
    } else {
      const e = frame.event;
      // In red what needs the operator: a task in ERROR (its state and the line saying why).
      const kind = e.to === 'ERROR' || (e.type === 'log' && e.text.includes('ERROR')) ? 'error' : 'info';
      item = el(
        'li',
        { class: kind, 'data-type': e.type, 'data-task': e.task, 'data-seq': frame.seq },
        el('span', { class: 'muted' }, `${seconds(e.t_ns)} `),
        eventText(e),
      );
    }
    this.root.prepend(item);
    while (this.root.children.length > MOST) this.root.lastChild.remove();
  }
}
