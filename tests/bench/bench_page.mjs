// The page's time to its first full render of a completed campaign of 10^6 samples, in Debian's
// headless Chromium (driven by playwright-core, like tests/browser/page_test.mjs), next to the
// same figure for a campaign of 1,000 samples in the same run (the baseline). Target: < 1.5 s.
// It asserts agreement (the loop drawn is the server's path with every reversal of the stored
// input, the time plot holds the run's history), never speed.
//
// The data: `bench_loop --fill DB N` (tests/bench/bench_loop.cpp, the one place that seeds a
// stored run) called twice on one fresh database: campaign 1 has ~1,000 samples, campaign 2
// ~10^6, each a FOT input of 12 rises and descents over 0..14 mm (23 reversals). hystlabd serves
// that database (one simulated rig, idle) to the page.
//
// One measurement: the page shows the other campaign, fully rendered; the campaign's entry in
// the list is clicked (what an operator does), and the
// time runs from just before that click (performance.now() in the page) to the first animation
// frame at whose start the page is fully rendered. "Fully rendered" means all of:
//   - the page's model: window.hystlab.selected() is the campaign and state() is "completed";
//   - the campaign's details in the DOM: #title names it, #state says "completed", #quality has a
//     line for its run, #downloads links the run's samples, the Preisach grid is set (78 cells);
//   - the loop: window.hystlab.loopInfo() is the server's decimated path of that run (its
//     sample count, its reversals), and the loop plot's uPlot holds those points and has drawn
//     them (its draw hook ran after the data was set);
//   - the time plot: its uPlot holds the run's history as the server bucketed it (two points
//     per bucket of /api/runs/ID/samples?points=3000) and has drawn it.
// The uPlot instances are observed by wrapping the global uPlot constructor before the page's
// scripts run (an init script): the page itself is not changed. That frame is the one the
// browser paints next. Each campaign is measured 5 times, alternating between the two; figures:
// medians. The first renders, when the daemon reads each run from SQLite into memory for its
// first loop request, are printed apart: the page's load (it shows the newest campaign, the big
// one, by itself; timed from the navigation's start) and the small one's first selection.
//
// Then the campaign report (GET /api/campaigns/ID/report.html, 3 times each, medians; and the PDF
// through `hystlab report ID -o report.pdf`, Chromium printing it, once each) of both campaigns:
// the 10^6-sample one against the 1,000-sample one. It asserts the report has its sections.
// usage: node bench_page.mjs HYSTLABD BENCH_LOOP OUT_DIR
import { execFileSync } from 'node:child_process';
import { startDaemon, stopDaemon } from '../browser/hystlabd.mjs';
import { Checks, chromium, chromiumPath as findChromium, freshDir } from '../browser/harness.mjs';
import fs from 'node:fs';
import path from 'node:path';


const [daemonPath, benchLoop, outDir] = process.argv.slice(2);
if (!daemonPath || !benchLoop || !outDir) { console.error('usage: node bench_page.mjs HYSTLABD BENCH_LOOP OUT_DIR'); process.exit(2); }
const chromiumPath = findChromium();
const BIG = Number(process.env.BENCH_PAGE_SAMPLES || 1000000), SMALL = 1000, REPEATS = 5;
const ROWS = 12, REVERSALS = 2 * ROWS - 1, CELLS = ROWS * (ROWS + 1) / 2;  // bench_loop's fill
const TIMEOUT_MS = 300000;  // one render, on a starved VM

freshDir(outDir);
const checks = new Checks(), check = checks.check;
const median = v => { const s = v.slice().sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };
const ms = v => `${Math.round(v).toLocaleString('en-US')} ms`;

// The data: two campaigns in one fresh database.
const db = path.join(outDir, 'bench.db');
for (const n of [SMALL, BIG]) {
  const t0 = Date.now();
  const out = execFileSync(benchLoop, ['--fill', db, String(n)], { encoding: 'utf8', timeout: 600000 });
  console.log(`${out.trim()} (in ${((Date.now() - t0) / 1000).toFixed(1)} s)`);
}

// The daemon, on that database, with one simulated rig (as in page_test.mjs).
fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({ rigs: [{ name: 'sim frame', simulate: { time_scale: 10, noise_N: 0.05 } }] }));
let log = '';  // what the daemon printed, shown when a check fails
const { proc: daemon, port: daemonPort } = startDaemon(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--db', db, '--port', '0'],
                                                       { cwd: outDir, onOutput: d => { log += d; } });
