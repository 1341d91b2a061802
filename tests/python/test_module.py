#!/usr/bin/env python3
"""hystlab's Python module against the CLI: the same forces to the last digit on a random input
(a uniform table, a table on a grid of its own, the simplified model), memory kept between calls,
copies, pickles and saved states that continue identically, and errors with the CLI's messages.

usage: test_module.py HYSTLAB_CLI [unittest options]    (PYTHONPATH: the built package)
"""
import concurrent.futures
import copy
import json
import pickle
import sys
import unittest

import numpy as np

import hystlab
from support import Scratch

S = None  # the scratch files, made once


def setUpModule():
    global S
    S = Scratch(CLI)


def tearDownModule():
    S.close()


def model_of(name):
    return hystlab.Model(hystlab.Table.load(S.path(name)) if name != "P.json" else hystlab.Params.load(S.path(name)))


CLI_ARGS = {"T.json": ["--table", "T.json"], "R.json": ["--table", "R.json"],
            "P.json": ["--model", "simplified", "--params", "P.json"]}


class SameForcesAsTheCli(unittest.TestCase):
    def test_every_model_to_the_last_digit(self):
        for name, args in CLI_ARGS.items():
            with self.subTest(name):
                want = S.cli.eval_forces(*args)
                got = model_of(name).evaluate(S.x)
                self.assertEqual(got.dtype, np.float64)
                self.assertEqual(len(got), len(S.x))
                self.assertTrue(np.array_equal(got, want), "%d of %d differ" % (np.sum(got != want), len(want)))
                # Model.load (and Model(path)) tells a table from parameters by the document.
                self.assertTrue(np.array_equal(hystlab.Model.load(S.path(name)).evaluate(S.x), want))
                self.assertTrue(np.array_equal(hystlab.Model(S.path(name)).evaluate(S.x), want))

    def test_the_grid_of_its_own_is_version_2(self):
        self.assertEqual(hystlab.Table.load(S.path("T.json")).version, 1)
        r = hystlab.Table.load(S.path("R.json"))
        self.assertEqual(r.version, 2)
        self.assertFalse(r.uniform)
        self.assertEqual(list(r.nodes), json.loads(S.read("R.json"))["nodes_mm"])

    def test_any_array_like_is_converted(self):
        m = model_of("T.json")
        want = m.copy().evaluate(S.x[:200])
        self.assertTrue(np.array_equal(m.copy().evaluate(list(S.x[:200])), want))
        strided = np.repeat(S.x[:200], 2)[::2]  # not contiguous
        self.assertFalse(strided.flags.c_contiguous)
        self.assertTrue(np.array_equal(m.copy().evaluate(strided), want))
        self.assertTrue(np.array_equal(m.copy().evaluate(S.x[:200].astype(np.float32)),
                                       m.copy().evaluate(S.x[:200].astype(np.float32).astype(np.float64))))
        two_d = m.copy().evaluate(S.x[:200].reshape(20, 10))
        self.assertEqual(two_d.shape, (20, 10))
        self.assertTrue(np.array_equal(two_d.ravel(), want))
        self.assertEqual(m.copy()(S.x[:200]).tolist(), want.tolist())  # a model is callable


