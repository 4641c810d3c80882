#!/usr/bin/env bash
# The tuning UI end to end under Xvfb (docs/ui.md): `run` in an SDL window with
# a simulated pad whose program opens the UI by the chord back + start, moves
# the gait's step-length slider with the d-pad, saves with north and closes the
# UI; the saved TOML has the new value and the old comments, the log records
# the edit as a configuration change, and `replay` gives the run's final hash.
# Usage: ui_xvfb_tests.sh MARIONETTE_BINARY
bin=$1
source "$(dirname "${BASH_SOURCE[0]}")/xvfb_common.sh"

cat >tuned.toml <<'TOML'
# my walk, tuned on the screen
[gait]                      # the spline-IK walk
walk_duty = 0.58            # planted a little longer
step_length_multiplier = 0.45   # stride
TOML
cp tuned.toml original.toml
# Presses are 0.8 s apart (any spacing works: presses are queued and each is one
# step however long the frames are; 150 ms taps stay under the 0.5 s repeat delay).
cat >ui.prog <<'PROG'
hold 1s
press back+start 200ms
hold 800ms
press dpad_down 150ms
hold 800ms
press south 150ms
hold 800ms
press dpad_right 150ms
hold 800ms
press dpad_right 150ms
hold 800ms
press south 150ms
hold 800ms
press north 150ms
hold 1s
press back+start 200ms
hold 500ms
ramp 300ms ly=1
hold 1.5s
ramp 300ms ly=0
hold 1s
PROG

run_in_window --input sim:ui.prog --duration 14 --config tuned.toml --record ui.mlog --stats-json stats.json
code=$run_code
check "run under Xvfb exits 0 (got $code)" test $code -eq 0
check "the chord opened the UI" grep -q "^ui: opened" run.txt
# Each tap is exactly one step (app/ui/pad_presses.hpp): two edits, 0.45 -> 0.47 -> 0.49, no other row.
check "the d-pad moved gait.step_length_multiplier up by exactly two steps" \
  bash -c "diff <(grep -E '^ui: [a-z_]+\.[a-z_]+ ' run.txt) <(printf 'ui: gait.step_length_multiplier 0.45 -> 0.47\nui: gait.step_length_multiplier 0.47 -> 0.49\n')"
check "north saved the file" grep -q "^ui: saved 1 edited key(s) to tuned.toml" run.txt
check "the chord closed the UI" grep -q "^ui: closed" run.txt
check "the edit was applied at a tick boundary" grep -q "config: applied before tick" run.txt
value=$(sed -nE 's/^step_length_multiplier = ([0-9.]+)   # stride$/\1/p' tuned.toml)
check "the saved TOML has the new value ($value, expected 0.49) with its comment" test "$value" = 0.49
check "the saved TOML keeps the other lines" bash -c "diff <(grep -v '^step_length_multiplier' original.toml) <(grep -v '^step_length_multiplier' tuned.toml)"
hash=$(sed -E 's/.*"final_hash":"([0-9a-f]+)".*/\1/' stats.json)
check "replay of the recording gives the run's final hash ($hash)" test "$hash" = "$("$bin" replay ui.mlog --hash)"
check "the run says it applied a configuration change" grep -q '"config_changes":[1-9]' stats.json
grep -E "^(ui|config): " run.txt
echo "saved: $(grep '^step_length_multiplier' tuned.toml); final hash $hash"
finish tuned.toml
