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

// After a change of the viewport's width, the page's plots follow their containers through
// ResizeObserver callbacks, a frame or more later, one after another (each plot's new size may
// resize the next); a machine that freezes for a moment delays them further. Stop 38's CI read
// scrollWidth 1005 at 800 px once the loop plot had shrunk but before every other one had.
// So this waits until nothing reaches past the width and no plot's canvas has changed its width
// for 10 frames (up to timeout ms, polled each frame), and says what still reaches past it when
// it gives up: the settled layout is what is checked, and a layout that never fits still fails,
// naming its widest elements.
export async function settledWidth(page, width, timeout = 10000) {
  await page.waitForFunction(w => {
    const now = [...document.querySelectorAll('canvas')].map(c => c.getBoundingClientRect().width).join(',');
    const s = window.__settle || (window.__settle = { last: '', frames: 0 });
    s.frames = now === s.last ? s.frames + 1 : 0;
    s.last = now;
    return document.documentElement.scrollWidth <= w && s.frames >= 10;
  }, width, { timeout, polling: 'raf' }).catch(() => {});
  await page.evaluate(() => { delete window.__settle; });
  return page.evaluate(w => {
    const over = [];
    for (const el of document.querySelectorAll('body *')) {
      const r = el.getBoundingClientRect();
      if (r.width > 0 && r.right + window.scrollX > w) {
        over.push(`${el.tagName.toLowerCase()}${el.id ? '#' + el.id : ''}${el.className && typeof el.className === 'string' ? '.' + el.className.split(' ')[0] : ''} ${Math.round(r.right + window.scrollX)}`);
      }
    }
    return { scrollWidth: document.documentElement.scrollWidth, over: over.slice(0, 6) };
  }, width);
}
