// The page in real headless Chromium (Debian's), driven by playwright-core, against a real
// hystlabd running short simulated FOT campaigns: the page loads and goes live, the loop plot
// and the Preisach heatmap fill, the identified model is drawn, a table downloads, and pause,
// resume and abort work from the buttons; the rig panel's E-STOP latches and Reset releases;
// the form checks its fields and shows the server's plan errors beside the input; the layout
// fits 800 px and uses 2560 px; a long campaign's loop keeps its unloading branches; data
// quality warnings are shown, among them, deterministically, the hole left by a 1 s outage of
// the load frame's controller (its simulator frozen with SIGSTOP while a campaign runs).
// Saves screenshots in OUT_DIR.
// usage: [ONLY=outage] node page_test.mjs HYSTLABD OUT_DIR
import { startDaemon as startHystlabd, stopDaemon as stopHystlabd } from './hystlabd.mjs';
import { Checks, chromium, chromiumPath as findChromium, freshDir, settledWidth } from './harness.mjs';
import fs from 'node:fs';
import path from 'node:path';


const [daemonPath, outDir] = process.argv.slice(2);
if (!daemonPath || !outDir) { console.error('usage: node page_test.mjs HYSTLABD OUT_DIR'); process.exit(2); }
// ONLY=outage runs the page's first checks and the injected outage alone (a quicker loop while
// working on it); the test as a whole runs everything.
const only = (process.env.ONLY || '').split(',').filter(Boolean);
const chromiumPath = findChromium();
freshDir(outDir);

const checks = new Checks(), check = checks.check;

// The daemon: its own database and config (a fast simulated load frame), a free port.
const FRAME_TIME_SCALE = 10;
fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'browser.db', rigs: [{ name: 'sim frame', simulate: { time_scale: FRAME_TIME_SCALE, noise_N: 0.05 } },
                           { name: 'sim shaker', simulate: { time_scale: 1, rig: 'shaker' } }],
}));
function startDaemon(portArg) {
  return startHystlabd(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', String(portArg)],
                       { cwd: outDir, timeoutMs: 20000, onOutput: d => { daemonLog += d; } });
}
// A campaign's own run (the newest, after a resume): not the validation run created beside it.
const ownRun = d => { const own = d.runs.filter(r => r.role !== 'validation'); return own[own.length - 1]; };

async function stopDaemon(d) { await stopHystlabd(d.proc); }
let daemonLog = '';
let pageWarnings = [];  // everything the daemons printed, shown when a check fails
let daemon = startDaemon(0);
const port = await daemon.port;
const base = `http://127.0.0.1:${port}`;

const browser = await chromium.launch({
  executablePath: chromiumPath, headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
         '--no-first-run', '--disable-sync', '--disable-quic'],
});
// On a timeout, say what the page and the daemon saw, so a failure in CI explains itself.
async function explain(page, what) {
  console.log(`timed out waiting for ${what}`);
  try {
    const seen = await page.evaluate(() => ({ state: window.hystlab.state(), selected: window.hystlab.selected(),
      online: window.hystlab.online(), loop: window.hystlab.loopPoints(), identified: window.hystlab.heatmapIdentified() }));
    console.log('  the page: ' + JSON.stringify(seen));
    if (seen.selected != null) {
      const get = async p => { const r = await fetch(base + p, { signal: AbortSignal.timeout(5000) }); return r.ok ? r.json() : `${r.status} ${await r.text()}`; };
      const c = await get(`/api/campaigns/${seen.selected}`);
      console.log('  the daemon: ' + JSON.stringify({ state: c.state, progress: c.progress, runs: c.runs && c.runs.length }));
      const ev = await get(`/api/campaigns/${seen.selected}/events`);
      const list = Array.isArray(ev) ? ev : (ev.events || []);
      for (const e of list.slice(-8)) console.log('  event: ' + JSON.stringify(e));
      console.log('  rigs: ' + JSON.stringify(await get('/api/rigs')));
    }
  } catch (e) { console.log('  (could not ask: ' + e + ')'); }
}
const wait = (page, fn, arg, what, timeout = 60000) =>
  page.waitForFunction(fn, arg, { timeout, polling: 100 }).then(() => true, async () => { await explain(page, what); return false; });

// The daemon, asked directly (no Origin header: allowed).
const has = async p => (await fetch(base + p, { signal: AbortSignal.timeout(10000) })).status !== 404;
const getJSON = async p => (await fetch(base + p, { signal: AbortSignal.timeout(10000) })).json();
const rigLatched = name => window.hystlab.rigs().some(r => r.name === name && r.latched);

