#!/usr/bin/env bash
# Builds and runs every test: the optimised build first, then the asan build
# (AddressSanitizer + UBSan). The golden replay traces are checked in both, so an
# optimisation-dependent result fails here. `.ci/run` calls exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)
for preset in release asan; do
  echo "== $preset: configure and build"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" -j "$jobs"
  echo "== $preset: test"
  ctest --preset "$preset" -j "$jobs"
done
