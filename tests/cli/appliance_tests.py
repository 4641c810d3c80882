#!/usr/bin/env python3
"""`marionette run` as a service (issue 17, docs/deploy.md): recording rotation
under its caps, a full disk while recording, the systemd watchdog protocol and
syslog priority prefixes on stderr.

usage: appliance_tests.py MARIONETTE PART   (PART: rotation, full-disk, watchdog, journal)
Exit 0 pass, 1 fail, 77 skipped (full-disk without a private mount namespace, unless CI=true).
"""
import os
import re
import socket
import subprocess
import sys
import tempfile
import time

MARIONETTE = sys.argv[1]
PART = sys.argv[2]
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def run(args, env=None, **kw):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([MARIONETTE] + args, env=e, capture_output=True, text=True, **kw)


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def recordings(d):
    return sorted(os.listdir(d)) if os.path.isdir(d) else []


def replay_matches(first_file, trace, tmp):
    out = os.path.join(tmp, "replay.csv")
    r = run(["replay", first_file, "--trace", out])
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        return False, 0
    got = open(out).read().splitlines()
    want = open(trace).read().splitlines()
    return got == want[: len(got)], len(got) - 1


def test_rotation(tmp):
    # 20 s of the demo makes a log of about 21 kB: 10 kB files, 50 kB for all.
    cfg = os.path.join(tmp, "small.toml")
    write(cfg, "[recording]\nmax_total_mb = 0.05\nmax_file_mb = 0.01\nmin_free_mb = 0\n")
    rec_dir = os.path.join(tmp, "state", "marionette", "recordings")
    env = {"XDG_STATE_HOME": os.path.join(tmp, "state")}
    env.pop("STATE_DIRECTORY", None)
    made = []
    for i in range(5):
        trace = os.path.join(tmp, f"trace{i}.csv")
        r = run(["run", "--fast", "--duration", "20", "--record", "auto", "--config", cfg, "--trace", trace],
                env=dict(env, STATE_DIRECTORY=""))
        check(r.returncode == 0, f"run {i} with --record auto exits 0 ({r.returncode}: {r.stderr.strip()[-300:]})")
        m = re.search(r"recording to (\S+)", r.stdout)
        check(m is not None and m.group(1).startswith(rec_dir + "/run-"), f"run {i} records under {rec_dir}")
        if not m:
            return
        made.append(os.path.basename(m.group(1)))
        sizes = {n: os.path.getsize(os.path.join(rec_dir, n)) for n in recordings(rec_dir)}
        check(sum(sizes.values()) <= 50_000, f"after run {i}: {sum(sizes.values())} bytes in all <= 50000 (max_total_mb)")
        check(all(s <= 10_000 for s in sizes.values()), f"after run {i}: every file <= 10000 bytes (max_file_mb): {sizes}")
        parts = [n for n in sizes if n.startswith(made[-1])]
        check(len(parts) >= 3, f"run {i}'s recording continued in new files: {sorted(parts)}")
        ok, ticks = replay_matches(m.group(1), trace, tmp)
        check(ok and ticks == 4800, f"run {i}: replay of its files gives the run's trace ({ticks} ticks)")
        if i > 0:
            time.sleep(1.1)  # distinct names and modification times
    kept = {n.split(".mlog")[0] + ".mlog" for n in recordings(rec_dir)}
    check(kept == set(made[-2:]), f"the two newest recordings are kept, the oldest deleted first: {sorted(kept)}")
    # A recording that alone passes max_total_mb ends cleanly, within the cap.
    cfg2 = os.path.join(tmp, "tiny.toml")
    write(cfg2, "[recording]\nmax_total_mb = 0.015\nmax_file_mb = 0.01\nmin_free_mb = 0\n")
    trace = os.path.join(tmp, "trace_cap.csv")
    r = run(["run", "--fast", "--duration", "20", "--record", "auto", "--config", cfg2, "--trace", trace], env=env)
    check(r.returncode == 0, "a recording over max_total_mb by itself: the run goes on and exits 0")
    check(r.stderr.count("recording stopped") == 1 and "max_total_mb" in r.stderr,
          "one message says the recording stopped at max_total_mb: " + r.stderr.strip()[-200:])
    total = sum(os.path.getsize(os.path.join(rec_dir, n)) for n in recordings(rec_dir))
    check(total <= 15_000, f"{total} bytes in all <= 15000")
    first = re.search(r"recording to (\S+)", r.stdout).group(1)
    ok, ticks = replay_matches(first, trace, tmp)
    check(ok and 0 < ticks < 4800, f"what was kept replays to the run's trace ({ticks} ticks)")


