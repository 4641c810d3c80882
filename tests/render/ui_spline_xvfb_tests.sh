#!/usr/bin/env bash
# The spline editor end to end under Xvfb (docs/ui.md, "Spline editor"): `run`
# in an SDL window with a simulated pad that opens the UI by the chord, jumps
# with west twice to the spline editor's curve, starts its d-pad mode with south,
# raises the walk's swing-foot key 1 two steps and moves it one step later,
# walks with the left stick while the d-pad mode is on and raises it once more,
# leaves the mode with east, saves with north and closes the UI. The saved TOML
# has the new prototype and its old comments, every edit was applied at a tick
# boundary, the puppet walked between the edits, and `replay` of the recording
# gives the run's final hash.
# Usage: ui_spline_xvfb_tests.sh MARIONETTE_BINARY
bin=$1
source "$(dirname "${BASH_SOURCE[0]}")/xvfb_common.sh"

cat >tuned.toml <<'TOML'
# my walk, tuned on the screen
[gait]                      # the spline-IK walk
walk_duty = 0.58            # planted a little longer

# the walk's prototypes
[gait.walk]   # keys [phase, x, y, z]
swing_foot = [[0.0, 0.0, 0.0, 0.0], [0.2, 0.005, 0.05, 0.1], [0.5, 0.01, 0.075, 0.5], [0.8, 0.005, 0.04, 0.9], [1.0, 0.0, 0.0, 1.0]]   # lift
hand = [[0.0, 0.02, 0.0, -0.12], [0.5, 0.02, 0.03, 0.14], [1.0, 0.02, 0.0, -0.12]]
TOML
cp tuned.toml original.toml

# Taps 0.8 s apart (each is one step however slow the frames, app/ui/pad_presses.hpp).
cat >spline.prog <<'PROG'
hold 1s
press back+start 200ms
hold 800ms
press west 150ms
hold 800ms
press west 150ms
hold 800ms
press south 150ms
hold 800ms
press dpad_up 150ms
hold 800ms
press dpad_up 150ms
hold 800ms
press dpad_right 150ms
hold 800ms
ramp 300ms ly=1
hold 1.5s
press dpad_up 150ms
hold 800ms
ramp 300ms ly=0
hold 800ms
press east 150ms
hold 800ms
press north 150ms
hold 1s
press back+start 200ms
hold 1s
PROG

run_in_window --input sim:spline.prog --duration 16 --config tuned.toml --record spline.mlog --stats-json stats.json
code=$run_code
check "run under Xvfb exits 0 (got $code)" test $code -eq 0
check "the chord opened the UI" grep -q "^ui: opened" run.txt
check "south on the curve started the d-pad mode" grep -q "^ui: spline: the d-pad moves the key" run.txt
expected='ui: gait.walk.swing_foot key 1 -> [0.2, 0.005, 0.055, 0.1]
ui: gait.walk.swing_foot key 1 -> [0.2, 0.005, 0.06, 0.1]
ui: gait.walk.swing_foot key 1 -> [0.21, 0.005, 0.06, 0.1]
ui: gait.walk.swing_foot key 1 -> [0.21, 0.005, 0.065, 0.1]'
check "each tap moved the key by exactly one step, no other key or slider moved" \
  bash -c "diff <(grep -E '^ui: [a-z_]+\.[a-z_.]+ ' run.txt) <(printf '%s\n' '$expected')"
check "north saved the file" grep -q "^ui: saved 1 edited key(s) to tuned.toml" run.txt
check "the chord closed the UI" grep -q "^ui: closed" run.txt
line='swing_foot = [[0.0, 0.0, 0.0, 0.0], [0.21, 0.005, 0.065, 0.1], [0.5, 0.01, 0.075, 0.5], [0.8, 0.005, 0.04, 0.9], [1.0, 0.0, 0.0, 1.0]]   # lift'
check "the saved TOML has the new prototype with its comment" grep -qxF "$line" tuned.toml
check "the saved TOML keeps every other line" bash -c "diff <(grep -v '^swing_foot' original.toml) <(grep -v '^swing_foot' tuned.toml)"
# Four edits, each applied at a tick boundary; the puppet walked between the third and the fourth.
mapfile -t ticks < <(sed -nE 's/.*config: applied before tick ([0-9]+).*/\1/p' run.txt)
check "four edits applied at tick boundaries (${ticks[*]})" test "${#ticks[@]}" -ge 4
hash=$(sed -E 's/.*"final_hash":"([0-9a-f]+)".*/\1/' stats.json)
check "replay of the recording gives the run's final hash ($hash)" test "$hash" = "$("$bin" replay spline.mlog --hash --trace trace.csv)"
if [[ ${#ticks[@]} -ge 4 ]]; then
  walked=$(awk -F, -v a="${ticks[2]}" -v b="${ticks[3]}" \
    '$1 == a { x = $3; z = $5 } $1 == b { printf "%.2f", sqrt(($3 - x) ^ 2 + ($5 - z) ^ 2) }' trace.csv)
  check "the puppet kept walking while the key was edited (${walked:-?} m between the 3rd and 4th edit)" \
    awk -v d="${walked:-0}" 'BEGIN { exit !(d > 0.5) }'
fi
grep -E "^(ui|config): |config: applied" run.txt
finish tuned.toml
