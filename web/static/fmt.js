// Numbers for people: a few significant figures, durations in words, local times.

// 3 significant figures at most, no trailing zeros ("12.1", "0.0512", "2050").
export function num(v, sig = 3) {
  if (v == null || !Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  const a = Math.abs(v);
  const decimals = Math.max(0, sig - 1 - Math.floor(Math.log10(a)));
  return Number(v.toFixed(Math.min(decimals, 6))).toLocaleString('en', { maximumFractionDigits: 6 });
}
// A force or length as a person reads it: "12 N", "3.2 N", "0.41 N".
export function round2(v) {
  if (v == null || !Number.isFinite(v)) return '–';
  const a = Math.abs(v);
  return a >= 10 ? Math.round(v).toLocaleString('en') : a >= 1 ? v.toFixed(1) : num(v, 2);
}
export const count = v => (v == null ? '–' : Number(v).toLocaleString('en'));
export const plural = (n, one, many = one + 's') => `${count(n)} ${n === 1 ? one : many}`;

// "2 min 10 s", "1 h 5 min", "8 s".
export function duration(s) {
  if (s == null || !Number.isFinite(s)) return '–';
  if (s < 60) return `${s < 10 ? num(s, 2) : Math.round(s)} s`;
  const m = Math.round(s);
  if (m < 3600) return `${Math.floor(m / 60)} min${m % 60 ? ` ${m % 60} s` : ''}`;
  const min = Math.round(m / 60);
  return `${Math.floor(min / 60)} h${min % 60 ? ` ${min % 60} min` : ''}`;
}
// A rough time to go: "≈ 40 s", "≈ 3 min", "≈ 1 h 20 min".
export function roughly(s) {
  if (!Number.isFinite(s) || s < 0) return '';
  if (s < 60) return `≈ ${Math.max(5, Math.round(s / 5) * 5)} s`;
  if (s < 3600) return `≈ ${Math.round(s / 60)} min`;
  return `≈ ${duration(Math.round(s / 300) * 300)}`;
}
export const localTime = at => { const d = new Date(at); return Number.isNaN(d.getTime()) ? String(at) : d.toLocaleTimeString(); };

export function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (v != null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}
