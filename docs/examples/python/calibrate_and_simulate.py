#!/usr/bin/env python3
"""hystlab from Python, as a notebook: calibrate the simplified SMA model on a loop, identify an
Everett table from it, simulate, check the accuracy, save and reload, branch a history, and
(optionally) fetch a table from a running hystlabd.

Run it whole (`python3 calibrate_and_simulate.py [--out DIR] [--daemon URL]`), or cell by cell in
an editor that knows `# %%` cells (VS Code, Spyder, Jupytext). It needs the hystlab package
(`cmake --install`, or PYTHONPATH=<build>/python) and numpy; the tests run it (python_example).
"""
# %% [markdown]
# ## Setup
# Debian's python3 finds an installed hystlab in /usr/local/lib/python3.11/dist-packages.
import argparse
import copy
import os
import tempfile

import numpy as np

import hystlab

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", help="where to write the files (default: a temporary directory)")
parser.add_argument("--daemon", help="a running hystlabd, e.g. http://127.0.0.1:8080")
parser.add_argument("--params", help="simplified-model parameters (docs/FORMATS.md); default: the paper's Table 1")
args = parser.parse_args()
out = args.out or tempfile.mkdtemp(prefix="hystlab-example-")
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(2026)

# %% [markdown]
# ## 1. A measured loop, and the simplified model calibrated on it
# A lab would load its record here (np.loadtxt on a CSV). We make one: the specimen behaves like
# Table 1 with a slightly stiffer austenite, and the load cell has 0.2 N of noise. One isothermal
# loop fixes KA, KM, dtr_max and the four transition forces; C and T come from the initial guess.
initial = hystlab.Params.load(args.params) if args.params else hystlab.Params()
specimen = hystlab.Params(KA=44.0, KM=initial.KM, dtr_max=initial.dtr_max, C=initial.C, Mf0=initial.Mf0,
                          Ms0=initial.Ms0, As0=initial.As0, Af0=initial.Af0, T=initial.T)
loop_x = np.concatenate([np.linspace(0.0, 4.5, 451), np.linspace(4.5, 0.0, 451)[1:]])
loop_f = hystlab.Model(specimen).evaluate(loop_x) + rng.normal(0.0, 0.2, loop_x.size)
params, fit = hystlab.calibrate(loop_x, loop_f, initial=initial, origin="example loop", details=True)
print("calibrated:", params)
print("  residual rms %.3f N after %d iterations" % (fit["rms_residual_N"], fit["iterations"]))
assert abs(params.KA - specimen.KA) < 1.0, params

# %% [markdown]
# The loop's material figures (as `hystlab loops` reports them): dissipated energy, damping,
# and the transformation points found by tangent intersection.
for k, cycle in enumerate(hystlab.loops(loop_x, loop_f, plateaus=[2.0]), 1):
    print("cycle %d: E_d %.1f N mm, zeta %.3f, plateau at 2 mm: %.1f / %.1f N" % (
        k, cycle["energy_Nmm"], cycle["damping_ratio"], cycle["plateaus"][0]["loading_N"], cycle["plateaus"][0]["unloading_N"]))

# %% [markdown]
# ## 2. An Everett table identified virtually from the calibrated model
# The FOT campaign run on the model (MODELS.md §3). The grid is refined around a 2 mm preload,
# where the spring will work: half of the 16 steps within 2 +- 0.75 mm (table format version 2).
table = hystlab.identify_virtual(params, range=(0.0, 4.0), subdivisions=16, refine=(2.0, 1.5))
print(table, "version", table.version)
print("nodes (mm):", np.round(table.nodes, 3))

# %% [markdown]
# ## 3. Simulate a random path, and compare the table with the model it came from
# Model.evaluate takes a numpy array and keeps the memory of the history between calls.
x = np.clip(np.cumsum(rng.normal(0.0, 0.05, 20_000)) + 2.0, 0.0, 4.0)
preisach = hystlab.Model(table)
simplified = hystlab.Model(params)
f_table = preisach.evaluate(x)
f_model = simplified.evaluate(x)
acc = hystlab.compare(x, f_model, f_table)
print("table vs simplified model on %d samples: rms %.3f N (%.2f %% of the range), max %.3f N" % (
    acc["overall"]["samples"], acc["overall"]["rms_N"], 100 * acc["overall"]["rms_norm"], acc["overall"]["max_N"]))
assert acc["overall"]["rms_norm"] < 0.05

# %% [markdown]
# ## 4. Save, reload: the same forces to the last digit
# Table.save writes the JSON `hystlab identify` writes; the CLI, the daemon, the C API and the FMU
# read it. Params.save likewise.
table.save(os.path.join(out, "table.json"))
params.save(os.path.join(out, "params.json"))
again = hystlab.Model(hystlab.Table.load(os.path.join(out, "table.json")))
assert np.array_equal(again.evaluate(x), f_table)
print("saved and reloaded", os.path.join(out, "table.json"))

# %% [markdown]
# ## 5. Branch a history
# Preload the spring to 2 mm through a few cycles, then ask "what if": a copy continues from the
# same memory, so one branch goes up to 3.5 mm and the other down to 0.5 mm. Model.state saves
# the memory as bytes to roll back to (it only restores into a model of the same table).
m = hystlab.Model(table)
m.evaluate([0.0, 3.0, 1.0, 2.5, 1.5, 2.0])
preload = m.state
up = m.copy()
down = copy.deepcopy(m)
f_up = up.evaluate(np.linspace(2.0, 3.5, 31))
f_down = down.evaluate(np.linspace(2.0, 0.5, 31))
print("from the preload of %.2f N: %.2f N at 3.5 mm, %.2f N at 0.5 mm" % (m.output, f_up[-1], f_down[-1]))
m.evaluate(np.linspace(2.0, 3.5, 31))
m.state = preload  # back to the preload
assert np.array_equal(m.evaluate(np.linspace(2.0, 0.5, 31)), f_down)

# %% [markdown]
# Errors are Python exceptions with the CLI's messages.
try:
    m.evaluate([1.0, float("nan")])
except ValueError as e:
    print("refused:", e)

# %% [markdown]
# ## 6. A running daemon (optional)
# hystlab.Client speaks hystlabd's HTTP API: campaigns, runs, samples as numpy arrays, tables.
if args.daemon:
    api = hystlab.Client(args.daemon)
    print("daemon:", api.status()["version"], "-", len(api.campaigns()), "campaign(s),", len(api.tables()), "table(s)")
    for info in api.tables()[-1:]:
        t = api.table(info["id"])
        print("table %d:" % info["id"], t, "force at 2 mm from rest: %.2f N" % hystlab.Model(t).evaluate([t.lo, 2.0])[-1])
print("done; files in", out)