// The form is the daemon's table of plan fields (GET /api/plans/form): an input for each field
// the table gives one, with its words. A field given an input there (here: control.gain, added
// to the answer on its way to the page) appears on the form, is checked with its bounds, and is
// sent at its path in the plan.
async function checkFormFromTable(context) {
  const table = await getJSON('/api/plans/form');
  const page = await context.newPage();
  await page.route('**/api/plans/form', async route => {
    const answer = await (await route.fetch()).json();
    answer.fields.push({ path: 'control.gain', words: 'control gain', label: 'control gain', unit: '', type: 'number', min: 0.05, max: 1,
                         group: 'sine', input: 'gain', value: '0.5', placeholder: '', optional: false });
    await route.fulfill({ json: answer });
  });
  const previews = [];
  page.on('request', r => { if (r.url().endsWith('/api/plans/preview')) previews.push(r.postDataJSON()); });
  await page.goto(base + '/');
  await page.waitForSelector('#f-gain', { state: 'attached', timeout: 20000 });
  const shown = await page.evaluate(fields => fields.filter(f => f.group).map(f => {
    const label = document.querySelector(`label[for="f-${f.input}"]`);
    return label && label.textContent.startsWith(f.label) && document.querySelector(`fieldset.${f.group} #f-${f.input}`) ? null : f.input;
  }).filter(Boolean), table.fields);
  check(shown.length === 0 && table.fields.filter(f => f.group).length > 20, `every input of the daemon's table is on the form, with its words (missing: ${shown.join(', ') || 'none'})`);
  await page.selectOption('select[name=kind]', 'sine');
  await page.fill('input[name=gain]', '0.3');
  const sent = () => previews.some(b => b.plan && b.plan.kind === 'sine' && b.plan.control && b.plan.control.gain === 0.3);
  for (const end = Date.now() + 10000; !sent() && Date.now() < end;) await new Promise(r => setTimeout(r, 100));
  check(sent(), 'a field added to the table reaches the plan the page sends (control.gain 0.3)');
  await page.fill('input[name=gain]', '2');
  await page.click('#submit');
  check(await wait(page, () => /control gain must be from 0\.05 to 1/.test(document.getElementById('f-gain-msg').textContent), null, 'the new field\'s bounds', 10000),
        'and is checked with the bounds the table gives it');
  await page.close();
}

// A ramp rate above the rig's maximum speed (20 mm/s): the server refuses the plan and names
// the field; the page shows its message beside the ramp rate input, and drops it on a change.
async function checkServerFieldError(page) {
  const plan = { kind: 'fot', range_mm: [0, 2], subdivisions: 2, ramp_rate_mm_s: 50 };
  const answer = await fetch(base + '/api/campaigns', { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ plan, rig: 'sim frame' }), signal: AbortSignal.timeout(10000) });
  const body = await answer.json().catch(() => ({}));
  await page.fill('input[name=hi]', '2');
  await page.fill('input[name=n]', '2');
  await page.fill('input[name=rate]', '50');
  await page.click('#submit');
  const shown = await page.waitForFunction(() => document.getElementById('f-rate-msg').textContent.length > 0 &&
      document.querySelector('input[name=rate]').getAttribute('aria-invalid') === 'true', null, { timeout: 20000, polling: 100 }).then(() => true, () => false);
  const message = await page.textContent('#f-rate-msg');
  if (answer.status === 400 && body.field) {
    const tail = String(body.detail || '').slice(-12);
    check(shown && message.includes(tail), `the server's plan error shows beside the ramp rate input ("${message}"; field ${body.field})`);
  } else console.log(`skip the server field check (the daemon answered ${answer.status} without "field"; the page showed "${message}")`);
  await page.fill('input[name=rate]', '0.5');
  check(await wait(page, () => document.getElementById('f-rate-msg').textContent === '' && !document.querySelector('input[name=rate][aria-invalid]'), null, 'message cleared', 10000),
        'the old message goes when the ramp rate changes');
  await page.fill('input[name=hi]', '4');
}

// The sticky header (the rigs with their E-STOP, the campaign's controls) leaves the screen to
// the work: at most about 12 % of the viewport from 800 px up, every E-STOP inside it; a rig's
// card opened (▸) shows its status bits, link and envelope.
async function checkHeaderShare(page) {
  const before = page.viewportSize();
  for (const [w, h] of [[800, 700], [1280, 800], [2560, 1440]]) {
    await page.setViewportSize({ width: w, height: h });
    await wait(page, ww => innerWidth === ww, w, `the viewport at ${w} px`, 10000);
    await page.evaluate(() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r))));  // laid out and drawn
    const m = await page.evaluate(() => {
      const top = document.getElementById('top').getBoundingClientRect();
      const stops = [...document.querySelectorAll('#top button.estop')].map(b => b.getBoundingClientRect());
      return { header: top.height, inside: stops.every(b => b.bottom <= top.bottom && b.right <= window.innerWidth), height: window.innerHeight };
    });
    await page.screenshot({ path: path.join(outDir, `header-${w}x${h}.png`) });
    check(m.header / m.height <= 0.13 && m.inside, `the header takes ${Math.round(m.header)} px of ${m.height} at ${w}x${h} (${(100 * m.header / m.height).toFixed(1)} %), every E-STOP in it`);
  }
  const card = page.locator('.rig[data-rig="sim frame"]');
  await card.locator('button.more').click();
  check(await card.locator('.health').isVisible() && await card.locator('.bits').isVisible(), 'an opened rig card shows its status bits and link health');
  await card.locator('button.more').click();
  await page.setViewportSize(before);
}

