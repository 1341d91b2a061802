// What the browser test and bench_page share besides the daemon (hystlabd.mjs): Debian's Chromium
// driven by web/'s playwright-core, a fresh output folder, and counted checks.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.resolve(here, '../../web/package.json'));
export const { chromium } = require('playwright-core');

// $CHROMIUM or Debian's; exits with a clear message when it is not installed.
export function chromiumPath() {
  const p = process.env.CHROMIUM || '/usr/bin/chromium';
  if (!fs.existsSync(p)) { console.error(`no Chromium at ${p} (apt install chromium)`); process.exit(1); }
  return p;
}

export function freshDir(dir) {
  fs.rmSync(dir, { recursive: true, force: true });
  fs.mkdirSync(dir, { recursive: true });
}

// check(cond, what) prints ok/FAIL and counts the failures.
export class Checks {
  failures = 0;
  check = (cond, what) => {
    console.log(`${cond ? 'ok  ' : 'FAIL'} ${what}`);
    if (!cond) this.failures++;
    return cond;
  };
}
