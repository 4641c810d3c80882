#!/usr/bin/env bash
# Regenerates tests/golden/*.trace.csv after a change that alters the simulation
# on purpose. Review the diff (git diff --stat tests/golden) and say why in the
# commit message: a golden change is a behaviour change.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release --target marionette
bin=build/release/app/marionette
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for program in stand_still walk_stop circle demo slow_walk fast_walk run start_stop full_circle reversals stop_mid_step; do
  "$bin" record --program "config/programs/$program.prog" -o "$tmp/$program.mlog" >/dev/null
  "$bin" replay "$tmp/$program.mlog" --trace "tests/golden/$program.trace.csv"
done
# The motion-graph goldens (tests/app/test_replay_golden.cpp, [golden_graph]):
# written by the test itself, with the default graph's hash they belong to.
cmake --build --preset release --target marionette_golden_tests
(cd "$tmp" && MARIONETTE_WRITE_GOLDEN=1 "$OLDPWD/build/release/tests/marionette_golden_tests" "[golden_graph]" >/dev/null)
for name in graph_actions graph_feet_circle_stairs graph_switch_stairs matching_demo_stairs matching_switch_slope; do
  cp "$tmp/golden_$name.csv" "tests/golden/$name.trace.csv"
done
cp "$tmp/default_graph.hash" tests/golden/default_graph.hash
