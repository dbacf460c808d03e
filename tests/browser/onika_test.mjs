// Onika in a real browser (issue 14, section 3): Debian's chromium, headless, driven by
// playwright-core, against a real `chimera serve` / `chimera run --listen` on loopback. Each test
// does what a user does with the mouse and checks what the subsystem did, not only what the page
// shows: the saved file is verified by `chimera verify`, states are read back from the API.
//
//   CHIMERA_BIN=build/apps/chimera/chimera node --test tests/browser/onika_test.mjs
//
// Screenshots go to ONIKA_SCREENSHOTS (default: a temporary folder).

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, writeFileSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const source = join(here, '..', '..');
const chimera = process.env.CHIMERA_BIN || join(source, 'build', 'apps', 'chimera', 'chimera');
const browserPath = process.env.CHROMIUM || '/usr/bin/chromium';
const work = mkdtempSync(join(tmpdir(), 'onika-test-'));
const shots = process.env.ONIKA_SCREENSHOTS || join(work, 'screenshots');
mkdirSync(shots, { recursive: true });

let browser;

before(async () => {
  browser = await chromium.launch({
    executablePath: browserPath,
    headless: true,
    // As root in a sandbox without a network: no sandbox, and none of chromium's own traffic.
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync'],
  });
});

after(async () => {
  if (browser) await browser.close();
});

/** Starts chimera with `args`; resolves with the page's link (token included) from its stderr. */
function startChimera(args, name) {
  const logs = join(work, name);
  mkdirSync(logs, { recursive: true });
  const child = spawn(chimera, args, { env: { ...process.env, CHIMERA_LOG_DIR: logs }, stdio: ['pipe', 'pipe', 'pipe'] });
  let err = '';
  const link = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no page link from chimera within 20 s:\n${err}`)), 20000);
    child.stderr.on('data', (chunk) => {
      err += chunk;
      const m = err.match(/Onika, the page, on (http:\/\/\S+#token=\S+)/);
      if (m) {
        clearTimeout(timer);
        resolve(m[1]);
      }
    });
    child.on('exit', (code) => reject(new Error(`chimera exited (${code}) before serving:\n${err}`)));
  });
  child.stdout.on('data', () => {});
  return { child, link, stderr: () => err, logs };
}

async function stopChimera(run) {
  const done = new Promise((resolve) => run.child.on('exit', (code) => resolve(code)));
  run.child.stdin.end('quit\n');
  const timer = setTimeout(() => run.child.kill('SIGKILL'), 15000);
  const code = await done;
  clearTimeout(timer);
  return code;
}

async function openPage(link) {
  const context = await browser.newContext({ viewport: { width: 1600, height: 1000 } });
  const page = await context.newPage();
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  // A refused command is a 409 reply, which the browser logs as a failed load: that one is the
  // API at work (the page shows its reason); any other error, a missing file above all, is not.
  page.on('console', (m) => m.type() === 'error' && !m.text().includes('status of 409') && problems.push(`console: ${m.text()}`));
  await page.goto(link);
  await page.waitForSelector('body[data-ready=true]', { timeout: 15000 });
  return { page, context, problems };
}

/** What the API says the tasks' states are, with the token the page was given. */
async function apiStatus(link) {
  const url = new URL(link);
  const token = new URLSearchParams(url.hash.slice(1)).get('token');
  const r = await fetch(new URL('/api/status', url), { headers: { Authorization: `Bearer ${token}` } });
  return (await r.json()).status;
}

/** Drags module `module` from the library onto the canvas and adds it as task `name`. */
async function dragIn(page, module, name, { criticality = 'hard', period = '1ms', params = '' } = {}) {
  await page.dragAndDrop(`#library-list li[data-module="${module}"]`, '#canvas');
  await page.waitForSelector('#add-dialog[open]');
  await page.fill('#add-name', name);
  await page.fill('#add-period', period);
  await page.selectOption('#add-criticality', criticality);
  await page.fill('#add-params', params);
  await page.click('#add-ok');
  await page.waitForSelector(`#canvas g.task[data-task="${name}"]`, { timeout: 10000 });
}

async function waitForState(page, task, state) {
  await page.waitForSelector(`#tasks tr[data-task="${task}"][data-state="${state}"]`, { timeout: 15000 });
}

