#!/usr/bin/python3
"""Reads hystlab's HDF5 exports back with h5py (docs/FORMATS.md, "Runs as HDF5") and checks them
against the CLI: every sample equals the CSV export's (the same doubles), every table evaluates
to the CLI's forces on a random input to the last digit, both from its stored document and
rebuilt from its numeric datasets, and the campaign's records are those `campaign show` gives.

usage: check_h5.py HYSTLAB_CLI DB FILE.h5 ...   (Debian's /usr/bin/python3: h5py and numpy)
"""
import atexit
import json
import random
import subprocess
import sys
import tempfile
import os
import shutil

import h5py
import numpy as np

cli, db, files = sys.argv[1], sys.argv[2], sys.argv[3:]
work = tempfile.mkdtemp(prefix="hystlab-h5-check-")
atexit.register(shutil.rmtree, work, True)


def run(*args):
    r = subprocess.run([cli, *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("FAIL: hystlab %s: %s" % (" ".join(args), r.stderr.strip()))
    return r.stdout


def text(ds):
    return ds[()].decode("utf-8")


def attr(obj, name):
    v = obj.attrs[name]
    return v.decode("utf-8") if isinstance(v, bytes) else v


def check(cond, what):
    if not cond:
        sys.exit("FAIL: " + what)


def check_root(f, path):
    check(attr(f, "format") == "hystlab-run-h5", path + ": format")
    check(attr(f, "format_version") == 1, path + ": format_version")
    version = run("--version").split()[1]
    check(attr(f, "software_version") == version, path + ": software_version %r, the CLI says %r" % (attr(f, "software_version"), version))
    check(attr(f, "scope") in ("run", "campaign"), path + ": scope")


# The CSV's column names that differ from the datasets' (the CSV keeps the API's t_s).
CSV_TO_H5 = {"t_s": "time_s"}


def check_run(f, name, path):
    g = f["runs"][name]
    rid = int(g.attrs["id"])
    csv = run("runs", "export", str(rid), "--db", db).splitlines()
    header = csv[0].split(",")
    rows = [line.split(",") for line in csv[1:]]
    n = int(g.attrs["samples"])
    check(n == len(rows) and n > 0, "%s run %d: %d samples in the file, %d in the CSV" % (path, rid, n, len(rows)))
    check(header[:2] == ["seq", "t_s"] and header[-1] == "status", "%s run %d: the CSV's header %s (docs/FORMATS.md, \"Runs as CSV\")" % (path, rid, header))
    for k, col in enumerate(header):
        col = CSV_TO_H5.get(col, col)
        ds = g[col]
        check(ds.shape == (n,), "%s run %d: %s has shape %s" % (path, rid, col, ds.shape))
        check(ds.chunks is not None and ds.compression == "gzip" and ds.maxshape == (None,), "%s: %s is not chunked, deflated, extendable" % (path, col))
        if col in ("seq", "status"):  # integers
            check(ds.dtype == np.int64 and np.array_equal(ds[()], np.array([int(r[k]) for r in rows], dtype=np.int64)), "%s run %d: %s differs" % (path, rid, col))
            continue
        want = np.array([float(r[k]) for r in rows])  # the shortest form reads back to the same double
        got = ds[()]
        check(got.dtype == np.float64, "%s: %s is %s" % (path, col, got.dtype))
        check(np.array_equal(got.view(np.uint64), want.view(np.uint64)), "%s run %d: %s differs from the CSV" % (path, rid, col))
        unit = attr(ds, "units")
        check(unit and col.lower().endswith("_" + unit.replace("/", "_").replace("²", "2").lower()), "%s: %s has units %r" % (path, col, unit))
    check(attr(g["time_s"], "wall_anchor_unix") == attr(g, "wall_anchor_unix") > 1e9, path + ": the wall-clock anchor")
    check(np.all(np.diff(g["seq"][()]) > 0), path + ": seq increases")
    print("%s run %d: %d samples x %d columns equal the CSV export's" % (path, rid, n, len(header)))


def random_input(lo, hi, seed):
    rnd = random.Random(seed)
    xs, a = [], lo
    for _ in range(25):
        b = rnd.uniform(lo, hi)
        xs += [a + (b - a) * k / 37 for k in range(37)]
        a = b
    path = os.path.join(work, "X.csv")
    with open(path, "w") as out:
        out.write("displacement_mm\n" + "".join("%r\n" % x for x in xs))
    return path


def eval_table(doc_text, name, xcsv):
    path = os.path.join(work, name)
    with open(path, "w") as out:
        out.write(doc_text)
    return run("eval", "--table", path, "--input", xcsv)


def rebuilt_document(g):
    """The table from its numeric datasets alone (nodes_mm, everett_N, force_offset_N)."""
    nodes = [float(v) for v in g["nodes_mm"][()]]
    e = g["everett_N"][()]
    m = len(nodes)
    check(e.shape == (m, m) and all(np.isnan(e[i][j]) for i in range(m) for j in range(i + 1, m)), "everett_N is not lower-triangular with NaN above")
    return json.dumps({"format": "hystlab-everett-table", "version": 2, "units": {"displacement": "mm", "force": "N"},
                       "range_mm": [nodes[0], nodes[-1]], "subdivisions": m - 1, "nodes_mm": nodes,
                       "force_offset_N": float(g["force_offset_N"][()]),
                       "rows": [[float(e[i][j]) for j in range(i + 1)] for i in range(m)],
                       "provenance": json.loads(text(g["provenance"]))})


def check_tables(f, path):
    for name, g in f["tables"].items():
        tid = int(g.attrs["id"])
        stored = run("tables", "export", str(tid), "--db", db)
        lo, hi = (float(v) for v in g.attrs["range_mm"])
        xcsv = random_input(lo, hi, tid)
        want = eval_table(stored, "cli.json", xcsv)
        check(eval_table(text(g["document"]), "doc.json", xcsv) == want, "%s table %d: the stored document evaluates differently" % (path, tid))
        check(eval_table(rebuilt_document(g), "num.json", xcsv) == want, "%s table %d: the numeric datasets evaluate differently" % (path, tid))
        json.loads(text(g["accuracy"]))
        print("%s table %d: %d forces from the document and from the numbers equal the CLI's, to the last digit" % (path, tid, len(want.splitlines()) - 1))


def check_campaign(f, path):
    cid = int(f.attrs["campaign"])
    shown = json.loads(run("campaign", "show", str(cid), "--json", "--db", db))
    c = f["campaign"]
    check(json.loads(text(c["plan"])) == shown["plan"], path + ": plan")
    check(attr(c, "kind") == shown["kind"] and attr(c, "state") == shown["state"], path + ": kind, state")
    json.loads(text(c["rig_config"])), json.loads(text(c["limits"]))
    # The envelope in force: the one hystlabd recorded when it handed the campaign to its rig.
    envelope = json.loads(text(c["envelope"]))
    recorded = [e["detail"] for e in shown["events"] if e["kind"] == "envelope"]
    check(recorded and envelope == json.loads(recorded[-1]) and ("stroke_mm" in envelope or "displacement_mm" in envelope),
          path + ": envelope %r, the campaign recorded %s" % (envelope, recorded[-1] if recorded else "none"))
    # What the lab recorded with it, as `campaign show` says.
    check(attr(c, "specimen") == (shown.get("specimen") or "") and attr(c, "notes") == (shown.get("notes") or ""),
          path + ": specimen %r and notes as the campaign's" % attr(c, "specimen"))
    ev = f["events"]
    kinds = [v.decode() for v in ev["kind"][()]]
    check(kinds == [e["kind"] for e in shown["events"]], path + ": events")
    check([v.decode() for v in ev["detail"][()]] == [e["detail"] for e in shown["events"]], path + ": event details")
    nodes = sum(r["nodes"] for r in shown["runs"])
    check(f["fot_nodes"]["alpha_mm"].shape == (nodes,), path + ": %d FOT nodes, the campaign has %d" % (f["fot_nodes"]["alpha_mm"].shape[0], nodes))
    check(sorted(int(g.attrs["id"]) for g in f["tables"].values()) == sorted(t["id"] for t in shown["tables"]), path + ": tables")
    runs = sorted(int(g.attrs["id"]) for g in f["runs"].values())
    if attr(f, "scope") == "campaign":
        check(runs == sorted(r["id"] for r in shown["runs"] if r["samples"] > 0), path + ": the campaign's runs")
    else:
        check(len(runs) == 1, path + ": one run")
    print("%s: plan, %d events, %d FOT nodes, %d tables, runs %s as `campaign show` says" % (path, len(kinds), nodes, len(shown["tables"]), runs))


for path in files:
    with h5py.File(path, "r") as f:
        check_root(f, path)
        check_campaign(f, path)
        for name in f["runs"]:
            check_run(f, name, path)
        check_tables(f, path)
print("ok")
