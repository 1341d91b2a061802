// The page's shaker view in real headless Chromium against a real hystlabd with a simulated
// shaker (real time): the form's sine defaults and a check of its own; a short up-down sweep at
// two amplitudes submitted from the form; while it runs, the step "k of N" with its frequency,
// amplitude and ETA in the header, base and mass on one displacement axis (a trace, and each
// cycle's envelope where a cycle has fewer than 20 samples), the sweep's view restored by a
// reload; once it ends, the transmissibility on log-log axes with its phase, a curve per amplitude
// and direction, the resonance table, the stored run's envelope against time, the warnings, the
// downloads, and the same again after a reload. Saves screenshots in OUT_DIR.
// usage: node shaker_test.mjs HYSTLABD OUT_DIR
import { startDaemon, stopDaemon } from './hystlabd.mjs';
import { Checks, chromium, chromiumPath as findChromium, freshDir, settledWidth } from './harness.mjs';
import fs from 'node:fs';
import path from 'node:path';

const [daemonPath, outDir] = process.argv.slice(2);
if (!daemonPath || !outDir) { console.error('usage: node shaker_test.mjs HYSTLABD OUT_DIR'); process.exit(2); }
const chromiumPath = findChromium();
freshDir(outDir);
const started = Date.now();
const checks = new Checks(), check = checks.check;

// The sweep: 1 Hz steps around the simulated isolator's resonance (17.7 Hz at 0.005 mm, lower at
// 0.05 mm, where the springs transform: fine enough for the backbone to show it) and one at 60 Hz,
// where a cycle has under 20 samples at 1000 Hz (the time plot draws envelopes there); both
// amplitudes, up then down: 32 steps, about 50 s of rig time.
const FREQS = [10, 15, 16, 17, 18, 19, 30, 60], AMPS = [0.005, 0.05], STEPS = FREQS.length * AMPS.length * 2;

fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'shaker.db', rigs: [{ name: 'sim shaker', simulate: { rig: 'shaker', time_scale: 1 } }],
}));
let daemonLog = '';
const daemon = startDaemon(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', '0'],
                           { cwd: outDir, timeoutMs: 20000, onOutput: d => { daemonLog += d; } });
const base = `http://127.0.0.1:${await daemon.port}`;
const getJSON = async p => (await fetch(base + p, { signal: AbortSignal.timeout(10000) })).json();

const browser = await chromium.launch({
  executablePath: chromiumPath, headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
         '--no-first-run', '--disable-sync', '--disable-quic'],
});
const hooks = page => page.evaluate(() => ({
  state: window.hystlab.state(), status: window.hystlab.sineStatus(), curves: window.hystlab.transmissibilityCurves(),
  scales: window.hystlab.transmissibilityScales(), rows: window.hystlab.resonanceRows(), time: window.hystlab.timeAxes(),
  progress: document.getElementById('progress').textContent, eta: document.getElementById('eta').textContent }));
async function explain(page, what) {
  console.log(`timed out waiting for ${what}`);
  try {
    console.log('  the page: ' + JSON.stringify(await hooks(page)));
    const id = await page.evaluate(() => window.hystlab.selected());
    if (id != null) for (const e of (await getJSON(`/api/campaigns/${id}/events`)).slice(-6)) console.log('  event: ' + JSON.stringify(e));
  } catch (e) { console.log('  (could not ask: ' + e + ')'); }
}
// A figure's screenshot, from the top of the page: scrolled to, the sticky header would cover it.
async function shoot(page, selector, file) {
  await page.evaluate(() => window.scrollTo(0, 0));
  const box = await page.locator(selector).boundingBox();
  if (box) await page.screenshot({ path: path.join(outDir, file), fullPage: true, clip: box });
}
const wait = (page, fn, arg, what, timeout = 60000) =>
  page.waitForFunction(fn, arg, { timeout, polling: 100 }).then(() => true, async () => { await explain(page, what); return false; });

