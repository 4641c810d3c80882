#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang++-14, ASan + UBSan) and
# runs each one for SECONDS (default 30) on its checked-in seed corpus
# (tests/fuzz/corpus/<target>) plus every kept reproducer
# (tests/data/fuzz_regressions/<target>). New inputs go to a scratch folder under
# build/fuzz/run/, so the checked-in corpus never grows unless --grow is given
# (then the new inputs are merged into it with libFuzzer's -merge=1: review the
# size before committing).
#
#   scripts/fuzz.sh [--grow] [--only REGEX] [SECONDS]
#
# Exits non-zero when any target finds a crash, UB, leak, timeout (> -timeout s
# for one input) or an allocation over -malloc_limit_mb; the reproducer is
# left in build/fuzz/findings/<target>/ and the log in build/fuzz/run/<target>.log.
# Prints each target's executions and final coverage (cov: edges, ft: features).
# Targets run FUZZ_JOBS at a time (default: the number of cores). FUZZ_RUNS=N
# also stops each target after N executions (the issue's long campaign is
# `FUZZ_RUNS=10000000 scripts/fuzz.sh 1800`: 10 million executions or 30 minutes,
# whichever comes first); the table then shows each target's CPU seconds, so a
# run on a busy machine can be read honestly. FUZZ_TIMEOUT
# overrides every target's per-input limit (libFuzzer's -timeout is wall-clock
# time, so a heavily loaded machine can turn a 5 ms input into a false timeout:
# re-run the reproducer alone, `build/fuzz/tests/fuzz/fuzz_<target> FILE`, before
# calling it a hang).
set -euo pipefail
cd "$(dirname "$0")/.."

grow=0
only=.
seconds=30
while (($#)); do
  case "$1" in
    --grow) grow=1 ;;
    --only) only="$2"; shift ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    *) seconds="$1" ;;
  esac
  shift
done
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2; }

# target  max_len  timeout_s  dictionary
targets=(
  "bvh_import       8192 1 bvh.dict"
  "bvh_roundtrip    8192 1 bvh.dict"
  "asf_skeleton     4096 1 asf_amc.dict"
  "asf_amc          4096 1 asf_amc.dict"
  "input_log        4096 1 -"
  "input_log_crc    4096 1 -"
  "stick_program    2048 1 stick_program.dict"
  "mgraph           8192 1 -"
  "mgraph_hash      8192 1 -"
  "terrain          8192 1 toml.dict"
  "config           8192 1 toml.dict"
  "hid               256 1 -"
  "evdev            1024 1 -"
)

start=$(date +%s)
echo "== fuzz: configure and build (preset fuzz)"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$(nproc)"
built=$(date +%s)

bin=build/fuzz/tests/fuzz
run=build/fuzz/run
findings=build/fuzz/findings
rm -rf "$run" "$findings"
mkdir -p "$run" "$findings"

run_one() {
  local name=$1 max_len=$2 timeout=$3 dict=$4
  local exe="$bin/fuzz_$name" work="$run/$name" log="$run/$name.log"
  mkdir -p "$work" "$findings/$name"
  local seeds=("tests/fuzz/corpus/$name")
  [[ -d "tests/data/fuzz_regressions/$name" ]] && seeds+=("tests/data/fuzz_regressions/$name")
  local args=(-max_total_time="$seconds" -max_len="$max_len" -timeout="${FUZZ_TIMEOUT:-$timeout}" -rss_limit_mb=2048
              -malloc_limit_mb=512 -print_final_stats=1 -artifact_prefix="$findings/$name/")
  [[ "$dict" != - ]] && args+=(-dict="tests/fuzz/dict/$dict")
  [[ -n "${FUZZ_RUNS:-}" ]] && args+=(-runs="$FUZZ_RUNS")
  local rc=0 TIMEFORMAT='%U %S'   # bash's `time`: the fuzzer's user and system CPU seconds
  { time UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 "$exe" "${args[@]}" "$work" "${seeds[@]}" >"$log" 2>&1; } \
    2>"$run/$name.time" || rc=$?
  echo "$rc" >"$run/$name.rc"
  awk '{ printf "%.0f\n", $1 + $2 }' "$run/$name.time" >"$run/$name.cpu"
  if ((grow)) && [[ "$rc" == 0 ]]; then
    "$exe" -merge=1 -max_len="$max_len" "tests/fuzz/corpus/$name" "$work" >>"$log" 2>&1
  fi
}

jobs=${FUZZ_JOBS:-$(nproc)}
selected=()
for t in "${targets[@]}"; do
  read -r name _ <<<"$t"
  [[ "$name" =~ $only ]] && selected+=("$t")
done
echo "== fuzz: ${#selected[@]} targets, ${seconds} s each, $jobs at a time"
running=0
for t in "${selected[@]}"; do
  # shellcheck disable=SC2086
  run_one $t &
  running=$((running + 1))
  if ((running >= jobs)); then wait -n || true; running=$((running - 1)); fi
done
wait

failed=0
printf '%-15s %12s %8s %7s %8s %7s %7s  %s\n' target executions exec/s cpu_s cov ft rss_mb result
for t in "${selected[@]}"; do
  read -r name _ <<<"$t"
  log="$run/$name.log"
  rc=$(cat "$run/$name.rc")
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  cpu=$(cat "$run/$name.cpu" 2>/dev/null || echo '?')
  # The last status line ("#N DONE cov: X ft: Y ..." or the last pulse) holds the final coverage.
  cov=$(grep -E '^#[0-9]+' "$log" | grep -o 'cov: [0-9]*' | tail -1 | cut -d' ' -f2)
  ft=$(grep -E '^#[0-9]+' "$log" | grep -o 'ft: [0-9]*' | tail -1 | cut -d' ' -f2)
  result=ok
  if [[ "$rc" != 0 ]]; then
    result="FINDING (exit $rc): $(ls -t "$findings/$name" | head -1) — see $log"
    failed=1
  fi
  printf '%-15s %12s %8s %7s %8s %7s %7s  %s\n' "$name" "${execs:-?}" "${speed:-?}" "$cpu" "${cov:-?}" "${ft:-?}" "${rss:-?}" "$result"
done
end=$(date +%s)
echo "== fuzz: build $((built - start)) s, fuzzing $((end - built)) s, total $((end - start)) s"
if ((failed)); then
  echo "fuzz: FINDINGS above: fix the parser and keep the reproducer under tests/data/fuzz_regressions/<target>/" >&2
  exit 1
fi
