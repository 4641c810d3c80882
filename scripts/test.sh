#!/usr/bin/env bash
# Builds and runs every test: the optimised build first, then the asan build
# (AddressSanitizer + UBSan). The golden replay traces are checked in both, so an
# optimisation-dependent result fails here. Then ThreadSanitizer, on the lock-free
# stress tests only (tests/stress). `.ci/run` calls exactly this.
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
  if [ "$preset" = release ]; then
    # Graph bytes under every OpenBLAS kernel and thread count (builds nothing).
    echo "== release: graph builds independent of BLAS"
    bash scripts/check-blas.sh
  fi
done
# ThreadSanitizer: only the pipeline's stress target (a full tsan build would not
# fit CI's budget on two cores; the handoffs are what it must check).
echo "== tsan: configure and build the stress tests"
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j "$jobs" --target marionette_stress_tests
echo "== tsan: test"
ctest --preset tsan -R '^stress:' -j 1
