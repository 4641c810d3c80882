#!/usr/bin/env bash
# CPU time and wake-ups of `marionette run` (docs/pipeline.md, "Power").
#
#   bash scripts/measure-power.sh [--runs N] [--duration S] [--binary PATH] [-- extra run arguments]
#
# Runs `marionette run --display headless --input sim:config/programs/circle.prog
# --duration S` N times (defaults: 3 runs of 10 s) and prints, per run and as
# min/median/max, the CPU time per wall second (% of one core, user + system,
# all threads) and the wake-ups per second (voluntary context switches of all
# threads: each is a thread going to sleep, so one wake-up each). The figures
# come from wait4()'s rusage of the child, so nothing else on the machine is
# counted; a loaded machine still moves them a little (cache, migrations), so
# look at the spread. Extra arguments after `--` replace the default input and
# display (e.g. `-- --display window` under xvfb-run).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=3
duration=10
binary=build/release/app/marionette
while [[ $# -gt 0 ]]; do
    case "$1" in
        --runs) runs="$2"; shift 2 ;;
        --duration) duration="$2"; shift 2 ;;
        --binary) binary="$2"; shift 2 ;;
        --) shift; break ;;
        *) echo "measure-power.sh: unknown option $1 (expected --runs N, --duration S, --binary PATH, -- ARGS)" >&2; exit 2 ;;
    esac
done
[[ -x "$binary" ]] || { echo "measure-power.sh: $binary: not built (cmake --build --preset release --target marionette)" >&2; exit 2; }
if [[ $# -gt 0 ]]; then extra=("$@"); else extra=(--display headless --input sim:config/programs/circle.prog); fi
python3 - "$runs" "$binary" "$duration" "${extra[@]}" <<'PY'
import os, statistics, subprocess, sys, time
runs, binary, duration, extra = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4:]
cpu, wakes = [], []
for i in range(runs):
    start = time.monotonic()
    p = subprocess.Popen([binary, "run", "--duration", duration, *extra], stdout=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - start
    if status != 0:
        sys.exit(f"measure-power.sh: run {i + 1} failed (wait status {status})")
    c = 100.0 * (ru.ru_utime + ru.ru_stime) / wall
    w = ru.ru_nvcsw / wall
    cpu.append(c)
    wakes.append(w)
    print(f"run {i + 1}: {wall:.2f} s wall, user {ru.ru_utime:.3f} s, system {ru.ru_stime:.3f} s, "
          f"CPU {c:.2f} % of one core, {w:.0f} wake-ups/s (voluntary), {ru.ru_nivcsw / wall:.0f} preemptions/s")
def spread(xs, fmt):
    return f"min {fmt.format(min(xs))} median {fmt.format(statistics.median(xs))} max {fmt.format(max(xs))}"
print(f"CPU % of one core: {spread(cpu, '{:.2f}')}")
print(f"wake-ups/s: {spread(wakes, '{:.0f}')}")
PY
