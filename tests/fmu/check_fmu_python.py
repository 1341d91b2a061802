#!/usr/bin/env python3
"""The FMU through a second, independent importer: hystlab.fmu (ctypes, zipfile, ElementTree)
against the CLI and against the Python module, to the last digit; its state rolled back and
carried as bytes; its refusals. usage: check_fmu_python.py HYSTLAB_CLI"""
import os
import random
import subprocess
import sys
import tempfile

import numpy as np

import hystlab
import hystlab.fmu

cli = sys.argv[1]
failures = 0


def check(cond, what):
    global failures
    print(("ok   " if cond else "FAIL ") + what)
    failures += 0 if cond else 1


def run(args, cwd):
    return subprocess.run([cli] + args, cwd=cwd, check=True, capture_output=True, text=True).stdout


def cli_forces(d, model_args, x):
    with open(os.path.join(d, "X.csv"), "w") as f:
        f.write("displacement_mm\n" + "".join("%r\n" % v for v in x))
    out = run(["eval"] + model_args + ["--input", "X.csv"], d).strip().splitlines()
    return [float(line.split(",")[1]) for line in out[1:]]


def steps(fmu, xs, h=1e-3):
    """One step per input from where the instance stands; F after each."""
    out = []
    for v in xs:
        fmu.set(x=v)
        fmu.do_step(h)
        out.append(fmu.get("F"))
    return out


def random_path(seed, lo, hi, n):
    rng = random.Random(seed)
    x = [0.0]
    while len(x) < n:
        a, b = x[-1], rng.uniform(lo, hi)
        steps = 1 + int(abs(b - a) / 0.05)
        x += [a + (b - a) * k / steps for k in range(1, steps + 1)]
    return x[:n]


with tempfile.TemporaryDirectory() as d:
    run(["identify", "--model", "simplified", "--range", "0,4", "--subdivisions", "12", "-o", "T.json"], d)
    run(["identify", "--model", "simplified", "--range", "0,4", "--subdivisions", "12", "--refine", "2,1", "-o", "T2.json"], d)
    with open(os.path.join(d, "P.json"), "w") as f:
        f.write('{"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7,'
                ' "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25}')
    cases = [("T.json", ["--table", "T.json", "--clamp"], lambda p: hystlab.Table.load(p)),
             ("T2.json", ["--table", "T2.json", "--clamp"], lambda p: hystlab.Table.load(p)),
             ("P.json", ["--model", "simplified", "--params", "P.json"], lambda p: hystlab.Params.load(p))]
    for seed, (name, args, load) in enumerate(cases):
        flag = "--params" if name.startswith("P") else "--table"
        run(["export", flag, name, "--format", "fmu", "-o", name + ".fmu"], d)
        x = random_path(seed, -0.3, 4.3, 3000)
        want = cli_forces(d, args, x)
        with hystlab.fmu.Fmu(os.path.join(d, name + ".fmu")) as f:
            got = f.simulate(x)
            dyn = subprocess.run(["readelf", "-d", os.path.join(f._dir, "binaries", "linux64", f.identifier + ".so")],
                                 capture_output=True, text=True).stdout
            check("libstdc++" not in dyn and "[$ORIGIN]" in dyn,
                  "%s: the binary carries its C++ runtime (simulation tools load their own libstdc++) and runs from $ORIGIN" % name)
            check(f.model_name in ("hystlab_table", "hystlab_params") and f.identifier == "hystlab_element", "%s: the model description read" % name)
        module = hystlab.Model(load(os.path.join(d, name))).evaluate(np.array(x))
        check(len(got) == len(want) == len(x), "%s: %d forces" % (name, len(got)))
        check(sum(g == w for g, w in zip(got, want)) == len(x), "%s: the FMU through ctypes gives the CLI's forces to the last digit" % name)
        check(sum(g == m for g, m in zip(got, module.tolist())) == len(x), "%s: and the Python module's" % name)

    x = random_path(9, 0.0, 4.0, 1500)
    fmu_t = os.path.join(d, "T.json.fmu")
    with hystlab.fmu.Fmu(fmu_t) as f, hystlab.fmu.Fmu(fmu_t, "second") as g, hystlab.fmu.Fmu(os.path.join(d, "T2.json.fmu")) as other:
        f.simulate(x[:700])
        s = f.get_state()
        ahead = steps(f, x[700:])
        t_ahead = f.time
        f.set_state(s)
        check(f.time < t_ahead and f.time == s.time, "set_state takes the time back too (%.3f s)" % f.time)
        again = steps(f, x[700:])
        check(again == ahead, "a state set back gives the same outputs (%d steps)" % len(ahead))
        blob = f.serialize(s)
        g.simulate([0.0])
        g.set_state(g.deserialize(blob))
        moved = steps(g, x[700:])
        check(moved == ahead, "a serialized state (%d bytes) continues in another instance" % len(blob))
        other.simulate([0.0])
        try:
            other.deserialize(blob)
            check(False, "a state from another table is refused")
        except hystlab.fmu.FmuError as e:
            check("another FMU" in str(e), "a state from another table is refused: %s" % e)
        try:
            f.set(x=float("nan"))
            check(False, "NaN is refused")
        except hystlab.fmu.FmuError as e:
            check("not a finite number" in str(e), "a NaN input is refused: %s" % e)
    with open(os.path.join(d, "junk.fmu"), "w") as j:
        j.write("not a zip")
    try:
        hystlab.fmu.Fmu(os.path.join(d, "junk.fmu"))
        check(False, "a file that is no FMU is refused")
    except hystlab.fmu.FmuError as e:
        check("not a ZIP archive" in str(e), "a file that is no FMU is refused: %s" % e)

print("%d failure(s)" % failures if failures else "all checks passed")
sys.exit(1 if failures else 0)
