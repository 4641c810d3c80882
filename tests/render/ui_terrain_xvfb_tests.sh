#!/usr/bin/env bash
# The terrain editor end to end under Xvfb (docs/ui.md, "Terrain editor"): `run`
# in an SDL window with a simulated pad that opens the UI by the chord, jumps to
# the [terrain] editor with west, adds a box under the puppet with south, steps
# down to "Save terrain" and presses it, closes the UI and walks onto the box. The edit is applied at a tick boundary and recorded,
# `replay` of the recording gives the run's final hash, and the saved terrain
# file holds the stairs' boxes plus the new one.
# Usage: ui_terrain_xvfb_tests.sh MARIONETTE_BINARY SOURCE_DIR
bin=$1
src=$2
source "$(dirname "${BASH_SOURCE[0]}")/xvfb_common.sh"

# West jumps to the terrain editor (opened, the pad on "add box"); each tap is
# one step however slow the frames (app/ui/pad_presses.hpp); eight downs reach
# "Save terrain" (box, box size, slope, slope grade, two sliders, heightfield, Save).
cat >terrain.prog <<'PROG'
hold 1s
press back+start 200ms
hold 800ms
press west 150ms
hold 800ms
press south 150ms
hold 500ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press dpad_down 150ms
hold 300ms
press south 150ms
hold 1s
press back+start 200ms
hold 500ms
ramp 300ms ly=1
hold 1.5s
ramp 300ms ly=0
hold 1s
PROG

run_in_window --input sim:terrain.prog --duration 16 --record terrain.mlog --stats-json stats.json
code=$run_code
check "run under Xvfb exits 0 (got $code)" test $code -eq 0
check "the chord opened the UI" grep -q "^ui: opened" run.txt
check "the pad added a box under the puppet" grep -q "^ui: terrain: added box [0-9]* under the puppet" run.txt
check "no slider moved on the way down" bash -c "! grep -qE '^ui: [a-z_]+\.[a-z_]+ ' run.txt"
check "the edit was applied at a tick boundary, one more box" grep -qE "config: applied before tick [0-9]+: terrain 63 box\(es\), 0 slope\(s\), heightfield 0x0 → 64 box\(es\)" run.txt
check "Save terrain wrote marionette-terrain.toml" grep -q "^ui: saved the terrain .* to marionette-terrain.toml" run.txt
boxes=$(grep -c '^\[\[box\]\]' marionette-terrain.toml 2>/dev/null)
stairs=$(grep -c '^\[\[box\]\]' "$src/config/terrain/stairs.toml")
check "the saved terrain has the stairs' boxes plus one ($boxes, stairs $stairs)" test "$boxes" -eq $((stairs + 1))
hash=$(sed -E 's/.*"final_hash":"([0-9a-f]+)".*/\1/' stats.json)
check "replay of the recording gives the run's final hash ($hash)" test "$hash" = "$("$bin" replay terrain.mlog --hash)"
check "the run says it applied a configuration change" grep -q '"config_changes":[1-9]' stats.json
# Save terrain named the file in the configuration Save writes (no --config
# here: marionette-tuned.toml), so a restart with it starts on the edited ground:
# standing at the start, the puppet is higher by about the new box's 0.1 m.
check "Save terrain wrote [terrain] name into marionette-tuned.toml" grep -q '^name = "marionette-terrain.toml"' marionette-tuned.toml
printf 'hold 1s\n' >stand.prog
stand_height() {  # root height at the last tick of a 1 s headless stand, with ARGS
  HOME=$work/home XDG_CONFIG_HOME=$work/home/.config "$bin" run --display headless --input sim:stand.prog --duration 1 \
    --record stand.mlog "$@" >/dev/null 2>&1 && "$bin" replay stand.mlog --trace stand.csv >/dev/null && tail -1 stand.csv | cut -d, -f4
}
before=$(stand_height)
after=$(stand_height --config marionette-tuned.toml)
check "run --config marionette-tuned.toml starts on the saved terrain (root y $before -> $after)" \
  awk -v a="$before" -v b="$after" 'BEGIN { exit !(a != "" && b != "" && b - a > 0.05 && b - a < 0.15) }'
grep -E "^(ui|config): |config: applied" run.txt
finish marionette-tuned.toml
