#!/usr/bin/env bash
# Determinism across build types and compilers: builds the golden-trace tests
# (tests/app/test_replay_golden.cpp: every shipped program with the gait, the
# motion-graph goldens with graph, graph_feet and a live source switch, and the
# motion-matching goldens: a whole run and switches to and from matching) in the
# configurations the presets do not cover, and runs them. Each configuration
# compiles only the deterministic core (MARIONETTE_CORE_ONLY). The release and
# asan presets already run the goldens in scripts/test.sh.
#   gcc-O3    a plain `cmake -DCMAKE_BUILD_TYPE=Release` (GCC -O3, no -Werror: as
#             a packager builds it)
#   clang14   Clang 14, -O2, -Werror
# Usage: scripts/check-builds.sh [CONFIG ...]   (default: all)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
configs=("$@")
((${#configs[@]})) || configs=(gcc-O3 clang14)
if [[ " ${configs[*]} " == *" clang14 "* ]] && ! command -v clang++-14 >/dev/null 2>&1; then
  MARIONETTE_SETUP_CLANG=1 bash scripts/setup.sh
fi
passed=0
for config in "${configs[@]}"; do
  case "$config" in
    gcc-O3) args=(-DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=g++) ;;
    clang14) args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 -DMARIONETTE_WERROR=ON) ;;
    *) echo "check-builds: unknown configuration '$config' (gcc-O3, clang14)" >&2; exit 2 ;;
  esac
  dir="build/check-$config"
  start=$(date +%s)
  echo "== check-builds: $config: configure and build the golden tests"
  cmake -S . -B "$dir" -G Ninja "${args[@]}" -DMARIONETTE_CORE_ONLY=ON -DMARIONETTE_BUILD_BENCH=OFF >/dev/null
  cmake --build "$dir" -j "$jobs" --target marionette_golden_tests
  echo "== check-builds: $config: run the golden tests"
  out=$(cd "$dir/tests" && ./marionette_golden_tests 2>&1) || { echo "$out" | tail -40; echo "check-builds: $config: FAILED"; exit 1; }
  echo "$out" | tail -2
  if grep -q "not the one the golden traces were made with" <<<"$out"; then
    echo "check-builds: $config: FAILED: this build makes another default motion graph, so the graph goldens could not be compared"
    exit 1
  fi
  echo "check-builds: $config: goldens identical ($(($(date +%s) - start)) s)"
  passed=$((passed + 1))
done
echo "check-builds: ${passed} of ${#configs[@]} configurations give the golden traces bit for bit"
