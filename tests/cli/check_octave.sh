#!/usr/bin/env bash
# The MATLAB/Octave export, run in Octave: hystlab_eval of the exported table on a path with
# reversals and wiping-out gives the CLI's forces (to rounding), and the parameters script loads.
# usage: check_octave.sh HYSTLAB_CLI OCTAVE_CLI
set -euo pipefail
cli=$1 octave=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
cd "$d"
"$cli" identify --model simplified --range 0,4 --subdivisions 12 -o T.json > /dev/null
"$cli" export --table T.json --format m -o table.m
python3 - <<'PY'
path = [0, 3.5, 1, 3, 1.5, 4, 2, 2.5, 0.5, 3.9, 2.2, 3.1, 0]
xs = []
for a, b in zip(path, path[1:]):
    xs += [a + (b - a) * k / 40 for k in range(40)]
open("X.csv", "w").write("displacement_mm\n" + "".join("%r\n" % x for x in xs))
open("x.txt", "w").write("".join("%r\n" % x for x in xs))
PY
"$cli" eval --table T.json --input X.csv | tail -n +2 | cut -d, -f2 > cli.txt
"$octave" --no-gui --quiet --norc --eval "source('table.m'); x = load('x.txt'); f = hystlab_eval(T, x); printf('%.17g\n', f);" > octave.txt 2> octave.err
python3 - <<'PY'
import sys
cli = [float(v) for v in open("cli.txt")]
octave = [float(v) for v in open("octave.txt")]
if len(cli) != len(octave) or not cli:
    sys.exit("FAIL: %d values from the CLI, %d from Octave" % (len(cli), len(octave)))
worst = max(abs(a - b) for a, b in zip(cli, octave))
scale = max(abs(v) for v in cli)
print("%d values; largest difference %.3g N (forces up to %.3g N)" % (len(cli), worst, scale))
sys.exit(0 if worst <= 1e-9 * scale else "FAIL: the exported script departs from the library")
PY
printf '{"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7, "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25}' > P.json
"$cli" export --params P.json --format m -o params.m
km=$("$octave" --no-gui --quiet --norc --eval "source('params.m'); printf('%.17g', P.KM * P.dtr_max);" 2> /dev/null)
[ "$km" = "442.5" ] && echo "ok: the parameters script loads (KM * dtr_max = $km)" || { echo "FAIL: params.m gave '$km'"; exit 1; }
