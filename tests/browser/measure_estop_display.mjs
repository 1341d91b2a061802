// The time from a click on a rig's E-STOP to the page showing the rig latched, while a campaign
// runs: the distribution behind page_test.mjs's bound (not run by the CI; run it on a loaded
// machine, e.g. with `stress-ng --cpu 1` beside it).
//   node tests/browser/measure_estop_display.mjs build/daemon/hystlabd [presses, default 25]
// Each press: a FOT campaign submitted and running on a simulated frame (10 times real time, as
// in the page test), the click, the wait for the rig panel's latch; then a reset through the API
// (pressed again while the rig refuses it) before the next. Prints every time and p50/p95/max.
import path from 'node:path';
import os from 'node:os';
import fs from 'node:fs';
import { startDaemon, stopDaemon } from './hystlabd.mjs';
import { chromium, chromiumPath } from './harness.mjs';

const [daemonPath, pressesArg] = process.argv.slice(2);
if (!daemonPath) { console.error('usage: node measure_estop_display.mjs HYSTLABD [PRESSES]'); process.exit(2); }
const presses = Number(pressesArg || 25);
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'hystlab-estop-'));
fs.writeFileSync(path.join(dir, 'hystlab.json'), JSON.stringify({
  db: 'estop.db', rigs: [{ name: 'sim frame', simulate: { time_scale: 10, noise_N: 0.05 } }] }));
const daemon = startDaemon(path.resolve(daemonPath), ['--config', path.join(dir, 'hystlab.json'), '--port', '0'], { cwd: dir });
const base = `http://127.0.0.1:${await daemon.port}`;
const call = async (method, p, body) => {
  const r = await fetch(base + p, { method, headers: { 'Content-Type': 'application/json' }, body: body && JSON.stringify(body), signal: AbortSignal.timeout(20000) });
  return { status: r.status, json: await r.json().catch(() => null) };
};
const sleep = ms => new Promise(r => setTimeout(r, ms));
const rigLatched = async () => (await call('GET', '/api/rigs')).json.some(r => r.name === 'sim frame' && r.latched);

const browser = await chromium.launch({ executablePath: chromiumPath(), headless: true, args: ['--headless', '--no-sandbox', '--disable-gpu'] });
const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
await page.goto(base + '/');
await page.waitForFunction(() => window.hystlab && window.hystlab.rigs().some(r => r.name === 'sim frame'), null, { timeout: 30000 });
const plan = { kind: 'fot', range_mm: [0, 4], subdivisions: 4, ramp_rate_mm_s: 0.5, sample_rate_hz: 500,
               limits: { displacement_mm: [-0.5, 4.5], force_N: 400, rate_mm_s: 20 } };
const times = [];
try {
  for (let k = 0; k < presses; k++) {
    const submitted = await call('POST', '/api/campaigns', { plan, rig: 'sim frame' });
    if (submitted.status !== 201) throw new Error(`press ${k}: submission answered ${submitted.status} ${JSON.stringify(submitted.json)}`);
    const id = submitted.json.id;
    let state = '';
    for (let t = 0; t < 300 && state !== 'running'; t++) { state = (await call('GET', `/api/campaigns/${id}`)).json.state; if (state !== 'running') await sleep(100); }
    if (state !== 'running') throw new Error(`press ${k}: campaign ${id} did not run (${state})`);
    const pressed = Date.now();
    await page.click('.rig[data-rig="sim frame"] button.estop');
    await page.waitForFunction(name => window.hystlab.rigs().some(r => r.name === name && r.latched), 'sim frame', { timeout: 20000, polling: 10 });
    times.push(Date.now() - pressed);
    console.log(`press ${k + 1}: shown ${times[times.length - 1]} ms after the click`);
    for (let t = 0; t < 60 && await rigLatched(); t++) { await call('POST', '/api/rigs/sim%20frame/reset'); await sleep(500); }
    if (await rigLatched()) throw new Error(`press ${k}: the rig stayed latched after 60 resets`);
    for (let t = 0; t < 100 && !(await call('GET', `/api/campaigns/${id}`)).json.final; t++) await sleep(100);
  }
} finally {
  await browser.close();
  await stopDaemon(daemon.proc);
  fs.rmSync(dir, { recursive: true, force: true });
}
const sorted = [...times].sort((a, b) => a - b);
const q = p => sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
console.log(`${sorted.length} presses: p50 ${q(0.5)} ms, p95 ${q(0.95)} ms, max ${sorted[sorted.length - 1]} ms (load average ${os.loadavg()[0].toFixed(2)})`);
