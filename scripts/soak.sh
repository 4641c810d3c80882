#!/usr/bin/env bash
# Soak: `marionette run --fast` for MINUTES of simulated time (default 60) on a
# random stick program generated from a fixed seed, with the simulated controller
# unplugged for 2 s in every minute (--sim-unplug) and a live edit of the watched
# configuration every 5 simulated minutes. Checks that:
#   - the run finishes every tick, logs every unplug and replug, and applies every edit;
#   - `replay` of the recording gives exactly the run's trace (byte for byte);
#   - RSS at the end is within 1 MiB (1024 KiB) of RSS after the first simulated minute.
# Prints one line of figures ("soak: ...") and exits 1 on any failure.
# Usage: scripts/soak.sh [MINUTES] [MARIONETTE_BINARY]   (SOAK_SEED=N to change the program)
set -uo pipefail
minutes=${1:-60}
bin=${2:-$(cd "$(dirname "$0")/.." && pwd)/build/release/app/marionette}
seed=${SOAK_SEED:-20261202}
[[ $minutes =~ ^[0-9]+$ && $minutes -ge 1 ]] || { echo "soak.sh: MINUTES must be a whole number >= 1, got '$minutes'" >&2; exit 2; }
[[ -x $bin ]] || { echo "soak.sh: $bin is not an executable (build the marionette target)" >&2; exit 2; }
bin=$(realpath "$bin")  # the run happens in a scratch folder
work=$(mktemp -d)
[[ -n ${SOAK_KEEP:-} ]] && echo "soak: keeping $work" || trap 'rm -rf "$work"' EXIT
cd "$work"

# The program: random holds, ramps, circles and presses until MINUTES are full.
python3 - "$seed" "$minutes" >soak.prog <<'EOF'
import random, sys
rng = random.Random(int(sys.argv[1]))
total_ms = int(sys.argv[2]) * 60_000
buttons = ["south", "east", "west", "north", "left_shoulder", "right_shoulder", "back", "start",
           "left_stick", "right_stick", "dpad_up", "dpad_down", "dpad_left", "dpad_right"]
def v(lo=-1.0):
    return f"{rng.uniform(lo, 1.0):.3f}"
t = 0
print(f"# soak program, seed {sys.argv[1]}, {sys.argv[2]} min")
while t < total_ms:
    d = min(rng.randint(50, 8000), total_ms - t)
    kind = rng.random()
    if kind < 0.35:
        print(f"hold {d}ms lx={v()} ly={v()} rx={v()} ry={v()} lt={v(0)} rt={v(0)}")
    elif kind < 0.7:
        print(f"ramp {d}ms lx={v()} ly={v()} rx={v()} ry={v()} lt={v(0)} rt={v(0)}")
    elif kind < 0.85:
        stick = rng.choice(["left", "right"])
        print(f"circle {d}ms radius={rng.uniform(0, 1):.3f} turns={rng.uniform(-3, 3):.2f} "
              f"from={rng.randint(0, 359)} stick={stick}")
    else:
        print(f"press {rng.choice(buttons)} {d}ms")
    t += d
EOF

# Unplugged from second 30 of every minute for 2 s (the last minute too).
unplug=()
for ((m = 0; m < minutes; m++)); do unplug+=(--sim-unplug "$((m * 60 + 30))" 2); done
printf '[locomotion]\nmax_speed = 3.0\n' >tune.toml

start_ns=$(date +%s%N)
# The driver (one Python process, so it keeps up with a run that simulates
# ~100 s per wall second) starts the run and follows its simulated time (the
# status line every simulated second): it edits the config at every 5th minute
# (not in the last 3: the status line comes from the writer, up to the record
# ring's 68 s behind the simulation, and an edit takes 100 ms of quiet to
# apply, so a later edit could land after the last tick), and reads RSS after
# the first minute and for the last time just before the run exits.
python3 - "$bin" "$minutes" "${unplug[@]}" >driver.txt 2>driver.err <<'PY'
import re, subprocess, sys, time
bin, minutes, unplug = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
out = open("run.out", "wb")
proc = subprocess.Popen([bin, "run", "--fast", "--display", "headless", "--input", "sim:soak.prog",
                         "--config", "tune.toml", *unplug, "--record", "soak.mlog", "--trace", "run.csv",
                         "--stats-json", "stats.json"], stdout=out, stderr=open("run.err", "wb"))
