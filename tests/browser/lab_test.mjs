// The lab view in real headless Chromium (docs/LAB.md, "One view of the lab"): a lab of its own
// (hystlab-lab-world: PostgreSQL, Mosquitto, two daemons with simulated load frames running a
// campaign each, the lab view over them). Checks both daemons online and their rigs' live state
// (from the broker), both campaigns (from the database) with a campaign's plot on a click, the
// tables' list, the links to each daemon's own page, nothing but GET served; then one daemon
// killed (SIGKILL) and the view showing it offline (the broker's will). Screenshots at 1280 and
// 800 px in OUT_DIR.
// usage: node lab_test.mjs LAB_WORLD OUT_DIR
import { Checks, chromium, chromiumPath as findChromium, freshDir } from './harness.mjs';
import { spawn } from 'node:child_process';
import path from 'node:path';

const [worldPath, outDir] = process.argv.slice(2);
if (!worldPath || !outDir) { console.error('usage: node lab_test.mjs LAB_WORLD OUT_DIR'); process.exit(2); }
const chromiumPath = findChromium();
freshDir(outDir);
const checks = new Checks(), check = checks.check;

// The world prints "lab view: URL" once both campaigns' samples are in the lab database.
const world = spawn(worldPath, [], { stdio: ['pipe', 'pipe', 'inherit'] });
let out = '';
const said = (re, ms) => new Promise((resolve, reject) => {
  const timer = setTimeout(() => reject(new Error(`the lab world did not say ${re} in ${ms} ms; it said: ${out}`)), ms);
  const look = () => { const m = out.match(re); if (m) { clearTimeout(timer); resolve(m); } };
  world.stdout.on('data', d => { out += d; look(); });
  look();
});
world.on('exit', code => { if (code) console.log(`the lab world exited with ${code}`); });
const base = (await said(/lab view: (http:\S+)\//, 240000))[1];
console.log(`lab view at ${base}`);

// A campaign on its rig's own page, read-only, from the lab database (/daemons/NAME/): the loop
// with the identified table's force, the Preisach triangle, the held-out score, downloads from
// the lab; no form, no commands. Screenshots at 1280 and 800 px.
async function archivePage(browser, base, href) {
  check(/^\/daemons\/frame-pc-2\/#campaign\/1$/.test(href || ''), `the view links the campaign to its rig's page: ${href}`);
  const p = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  const errs = [];
  p.on('pageerror', e => errs.push(String(e)));
  await p.goto(base + href);
  const shown = await wait(p, () => window.hystlab && window.hystlab.state() === 'completed' && window.hystlab.loopPoints() > 100 &&
    window.hystlab.modelPoints() > 100 && window.hystlab.heatmapIdentified() > 0, null, 'the archived campaign\'s plots');
  check(shown, `its loop, the table's force and the triangle: ${await p.evaluate(() => JSON.stringify({ s: window.hystlab.state(),
    loop: window.hystlab.loopPoints(), model: window.hystlab.modelPoints(), nodes: window.hystlab.heatmapIdentified() }))}`);
  check(await p.evaluate(() => window.hystlab.archive() && window.hystlab.heatmapIdentified() === window.hystlab.heatmapRequired()),
    'every node of the triangle, as the daemon identified it');
  check(/Campaign #1: fot on sim frame · SMA spring 8/.test(await p.textContent('#title')), `its title: ${await p.textContent('#title')}`);
  check(!(await p.isVisible('#plan-form')) && !(await p.isVisible('#pause')) && !(await p.isVisible('#abort')) && !(await p.isVisible('.edit-record')),
    'no form, no commands, no editing of the record (read-only)');
  check(/frame-pc-2 \(read-only, from the lab database\)/.test(await p.textContent('#daemon')), `it says where it reads: ${await p.textContent('#daemon')}`);
  check((await p.$$eval('#accuracy .heldout', es => es.map(e => e.textContent))).length > 0, 'the held-out score beside the table');
  const exports = await p.$$eval('#downloads a', as => as.map(a => a.getAttribute('href')));
  check(exports.length > 0 && exports.every(h => h.startsWith('/daemons/frame-pc-2/api/tables/')), `downloads from the lab database: ${exports}`);
  const table = await fetch(base + exports.find(h => h.endsWith('format=json')));
  check(table.status === 200 && (await table.json()).format !== undefined, `a table's document downloads (${table.status})`);
  await p.screenshot({ path: path.join(outDir, 'lab-archive-1280.png'), fullPage: true });
  await p.setViewportSize({ width: 800, height: 900 });
  await p.waitForTimeout(300);
  check(await p.evaluate(() => document.documentElement.scrollWidth <= 800), 'the archived page fits 800 px');
  await p.screenshot({ path: path.join(outDir, 'lab-archive-800.png'), fullPage: true });
  check(errs.length === 0, `no script error on the archived page: ${errs.join('; ')}`);
  await p.close();
}

const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--no-first-run', '--disable-sync'] });
const wait = (page, fn, arg, what, timeout = 30000) =>
  page.waitForFunction(fn, arg, { timeout, polling: 200 }).then(() => true, () => { console.log(`timed out waiting for ${what}`); return false; });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  const errors = [];
  page.on('pageerror', e => errors.push(String(e)));
  await page.goto(base + '/');
  check(await wait(page, () => document.querySelectorAll('#lab-rigs .lab-rig').length === 2 &&
        [...document.querySelectorAll('#lab-rigs .lab-rig .state')].every(s => /^(idle|arming|armed|paused|safing)$/.test(s.textContent)), null, 'two rigs with live state'),
        `both rigs with their live state: ${await page.textContent('#lab-rigs')}`);
  check(await wait(page, () => /campaign 1 · /.test(document.getElementById('lab-rigs').textContent), null, 'a running campaign on a rig card'),
        `a rig's running campaign with its phase (the broker's state): ${await page.textContent('#lab-rigs')}`);
  check(await wait(page, () => [...document.querySelectorAll('#lab-daemons tbody tr')].filter(r => /online/.test(r.textContent)).length === 2, null, 'two daemons online'),
        'both daemons online (their retained status)');
  check(await page.textContent('#mqtt-link') === 'broker connected' && await page.textContent('#pg-link') === 'database connected', 'the broker and the database connected');
  const links = await page.$$eval('#lab-rigs a.lab-open', as => as.map(a => a.href));
  check(links.length === 2 && links.every(h => /^http:\/\/127\.0\.0\.1:\d+\/$/.test(h)), `each rig links to its daemon's own page: ${links}`);
  check(await wait(page, () => document.querySelectorAll('#lab-campaigns tbody tr').length === 2, null, 'two campaigns'), 'both campaigns, from the lab database');
  const specimens = await page.$$eval('#lab-campaigns tbody tr td:nth-child(6)', tds => tds.map(t => t.textContent).sort());
  check(JSON.stringify(specimens) === '["SMA spring 7","SMA spring 8"]', `each campaign's specimen: ${specimens}`);
  await page.fill('#lab-specimen', 'SMA spring 8');
  await page.click('#lab-filter button');
  check(await wait(page, () => document.querySelectorAll('#lab-campaigns tbody tr').length === 1, null, 'the filter'), 'the specimen filter leaves one campaign');
  await page.click('#lab-campaigns tbody tr');
  check(await wait(page, () => !document.getElementById('lab-campaign').hidden && document.querySelector('#lab-plot canvas') !== null, null, 'the campaign plot'),
        `a campaign's plot on a click: ${await page.textContent('#lab-campaign-title')}`);
  check(/frame-pc-2 · campaign 1 \(fot\)/.test(await page.textContent('#lab-campaign-title')), 'the campaign picked is the filtered one');
  check(Number((await page.textContent('#lab-runs tbody tr td:nth-child(4)')) || 0) > 2000, 'its run with its samples in the lab database');
  // The campaigns end (about 25 s of a simulated FOT at 20 times real time): their tables, each
  // with its held-out RMS (a validation run), listed from the lab database.
  check(await wait(page, () => document.querySelectorAll('#lab-tables tbody tr').length >= 2, null, 'the tables', 90000), 'both campaigns\' tables');
  const heldOut = await page.$$eval('#lab-tables tbody tr td:nth-child(6)', tds => tds.map(t => t.textContent));
  check(heldOut.length >= 2 && heldOut.every(t => /^\d+\.\d{3} N$/.test(t)), `each table's held-out RMS: ${heldOut}`);
  await page.click('#lab-campaigns tbody tr');
  check(await wait(page, () => /completed/.test(document.getElementById('lab-campaign-title').textContent), null, 'the campaign completed'), 'the campaign shown completed');
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: path.join(outDir, 'lab-1280.png'), fullPage: true });
  await page.setViewportSize({ width: 800, height: 900 });
  await page.waitForTimeout(300);
  await page.evaluate(() => window.scrollTo(0, 0));
  check(await page.evaluate(() => document.documentElement.scrollWidth <= 800), `nothing wider than 800 px (${await page.evaluate(() => document.documentElement.scrollWidth)})`);
  check(await page.evaluate(() => document.querySelector('#lab-plot canvas').getBoundingClientRect().right <= 800), 'the plot follows the width');
  await page.screenshot({ path: path.join(outDir, 'lab-800.png'), fullPage: true });
  await archivePage(browser, base, await page.getAttribute('#lab-campaign-open', 'href'));
  const post = await fetch(base + '/api/campaigns', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{"plan": {}}' });
  check(post.status === 405, `read-only: a POST is refused (${post.status})`);
  // A rig's own page (the card's link): its daemon's replication and broker in its header.
  const own = await browser.newPage({ viewport: { width: 800, height: 700 } });
  await own.goto(links[0]);
  check(await wait(own, () => /^lab db lag \d+\.\d s.* · broker up$/.test(document.getElementById('lab-status').textContent), null, 'the lab status on the rig page'),
        `the rig's own page says its lab link: "${await own.textContent('#lab-status')}"`);
  await own.screenshot({ path: path.join(outDir, 'rig-page-lab-800.png') });
  await own.close();
  // A daemon dies: the broker publishes its will, and the view says so.
  world.stdin.write('kill frame-pc-2\n');
  await said(/done: kill frame-pc-2/, 30000);
  check(await wait(page, () => /daemon offline/.test(document.querySelector('[data-rig="frame-pc-2/sim frame"]')?.textContent || ''), null, 'frame-pc-2 offline', 30000),
        'a killed daemon\'s rig shows "daemon offline" (its will)');
  await page.screenshot({ path: path.join(outDir, 'lab-offline-800.png'), fullPage: true });
  check(errors.length === 0, `no script error on the page: ${errors.join('; ')}`);
} finally {
  await browser.close();
  world.stdin.end('quit\n');
  await new Promise(r => world.on('exit', r));
}
console.log(`${checks.failures === 0 ? 'PASS' : 'FAIL'}: lab view, ${checks.failures} failure(s)`);
process.exit(checks.failures === 0 ? 0 : 1);
