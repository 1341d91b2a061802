// The page's address says what it shows, so a colleague can be sent a link:
//   #campaign/12          campaign 12 (its own run: the newest that is not a validation run)
//   #campaign/12/run/14   campaign 12 with run 14 in the plots (its validation run, say)
// Following the newest campaign changes the address without a history entry; choosing one
// (the list, a run's "show") adds one, so Back returns to what was shown before.

export function parseRoute(hash = window.location.hash) {
  const m = /^#campaign\/(\d+)(?:\/run\/(\d+))?$/.exec(hash || '');
  return m ? { campaign: Number(m[1]), run: m[2] ? Number(m[2]) : null } : null;
}

export function routeHref(campaign, run = null) {
  return campaign == null ? '#' : `#campaign/${campaign}` + (run != null ? `/run/${run}` : '');
}

// Shows the route in the address bar; `remember`: a history entry (a choice, not following).
export function setRoute(campaign, run, remember) {
  const href = routeHref(campaign, run);
  if (window.location.hash === href) return;
  if (remember) window.history.pushState(null, '', href); else window.history.replaceState(null, '', href);
}

// The whole address of a route, for copying.
export const routeUrl = (campaign, run) => window.location.origin + window.location.pathname + routeHref(campaign, run);
