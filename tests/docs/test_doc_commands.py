#!/usr/bin/env python3
"""Every command the docs give, run exactly as written against hystlabd on its embedded defaults.

The commands are read from the docs themselves: every indented line of README.md and docs/*.md
that starts with `curl `, `build/` or `mbpoll ` (a `\\` continues it on the next line). Each must be listed
below with what its output must show, or as not run with the reason: a command added to the
docs without a check here fails this test, so the docs cannot drift from what works.

They run in a folder of their own (docs/ and build/ linked into it, so relative paths work as
from the repository's root, and nothing outside it is needed: the paper's Table 1 is
docs/examples/table1-params.json), with `H` the daemon's address (docs/API.md: "The examples use
H=http://127.0.0.1:8080"; the daemon here takes a free port) and HYSTLAB_DAEMON set to it for
the CLI. The daemon is `build/daemon/hystlabd --port 0`: the embedded defaults of README's first
command, a simulated load frame (time scale 10) and a simulated shaker.

usage: test_doc_commands.py REPO BUILD_DIR
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request

REPO, BUILD = sys.argv[1], sys.argv[2]
FRAME = "simulated%20load%20frame"


def doc_commands():
    """(file, command) for every runnable command line of the docs, continuations joined."""
    out = []
    files = ["README.md"] + sorted("docs/" + f for f in os.listdir(os.path.join(REPO, "docs")) if f.endswith(".md"))
    for name in files:
        lines = open(os.path.join(REPO, name), encoding="utf-8").read().split("\n")
        k = 0
        while k < len(lines):
            line = lines[k]
            if re.match(r"^    (curl |build/|mbpoll )", line):
                cmd = line[4:]
                while cmd.rstrip().endswith("\\") and k + 1 < len(lines):
                    k += 1
                    cmd = cmd.rstrip()[:-1].rstrip() + " " + lines[k].strip()
                out.append((name, re.sub(r"\s+#.*$", "", cmd).strip()))
            k += 1
    return out


def as_json(text):
    try:
        return json.loads(text)
    except ValueError:
        raise AssertionError("not JSON: " + text[:300])


def api(h, path, method="GET", body=None):
    req = urllib.request.Request(h + path, method=method, data=body, headers={"Content-Type": "application/json"} if body else {})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return json.loads(r.read() or b"null")
    except urllib.error.HTTPError as e:
        return json.loads(e.read() or b"null")


def wait(what, pred, seconds):
    end = time.time() + seconds
    while time.time() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.2)
    raise AssertionError("timed out waiting for " + what)


# The checks, by command as the docs write it, in the order a user would take them: the rig's
# commands, a campaign (paused, resumed), a second one from the CLI (aborted here, to save its
# minute), then what a finished campaign offers. Each gets (return code, stdout, the run's folder).
def ok_json(pred, why):
    def check(rc, out, cwd):
        assert rc == 0, "exit status %d" % rc
        j = as_json(out)
        assert pred(j), why + ": " + out[:400]
    return check


def file_check(name, pred, why):
    def check(rc, out, cwd):
        assert rc == 0, "exit status %d" % rc
        p = os.path.join(cwd, name)
        assert os.path.exists(p), name + " was not written"
        data = open(p, "rb").read()
        assert pred(data), why
    return check


def cli_ok(needle):
    def check(rc, out, cwd):
        assert rc == 0, "exit status %d: %s" % (rc, out[:300])
        assert needle in out, "expected %r in: %s" % (needle, out[:400])
    return check


CHECKS = {
    "curl -s $H/api/status": ok_json(lambda j: len(j["rigs"]) == 2, "two rigs"),
    "curl -s $H/api/plans/form": ok_json(lambda j: any(f["path"] == "dwell_s" and f["max"] == 3600 for f in j["fields"]), "the plan's fields, dwell_s up to 3600 s"),
    "curl -s $H/api/rigs": ok_json(lambda j: [r["kind"] for r in j] == ["load_frame", "shaker"], "a load frame and a shaker"),
    'curl -s -X POST -d \'\' "$H/api/rigs/%s/estop"' % FRAME: ok_json(lambda j: j["result"] == "done" and j["latched"] and j["confirmed"], "latched and confirmed"),
    'curl -s -X POST -d \'\' "$H/api/rigs/%s/reset"' % FRAME: ok_json(lambda j: j["result"] == "done" and not j["latched"], "reset: not latched"),
    'curl -s -X POST -d \'\' "$H/api/rigs/%s/recover"' % FRAME: ok_json(
        lambda j: j["result"] == "conflict" and "nothing to recover" in j["reason"], "409: a frame within its stroke has nothing to recover"),
    "curl -s -X POST $H/api/campaigns -H 'Content-Type: application/json' -d \"{\\\"plan\\\": $(cat docs/examples/fot_n12.json)}\"": ok_json(
        lambda j: j["id"] == 1 and j["rig"] == "simulated load frame", "campaign 1, on the load frame without naming it"),
    "curl -s -X POST $H/api/campaigns/1/pause": ok_json(lambda j: j["accepted"], "the pause accepted"),
    "build/daemon/hystlab campaign submit --plan docs/examples/fot_n12.json": cli_ok("queued"),
    "curl -s $H/api/campaigns": ok_json(lambda j: [c["id"] for c in j][-2:] in ([1, 2], [2, 1]), "both campaigns listed"),
    "curl -s $H/api/campaigns/1": ok_json(lambda j: j["id"] == 1 and j["state"] == "completed" and len(j["tables"]) >= 2, "completed, with tables"),
    "curl -s $H/api/campaigns/1/nodes": ok_json(lambda j: len(j["nodes"]) >= 78, "the 78 nodes of n = 12"),
    'curl -s "$H/api/runs/1/loop?points=2000"': ok_json(lambda j: 0 < len(j["x"]) <= 2000 and len(j["model"]["force_N"]) == len(j["x"]), "at most 2000 points, the model over them"),
    'curl -s "$H/api/runs/1/samples?points=500"': ok_json(lambda j: 0 < len(j["displacement_max_mm"]) <= 500, "at most 500 buckets"),
    "curl -s -o run1.csv $H/api/runs/1/samples.csv": file_check("run1.csv", lambda d: d.count(b"\n") > 1000 and b"displacement" in d.split(b"\n")[0], "a CSV of the run"),
    "curl -s -o run1.h5 $H/api/runs/1/samples.h5": file_check("run1.h5", lambda d: d[:8] == b"\x89HDF\r\n\x1a\n", "an HDF5 file"),
    'curl -s "$H/api/tables/2/score?run=2"': ok_json(lambda j: 0 < j["overall"]["rms_N"] < 20, "a score on the validation run"),
    'curl -s -OJ "$H/api/tables/1/export?format=m"': lambda rc, out, cwd: (
        assert_(rc == 0, "exit status %d" % rc), assert_(any(f.endswith(".m") for f in os.listdir(cwd)), "no .m file written")),
    "curl -s -X POST $H/api/evaluate -H 'Content-Type: application/json' -d '{\"table_id\": 1, \"displacement_mm\": [0, 1, 2, 3, 2, 1, 2]}'": ok_json(
        lambda j: len(j["force_N"]) == 7 and j["force_N"][3] > j["force_N"][1], "seven forces, rising with the input"),
    'curl -sN "$H/api/stream?rate=5"': lambda rc, out, cwd: assert_("event: hello" in out and "event: samples" in out, "hello and samples: " + out[:300]),
    "curl -s $H/metrics": lambda rc, out, cwd: assert_(rc == 0 and "hystlab_rig_latched" in out, "the rig gauges: " + out[:300]),
    "curl -s -o report1.html $H/api/campaigns/1/report.html": file_check(
        "report1.html", lambda d: b"<h2>Identification</h2>" in d and b"Recommended: table #" in d and d.count(b"<svg") >= 2, "the report's sections and figures"),
    "build/daemon/hystlab report 1 -o report1.pdf": lambda rc, out, cwd: pdf_pages(rc, out, cwd, "report1.pdf"),
    # README's models from the command line, with the reader's own files (my_path.csv,
    # measured.csv) put where theirs would be.
    "build/daemon/hystlab identify --model simplified --params docs/examples/table1-params.json --range 0,4 --subdivisions 12 -o T12.json":
        file_check("T12.json", lambda d: json.loads(d)["subdivisions"] == 12 and len(json.loads(d)["rows"]) > 0, "a table of n = 12"),
    "build/daemon/hystlab eval --table T12.json --input my_path.csv -o predicted.csv":
        file_check("predicted.csv", lambda d: d.count(b"\n") >= 200 and b"force_N" in d.split(b"\n")[0], "a force per input row"),
    "build/daemon/hystlab compare --table T12.json --data measured.csv": lambda rc, out, cwd: assert_(
        rc == 0 and re.search(r"^overall +253 +(\d+\.\d+)", out, re.M) and float(re.search(r"^overall +253 +(\d+\.\d+)", out, re.M)[1]) < 5,
        "the table against the model it was identified from, within 5 N RMS: " + out[:400]),
    "build/daemon/hystlab design --table T12.json --budget-s 300": lambda rc, out, cwd: assert_(
        rc == 0 and "row 1: up to " in out and re.search(r"^\d+ rows, [\d.e+]+ s of rig time; stopped: ", out, re.M),
        "rows within the budget and why it stopped: " + out[:400]),
    # README's simulated frame polled with any Modbus client.
    "build/drivers/sim/hystlab-sim --port 1502 --time-scale 1 &": lambda rc, out, cwd: assert_(rc == 0, "exit status %d" % rc),
    "mbpoll -m tcp -0 -1 -t 3 -r 0 -c 12 -p 1502 127.0.0.1": lambda rc, out, cwd: assert_(rc == 0 and "[11]:" in out, "twelve registers: " + out[:300]),
}
NOT_RUN = {
    "build/daemon/hystlabd": "the daemon this test runs itself, on a free port (--port 0) instead of 8080",
    "build/daemon/hystlabd --config hystlab.json": "the reader's own config file; docs/examples/hystlab.json is parsed by tests/daemon/test_daemon.cpp",
}


def pdf_pages(rc, out, cwd, name):
    """A PDF that Chromium printed, turned into PNG pages (pdftoppm, when installed) kept in the
    build tree to be looked at: BUILD/tests/doc_commands/NAME-N.png."""
    assert_(rc == 0, "exit status %d: %s" % (rc, out[:300]))
    data = open(os.path.join(cwd, name), "rb").read()
    assert_(data[:5] == b"%PDF-" and len(data) > 20000, "not a PDF of a report (%d bytes)" % len(data))
    if shutil.which("pdftoppm"):
        keep = os.path.join(BUILD, "tests", "doc_commands")
        os.makedirs(keep, exist_ok=True)
        subprocess.run(["pdftoppm", "-png", "-r", "60", os.path.join(cwd, name), os.path.join(keep, name[:-4])], check=True)
        pages = [f for f in os.listdir(keep) if f.startswith(name[:-4]) and f.endswith(".png")]
        assert_(len(pages) >= 2, "the report printed on %d page(s)" % len(pages))


def assert_(cond, why):
    if not cond:
        raise AssertionError(why)


BACKGROUND = []  # process groups a documented `... &` left running, stopped at the end


def run(cmd, cwd, env, timeout=60):
    """Runs cmd as the docs write it, in bash; its output goes to a file (a background child may
    hold it open). An event stream never ends by itself: 2.5 s of it are read."""
    stream = "-sN" in cmd
    out_path = os.path.join(cwd, ".out")
    with open(out_path, "wb") as f:
        p = subprocess.Popen(["bash", "-c", cmd], cwd=cwd, env=env, stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
        if cmd.rstrip().endswith("&"):
            BACKGROUND.append(p.pid)
        try:
            p.wait(timeout=2.5 if stream else timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait()
            if not stream:
                raise AssertionError("did not finish within %d s" % timeout)
    return p.returncode, open(out_path, "rb").read().decode("utf-8", "replace")


def main():
    docs = doc_commands()
    unknown = [(f, c) for f, c in docs if c not in CHECKS and c not in NOT_RUN]
    for f, c in unknown:
        print("FAIL %s: a documented command with no check in tests/docs/test_doc_commands.py: %s" % (f, c))
    documented = {c for _, c in docs}
    stale = [c for c in CHECKS if c not in documented]
    for c in stale:
        print("FAIL a checked command that the docs no longer give: " + c)
    cwd = tempfile.mkdtemp(prefix="hystlab-docs-")  # the reader's clone, standing alone: nothing beside it is read
    os.symlink(os.path.join(REPO, "docs"), os.path.join(cwd, "docs"))
    os.symlink(BUILD, os.path.join(cwd, "build"))
    readers_files(cwd)
    log = open(os.path.join(cwd, "daemon.log"), "wb")
    daemon = subprocess.Popen(["build/daemon/hystlabd", "--port", "0"], cwd=cwd, stdout=log, stderr=subprocess.STDOUT)
    failures = len(unknown) + len(stale)
    try:
        port = wait("the daemon to serve", lambda: (re.search(r"serving the API and the page on http://127\.0\.0\.1:(\d+)/",
                                                                open(os.path.join(cwd, "daemon.log"), errors="replace").read()) or [None, None])[1], 30)
        h = "http://127.0.0.1:" + port
        env = dict(os.environ, H=h, HYSTLAB_DAEMON=h)
        wait("the rigs to be idle", lambda: all(r.get("state") == "idle" for r in api(h, "/api/rigs")), 30)
        for cmd in CHECKS:  # in the order a user would take them (the dict's)
            before(cmd, h)
            t0 = time.time()
            rc, out = run(cmd, cwd, env)
            try:
                CHECKS[cmd](rc, out, cwd)
                print("ok   %5.2f s  %s" % (time.time() - t0, cmd))
            except (AssertionError, KeyError, TypeError, IndexError) as e:  # a missing field is a failure too
                failures += 1
                print("FAIL %s\n     %s: %s\n     output: %s" % (cmd, type(e).__name__, e, out[:300]))
        for cmd, why in NOT_RUN.items():
            print("not run: %s (%s)" % (cmd, why))
    finally:
        for pgid in BACKGROUND:
            try:
                os.killpg(pgid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        daemon.send_signal(signal.SIGTERM)
        try:
            daemon.wait(timeout=30)
        except subprocess.TimeoutExpired:
            daemon.kill()
        if failures:
            print(open(os.path.join(cwd, "daemon.log"), errors="replace").read()[-4000:])
        shutil.rmtree(cwd, ignore_errors=True)
    print("%d documented commands, %d checked, %d failed" % (len(documented), len(CHECKS), failures))
    return 1 if failures else 0


def readers_files(cwd):
    """A displacement path (a 0-4 mm loop and a rise to 2 mm) and a 'measured' loop over it, as a
    reader's own CSV files (docs/FORMATS.md)."""
    xs = [4 * k / 100 for k in range(101)] + [4 - 4 * k / 100 for k in range(101)] + [2 * k / 50 for k in range(51)]
    with open(os.path.join(cwd, "my_path.csv"), "w") as f:
        f.write("displacement_mm\n" + "".join("%.4f\n" % x for x in xs))
    # The 'measurement': the simplified model (Table 1) along that path, as a rig would give it.
    subprocess.run(["build/daemon/hystlab", "eval", "--model", "simplified", "--params", "docs/examples/table1-params.json",
                    "--input", "my_path.csv", "-o", "measured.csv"], cwd=cwd, check=True, stdout=subprocess.DEVNULL)


def port_open(port):
    import socket
    with socket.socket() as s:
        return s.connect_ex(("127.0.0.1", port)) == 0


def before(cmd, h):
    """What the user would do between the documented commands (through the API, not a doc line)."""
    if "/campaigns/1/pause" in cmd:
        wait("campaign 1 to run", lambda: api(h, "/api/campaigns/1").get("state") == "running", 60)
    if "campaign submit" in cmd:
        wait("campaign 1 to be paused", lambda: api(h, "/api/campaigns/1").get("state") == "paused", 30)
        api(h, "/api/campaigns/1/resume", "POST")
    if cmd == "curl -s $H/api/campaigns":
        api(h, "/api/campaigns/2/abort", "POST")
    if cmd.startswith("mbpoll "):
        wait("hystlab-sim on port 1502", lambda: port_open(1502), 20)
    if cmd == "curl -s $H/api/campaigns/1":
        wait("campaign 1 to complete", lambda: api(h, "/api/campaigns/1").get("final"), 600)


if __name__ == "__main__":
    sys.exit(main())
