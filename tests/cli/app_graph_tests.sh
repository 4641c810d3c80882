#!/usr/bin/env bash
# The motion graph in the app (issue 4): `gait-eval --graph default` prints finite
# metrics with a skate figure; [motion_graph.buttons] remaps buttons and a
# changed key naming a label the graph lacks is exit 2 naming file:line and key;
# `run --graph F` rebuilds a stale graph (a copied CMU clip edited) and writes it
# back, and uses it as it is (with a warning) when a source is missing.
# Usage: app_graph_tests.sh MARIONETTE_BINARY SOURCE_DIR
bin=$(realpath "$1")
src=$(realpath "$2")
source "$src/tests/cli/check_lib.sh"

# 1. gait-eval --graph
check "gait-eval --graph default --json on flat ground prints finite metrics and a skate figure" bash -c "
  '$bin' gait-eval --graph default --terrain flat --program builtin:fast_walk --json >ge.json && python3 -c \"
import json, math, sys
d = json.load(open('ge.json'))
ok = d['motion_source'] == 'graph' and d['graph'] == 'default' and d['limits_ok'] is None
for k in ['foot_skate_mm', 'penetration_mm', 'speed_error_pct', 'max_joint_speed_deg_s']:
    ok = ok and isinstance(d[k], (int, float)) and math.isfinite(d[k])
ok = ok and d['steps'] > 0 and d['speed_windows'] == 1
print('gait-eval --graph default fast_walk:', {k: d[k] for k in ['foot_skate_mm','penetration_mm','speed_error_pct','max_joint_speed_deg_s','steps','flight_phases']})
sys.exit(0 if ok else 1)\""
check "gait-eval --graph default --check exits 0 (only non-finite metrics fail with a graph)" \
  bash -c "'$bin' gait-eval --graph default --terrain flat --program builtin:slow_walk --check --json >/dev/null"
check "gait-eval without --graph says the gait drove it" bash -c "'$bin' gait-eval --terrain flat --program builtin:slow_walk --json | grep -q '\"motion_source\":\"gait\"'"

# 2. [motion_graph.buttons]
printf '[motion_graph.buttons]\neast = "bow"\n\ndpad_up = "dance"\n' >badbuttons.toml
expect_error "a remapped button naming a label the default graph lacks is exit 2 with file:line and key" 2 \
  "badbuttons.toml:4: motion_graph.buttons.dpad_up: label 'dance' is not in" \
  "$bin" record --graph default --program "$src/config/programs/actions.prog" --config badbuttons.toml -o bad.mlog
printf '[motion_graph.buttons]\nsouth = "wave"\nnorth = ""\n' >buttons.toml
check "a valid remap records and replays to the same hash" bash -c "
  '$bin' record --graph default --program '$src/config/programs/actions.prog' --config buttons.toml -o remap.mlog --json >rec.json &&
  h=\$(python3 -c 'import json; print(json.load(open(\"rec.json\"))[\"final_hash\"])') &&
  [[ \$('$bin' replay remap.mlog --graph default --hash) == \$h ]]"
check "the remap changes the motion (other final hash than the default map)" bash -c "
  '$bin' record --graph default --program '$src/config/programs/actions.prog' -o plain.mlog --json >plain.json &&
  [[ \$(python3 -c 'import json; print(json.load(open(\"plain.json\"))[\"final_hash\"])') != \$(python3 -c 'import json; print(json.load(open(\"rec.json\"))[\"final_hash\"])') ]]"
printf '[motion_graph.buttons]\nsouth = 1\n' >typo.toml
expect_error "a non-string button value is a config error" 2 "typo.toml:2: motion_graph.buttons.south: expected a label name" \
  "$bin" gait-eval --program builtin:slow_walk --config typo.toml

# 3. stale graph rebuild (needs the shared CMU clips)
mocap=${MARIONETTE_MOCAP_DIR:-$src/../shared/data/mocap}
if [[ -d $mocap/cmu_amc_16 ]]; then
  mkdir -p clips && cp "$mocap/cmu_amc_16/16.asf" "$mocap/cmu_amc_16/16_35.amc" "$mocap/cmu_amc_16/16_41.amc" clips/ && chmod u+w clips/*
  hash_of() { "$bin" graph info "$1" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["source_hash"])'; }
  check "graph build from two copied CMU clips" bash -c "'$bin' graph build --asf clips/16.asf clips/16_35.amc clips/16_41.amc -o small.mgraph >/dev/null"
  before=$(hash_of small.mgraph)
  check "run --graph on a fresh graph does not rebuild it" bash -c "
    '$bin' run --fast --duration 0.5 --graph small.mgraph --input sim:builtin:slow_walk >run1.txt 2>&1 && ! grep -q 'rebuilt' run1.txt && grep -q 'final state hash' run1.txt"
  # Edit one clip: the root x of frame 10 moves by half an ASF length unit.
  python3 - <<'PY'
lines = open('clips/16_35.amc').read().split('\n')
i = lines.index('10') + 1
f = lines[i].split()
f[1] = repr(float(f[1]) + 0.5)
lines[i] = ' '.join(f)
open('clips/16_35.amc', 'w').write('\n'.join(lines))
PY
  check "run --graph on an edited source rebuilds the graph and says why" bash -c "
    '$bin' run --fast --duration 0.5 --graph small.mgraph --input sim:builtin:slow_walk >run2.txt 2>&1 && grep -q 'small.mgraph: stale (source hash $before' run2.txt && grep -q 'rebuilt in' run2.txt && grep -q 'final state hash' run2.txt"
  after=$(hash_of small.mgraph)
  check "the rebuilt file carries a new source hash" test "$before" != "$after"
  check "no temporary file is left beside the graph" bash -c "! ls small.mgraph.tmp* 2>/dev/null"
  check "the rebuilt graph is fresh: a second run does not rebuild" bash -c "
    '$bin' run --fast --duration 0.5 --graph small.mgraph --input sim:builtin:slow_walk >run3.txt 2>&1 && ! grep -q 'rebuilt' run3.txt"
  printf '[motion_graph]\nwindow_frames = 8\n' >k8.toml
  check "changed [motion_graph] build parameters make it stale too" bash -c "
    '$bin' run --fast --duration 0.5 --graph small.mgraph --config k8.toml --input sim:builtin:slow_walk >run4.txt 2>&1 && grep -q 'rebuilt in' run4.txt && [[ \$('$bin' graph info small.mgraph --json | python3 -c 'import json,sys; print(json.load(sys.stdin)[\"window_frames\"])') == 8 ]]"
  printf '[motion_graph]\nwindow_frames = 9\n' >k9.toml
  check "record --graph rebuilds a stale graph too; replay of its log needs the rebuilt file and does not rebuild" bash -c "
    '$bin' record --graph small.mgraph --config k9.toml --program '$src/config/programs/slow_walk.prog' -o k9.mlog >rec9.txt 2>&1 && grep -q 'rebuilt in' rec9.txt &&
    '$bin' replay k9.mlog --graph small.mgraph --hash >rep9.txt 2>&1 && ! grep -q 'rebuilt' rep9.txt"
  cp small.mgraph kept.mgraph
  rm clips/16_41.amc
  check "missing sources: the graph is used as it is, with a warning" bash -c "
    '$bin' run --fast --duration 0.5 --graph small.mgraph --input sim:builtin:slow_walk >run5.txt 2>&1 && grep -q 'warning: small.mgraph: 1 of its source files is missing' run5.txt && cmp small.mgraph kept.mgraph"
else
  echo "skipped the stale-graph checks: no $mocap/cmu_amc_16"
fi

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
