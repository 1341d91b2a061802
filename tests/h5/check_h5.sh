#!/usr/bin/env bash
# Runs as HDF5, end to end: two short FOT campaigns on hystlabd's simulated load frame (a uniform
# grid, and a grid of its own: table formats 1 and 2), exported by the CLI (a run, a campaign) and
# over HTTP, read back by h5dump (layout, compression, units), by Debian's h5py (every sample equals
# the CSV export's, every table evaluates to the CLI's forces to the last digit: check_h5.py) and
# by Octave's load when given; then the refusals: no such run, a run without samples, an
# unwritable path, HDF5 to stdout, an unknown format — one line each, exit 2, no file left behind.
# usage: check_h5.sh HYSTLABD HYSTLAB_CLI [OCTAVE_CLI]
set -euo pipefail
hystlabd=$1 cli=$2 octave=${3:-}
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3  # Debian's, with h5py and numpy (the python3 on PATH may be another)
d=$(mktemp -d)
pid=
cleanup() {
  if [ -n "$pid" ]; then kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; fi
  rm -rf "$d"
}
trap cleanup EXIT
cd "$d"
mkdir tmp
fail() { echo "FAIL: $*"; [ -f d.log ] && tail -n 20 d.log; exit 1; }

echo '{"rigs": [{"name": "sim frame", "simulate": {"time_scale": 10, "noise_N": 0.05}}]}' > cfg.json
echo '{"kind": "fot", "range_mm": [0, 2], "subdivisions": 4, "ramp_rate_mm_s": 1, "sample_rate_hz": 500, "validation": {"reversals": 6, "seed": 3}, "specimen": "NiTi S-h5", "notes": "two lines\nof notes"}' > uniform.json
echo '{"kind": "fot", "nodes_mm": [0, 0.3, 0.8, 1.1, 2], "ramp_rate_mm_s": 1, "sample_rate_hz": 500, "validation": false}' > refined.json
# The HTTP export writes its temporary file beside the database (h.db here); nothing may be left
# there, nor in TMPDIR, after any request.
TMPDIR="$d/tmp" "$hystlabd" --config cfg.json --db h.db --port 0 > d.log 2>&1 &
pid=$!
port=
for _ in $(seq 600); do
  port=$(grep -o 'page on http://127.0.0.1:[0-9]*' d.log | cut -d: -f3 || true)
  [ -n "$port" ] && break
  sleep 0.1
done
[ -n "$port" ] || fail "hystlabd did not start"
api=http://127.0.0.1:$port
"$cli" campaign submit --plan uniform.json --daemon "$api"
"$cli" campaign submit --plan refined.json --daemon "$api"
for _ in $(seq 1200); do
  [ "$("$cli" campaign list --db h.db | grep -c completed)" = 2 ] && break
  if "$cli" campaign list --db h.db | grep -Eq 'aborted|failed'; then fail "a campaign ended early: $("$cli" campaign list --db h.db)"; fi
  sleep 0.5
done
[ "$("$cli" campaign list --db h.db | grep -c completed)" = 2 ] || fail "the campaigns did not complete: $("$cli" campaign list --db h.db)"
"$cli" campaign show 1 --db h.db | head -4

# The exports: a run and a campaign by the CLI, the same over HTTP.
"$cli" tables export 3 --db h.db | grep -q '"version": 2' || fail "campaign 2's table is not format version 2 (a grid of its own)"
"$cli" runs export 1 --format h5 -o run1.h5 --db h.db
"$cli" runs export --campaign 1 --format h5 -o campaign1.h5 --db h.db
"$cli" runs export --campaign 2 --format h5 -o campaign2.h5 --db h.db
code=$(curl -s -o http1.h5 -w '%{http_code}' "$api/api/runs/1/samples.h5")
[ "$code" = 200 ] || fail "GET /api/runs/1/samples.h5: HTTP $code"
code=$(curl -s -o httpc2.h5 -w '%{http_code}' "$api/api/campaigns/2/samples.h5")
[ "$code" = 200 ] || fail "GET /api/campaigns/2/samples.h5: HTTP $code"
# A client that goes away after the first bytes: nothing is left in the temporary folder.
curl -s "$api/api/campaigns/1/samples.h5" | head -c 100 > /dev/null || true
code=$(curl -s -o nf.json -w '%{http_code}' "$api/api/runs/99/samples.h5")
[ "$code" = 404 ] && grep -q 'no run 99' nf.json || fail "an unknown run over HTTP: HTTP $code $(cat nf.json)"