test('assembles Figure 4 from an empty canvas, runs it, plots it and saves a file chimera verify accepts', async () => {
  const run = startChimera(['serve', '--listen', '127.0.0.1:0'], 'fig4');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    // The library: searched by port.
    await page.fill('#library-search', 'produces tau_r');
    const producers = await page.$$eval('#library-list li', (items) => items.map((i) => i.dataset.module));
    assert.ok(producers.includes('pid_joint'), `pid_joint produces tau_r: ${producers}`);
    assert.ok(!producers.includes('robot_torque'), 'robot_torque consumes tau_r, it does not produce it');
    await page.click('#library-list li[data-module="pid_joint"]');
    await page.waitForSelector('#details article.module-page[data-module="pid_joint"]');
    // ... and by name: a part of a module's name finds it.
    await page.fill('#library-search', 'traj');
    const named = await page.$$eval('#library-list li', (items) => items.map((i) => i.dataset.module));
    assert.ok(named.includes('joint_traj_gen'), `'traj' finds joint_traj_gen: ${named}`);
    assert.ok(!named.includes('pid_joint'), `'traj' does not find pid_joint: ${named}`);
    await page.fill('#library-search', '');

    // Soft tasks: a shared test machine may miss a deadline, which is the next test's subject.
    // The robot interface first: its out-const ndof sizes the others' ports, so the others are
    // refused before it, with that reason in the form.
    await page.dragAndDrop('#library-list li[data-module="joint_traj_gen"]', '#canvas');
    await page.waitForSelector('#add-dialog[open]');
    await page.click('#add-ok');
    await page.waitForFunction(() => document.querySelector('#add-error').textContent.includes('add first the task that gives the constant'));
    await page.click('#add-cancel');
    await dragIn(page, 'robot_torque', 'robot', { criticality: 'soft' });
    await dragIn(page, 'joint_traj_gen', 'traj', { criticality: 'soft', params: '{loop: true}' });
    // Two of three: verified on the edit, the missing producer named and drawn in red.
    await page.waitForFunction(() => document.querySelector('#verdict').textContent.includes('tau_r has no producer'));
    assert.ok(await page.$('#canvas .port.bad[data-variable="tau_r"]'), 'the unproduced tau_r is highlighted');
    assert.equal(await page.isDisabled('#switch'), true, 'an illegal configuration cannot be switched to');
    await page.screenshot({ path: join(shots, 'onika-fig4-missing-producer.png') });

    await dragIn(page, 'pid_joint', 'pid', { criticality: 'soft' });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');
    // The links follow from the port names: the loop of Figure 4, and the fan-out of theta_m.
    for (const [from, to, variable] of [['traj', 'pid', 'theta_d'], ['pid', 'robot', 'tau_r'], ['robot', 'pid', 'theta_m']])
      assert.ok(await page.$(`#canvas path.link[data-from="${from}"][data-to="${to}"][data-variable="${variable}"]`), `${from} -> ${to} (${variable})`);
    assert.equal(await page.$$eval('#canvas .bad', (n) => n.length), 0, 'nothing is highlighted once legal');
    // The tracking monitor beside them (Figure 4's tracking error): theta_d and theta_m fan out to it.
    await dragIn(page, 'tracking_monitor', 'monitor', { criticality: 'soft' });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');
    for (const [from, variable] of [['traj', 'theta_d'], ['robot', 'theta_m']])
      assert.ok(await page.$(`#canvas path.link[data-from="${from}"][data-to="monitor"][data-variable="${variable}"]`), `${from} -> monitor (${variable})`);

    await page.click('#switch');
    for (const task of ['traj', 'pid', 'robot', 'monitor']) await waitForState(page, task, 'ON');
    // The switch and the states it changed come as events, in the shell's words.
    await page.waitForSelector('#events li[data-type="switch"]', { timeout: 15000 });
    assert.match(await page.textContent('#events li[data-type="switch"]'), /switch empty → assembly \(operator\): on [a-z ]*pid/);
    // A change is what one look saw against the one before (docs/control-api.md, "Streams").
    await page.waitForSelector('#events li[data-type="state"][data-task="pid"]:has-text("→ ON")', { timeout: 15000 });
    assert.match(await page.textContent('#events li[data-type="state"][data-task="pid"]:has-text("→ ON")'), /pid: NOT-CREATED → ON/);

    // The timing of a task, live: the histogram is there and the cycles go on rising.
    await page.click('#tasks tr[data-task="pid"] button[data-action="stats"]');
    await page.waitForSelector('#details article.timing[data-task="pid"] figure.histogram');
    const cycles = Number(await page.getAttribute('#details article.timing[data-task="pid"]', 'data-cycles'));
    await page.waitForFunction((seen) => Number(document.querySelector('#details article.timing[data-task="pid"]').dataset.cycles) > seen + 100, cycles, { timeout: 15000 });
    await page.screenshot({ path: join(shots, 'onika-timing.png') });
    const status = await apiStatus(link);
    assert.equal(status.configuration, 'assembly');
    assert.deepEqual(status.tasks.map((t) => t.state), ['ON', 'ON', 'ON', 'ON']);

    // A live plot of the arm's joints and the tracking error: samples arrive and the values move.
    await page.selectOption('#plot-variables', ['theta_d', 'theta_m', 'tracking_error']);
    await page.fill('#plot-rate', '200');
    await page.click('#plot-live');
    await page.waitForFunction(() => Number(document.querySelector('#plot').dataset.samples || 0) > 50, null, { timeout: 15000 });
    // The trajectory loops (loop: true): the arm is moving or about to, whenever the plot starts.
    const first = await page.$eval('#plot', (c) => c.dataset.latest);
    await page.waitForFunction((seen) => document.querySelector('#plot').dataset.latest !== seen, first, { timeout: 15000 });
    const latest = JSON.parse(await page.$eval('#plot', (c) => c.dataset.latest));
    assert.equal(latest.tracking_error.length, 3, `the tracking error is plotted: ${JSON.stringify(latest)}`);
    await page.screenshot({ path: join(shots, 'onika-fig4.png') });

    // A recorded run: the data logger's CSV of Figure 4 (two seconds on the virtual clock), opened
    // in the same plot, every row of it, a line per column.
    const logs = join(work, 'fig4-log');
    mkdirSync(logs, { recursive: true });
    // Under a name of its own: another test (the soak's) may be running fig4 beside this one.
    const fig4 = readFileSync(join(source, 'examples', 'fig4_pid_joint.yaml'), 'utf8');
    assert.match(fig4, /^subsystem: fig4$/m, 'the example changed: adapt this test');
    const logFile = join(logs, 'fig4_onika.yaml');
    writeFileSync(logFile, fig4.replace(/^subsystem: fig4$/m, `subsystem: onika_log_${process.pid}`));
    const logged = spawnSync(chimera, ['run', logFile, '--clock', 'virtual', '--for', '2s'],
      { encoding: 'utf8', env: { ...process.env, CHIMERA_LOG_DIR: logs } });
    assert.equal(logged.status, 0, `${logged.stdout}${logged.stderr}`);
    const csv = join(logs, 'fig4.csv');
    const rows = readFileSync(csv, 'utf8').trim().split('\n').length - 1;
    assert.ok(rows >= 1990, `two seconds of rows at 1 kHz: ${rows}`);
    await page.setInputFiles('#plot-file', csv);
    await page.waitForFunction((n) => Number(document.querySelector('#plot').dataset.samples) === n, rows, { timeout: 15000 });
    const series = (await page.$eval('#plot', (c) => c.dataset.series)).split(',');
    assert.ok(series.includes('tracking_error[0]') && series.includes('theta_m[5]'), `the log's columns: ${series}`);
    assert.equal(await page.textContent('#plot-state'), 'fig4.csv');

    // Save: the file the page shows is one chimera verify accepts.
    await page.click('#save');
    await page.waitForSelector('#save-dialog[open]');
    const yaml = await page.inputValue('#save-text');
    const file = join(work, 'saved_fig4.yaml');
    writeFileSync(file, yaml);
    const verified = spawnSync(chimera, ['verify', file], { encoding: 'utf8' });
    assert.equal(verified.status, 0, `chimera verify ${file}: ${verified.stdout}${verified.stderr}\n${yaml}`);
    assert.match(yaml, /pid_joint/);
    assert.deepEqual(problems, []);
  } finally {
    await context.close();
    assert.equal(await stopChimera(run), 0, run.stderr());
  }
});

