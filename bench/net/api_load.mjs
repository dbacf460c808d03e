// The network API's load for bench/run.py (issue 14, section 3): clients streaming state
// variables over /api/stream, and commands' round trips, against a running chimera.
//
//   node --experimental-websocket bench/net/api_load.mjs stream URL TOKEN CLIENTS RATE_HZ SECONDS VAR,VAR,... [BATCH_HZ]
//
// With BATCH_HZ the clients subscribe as Onika does (batch_hz: the samples in that many frames a
// second); `samples` counts the samples received either way, `frames` the frames.
//   node --experimental-websocket bench/net/api_load.mjs roundtrip URL TOKEN COUNT [keepalive]
//   node --experimental-websocket bench/net/api_load.mjs windows URL TOKEN CLIENTS RATE_HZ WINDOW_S PAIRS VAR,... BATCH_HZ TASK,...
//
// `windows` compares in one run: PAIRS pairs of windows of WINDOW_S seconds, one quiet, one with
// CLIENTS streaming, in the order quiet-streaming, streaming-quiet, ... (so that a drift of the
// machine's noise during the run weighs on both alike). Around each window it takes the `stats`
// reply, and reports per window the TASKs' cycles, misses and release latency histogram counted
// within it (the difference of the two replies' cumulative figures).
//
// URL is http://127.0.0.1:PORT/. Prints one JSON object on stdout.

import http from 'node:http';

const [mode, base, token, ...rest] = process.argv.slice(2);
const wsBase = base.replace(/^http/, 'ws');

function percentile(sorted, p) {
  if (!sorted.length) return 0;
  return sorted[Math.min(sorted.length - 1, Math.floor(p * (sorted.length - 1)))];
}

// Opens the clients and subscribes them; resolves once each is accepted or refused (5 s).
async function openClients(clients, rateHz, variables, batchHz) {
  const sockets = [];
  const counts = [];
  const frameCounts = [];
  let accepted = 0;
  let refused = 0;
  const opened = [];
  for (let i = 0; i < clients; ++i) {
    counts.push(0);
    frameCounts.push(0);
    const socket = new WebSocket(`${wsBase}api/stream?access_token=${encodeURIComponent(token)}`);
    sockets.push(socket);
    opened.push(
      new Promise((resolve) => {
        const timer = setTimeout(() => {
          refused += 1;
          resolve();
        }, 5000);
        socket.onopen = () => {
          clearTimeout(timer);
          accepted += 1;
          socket.send(JSON.stringify(batchHz ? { variables, rate_hz: rateHz, batch_hz: batchHz } : { variables, rate_hz: rateHz }));
          resolve();
        };
        socket.onerror = () => {};
        socket.onclose = () => {
          clearTimeout(timer);
          resolve();
        };
      }),
    );
    socket.onmessage = (event) => {
      const frame = JSON.parse(event.data);
      if (!frame.values) return;
      counts[i] += frame.kind === 'samples' ? frame.count : 1;
      frameCounts[i] += 1;
    };
  }
  await Promise.all(opened);
  return { sockets, counts, frameCounts, accepted, refused: clients - accepted };
}

const sleep = (seconds) => new Promise((r) => setTimeout(r, seconds * 1000));
const sum = (list) => list.reduce((a, b) => a + b, 0);

// Counts what the open clients receive while `during` runs (after they were accepted).
async function measureClients(open, clients, rateHz, variables, batchHz, during) {
  const start = performance.now();
  const before = sum(open.counts);
  const framesBefore = sum(open.frameCounts);
  await during();
  const samples = sum(open.counts) - before;
  const frames = sum(open.frameCounts) - framesBefore;
  const elapsed = (performance.now() - start) / 1000;
  const { accepted, refused } = open;
  return { clients, accepted, refused, variables: variables.length, rate_hz: rateHz, batch_hz: batchHz || 0, seconds: elapsed, samples, frames, samples_per_client_per_s: accepted ? samples / accepted / elapsed : 0, frames_per_client_per_s: accepted ? frames / accepted / elapsed : 0 };
}

async function stream(clients, rateHz, seconds, variables, batchHz) {
  const open = await openClients(clients, rateHz, variables, batchHz);
  const result = await measureClients(open, clients, rateHz, variables, batchHz, () => sleep(seconds));
  for (const s of open.sockets) s.close();
  return result;
}