// The form: a sine sweep's defaults, and a frequency beyond 8 samples a cycle named beside its input.
async function checkForm(page) {
  await page.selectOption('select[name=kind]', 'sine');
  check(await page.inputValue('select[name=rig]') === 'sim shaker', 'a sine plan picks the shaker');
  const defaults = {};
  for (const n of ['fromhz', 'tohz', 'steps', 'direction', 'amps', 'settlechange', 'settle', 'measured', 'tol']) defaults[n] = await page.inputValue(`[name=${n}]`);
  check(defaults.fromhz === '5' && defaults.tohz === '60' && defaults.steps === '24' && defaults.direction === 'up-down' && defaults.amps === '0.005, 0.05' &&
        defaults.settlechange === '2' && defaults.measured === '10' && defaults.tol === '5', `the form's sine defaults: ${JSON.stringify(defaults)}`);
  check(await wait(page, () => /96 steps/.test(document.getElementById('preview').textContent) && !document.getElementById('preview').hidden, null, 'the preview', 20000),
        `the preview of the default sweep: "${await page.textContent('#preview')}"`);
  await page.fill('input[name=hz]', '200');
  await page.click('#submit');
  check(await wait(page, () => /at most 25 Hz/.test(document.getElementById('f-tohz-msg').textContent), null, 'the sweep-to message', 10000),
        `a sweep beyond 8 samples a cycle is named beside "sweep to": "${await page.textContent('#f-tohz-msg')}"`);
  await page.fill('input[name=hz]', '1000');
}

// While it runs: the header's step, the stream's rate, one displacement axis, and the envelope at 60 Hz.
async function checkRunning(page) {
  check(await wait(page, () => window.hystlab.state() === 'running' && window.hystlab.sineStatus() && window.hystlab.sineStatus().k >= 1, null, 'the first step', 60000),
        'the sweep runs and the page knows its step');
  check(await wait(page, n => new RegExp(`^step \\d+ of ${n}: [\\d.]+ Hz · [\\d.]+ mm (up|down)`).test(document.getElementById('progress').textContent), STEPS, 'the header step', 20000),
        `the header shows the step, its frequency, amplitude and direction: "${await page.textContent('#progress')}"`);
  check(await wait(page, () => /^ETA ≈ \d+ (s|min)$/.test(document.getElementById('eta').textContent), null, 'the ETA', 20000), `and the ETA: "${await page.textContent('#eta')}"`);
  check(await wait(page, () => /control error [+−]?[\d.]+ %/.test(document.getElementById('progress').textContent), null, 'the control error', 30000),
        `and the control error: "${await page.textContent('#progress')}"`);
  check(await page.evaluate(() => window.hystlab.streamRate()) === 1000, 'the stream brings 1000 samples/s for a sweep up to 60 Hz (20 a cycle, capped at the plan\'s rate)');
  check(await wait(page, () => { const t = window.hystlab.timeAxes(); return t.yAxes === 1 && t.trace > 200; }, null, 'the live trace', 20000),
        `base and mass against time on one displacement axis: ${JSON.stringify(await page.evaluate(() => window.hystlab.timeAxes()))}`);
  const axes = await page.evaluate(() => window.hystlab.timeAxes());
  check(axes.label === 'displacement (mm)' && axes.legend.join() === 'base,mass', `its axis "${axes.label}", legend ${JSON.stringify(axes.legend)}`);
  await page.selectOption('#time-mode', 'accel');
  check(await wait(page, () => { const t = window.hystlab.timeAxes(); return t.label === 'mass acceleration (g)' && t.legend.join() === 'mass' && t.trace > 0; }, null, 'acceleration', 10000),
        'the time plot switches to the mass acceleration in g');
  await page.selectOption('#time-mode', 'disp');
  check(await wait(page, () => window.hystlab.transmissibilityPoints() >= 1, null, 'a live point', 60000), 'transmissibility points arrive while it runs');
  await page.screenshot({ path: path.join(outDir, 'sweep-running.png'), fullPage: true });
  // A reload halfway: the points, the step and the signals are back.
  await wait(page, () => window.hystlab.transmissibilityCurves().reduce((n, c) => n + c.points, 0) >= 5, null, 'five points', 60000);
  const before = await page.evaluate(() => window.hystlab.transmissibilityCurves().reduce((n, c) => n + c.points, 0));
  // The live mass-against-base plot: no "identified model" offered (a shaker has none), and tick
  // labels that say different numbers (a 0.005 mm sine once read "0.01, 0.01, 0.00").
  const loop = await page.evaluate(() => ({ legend: [...document.querySelectorAll('#loop-plot .u-legend .u-series')].filter(e => e.style.display !== 'none').map(e => e.textContent.trim()),
                                             ticks: window.hystlab.loopTicks() }));
  check(!loop.legend.some(t => /identified model/.test(t)) && loop.ticks.every(a => a.length > 1 && new Set(a).size === a.length),
        `the live mass-against-base plot offers no model and its ticks differ (legend ${JSON.stringify(loop.legend)}; ticks ${JSON.stringify(loop.ticks)})`);
  await page.reload();
  check(await wait(page, n => window.hystlab.online() && window.hystlab.transmissibilityCurves().reduce((k, c) => k + c.points, 0) >= n &&
                   window.hystlab.sineStatus() && window.hystlab.sineStatus().k > 0 && window.hystlab.timeAxes().points > 0, before, 'the running sweep restored', 30000),
        `a reload while it runs restores its ${before}+ points, its step and the time plot`);
  check(await wait(page, () => window.hystlab.timeAxes().liveCycles > 0, null, 'the 60 Hz envelope', 120000),
        `at 60 Hz (${1000 / 60 | 0} samples a cycle) the time plot draws each cycle's min–max: ${JSON.stringify(await page.evaluate(() => window.hystlab.timeAxes()))}`);
  await shoot(page, '#shaker-time-fig', 'time-live-envelope.png');
}