/** The box of task `name` on the main canvas: where it is drawn, and whether it was moved by hand. */
async function boxOf(page, name) {
  return page.$eval(`#canvas g.task[data-task="${name}"]`, (g) => ({ x: Number(g.dataset.x), y: Number(g.dataset.y), moved: g.classList.contains('moved') }));
}

test('a task\'s parameters edited on the canvas, a refusal changing nothing; its box moved, and kept', async () => {
  const run = startChimera(['serve', '--listen', '127.0.0.1:0'], 'edit');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    await dragIn(page, 'robot_torque', 'robot', { criticality: 'soft' });
    await dragIn(page, 'joint_traj_gen', 'traj', { criticality: 'soft', params: '{loop: true}' });
    await dragIn(page, 'pid_joint', 'pid', { criticality: 'soft' });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');

    // A value out of the parameter's range is refused with the loader's reason, and the task is
    // back as it was: in the configuration, with its old parameters.
    await page.click('#canvas g.task[data-task="traj"] rect');
    await page.waitForSelector('#edit-task[data-task="traj"]');
    // Every parameter as the task has it, the defaults filled in: the one given, and the others.
    const shown = JSON.parse(await page.inputValue('#edit-params'));
    assert.equal(shown.loop, true);
    assert.equal(shown.segment_time, 1.5);
    await page.fill('#edit-params', '{loop: true, segment_time: -1}');
    await page.click('#edit-apply');
    await page.waitForFunction(() => document.querySelector('#edit-error').textContent.includes('segment_time'));
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');
    assert.ok(await page.$('#canvas g.task[data-task="traj"]'), 'traj is back in the configuration');

    // A good value: the task is added anew with it, and the saved file says so.
    await page.click('#canvas g.task[data-task="traj"] rect');
    await page.waitForSelector('#edit-task[data-task="traj"]');
    await page.fill('#edit-params', '{loop: true, segment_time: 3}');
    await page.fill('#edit-period', '2ms');
    await page.click('#edit-apply');
    await page.waitForFunction(() => document.querySelector('#edit-params') && document.querySelector('#edit-params').value.includes('"segment_time":3'));
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');

    // A rename edited on a port: traj's output theta_d bound to theta_ref leaves pid's theta_d
    // without a producer, said in words and drawn in red; pid's input bound to it too, and the
    // link is drawn again, under the new name.
    const renameTo = (variable) => page.once('dialog', (d) => d.accept(variable));
    renameTo('theta_ref');
    await page.click('#canvas g.task[data-task="traj"] g.port[data-port="theta_d"]');
    // traj is added anew with the rename (taken out of the configuration meanwhile): the port shows it.
    await page.waitForSelector('#canvas g.task[data-task="traj"] g.port.renamed[data-port="theta_d"][data-variable="theta_ref"]', { timeout: 15000 });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent.includes('theta_d has no producer'));
    assert.ok(await page.$('#canvas g.task[data-task="pid"] g.port.bad[data-port="theta_d"]'), "pid's theta_d is red");
    renameTo('theta_ref');
    await page.click('#canvas g.task[data-task="pid"] g.port[data-port="theta_d"]');
    await page.waitForSelector('#canvas g.task[data-task="pid"] g.port.renamed[data-port="theta_d"][data-variable="theta_ref"]', { timeout: 15000 });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');
    assert.ok(await page.$('#canvas path.link[data-from="traj"][data-to="pid"][data-variable="theta_ref"]'), 'traj -> pid (theta_ref)');

    await page.click('#save');
    await page.waitForSelector('#save-dialog[open]');
    const yaml = await page.inputValue('#save-text');
    await page.click('#save-close');
    assert.match(yaml, /segment_time: 3/, yaml);
    assert.match(yaml, /rename: *\{ *theta_d: theta_ref *\}|rename:\s*\n\s+theta_d: theta_ref/, yaml);
    assert.match(yaml, /name: traj[^\n]*\n(?:[^\n]*\n)*?\s+period: 2ms/, yaml);

    // The box moved by hand: where it is let go (on the grid), the links following it; after a
    // reload of the page it is still there; Auto layout puts it back.
    const before = await boxOf(page, 'traj');
    const rect = await page.$('#canvas g.task[data-task="traj"] rect');
    const at = await rect.boundingBox();
    await page.mouse.move(at.x + 20, at.y + 10);
    await page.mouse.down();
    await page.mouse.move(at.x + 30, at.y + 60, { steps: 5 });
    await page.mouse.move(at.x + 40, at.y + 160, { steps: 5 });
    await page.mouse.up();
    await page.waitForSelector('#canvas g.task.moved[data-task="traj"]');
    const moved = await boxOf(page, 'traj');
    assert.ok(moved.y > before.y + 40, `moved down: ${JSON.stringify(before)} -> ${JSON.stringify(moved)}`);
    assert.equal(moved.x % 10, 0);
    assert.equal(moved.y % 10, 0);
    assert.ok(await page.$('#canvas path.link[data-from="traj"][data-to="pid"][data-variable="theta_ref"]'), 'the link follows the box');
    await page.reload();
    await page.waitForSelector('body[data-ready=true]', { timeout: 15000 });
    await page.click('#configuration-tabs button[data-configuration="assembly"]');
    await page.waitForSelector('#canvas g.task[data-task="traj"]');
    assert.deepEqual(await boxOf(page, 'traj'), moved, 'the layout is kept by the browser');
    await page.click('#auto-layout');
    await page.waitForSelector('#canvas g.task[data-task="traj"]:not(.moved)');
    assert.deepEqual(await boxOf(page, 'traj'), before);
    await page.screenshot({ path: join(shots, 'onika-edit.png') });
    assert.deepEqual(problems.filter((p) => !p.includes('status of 400')), []);
  } finally {
    await context.close();
    assert.equal(await stopChimera(run), 0, run.stderr());
  }
});

