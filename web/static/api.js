// Talking to hystlabd (docs/API.md): JSON in and out, the read token when the daemon asks for
// one, and errors that keep the server's answer (the page maps `field` to the form's input).

const TOKEN_KEY = 'hystlab-token';
const API_TIMEOUT_MS = 20000;  // a request that never ends must not stall every later update
let asked = false;             // prompt for the token once per page, not on every poll

export class ApiError extends Error {
  constructor(status, body) {
    const detail = body && typeof body === 'object' ? (body.detail || body.error) : '';
    super(detail || `HTTP ${status}`);
    this.status = status;
    this.body = body && typeof body === 'object' ? body : null;
  }
}

export const token = () => sessionStorage.getItem(TOKEN_KEY);

// Where this page's daemon answers. A rig's own daemon: here (""). The lab view shows a daemon's
// records from the lab database at /daemons/NAME/ and says so in the page's head (docs/LAB.md):
// the same endpoints under that prefix, read-only (ARCHIVE: no commands, no live stream).
const baseMeta = document.querySelector('meta[name="hystlab-base"]');
export const BASE = baseMeta ? baseMeta.content : '';
export const ARCHIVE = !!baseMeta;
export const href = path => BASE + path;

export async function api(path, options = {}) {
  const headers = Object.assign({}, options.body ? { 'Content-Type': 'application/json' } : {}, options.headers || {});
  const t = token();
  if (t) headers.Authorization = 'Bearer ' + t;
  const res = await fetch(BASE + path, Object.assign({ signal: AbortSignal.timeout(API_TIMEOUT_MS) }, options, { headers }));
  const body = res.headers.get('Content-Type')?.includes('json') ? await res.json().catch(() => null) : await res.text();
  if (res.status === 401 && !options.retried && !asked) {
    asked = true;
    const entered = window.prompt('This daemon needs its token:');
    if (entered) { sessionStorage.setItem(TOKEN_KEY, entered.trim()); asked = false; return api(path, Object.assign({}, options, { retried: true })); }
  }
  if (!res.ok) throw new ApiError(res.status, body);
  return body;
}

export const post = (path, body) => api(path, body === undefined ? { method: 'POST' } : { method: 'POST', body: JSON.stringify(body) });
