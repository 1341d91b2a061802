// The page as a newcomer works with it, in Debian's headless Chromium against a real hystlabd
// (its simulated load frame at time scale 10, as the embedded defaults): a FOT campaign with
// training submitted from the form with a specimen, followed live (the loop's caption moves with
// the samples), then read: the loop, the heatmap and the time plot on one 1280x800 screen, the
// heatmap's colour scale fitted to its cells, whole training cycles on the shakedown plot, the
// lsq table's prior as a field, the report's link, the address of the campaign and of its
// validation run (a reload opens them), the specimen and notes changed under the plots (and
// refused in the server's words), a limit beyond the rig's said in the preview, an error in a
// pasted plan marked on the text box; then an adaptive campaign's design panel. Screenshots at
// 800x700, 1280x800 and 2560x1440 in OUT_DIR.
// usage: node work_test.mjs HYSTLABD OUT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { Checks, chromium, chromiumPath, freshDir } from './harness.mjs';
import { startDaemon, stopDaemon } from './hystlabd.mjs';

const [daemonPath, outDir] = process.argv.slice(2);
if (!daemonPath || !outDir) { console.error('usage: node work_test.mjs HYSTLABD OUT_DIR'); process.exit(2); }
freshDir(outDir);
const checks = new Checks(), { check } = checks;

fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'work.db', rigs: [{ name: 'sim frame', simulate: { time_scale: 10, noise_N: 0.05 } }],
}));
let log = '';
const daemon = startDaemon(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', '0'], { cwd: outDir, onOutput: d => { log += d; } });
const base = `http://127.0.0.1:${await daemon.port}`;
const getJSON = async p => (await fetch(base + p, { signal: AbortSignal.timeout(10000) })).json();
const postJSON = (p, body) => fetch(base + p, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body), signal: AbortSignal.timeout(10000) });

const browser = await chromium.launch({ executablePath: chromiumPath(), headless: true, args: ['--headless', '--no-sandbox', '--disable-gpu'] });
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
const pageErrors = [];
page.on('pageerror', e => pageErrors.push(e.message));
const wait = (fn, arg, timeout = 60000) => page.waitForFunction(fn, arg, { timeout, polling: 100 }).then(() => true, () => false);
// The page as it opens (scrolled to its top) at w x h.
const shoot = async (name, w, h) => {
  await page.setViewportSize({ width: w, height: h });
  await page.evaluate(() => { document.activeElement && document.activeElement.blur(); window.scrollTo(0, 0); });
  await page.waitForTimeout(400);
  await page.screenshot({ path: path.join(outDir, `${name}-${w}x${h}.png`) });
};

