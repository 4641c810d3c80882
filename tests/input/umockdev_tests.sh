#!/usr/bin/env bash
# The evdev backend and `marionette input monitor` on simulated pads under
# umockdev: sim-pad writes an evemu event stream from a stick program, and
# umockdev-run plays it through a device and ioctl description of an Xbox 360
# pad (xpad) and a DualSense (hid-playstation), so the real libevdev code path
# runs without hardware. check_monitor.py checks every printed sample against
# the stream independently.
# Usage: umockdev_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$1
src=$2
if ! command -v umockdev-run >/dev/null; then
  if [[ ${CI:-} == true ]]; then echo "umockdev-run missing (CI installs umockdev)"; exit 1; fi
  echo "umockdev-run not installed: skipped"; exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
failures=0
passes=0
check() {  # check "what" command...
  local what=$1; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAILED: $what"; failures=$((failures + 1)); fi
}
data=$src/tests/data/umockdev
program=$src/tests/data/programs/umockdev_pad.prog

for pad in xbox dualsense; do
  node=$(sed -n 's/^N: input\/\(event[0-9]*\)$/\1/p' "$data/$pad.umockdev")
  "$bin" sim-pad --format evemu --pad "$pad" --rate 1000 --program "$program" \
    --faults syn_dropped=800ms --out "$pad.events" >sim.txt
  check "$pad: sim-pad reports one SYN_DROPPED" grep -q "SYN_DROPPED 1" sim.txt
  # Every SYN_REPORT frame, plus the state re-read after SYN_DROPPED.
  expected=$(python3 "$src/tests/input/check_monitor.py" --expected-count "$pad.events")
  timeout 20 umockdev-run -d "$data/$pad.umockdev" -i "/dev/input/$node=$data/$pad.ioctl" \
    -e "/dev/input/$node=$pad.events" -- \
    "$bin" input monitor --device "/dev/input/$node" --raw --json --count "$expected" --timeout 5 \
    >"$pad.json" 2>"$pad.err"
  rc=$?
  check "$pad: monitor exits 0 after $expected samples (rc $rc: $(grep -v WARNING "$pad.err" | grep -v '^$' | tail -2))" test $rc -eq 0
  check "$pad: monitor names the pad" grep -q "input: evdev: /dev/input/$node" "$pad.err"
  check "$pad: monitor resynchronised after SYN_DROPPED" grep -q "1 SYN_DROPPED resynchronised" "$pad.err"
  check "$pad: every sample matches the event stream" python3 "$src/tests/input/check_monitor.py" "$pad.events" "$pad.json"
  # The press shorter than a tick is its own frame; a full-left-down stick reads -1.
  check "$pad: the 1 ms south press is seen" test "$(grep -c '"buttons":\["south"\]' "$pad.json")" -ge 1
  check "$pad: d-pad up is seen" grep -q '"dpad_up"' "$pad.json"
  check "$pad: full deflection reads -1" grep -q '"lx":-1,"ly":-1' "$pad.json"
  check "$pad: right trigger reads 1" grep -q '"rt":1' "$pad.json"

  # Without --raw the [evdev] calibration's deadzone applies: small values vanish.
  timeout 20 umockdev-run -d "$data/$pad.umockdev" -i "/dev/input/$node=$data/$pad.ioctl" \
    -e "/dev/input/$node=$pad.events" -- \
    "$bin" input monitor --backend evdev --json --count "$expected" --timeout 5 >"$pad.cal.json" 2>/dev/null
  check "$pad: backend auto-discovers the pad under /dev/input" test "$(wc -l <"$pad.cal.json")" -eq "$expected"
done

# The SDL2 GameController backend on the same test bed: SDL finds the pad through
# libudev (which umockdev fakes too), reads its ids and opens it as a game
# controller with its built-in mapping. (Its event delivery is checked in
# backends_run_tests.sh: SDL opens the node more than once, and what umockdev's
# evemu replay sends before SDL's probe closes the node is lost, so there the
# events wait until SDL has opened it for good.)
timeout 20 umockdev-run -d "$data/dualsense.umockdev" -i "/dev/input/event9=$data/dualsense.ioctl" -- \
  "$bin" input monitor --backend sdl --raw --json --timeout 0.5 >sdl.json 2>sdl.err
check "sdl: SDL2 opens the DualSense as a game controller ($(grep -v WARNING sdl.err | grep -v '^$' | head -1))" \
  grep -q 'input: sdl: 1 joystick(s), 0 mapping(s) loaded, using "PS5 Controller"' sdl.err

# `marionette run --input evdev` on the Xbox pad: the pad's samples drive the
# live pipeline for --duration, the recording replays to the run's own trace,
# and the puppet walks while the stream holds the stick forward.
"$bin" sim-pad --format evemu --pad xbox --rate 1000 --program "$src/tests/data/programs/umockdev_walk.prog" \
  --out walk.events >/dev/null
timeout 30 umockdev-run -d "$data/xbox.umockdev" -i "/dev/input/event7=$data/xbox.ioctl" \
  -e "/dev/input/event7=walk.events" -- \
  "$bin" run --input evdev --duration 2 --display headless --record r.mlog --trace a.csv >run.txt 2>run.err
rc=$?
check "run --input evdev exits 0 after --duration (rc $rc: $(grep -v WARNING run.err | grep -v '^$' | tail -2))" \
  test $rc -eq 0
check "run --input evdev names the pad" grep -q "controller (evdev)" run.txt
check "run --input evdev traced every tick of 2 s" test "$(($(wc -l <a.csv) - 1))" -ge 400
"$bin" replay r.mlog --trace b.csv >/dev/null 2>&1
check "replay of the evdev run matches its trace" cmp -s a.csv b.csv
# The root position (columns 3-5) of the first and last ticks differ: it walked.
check "the puppet moved when the stick was pushed" \
  test "$(sed -n 2p a.csv | cut -d, -f3-5)" != "$(tail -1 a.csv | cut -d, -f3-5)"

# `input list` sees both pads at once.
timeout 20 umockdev-run -d "$data/xbox.umockdev" -d "$data/dualsense.umockdev" \
  -i "/dev/input/event7=$data/xbox.ioctl" -i "/dev/input/event9=$data/dualsense.ioctl" -- \
  "$bin" input list --json >list.json 2>/dev/null
check "input list finds the Xbox pad" grep -q '"path":"/dev/input/event7","name":"Microsoft X-Box 360 pad","vendor_id":"045e","product_id":"028e"' list.json
check "input list finds the DualSense" grep -q '"name":"Sony Interactive Entertainment DualSense Wireless Controller","vendor_id":"054c"' list.json

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
