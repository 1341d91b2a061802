#!/usr/bin/env python3
"""Evaluate a table (or simplified-model parameters) on the displacement_mm column of a CSV,
through hystlab's C API, and print displacement_mm,force_N as `hystlab eval` does.

usage: evaluate_ctypes.py MODEL.json X.csv      (the library: $HYSTLAB_LIBRARY or the loader's path)
"""
import csv
import sys

from hystlab_ctypes import HystlabError, Model


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    with open(argv[2], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or "displacement_mm" not in rows[0]:
        print("evaluate_ctypes.py: %s has no displacement_mm column" % argv[2], file=sys.stderr)
        return 2
    x = [float(r["displacement_mm"]) for r in rows]
    try:
        with Model(argv[1]) as m:
            force = m.evaluate(x)
    except HystlabError as e:
        print("evaluate_ctypes.py: %s" % e, file=sys.stderr)
        return 2
    print("displacement_mm,force_N")
    for xi, fi in zip(x, force):
        print("%r,%r" % (xi, fi))  # repr: the shortest text that reads back to the same double
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
