#!/usr/bin/env bash
# The MATLAB/Octave export, run in Octave: hystlab_eval of the exported table on a path with
# reversals and wiping-out gives the CLI's forces to the last digit, and the parameters script loads.
# usage: check_octave.sh HYSTLAB_CLI OCTAVE_CLI
set -euo pipefail
cli=$1 octave=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
cd "$d"
python3 - <<'PY'
path = [0, 3.5, 1, 3, 1.5, 4, 2, 2.5, 0.5, 3.9, 2.2, 3.1, 0]
xs = []
for a, b in zip(path, path[1:]):
    xs += [a + (b - a) * k / 40 for k in range(40)]
open("X.csv", "w").write("displacement_mm\n" + "".join("%r\n" % x for x in xs))
open("x.txt", "w").write("".join("%r\n" % x for x in xs))
PY
# A uniform table (format v1) and a grid of its own refined about 2 mm (format v2, T.nodes).
check_table() {
  "$cli" export --table "$1" --format m -o table.m
  "$cli" eval --table "$1" --input X.csv | tail -n +2 | cut -d, -f2 > cli.txt
  "$octave" --no-gui --quiet --norc --eval "source('table.m'); x = load('x.txt'); f = hystlab_eval(T, x); printf('%.17g\n', f);" > octave.txt 2> octave.err
  python3 - "$1" <<'PY'
import sys
cli = [float(v) for v in open("cli.txt")]
octave = [float(v) for v in open("octave.txt")]
if len(cli) != len(octave) or not cli:
    sys.exit("FAIL: %d values from the CLI, %d from Octave" % (len(cli), len(octave)))
worst = max(abs(a - b) for a, b in zip(cli, octave))
scale = max(abs(v) for v in cli)
print("%s: %d values; largest difference %.3g N (forces up to %.3g N)" % (sys.argv[1], len(cli), worst, scale))
sys.exit(0 if worst == 0 else "FAIL: the exported script departs from the library (it must agree to the last digit)")
PY
}
"$cli" identify --model simplified --range 0,4 --subdivisions 12 -o T.json > /dev/null
check_table T.json
"$cli" identify --model simplified --range 0,4 --subdivisions 12 --refine 2,1.2 -o R.json > /dev/null
grep -q '"version": 2' R.json || { echo "FAIL: the refined table is not format version 2"; exit 1; }
check_table R.json
printf '{"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7, "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25}' > P.json
"$cli" export --params P.json --format m -o params.m
km=$("$octave" --no-gui --quiet --norc --eval "source('params.m'); printf('%.17g', P.KM * P.dtr_max);" 2> /dev/null)
[ "$km" = "442.5" ] && echo "ok: the parameters script loads (KM * dtr_max = $km)" || { echo "FAIL: params.m gave '$km'"; exit 1; }