status = re.compile(rb"^\[ *(\d+)\.\d s\] ", re.M)
rss_1min = rss_end = None
rss_end_at = 0
next_edit, edits, seen, applied = 300, 0, 0, 0
pending = b""
log = open("edits.log", "w")
with open("run.out", "rb") as follow:
    while proc.poll() is None:
        pending += follow.read()
        cut = pending.rfind(b"\n") + 1  # whole lines only
        chunk, pending = pending[:cut], pending[cut:]
        for m in status.finditer(chunk):
            seen = int(m.group(1))
        applied += chunk.count(b"config: applied before tick")
        try:
            rss = int(re.search(r"VmRSS:\s*(\d+) kB", open(f"/proc/{proc.pid}/status").read()).group(1))
        except (OSError, AttributeError):
            rss = None
        # Once the last status line is out the run is tearing down: not sampled.
        if rss is not None and seen < minutes * 60:
            if rss_1min is None and seen >= 60:
                rss_1min = rss
            rss_end, rss_end_at = rss, seen
        # One edit at a time: on a loaded machine this loop may wake after two
        # marks have passed, and a second edit before the first is applied would
        # undo it (the watcher reads the file once it is quiet).
        if seen >= next_edit and seen <= minutes * 60 - 180 and applied == edits:
            edits += 1
            speed = "2.5" if edits % 2 else "3.0"
            open("tune.new", "w").write(f"[locomotion]\nmax_speed = {speed}\n")
            import os
            os.replace("tune.new", "tune.toml")
            log.write(f"edit {edits} at status line {seen} s: max_speed = {speed}\n")
            next_edit += 300
        time.sleep(0.005)
print(f"rc={proc.returncode} rss_1min={rss_1min or ''} rss_end={rss_end or ''} rss_end_at={rss_end_at} edits={edits}")
PY
rc=; rss_1min=; rss_end=; rss_end_at=0; edits=0
eval "$(cat driver.txt)"
[[ -n $rc ]] || { echo "soak FAILED: the driver did not finish: $(tail -3 driver.err 2>/dev/null)"; exit 1; }
wall_s=$(( ($(date +%s%N) - start_ns) / 1000000 ))

failures=0
fail() { echo "soak FAILED: $*"; failures=$((failures + 1)); }
[[ $rc -eq 0 ]] || fail "run exited $rc: $(tail -3 run.err)"
ticks=$(($(wc -l <run.csv) - 1))
expected_ticks=$((minutes * 60 * 240))
[[ $ticks -eq $expected_ticks ]] || fail "traced $ticks ticks, expected $expected_ticks"
disconnects=$(grep -c 'controller disconnected' run.out)
reconnects=$(grep -c 'controller connected: resuming' run.out)
[[ $disconnects -eq $minutes ]] || fail "$disconnects unplugs logged, expected $minutes"
# The last minute's replug comes 28 s before the end, so every unplug is followed by one.
[[ $reconnects -eq $minutes ]] || fail "$reconnects replugs logged, expected $minutes"
applied=$(grep -c 'config: applied before tick' run.out)
# An edit is made only once the one before it is applied, and none in the last
# 3 simulated minutes: the writer thread that prints the status lines drains at
# most one record ring (68 s of ticks) per pass before it looks at the watched
# file (app/live/pipeline.cpp, write_until_done), so every edit must apply.
((edits >= 1 && applied == edits)) || fail "$applied config edits applied, $edits made"
"$bin" replay soak.mlog --trace replay.csv >replay.out 2>&1 || fail "replay exited $?: $(tail -2 replay.out)"
if cmp -s run.csv replay.csv; then same=yes; else same=no; fail "replay trace differs from the run's: $(cmp run.csv replay.csv | head -1)"; fi
if [[ -z $rss_1min ]]; then
  fail "no RSS sample after the first simulated minute"; growth=?
else
  growth=$((rss_end - rss_1min))
  # SOAK_RSS_LIMIT_KIB=none under AddressSanitizer: its quarantine keeps freed
  # blocks (up to 256 MB by default) out of reuse, so RSS grows with any
  # allocation churn and says nothing about leaks there (LeakSanitizer does).
  limit=${SOAK_RSS_LIMIT_KIB:-1024}
  if [[ $limit != none ]]; then
    ((growth <= limit)) || fail "RSS grew by $growth KiB from minute 1 to the end (limit $limit)"
  fi
fi
distance=$(sed -n 's/.*"distance_m":\([0-9.e+-]*\).*/\1/p' stats.json)
echo "soak: ${minutes} min simulated (seed $seed), $ticks ticks, wall ${wall_s} ms; $disconnects unplugs, $reconnects replugs," \
  "$applied/$edits config edits applied; replay trace identical: $same; RSS after 1 min ${rss_1min:-?} KiB," \
  "last sample (status line at ${rss_end_at} s) ${rss_end:-?} KiB (growth ${growth} KiB); walked ${distance} m; log $(stat -c %s soak.mlog) bytes"
[[ $failures -eq 0 ]]