class Memory(unittest.TestCase):
    def test_two_halves_are_the_whole(self):
        for name in CLI_ARGS:
            with self.subTest(name):
                whole = model_of(name).evaluate(S.x)
                m = model_of(name)
                halves = np.concatenate([m.evaluate(S.x[:777]), m.evaluate(S.x[777:])])
                self.assertTrue(np.array_equal(halves, whole))
                m = model_of(name)
                self.assertEqual([m.step(v) for v in S.x[:300]], whole[:300].tolist())

    def test_a_copy_continues_identically(self):
        for name in CLI_ARGS:
            with self.subTest(name):
                m = model_of(name)
                m.evaluate(S.x[:1000])
                for branch in (m.copy(), copy.copy(m), copy.deepcopy(m)):
                    a = branch.evaluate(S.x[1000:])
                    self.assertTrue(np.array_equal(a, model_of(name).evaluate(S.x)[1000:]))
                rest = m.evaluate(S.x[1000:])
                self.assertTrue(np.array_equal(rest, a))

    def test_threads(self):
        """Copies evaluated on threads at once (the loop runs without the GIL) give the same forces;
        one model shared by threads is serialised, never torn."""
        want = model_of("R.json").evaluate(S.x)
        models = [model_of("R.json") for _ in range(4)]
        with concurrent.futures.ThreadPoolExecutor(4) as pool:
            results = list(pool.map(lambda m: np.concatenate([m.evaluate(S.x[:1000]), m.evaluate(S.x[1000:])]), models))
        for r in results:
            self.assertTrue(np.array_equal(r, want))
        shared = model_of("R.json")
        with concurrent.futures.ThreadPoolExecutor(4) as pool:
            list(pool.map(lambda _: shared.evaluate(S.x), range(8)))
        self.assertEqual(shared.input, S.x[-1])

    def test_reset_goes_back_to_rest(self):
        m = model_of("T.json")
        first = m.evaluate(S.x[:500])
        m.evaluate(S.x[500:])
        m.reset()
        self.assertTrue(np.array_equal(m.evaluate(S.x[:500]), first))

    def test_pickle_round_trip_continues(self):
        for name in CLI_ARGS:
            with self.subTest(name):
                m = model_of(name)
                m.evaluate(S.x[:1234])
                back = pickle.loads(pickle.dumps(m))
                self.assertTrue(np.array_equal(back.evaluate(S.x[1234:]), m.evaluate(S.x[1234:])))
                t = hystlab.Table.load(S.path("R.json"))
                self.assertEqual(pickle.loads(pickle.dumps(t)), t)
                p = hystlab.Params.load(S.path("P.json"))
                self.assertEqual(pickle.loads(pickle.dumps(p)), p)

    def test_state_rolls_back(self):
        for name in CLI_ARGS:
            with self.subTest(name):
                m = model_of(name)
                m.evaluate(S.x[:900])
                saved = m.state
                self.assertIsInstance(saved, bytes)
                a = m.evaluate(S.x[900:])
                m.state = saved
                self.assertTrue(np.array_equal(m.evaluate(S.x[900:]), a))
                fresh = model_of(name)  # another instance of the same table takes it too
                fresh.state = saved
                self.assertTrue(np.array_equal(fresh.evaluate(S.x[900:]), a))

    def test_clamped_inputs_are_counted(self):
        m = model_of("T.json")
        self.assertEqual(m.range, (0.0, 4.0))
        f = m.evaluate([2.0, 9.0, -1.0])
        self.assertEqual(m.saturations, 2)
        self.assertEqual(f[1], m.peek(4.0))
        self.assertEqual(m.step(5.0), m.peek(4.0))
        self.assertEqual(m.saturations, 3)
        with self.assertRaises(ValueError):
            m.step(5.0, clamp=False)
        with self.assertRaises(ValueError) as e:
            m.evaluate([1.0, 4.5], clamp=False)
        self.assertEqual(str(e.exception), "x[1]: displacement 4.5 mm is outside the table's range 0..4 mm (clamp=True clamps and counts)")


