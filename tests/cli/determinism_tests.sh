#!/usr/bin/env bash
# Logs that say what recorded them and what they need (docs/determinism.md):
# checkpoints verified on replay, an altered checkpoint stops the replay at its
# tick with exit 3, --no-verify replays on, and a log recorded with the default
# graph or a graph file replays (and renders) without --graph.
# Usage: determinism_tests.sh MARIONETTE_BINARY SOURCE_DIR
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"

"$bin" record --program "$src/config/programs/circle.prog" -o circle.mlog >/dev/null
check "replay --json verifies every checkpoint (one per 240 ticks and the last)" python3 -c "
import json, subprocess, sys
d = json.loads(subprocess.check_output(['$bin', 'replay', 'circle.mlog', '--json']))
sys.exit(0 if d['checkpoints'] >= 5 and d['checkpoints_verified'] == d['checkpoints'] and d['recorded_by'].startswith('marionette ') else 1)"
check "an altered checkpoint still decodes (the patcher fixed its CRC)" bash -c "python3 '$src/tests/cli/alter_checkpoint.py' circle.mlog altered.mlog 1 >tick.txt && [[ \$(cat tick.txt) == 480 ]]"
expect_error "replay of an altered checkpoint names the tick and exits 3" 3 "diverged from the recording at tick 480" "$bin" replay altered.mlog
expect_error "the desync message names the recording build" 3 "recorded by: marionette" "$bin" replay altered.mlog
check "replay --no-verify replays an altered log to its end" bash -c "'$bin' replay altered.mlog --no-verify --json | grep -q '\"checkpoints_verified\":0'"
check "record --graph default: replay and render need no --graph" bash -c "'$bin' record --program '$src/config/programs/actions.prog' --graph default -o act.mlog --json >rec.json && h=\$(python3 -c 'import json; print(json.load(open(\"rec.json\"))[\"final_hash\"])') && [[ \$('$bin' replay act.mlog --hash) == \$h ]] && '$bin' render act.mlog --out frames --from 1 --to 1.1 --fps 10 >/dev/null && ls frames | grep -q frame_"
"$bin" graph build --default -o mine.mgraph >/dev/null
check "record --graph FILE: replay finds the file by its recorded path" bash -c "'$bin' record --program '$src/config/programs/walk_stop.prog' --graph mine.mgraph -o file.mlog >/dev/null && mkdir -p elsewhere && cd elsewhere && '$bin' replay ../file.mlog --json | grep -q '\"checkpoints_verified\"'"
mv mine.mgraph moved.mgraph
expect_error "a log whose graph file is gone names the graph to pass" 2 "pass that graph with --graph" "$bin" replay file.mlog
check "--graph still overrides what the log names" bash -c "'$bin' replay file.mlog --graph moved.mgraph --hash >/dev/null"

check "run --record writes checkpoints that its replay verifies" bash -c "'$bin' run --fast --duration 5 --input 'sim:$src/config/programs/circle.prog' --display headless --record live.mlog >/dev/null && python3 -c \"
import json, subprocess, sys
d = json.loads(subprocess.check_output(['$bin', 'replay', 'live.mlog', '--json']))
sys.exit(0 if d['checkpoints'] >= 5 and d['checkpoints_verified'] == d['checkpoints'] else 1)\""
check "run --graph default --record: replay needs no --graph" bash -c "'$bin' run --fast --duration 3 --graph default --input 'sim:$src/config/programs/actions.prog' --display headless --record live_graph.mlog >live.txt && h=\$(grep -o 'final state hash [0-9a-f]*' live.txt | sed 's/.*final state hash //') && [[ \$('$bin' replay live_graph.mlog --hash) == \$h ]]"

# A version 1 log (recorded before checkpoints existed, its configuration text
# with the [realtime] and graph-build keys of that time) still replays: to the
# same final state as the same program recorded now.
"$bin" record --program "$src/config/programs/walk_stop.prog" -o walk_v2.mlog >/dev/null
check "a version 1 log replays like a fresh recording of the same program" bash -c "[[ \$('$bin' replay '$src/tests/data/logs/walk_stop_v1.mlog' --hash) == \$('$bin' replay walk_v2.mlog --hash) ]]"
check "a version 1 log has no checkpoints to verify" bash -c "'$bin' replay '$src/tests/data/logs/walk_stop_v1.mlog' --json | grep -q '\"checkpoints\":0,\"checkpoints_verified\":0,\"recorded_by\":null'"

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
