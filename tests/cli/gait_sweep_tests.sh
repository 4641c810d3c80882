#!/usr/bin/env bash
# `gait-eval --sweep` from the command line (issue 13, docs/gait.md "The envelope"):
# the same seed prints the same bytes on every run; --out writes each failing
# case's .prog and .toml, and the plain gait-eval replays them to the same
# metrics; misuse is exit 2 naming the option.
# Usage: gait_sweep_tests.sh MARIONETTE_BINARY SOURCE_DIR
# (The CI sweep itself, 2 × 300 cases that must all pass, is its own CTest entry.)
bin=$(realpath "$1")
src=$(realpath "$2")
source "$src/tests/cli/check_lib.sh"

check "the same seed prints the same JSON on every run" bash -c "
  '$bin' gait-eval --sweep 25 --seed 4 --json >a.json && '$bin' gait-eval --sweep 25 --seed 4 --json >b.json && cmp -s a.json b.json"
check "the summary names cases, passed, failed and the worst value of every metric with its case" python3 -c "
import json
d = json.load(open('a.json'))
assert d['seed'] == 4 and d['cases'] == 25 and d['passed'] + d['failed'] == 25, d
assert len(d['failures']) == d['failed']
for k in ['foot_skate_mm', 'penetration_mm', 'speed_error_pct', 'max_joint_speed_deg_s']:
    w = d['worst'][k]
    assert w['value'] >= 0 and w['case'].startswith('4-') and w['limit'] > 0, (k, w)
assert sum(g['cases'] for g in d['by_ground'].values()) == 25
"
check "a different seed gives other cases" bash -c "
  '$bin' gait-eval --sweep 25 --seed 5 --json >c.json && ! cmp -s a.json c.json"
check "--out writes both files of every failing case, and the plain gait-eval replays them to the same metrics" bash -c "
  '$bin' gait-eval --sweep 25 --seed 4 --out failing --json >out.json && python3 - '$bin' <<'PY'
import json, os, subprocess, sys
d = json.load(open('out.json'))
names = sorted(os.listdir('failing')) if os.path.isdir('failing') else []
expected = sorted([f['case'] + ext for f in d['failures'] for ext in ('.prog', '.toml')])
assert names == expected, (names, expected)
for f in d['failures'][:6]:
    r = subprocess.run([sys.argv[1], 'gait-eval', '--terrain', 'failing/%s.toml' % f['case'],
                        '--program', 'failing/%s.prog' % f['case'], '--json'], capture_output=True, text=True, check=True)
    m = json.loads(r.stdout)
    for k in ['foot_skate_mm', 'penetration_mm', 'max_joint_speed_deg_s']:
        assert m[k] == f[k], (f['case'], k, m[k], f[k])
print('replayed', min(len(d['failures']), 6), 'of', len(d['failures']), 'failing cases')
PY"
expect_error "--sweep with --program is exit 2 naming --sweep" 2 "--sweep" \
  "$bin" gait-eval --sweep 3 --program "$src/config/programs/run.prog"
expect_error "--out without --sweep is exit 2 naming --out" 2 "--out" \
  "$bin" gait-eval --program "$src/config/programs/run.prog" --out x
expect_error "no --program and no --sweep is exit 2 naming --program" 2 "--program" "$bin" gait-eval
expect_error "--sweep 0 is exit 2 naming --sweep" 2 "--sweep: 0: expected a number of cases" "$bin" gait-eval --sweep 0

echo "gait-eval --sweep: $passes passed, $failures failed"
[[ $failures -eq 0 ]]