def test_full_disk(tmp):
    mnt = os.path.join(tmp, "full")
    os.mkdir(mnt)
    cfg = os.path.join(tmp, "nofree.toml")
    write(cfg, "[recording]\nmin_free_mb = 0\n")
    log = os.path.join(mnt, "r.mlog")
    trace = os.path.join(tmp, "trace.csv")
    err = os.path.join(tmp, "stderr.txt")
    # A 16 kB tmpfs in a private mount namespace; stderr as the journal would see it.
    script = (f"mount -t tmpfs -o size=16k tmpfs '{mnt}' || exit 77; "
              f"export JOURNAL_STREAM=$(stat -c '%d:%i' '{err}'); "
              f"'{MARIONETTE}' run --fast --duration 60 --record '{log}' --config '{cfg}' --trace '{trace}' 2>>'{err}'; "
              f"rc=$?; cp '{log}' '{tmp}/kept.mlog'; ls -l '{mnt}' >&2; exit $rc")
    write(err, "")
    r = subprocess.run(["unshare", "-m", "bash", "-c", script], capture_output=True, text=True)
    if r.returncode == 77 or "unshare failed" in r.stderr or "Operation not permitted" in r.stderr:
        print("cannot mount a tmpfs here (needs root): skipped")
        sys.exit(1 if os.environ.get("CI") == "true" else 77)
    stderr = open(err).read()
    print(r.stdout[-400:], stderr, r.stderr)
    check(r.returncode == 0, f"the run goes on to the end and exits 0 ({r.returncode})")
    check("demo finished: 60.0 s, 14400 ticks" in r.stdout, "all 14400 ticks ran")
    lines = [l for l in stderr.splitlines() if "recording stopped" in l]
    check(len(lines) == 1, f"the message comes once ({len(lines)})")
    check(len(lines) == 1 and lines[0].startswith("<3>error: recording stopped: ") and "No space left on device" in lines[0]
          and "the run goes on without recording" in lines[0], "it names the full disk, at error priority: " + (lines[0] if lines else ""))
    check(os.path.getsize(os.path.join(tmp, "kept.mlog")) <= 16384, "the log fits the file system")
    r2 = run(["replay", os.path.join(tmp, "kept.mlog"), "--trace", os.path.join(tmp, "replay.csv")])
    check(r2.returncode == 0, "replay reads what was kept: " + r2.stderr.strip())
    check("no end marker" in r2.stderr and "truncated or corrupt" not in r2.stderr,
          "the kept log ends on a whole chunk (only the end marker is missing)")
    got = open(os.path.join(tmp, "replay.csv")).read().splitlines()
    want = open(trace).read().splitlines()
    m = re.search(r"the (\d+) ticks before it", lines[0]) if lines else None
    check(m is not None and len(got) - 1 == int(m.group(1)) > 0, f"replay has the {len(got) - 1} ticks the message names")
    check(got == want[: len(got)], "and they match the run's trace")


def notifications(sock, seconds_after_exit, proc):
    got = []
    sock.settimeout(0.05)
    end = None
    while True:
        try:
            data = sock.recv(4096)
            got.append((time.monotonic(), data.decode()))
        except socket.timeout:
            pass
        if end is None and proc.poll() is not None:
            end = time.monotonic() + seconds_after_exit
        if end is not None and time.monotonic() > end:
            return got


