// Small helpers to build the page's elements without HTML strings (nothing a server or a file
// sends is ever parsed as markup).

export function el(tag, attributes = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) {
    if (value === undefined || value === null || value === false) continue;
    node.setAttribute(key, value === true ? '' : String(value));
  }
  for (const child of children) {
    if (child === '' || child === null || child === undefined) continue;
    node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return node;
}

export function svg(tag, attributes = {}, ...children) {
  const node = document.createElementNS('http://www.w3.org/2000/svg', tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, String(value));
  for (const child of children) node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  return node;
}

export function clear(node) {
  while (node.firstChild) node.firstChild.remove();
}

/** "1ms" for 1e6 ns: the shortest of s, ms, us, ns that is whole. */
export function durationText(ns) {
  if (ns === null || ns === undefined) return 'aperiodic';
  for (const [unit, size] of [['s', 1e9], ['ms', 1e6], ['us', 1e3]]) if (ns % size === 0) return `${ns / size}${unit}`;
  return `${ns}ns`;
}
