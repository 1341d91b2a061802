// Submission latency: from hystlabd's submit() being called (inside POST /api/campaigns) to the
// rig's thread taking the job, as the daemon measures it (hystlab_submission_latency_seconds in
// /metrics, monotonic clock), over 20 submissions to an idle simulated load frame (each waits for
// the one before to end: a queued job waits for its rig, which is not submission latency). Beside
// it, in the same run, the HTTP round trip of the submission (POST to 201) and of GET
// /api/status (the bare request the daemon answers without work): the ratio says what the
// submission costs over a request. Target: p99 < 5 ms (the plan parsed once, the job handed to
// the rig's thread without a database round trip). It asserts every campaign completed, and that
// the latency was measured for each submission.
// usage: node bench_submit.mjs HYSTLABD OUT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { freshDir } from '../browser/harness.mjs';
import { startDaemon, stopDaemon } from '../browser/hystlabd.mjs';

const [daemonPath, outDir] = process.argv.slice(2);
if (!daemonPath || !outDir) { console.error('usage: node bench_submit.mjs HYSTLABD OUT_DIR'); process.exit(2); }
freshDir(outDir);
const N = Number(process.env.BENCH_SUBMIT_N || 20);
fs.writeFileSync(path.join(outDir, 'hystlab.json'), JSON.stringify({
  db: 'submit.db', rigs: [{ name: 'sim frame', simulate: { time_scale: 10, noise_N: 0.05 } }],
}));
let log = '';
const daemon = startDaemon(daemonPath, ['--config', path.join(outDir, 'hystlab.json'), '--port', '0'], { cwd: outDir, onOutput: d => { log += d; } });
const base = `http://127.0.0.1:${await daemon.port}`;
const timed = async (p, opts = {}) => {
  const t0 = performance.now();
  const r = await fetch(base + p, { signal: AbortSignal.timeout(20000), ...opts });
  const body = await r.text();
  return { ms: performance.now() - t0, status: r.status, body };
};
const pct = (v, q) => { const s = v.slice().sort((a, b) => a - b); return s[Math.min(s.length - 1, Math.floor(q * s.length))]; };
const f = v => `${v.toFixed(2)} ms`;
const plan = { kind: 'fot', range_mm: [0, 0.5], subdivisions: 1, ramp_rate_mm_s: 2, sample_rate_hz: 200, validation: false };
let failures = 0;
const latency = [], post = [], status = [];
try {
  for (let k = 0; k < 20; k++) status.push((await timed('/api/status')).ms);  // warm
  for (let k = 0; k < N; k++) {
    for (let j = 0; j < 3; j++) status.push((await timed('/api/status')).ms);
    const r = await timed('/api/campaigns', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ plan }) });
    if (r.status !== 201) throw new Error(`submission ${k}: ${r.status} ${r.body}`);
    post.push(r.ms);
    const id = JSON.parse(r.body).id;
    let state = '';
    for (let t = 0; t < 300 && !['completed', 'aborted', 'failed'].includes(state); t++) {
      await new Promise(res => setTimeout(res, 50));
      state = JSON.parse((await timed(`/api/campaigns/${id}`)).body).state;
    }
    if (state !== 'completed') { console.log(`FAIL campaign ${id} ended ${state}`); failures++; }
    const m = /hystlab_submission_latency_seconds\{rig="sim frame"\} ([0-9.e+-]+)/.exec((await timed('/metrics')).body);
    if (!m) { console.log(`FAIL no submission latency in /metrics after campaign ${id}`); failures++; continue; }
    latency.push(1000 * Number(m[1]));
  }
} catch (e) {
  console.log('FAIL ' + (e.stack || e));
  failures++;
} finally {
  await stopDaemon(daemon.proc);
}
if (latency.length) {
  const p50 = pct(latency, 0.5), p99 = pct(latency, 0.99), s50 = pct(status, 0.5), post50 = pct(post, 0.5);
  console.log(`submission latency (submit() called -> the rig's thread has the job), ${latency.length} submissions: p50 ${f(p50)}, p99 ${f(p99)}, max ${f(Math.max(...latency))} ` +
              `(target p99 < 5 ms: ${p99 < 5 ? 'met' : 'NOT met'})`);
  console.log(`HTTP round trips in the same run: POST /api/campaigns p50 ${f(post50)}, p99 ${f(pct(post, 0.99))}; GET /api/status (bare) p50 ${f(s50)}; ` +
              `submission over a bare request: ${(post50 / s50).toFixed(2)}`);
}
if (failures) console.log(log.slice(-3000));
console.log(failures ? `${failures} check(s) failed` : 'all checks passed');
process.exit(failures ? 1 : 0);
