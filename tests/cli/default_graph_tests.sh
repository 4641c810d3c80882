#!/usr/bin/env bash
# `marionette graph build --default` end to end: exports the embedded default
# graph, twice with identical bytes, keeping every label; it loads with
# `graph info` and `graph path` reaches an action; bad combinations exit 2.
# Usage: default_graph_tests.sh MARIONETTE_BINARY SOURCE_DIR
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"

check "graph build --default writes a graph" bash -c "'$bin' graph build --default -o a.mgraph --json >build.json"
check "graph build --default writes a PNG plot and a Graphviz graph" bash -c "'$bin' graph build --default -o p.mgraph --plot m.png --dot g.dot >/dev/null && head -c 8 m.png | od -An -c | grep -q 'P   N   G' && grep -q '^digraph motion_graph' g.dot"
check "graph build --default keeps every label" python3 -c "
import json, sys
d = json.load(open('build.json'))
want = {'walk','run','turn','idle','stop','wave','bow','jump','look_around'}
sys.exit(0 if want <= set(d['labels_kept']) and {'wave','bow','jump','look_around'} <= set(d['clips_kept']) else 1)"
check "graph build --default is byte-identical run to run" bash -c "'$bin' graph build --default -o b.mgraph >/dev/null && cmp a.mgraph b.mgraph"
check "graph info reads the default graph" bash -c "'$bin' graph info a.mgraph --json | grep -q '\"look_around\"'"
check "graph path from idle reaches wave" bash -c "'$bin' graph path a.mgraph --from idle:20 --to wave --json | grep -q '\"found\":true'"
check "record --graph default plays the action program; replay --graph default gives its hash" bash -c "'$bin' record --program '$src/config/programs/actions.prog' --graph default -o act.mlog --json >rec.json && h=\$(python3 -c 'import json; print(json.load(open(\"rec.json\"))[\"final_hash\"])') && [[ \$('$bin' replay act.mlog --graph default --hash) == \$h ]] && [[ \$('$bin' replay act.mlog --graph a.mgraph --hash) == \$h ]]"
check "replay --graph default --bvh writes the graph-driven motion" bash -c "'$bin' replay act.mlog --graph default --bvh act.bvh >/dev/null && grep -q '^MOTION' act.bvh"
check "run --graph default records a live run that replays to its final hash" bash -c "'$bin' run --fast --graph default --input 'sim:$src/config/programs/actions.prog' --record live.mlog >live.txt && h=\$(grep -o 'final state hash [0-9a-f]*' live.txt | sed 's/.*final state hash //') && [[ \$('$bin' replay live.mlog --graph default --hash) == \$h ]]"
expect_error "run --graph with a missing file names it" 2 "nope.mgraph" "$bin" run --fast --graph nope.mgraph --input "sim:$src/config/programs/actions.prog"
check "a log recorded with the default graph replays without --graph (the log names it)" bash -c "[[ \$('$bin' replay act.mlog --hash) == \$(python3 -c 'import json; print(json.load(open(\"rec.json\"))[\"final_hash\"])') ]]"
expect_error "graph build --default refuses clip files" 2 "--default builds the embedded clips" "$bin" graph build --default x.bvh -o c.mgraph
expect_error "graph build without clips or --default" 2 "needs CLIPS" "$bin" graph build -o c.mgraph

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