// One request: on a new connection each (agent false), as `curl` sends it, or on one kept open
// (a keep-alive agent), as a browser's fetch and a script's session send them.
// Resolves to the reply's body.
function command(url, body, agent) {
  return new Promise((resolve, reject) => {
    const req = http.request(url, { method: 'POST', agent, headers: { Authorization: `Bearer ${token}`, 'Content-Type': 'application/json', 'Content-Length': Buffer.byteLength(body) } }, (res) => {
      const chunks = [];
      res.on('data', (chunk) => chunks.push(chunk));
      res.on('end', () => (res.statusCode === 200 ? resolve(Buffer.concat(chunks).toString()) : reject(new Error(`HTTP ${res.statusCode}`))));
    });
    req.on('error', reject);
    req.end(body);
  });
}

async function roundtrip(count, keepAlive) {
  const times = [];
  const url = `${base}api/command`;
  const agent = keepAlive ? new http.Agent({ keepAlive: true, maxSockets: 1 }) : false;
  for (let i = 0; i < count; ++i) {
    const t0 = process.hrtime.bigint();
    await command(url, '{"command": "get theta_m"}', agent);
    times.push(Number(process.hrtime.bigint() - t0));
  }
  if (agent) agent.destroy();
  times.sort((a, b) => a - b);
  return { count, connection: keepAlive ? 'kept alive' : 'new per request', p50_ns: percentile(times, 0.5), p99_ns: percentile(times, 0.99), max_ns: times[times.length - 1] };
}

// The tasks' cumulative figures now: cycles, missed, and the latency histogram as {bound: count}.
async function figures(tasks) {
  const reply = JSON.parse(await command(`${base}api/command`, '{"command": "stats"}', false));
  const out = {};
  for (const t of tasks) {
    const s = reply.stats.tasks[t];
    out[t] = { cycles: s.cycles, missed: s.missed, latency: Object.fromEntries(s.histograms.latency_ns) };
  }
  return out;
}

// What happened between two `figures`: per task the cycles, misses and latency histogram of the window.
function between(before, after) {
  const out = {};
  for (const [t, a] of Object.entries(after)) {
    const b = before[t];
    const latency = [];
    for (const [bound, count] of Object.entries(a.latency)) {
      const n = count - (b.latency[bound] || 0);
      if (n > 0) latency.push([Number(bound), n]);
    }
    latency.sort((x, y) => x[0] - y[0]);
    out[t] = { cycles: a.cycles - b.cycles, missed: a.missed - b.missed, latency_histogram: latency };
  }
  return out;
}

async function windows(clients, rateHz, windowS, pairs, variables, batchHz, tasks) {
  const settle = 0.3;  // for the clients' connections to open, or close, outside the windows
  const quiet = async () => {
    const before = await figures(tasks);
    await sleep(windowS);
    return { kind: 'none', tasks: between(before, await figures(tasks)) };
  };
  const streaming = async () => {
    const open = await openClients(clients, rateHz, variables, batchHz);
    await sleep(settle);
    let tasksOf;
    const got = await measureClients(open, clients, rateHz, variables, batchHz, async () => {
      const before = await figures(tasks);
      await sleep(windowS);
      tasksOf = between(before, await figures(tasks));
    });
    for (const s of open.sockets) s.close();
    await sleep(settle);
    return { kind: 'clients', stream: got, tasks: tasksOf };
  };
  const out = [];
  for (let i = 0; i < pairs; ++i) {
    const order = i % 2 === 0 ? [quiet, streaming] : [streaming, quiet];
    for (const w of order) out.push(await w());
  }
  return { window_s: windowS, pairs, windows: out };
}

let result;
if (mode === 'stream') {
  const [clients, rate, seconds, vars, batch] = rest;
  result = await stream(Number(clients), Number(rate), Number(seconds), vars.split(','), Number(batch || 0));
} else if (mode === 'windows') {
  const [clients, rate, windowS, pairs, vars, batch, tasks] = rest;
  result = await windows(Number(clients), Number(rate), Number(windowS), Number(pairs), vars.split(','), Number(batch), tasks.split(','));
} else if (mode === 'roundtrip') {
  result = await roundtrip(Number(rest[0]), rest[1] === 'keepalive');
} else {
  console.error(`api_load: unknown mode ${mode}`);
  process.exit(2);
}
// Exits once the whole reply is written: a pipe takes 64 KiB at once, and exit() would cut it there.
process.stdout.write(`${JSON.stringify(result)}\n`, () => process.exit(0));