// The ended sweep's view (after it ends, and again after a reload).
async function checkEnded(page, when) {
  check(await wait(page, n => window.hystlab.transmissibilityCurves().length === 4 && window.hystlab.transmissibilityCurves().every(c => c.points === n) &&
                   window.hystlab.resonanceRows().length >= 4 && window.hystlab.timeAxes().trace === 0 && window.hystlab.timeAxes().envelope > 1000,
                   FREQS.length, `the ended view (${when})`, 30000),
        `${when}: four curves of ${FREQS.length} points, the resonance table and the run's envelope`);
  const h = await hooks(page);
  const s = h.scales;
  check(s.ratio.x === 3 && s.ratio.y === 3, `${when}: the transmissibility has log x and log y scales (distr ${s.ratio.x}, ${s.ratio.y})`);
  check(s.phase.x === 3 && s.phase.height >= 100 && s.phase.series === s.ratio.series, `${when}: a phase plot under it on the same log frequency axis (${s.phase.width}×${s.phase.height})`);
  const labels = h.curves.map(c => c.label);
  check(labels.join() === '0.005 mm up,0.005 mm down,0.05 mm up,0.05 mm down', `${when}: one curve per amplitude and direction: ${labels.join(', ')}`);
  check(new Set(h.curves.map(c => c.color)).size === 2, `${when}: a colour per amplitude`);
  const predicted = h.curves.every(c => c.predicted === FREQS.length);
  check(predicted && s.legend.includes('0.05 mm down (predicted)'), `${when}: the model's predictions drawn and named: ${s.legend.join(' | ')}`);
  const header = h.rows.length ? Object.keys(h.rows[0]).length : 0;
  check(h.rows.some(r => r[0] === '0.05 mm up' && (Number(r[1]) > 10 || r[1] === 'beyond the sweep')) && header === 7,
        `${when}: the resonance table: ${h.rows.slice(0, 4).map(r => r.join(' / ')).join('; ')}`);
  // The backbone's damping (ζ eq, from the steps' loops): the SMA springs transform at 0.05 mm and
  // their loop opens, so the isolator damps more there than at 0.005 mm (seen 0.085 and 0.021).
  const zeta = a => Number((h.rows.find(r => r[0] === `${a} mm up`) || [])[6]);
  check(zeta('0.005') > 0.005 && zeta('0.05') > 2 * zeta('0.005'), `${when}: ζ eq at the resonance grows with amplitude: ${zeta('0.005')} at 0.005 mm, ${zeta('0.05')} at 0.05 mm`);
  // The backbone: three small plots against the base amplitude (resonance, peak, ζ eq), measured
  // and predicted; the SMA springs soften as they transform, so the resonance falls with the
  // amplitude, in the measurement as in the model.
  const bb = await page.evaluate(() => window.hystlab.backbone());
  const line = (key, label) => { const k = bb ? bb.series.indexOf(label) : -1; return k < 0 ? [] : bb.values[key][k]; };
  check(bb && bb.plots === 3 && bb.amplitudes === 2 && ['measured up', 'measured down', 'predicted up'].every(l => bb.series.includes(l)),
        `${when}: the backbone's three plots over two amplitudes, measured and predicted: ${JSON.stringify(bb && bb.series)}`);
  const fm = line('frequency_hz', 'measured up'), fp = line('frequency_hz', 'predicted up'), zm = line('equivalent_damping', 'measured up');
  const finite = v => v.length === 2 && v.every(Number.isFinite);
  check(finite(fm) && fm[1] < fm[0] && finite(fp) && fp[1] < fp[0],
        `${when}: the backbone falls with amplitude, measured (${fm.map(v => v && v.toFixed(2)).join(' → ')} Hz) as predicted (${fp.map(v => v && v.toFixed(2)).join(' → ')} Hz)`);
  check(finite(zm) && zm[1] > zm[0], `${when}: and its damping grows (ζ eq ${zm.map(v => v && v.toFixed(3)).join(' → ')})`);
  check(h.time.yAxes === 1 && h.time.envelope > 1000, `${when}: the whole stored run against time, as an envelope (${h.time.envelope} values)`);
  check(new RegExp(`^${STEPS} of ${STEPS} steps measured`).test(h.progress) && h.eta === '', `${when}: the header says "${h.progress}"`);
  // Acceleration is a live view (the stored overview keeps displacements): not offered empty.
  check(await page.evaluate(() => document.querySelector('#time-mode option[value=accel]').disabled && document.getElementById('time-mode').value === 'disp'),
        `${when}: the ended sweep does not offer an empty acceleration view`);
}

