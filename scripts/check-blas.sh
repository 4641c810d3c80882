#!/usr/bin/env bash
# Graph builds do not depend on BLAS (issue 16, docs/determinism.md "Graph builds"):
# builds the default graph and the CMU subject-16 graph under every OpenBLAS kernel
# type below, with OPENBLAS_NUM_THREADS 1 and 2 and the builder's own --threads 1, 2
# and 3, and fails unless every file of a graph has the same bytes. It also fails
# when OpenBLAS did not run the kernel asked for (OPENBLAS_VERBOSE=2 names the one it
# loaded; an unknown or unsupported name would silently fall back to the CPU's own).
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
if [ "$failed" -ne 0 ]; then
  echo "check-blas: FAIL" >&2
  exit 1
fi
echo "check-blas: OK: every kernel and thread count gives the same bytes"
