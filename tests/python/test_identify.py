#!/usr/bin/env python3
"""hystlab's Python identification, fit, calibration and measures against the CLI's: the same
tables and parameters to the last digit, the same accuracy figures and loop figures.

usage: test_identify.py HYSTLAB_CLI [unittest options]    (PYTHONPATH: the built package)
"""
import json
import sys
import unittest

import numpy as np

import hystlab
from support import Scratch, random_path, write_csv

S = None


def setUpModule():
    global S
    S = Scratch(CLI, seed=7)


def tearDownModule():
    S.close()


def without_created(text):
    doc = json.loads(text)
    doc["provenance"].pop("created")
    return doc


def fot_nodes(params, n, repeats, noise, rng):
    """FOT nodes of the simplified model on n steps of 0..4 mm, each descent `repeats` times with
    force noise: rise from 0 to δ_i, then down through δ_{i-1} .. δ_0."""
    m = hystlab.Model(params)
    d = np.linspace(0.0, 4.0, n + 1)
    cols = {"alpha_mm": [], "beta_mm": [], "force_alpha_N": [], "force_alpha_beta_N": []}
    for _ in range(repeats):
        m.reset()
        for i in range(1, n + 1):
            fa = m.step(d[i]) + rng.normal(0, noise)
            for j in range(i - 1, -1, -1):
                fab = m.step(d[j]) + rng.normal(0, noise)
                for key, v in zip(cols, (d[i], d[j], fa, fab)):
                    cols[key].append(v)
    return {k: np.array(v) for k, v in cols.items()}


class Identify(unittest.TestCase):
    def test_virtual_identification_is_the_clis(self):
        p = hystlab.Params.load(S.path("P.json"))
        cases = {"uniform": ({"range": (0, 4), "subdivisions": 12}, "T.json"),
                 "refined": ({"range": (0, 4), "subdivisions": 10, "refine": (2, 1)}, "R.json")}
        for what, (kwargs, name) in cases.items():
            with self.subTest(what):
                t = hystlab.identify_virtual(p, **kwargs)
                self.assertEqual(t, hystlab.Table.load(S.path(name)))
                self.assertEqual(t.provenance["method"], "virtual-fot")
        nodes = [0, 0.5, 1.5, 1.75, 2, 2.25, 3, 4]
        S.cli.run("identify", "--model", "simplified", "--params", "P.json", "--nodes", ",".join(map(str, nodes)), "-o", "N.json")
        self.assertEqual(hystlab.identify_virtual(p, nodes=nodes), hystlab.Table.load(S.path("N.json")))
        for bad in ({"range": (0, 4)}, {"subdivisions": 4}, {"range": (4, 0), "subdivisions": 4},
                    {"nodes": nodes, "subdivisions": 4}, {"nodes": [0, 2, 1]}):
            with self.subTest(bad=bad), self.assertRaises(ValueError):
                hystlab.identify_virtual(p, **bad)

    def test_identification_from_nodes_is_the_clis(self):
        cols = fot_nodes(hystlab.Params.load(S.path("P.json")), 8, 2, 0.3, S.rng)
        write_csv(S.path("nodes.csv"), cols)
        out = S.cli.run("identify", "--fot", "nodes.csv", "-o", "F.json")
        t, details = hystlab.identify_from_nodes(*cols.values(), origin="nodes.csv", details=True)
        self.assertEqual(without_created(t.to_json()), without_created(S.read("F.json")))
        self.assertEqual(len(details["violations"]), out.count("warning: cell"))
        self.assertEqual(t.provenance["details"]["drift_max_spread_N"], details["drift"]["max_spread_N"])
        S.cli.run("identify", "--fot", "nodes.csv", "--noise", "2.5", "-o", "F2.json")
        t2 = hystlab.identify_from_nodes(*cols.values(), noise=2.5, origin="nodes.csv")
        self.assertEqual(without_created(t2.to_json()), without_created(S.read("F2.json")))
        with self.assertRaises(ValueError):
            hystlab.identify_from_nodes(*cols.values(), noise=-1)