async function checkWarnings(page, id) {
  const events = await getJSON(`/api/campaigns/${id}/events`);
  const n = events.filter(e => e.kind === 'control_warning').length;
  if (!n) { console.log('skip the control warnings (this sweep had none)'); return; }
  const text = await page.textContent('#warnings');
  check(!(await page.locator('#warnings').isHidden()) && (n === 1 ? /control: at [\d.]+ Hz/ : new RegExp(`${n} control warnings`)).test(text),
        `the sweep's ${n} control warning(s) are in the warning box`);
}

async function checkDownloads(page, id) {
  const hrefs = await page.evaluate(() => [...document.querySelectorAll('#downloads a')].map(a => a.getAttribute('href')));
  check(hrefs.includes(`/api/campaigns/${id}/sweep.csv`) && hrefs.includes(`/api/campaigns/${id}/sweep`) && hrefs.some(h => /^\/api\/runs\/\d+\/samples\.csv$/.test(h)),
        `the downloads: sweep CSV, sweep JSON, the run's samples CSV (${hrefs.join(', ')})`);
  const link = page.locator('#downloads a', { hasText: 'sweep points .csv' });
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 20000 }), link.click()]);
  const file = path.join(outDir, download.suggestedFilename());
  await download.saveAs(file);
  const lines = fs.readFileSync(file, 'utf8').trim().split('\n');
  check(lines[0].split(',').includes('frequency_hz') && lines.length === STEPS + 1, `the sweep CSV downloads (${path.basename(file)}: ${lines.length - 1} rows, "${lines[0].slice(0, 60)}…")`);
  const json = await page.evaluate(async u => (await fetch(u)).json(), `/api/campaigns/${id}/sweep`);
  check(json.measured && json.measured.curves.length === 4, 'the sweep JSON holds the four curves');
}