# h5dump: the layout, the units, the compression.
h5dump -A -a /format run1.h5 | grep -q '"hystlab-run-h5"' || fail "h5dump: no format attribute"
h5dump -a /runs/run_1/force_N/units run1.h5 | grep -q '"N"' || fail "h5dump: force_N has no units N"
h5dump -a /runs/run_1/time_s/units run1.h5 | grep -q '"s"' || fail "h5dump: time_s has no units s"
h5dump -H -p -d /runs/run_1/displacement_mm run1.h5 > dump.txt
for want in CHUNKED 'COMPRESSION DEFLATE' SHUFFLE 'H5S_UNLIMITED'; do grep -q "$want" dump.txt || fail "h5dump: displacement_mm is not $want"; done
h5dump -H campaign1.h5 > layout.txt
for want in 'GROUP "campaign"' 'DATASET "plan"' 'GROUP "events"' 'GROUP "fot_nodes"' 'GROUP "table_1"' 'DATASET "everett_N"' 'GROUP "run_2"'; do
  grep -q "$want" layout.txt || fail "h5dump: no $want in the campaign's file"
done
echo "h5dump: layout, units and compression as documented"

# A shaker's run has its own signals: a sine campaign's run of 3,000 samples, stored beside the
# daemon's (the test's own SQL; a real sweep takes minutes of real time), with the envelope it ran
# under recorded as an event (the envelope in force, which the export carries: /campaign/envelope).
"$py" - <<'PY'
import math, sqlite3
c = sqlite3.connect("h.db")
cid = c.execute("""INSERT INTO campaigns(rig_id, kind, plan, state, created_at, updated_at)
                   VALUES(1, 'sine', '{"kind": "sine", "frequencies_hz": [12]}', 'completed', 't', 't')""").lastrowid
rid = c.execute("INSERT INTO runs(campaign_id, started_at, wall_anchor_unix, monotonic_anchor_s, state) VALUES(?, 't', 1.8e9, 0, 'completed')", (cid,)).lastrowid
c.executemany("INSERT INTO shaker_samples VALUES(?,?,?,?,?,?,?,?,?,?)",
              [(rid, k, k / 1000, 12.0, 0.5, 0.5 * math.sin(0.0754 * k), 1.3 * math.sin(0.0754 * k - 0.4), -2.8 * math.sin(0.0754 * k),
                -7.4 * math.sin(0.0754 * k - 0.4), k % 3) for k in range(3000)])
c.execute("INSERT INTO events(campaign_id, at, kind, detail) VALUES(?, 't', 'envelope', ?)",
          (cid, '{"accel_g":10.0,"displacement_mm":4.5,"frequency_hz":[1.0,200.0],"velocity_mm_s":300.0}'))
c.commit()
open("shaker_run", "w").write(str(rid))
PY
"$cli" runs export "$(cat shaker_run)" --format h5 -o shaker.h5 --db h.db
h5dump -a "/runs/run_$(cat shaker_run)/base_accel_m_s2/units" shaker.h5 | grep -q 'm/s' || fail "h5dump: base_accel_m_s2 has no units m/s²"

# h5py: every sample, every table, every record.
"$py" "$here/check_h5.py" "$cli" h.db run1.h5 campaign1.h5 campaign2.h5 http1.h5 httpc2.h5 shaker.h5
"$py" -c 'import h5py, json, sys; e = json.loads(h5py.File("shaker.h5")["campaign/envelope"][()].decode()); sys.exit(0 if e and e["displacement_mm"] == 4.5 else "the envelope: %r" % (e,))' \
  || fail "shaker.h5: /campaign/envelope is not the envelope the campaign recorded"
# One CSV layout (docs/FORMATS.md, "Runs as CSV"): the CLI's and the API's bytes are the same.
for run in 1 "$(cat shaker_run)"; do
  "$cli" runs export "$run" --db h.db > cli.csv
  curl -s -o api.csv "$api/api/runs/$run/samples.csv"
  cmp -s cli.csv api.csv || fail "run $run: the CLI's CSV and GET /api/runs/$run/samples.csv differ: $(head -1 cli.csv) / $(head -1 api.csv)"
