#!/usr/bin/env bash
# Graph builds do not depend on BLAS (issue 16, docs/determinism.md "Graph builds"):
# builds the default graph and the CMU subject-16 graph under every OpenBLAS kernel
# type below, with OPENBLAS_NUM_THREADS 1 and 2 and the builder's own --threads 1, 2
# and 3, and fails unless every file of a graph has the same bytes; then records a
# log with `record --graph default` under every kernel type (all logs must be the
# same bytes) and replays it under every kernel type, every checkpoint verified.
# It also fails when OpenBLAS did not run the kernel asked for (OPENBLAS_VERBOSE=2
# names the one it loaded; an unknown or unsupported name would silently fall back
# to the CPU's own).
# Builds nothing: it runs build/release/app/marionette (scripts/test.sh builds it
# first; MARIONETTE_BIN overrides). The clips: MARIONETTE_MOCAP_DIR (default
# ../shared/data/mocap).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MARIONETTE_BIN:-build/release/app/marionette}
mocap=${MARIONETTE_MOCAP_DIR:-../shared/data/mocap}
cores=(Prescott Nehalem Sandybridge Haswell Zen SkylakeX)
[ -x "$bin" ] || { echo "check-blas: $bin is missing (build the release preset's marionette first)" >&2; exit 1; }
[ -f "$mocap/cmu_amc_16/16.asf" ] || { echo "check-blas: no CMU clips in $mocap/cmu_amc_16 (set MARIONETTE_MOCAP_DIR)" >&2; exit 1; }
start=$(date +%s)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0
builds=0
for graph in default cmu16; do
  if [ "$graph" = default ]; then
    args=(--default)
  else
    args=(--asf "$mocap/cmu_amc_16/16.asf" "$mocap"/cmu_amc_16/*.amc)
  fi
  first=""
  run=0
  for core in "${cores[@]}"; do
    for blas_threads in 1 2; do
      builder_threads=$((run % 3 + 1))
      run=$((run + 1))
      builds=$((builds + 1))
      out="$tmp/$graph-$core-$blas_threads.mgraph"
      if ! OPENBLAS_VERBOSE=2 OPENBLAS_CORETYPE=$core OPENBLAS_NUM_THREADS=$blas_threads \
          "$bin" graph build "${args[@]}" --threads "$builder_threads" -o "$out" >"$tmp/log" 2>&1; then
        cat "$tmp/log" >&2
        echo "check-blas: FAIL: the $graph build under $core failed" >&2
        exit 1
      fi
      ran=$(grep -m1 -o 'Core: [A-Za-z0-9]*' "$tmp/log" | cut -d' ' -f2 || true)
      hash=$(sha256sum "$out" | cut -c1-16)
      echo "$graph: kernel $core (ran: ${ran:-?}), OPENBLAS_NUM_THREADS=$blas_threads, --threads $builder_threads: $hash"
      if [ "$ran" != "$core" ]; then
        echo "check-blas: FAIL: OpenBLAS ran kernel '${ran:-?}', not $core" >&2
        failed=1
      fi
      if [ -z "$first" ]; then
        first=$out
      elif ! cmp -s "$first" "$out"; then
        echo "check-blas: FAIL: $graph under $core / $blas_threads thread(s) differs from $(basename "$first")" >&2
        failed=1
      fi
    done
  done
done
echo "check-blas: $builds builds in $(($(date +%s) - start)) s"

# Logs across kernels (issue 16): `record --graph default` under each kernel type
# gives the same log bytes (so a log recorded under any one is the log recorded
# under every other), and that log replays under every kernel type with all its
# state-hash checkpoints verified (replay builds the embedded default graph itself,
# under the kernel it runs).
replay_start=$(date +%s)
program=config/programs/actions.prog
first_log=""
for core in "${cores[@]}"; do
  log="$tmp/record-$core.mlog"
  if ! OPENBLAS_VERBOSE=2 OPENBLAS_CORETYPE=$core "$bin" record --program "$program" --graph default -o "$log" \
      >"$tmp/log" 2>&1; then
    cat "$tmp/log" >&2
    echo "check-blas: FAIL: record --graph default under $core failed" >&2
    exit 1
  fi
  ran=$(grep -m1 -o 'Core: [A-Za-z0-9]*' "$tmp/log" | cut -d' ' -f2 || true)
  [ "$ran" = "$core" ] || { echo "check-blas: FAIL: record: OpenBLAS ran kernel '${ran:-?}', not $core" >&2; failed=1; }
  if [ -z "$first_log" ]; then
    first_log=$log
  elif ! cmp -s "$first_log" "$log"; then
    echo "check-blas: FAIL: the log recorded under $core differs from $(basename "$first_log")" >&2
    failed=1
  fi
done
for core in "${cores[@]}"; do
  if ! OPENBLAS_VERBOSE=2 OPENBLAS_CORETYPE=$core "$bin" replay "$first_log" --json >"$tmp/replay.json" 2>"$tmp/log"; then
    cat "$tmp/log" "$tmp/replay.json" >&2
    echo "check-blas: FAIL: the log recorded under ${cores[0]} does not replay under $core" >&2
    failed=1
    continue
  fi
  ran=$(grep -m1 -o 'Core: [A-Za-z0-9]*' "$tmp/log" | cut -d' ' -f2 || true)
  [ "$ran" = "$core" ] || { echo "check-blas: FAIL: replay: OpenBLAS ran kernel '${ran:-?}', not $core" >&2; failed=1; }
  verified=$(python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(d["checkpoints_verified"] if d["checkpoints"] >= 2 and d["checkpoints_verified"] == d["checkpoints"] else "bad")' "$tmp/replay.json")
  if [ "$verified" = bad ]; then
    echo "check-blas: FAIL: replay under $core did not verify every checkpoint: $(cat "$tmp/replay.json")" >&2
    failed=1
  else
    echo "log recorded with --graph default under each kernel (identical bytes): replay under $core (ran: ${ran:-?}): $verified checkpoints verified"
  fi
done
echo "check-blas: ${#cores[@]} recordings and ${#cores[@]} replays in $(($(date +%s) - replay_start)) s"
if [ "$failed" -ne 0 ]; then
  echo "check-blas: FAIL" >&2
  exit 1
fi
echo "check-blas: OK: every kernel and thread count gives the same graph bytes, and a log recorded under any kernel replays under all ${#cores[@]} with every checkpoint verified"
