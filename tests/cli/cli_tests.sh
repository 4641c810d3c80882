#!/usr/bin/env bash
# End-to-end checks of the `marionette` command: record/replay exactness, run vs
# replay traces, truncated logs, exports, and error messages for bad input.
# Usage: cli_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"

for program in stand_still walk_stop circle demo slow_walk fast_walk run start_stop full_circle reversals stop_mid_step; do
  "$bin" record --program "$src/config/programs/$program.prog" -o "$program.mlog" --json >rec.json
  rec_hash=$(sed -E 's/.*"final_hash":"([0-9a-f]+)".*/\1/' rec.json)
  h1=$("$bin" replay "$program.mlog" --hash)
  h2=$("$bin" replay "$program.mlog" --hash)
  check "$program: replay hash equals the recorded run's" test "$h1" = "$rec_hash"
  check "$program: two replays agree" test "$h1" = "$h2"
  "$bin" replay "$program.mlog" --trace "$program.csv" >/dev/null
  check "$program: trace equals the committed golden trace" cmp -s "$program.csv" "$src/tests/golden/$program.trace.csv"
done

# A live run's trace and the replay of its recording are byte-identical.
"$bin" run --fast --input "sim:$src/config/programs/walk_stop.prog" --display headless --record run.mlog --trace a.csv >run.txt
check "run exits 0 and reports" grep -q "demo finished" run.txt
"$bin" replay run.mlog --trace b.csv >/dev/null
check "run --trace equals replay --trace" cmp -s a.csv b.csv
check "run --trace has one row per tick plus a header" test "$(wc -l <a.csv)" -eq 1621

# --duration and the built-in demo.
"$bin" run --fast --duration 2 >dur.txt
check "run --duration 2 runs 480 ticks" grep -q "480 ticks" dur.txt

# Exports.
"$bin" replay walk_stop.mlog --joints-csv joints.csv --bvh perf.bvh --json >summary.json
check "joints csv header names every joint" grep -q '^tick,pelvis.x,pelvis.y,pelvis.z,spine_01.x' joints.csv
check "joints csv has a row per tick" test "$(wc -l <joints.csv)" -eq 1621
"$bin" clip info perf.bvh --json >perf.json
check "the exported BVH imports with one frame per tick" grep -q '"frames":1620' perf.json
check "the exported BVH has the puppet's 22 joints" grep -q '"joints":22' perf.json
check "json summary has ticks and hash" grep -q '"ticks":1620,"tick_rate_hz":240' summary.json

# Truncated logs replay up to their last good chunk, with a warning naming the byte.
size=$(stat -c %s demo.mlog)
head -c $((size / 2)) demo.mlog >half.mlog
"$bin" replay half.mlog --json >half.json 2>half.err
check "truncated log replays (exit 0)" test $? -eq 0
check "truncated log warns with a byte offset" grep -q "truncated or corrupt at byte" half.err
check "truncated log replays some ticks" grep -qE '"ticks":[1-9][0-9]*' half.json

# Bad input: clear errors, exit code 2, never a crash.
head -c 10 demo.mlog >tiny.mlog
expect_error "too-short log" 2 "tiny.mlog: at byte 0: file is too short" "$bin" replay tiny.mlog
printf 'not a log at all, just some text that is long enough' >text.mlog
expect_error "not a log" 2 "not a marionette input log" "$bin" replay text.mlog
expect_error "missing log" 2 "cannot open file" "$bin" replay nonexistent.mlog
printf '[locomotion]\nmax_speed = "fast"\n' >bad.toml
expect_error "bad config value" 2 "bad.toml:2: locomotion.max_speed: expected a number" "$bin" record --program "$src/config/programs/circle.prog" -o x.mlog --config bad.toml
printf 'hold 1s\nwalk 2s\n' >bad.prog
expect_error "bad program" 2 "bad.prog:2: unknown command 'walk'" "$bin" record --program bad.prog -o x.mlog
expect_error "unknown clip format" 2 "unknown clip format" "$bin" clip info bad.prog
expect_error "frame out of range" 2 "frame 5000 is out of range" "$bin" clip fk perf.bvh --frame 5000
expect_error "bad command line" 106 "--frame is required" "$bin" clip fk perf.bvh
expect_error "no subcommand" 106 "subcommand" "$bin"

