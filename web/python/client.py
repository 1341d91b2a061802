"""A small client for a running hystlabd, over its HTTP/JSON API (docs/API.md).

    from hystlab import Client
    api = Client("http://127.0.0.1:8080")          # token=... when the daemon has one
    c = api.submit({"kind": "waveform", "points_mm": [0, 3, 1, 4, 0], ...})
    api.wait(c["id"])
    run = api.runs(c["id"])[0]["id"]
    s = api.samples(run)                            # {"t_s": array, "displacement_mm": array, ...}
    table = api.table(api.tables()[-1]["id"])        # a hystlab.Table

The standard library speaks HTTP (urllib.request, json, csv); samples come back as numpy arrays.
An error answer raises ApiError with the daemon's own message; a daemon that cannot be reached
raises ConnectionError.
"""
import csv
import io
import json
import time
import urllib.error
import urllib.parse
import urllib.request

import numpy as np

__all__ = ["ApiError", "Client"]


class ApiError(Exception):
    """An error answer of the API: `status` (HTTP), `error` (its kind), `detail` (what exactly is
    wrong, as the daemon says it) and `field` (the request field at fault, or None)."""

    def __init__(self, status, error, detail, field=None):
        super().__init__("%s (HTTP %d %s)" % (detail, status, error))
        self.status, self.error, self.detail, self.field = status, error, detail, field


# Columns of samples.csv that are counters, not measurements.
_INTEGER_COLUMNS = {"seq", "status"}