// E-STOP from the rig panel **while a campaign runs** (it once did nothing then: the rig's
// commands were read only between campaigns): the campaign ends aborted, the rig latches, the page
// shows it within 3 s (below), the reason shown, Submit refused; Reset asks first, then the latch
// clears when the simulated rig reports ready (it may refuse a reset on a busy machine: the
// operator, and this test, press it again).
async function checkEstop(page) {
  await page.selectOption('select[name=kind]', 'fot');
  await page.selectOption('select[name=rig]', 'sim frame');
  const plan = { kind: 'fot', range_mm: [0, 4], subdivisions: 4, ramp_rate_mm_s: 0.5, sample_rate_hz: 500,
                 limits: { displacement_mm: [-0.5, 4.5], force_N: 400, rate_mm_s: 20 } };
  const answer = await fetch(base + '/api/campaigns', { method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ plan, rig: 'sim frame' }), signal: AbortSignal.timeout(10000) });
  const id = (await answer.json()).id;
  const running = async () => { for (let k = 0; k < 300; k++) { if ((await getJSON(`/api/campaigns/${id}`)).state === 'running') return true; await new Promise(r => setTimeout(r, 100)); } return false; };
  check(answer.status === 201 && await running(), `a campaign runs on "sim frame" (campaign ${id})`);
  const pressed = Date.now();
  await page.click('.rig[data-rig="sim frame"] button.estop');
  const latched = await wait(page, rigLatched, 'sim frame', 'the rig latched', 20000);
  const shownMs = Date.now() - pressed;
  // The bound is the page's, not the rig's (the e-stop acts within 36 ms: test_estop_phases,
  // bench_estop): the page shows the latch on its POST's answer, not at its next poll of the rigs.
  // Measured with measure_estop_display.mjs (stop 51, 25 presses each): stress-ng --cpu 1 beside,
  // p50 208 ms, p95 437, max 501; --cpu 2, p50 141, p95 499, max 664; 1,144 ms once in a clean
  // clone's CI run beside the other browser tests and the fuzzers (the machine 92 % busy), over
  // the 1 s this bound was. 3 s: over 4 times the worst measured under stress-ng.
  check(latched && shownMs < 3000, `E-STOP during the campaign latches "sim frame", shown on the page ${shownMs} ms after the click (bound: 3 s)`);
  let ended = null;
  for (let k = 0; k < 100 && !ended; k++) { const c = await getJSON(`/api/campaigns/${id}`); if (c.final) ended = c; else await new Promise(r => setTimeout(r, 100)); }
  check(ended && ended.state === 'aborted', `the running campaign ends aborted by the e-stop (${ended && ended.state})`);
  check(await wait(page, () => { const l = document.querySelector('.rig[data-rig="sim frame"] .latch'); return l && !l.hidden && /LATCHED: \S/.test(l.textContent); },
                    null, 'the latch shown', 10000), 'the rig panel shows the latch and its reason: ' +
        JSON.stringify(await page.textContent('.rig[data-rig="sim frame"] .latch strong')));
  check(await wait(page, () => document.getElementById('submit').disabled && /latched/.test(document.getElementById('submit-why').textContent), null, 'Submit disabled', 10000),
        'Submit is disabled while the rig is latched, with the reason beside it');
  await page.screenshot({ path: path.join(outDir, 'estop.png') });
  const dialogs = [];
  let released = false, attempts = 0;
  const deadline = Date.now() + 60000;
  while (!released && Date.now() < deadline) {
    attempts++;
    page.once('dialog', d => { dialogs.push(d.type()); d.accept(); });
    await page.click('.rig[data-rig="sim frame"] button.reset', { timeout: 30000 });
    // Released, or refused (then press again).
    await page.waitForFunction(() => { const r = window.hystlab.rigs().find(x => x.name === 'sim frame');
      return r && (!r.latched || (r.reset_refusal && !r.resetting)); }, null, { timeout: 30000, polling: 200 }).catch(() => {});
    released = !(await page.evaluate(rigLatched, 'sim frame'));
    if (!released) await page.waitForTimeout(1000);
  }
  check(dialogs[0] === 'confirm', 'Reset asks for confirmation first');
  check(released, `Reset releases the latch (${attempts} press${attempts > 1 ? 'es' : ''})`);
  check(await wait(page, () => !document.getElementById('submit').disabled && document.getElementById('submit-why').textContent === '', null, 'Submit enabled', 10000),
        'Submit is enabled again');
}

// Reversals of x with a threshold of 2 % of its range; per descending branch, its x drop and
// the range of y along it.
function descendingBranches(x, y) {
  let lo = Infinity, hi = -Infinity, ylo = Infinity, yhi = -Infinity;
  for (const v of x) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  for (const v of y) { ylo = Math.min(ylo, v); yhi = Math.max(yhi, v); }
  const thr = 0.02 * (hi - lo), turns = [0];
  let dir = 0, ext = 0;
  for (let i = 1; i < x.length; i++) {
    if (dir === 0) { if (Math.abs(x[i] - x[0]) > thr) { dir = x[i] > x[0] ? 1 : -1; ext = i; } continue; }
    if (dir > 0) { if (x[i] >= x[ext]) ext = i; else if (x[ext] - x[i] > thr) { turns.push(ext); dir = -1; ext = i; } }
    else if (x[i] <= x[ext]) ext = i; else if (x[i] - x[ext] > thr) { turns.push(ext); dir = 1; ext = i; }
  }
  turns.push(ext);
  const branches = [];
  for (let k = 1; k < turns.length; k++) {
    const a = turns[k - 1], b = turns[k];
    if (!(x[b] < x[a])) continue;
    let bl = Infinity, bh = -Infinity;
    for (let i = a; i <= b; i++) { bl = Math.min(bl, y[i]); bh = Math.max(bh, y[i]); }
    branches.push({ drop: x[a] - x[b], yRange: bh - bl });
  }
  return { branches, xRange: hi - lo, yRange: yhi - ylo };
}
function checkLoopShape(lp, subdivisions, what) {
  const { branches, xRange, yRange } = descendingBranches(lp.x, lp.y);
  const step = xRange / subdivisions;
  const real = branches.filter(b => b.drop > step);
  const flat = real.filter(b => b.yRange <= 0.1 * yRange);
  check(branches.length >= subdivisions, `${what}: ${branches.length} descending branches (at least ${subdivisions}) in ${lp.x.length} points`);
  check(real.length > 0 && flat.length === 0, `${what}: each of the ${real.length} long unloading branches drops the force by over 10 % of its range` +
        (flat.length ? ` (${flat.length} do not: ${JSON.stringify(flat.slice(0, 3))})` : ''));
}