class Errors(unittest.TestCase):
    def assert_same_message(self, exc_type, make, *cli_args):
        with self.assertRaises(exc_type) as e:
            make()
        self.assertEqual(str(e.exception), S.cli.error(*cli_args))

    def write(self, name, text):
        with open(S.path(name), "w") as f:
            f.write(text)
        return S.path(name)

    def test_unknown_table_version(self):
        doc = json.loads(S.read("T.json"))
        doc["version"] = 7
        path = self.write("V7.json", json.dumps(doc))
        self.assert_same_message(hystlab.FormatError, lambda: hystlab.Table.load(path), "eval", "--table", path, "--input", "X.csv")
        self.assertTrue(issubclass(hystlab.FormatError, ValueError))

    def test_documents_the_cli_refuses(self):
        doc = json.loads(S.read("T.json"))
        doc["rows"][3][1] = "x"
        cases = {"not JSON": ("{oops", hystlab.Table), "a bad cell": (json.dumps(doc), hystlab.Table),
                 "another format": ('{"format": "something", "version": 1}', hystlab.Table),
                 "bad parameters": (S.read("P.json").replace('"KA_N_per_mm": 40', '"KA_N_per_mm": -40'), hystlab.Params)}
        for what, (text, cls) in cases.items():
            with self.subTest(what):
                path = self.write("bad.json", text)
                args = ["--table", path] if cls is hystlab.Table else ["--model", "simplified", "--params", path]
                self.assert_same_message(hystlab.FormatError, lambda: cls.load(path), "eval", *args, "--input", "X.csv")
                # From text: the CLI's message, naming the text where the CLI names its file.
                with self.assertRaises(hystlab.FormatError) as e:
                    cls.from_json(text)
                named = "table" if cls is hystlab.Table else "parameter"
                self.assertEqual(str(e.exception), S.cli.error("eval", *args, "--input", "X.csv").replace("%s file '%s'" % (named, path), named + " text"))

    def test_missing_file(self):
        with self.assertRaises(FileNotFoundError) as e:
            hystlab.Table.load("nope.json")
        self.assertEqual(str(e.exception), S.cli.error("eval", "--table", "nope.json", "--input", "X.csv"))
        self.assertEqual(str(e.exception), "cannot open 'nope.json': No such file or directory")
        with self.assertRaises(FileNotFoundError):
            hystlab.Params.load("nope.json")

    def test_non_finite_input_names_its_index_and_changes_nothing(self):
        for name in CLI_ARGS:
            with self.subTest(name):
                m = model_of(name)
                m.evaluate(S.x[:500])
                before = m.state
                for bad in (float("nan"), float("inf"), -float("inf")):
                    x = S.x[500:510].copy()
                    x[3] = bad
                    with self.assertRaises(ValueError) as e:
                        m.evaluate(x)
                    self.assertEqual(str(e.exception), "x[3] is not a finite number")
                    with self.assertRaises(ValueError):
                        m.step(bad)
                self.assertEqual(m.state, before)
        with self.assertRaises(ValueError) as e:
            model_of("T.json").evaluate(np.array([[0.0, 1.0], [np.nan, 2.0]]))
        self.assertEqual(str(e.exception), "x[1, 0] is not a finite number")
        with self.assertRaises(ValueError):
            model_of("T.json").evaluate(["a", "b"])

    def test_a_state_from_another_table(self):
        t = hystlab.Table.load(S.path("T.json"))
        # The same grid, other values: save_state alone cannot tell them apart; the fingerprint can.
        other = hystlab.Table(t.nodes, t.values * 1.5, force_offset=t.force_offset)
        a, b = hystlab.Model(t), hystlab.Model(other)
        a.evaluate(S.x[:300])
        with self.assertRaises(ValueError) as e:
            b.state = a.state
        self.assertIn("another table", str(e.exception))
        for wrong in (model_of("R.json"), model_of("P.json")):
            with self.assertRaises(ValueError):
                wrong.state = a.state
        with self.assertRaises(ValueError):
            a.state = b"not a state at all"
        with self.assertRaises(ValueError):
            a.state = a.state[:-8]  # a state cut short: restore_state names what is wrong
        with self.assertRaises(TypeError):
            a.state = [1.0, 2.0]


class Documents(unittest.TestCase):
    def test_save_and_load_round_trip_to_the_cli_text(self):
        for name, cls in (("T.json", hystlab.Table), ("R.json", hystlab.Table)):
            text = S.read(name)
            self.assertEqual(cls.load(S.path(name)).to_json(), text)
            cls.load(S.path(name)).save(S.path("copy.json"))
            self.assertEqual(S.read("copy.json"), text)
        p = hystlab.Params.load(S.path("P.json"))
        self.assertEqual(p, hystlab.Params())  # Table 1 is the default
        self.assertEqual(p.source, "Table 1")
        p.save(S.path("P2.json"))
        self.assertEqual(hystlab.Params.load(S.path("P2.json")), p)

    def test_a_table_from_arrays(self):
        t = hystlab.Table.load(S.path("R.json"))
        again = hystlab.Table(t.nodes, t.matrix(), t.force_offset, provenance=t.provenance)
        self.assertEqual(again, t)
        self.assertEqual(again.to_json(), t.to_json())
        i, j = 5, 2
        self.assertEqual(t.everett(t.nodes[i], t.nodes[j]), t.matrix()[i, j])
        self.assertEqual(t.provenance["method"], "virtual-fot")
        with self.assertRaises(ValueError):
            hystlab.Table([0.0, 1.0, 0.5], np.zeros(6))  # nodes must increase
        with self.assertRaises(ValueError):
            hystlab.Table([0.0, 1.0], np.ones(3))  # F(α, α) must be 0

    def test_every_export_is_the_clis(self):
        t = hystlab.Table.load(S.path("R.json"))
        self.assertEqual(t.to_csv(), S.cli.run("export", "--table", "R.json", "--format", "csv"))
        self.assertEqual(t.to_matlab(), S.cli.run("export", "--table", "R.json", "--format", "m"))
        self.assertEqual(t.to_c_header("hystlab_table"), S.cli.run("export", "--table", "R.json", "--format", "h"))
        p = hystlab.Params.load(S.path("P.json"))
        self.assertEqual(p.to_csv(), S.cli.run("export", "--params", "P.json", "--format", "csv"))
        self.assertEqual(p.to_c_header("hystlab_params"), S.cli.run("export", "--params", "P.json", "--format", "h"))


if __name__ == "__main__":
    CLI = sys.argv.pop(1)
    unittest.main(verbosity=2)
