// The rig panel when a load frame has left its stroke, in Debian's headless Chromium: hystlab-sim
// (its own process, in real time) is pushed past its 12 mm limit by `fault overtravel 13`; the
// panel must show the latch with its reason and a "Bring back into stroke…" button that asks
// first, then brings the frame back at the safe rate (the card goes idle, the button away).
// Screenshots at 800 and 1280 px in OUT_DIR.
// usage: node recovery_test.mjs HYSTLABD OUT_DIR
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import path from 'node:path';
import { Checks, chromium, chromiumPath, freshDir } from './harness.mjs';
import { startDaemon, stopDaemon } from './hystlabd.mjs';

const [daemonPath, outDir] = process.argv.slice(2);
freshDir(outDir);
const checks = new Checks();
const { check } = checks;
let failures = 0;
const simPath = path.resolve(path.dirname(daemonPath), '../drivers/sim/hystlab-sim');

// hystlab-sim: its Modbus and control ports from the lines it prints.
const sim = spawn(simPath, ['--port', '0', '--time-scale', '1', '--noise', '0.05', '--exit-with-parent', '1'], { stdio: ['ignore', 'pipe', 'inherit'] });
const ports = await new Promise((resolve, reject) => {
  let out = '';
  const timer = setTimeout(() => reject(new Error('hystlab-sim did not start: ' + out)), 10000);
  sim.stdout.on('data', d => {
    out += d;
    const m = /modbus-tcp 127\.0\.0\.1:(\d+)/.exec(out), c = /control 127\.0\.0\.1:(\d+)/.exec(out);
    if (m && c && /ready/.test(out)) { clearTimeout(timer); resolve({ modbus: Number(m[1]), control: Number(c[1]) }); }
  });
});
const control = line => new Promise((resolve, reject) => {
  const s = net.connect(ports.control, '127.0.0.1', () => s.write(line + '\n'));
  s.on('data', d => { resolve(String(d)); s.end(); });
  s.on('error', reject);
});

fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'recovery.db', rigs: [{ name: 'frame A', transport: 'modbus-tcp', host: '127.0.0.1', port: ports.modbus }],
}));
const daemon = startDaemon(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', '0'], { cwd: outDir });
const base = `http://127.0.0.1:${await daemon.port}`;
const rig = async () => (await (await fetch(base + '/api/rigs/frame%20A')).json());

const browser = await chromium.launch({ executablePath: chromiumPath(), headless: true, args: ['--headless', '--no-sandbox', '--disable-gpu'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base + '/');
  const card = page.locator('.rig[data-rig="frame A"]');
  await card.waitFor({ timeout: 20000 });
  const button = card.getByRole('button', { name: /Bring back into stroke/ });
  check(!(await button.isVisible()), 'no recovery button while the frame is within its stroke');

  check((await control('fault overtravel 13')).startsWith('ok'), 'the simulator takes "fault overtravel 13"');
  await page.waitForFunction(() => document.querySelector('.rig[data-rig="frame A"]').classList.contains('latched'), null, { timeout: 20000 });
  const latch = await card.locator('.latch').innerText();
  check(/LATCHED: limit tripped/.test(latch), `the latch says why: "${latch.split('\n')[0]}"`);
  check(await button.isVisible(), 'the recovery button is shown beside Reset');
  for (const width of [1280, 800]) {
    await page.setViewportSize({ width, height: 800 });
    await card.screenshot({ path: path.join(outDir, `rig-beyond-stroke-${width}.png`) });
  }
  const before = (await rig()).sample.displacement_mm;
  const dialogs = [];
  page.once('dialog', d => { dialogs.push(d.message()); d.accept(); });
  await button.click();
  check(dialogs.length === 1 && /safe rate/.test(dialogs[0]), `it asks first: "${dialogs[0] || ''}"`);
  await page.waitForFunction(() => document.querySelector('.rig[data-rig="frame A"] .rstate').textContent === 'idle', null, { timeout: 30000 })
    .catch(() => {});
  const after = await rig();
  check(after.state === 'idle' && !after.latched, `the rig is idle and not latched (${after.state}: ${after.recovery_result})`);
  check(Math.abs(after.sample.displacement_mm - 9.5) < 0.05, `the frame is 0.5 mm inside its ±10 mm stroke: ${before.toFixed(3)} -> ${after.sample.displacement_mm.toFixed(3)} mm`);
  check(!(await button.isVisible()) && !(await card.locator('.latch').isVisible()), 'the latch and the button are gone');
  await card.screenshot({ path: path.join(outDir, 'rig-recovered-800.png') });
} catch (e) {
  console.log('FAIL ' + e.message);
  failures++;
} finally {
  await browser.close();
  await stopDaemon(daemon.proc);
  sim.kill('SIGTERM');
}
process.exit(checks.failures + failures > 0 ? 1 : 0);