try {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1280, height: 1000 } });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', e => errors.push(String(e)));
  // A 4xx the page handles (the preview of a plan the server refuses) is logged by the browser
  // as a failed resource: not a script error.
  page.on('console', m => { if (m.type() === 'error' && !/Failed to load resource: the server responded with a status of 4\d\d/.test(m.text())) errors.push(m.text()); });
  await page.goto(base + '/');
  check(await wait(page, () => window.hystlab && window.hystlab.online(), null, 'the event stream'), 'the page loads and goes live');
  await checkForm(page);

  // The sweep from the form, with the control's defaults (the daemon's warning and abort bands:
  // a sweep through the isolator's resonance must not trip them).
  await page.fill('input[name=freqs]', FREQS.join(', '));
  await page.fill('input[name=settle]', '5');
  await page.fill('input[name=measured]', '5');
  // The form proposes refining the resonance (5 points in its half-power band); this sweep keeps
  // its 20 steps to be counted (the refinement: tests/daemon/test_shaker_campaign.cpp).
  check(await page.inputValue('input[name=respts]') === '5', 'the form proposes refining the resonance to 5 half-power points');
  await page.fill('input[name=respts]', '');
  await page.click('#submit');
  await checkRunning(page);
  check(await wait(page, () => window.hystlab.state() === 'completed', null, 'the sweep completing', 180000), 'the sweep completes');
  const id = await page.evaluate(() => window.hystlab.selected());
  await checkEnded(page, 'ended');
  await checkWarnings(page, id);
  await checkDownloads(page, id);
  for (const width of [1280, 800]) {
    await page.setViewportSize({ width, height: 1000 });
    const settled = await settledWidth(page, width);
    if (width === 800) {
      check(settled.scrollWidth <= 800, `no horizontal scrolling at 800 px (scrollWidth ${settled.scrollWidth}${settled.scrollWidth > 800 && settled.over.length ? '; past 800 px: ' + settled.over.join(', ') : ''})`);
    }
    await page.screenshot({ path: path.join(outDir, `sweep-${width}.png`), fullPage: true });
    await shoot(page, '#sweep-fig', `transmissibility-${width}.png`);
    await shoot(page, '#backbone', `backbone-${width}.png`);
    if (width === 800) {
      const w = await page.evaluate(() => window.hystlab.backbone().widths);
      check(w.every(x => x <= 800), `at 800 px the backbone's plots fit (${w.join(', ')} px)`);
    }
  }
  await page.setViewportSize({ width: 1280, height: 1000 });
  await page.reload();
  check(await wait(page, n => window.hystlab.online() && window.hystlab.selected() === n, id, 'the reload'), 'after a reload the page shows the sweep again');
  await checkEnded(page, 'reloaded');
  await shoot(page, '#shaker-time-fig', 'time-stored.png');
  check(errors.length === 0, 'no script errors on the page' + (errors.length ? ': ' + errors.join(' | ') : ''));
} catch (e) {
  console.log('FAIL ' + (e.stack || e));
  checks.failures++;
} finally {
  await browser.close();
  await stopDaemon(daemon.proc);
}
if (checks.failures) console.log('the daemon printed (last 4000 characters):\n' + daemonLog.slice(-4000));
console.log(`${checks.failures ? `${checks.failures} check(s) failed` : 'all checks passed'} in ${Math.round((Date.now() - started) / 1000)} s (screenshots in ${outDir})`);
process.exit(checks.failures ? 1 : 0);
