"""What the Python tests share: the CLI run as a subprocess, a scratch directory with a table on
a uniform grid, one on a grid of its own, simplified parameters, and a random displacement path."""
import os
import subprocess
import tempfile

import numpy as np

TABLE1 = ('{"model": "simplified-sma", "source": "Table 1", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95,'
          ' "C_N_per_degC": 5.7, "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25}\n')


class Cli:
    """`hystlab` in a directory: run() gives stdout or raises with stderr; error() gives the
    message the CLI prints after "hystlab: error: " (and checks that it failed with code 2)."""

    def __init__(self, exe, cwd):
        self.exe, self.cwd = exe, cwd

    def run(self, *args):
        r = subprocess.run([self.exe] + [str(a) for a in args], cwd=self.cwd, capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError("hystlab %s: %s" % (" ".join(map(str, args)), r.stderr))
        return r.stdout

    def error(self, *args):
        r = subprocess.run([self.exe] + [str(a) for a in args], cwd=self.cwd, capture_output=True, text=True)
        assert r.returncode == 2, (args, r.returncode, r.stderr)
        line = r.stderr.strip()
        assert line.startswith("hystlab: error: "), line
        return line[len("hystlab: error: "):]

    def eval_forces(self, *model_args, input="X.csv"):
        """hystlab eval's force column, as the doubles it printed (shortest text that reads back exactly)."""
        lines = self.run("eval", *model_args, "--input", input).strip().splitlines()
        assert lines[0] == "displacement_mm,force_N", lines[0]
        return np.array([float(line.split(",")[1]) for line in lines[1:]])


def random_path(rng, n, lo=0.0, hi=4.0):
    """A random walk with reversals of every size inside [lo, hi], starting at lo."""
    x = np.empty(n)
    x[0] = lo
    v = 0.0
    for k in range(1, n):
        v = 0.8 * v + rng.normal(0.0, 0.05)
        x[k] = min(hi, max(lo, x[k - 1] + v))
    return x


def write_csv(path, columns):
    """A data CSV with a header row; repr writes the shortest text that reads back exactly."""
    names = list(columns)
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*(columns[n] for n in names)):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


class Scratch:
    """T.json (n = 12 on 0..4), R.json (n = 10 refined around 2 mm: version 2), P.json (Table 1)
    and X.csv (2,000 random displacements), made by the CLI in a temporary directory."""

    def __init__(self, cli_exe, seed=15):
        self._tmp = tempfile.TemporaryDirectory()
        self.dir = self._tmp.name
        self.cli = Cli(cli_exe, self.dir)
        self.rng = np.random.default_rng(seed)
        self.x = random_path(self.rng, 2000)
        write_csv(self.path("X.csv"), {"displacement_mm": self.x})
        with open(self.path("P.json"), "w") as f:
            f.write(TABLE1)
        self.cli.run("identify", "--model", "simplified", "--params", "P.json", "--range", "0,4", "--subdivisions", 12, "-o", "T.json")
        self.cli.run("identify", "--model", "simplified", "--params", "P.json", "--range", "0,4", "--subdivisions", 10,
                     "--refine", "2,1", "-o", "R.json")

    def path(self, name):
        return os.path.join(self.dir, name)

    def read(self, name):
        with open(self.path(name)) as f:
            return f.read()

    def close(self):
        self._tmp.cleanup()