const port = await daemonPort;
const base = `http://127.0.0.1:${port}`;
const getJSON = async p => {
  const r = await fetch(base + p, { signal: AbortSignal.timeout(TIMEOUT_MS) });
  if (!r.ok) throw new Error(`GET ${p}: ${r.status} ${await r.text()}`);
  return r.json();
};

// What each campaign must look like once rendered, from the daemon. The time plot's buckets are
// asked the way the page asks them (the answer is the same every time).
const campaigns = [];
for (const c of (await getJSON('/api/campaigns')).sort((a, b) => a.id - b.id)) {
  const d = await getJSON(`/api/campaigns/${c.id}`);
  const own = d.runs.filter(r => r.role !== 'validation');  // the campaign's run, not its validation run
  const run = own[own.length - 1];
  const samples = (await getJSON(`/api/runs/${run.id}`)).samples;
  const buckets = (await getJSON(`/api/runs/${run.id}/samples?points=3000`)).buckets;
  campaigns.push({ id: c.id, run: run.id, samples, buckets, title: `Campaign #${c.id}: ${d.kind} on ${d.rig}` });
}
check(campaigns.length === 2, `the database holds the two campaigns (${campaigns.map(c => `#${c.id}: ${c.samples} samples`).join(', ')})`);
const [small, big] = campaigns;

const browser = await chromium.launch({
  executablePath: chromiumPath, headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
         '--no-first-run', '--disable-sync', '--disable-quic'],
});

// Before the page's scripts: uPlot's constructor wrapped, so each plot's instance is found from
// its element (el.__uplot) and each draw is recorded (u.__drawnData: the data it drew).
function observeUplot() {
  let wrapped;
  Object.defineProperty(window, 'uPlot', {
    configurable: true,
    get: () => wrapped,
    set(U) {
      function W(opts, data, target) {
        const hooks = { ...(opts.hooks || {}) };
        hooks.draw = [...(hooks.draw || []), u => { u.__drawnData = u.data; }];
        const u = new U({ ...opts, hooks }, data, target);
        if (target) target.__uplot = u;
        return u;
      }
      Object.setPrototypeOf(W, U);
      W.prototype = U.prototype;
      wrapped = W;
    },
  });
}

