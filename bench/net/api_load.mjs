// The network API's load for bench/run.py (issue 14, section 3): clients streaming state
// variables over /api/stream, and commands' round trips, against a running chimera.
//
//   node --experimental-websocket bench/net/api_load.mjs stream URL TOKEN CLIENTS RATE_HZ SECONDS VAR,VAR,... [BATCH_HZ]
//
// With BATCH_HZ the clients subscribe as Onika does (batch_hz: the samples in that many frames a
// second); `samples` counts the samples received either way, `frames` the frames.
//   node --experimental-websocket bench/net/api_load.mjs roundtrip URL TOKEN COUNT [keepalive]
//
// URL is http://127.0.0.1:PORT/. Prints one JSON object on stdout.

import http from 'node:http';

const [mode, base, token, ...rest] = process.argv.slice(2);
const wsBase = base.replace(/^http/, 'ws');

function percentile(sorted, p) {
  if (!sorted.length) return 0;
  return sorted[Math.min(sorted.length - 1, Math.floor(p * (sorted.length - 1)))];
}

async function stream(clients, rateHz, seconds, variables, batchHz) {
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
  refused = clients - accepted;
  const start = performance.now();
  const sum = (list) => list.reduce((a, b) => a + b, 0);
  const before = sum(counts);
  const framesBefore = sum(frameCounts);
  await new Promise((r) => setTimeout(r, seconds * 1000));
  const samples = sum(counts) - before;
  const frames = sum(frameCounts) - framesBefore;
  const elapsed = (performance.now() - start) / 1000;
  for (const s of sockets) s.close();
  return { clients, accepted, refused, variables: variables.length, rate_hz: rateHz, batch_hz: batchHz || 0, seconds: elapsed, samples, frames, samples_per_client_per_s: accepted ? samples / accepted / elapsed : 0, frames_per_client_per_s: accepted ? frames / accepted / elapsed : 0 };
}

// One request: on a new connection each (agent false), as `curl` sends it, or on one kept open
// (a keep-alive agent), as a browser's fetch and a script's session send them.
function command(url, body, agent) {
  return new Promise((resolve, reject) => {
    const req = http.request(url, { method: 'POST', agent, headers: { Authorization: `Bearer ${token}`, 'Content-Type': 'application/json', 'Content-Length': Buffer.byteLength(body) } }, (res) => {
      res.on('data', () => {});
      res.on('end', () => (res.statusCode === 200 ? resolve() : reject(new Error(`HTTP ${res.statusCode}`))));
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

let result;
if (mode === 'stream') {
  const [clients, rate, seconds, vars, batch] = rest;
  result = await stream(Number(clients), Number(rate), Number(seconds), vars.split(','), Number(batch || 0));
} else if (mode === 'roundtrip') {
  result = await roundtrip(Number(rest[0]), rest[1] === 'keepalive');
} else {
  console.error(`api_load: unknown mode ${mode}`);
  process.exit(2);
}
console.log(JSON.stringify(result));
process.exit(0);