test('a task in ERROR shows its message and the clear button brings it back', async () => {
  const run = startChimera(['serve', '--listen', '127.0.0.1:0'], 'error');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    // A hard task whose cycle takes 5 ms of a 2 ms period misses its first deadline.
    await dragIn(page, 'cpu_load', 'load', { period: '2ms', params: '{exec: 0.005}' });
    await page.waitForFunction(() => document.querySelector('#verdict').textContent === 'legal');
    await page.click('#switch');
    await waitForState(page, 'load', 'ERROR');
    const message = await page.textContent('#tasks tr[data-task="load"] .error-text');
    assert.ok(message.length > 0, 'the ERROR has its message');
    // The ERROR came as events too: the state change, and the line that says why.
    await page.waitForSelector('#events li[data-type="log"][data-task="load"]', { timeout: 15000 });
    // The look after the switch may come after the first miss: then it saw NOT-CREATED → ERROR.
    await page.waitForSelector('#events li[data-type="state"][data-task="load"]:has-text("→ ERROR")', { timeout: 15000 });
    assert.match(await page.textContent('#events li[data-type="state"][data-task="load"]:has-text("→ ERROR")'), /load: (ON|NOT-CREATED) → ERROR/);
    assert.ok(await page.$('#canvas g.task.state-ERROR[data-task="load"]'), 'the canvas shows ERROR by colour');
    // While a task is in ERROR the illegal-configuration flag is up (docs/lifecycle.md), in the header.
    await page.waitForSelector('#illegal-flag:not([hidden])', { timeout: 15000 });
    assert.equal((await apiStatus(link)).illegal_configuration, true);
    await page.screenshot({ path: join(shots, 'onika-error.png') });
    await page.click('#tasks tr[data-task="load"] button[data-action="clear"]');
    await waitForState(page, 'load', 'OFF');
    assert.equal((await apiStatus(link)).tasks[0].state, 'OFF');
    await page.waitForSelector('#illegal-flag[hidden]', { state: 'attached', timeout: 15000 });
    assert.deepEqual(problems, []);
  } finally {
    await context.close();
    await stopChimera(run);
  }
});

