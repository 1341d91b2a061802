#!/usr/bin/env python3
"""The C API from Python (ctypes over libhystlab.so, hystlab_ctypes.py beside this file) against
the CLI, to the last digit: a table identified by the CLI and the simplified model, on one
displacement path; and its errors.

usage: check_python.py HYSTLAB_CLI LIBHYSTLAB"""
import os
import subprocess
import sys
import tempfile

cli, lib = sys.argv[1:3]
here = os.path.dirname(os.path.abspath(__file__))
os.environ["HYSTLAB_LIBRARY"] = lib
sys.path.insert(0, here)
from hystlab_ctypes import HystlabError, Model  # noqa: E402

failures = 0


def check(cond, what):
    global failures
    print(("ok   " if cond else "FAIL ") + what)
    failures += 0 if cond else 1


def columns(text):
    lines = text.strip().splitlines()
    assert lines[0] == "displacement_mm,force_N", lines[0]
    return [tuple(float(v) for v in line.split(",")) for line in lines[1:]]


with tempfile.TemporaryDirectory() as d:
    path = [0, 3.5, 1, 3, 1.5, 4, 2, 2.5, 0.5, 3.9, 0]
    xs = []
    for a, b in zip(path, path[1:]):
        n = 40
        xs += [a + (b - a) * k / n for k in range(n)]
    with open(os.path.join(d, "X.csv"), "w") as f:
        f.write("displacement_mm\n" + "".join("%r\n" % x for x in xs))
    subprocess.run([cli, "identify", "--model", "simplified", "--range", "0,4", "--subdivisions", "12", "-o",
                    os.path.join(d, "T.json")], check=True, capture_output=True)
    with open(os.path.join(d, "P.json"), "w") as f:
        f.write('{"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7,'
                ' "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25}')
    for name, args in (("T.json", ["--table", "T.json"]), ("P.json", ["--model", "simplified", "--params", "P.json"])):
        want = columns(subprocess.run([cli, "eval"] + args + ["--input", "X.csv"], cwd=d, check=True,
                                      capture_output=True, text=True).stdout)
        got = columns(subprocess.run([sys.executable, os.path.join(here, "evaluate_ctypes.py"), name, "X.csv"], cwd=d,
                                     check=True, capture_output=True, text=True).stdout)
        check(len(got) == len(want) == len(xs), "%s: %d values" % (name, len(got)))
        same = sum(1 for g, w in zip(got, want) if g == w)  # exact: the same doubles
        check(same == len(want), "%s: the C API from Python matches the CLI to the last digit (%d of %d)" % (name, same, len(want)))

    with Model(os.path.join(d, "T.json")) as m:
        first = m.evaluate(xs[:100])
        branch = m.copy()
        a, b = m.evaluate(xs[100:200]), branch.evaluate(xs[100:200])
        check(a == b, "a copy continues from the same memory")
        m.reset()
        check(m.evaluate(xs[:100]) == first, "reset goes back to rest")
        m.step(9.0)
        check(m.saturations == 1, "an input outside the table's range is clamped and counted")
        branch.close()
    for what, make in (("missing file", lambda: Model(os.path.join(d, "nope.json"))),
                       ("bad version", lambda: Model(json_text='{"format": "hystlab-everett-table", "version": 7}')),
                       ("not JSON", lambda: Model(json_text="{oops"))):
        try:
            make()
            check(False, what + " is refused")
        except HystlabError as e:
            check(str(e).split(":")[0] in ("io", "format") and len(str(e)) > 10, "%s is refused: %s" % (what, e))
    with Model(os.path.join(d, "T.json")) as m:
        try:
            m.step(float("nan"))
            check(False, "NaN is refused")
        except HystlabError as e:
            check("finite" in str(e), "a NaN input is refused: %s" % e)

print("%d failure(s)" % failures if failures else "all checks passed")
sys.exit(1 if failures else 0)