// A FOT campaign long enough for >= 20,000 samples (0-4 mm, n = 6, 0.1 mm/s: ~150 s of rig
// time at time_scale 10 and 1000 Hz). Its loop, drawn from the server's shape-preserving path,
// must keep every unloading branch; screenshots of it drawn with ~5 k and ~50 k points.
async function checkLongLoop(page) {
  const subdivisions = 6;
  await page.fill('input[name=lo]', '0');
  await page.fill('input[name=hi]', '4');
  await page.fill('input[name=n]', String(subdivisions));
  await page.fill('input[name=rate]', '0.1');
  await page.fill('input[name=dwell]', '0.2');
  await page.fill('input[name=hz]', '1000');
  await page.click('#submit');
  check(await wait(page, () => window.hystlab.state() === 'running', null, 'the long campaign running', 60000), 'the long campaign runs');
  await wait(page, () => window.hystlab.loopPoints() > 300, null, 'a live loop', 120000);
  await page.locator('#loop-plot').screenshot({ path: path.join(outDir, 'loop-live.png') });
  check(await wait(page, () => window.hystlab.state() === 'completed', null, 'the long campaign completing', 900000), 'the long campaign completes');
  const id = await page.evaluate(() => window.hystlab.selected());
  const d = await getJSON(`/api/campaigns/${id}`);
  const run = ownRun(d);
  const samples = (await getJSON(`/api/runs/${run.id}`)).samples;
  check(samples >= 20000, `the long run stored ${samples} samples (at least 20,000${samples < 20000 ? ': a very busy machine stores fewer' : ''})`);
  if (!(await has(`/api/runs/${run.id}/loop?points=10`))) {
    console.log('skip the loop shape and the 5 k / 50 k screenshots (this daemon has no /api/runs/ID/loop)');
    await page.locator('#loop-plot').screenshot({ path: path.join(outDir, 'loop-live-completed.png') });
  } else {
    check(await wait(page, () => window.hystlab.loopInfo() && window.hystlab.loopPoints() > 100, null, 'the server loop', 30000), 'the completed loop comes from the server');
    const lp = await page.evaluate(() => window.hystlab.loopPath());
    console.log(`     the completed view draws ${lp.x.length} points`);
    checkLoopShape(lp, subdivisions, 'the completed loop');
    for (const [points, file] of [[5000, 'loop-5k.png'], [50000, 'loop-50k.png']]) {
      await page.evaluate(n => window.hystlab.loadLoop(n), points);  // resolves once loaded and drawn
      await page.evaluate(() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r))));
      const drawn = await page.evaluate(() => window.hystlab.loopPath());
      console.log(`     ${file}: ${drawn.x.length} points drawn`);
      checkLoopShape(drawn, subdivisions, `the loop at ${points} points`);
      await page.locator('#loop-plot').screenshot({ path: path.join(outDir, file) });
    }
    await page.evaluate(() => window.hystlab.loadLoop(2000));
  }
  await checkQualityWarning(page);
}

// IF the selected campaign's runs or tables carry warnings THEN the page shows every one of
// them in the warning box (a busy machine makes some; without any: skip, unless `required`:
// the outage campaign below must have them, and none is a failure).
async function checkQualityWarning(page, { required = false, shot = 'warnings.png' } = {}) {
  const id = await page.evaluate(() => window.hystlab.selected());
  const d = await getJSON(`/api/campaigns/${id}`);
  const expected = [];
  for (const r of d.runs) for (const w of (r.quality && r.quality.warnings) || []) expected.push(w);
  for (const t of d.tables || []) for (const w of t.warnings || []) expected.push(w);
  if (d.runs.some(r => r.quality)) {
    check(await wait(page, () => /missed deadline/.test(document.getElementById('quality').textContent), null, 'the quality line', 20000),
          'each run shows its quality line (missed deadlines, lost samples, I/O errors, gaps)');
  } else console.log('skip the quality line (this daemon sends no run quality)');
  if (!expected.length) {
    if (required) check(false, `campaign #${id} has warnings for the page to show (it has none)`);
    else console.log('skip the warning box (this campaign has no warnings)');
    return;
  }
  check(await wait(page, n => window.hystlab.warnings().length >= n && !document.getElementById('warnings').hidden, expected.length, 'the warnings', 20000),
        `the page shows the campaign's ${expected.length} warning(s) in the warning box`);
  const text = await page.textContent('#warnings');
  check(expected.every(w => text.includes(w)), 'every warning of the runs and tables is in the box');
  if (shot) await page.screenshot({ path: path.join(outDir, shot) });
}

// The load frame's simulator: the child of hystlabd whose command line says `--rig load_frame`
// (hystlabd spawns one hystlab-sim per simulated rig; daemon/src/sim_child.cpp). Read from
// /proc when needed: a simulator that died is started again under a new pid.
function frameSimulator() {
  const children = [];
  const tasks = `/proc/${daemon.proc.pid}/task`;
  for (const t of fs.readdirSync(tasks)) {
    try { children.push(...fs.readFileSync(`${tasks}/${t}/children`, 'utf8').trim().split(/\s+/).filter(Boolean).map(Number)); } catch { /* a thread gone */ }
  }
  const sims = [];
  for (const pid of new Set(children)) {
    let argv;
    try { argv = fs.readFileSync(`/proc/${pid}/cmdline`, 'utf8').split('\0'); } catch { continue; }
    const rig = argv[argv.indexOf('--rig') + 1];
    if (path.basename(argv[0]) === 'hystlab-sim' && argv.includes('--rig')) sims.push({ pid, rig, cmdline: argv.join(' ').trim() });
  }
  const frames = sims.filter(s => s.rig === 'load_frame');
  return { frames, sims };
}