test('Figures 8 and 9: two configurations of one file side by side, switched with one click', async () => {
  // examples/visual_servo.yaml (standard is Figure 8, near_singularity Figure 9) without the
  // monitor's switch requests, so that only the clicks switch, and with its hard tasks soft: a
  // shared test machine may miss a deadline, which is not this test's subject.
  const example = readFileSync(join(source, 'examples', 'visual_servo.yaml'), 'utf8');
  const text = example.slice(0, example.indexOf('\nrequests:') + 1).replaceAll('    period: 1ms\n', '    period: 1ms\n    criticality: soft\n');
  assert.ok(text.includes('near_singularity: [') && text.includes('criticality: soft\n    params: { gain: 20 }'), 'the example changed: adapt this test');
  const file = join(work, 'visual_servo.yaml');
  writeFileSync(file, text);
  const run = startChimera(['run', file, '--listen', '127.0.0.1:0'], 'fig89');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    await page.click('#configuration-tabs button[data-configuration="standard"]');
    await page.selectOption('#compare-with', 'near_singularity');
    await page.waitForSelector('#compare-canvas g.task[data-task="dls"]');
    assert.ok(await page.$('#canvas g.task[data-task="ik"]'), 'Figure 8 has inverse kinematics');
    assert.equal(await page.$('#canvas g.task[data-task="dls"]'), null, 'Figure 8 has no damped least squares');
    assert.ok(await page.$('#compare-canvas path.link[data-from="dls"][data-to="integ"]'), 'Figure 9: dls -> integ');
    await waitForState(page, 'ik', 'ON');
    await page.screenshot({ path: join(shots, 'onika-fig8-fig9.png') });
    await page.click('#compare-switch');
    await page.waitForFunction(() => document.querySelector('#configuration-on').textContent === 'on: near_singularity', null, { timeout: 15000 });
    await waitForState(page, 'dls', 'ON');
    await waitForState(page, 'ik', 'OFF');
    assert.equal((await apiStatus(link)).configuration, 'near_singularity');
    await page.click('#switch');
    await page.waitForFunction(() => document.querySelector('#configuration-on').textContent === 'on: standard', null, { timeout: 15000 });
    await waitForState(page, 'ik', 'ON');
    assert.equal((await apiStatus(link)).illegal_configuration, false);
    assert.deepEqual(problems, []);
  } finally {
    await context.close();
    await stopChimera(run);
  }
});