class Client:
    """One daemon. Reads need no token unless the daemon sets a read token; writes need the token
    whenever the daemon has one."""

    def __init__(self, url="http://127.0.0.1:8080", token=None, timeout=30.0):
        self.url = url.rstrip("/")
        self.token = token
        self.timeout = timeout

    def __repr__(self):
        return "hystlab.Client(%r)" % self.url

    # -- plumbing ---------------------------------------------------------------------------
    def _open(self, method, path, body=None, query=None):
        url = self.url + path
        if query:
            url += "?" + urllib.parse.urlencode({k: v for k, v in query.items() if v is not None})
        data = None
        headers = {"Accept": "application/json"}
        if body is not None:
            data = json.dumps(body).encode()
            headers["Content-Type"] = "application/json"
        if self.token:
            headers["Authorization"] = "Bearer " + self.token
        # A command has no body at all (data None: http.client sends Content-Length 0); b"" would get
        # urllib's form content type, which the API refuses (415) as a browser form.
        req = urllib.request.Request(url, data=data, method=method, headers=headers)
        try:
            return urllib.request.urlopen(req, timeout=self.timeout)
        except urllib.error.HTTPError as e:
            raise _api_error(e) from None
        except urllib.error.URLError as e:
            raise ConnectionError("cannot reach hystlabd at %s: %s" % (self.url, e.reason)) from None

    def _json(self, method, path, body=None, query=None):
        with self._open(method, path, body, query) as r:
            return json.loads(r.read().decode())

    def get(self, path, **query):
        """Any GET route of the API, as parsed JSON: client.get("/api/campaigns/1/nodes")."""
        return self._json("GET", path, query=query)

    def text(self, path, **query):
        """Any GET route, as text (CSV, the table exports)."""
        with self._open("GET", path, query=query) as r:
            return r.read().decode()

    # -- status and rigs --------------------------------------------------------------------
    def status(self):
        return self._json("GET", "/api/status")

    def rigs(self):
        return self._json("GET", "/api/rigs")

    def rig(self, name):
        return self._json("GET", "/api/rigs/" + urllib.parse.quote(str(name), safe=""))

    # -- campaigns --------------------------------------------------------------------------
    def campaigns(self, state=None):
        """Every campaign (or those in one state: queued, running, completed, ...)."""
        return self._json("GET", "/api/campaigns", query={"state": state})

    def campaign(self, campaign_id):
        return self._json("GET", "/api/campaigns/%d" % campaign_id)

    def runs(self, campaign_id):
        """The runs of a campaign, with their sample counts."""
        return self._json("GET", "/api/campaigns/%d/runs" % campaign_id)

    def nodes(self, campaign_id):
        """The FOT nodes measured so far and the coverage of the Preisach triangle."""
        return self._json("GET", "/api/campaigns/%d/nodes" % campaign_id)

    def loops(self, campaign_id):
        """The figures of every closed cycle of the campaign's runs (as hystlab.loops gives)."""
        return self._json("GET", "/api/campaigns/%d/loops" % campaign_id)

    def submit(self, plan, rig=None):
        """Queues a campaign (plans: docs/DAEMON.md); returns it, with its "id"."""
        body = {"plan": plan}
        if rig is not None:
            body["rig"] = rig
        return self._json("POST", "/api/campaigns", body)

    def preview(self, plan, rig=None):
        body = {"plan": plan}
        if rig is not None:
            body["rig"] = rig
        return self._json("POST", "/api/plans/preview", body)

    def command(self, campaign_id, verb):
        """pause, resume, abort or estop; 202 when queued (the state changes later)."""
        return self._json("POST", "/api/campaigns/%d/%s" % (campaign_id, verb))

    def pause(self, campaign_id):
        return self.command(campaign_id, "pause")

    def resume(self, campaign_id):
        return self.command(campaign_id, "resume")

    def abort(self, campaign_id):
        return self.command(campaign_id, "abort")

    def estop(self, campaign_id):
        return self.command(campaign_id, "estop")

    def wait(self, campaign_id, timeout=600.0, poll=0.5):
        """Polls until the campaign is over (completed, aborted or failed); returns it. Raises
        TimeoutError naming its state when it is not over in time."""
        deadline = time.monotonic() + timeout
        while True:
            c = self.campaign(campaign_id)
            if c.get("final"):
                return c
            if time.monotonic() > deadline:
                raise TimeoutError("campaign %d is still %s after %g s" % (campaign_id, c.get("state"), timeout))
            time.sleep(poll)

    # -- runs and samples -------------------------------------------------------------------
    def run(self, run_id):
        return self._json("GET", "/api/runs/%d" % run_id)

    def samples(self, run_id):
        """Every sample of a run at full resolution (GET /api/runs/ID/samples.csv) as a dict of
        numpy arrays by column: seq, t_s, command_mm, displacement_mm, force_N, status for a load
        frame; a shaker's run has its own columns (docs/FORMATS.md, "Runs as CSV"). The numbers
        are the stored doubles exactly.
        Columns are float64, seq and status int64."""
        with self._open("GET", "/api/runs/%d/samples.csv" % run_id) as r:
            reader = csv.reader(io.TextIOWrapper(r, encoding="utf-8", newline=""))
            header = next(reader, None)
            if header is None:
                return {}
            rows = [row for row in reader if row]
        columns = list(zip(*rows)) if rows else [() for _ in header]
        return {name: np.array(col, dtype=np.int64 if name in _INTEGER_COLUMNS else np.float64)
                for name, col in zip(header, columns)}

    # -- tables -----------------------------------------------------------------------------
    def tables(self):
        """Every calibrated table with its provenance and accuracy (not the documents)."""
        return self._json("GET", "/api/tables")

    def table_info(self, table_id):
        return self._json("GET", "/api/tables/%d" % table_id)

    def table(self, table_id):
        """The table as a hystlab.Table (its canonical JSON document)."""
        from ._hystlab import Table
        return Table.from_json(self.text("/api/tables/%d/export" % table_id, format="json"))

    def score(self, table_id, run_id):
        """The table scored on a run's samples (GET /api/tables/ID/score?run=RUN)."""
        return self._json("GET", "/api/tables/%d/score" % table_id, query={"run": run_id})

    def evaluate(self, displacement, table_id=None, table=None, params=None):
        """The daemon's POST /api/evaluate: forces from rest (a numpy array) and the count of
        inputs clamped to the table's range. Give one of table_id, table (hystlab.Table) or params
        (hystlab.Params)."""
        body = {"displacement_mm": [float(v) for v in np.asarray(displacement, dtype=np.float64).ravel()]}
        if table_id is not None:
            body["table_id"] = table_id
        if table is not None:
            body["table"] = json.loads(table.to_json())
        if params is not None:
            body["params"] = json.loads(params.to_json())
        answer = self._json("POST", "/api/evaluate", body)
        return np.array(answer["force_N"], dtype=np.float64), answer.get("saturations", 0)


def _api_error(e):
    """The daemon's error body ({"error", "detail", "field"}) as an ApiError."""
    try:
        body = json.loads(e.read().decode())
    except (ValueError, OSError):
        body = {}
    if not isinstance(body, dict):
        body = {}
    return ApiError(e.code, body.get("error", e.reason), body.get("detail", str(e.reason)), body.get("field"))
