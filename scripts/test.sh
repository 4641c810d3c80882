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
  if [[ $preset == release ]]; then
    # ccache for the optimised build, so the package below reuses its objects
    # (same flags; scripts/package.sh sets the same ccache variables).
    export CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
  fi
  cmake --preset "$preset" >/dev/null
  unset CMAKE_CXX_COMPILER_LAUNCHER
  cmake --build --preset "$preset" -j "$jobs"
  echo "== $preset: test"
  ctest --preset "$preset" -j "$jobs"
  if [[ $preset == release ]]; then
    # The Debian package (docs/deploy.md): build it, check its contents and run
    # it unprivileged from a dpkg -x root. The install into a fresh debootstrap
    # root is not in CI (about 15 min here, and the network); see the docs.
    echo "== package: build and test the .deb"
    deb=$(bash scripts/package.sh | tail -1)
    bash tests/packaging/package_tests.sh "$deb"
  fi
done
# ThreadSanitizer: only the pipeline's stress target (a full tsan build would not
# fit CI's budget on two cores; the handoffs are what it must check).
echo "== tsan: configure and build the stress tests"
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j "$jobs" --target marionette_stress_tests
echo "== tsan: test"
ctest --preset tsan -R '^stress:' -j 1