test("Figure 3's join connector: drawn as a funnel, its two producers' links converging on it", async () => {
  // examples/fig3_join.yaml under a name of its own (a test of the examples may run it meanwhile)
  // and with every task soft: a shared test machine may miss a deadline, not this test's subject.
  const example = readFileSync(join(source, 'examples', 'fig3_join.yaml'), 'utf8');
  const name = `onika_join_${process.pid}`;
  const text = example.replace('\nsubsystem: fig3_join\n', `\nsubsystem: ${name}\n`).replace(/( {4}period: \S+\n)(?! {4}criticality)/g, '$1    criticality: soft\n');
  assert.ok(text.includes(`subsystem: ${name}\n`) && (text.match(/criticality: soft/g) || []).length === 6, 'the example changed: adapt this test');
  const file = join(work, 'fig3_join.yaml');
  writeFileSync(file, text);
  const run = startChimera(['run', file, '--listen', '127.0.0.1:0'], 'fig3');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    await page.waitForSelector('#canvas g.task.join[data-task="join"] polygon.task-box.join');
    // Only the join is drawn so: the cameras and the rest are boxes.
    assert.deepEqual(await page.$$eval('#canvas g.task.join', (gs) => gs.map((g) => g.dataset.task)), ['join']);
    assert.ok(await page.$('#canvas g.task[data-task="camera_a"] rect.task-box'), 'a camera is a box');
    // Every task is fed (the cameras read the measured pose): the loop is cut where the file
    // begins it, and the two cameras stand in the first column, left of the join they feed.
    const [cameraA, cameraB, joinBox] = [await boxOf(page, 'camera_a'), await boxOf(page, 'camera_b'), await boxOf(page, 'join')];
    assert.equal(cameraA.x, cameraB.x, `both cameras in one column: ${JSON.stringify([cameraA, cameraB])}`);
    assert.ok(cameraA.x < joinBox.x && cameraA.y !== cameraB.y, `the cameras left of the join: ${JSON.stringify([cameraA, cameraB, joinBox])}`);
    const into = await page.$$eval('#canvas path.link[data-to="join"]', (ps) => ps.map((p) => `${p.dataset.from}:${p.dataset.variable}`).sort());
    assert.deepEqual(into, ['camera_a:x_d_a', 'camera_b:x_d_b']);
    // Its one output leaves from the funnel's point.
    const [tipX, tipY] = await page.$eval('#canvas g.task[data-task="join"] polygon', (p) => [p.points[2].x, p.points[2].y]);
    const start = await page.$eval('#canvas path.link[data-from="join"][data-to="ik"]', (p) => p.getAttribute('d').match(/^M([-\d.]+),([-\d.]+)/).slice(1).map(Number));
    assert.deepEqual(start, [tipX, tipY], 'x_d starts at the point of the join');
    assert.equal(await page.$eval('#canvas path.link[data-from="join"][data-to="ik"]', (p) => p.dataset.variable), 'x_d');
    await waitForState(page, 'join', 'ON');
    await page.screenshot({ path: join(shots, 'onika-fig3-join.png') });
    assert.deepEqual(problems, []);
  } finally {
    await context.close();
    await stopChimera(run);
  }
});

