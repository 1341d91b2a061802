// The page in real headless Chromium (Debian's), driven by playwright-core, against a real
// hystlabd running short simulated FOT campaigns: the page loads and goes live, the loop plot
// and the Preisach heatmap fill, the identified model is drawn, a table downloads, and pause,
// resume and abort work from the buttons. Saves a screenshot.
// usage: node page_test.mjs HYSTLABD OUT_DIR
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.resolve(here, '../../web/package.json'));
const { chromium } = require('playwright-core');

const [daemonPath, outDir] = process.argv.slice(2);
if (!daemonPath || !outDir) { console.error('usage: node page_test.mjs HYSTLABD OUT_DIR'); process.exit(2); }
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
if (!fs.existsSync(chromiumPath)) { console.error(`no Chromium at ${chromiumPath} (apt install chromium)`); process.exit(1); }
fs.rmSync(outDir, { recursive: true, force: true });
fs.mkdirSync(outDir, { recursive: true });

let failures = 0;
function check(cond, what) {
  console.log(`${cond ? 'ok  ' : 'FAIL'} ${what}`);
  if (!cond) failures++;
}

// The daemon: its own database and config (a fast simulated load frame), a free port.
fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'browser.db', rigs: [{ name: 'sim frame', simulate: { time_scale: 10, noise_N: 0.05 } },
                           { name: 'sim shaker', simulate: { time_scale: 1, rig: 'shaker' } }],
}));
function startDaemon(portArg) {
  const proc = spawn(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', String(portArg)], { cwd: outDir, stdio: ['ignore', 'pipe', 'pipe'] });
  let log = '';
  proc.stdout.on('data', d => { daemonLog += d; });
  proc.stderr.on('data', d => { daemonLog += d; });
  const port = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error('hystlabd did not start within 20 s:\n' + log)), 20000);
    const onData = d => {
      log += d;
      const m = /serving the API and the page on http:\/\/127\.0\.0\.1:(\d+)\//.exec(log);
      if (m) { clearTimeout(timer); resolve(Number(m[1])); }
    };
    proc.stdout.on('data', onData);
    proc.stderr.on('data', onData);
    proc.on('exit', code => reject(new Error(`hystlabd exited (${code}):\n${log}`)));
  });
  return { proc, port };
}
async function stopDaemon(d) {
  if (d.proc.exitCode !== null) return;
  const exited = new Promise(r => d.proc.on('exit', r));
  d.proc.kill('SIGTERM');
  await exited;
}
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