try {
  await page.goto(base + '/');
  await wait(() => window.hystlab.online() && window.hystlab.rigs().length > 0);

  // A limit looser than the rig's (2000 N) is not refused: the preview says which one holds.
  await page.fill('#f-force', '5000');
  check(await wait(() => /the rig's 2000 N applies \(the plan asked 5000 N\)/.test(document.getElementById('preview').textContent), null, 15000),
        `a force limit above the rig's is said in the preview ("${(await page.textContent('#preview')).slice(-70)}")`);

  // An error in a pasted plan belongs to the text box, not to the form's (valid) fields.
  await page.click('#json-box summary');
  await page.fill('#f-json', JSON.stringify({ kind: 'fot', range_mm: [0, 4], subdivisions: 4, ramp_rate_mm_s: 50 }));
  await page.click('#submit');
  const jsonMarked = await wait(() => document.getElementById('f-json').getAttribute('aria-invalid') === 'true' &&
    /pasted plan/.test(document.getElementById('f-json-msg').textContent), null, 15000);
  const rateMarked = await page.evaluate(() => document.getElementById('f-rate').getAttribute('aria-invalid'));
  check(jsonMarked && rateMarked !== 'true', `a pasted plan's error marks the text box ("${await page.textContent('#f-json-msg')}"), not the ramp rate input`);
  await page.fill('#f-json', '{"kind": "fot", ');
  await page.click('#submit');
  check(await wait(() => /not valid JSON/.test(document.getElementById('f-json-msg').textContent), null, 5000), 'a pasted plan that is not JSON is said beside the text box');
  await page.fill('#f-json', '');

  // The campaign: training (2 cycles), n = 4, a specimen; submitted from the form.
  await page.fill('#f-force', '400');
  await page.fill('#f-n', '4');
  await page.fill('#f-training', '2');
  await page.fill('#f-specimen', 'NiTi spring S-07');
  await page.click('#submit');
  check(await wait(() => window.hystlab.state() === 'running', null, 30000), 'the campaign runs');
  const id = await page.evaluate(() => window.hystlab.selected());
  check(await page.evaluate(() => location.hash) === `#campaign/${id}`, `the address follows the campaign shown (#campaign/${id})`);
  // Live, the loop's caption counts what the stream brought (it stayed at its first count).
  const caption = () => page.textContent('#loop-caption');
  await wait(() => /live: [\d,]+ samples/.test(document.getElementById('loop-caption').textContent), null, 20000);
  const first = await caption();
  await page.waitForTimeout(1500);
  const second = await caption();
  check(/live/.test(first) && first !== second, `the live loop's caption moves ("${first}" then "${second}")`);
  check(await wait(() => window.hystlab.state() === 'completed' && window.hystlab.recommended() != null, null, 120000), 'the campaign completes with a recommended table');
  await page.waitForTimeout(500);

  const d = await getJSON(`/api/campaigns/${id}`);
  check(d.specimen === 'NiTi spring S-07', `the form's specimen is the campaign's (${JSON.stringify(d.specimen)})`);
  // The work view: the loop, the heatmap and the time plot on one screen at 1280x800 (and wider).
  for (const [w, h] of [[1280, 800], [2560, 1440]]) {
    await shoot('completed', w, h);
    const boxes = await page.evaluate(() => ['loop-fig', 'heatmap-plot', 'time-fig'].map(k => {
      const r = document.getElementById(k).getBoundingClientRect();
      return { k, top: Math.round(r.top), bottom: Math.round(r.bottom), height: Math.round(r.height) };
    }).concat([{ k: 'viewport', bottom: window.innerHeight }]));
    const vh = boxes.pop().bottom;
    check(boxes.every(b => b.top >= 0 && b.bottom <= vh && b.height > 150), `at ${w}x${h} the loop, the heatmap and the time plot are in view together: ${JSON.stringify(boxes)}`);
  }
  await shoot('completed', 800, 700);
  await page.setViewportSize({ width: 1280, height: 800 });

  // The heatmap's colour scale fitted to its cells (it ran to 200 N for cells up to 70 N).
  const nodes = await getJSON(`/api/campaigns/${id}/nodes`);
  const maxF = Math.max(...nodes.nodes.map(n => n.F));
  const lim = await page.evaluate(() => window.hystlab.heatmapLimits());
  check(lim && lim[1] >= maxF && lim[1] <= 1.1 * maxF, `the heatmap's scale ends at ${lim && lim[1]} N for cells up to ${maxF.toFixed(1)} N`);
  // Whole training cycles on the shakedown plot's axis.
  const ticks = await page.evaluate(() => window.hystlab.shakedownTicks());
  check(ticks.length > 0 && ticks.every(t => /^\d+$/.test(t)), `the training plot's cycle ticks are whole numbers (${ticks.join(', ')})`);
  // The lsq table's prior as a field of its own.
  const prior = await page.evaluate(() => [...document.querySelectorAll('#accuracy .prior')].map(e => e.textContent));
  check(prior.length === 1 && /^prior: (signed|monotone)/.test(prior[0]), `the lsq table's prior is shown as a field ("${prior[0]}")`);
  // The report, a link away.
  const report = await page.getAttribute('#downloads a.report', 'href');
  const reportAnswer = report ? await fetch(base + report, { signal: AbortSignal.timeout(60000) }) : null;
  check(report === `/api/campaigns/${id}/report.html` && reportAnswer && reportAnswer.status === 200 && /NiTi spring S-07/.test(await reportAnswer.text()),
        `the page links the campaign's report (${report}), which names the specimen`);

  // A link per campaign and per run: a fresh page opens them, and does not follow the newest.
  const validation = d.runs.find(r => r.role === 'validation');
  const runLink = await page.getAttribute(`#quality li[data-run="${validation.id}"] a.show-run`, 'href');
  check(runLink === `#campaign/${id}/run/${validation.id}`, `the validation run's line links to it (${runLink})`);
  await page.click(`#quality li[data-run="${validation.id}"] a.show-run`);
  check(await wait(r => window.hystlab.shownRun() === r && /run #\d+ \(validation\)/.test(document.getElementById('loop-caption').textContent), validation.id, 20000),
        `"show" puts the validation run in the plots ("${(await caption()).slice(0, 60)}")`);
  const other = await (await postJSON('/api/campaigns', { plan: { kind: 'fot', range_mm: [0, 1], subdivisions: 1, validation: false } })).json();
  const page2 = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page2.goto(`${base}/#campaign/${id}/run/${validation.id}`);
  check(await page2.waitForFunction(([c, r]) => window.hystlab.selected() === c && window.hystlab.shownRun() === r, [id, validation.id], { timeout: 20000, polling: 100 }).then(() => true, () => false),
        `a fresh page at #campaign/${id}/run/${validation.id} shows that run`);
  await page2.waitForTimeout(1500);
  check(await page2.evaluate(() => window.hystlab.selected()) === id, `and stays there while campaign ${other.id} runs (not following the newest)`);
  check(await page2.getAttribute('#title', 'href') === `#campaign/${id}/run/${validation.id}`, 'the title is the link to what is shown');
  await page2.goto(`${base}/#campaign/9999`);
  check(await page2.waitForFunction(() => /no campaign #9999/.test(document.getElementById('title').textContent), null, { timeout: 10000 }).then(() => true, () => false),
        'an address of a campaign that does not exist says so');
  await page2.close();

  // Specimen and notes changed under the plots; a refusal shown beside its input.
  await page.click('#record button.edit-record');
  await page.fill('#record input[name=specimen]', 'NiTi spring S-07b');
  await page.fill('#record textarea[name=notes]', 'spring reseated after run 1\nroom 21 °C');
  await page.click('#record button[type=submit]');
  check(await wait(() => /S-07b/.test(document.getElementById('title').textContent) && /reseated/.test(document.getElementById('record').textContent), null, 10000),
        'a changed specimen and notes are shown in the title and under the plots');
  const after = await getJSON(`/api/campaigns/${id}`);
  check(after.specimen === 'NiTi spring S-07b' && after.notes === 'spring reseated after run 1\nroom 21 °C' && !!after.record_changed_at,
        `the API has the change (${JSON.stringify([after.specimen, after.notes])}), with its time`);
  const events = await getJSON(`/api/campaigns/${id}/events`);
  check(events.some(e => e.kind === 'record'), 'the change is kept in the campaign\'s events');
  await page.click('#record button.edit-record');
  await page.evaluate(() => { const t = document.querySelector('#record textarea[name=notes]'); t.removeAttribute('maxlength'); t.value = 'x'.repeat(4001); });
  await page.click('#record button[type=submit]');
  check(await wait(() => document.querySelector('#record textarea[name=notes]').getAttribute('aria-invalid') === 'true' &&
    /at most 4000 characters/.test(document.getElementById('record-msg').textContent), null, 10000), 'notes beyond 4000 characters are refused beside the notes');
  check((await getJSON(`/api/campaigns/${id}`)).notes === after.notes, 'and the notes stored before are kept');
  await page.click('#record button:text("Cancel")');

  await fetch(`${base}/api/campaigns/${other.id}/abort`, { method: 'POST', signal: AbortSignal.timeout(10000) });

  // An adaptive campaign (issue 41): the preview gives its budget; as it runs, the design panel
  // shows the estimated error against rig time and each row chosen with why, the heatmap the rows'
  // own (non-uniform) grid.
  const adaptive = { kind: 'fot', range_mm: [0, 4], subdivisions: 2, ramp_rate_mm_s: 1, specimen: 'NiTi spring S-08',
    design: { kind: 'adaptive', budget_s: 60, finest_subdivisions: 16 } };
  const preview = await (await postJSON('/api/plans/preview', { plan: adaptive })).json();
  check(preview.design && preview.design.budget_s === 60 && preview.design.coarse_subdivisions === 2, `the preview gives the design's budget (${JSON.stringify(preview.design || preview)})`);
  const ad = await (await postJSON("/api/campaigns", { plan: adaptive })).json();
  check(ad.id > 0, `the adaptive plan is taken (${JSON.stringify(ad)})`);
  await page.goto(`${base}/#campaign/${ad.id}`);
  // Live: the panel follows the design as it goes (a row at least, before the end).
  check(await wait(() => window.hystlab.designRows() >= 1 && window.hystlab.state() === 'running', null, 60000), 'the design panel shows the rows while the campaign runs');
  let final = null;
  for (let k = 0; k < 240 && !(final && final.final); k++) { await new Promise(r => setTimeout(r, 500)); final = await getJSON(`/api/campaigns/${ad.id}`); }
  check(final && final.state === 'completed', `the adaptive campaign completes (${final && final.state}: ${final && final.reason})`);
  check(await wait(() => window.hystlab.state() === 'completed', null, 20000), 'the page says so');
  check(await wait(() => window.hystlab.designRows() >= 3 && window.hystlab.designPoints() >= 3, null, 20000),
        `the design panel lists the rows chosen (${await page.evaluate(() => window.hystlab.designRows())}) and the error against rig time (${await page.evaluate(() => window.hystlab.designPoints())} points)`);
  const adNodes = await getJSON(`/api/campaigns/${ad.id}/nodes`);
  check(adNodes.grid.n > 2 && adNodes.identified === adNodes.required && adNodes.nodes.length === adNodes.required,
        `the heatmap's grid is the rows measured (n = ${adNodes.grid.n}: ${adNodes.grid.nodes_mm.join(', ')}), every node of it shown`);
  check(/^Adaptive design: \d+ rows, estimated held-out RMS/.test(await page.textContent('#design-caption')), `the design's caption ("${await page.textContent('#design-caption')}")`);
  await shoot('adaptive', 1280, 800);
  await page.evaluate(() => document.getElementById('design-fig').scrollIntoView());
  await page.screenshot({ path: path.join(outDir, 'adaptive-design-1280x800.png') });
  await page.setViewportSize({ width: 800, height: 700 });
  await page.waitForTimeout(400);
  await page.evaluate(() => document.getElementById('design-fig').scrollIntoView());
  await page.screenshot({ path: path.join(outDir, 'adaptive-design-800x700.png') });
  check(pageErrors.length === 0, `no errors in the page (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `the test ran to its end (${e.stack})`);
} finally {
  await browser.close();
  await stopDaemon(daemon.proc);
}
if (checks.failures) console.log(log.split('\n').slice(-40).join('\n'));
console.log(checks.failures ? `${checks.failures} check(s) FAILED` : 'all checks passed');
process.exit(checks.failures ? 1 : 0);