def watchdog_run(tmp, name, extra_env, duration):
    path = os.path.join(tmp, name + ".sock")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(path)
    env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC="1000000")
    env.pop("WATCHDOG_PID", None)
    env.update(extra_env)
    start = time.monotonic()
    proc = subprocess.Popen([MARIONETTE, "run", "--duration", str(duration), "--display", "headless"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    got = notifications(sock, 0.2, proc)
    out, err = proc.communicate()
    sock.close()
    print(f"{name}: " + ", ".join(f"{t - start:.2f} {m.replace(chr(10), '|')}" for t, m in got))
    return proc.returncode, got, out, err, start


def test_watchdog(tmp):
    # WATCHDOG_USEC=1 s: a ping every 0.5 s while both loops run.
    rc, got, out, err, start = watchdog_run(tmp, "healthy", {}, 4)
    check(rc == 0, "run exits 0 under NOTIFY_SOCKET")
    check(bool(got) and got[0][1].startswith("READY=1"), "READY=1 comes first")
    pings = [t for t, m in got if m == "WATCHDOG=1"]
    check(len(pings) >= 5, f"{len(pings)} WATCHDOG=1 in a 4 s run (>= 5)")
    times = [got[0][0]] + pings if got else pings
    gaps = [b - a for a, b in zip(times, times[1:])]
    check(bool(gaps) and max(gaps) < 1.0, f"never a gap of WATCHDOG_USEC (1 s) without a ping: max {max(gaps or [0]):.2f} s")
    check(bool(gaps) and min(gaps) > 0.3, f"pings at about half the interval, not faster: min {min(gaps or [0]):.2f} s")
    check(any(m.startswith("STOPPING=1") for t, m in got), "STOPPING=1 at the end")

    # The simulation stalls for 3 s after its first second: no ping while it is stuck.
    rc, got, out, err, start = watchdog_run(tmp, "stalled", {"MARIONETTE_TEST_STALL_SIM_MS": "3000"}, 5)
    check(rc == 0, "the stalled run exits 0")
    pings = [t - start for t, m in got if m == "WATCHDOG=1"]
    ready = [t - start for t, m in got if m.startswith("READY=1")]
    check(bool(ready), "READY=1 sent")
    times = ready[:1] + pings
    gaps = [(b - a, a) for a, b in zip(times, times[1:])]
    longest = max(gaps) if gaps else (0, 0)
    check(longest[0] >= 2.0, f"no WATCHDOG=1 for {longest[0]:.2f} s (from {longest[1]:.2f} s) while the simulation is stuck 3 s (>= 2.0 s)")
    check(any(p > longest[1] + longest[0] for p in pings) or longest[1] + longest[0] in pings,
          "the pings resume once it runs again")
    m = re.search(r"watchdog: (\d+) pings sent, (\d+) withheld", out)
    check(m is not None and int(m.group(2)) >= 4, "run counts the withheld pings: " + (m.group(0) if m else out[-300:]))

    # WATCHDOG_PID names another process: the watchdog is not ours, no pings (READY=1 still).
    rc, got, out, err, start = watchdog_run(tmp, "otherpid", {"WATCHDOG_PID": "1"}, 2)
    check(rc == 0 and bool(got) and got[0][1].startswith("READY=1"), "WATCHDOG_PID of another process: READY=1 still")
    check(not any(m == "WATCHDOG=1" for t, m in got), "and no WATCHDOG=1")


def test_journal(tmp):
    err = os.path.join(tmp, "stderr.txt")
    good = os.path.join(tmp, "good.mlog")
    # A log without its end marker: replaying it warns; recording into a missing directory is an error.
    r = run(["run", "--fast", "--duration", "2", "--record", good])
    check(r.returncode == 0, "a 2 s recording")
    data = open(good, "rb").read()
    cut = os.path.join(tmp, "cut.mlog")
    open(cut, "wb").write(data[:-10])

    def stderr_of(args, env):
        with open(err, "w") as f:
            st = os.fstat(f.fileno())
            e = dict(os.environ)
            e.pop("MARIONETTE_LOG_PREFIX", None)
            e.pop("JOURNAL_STREAM", None)
            e.update({k: v.format(dev=st.st_dev, ino=st.st_ino) for k, v in env.items()})
            p = subprocess.run([MARIONETTE] + args, env=e, stdout=subprocess.DEVNULL, stderr=f)
        return p.returncode, open(err).read().splitlines()

    journal = {"JOURNAL_STREAM": "{dev}:{ino}"}
    rc, lines = stderr_of(["run", "--fast", "--input", "log:" + cut], journal)
    check(rc == 0 and any(l.startswith("<4>warning: ") for l in lines), f"a warning to the journal starts <4>: {lines}")
    check(bool(lines) and all(re.match(r"<[3-7]>", l) for l in lines), "every stderr line has a priority")
    rc, lines = stderr_of(["run", "--fast", "--duration", "1", "--record", "/nonexistent/dir/x.mlog"], journal)
    check(rc != 0 and lines and lines[0].startswith("<3>error: ") and "/nonexistent/dir/x.mlog" in lines[0],
          f"an error starts <3>: {lines}")
    rc, lines = stderr_of(["run", "--fast", "--input", "log:" + cut], {"JOURNAL_STREAM": "{dev}:1"})
    check(lines and lines[0].startswith("warning: "), f"JOURNAL_STREAM naming another file: plain lines: {lines[:1]}")
    rc, lines = stderr_of(["run", "--fast", "--input", "log:" + cut], {})
    check(lines and lines[0].startswith("warning: "), "no JOURNAL_STREAM: plain lines")
    rc, lines = stderr_of(["run", "--fast", "--input", "log:" + cut], {"MARIONETTE_LOG_PREFIX": "syslog"})
    check(lines and lines[0].startswith("<4>warning: "), "MARIONETTE_LOG_PREFIX=syslog asks for them anywhere")
    rc, lines = stderr_of(["run", "--fast", "--input", "log:" + cut], dict(journal, MARIONETTE_LOG_PREFIX="none"))
    check(lines and lines[0].startswith("warning: "), "MARIONETTE_LOG_PREFIX=none turns them off")


with tempfile.TemporaryDirectory(prefix="marionette-appliance-") as tmp:
    started = time.monotonic()
    {"rotation": test_rotation, "full-disk": test_full_disk, "watchdog": test_watchdog, "journal": test_journal}[PART](tmp)
    print(f"{PART}: {time.monotonic() - started:.1f} s, {len(failures)} failure(s)")
sys.exit(1 if failures else 0)
