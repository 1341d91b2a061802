#!/usr/bin/env python3
"""hystlab.Client against a real hystlabd (a simulated load frame at 100x): a campaign submitted,
waited for, its samples as numpy arrays, its table as a hystlab.Table that scores and evaluates as
the daemon does, to the last digit; a campaign aborted; errors as ApiError with the daemon's words.

usage: test_client.py HYSTLABD [unittest options]    (PYTHONPATH: the built package)
"""
import os
import re
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

import hystlab

CONFIG = '{"rigs": [{"name": "sim frame", "simulate": {"time_scale": 100, "noise_N": 0.05}}]}'
FOT = {"kind": "fot", "range_mm": [0, 4], "subdivisions": 4, "ramp_rate_mm_s": 0.5, "sample_rate_hz": 200,
       "limits": {"displacement_mm": [-0.5, 4.5], "force_N": 400, "rate_mm_s": 50}}
LONG = {"kind": "waveform", "points_mm": [0, 4, 0] * 20, "ramp_rate_mm_s": 0.2, "sample_rate_hz": 200}

DAEMON = None
API = None


def setUpModule():
    global DAEMON, API
    API = hystlab.Client  # checked before a daemon is started, so a failure leaves none behind
    DAEMON = Daemon(HYSTLABD)
    API = hystlab.Client(DAEMON.url)


def tearDownModule():
    DAEMON.stop()


class Daemon:
    """hystlabd on a free port (--port 0; its log names the port), with its own database."""

    def __init__(self, exe):
        self.dir = tempfile.TemporaryDirectory()
        cfg = os.path.join(self.dir.name, "cfg.json")
        with open(cfg, "w") as f:
            f.write(CONFIG)
        self.log_path = os.path.join(self.dir.name, "daemon.log")
        self.log = open(self.log_path, "w")
        self.proc = subprocess.Popen([exe, "--config", cfg, "--db", os.path.join(self.dir.name, "d.db"), "--port", "0"],
                                     stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with open(self.log_path) as f:
                m = re.search(r"serving the API and the page on (http://127\.0\.0\.1:\d+)/", f.read())
            if m:
                self.url = m.group(1)
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.1)
        self.stop()
        raise RuntimeError("hystlabd did not start:\n" + open(self.log_path).read())

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(30)
        self.log.close()
        self.dir.cleanup()


class Client(unittest.TestCase):
    def test_a_campaign_its_samples_and_its_table(self):
        self.assertEqual(API.status()["name"], "hystlabd")
        c = API.submit(FOT, rig="sim frame")
        done = API.wait(c["id"], timeout=300)
        self.assertEqual(done["state"], "completed", done)
        runs = API.runs(c["id"])
        self.assertTrue(runs)
        run = runs[0]["id"]
        s = API.samples(run)
        self.assertEqual(list(s)[:6], ["seq", "t_s", "command_mm", "displacement_mm", "force_N", "status"])
        self.assertEqual(s["seq"].dtype, np.int64)
        self.assertEqual(len(s["force_N"]), API.run(run)["samples"])
        self.assertGreater(np.ptp(s["displacement_mm"]), 3.5)

        tables = [t for t in API.tables() if t["campaign"] == c["id"]]
        self.assertTrue(tables)
        tid = tables[0]["id"]
        table = API.table(tid)
        self.assertIsInstance(table, hystlab.Table)
        self.assertEqual(table.n, 4)
        # The daemon's score of its table on the run, and the module's on the samples it served
        # (samples.csv has 9 significant digits: the same figures to about 1e-8).
        x, f = s["displacement_mm"], s["force_N"]
        mine = table.score(np.clip(x, table.lo, table.hi), f)
        theirs = API.score(tid, run)
        for k in ("table", "run", "role"):
            theirs.pop(k)
        self.assertEqual(set(mine), set(theirs))
        for k in mine:
            a, b = mine[k], theirs[k]
            if isinstance(a, dict):
                self.assertEqual(a["samples"], b["samples"])
                a, b = [a[f] for f in sorted(a)], [b[f] for f in sorted(b)]
            np.testing.assert_allclose(a, b, rtol=1e-6, err_msg=k)
        forces, clamped = API.evaluate(x[:5000], table_id=tid)
        self.assertTrue(np.array_equal(forces, hystlab.Model(table).evaluate(x[:5000])))
        self.assertEqual(clamped, int(np.sum((x[:5000] < table.lo) | (x[:5000] > table.hi))))
        p = hystlab.Params()
        forces, _ = API.evaluate([0, 1, 2, 3, 2, 1], params=p)
        self.assertTrue(np.array_equal(forces, hystlab.Model(p).evaluate([0, 1, 2, 3, 2, 1])))
        self.assertIn("coverage", API.nodes(c["id"]))

    def test_abort(self):
        c = API.submit(LONG)
        deadline = time.monotonic() + 60
        while API.campaign(c["id"])["state"] in ("queued", "arming") and time.monotonic() < deadline:
            time.sleep(0.2)
        self.assertEqual(API.abort(c["id"])["command"], "abort")
        self.assertEqual(API.wait(c["id"], timeout=120)["state"], "aborted")
        with self.assertRaises(hystlab.ApiError) as e:
            API.pause(c["id"])
        self.assertEqual(e.exception.status, 409)

    def test_errors_carry_the_daemons_message(self):
        with self.assertRaises(hystlab.ApiError) as e:
            API.campaign(999999)
        self.assertEqual((e.exception.status, e.exception.error), (404, "not found"))
        self.assertIn("999999", e.exception.detail)
        with self.assertRaises(hystlab.ApiError) as e:
            API.submit(dict(FOT, subdivisions=0))
        self.assertEqual(e.exception.status, 400)
        self.assertIn("subdivisions", e.exception.detail)
        self.assertIn(e.exception.detail, str(e.exception))
        with self.assertRaises(hystlab.ApiError) as e:
            API.campaigns(state="sleeping")
        self.assertEqual(e.exception.field, "state")
        with self.assertRaises(ConnectionError):
            hystlab.Client("http://127.0.0.1:9", timeout=5).status()


if __name__ == "__main__":
    HYSTLABD = sys.argv.pop(1)
    unittest.main(verbosity=2)
