// The control API as the page uses it (docs/control-api.md): the token, JSON requests, the
// shell's commands, and the WebSocket streams of state variables, timing and events.

const TOKEN_KEY = 'chimera.token';

/** The token: from the address's #token=... (chimera prints that link), else the session's. */
export function token() {
  const hash = new URLSearchParams(window.location.hash.slice(1));
  const given = hash.get('token');
  if (given) {
    sessionStorage.setItem(TOKEN_KEY, given);
    // The token leaves the address bar (and the browser's history) once it is kept.
    history.replaceState(null, '', window.location.pathname + window.location.search);
    return given;
  }
  return sessionStorage.getItem(TOKEN_KEY) || '';
}

export function setToken(value) {
  sessionStorage.setItem(TOKEN_KEY, value.trim());
}

/** An error of the API: code ("refused", "bad_command", ...) and the shell's one-line reason. */
export class ApiError extends Error {
  constructor(status, code, message, reply) {
    super(message);
    this.status = status;
    this.code = code;
    this.reply = reply;
  }
}

async function request(method, path, body) {
  const headers = { Authorization: `Bearer ${token()}` };
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  let response;
  try {
    response = await fetch(path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
  } catch (e) {
    throw new ApiError(0, 'unreachable', `the subsystem does not answer (${e.message})`, null);
  }
  let reply;
  try {
    reply = await response.json();
  } catch (e) {
    throw new ApiError(response.status, 'bad_reply', `HTTP ${response.status}: not JSON`, null);
  }
  if (!reply.ok) {
    const error = reply.error || {};
    throw new ApiError(response.status, error.code || 'error', error.message || `HTTP ${response.status}`, reply);
  }
  return reply;
}

export const api = {
  get: (path) => request('GET', path),
  /** One shell command, as its line ("on pid") or as verb and arguments. */
  command: (line) => request('POST', '/api/command', { command: line }),
  verb: (verb, args) => request('POST', '/api/command', { verb, args }),
  status: async () => (await request('GET', '/api/status')).status,
  model: async () => (await request('GET', '/api/subsystem')).subsystem,
  modules: async () => (await request('GET', '/api/modules')).modules,
  whoami: async () => (await request('GET', '/api/whoami')).role,
  examples: async () => (await request('GET', '/api/examples')).examples,
  /** Replaces the running subsystem with a file's: {file: name, text}. */
  open: (file, text) => request('POST', '/api/open', { file, text }),
};

/**
 * One WebSocket stream of /api/stream (docs/control-api.md, "Streams"): the page names what it
 * watches, {variables, rate_hz}, {timing_hz, tasks}, {events: true}, and gets frames by kind
 * ("sample" or, with batch_hz, "samples"; "timing", "event", "missed"). The server never queues: a page that draws slowly
 * gets fewer samples, and no task ever waits for it. onFrame(frame) per frame; onState(text)
 * when the connection changes. With `reconnect`, a stream that closed opens again after a pause.
 */
export class Stream {
  constructor(onFrame, onState, { reconnect = false } = {}) {
    this.onFrame = onFrame;
    this.onState = onState;
    this.reconnect = reconnect;
    this.socket = null;
    this.wanted = null;
    this.retry = null;
  }

  subscribe(wanted) {
    this.wanted = wanted;
    if (this.socket && this.socket.readyState === WebSocket.OPEN) {
      this.socket.send(JSON.stringify(this.wanted));
      return;
    }
    this.open();
  }

  open() {
    this.close();
    const scheme = window.location.protocol === 'https:' ? 'wss' : 'ws';
    const url = `${scheme}://${window.location.host}/api/stream?access_token=${encodeURIComponent(token())}`;
    const socket = new WebSocket(url);
    this.socket = socket;
    socket.onopen = () => {
      this.onState('streaming');
      if (this.wanted) socket.send(JSON.stringify(this.wanted));
    };
    socket.onmessage = (event) => {
      const frame = JSON.parse(event.data);
      if (frame.ok === false) this.onState(`stream refused: ${frame.error.message}`);
      else if (frame.kind) this.onFrame(frame);
    };
    socket.onclose = () => {
      if (this.socket !== socket) return; // closed on purpose
      this.socket = null;
      this.onState('stream closed');
      if (this.reconnect) this.retry = setTimeout(() => this.open(), 2000);
    };
  }

  close() {
    clearTimeout(this.retry);
    if (this.socket) {
      const s = this.socket;
      this.socket = null;
      s.close();
    }
  }
}
