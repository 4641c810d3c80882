#!/usr/bin/env bash
# The terrain editor end to end under Xvfb (docs/ui.md, "Terrain editor"): `run`
# in an SDL window with a simulated pad that opens the UI by the chord, jumps to
# the [terrain] editor with west, adds a box under the puppet with south, steps
# down to "Save terrain" and presses it, closes the UI and walks onto the box. The edit is applied at a tick boundary and recorded,
# `replay` of the recording gives the run's final hash, and the saved terrain
# file holds the stairs' boxes plus the new one.
# Usage: ui_terrain_xvfb_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -u
bin=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
passes=0
failures=0
check() {
  local what=$1
  shift
  if "$@"; then passes=$((passes + 1)); else failures=$((failures + 1)); echo "FAIL: $what"; fi
}
if ! command -v xvfb-run >/dev/null; then
  echo "xvfb-run is not installed (scripts/setup.sh installs it)"
  exit 1
fi
mkdir -p home/.config/marionette
printf '[display]\nwidth = 640\nheight = 400\nmsaa_samples = 0\n' >home/.config/marionette/render.toml

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

HOME=$work/home XDG_CONFIG_HOME=$work/home/.config LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a -s "-screen 0 800x600x24" "$bin" run --display window --input sim:terrain.prog --duration 16 \
  --record terrain.mlog --stats-json stats.json >run.txt 2>run.err
code=$?
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
grep -E "^(ui|config): |config: applied" run.txt
if ((failures > 0)); then
  echo "--- run.txt"; cat run.txt; echo "--- run.err"; cat run.err
fi
echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