// In the page (installed by the init script): whether campaign c is fully rendered (the
// definition at the top of this file); and, from the page's start, the time of the first
// animation frame at which the campaign shown on load (the newest: c) is.
function pageHooks(c) {
  window.__benchRendered = c => {
    const h = window.hystlab, $ = id => document.getElementById(id);
    if (!h || h.selected() !== c.id || h.state() !== 'completed') return false;
    if ($('title').textContent !== c.title || $('state').textContent !== 'completed') return false;
    if (![...$('quality').children].some(li => li.textContent.startsWith(`run #${c.run}:`))) return false;
    if (!$('downloads').querySelector(`a[href="/api/runs/${c.run}/samples.csv"]`)) return false;
    if (h.heatmapRequired() !== c.cells) return false;
    const info = h.loopInfo();
    if (!info || info.samples !== c.samples || info.reversals !== c.reversals || info.points < 2 || h.loopPoints() !== info.points) return false;
    const lu = $('loop-plot').__uplot, tu = $('time-plot').__uplot;
    if (!lu || lu.__drawnData !== lu.data || !lu.data[1] || lu.data[1][0].length !== info.points) return false;
    if (!tu || tu.__drawnData !== tu.data || tu.data[0].length !== 2 * c.buckets) return false;
    return true;
  };
  window.__benchLoaded = null;
  const frame = () => {
    if (document.readyState !== 'loading' && window.__benchRendered(c)) window.__benchLoaded = performance.now();
    else if (performance.now() < c.timeout) requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
}

// In the page: click campaign c's entry, then resolve with the time to the first animation frame
// at which it is fully rendered, and the part of it spent waiting for the campaign's API answers
// (the union of their Resource Timing intervals: the page asks them one after another).
function selectAndTime(c) {
  const waited = (t0, t1) => {
    const mine = performance.getEntriesByType('resource').filter(e => e.startTime >= t0 && e.responseEnd <= t1 &&
      (e.name.includes(`/api/campaigns/${c.id}`) || e.name.includes(`/api/runs/${c.run}/`))).map(e => [e.startTime, e.responseEnd]).sort((a, b) => a[0] - b[0]);
    let sum = 0, end = -Infinity;
    for (const [a, b] of mine) { if (b > end) { sum += b - Math.max(a, end); end = b; } }
    const each = performance.getEntriesByType('resource').filter(e => e.startTime >= t0 && e.responseEnd <= t1)
      .map(e => [new URL(e.name).pathname + new URL(e.name).search, e.responseEnd - e.startTime]);
    return { requests: mine.length, api: sum, each };
  };
  return new Promise((resolve, reject) => {
    const li = document.querySelector(`#campaigns li[data-id="${c.id}"]`);
    if (!li) { reject(new Error(`campaign #${c.id} is not in the list`)); return; }
    performance.clearResourceTimings();  // the buffer is small, and the rig panel polls
    const t0 = performance.now();
    li.click();
    const frame = () => {
      if (window.__benchRendered(c)) { const t1 = performance.now(); resolve({ ms: t1 - t0, ...waited(t0, t1) }); return; }
      if (performance.now() - t0 > c.timeout) { reject(new Error(`campaign #${c.id} not fully rendered after ${c.timeout} ms`)); return; }
      requestAnimationFrame(frame);
    };
    requestAnimationFrame(frame);
  });
}

// Reversals of a path's x (direction changes, flat steps ignored).
function reversals(x) {
  let n = 0, dir = 0;
  for (let i = 1; i < x.length; i++) {
    const d = Math.sign(x[i] - x[i - 1]);
    if (d && dir && d !== dir) n++;
    if (d) dir = d;
  }
  return n;
}

// The report of each campaign, as HTML (the API) and as PDF (the CLI, through Chromium).
const reportTimes = new Map();
async function timeReports() {
  const cli = path.join(path.dirname(daemonPath), 'hystlab');
  for (const c of [small, big]) {
    const html = [];
    for (let k = 0; k < 3; k++) {
      const t0 = performance.now();
      const r = await fetch(`${base}/api/campaigns/${c.id}/report.html`, { signal: AbortSignal.timeout(TIMEOUT_MS) });
      const text = await r.text();
      html.push(performance.now() - t0);
      if (k === 0) check(r.status === 200 && /Data quality, per run/.test(text) && /Loop figures, per closed cycle|Identification/.test(text) && /<svg/.test(text),
                         `campaign #${c.id}'s report has its sections and vector figures (${text.length.toLocaleString('en-US')} bytes)`);
    }
    const pdf = path.join(outDir, `report-${c.id}.pdf`);
    const t0 = performance.now();
    execFileSync(cli, ['report', String(c.id), '-o', pdf, '--daemon', base], { timeout: TIMEOUT_MS, stdio: ['ignore', 'pipe', 'pipe'] });
    const pdfMs = performance.now() - t0;
    check(fs.statSync(pdf).size > 10000 && fs.readFileSync(pdf).subarray(0, 5).toString() === '%PDF-', `campaign #${c.id}'s report printed to PDF (${fs.statSync(pdf).size.toLocaleString('en-US')} bytes)`);
    reportTimes.set(c.id, { html: median(html), pdf: pdfMs });
  }
}

const times = new Map(campaigns.map(c => [c.id, []]));
const cold = new Map();
try {
  const arg = c => ({ ...c, reversals: REVERSALS, cells: CELLS, timeout: TIMEOUT_MS });
  const context = await browser.newContext({ viewport: { width: 1400, height: 1100 } });
  await context.addInitScript(observeUplot);
  await context.addInitScript(pageHooks, arg(big));
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', e => errors.push(String(e)));
  page.on('console', m => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(base + '/');
  // On load the page shows the newest campaign (the big one): its first render, from the start
  // of the navigation, with the daemon reading the run from SQLite for the loop.
  await page.waitForFunction(() => window.__benchLoaded != null && document.querySelectorAll('#campaigns li').length === 2,
                             null, { timeout: TIMEOUT_MS, polling: 100 });
  cold.set(big.id, await page.evaluate(() => window.__benchLoaded));
  check(await page.evaluate(() => !!(document.getElementById('loop-plot').__uplot && document.getElementById('time-plot').__uplot)),
        'the page\'s plots are uPlot instances the benchmark can observe');
  // The small one's first selection (its run read into memory too), then REPEATS alternating rounds.
  await page.waitForTimeout(300);
  cold.set(small.id, (await page.evaluate(selectAndTime, arg(small))).ms);
  await page.waitForTimeout(300);
  for (let k = 0; k < REPEATS; k++) {
    for (const c of [small, big]) {
      times.get(c.id).push(await page.evaluate(selectAndTime, arg(c)));
      await page.waitForTimeout(300);  // the page idle again before the next click
      if (k === 0) {
        // Agreement, on what was drawn: the server's path with every reversal of the stored input.
        const lp = await page.evaluate(() => window.hystlab.loopPath());
        const info = await page.evaluate(() => window.hystlab.loopInfo());
        check(reversals(lp.x) === REVERSALS && info.reversals === REVERSALS && info.samples === c.samples,
              `campaign #${c.id}: the loop drawn has ${reversals(lp.x)} reversals in ${lp.x.length} points (the stored input: ${REVERSALS}; the server: ` +
              `${info.reversals} of ${info.samples} samples)`);
        const tp = await page.evaluate(() => { const u = document.getElementById('time-plot').__uplot; return { n: u.data[0].length, t0: u.data[0][0], t1: u.data[0][u.data[0].length - 1] }; });
        const span = (c.samples - 1) * 1e-3;
        check(tp.n === 2 * c.buckets && tp.t0 <= 1e-6 && Math.abs(tp.t1 - span) <= 1e-3 * Math.max(1, span),
              `campaign #${c.id}: the time plot holds ${c.buckets} buckets over ${tp.t0}…${tp.t1} s (the run: 0…${span.toFixed(3)} s)`);
        await page.screenshot({ path: path.join(outDir, `campaign-${c.id}.png`), fullPage: true });
      }
    }
  }
  check(errors.length === 0, 'no script errors on the page' + (errors.length ? ': ' + errors.join(' | ') : ''));
  await timeReports();
} catch (e) {
  console.log('FAIL ' + (e.stack || e));
  checks.failures++;
} finally {
  await browser.close();
  await stopDaemon(daemon);
}

const tb = times.get(big.id), ts = times.get(small.id);
if (tb.length === REPEATS && ts.length === REPEATS) {
  const mb = median(tb.map(r => r.ms)), msm = median(ts.map(r => r.ms));
  const label = BIG === 1e6 ? '10^6' : BIG.toLocaleString('en-US'), count = c => c.samples.toLocaleString('en-US');
  const each = (c, rs) => `campaign #${c.id} (${count(c)} samples): ${rs.map(r => ms(r.ms)).join(', ')} (waiting for its ${rs[0].requests} API answers: median ${ms(median(rs.map(r => r.api)))})`;
  console.log(`each selection: ${each(big, tb)}; ${each(small, ts)}`);
  // The campaign's answers, slowest first (medians over the selections; the rig panel's are not its).
  const byPath = new Map();
  for (const r of tb) for (const [p, t] of r.each) if (p.startsWith(`/api/campaigns/${big.id}`) || p.startsWith(`/api/runs/${big.run}/`)) byPath.set(p, [...(byPath.get(p) || []), t]);
  console.log(`campaign #${big.id}'s answers in the page (median): ` +
              [...byPath].map(([p, v]) => [p, median(v)]).sort((a, b) => b[1] - a[1]).map(([p, t]) => `${p} ${ms(t)}`).join(', '));
  console.log(`first renders: the page loaded showing campaign #${big.id} in ${ms(cold.get(big.id))} from navigation (the daemon reads its run from SQLite); ` +
              `campaign #${small.id} first selected in ${ms(cold.get(small.id))}`);
  console.log(`page first render, ${label}-sample campaign: median ${ms(mb)} (baseline 1,000-sample campaign: ${ms(msm)}, ratio ${(mb / msm).toFixed(2)}) ` +
              `(target < 1.5 s: ${mb < 1500 ? 'met' : 'NOT met'})`);
}
if (reportTimes.size === 2) {
  const b = reportTimes.get(big.id), s = reportTimes.get(small.id);
  console.log(`report of the ${big.samples.toLocaleString('en-US')}-sample campaign: HTML median ${ms(b.html)} (1,000-sample campaign: ${ms(s.html)}, ratio ${(b.html / s.html).toFixed(2)}); ` +
              `PDF ${ms(b.pdf)} (1,000-sample campaign: ${ms(s.pdf)}, ratio ${(b.pdf / s.pdf).toFixed(2)})`);
}
if (checks.failures) console.log('the daemon printed (last 3000 characters):\n' + log.slice(-3000));
console.log(checks.failures ? `${checks.failures} check(s) failed (screenshots in ${outDir})` : `all checks passed (screenshots in ${outDir})`);
process.exit(checks.failures ? 1 : 0);