class FitAndCalibrate(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        m = hystlab.Model(hystlab.Params.load(S.path("P.json")))
        cls.x = random_path(S.rng, 3000)
        cls.f = m.evaluate(cls.x) + S.rng.normal(0, 0.2, len(cls.x))
        write_csv(S.path("D.csv"), {"displacement_mm": cls.x, "force_N": cls.f})

    def test_fit_is_the_clis(self):
        cases = {"auto": ([], {}),
                 "monotone, lambda, range": (["--prior", "monotone", "--lambda", "0.01", "--range", "0,4"],
                                             {"prior": "monotone", "lambda_": 0.01, "range": (0, 4)})}
        for what, (args, kwargs) in cases.items():
            with self.subTest(what):
                S.cli.run("fit", "--data", "D.csv", "--subdivisions", 8, *args, "-o", "L.json")
                t = hystlab.fit(self.x, self.f, subdivisions=8, origin="D.csv", **kwargs)
                want = hystlab.Table.load(S.path("L.json"))
                self.assertEqual(t, want)
                a, b = t.provenance["details"], want.provenance["details"]
                for k in ("seconds", "peak_bytes"):
                    a.pop(k), b.pop(k)
                self.assertEqual(a, b)
        with self.assertRaises(ValueError) as e:
            hystlab.fit(self.x, self.f, subdivisions=8, prior="maybe")
        self.assertEqual(str(e.exception), S.cli.error("fit", "--data", "D.csv", "--subdivisions", 8, "--prior", "maybe", "-o", "L.json")
                         .removeprefix("option --"))

    def test_calibrate_is_the_clis(self):
        truth = hystlab.Params(KA=45, KM=140, dtr_max=2.8)
        d = np.concatenate([np.linspace(0, 4.5, 400), np.linspace(4.5, 0, 400)[1:]])
        f = hystlab.Model(truth).evaluate(d) + S.rng.normal(0, 0.1, len(d))
        write_csv(S.path("loop.csv"), {"displacement_mm": d, "force_N": f})
        S.cli.run("calibrate", "--data", "loop.csv", "--initial", "P.json", "-o", "C.json")
        p, details = hystlab.calibrate(d, f, initial=hystlab.Params.load(S.path("P.json")), origin="loop.csv", details=True)
        self.assertEqual(p.to_json(), S.read("C.json"))
        self.assertLess(details["rms_residual_N"], 1.0)
        S.cli.run("calibrate", "--data", "loop.csv", "--temperature", 30, "--clausius", 6, "-o", "C2.json")
        self.assertEqual(hystlab.calibrate(d, f, temperature=30, clausius=6, origin="loop.csv").to_json(), S.read("C2.json"))
        with self.assertRaises(ValueError) as e:
            hystlab.calibrate(d, f)
        self.assertIn("temperature and clausius", str(e.exception))


class Measures(unittest.TestCase):
    def test_accuracy_is_the_clis(self):
        x = random_path(S.rng, 1500)
        f = hystlab.Model(hystlab.Params()).evaluate(x)
        write_csv(S.path("A.csv"), {"displacement_mm": x, "force_N": f})
        text = S.cli.run("compare", "--table", "T.json", "--data", "A.csv")
        table = hystlab.Table.load(S.path("T.json"))
        r = hystlab.compare(x, f, hystlab.Model(table).evaluate(x))
        self.assertEqual(r, table.score(x, f) | {k: r[k] for k in r if k.startswith("loop_energy_") and k.endswith("Nmm")})
        for branch in ("overall", "ascending", "descending"):
            row = next(line.split() for line in text.splitlines() if line.startswith(branch))
            s = r[branch]
            self.assertEqual(row[1:4], [str(s["samples"]), "%.6g" % s["rms_N"], "%.6g" % s["max_N"]])

    def test_loop_figures_are_the_clis(self):
        d = np.concatenate([np.linspace(0, 4.2, 300), np.linspace(4.2, 1, 200)[1:], np.linspace(1, 3, 150)[1:],
                            np.linspace(3, 1, 150)[1:], np.linspace(1, 0, 100)[1:]])
        f = hystlab.Model(hystlab.Params()).evaluate(d)
        write_csv(S.path("loops.csv"), {"displacement_mm": d, "force_N": f})
        want = json.loads(S.cli.run("loops", "--data", "loops.csv", "--plateaus", "1,3", "--json"))
        got = hystlab.loops(d, f, plateaus=[1, 3])
        self.assertEqual(got, want)
        self.assertGreaterEqual(len(got), 2)
        full = np.concatenate([np.linspace(0, 4.5, 400), np.linspace(4.5, 0, 400)[1:]])
        t = hystlab.loop_transformation(full, hystlab.Model(hystlab.Params()).evaluate(full))
        self.assertEqual(set(t), {"Ms", "Mf", "As", "Af"})
        self.assertIsNone(hystlab.loop_transformation(d[:100], f[:100]))  # loading only: no plateau to read
        self.assertGreater(hystlab.path_work(d, f), 0)
        with self.assertRaises(ValueError):
            hystlab.loops(d, f[:-1])


if __name__ == "__main__":
    CLI = sys.argv.pop(1)
    unittest.main(verbosity=2)