test('opens an example of the tree from the page, edited in place, and it runs', async () => {
  const run = startChimera(['serve', '--listen', '127.0.0.1:0'], 'open');
  const link = await run.link;
  const { page, context, problems } = await openPage(link);
  try {
    await page.click('#open');
    await page.waitForSelector('#open-dialog[open] #open-examples button[data-example]');
    const offered = await page.$$eval('#open-examples button[data-example]', (b) => b.map((x) => x.dataset.example).sort());
    const inTree = readdirSync(join(source, 'examples')).filter((f) => f.endsWith('.yaml')).sort();
    assert.deepEqual(offered, inTree, 'every example of the tree is offered');
    await page.click('#open-examples button[data-example="fig4_pid_joint.yaml"]');
    const example = readFileSync(join(source, 'examples', 'fig4_pid_joint.yaml'), 'utf8');
    assert.equal(await page.inputValue('#open-text'), example);

    // A mistake made in the text: the loader's message names the file, the line and the key, and
    // the running subsystem is as it was.
    await page.fill('#open-text', example.replace('    period: 1ms\n', '    period: 1 ms\n'));
    await page.click('#open-ok');
    await page.waitForFunction(() => document.querySelector('#open-error').textContent.includes('fig4_pid_joint.yaml:11: tasks[0].period'), null, { timeout: 15000 });
    assert.match((await apiStatus(link)).subsystem, /^serve_/);

    // Edited in place: a name of its own (its shared memory is named after it, and another test
    // may run the example meanwhile), the arm's loop soft (a shared test machine may miss a
    // deadline, which is not this test's subject); then opened.
    const name = `fig4_onika_${process.pid}`;
    const soft = example.replace('\nsubsystem: fig4\n', `\nsubsystem: ${name}\n`).replace('    module: pid_joint\n    period: 1ms\n', '    module: pid_joint\n    period: 1ms\n    criticality: soft\n')
      .replace('    module: robot_torque\n    period: 1ms\n', '    module: robot_torque\n    period: 1ms\n    criticality: soft\n');
    assert.ok(soft.includes(`subsystem: ${name}\n`) && (soft.match(/criticality: soft/g) || []).length === 5, 'the example changed: adapt this test');
    await page.fill('#open-text', soft);
    await page.screenshot({ path: join(shots, 'onika-open.png') });
    await page.click('#open-ok');
    await page.waitForSelector('#open-dialog', { state: 'hidden', timeout: 15000 });
    for (const task of ['traj', 'pid', 'robot', 'monitor', 'log']) await waitForState(page, task, 'ON');
    await page.waitForFunction((n) => document.querySelector('#subsystem-name').textContent === n, name, { timeout: 15000 });
    await page.waitForFunction(() => document.querySelector('#configuration-on').textContent === 'on: pid_control', null, { timeout: 15000 });
    assert.ok(await page.$('#canvas path.link[data-from="pid"][data-to="robot"][data-variable="tau_r"]'), 'the canvas draws the opened file');
    await page.waitForSelector('#events li[data-type="state"][data-task="pid"]:has-text("added (ON)")', { timeout: 15000 });
    const status = await apiStatus(link);
    assert.equal(status.subsystem, name);
    assert.deepEqual(status.tasks.map((t) => [t.name, t.state]), [['traj', 'ON'], ['pid', 'ON'], ['robot', 'ON'], ['monitor', 'ON'], ['log', 'ON']]);
    assert.deepEqual(problems, []);
  } finally {
    await context.close();
    assert.equal(await stopChimera(run), 0, run.stderr());
  }
});