// A data-quality warning from an injected 1 s outage, deterministically. A short FOT campaign
// runs on "sim frame" (time scale 10, so the freeze is 10 s of rig time); once it is running and
// its samples are stored, the load frame's simulated controller is frozen for OUTAGE_MS with
// SIGSTOP, then continued. The daemon's reads time out meanwhile (the acquisition loop counts
// the missed periods; 20 of them would hold the rig and a returning link would take the segment
// again, 500 would fail the campaign: acquisition_loop.cpp), and its time axis has a hole there.
// The campaign then ends however supervision decides (completed, or failed: a paused or
// interrupted one is resumed, as an operator would). Checked: the daemon's run quality counts
// a hole of the outage's length, overlapping the outage; the page, with the campaign selected,
// shows that warning in its warning box (and every other warning of the campaign).
const OUTAGE_MS = 1000, LIVE_STATES = ['queued', 'arming', 'running', 'paused'];
async function checkOutage(page) {
  const sleep = ms => new Promise(r => setTimeout(r, ms));
  const post = async (p, body) => {
    const r = await fetch(base + p, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: body ? JSON.stringify(body) : undefined,
                                      signal: AbortSignal.timeout(10000) });
    return { status: r.status, body: await r.json().catch(() => ({})) };
  };
  // 0-4 mm, n = 4, 0.5 mm/s: 40 s of rig time (4 s of wall time at time scale 10) and more on a busy host.
  const plan = { kind: 'fot', range_mm: [0, 4], subdivisions: 4, ramp_rate_mm_s: 0.5, dwell_s: 0.1, sample_rate_hz: 200 };
  const submitted = await post('/api/campaigns', { plan, rig: 'sim frame' });
  check(submitted.status === 201 && submitted.body.id, `the outage campaign is queued on "sim frame" (${submitted.status})`);
  const id = submitted.body.id;
  if (!id) return;
  // Running, with samples stored: the controller is answering before it is frozen.
  let d = null, stored = 0;
  for (const until = Date.now() + 120000; Date.now() < until; await sleep(100)) {
    d = await getJSON(`/api/campaigns/${id}`);
    if (d.state === 'running' && d.runs.length) stored = (await getJSON(`/api/runs/${ownRun(d).id}`)).samples || 0;
    if ((d.state === 'running' && stored >= 20) || !LIVE_STATES.includes(d.state)) break;
  }
  if (!check(d && d.state === 'running' && stored >= 20, `the outage campaign #${id} runs and stores samples (${d && d.state}, ${stored} samples)`)) return;
  const { frames, sims } = frameSimulator();
  check(frames.length === 1, `exactly one of hystlabd's simulators is the load frame's: ${JSON.stringify(sims.map(s => `${s.pid}: ${s.cmdline}`))}`);
  if (frames.length !== 1) return;
  const sim = frames[0].pid;
  const stateBefore = (await getJSON(`/api/campaigns/${id}`)).state;
  let stopAt = 0, contAt = 0;
  try {
    process.kill(sim, 'SIGSTOP');
    stopAt = Date.now();
    await sleep(OUTAGE_MS);
  } finally {
    contAt = Date.now();
    process.kill(sim, 'SIGCONT');
  }
  console.log(`     froze hystlab-sim ${sim} (--rig load_frame) for ${contAt - stopAt} ms while campaign #${id} was ${stateBefore}`);
  check(stateBefore === 'running', `the controller was frozen while the campaign ran (${stateBefore})`);
  // Until it ends; paused or interrupted: resumed, as an operator would.
  const resumed = [];
  for (const until = Date.now() + 300000; Date.now() < until; await sleep(250)) {
    d = await getJSON(`/api/campaigns/${id}`);
    if (['completed', 'failed', 'aborted'].includes(d.state)) break;
    if (['paused', 'interrupted'].includes(d.state) && resumed.length < 3) {
      const r = await post(`/api/campaigns/${id}/resume`);
      resumed.push(`${d.state}: resume ${r.status}`);
      await sleep(1000);
    }
  }
  const states = (await getJSON(`/api/campaigns/${id}/events`)).filter(e => e.kind === 'state').map(e => `${e.to}${e.detail ? ` (${e.detail})` : ''}`);
  console.log(`     campaign #${id}: ${states.join(' → ')}${resumed.length ? `; resumed: ${resumed.join(', ')}` : ''}`);
  if (!check(['completed', 'failed', 'aborted'].includes(d.state), `the outage campaign ends (${d.state})`)) return;

  // The daemon's account: a hole at least half the outage long (in rig time) overlapping at
  // least half of it. Its wall time is from the gap event: stored as the hole closed (`at`).
  const run = ownRun(d);
  const q = run.quality || {};
  const events = await getJSON(`/api/campaigns/${id}/events`);
  const holes = events.filter(e => e.kind === 'gap' && e.detail).map(e => {
    const end = Date.parse(e.at), start = end - e.detail.length_ms / FRAME_TIME_SCALE;
    return { ms: e.detail.length_ms, overlap: Math.min(end, contAt) - Math.max(start, stopAt) };
  });
  const outage = holes.filter(h => h.ms >= 0.5 * OUTAGE_MS * FRAME_TIME_SCALE && h.overlap >= 0.5 * (contAt - stopAt));
  check(outage.length >= 1, `a hole in campaign #${id}'s time axis covers the outage (${outage.length ? `${Math.round(outage[0].ms)} ms of rig time, ` +
        `${Math.round(outage[0].overlap)} ms of the ${contAt - stopAt} ms frozen` : `the holes: ${JSON.stringify(holes.slice(-5))}`})`);
  const longest = outage.length ? Math.max(...outage.map(h => h.ms)) / 1000 : Infinity;
  check(q.gaps >= 1 && q.longest_gap_s >= longest * 0.999,
        `run #${run.id}'s quality counts it: ${q.gaps} gap(s), the longest ${q.longest_gap_s} s of rig time; ${q.timeouts} timeouts, ${q.io_errors} I/O errors`);
  const gapWarning = ((q.warnings) || []).find(w => /holes? in the time axis/.test(w));
  check(!!gapWarning, `run #${run.id}'s quality warns of it: "${gapWarning}"`);

  // The page: the campaign selected from the list; its warning box shows the server's words.
  await page.click(`#campaigns li[data-id="${id}"]`);
  check(await wait(page, n => window.hystlab.selected() === n && window.hystlab.state() != null, id, 'the outage campaign selected', 20000),
        `campaign #${id} is selected on the page`);
  const line = `run #${run.id}: ${gapWarning}`;
  check(await wait(page, w => !document.getElementById('warnings').hidden && document.getElementById('warnings').textContent.includes(w), line, 'the outage warning', 20000),
        `the page's warning box shows "${line}"`);
  check(await wait(page, r => [...document.querySelectorAll('#quality li')].some(li => li.textContent.startsWith(`run #${r}:`) && /\d+ gaps? \(/.test(li.textContent)), run.id,
                   'the quality line with the gaps', 20000), `the page's quality line for run #${run.id} shows its gaps: ` +
        JSON.stringify(await page.evaluate(() => document.getElementById('quality').textContent)));
  await checkQualityWarning(page, { required: true, shot: null });
  await page.evaluate(() => { window.scrollTo(0, 0); document.getElementById('warnings').scrollIntoView({ block: 'center' }); });
  await page.screenshot({ path: path.join(outDir, 'outage-warning.png') });
}