done
echo "csv: the CLI's and the API's are the same bytes (a load frame's run and a shaker's)"

# Octave 7's load reads the datasets (not the attributes): the forces are the CSV's.
if [ -n "$octave" ]; then
  "$cli" runs export 1 --db h.db | tail -n +2 | cut -d, -f5 > csv_force.txt  # seq,t_s,command_mm,displacement_mm,force_N,status
  "$octave" --no-gui --quiet --norc --eval "x = load('run1.h5'); printf('%.17g\n', x.runs.run_1.force_N); t = x.tables.table_1; E = t.everett_N'; if ~isnan(E(1,2)) || E(2,1) == 0, exit(1); end" > octave_force.txt 2> octave.err \
    || fail "octave could not load run1.h5: $(head -5 octave.err)"
  "$py" - <<'PY' || fail "Octave's forces differ from the CSV's"
import sys
a = [float(v) for v in open("csv_force.txt")]
b = [float(v) for v in open("octave_force.txt")]
sys.exit(0 if a == b and a else "%d CSV values, %d from Octave" % (len(a), len(b)))
PY
  echo "octave: load gives the run's $(wc -l < csv_force.txt) forces exactly, and the table lower-triangular"
fi

# Refusals: one line naming the problem, exit 2, no file (and no .tmp) left.
refused() {  # refused EXPECTED_TEXT ARGS...
  local want=$1
  shift
  set +e
  "$cli" "$@" > out.txt 2> err.txt
  local rc=$?
  set -e
  [ "$rc" = 2 ] || fail "hystlab $*: exit $rc, expected 2"
  [ "$(wc -l < err.txt)" = 1 ] && grep -qF -- "$want" err.txt || fail "hystlab $*: said '$(cat err.txt)', expected '$want'"
}
refused "no samples for run 99: there is no run 99" runs export 99 --format h5 -o bad.h5 --db h.db
refused "no campaign 9" runs export --campaign 9 --format h5 -o bad.h5 --db h.db
refused "--format: 'h6' is not csv or h5" runs export 1 --format h6 -o bad.h5 --db h.db
refused "-o: HDF5 is a binary file" runs export 1 --format h5 --db h.db
refused "-o: cannot write '$d/no/such/dir/bad.h5'" runs export 1 --format h5 -o "$d/no/such/dir/bad.h5" --db h.db
refused "--campaign: a whole campaign is exported as HDF5 only" runs export --campaign 1 -o bad.csv --db h.db
# A run that took no sample (a row added beside the daemon's: the test's own SQL).
"$py" -c "import sqlite3; c = sqlite3.connect('h.db'); c.execute(\"INSERT INTO runs(campaign_id, started_at, wall_anchor_unix, monotonic_anchor_s, state) VALUES(2, 't', 0, 0, 'aborted')\"); c.commit()"
empty=$("$py" -c "import sqlite3; print(sqlite3.connect('h.db').execute('SELECT max(id) FROM runs').fetchone()[0])")
refused "no samples for run $empty" runs export "$empty" --format h5 -o bad.h5 --db h.db
refused "no samples for run $empty" runs export "$empty" -o bad.csv --db h.db
code=$(curl -s -o nf.json -w '%{http_code}' "$api/api/runs/$empty/samples.h5")
[ "$code" = 404 ] && grep -q "no samples for run $empty" nf.json || fail "a run without samples over HTTP: HTTP $code $(cat nf.json)"
ls bad.* bad.*.tmp 2>/dev/null && fail "a refused export left a file behind"
[ -z "$(ls tmp)" ] || fail "the HTTP export left $(ls tmp) in the temporary folder"
[ -z "$(ls hystlab-export-* 2>/dev/null)" ] || fail "the HTTP export left $(ls hystlab-export-*) beside the database"
kill -0 "$pid" || fail "hystlabd died"
echo "refusals: one line each, no file left behind; ok"
# The daemon stops cleanly, and (in the sanitized tree) said nothing of its memory.
kill "$pid"
wait "$pid" || fail "hystlabd exited $? on SIGTERM"
pid=
if grep -Eq 'AddressSanitizer|LeakSanitizer|runtime error' d.log; then fail "the sanitizers reported on hystlabd"; fi
echo ok