try {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1400, height: 1100 } });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', e => errors.push(String(e)));
  const warnings = [];  // the page's own account of a failed update (shown if a check fails)
  page.on('console', m => { if (m.type() === 'error') errors.push(m.text()); else if (m.type() === 'warning') warnings.push(m.text()); });
  pageWarnings = warnings;
  await page.goto(base + '/');
  check(await wait(page, () => window.hystlab && window.hystlab.online(), null, 'the event stream'), 'the page loads and its event stream goes live');
  check(await page.evaluate(() => typeof uPlot === 'function'), 'the plotting library is served by the daemon');

  // 1. A short FOT campaign from the form, run to completion.
  await page.fill('input[name=n]', '4');
  await page.fill('input[name=rate]', '1');
  await page.fill('input[name=dwell]', '0.1');
  await page.click('#submit');
  check(await wait(page, () => window.hystlab.selected() != null && window.hystlab.loopPoints() > 50, null, 'loop points'),
        'the force-displacement loop grows from live samples');
  check(await wait(page, () => window.hystlab.heatmapIdentified() > 0, null, 'heatmap'), 'the Preisach heatmap fills node by node');
  check(await wait(page, () => window.hystlab.state() === 'completed', null, 'completion', 120000), 'the campaign completes');
  check(await wait(page, () => window.hystlab.heatmapIdentified() === window.hystlab.heatmapRequired(), null, 'full triangle'),
        'every node of the triangle is identified (10 of 10)');
  check(await wait(page, () => window.hystlab.modelPoints() > 0, null, 'model overlay'), 'the identified model is drawn over the measured loop');
  check(/RMS/.test(await page.textContent('#accuracy')), 'the accuracy numbers are shown');
  const link = page.locator('#downloads a', { hasText: '(fot) .json' }).first();
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 20000 }), link.click()]);
  const file = path.join(outDir, 'downloaded-table.json');
  await download.saveAs(file);
  const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
  check(doc.format === 'hystlab-everett-table' && Array.isArray(doc.nodes_mm) && doc.nodes_mm.length === 5, `a table downloads (${download.suggestedFilename()})`);
  await page.screenshot({ path: path.join(outDir, 'fot-completed.png'), fullPage: true });

  // 2. A slower campaign: pause, resume and abort from the buttons.
  await page.fill('input[name=n]', '8');
  await page.fill('input[name=rate]', '0.2');
  await page.click('#submit');
  check(await wait(page, () => window.hystlab.state() === 'running', null, 'running'), 'the second campaign runs');
  await page.click('#pause');
  check(await wait(page, () => window.hystlab.state() === 'paused', null, 'paused', 20000), 'Pause holds the campaign');
  await page.click('#resume');
  check(await wait(page, () => window.hystlab.state() === 'running', null, 'resumed', 20000), 'Resume continues it');
  await page.click('#abort');
  check(await wait(page, () => window.hystlab.state() === 'aborted', null, 'aborted', 30000), 'Abort ends it (safe position)');
  await page.screenshot({ path: path.join(outDir, 'page.png'), fullPage: true });

  // 3. A shaker sweep: the rig is picked for the plan, transmissibility builds point by point.
  await page.selectOption('select[name=kind]', 'sine');
  check(await page.inputValue('select[name=rig]') === 'sim shaker', 'a sine plan picks the shaker');
  await page.fill('input[name=freqs]', '4, 8, 12');
  await page.fill('input[name=settle]', '3');
  await page.fill('input[name=measured]', '3');
  await page.fill('input[name=hz]', '500');
  await page.click('#submit');
  check(await wait(page, () => window.hystlab.transmissibilityPoints() >= 1 && window.hystlab.loopPoints() > 20, null, 'transmissibility'),
        'the transmissibility plot and the base/mass signals build while the sweep runs');
  check(await wait(page, () => window.hystlab.state() === 'completed' && window.hystlab.transmissibilityPoints() === 3, null, 'sweep done'),
        'the sweep completes with a point per frequency');
  await page.screenshot({ path: path.join(outDir, 'shaker.png'), fullPage: true });

  check(errors.length === 0, 'no script errors on the page' + (errors.length ? ': ' + errors.join(' | ') : ''));

  // 4. The daemon restarts: the page notices, and reconnects on its own (the browser logs the
  // broken stream as a failed resource; anything else would be a script error).
  errors.length = 0;
  await stopDaemon(daemon);
  check(await wait(page, () => !window.hystlab.online(), null, 'offline', 20000), 'the page shows the daemon gone');
  daemon = startDaemon(port);
  await daemon.port;
  check(await wait(page, () => window.hystlab.online(), null, 'reconnect', 30000), 'and reconnects when it is back');
  const unexpected = errors.filter(e => !/Failed to load resource: net::/.test(e));
  check(unexpected.length === 0, 'no script errors across the restart' + (unexpected.length ? ': ' + unexpected.join(' | ') : ''));
} catch (e) {
  console.log('FAIL ' + (e.stack || e));
  failures++;
} finally {
  await browser.close();
  await stopDaemon(daemon);
}
if (failures && pageWarnings.length) console.log('the page warned:\n' + pageWarnings.slice(-20).join('\n'));
if (failures) console.log('the daemon printed (last 6000 characters):\n' + daemonLog.slice(-6000));
console.log(failures ? `${failures} check(s) failed (screenshots in ${outDir})` : `all checks passed (screenshots in ${outDir})`);
process.exit(failures ? 1 : 0);