try {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1400, height: 1100 } });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', e => errors.push(String(e)));
  const warnings = [];  // the page's own account of a failed update (shown if a check fails)
  page.on('console', m => { if (m.type() === 'error') errors.push(m.text()); else if (m.type() === 'warning') warnings.push(m.text()); });
  pageWarnings = warnings;
  // Every 5xx the page received, by request and with the API's error, said in the log (the
  // console message names no URL).
  page.on('response', r => {
    if (r.status() < 500) return;
    const what = `${r.request().method()} ${new URL(r.url()).pathname}`;
    r.json().then(b => console.log(`     the page's ${what} was answered ${r.status()} (${b && b.error})`),
      () => console.log(`     the page's ${what} was answered ${r.status()} (no JSON body)`));
  });
  // A 4xx the page handles (a plan error, an endpoint an older daemon lacks) is logged by the
  // browser as a failed resource: not a script error. So is a 503, the API's answer while a rig
  // does not answer (docs/API.md: "rig unreachable"): this test freezes the frame's controller for
  // a second, and stop 50's clean clone saw hystlab-sim miss its 50 ms for half a minute beside
  // two browsers; the page shows the answer. A 500 (a daemon bug) stays an error.
  const scriptErrors = () => errors.filter(e => !/Failed to load resource: the server responded with a status of (4\d\d|503)/.test(e));
  await page.goto(base + '/');
  check(await wait(page, () => window.hystlab && window.hystlab.online(), null, 'the event stream'), 'the page loads and its event stream goes live');
  check(await page.evaluate(() => typeof uPlot === 'function'), 'the plotting library is served by the daemon');
  check(await wait(page, () => window.hystlab.rigs().length === 2 && document.querySelectorAll('.rig button.estop').length === 2, null, 'rig panel'),
        'the rig panel shows both rigs, each with its E-STOP');
  check(/x -?\d+\.\d+ mm · F -?\d+\.\d N/.test(await page.textContent('.rig[data-rig="sim frame"] .live')), 'the rig panel shows the live position and force');
  await checkHeaderShare(page);

  if (!only.length) {
    await checkFormFromTable(context);
    // 0. The form checks its fields before sending anything.
    const campaignCount = async () => (await getJSON('/api/campaigns')).length;
    const before = await campaignCount();
    let posts = 0;  // the page's submissions: the form's own checks send none
    const countPosts = r => { if (r.method() === 'POST' && r.url().endsWith('/api/campaigns')) ++posts; };
    page.on('request', countPosts);
    await page.fill('input[name=hi]', '');
    await page.click('#submit');
    check(await wait(page, () => /δmax is required/.test(document.getElementById('f-hi-msg').textContent), null, 'the δmax message', 10000) &&
          await page.getAttribute('input[name=hi]', 'aria-invalid') === 'true', 'a blank δmax is named beside its input, marked invalid');
    page.off('request', countPosts);
    check(posts === 0 && await campaignCount() === before, 'and nothing was submitted');
    await page.fill('input[name=hi]', '4');
    check(await wait(page, () => document.getElementById('f-hi-msg').textContent === '' && !document.querySelector('input[name=hi][aria-invalid]'), null, 'the message cleared', 10000),
          'typing a valid δmax clears the message');

    // 1. A short FOT campaign from the form, run to completion: three training cycles, the rows,
    // then the validation run (the form's default: 12 reversals).
    await page.fill('input[name=n]', '4');
    await page.fill('input[name=rate]', '1');
    await page.fill('input[name=dwell]', '0.1');
    await page.fill('input[name=training]', '3');
    await page.fill('input[name=plateaus]', '1, 3');
    await page.click('#submit');
    check(await wait(page, () => window.hystlab.selected() != null && window.hystlab.loopPoints() > 50, null, 'loop points'),
          'the force-displacement loop grows from live samples');
    check(await wait(page, () => window.hystlab.heatmapIdentified() > 0, null, 'heatmap'), 'the Preisach heatmap fills node by node');
    check(await wait(page, () => window.hystlab.state() === 'completed', null, 'completion', 120000), 'the campaign completes');
    check(await wait(page, () => window.hystlab.heatmapIdentified() === window.hystlab.heatmapRequired(), null, 'full triangle'),
          'every node of the triangle is identified (10 of 10)');
    const loopEndpoint = await has(`/api/runs/${(await getJSON(`/api/campaigns/${await page.evaluate(() => window.hystlab.selected())}`)).runs[0].id}/loop?points=10`);
    if (loopEndpoint) {
      check(await wait(page, () => window.hystlab.modelPoints() > 0, null, 'model overlay'), 'the identified model is drawn over the measured loop');
      check(await page.evaluate(() => { const m = window.hystlab.modelPath(), l = window.hystlab.loopPath(); return m.x.length === l.x.length && m.y.every(Number.isFinite); }),
            'the model is drawn on the measured loop\'s x (from /api/runs/ID/loop)');
    } else console.log('skip the identified model overlay and the loop checks (this daemon has no /api/runs/ID/loop)');
    check(/RMS/.test(await page.textContent('#accuracy')), 'the accuracy numbers are shown');
    const link = page.locator('#downloads a', { hasText: '(fot) .json' }).first();
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: 20000 }), link.click()]);
    const file = path.join(outDir, 'downloaded-table.json');
    await download.saveAs(file);
    const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
    check(doc.format === 'hystlab-everett-table' && Array.isArray(doc.nodes_mm) && doc.nodes_mm.length === 5, `a table downloads (${download.suggestedFilename()})`);
    const fmuLink = page.locator('#downloads a', { hasText: '(fot) .fmu' }).first();
    const [fmu] = await Promise.all([page.waitForEvent('download', { timeout: 20000 }), fmuLink.click()]);
    const fmuFile = path.join(outDir, 'downloaded-table.fmu');
    await fmu.saveAs(fmuFile);
    const fmuBytes = fs.readFileSync(fmuFile);
    check(fmuBytes.subarray(0, 4).equals(Buffer.from('PK\x03\x04', 'latin1')) && fmuBytes.includes('modelDescription.xml') && fmuBytes.length > 100000,
          `the table downloads as an FMU (${fmu.suggestedFilename()}, ${fmuBytes.length} bytes)`);
    // Identification: the training curve, each table's held-out error, the recommended table, the loop figures.
    check(await wait(page, () => window.hystlab.shakedownPoints() === 3, null, 'the shakedown curve', 20000), 'the training curve shows its 3 cycles');
    check(await wait(page, () => window.hystlab.heldOut().length === 2, null, 'held-out figures', 20000),
          'both tables show their error on the validation run (held out)');
    const shown = await getJSON(`/api/campaigns/${await page.evaluate(() => window.hystlab.selected())}`);
    check(shown.recommendation && await page.evaluate(() => window.hystlab.recommended()) === shown.recommendation.table,
          `the recommended table is marked (#${shown.recommendation && shown.recommendation.table}) and its reason given`);
    check(/lowest error on the validation run/.test(await page.textContent('#accuracy')), 'the recommendation says why');
    check(await wait(page, () => window.hystlab.loopRows() >= 7, null, 'loop figures', 20000),
          'the loop figures list every closed cycle (3 training loops, 4 rows, the validation\'s)');
    await page.evaluate(() => { document.getElementById('loops-box').open = true; });
    await page.fill('input[name=training]', '0');
    await page.fill('input[name=plateaus]', '');
    await page.screenshot({ path: path.join(outDir, 'fot-completed.png'), fullPage: true });

    // 2. A slower campaign: pause, resume and abort from the buttons.
    await page.fill('input[name=n]', '8');
    await page.fill('input[name=rate]', '0.2');
    await page.click('#submit');
    check(await wait(page, () => window.hystlab.state() === 'running', null, 'running'), 'the second campaign runs');
    // The layout at 800 px: no sideways scrolling, the commands in view; at 2560 px the plots grow.
    await page.setViewportSize({ width: 800, height: 900 });
    await wait(page, () => document.querySelector('#loop-plot canvas').getBoundingClientRect().width <= 800, null, 'the plots at 800 px', 10000);
    const settled = await settledWidth(page, 800);
    const fits = await page.evaluate(() => {
      const inside = el => { const r = el.getBoundingClientRect(); return r.width > 0 && r.left >= 0 && r.top >= 0 && r.right <= innerWidth && r.bottom <= innerHeight; };
      return { scrollWidth: document.documentElement.scrollWidth, pause: inside(document.getElementById('pause')), abort: inside(document.getElementById('abort')),
               estop: [...document.querySelectorAll('button.estop')].every(inside), loop: document.getElementById('loop-plot').getBoundingClientRect().width };
    });
    check(fits.scrollWidth <= 800, `no horizontal scrolling at 800 px (scrollWidth ${fits.scrollWidth}${fits.scrollWidth > 800 && settled.over.length ? '; past 800 px: ' + settled.over.join(', ') : ''})`);
    check(fits.pause && fits.abort && fits.estop, `Pause, Abort and E-STOP inside the viewport at 800 px (${JSON.stringify(fits)})`);
    await page.evaluate(() => window.scrollTo(0, 1500));
    await wait(page, () => window.scrollY > 0, null, 'scrolled', 10000);
    check(await page.evaluate(() => { const r = document.getElementById('abort').getBoundingClientRect(); return r.top >= 0 && r.bottom <= innerHeight; }),
          'Abort stays in view when the page is scrolled');
    await page.screenshot({ path: path.join(outDir, 'layout-800.png') });
    await page.evaluate(() => window.scrollTo(0, 0));
    await page.setViewportSize({ width: 2560, height: 1300 });
    await wait(page, w => document.querySelector('#loop-plot canvas').getBoundingClientRect().width > w, fits.loop, 'the plots at 2560 px', 10000);
    const wide = await page.evaluate(() => ({ scrollWidth: document.documentElement.scrollWidth, loop: document.getElementById('loop-plot').getBoundingClientRect().width,
                                              canvas: document.querySelector('#loop-plot canvas').getBoundingClientRect().width }));
    check(wide.loop > fits.loop && wide.canvas > fits.loop * 0.9 && wide.scrollWidth <= 2560, `the loop plot is wider at 2560 px (${Math.round(wide.canvas)} px) than at 800 px (${Math.round(fits.loop)} px)`);
    await page.screenshot({ path: path.join(outDir, 'layout-2560.png') });
    await page.setViewportSize({ width: 1400, height: 1100 });
    await wait(page, () => document.querySelector('#loop-plot canvas').getBoundingClientRect().width <= 1400, null, 'the plots at 1400 px', 10000);

    await page.click('#pause');
    check(await wait(page, () => window.hystlab.state() === 'paused', null, 'paused', 20000), 'Pause holds the campaign');
    await page.click('#resume');
    check(await wait(page, () => window.hystlab.state() === 'running', null, 'resumed', 20000), 'Resume continues it');
    await page.click('#abort');
    check(await wait(page, () => window.hystlab.state() === 'aborted', null, 'aborted', 30000), 'Abort ends it (safe position)');
    await page.screenshot({ path: path.join(outDir, 'page.png'), fullPage: true });

    // 2b. A plan error from the server is shown beside the input its `field` names.
    await checkServerFieldError(page);

    // 2c. The E-STOP latches the rig; Submit is refused until Reset (with a confirmation).
    await checkEstop(page);

    // 2d. A long campaign: the loop keeps its unloading branches (drawn in sample order).
    await checkLongLoop(page);
  }

  // 2e. A 1 s outage of the load frame's controller: the page warns of the hole it left.
  if (!only.length || only.includes('outage')) await checkOutage(page);

  if (!only.length) {
    // 3. A shaker sweep: the rig is picked for the plan, transmissibility builds point by point.
    await page.selectOption('select[name=kind]', 'sine');
    check(await page.inputValue('select[name=rig]') === 'sim shaker', 'a sine plan picks the shaker');
    await page.fill('input[name=freqs]', '4, 8, 12');
    await page.fill('input[name=settle]', '3');
    await page.fill('input[name=measured]', '3');
    await page.fill('input[name=hz]', '500');
    // The isolator's springs: the FOT table identified on the frame in 1., named by its id.
    const fot = (await getJSON('/api/tables')).filter(t => t.method === 'fot').map(t => t.id);
    const table = fot.length ? fot[0] : null;
    check(table != null, `the frame's FOT table is in the store for the shaker's prediction (#${table})`);
    await page.fill('input[name=isotable]', String(table));
    await page.click('#submit');
    check(await wait(page, () => window.hystlab.transmissibilityPoints() >= 1 && window.hystlab.loopPoints() > 20, null, 'transmissibility'),
          'the transmissibility plot and the base/mass signals build while the sweep runs');
    check(await wait(page, () => window.hystlab.state() === 'completed' && window.hystlab.transmissibilityPoints() === 3, null, 'sweep done'),
          'the sweep completes with a point per frequency');
    // Measured against predicted from the named table, with its provenance.
    check(await wait(page, () => window.hystlab.transmissibilityCurves().length === 4 && window.hystlab.transmissibilityCurves().every(c => c.predicted === 3), null, 'the prediction', 20000),
          `each curve predicted from table #${table} is drawn beside the measured one: ${JSON.stringify(await page.evaluate(() => window.hystlab.transmissibilityCurves()))}`);
    // The status line turns from the last step's progress to the sweep's summary on its own poll,
    // after the curves: wait for it (stop 41's clean-clone run read the progress line once, too early).
    await wait(page, () => document.querySelector('#sweep-status').textContent.includes('predicted with '), null, 'the summary line', 20000);
    const said = await page.textContent('#sweep-status');
    check(said.includes('predicted with ') && said.includes(`Preisach table n = 4 (fot, table ${table}: campaign `), `the page names the table and how it was identified: "${said}"`);
    await page.fill('input[name=isotable]', '');
    await page.screenshot({ path: path.join(outDir, 'shaker.png'), fullPage: true });

    check(scriptErrors().length === 0, 'no script errors on the page' + (scriptErrors().length ? ': ' + scriptErrors().join(' | ') : ''));

    // 4. The daemon restarts: the page notices, and reconnects on its own (the browser logs the
    // broken stream as a failed resource; anything else would be a script error).
    errors.length = 0;
    await stopDaemon(daemon);
    check(await wait(page, () => !window.hystlab.online(), null, 'offline', 20000), 'the page shows the daemon gone');
    daemon = startDaemon(port);
    await daemon.port;
    check(await wait(page, () => window.hystlab.online(), null, 'reconnect', 30000), 'and reconnects when it is back');
    const unexpected = scriptErrors().filter(e => !/Failed to load resource: net::/.test(e));
    check(unexpected.length === 0, 'no script errors across the restart' + (unexpected.length ? ': ' + unexpected.join(' | ') : ''));
  } else {
    check(scriptErrors().length === 0, 'no script errors on the page' + (scriptErrors().length ? ': ' + scriptErrors().join(' | ') : ''));
  }
} catch (e) {
  console.log('FAIL ' + (e.stack || e));
  checks.failures++;
} finally {
  await browser.close();
  await stopDaemon(daemon);
}
if (checks.failures && pageWarnings.length) console.log('the page warned:\n' + pageWarnings.slice(-20).join('\n'));
if (checks.failures) console.log('the daemon printed (last 6000 characters):\n' + daemonLog.slice(-6000));
console.log(checks.failures ? `${checks.failures} check(s) failed (screenshots in ${outDir})` : `all checks passed (screenshots in ${outDir})`);
process.exit(checks.failures ? 1 : 0);
