// Plots of state variables against time, drawn on a canvas: live from the stream (the last
// seconds of each chosen variable, one line per element), or a recorded run's CSV from the data
// logger (header t,name[0],name[1],...; the same file `chimera plot` draws) opened in the same plot.

const COLOURS = ['#1f77b4', '#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2', '#17becf', '#7f7f7f', '#bcbd22'];
const LIVE_WINDOW_S = 10;
const MAX_POINTS = 20000; // per line: the oldest go first

/** Reads a data_logger CSV: {t: [...], series: Map(name -> [...])}; throws with file line on error. */
export function parseLog(text, fileName = 'the file') {
  const lines = text.split(/\r?\n/).filter((l) => l.length);
  if (!lines.length) throw new Error(`${fileName}:1: the file is empty (a data_logger log starts with a header t,...)`);
  const header = lines[0].split(',');
  if (header[0] !== 't') throw new Error(`${fileName}:1: the first column is '${header[0]}', not t (is this a data_logger log?)`);
  const t = [];
  const columns = header.slice(1).map(() => []);
  for (let i = 1; i < lines.length; ++i) {
    const cells = lines[i].split(',');
    if (cells.length !== header.length) throw new Error(`${fileName}:${i + 1}: ${cells.length} values, but the header has ${header.length} columns`);
    const values = cells.map(Number);
    const badCell = values.findIndex((v) => !Number.isFinite(v));
    if (badCell >= 0) throw new Error(`${fileName}:${i + 1}: column ${header[badCell]}: '${cells[badCell]}' is not a number`);
    t.push(values[0]);
    values.slice(1).forEach((v, c) => columns[c].push(v));
  }
  return { t, series: new Map(header.slice(1).map((name, c) => [name, columns[c]])) };
}

export class Plot {
  constructor(canvas) {
    this.canvas = canvas;
    this.lines = new Map(); // "theta_m[2]" -> {t: [], v: []}
    this.live = true;
    this.samples = 0;
    this.pending = false;
  }

  reset(live) {
    this.lines.clear();
    this.live = live;
    this.samples = 0;
    this.draw();
  }

  /** One stream frame: {t_ns, values: {name: [..] | null}}. */
  addSample(frame) {
    const t = frame.t_ns * 1e-9;
    for (const [name, values] of Object.entries(frame.values)) {
      if (!values) continue;
      values.forEach((v, i) => {
        const key = values.length === 1 ? name : `${name}[${i}]`;
        let line = this.lines.get(key);
        if (!line) this.lines.set(key, (line = { t: [], v: [] }));
        line.t.push(t);
        line.v.push(v);
        if (line.t.length > MAX_POINTS) {
          line.t.splice(0, line.t.length - MAX_POINTS);
          line.v.splice(0, line.v.length - MAX_POINTS);
        }
      });
    }
    this.samples += 1;
    this.canvas.dataset.samples = String(this.samples);
    this.canvas.dataset.latest = JSON.stringify(frame.values);
    this.schedule();
  }

  /** One "samples" frame (batch_hz): {t_ns: [..], values: {name: [one value or null per sample]}}. */
  addSamples(frame) {
    frame.t_ns.forEach((t_ns, k) => {
      const values = {};
      for (const [name, list] of Object.entries(frame.values)) values[name] = list[k];
      this.addSample({ t_ns, values });
    });
  }

  /** A recorded log, replacing what is shown. */
  showLog(log) {
    this.reset(false);
    for (const [name, v] of log.series) this.lines.set(name, { t: log.t, v });
    this.canvas.dataset.samples = String(log.t.length);
    this.canvas.dataset.series = [...log.series.keys()].join(',');
    this.draw();
  }

  schedule() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  draw() {
    const c = this.canvas;
    const ratio = window.devicePixelRatio || 1;
    const width = c.clientWidth || 600;
    const height = c.clientHeight || 260;
    if (c.width !== Math.round(width * ratio)) c.width = Math.round(width * ratio);
    if (c.height !== Math.round(height * ratio)) c.height = Math.round(height * ratio);
    const g = c.getContext('2d');
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.clearRect(0, 0, width, height);
    const lines = [...this.lines.entries()];
    g.font = '11px system-ui, sans-serif';
    g.fillStyle = '#666';
    if (!lines.length) {
      g.fillText(this.live ? 'Choose variables to plot them live' : 'No data', 12, 20);
      return;
    }
    let t1 = -Infinity;
    for (const [, l] of lines) if (l.t.length) t1 = Math.max(t1, l.t[l.t.length - 1]);
    let t0 = Infinity;
    for (const [, l] of lines) if (l.t.length) t0 = Math.min(t0, l.t[0]);
    if (this.live) t0 = Math.max(t0, t1 - LIVE_WINDOW_S);
    let lo = Infinity;
    let hi = -Infinity;
    for (const [, l] of lines)
      for (let i = 0; i < l.t.length; ++i)
        if (l.t[i] >= t0) {
          lo = Math.min(lo, l.v[i]);
          hi = Math.max(hi, l.v[i]);
        }
    if (!Number.isFinite(lo)) return;
    if (hi - lo < 1e-9) {
      hi += 0.5;
      lo -= 0.5;
    }
    const left = 56;
    const right = width - 130;
    const top = 10;
    const bottom = height - 24;
    const x = (t) => left + ((t - t0) / Math.max(t1 - t0, 1e-9)) * (right - left);
    const y = (v) => bottom - ((v - lo) / (hi - lo)) * (bottom - top);
    g.strokeStyle = '#ccc';
    g.strokeRect(left, top, right - left, bottom - top);
    g.fillText(hi.toPrecision(4), 4, top + 8);
    g.fillText(lo.toPrecision(4), 4, bottom);
    g.fillText(`${t0.toFixed(2)} s`, left, height - 8);
    g.fillText(`${t1.toFixed(2)} s`, right - 40, height - 8);
    lines.forEach(([name, l], k) => {
      const colour = COLOURS[k % COLOURS.length];
      g.strokeStyle = colour;
      g.lineWidth = 1.2;
      g.beginPath();
      let started = false;
      // At most about two points a pixel: a long recorded log is drawn in strides.
      const stride = Math.max(1, Math.floor(l.t.length / ((right - left) * 2)));
      for (let i = 0; i < l.t.length; i += stride) {
        if (l.t[i] < t0) continue;
        if (started) g.lineTo(x(l.t[i]), y(l.v[i]));
        else g.moveTo(x(l.t[i]), y(l.v[i]));
        started = true;
      }
      g.stroke();
      if (k < 14) {
        g.fillStyle = colour;
        g.fillText(name, right + 8, top + 10 + k * 14);
      }
    });
  }
}