# Motion graph (docs/motion-graph.md): the build command on the shared CMU
# subject-16 clips, info, paths between kept clips, BVH export, and bad input.
mocap=${MARIONETTE_MOCAP_DIR:-$src/../shared/data/mocap}
if [[ -d $mocap/cmu_amc_16 ]]; then
  "$bin" graph build --asf "$mocap/cmu_amc_16/16.asf" "$mocap"/cmu_amc_16/*.amc -o cmu16.mgraph --json --dot g.dot --plot m.png >build.json
  check "graph build --json has the issue's keys" python3 -c "import json,sys; d=json.load(open('build.json')); sys.exit(0 if all(k in d for k in ['frames','candidates','nodes_before','edges_before','nodes','edges','frames_kept_pct','clips_kept','build_seconds','peak_rss_mb']) else 1)"
  check "graph build keeps walk, run and turn clips" python3 -c "import json,sys; k=json.load(open('build.json'))['clips_kept']; sys.exit(0 if {'16_15','16_35','16_17','16_41'} <= set(k) else 1)"
  check "graph build writes a PNG plot" bash -c "head -c 8 m.png | od -An -c | grep -q 'P   N   G'"
  check "graph build writes a Graphviz graph" grep -q '^digraph motion_graph' g.dot
  check "graph build is byte-identical run to run (no build time in the file)" bash -c "'$bin' graph build --asf '$mocap/cmu_amc_16/16.asf' '$mocap'/cmu_amc_16/*.amc -o cmu16b.mgraph >/dev/null && cmp cmu16.mgraph cmu16b.mgraph"
  "$bin" graph info cmu16.mgraph --json >info.json
  check "graph info claims no build time (the file stores none)" python3 -c "import json,sys; sys.exit(0 if 'build_seconds' not in json.load(open('info.json')) else 1)"
  check "graph info reports the pruned graph" python3 -c "import json,sys; a=json.load(open('info.json')); b=json.load(open('build.json')); sys.exit(0 if a['nodes']==b['nodes'] and a['edges']==b['edges'] else 1)"
  check "graph path finds a walk → run path and writes its BVH" bash -c "'$bin' graph path cmu16.mgraph --from 16_15:40 --to 16_35:20 --json --bvh path.bvh >path.json"
  check "the path BVH imports, on the puppet's skeleton (clips retargeted on load)" bash -c "'$bin' clip info path.bvh --json | grep -q '\"joints\":22'"
  check "graph path reaches a label" bash -c "'$bin' graph path cmu16.mgraph --from 16_41:20 --to walk --json | grep -q '\"found\":true'"
  expect_error "graph path: unknown label" 2 "neither CLIP:FRAME nor a label" "$bin" graph path cmu16.mgraph --from 16_15:40 --to dance
  expect_error "graph path: frame out of range" 2 "expected a 0-based frame index" "$bin" graph path cmu16.mgraph --from 16_15:9999 --to walk
  head -c 100 cmu16.mgraph >cut.mgraph
  expect_error "graph info: truncated graph" 2 "cut.mgraph: at byte 24" "$bin" graph info cut.mgraph
  expect_error "graph build: AMC without skeleton" 2 "needs its skeleton" "$bin" graph build "$mocap/cmu_amc_16/16_15.amc" -o x.mgraph
  expect_error "graph build --keep-skeleton: mixed skeletons" 2 "skeleton differs" "$bin" graph build --keep-skeleton --asf "$mocap/cmu_amc_16/16.asf" "$mocap/cmu_amc_16/16_15.amc" "$mocap/cmu_bvh_131/131_01.bvh" -o x.mgraph
  check "graph build: mixed skeletons are retargeted onto the puppet" bash -c "'$bin' graph build --asf '$mocap/cmu_amc_16/16.asf' '$mocap/cmu_amc_16/16_15.amc' '$mocap/cmu_amc_16/16_35.amc' '$mocap/cmu_bvh_131/131_01.bvh' -o mixed.mgraph >/dev/null && '$bin' graph info mixed.mgraph --json | grep -q '\"joints\":22'"
  # Retargeting (docs/retarget.md): chains and per-bone agreement in --json.
  "$bin" clip retarget "$mocap/cmu_bvh_131/131_01.bvh" -o rt.bvh --json >rt.json
  check "clip retarget: every bone agrees with the source (mean cos >= 0.97), contacts kept" python3 -c "import json,sys; d=json.load(open('rt.json')); sys.exit(0 if d['chains']['thigh_l']=='LeftHip' and all(b['mean_cos']>=0.97 for b in d['bones']) and d['contacts']['max_drift_m']<0.003 else 1)"
  check "clip retarget writes the puppet's skeleton" bash -c "'$bin' clip info rt.bvh --json | grep -q '\"joints\":22'"
  printf '[retarget]\nknee = "LeftLeg"\n' >bad_map.toml
  expect_error "clip retarget: bad map file" 2 "bad_map.toml:2: retarget.knee: unknown role" "$bin" clip retarget "$mocap/cmu_bvh_131/131_01.bvh" --map bad_map.toml -o x.bvh
fi

echo "cli: $passes passed, $failures failed"
[[ $failures -eq 0 ]]
