#!/usr/bin/env bash
# Key-pose graphs end to end on the shared CMU subject-16 clips
# (docs/motion-graph.md, "Key-pose graphs"): build, deterministic bytes, XML
# export / --from-xml round trip, a cross-clip path with its BVH, and every
# refusal with its exit code and message. Skipped (77) without the shared
# folder unless CI=true.
# Usage: key_pose_tests.sh MARIONETTE_BINARY SOURCE_DIR
bin=$1
src=$2
dir=${MARIONETTE_MOCAP_DIR:-$src/../shared/data/mocap}
if [[ ! -d $dir/cmu_amc_16 ]]; then
  if [[ ${CI:-} == true ]]; then echo "no mocap folder $dir"; exit 1; fi
  echo "no mocap folder $dir: skipped"; exit 77
fi
source "$src/tests/cli/check_lib.sh"
m=$dir/cmu_amc_16
clips=("$m"/16_*.amc)

check "graph build --key-poses writes a key-pose graph" bash -c "'$bin' graph build --key-poses --asf '$m/16.asf' ${clips[*]} -o kp.xml --json >b.json && python3 -c \"
import json, sys
d = json.load(open('b.json'))
sys.exit(0 if d['key_poses'] > 30 and d['edges'] > d['key_poses'] and d['link_threshold'] > d['thin_threshold'] else 1)\""
check "two builds give the same bytes" bash -c "'$bin' graph build --key-poses --asf '$m/16.asf' ${clips[*]} -o kp2.xml >/dev/null && cmp kp.xml kp2.xml"
check "graph export --xml gives the same text" bash -c "'$bin' graph export kp.xml --xml e.xml >/dev/null && cmp kp.xml e.xml"
check "graph build --from-xml gives the same text" bash -c "'$bin' graph build --from-xml kp.xml -o f.xml >/dev/null && cmp kp.xml f.xml"
# Two poses of different clips in one component, and two in different components (of a sparse graph).
pick() {  # pick FILE same|apart -> "A B"
  python3 - "$1" "$2" <<'PY'
import re, sys
t = open(sys.argv[1]).read()
clip = re.findall(r'<pose id="\d+" clip="([^"]*)"', t)
parent = list(range(len(clip)))
def root(x):
    while parent[x] != x: x = parent[x]
    return x
for a, b in re.findall(r'<edge from="(\d+)" to="(\d+)"', t):
    ra, rb = root(int(a)), root(int(b))
    parent[max(ra, rb)] = min(ra, rb)
for a in range(len(clip)):
    for b in range(len(clip) - 1, a, -1):
        if (sys.argv[2] == 'same') == (root(a) == root(b)) and clip[a] != clip[b]:
            print(a, b); sys.exit(0)
sys.exit(1)
PY
}
read -r a b < <(pick kp.xml same)
check "a path between poses of two clips, written as BVH, without pops" bash -c "'$bin' graph path kp.xml --from $a --to $b --bvh p.bvh --json >p.json && grep -q '^MOTION' p.bvh && python3 -c \"
import json, sys
d = json.load(open('p.json'))
clips = {p['clip'] for p in d['poses']}
sys.exit(0 if d['found'] and len(clips) >= 2 and d['largest_move'] <= 4 * d['p95_move'] else 1)\""
"$bin" graph build --key-poses --asf "$m/16.asf" "${clips[@]}" --link-percentile 5 -o sparse.xml >/dev/null
read -r c d < <(pick sparse.xml apart)
expect_error "no path is reported cleanly (exit 1)" 1 "no path from key pose $c" "$bin" graph path sparse.xml --from "$c" --to "$d"
expect_error "an unknown pose id is refused" 2 "--to: unknown key-pose id 999: the graph has poses 0.." "$bin" graph path kp.xml --from 0 --to 999
expect_error "an unknown clip is refused" 2 "no key pose of a clip named 'nope'" "$bin" graph path kp.xml --from nope:3 --to 0
head -c 3000 kp.xml >cut.xml
expect_error "truncated XML is refused naming file and line" 2 "cut.xml:" "$bin" graph export cut.xml --xml x.xml
sed 's/<edge from="\([0-9]*\)" to="[0-9]*"/<edge from="\1" to="5000"/' kp.xml >badid.xml
expect_error "an edge to an unknown pose id is refused" 2 "unknown pose id 5000" "$bin" graph build --from-xml badid.xml -o x.xml
expect_error "a link threshold below the thinning one is refused" 2 "must be above the thinning threshold" "$bin" graph build --key-poses --asf "$m/16.asf" "${clips[@]}" --thin 0.5 --link 0.1 -o x.xml
expect_error "--from-xml with CLIPS is refused" 2 "give no CLIPS" "$bin" graph build --from-xml kp.xml "${clips[0]}" -o x.xml

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
