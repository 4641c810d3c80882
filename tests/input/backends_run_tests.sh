#!/usr/bin/env bash
# Every input backend end to end in `marionette run` under umockdev: evdev (an
# Xbox 360 pad's event node), hidapi (a DualSense's hidraw node) and SDL2 (the
# DualSense's event node, found through umockdev's udev). sim-pad writes the
# firmware's output for a stick program (evemu events, or raw HID reports) and
# umockdev_script.py turns it into a umockdev script whose first read waits
# until the run has opened the node. For each backend:
#   plain:  umockdev-run plays the script; `run --record --trace`; the recording
#           replays to exactly the run's trace; the puppet walked as the program
#           says (check_walk.py against the simulated controller's trace);
#   replug: umockdev_replug plays the first leg, unplugs the pad (hang-up,
#           "remove" uevent, node removed), plugs one in on the next node ("add")
#           and plays the second leg; the
#           run keeps going, logs both, counts 1 disconnect and 1 reconnect, the
#           replay matches, and each leg went the program's way.
# Usage: backends_run_tests.sh MARIONETTE SOURCE_DIR UMOCKDEV_WRAPPER UMOCKDEV_REPLUG
set -uo pipefail
bin=$1; src=$2; wrapper=$3; replug=$4
if ! command -v umockdev-run >/dev/null; then
  if [[ ${CI:-} == true ]]; then echo "umockdev-run missing (CI installs umockdev)"; exit 1; fi
  echo "umockdev-run not installed: skipped"; exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
data=$src/tests/data/umockdev
failures=0; passes=0
check() {  # check "what" command...
  local what=$1; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAILED: $what"; failures=$((failures + 1)); fi
}
stat_of() { sed -n "s/.*\"$2\":\([0-9]*\).*/\1/p" "$1"; }

# The legs: forward, then (after the unplug) right; the reference plays both
# with the rest between them, and is cut where that rest begins.
printf 'hold 1200ms ly=0.9\nhold 300ms ly=0\n' >leg1.prog
printf 'hold 1200ms lx=0.9\nhold 300ms lx=0\n' >leg2.prog
printf 'hold 1200ms ly=0.9\nhold 3000ms ly=0\nhold 1200ms lx=0.9\nhold 2000ms lx=0\n' >ref.prog
"$bin" run --fast --display headless --input sim:ref.prog --trace ref.csv >/dev/null

# firmware FORMAT PAD PROGRAM OUT LEAD_MS: the umockdev script of a sim-pad run.
# HID reports at 125 Hz: umockdev sleeps before each read, and on a loaded machine
# every sleep overshoots, so fewer reads stretch a program less.
firmware() {
  if [[ $1 == hid ]]; then
    "$bin" sim-pad --format dualsense --rate 125 --program "$3" --out "$4.bin" >/dev/null &&
      python3 "$src/tests/input/umockdev_script.py" hid "$4.bin" "$4" --rate 125 --report-size 64 --lead "$5"
  else
    "$bin" sim-pad --format evemu --pad "$2" --rate 1000 --program "$3" --out "$4.events" >/dev/null &&
      python3 "$src/tests/input/umockdev_script.py" evemu "$4.events" "$4" --lead "$5"
  fi
}

# backend  what the run prints  format  pad  description  node  ioctl  replugged node  sed for the replugged description
for spec in \
  "evdev|evdev|evemu|xbox|xbox.umockdev|/dev/input/event7|xbox.ioctl|/dev/input/event8|s/event7/event8/g;s/input7/input8/g;s/13:71/13:72/;s/MINOR=71/MINOR=72/" \
  "hidapi|hidraw|hid|dualsense|dualsense_hidraw.umockdev|/dev/hidraw0|dualsense_hidraw.ioctl|/dev/hidraw1|" \
  "sdl|sdl|evemu|dualsense|dualsense.umockdev|/dev/input/event9|dualsense.ioctl|/dev/input/event10|s/event9/event10/g;s/input9/input10/g;s/13:73/13:74/;s/MINOR=73/MINOR=74/"; do
  IFS='|' read -r backend shown format pad desc node ioctl node2 rename <<<"$spec"
  b=$backend
  # Plain: the first leg after 2.5 s (the run has opened the node by then, and
  # SDL2 has closed the node it only probed: a pty's last close drops what it holds).
  firmware "$format" "$pad" leg1.prog "$b.plain.script" 2500
  timeout 40 umockdev-run -d "$data/$desc" -i "$node=$data/$ioctl" -s "$node=$b.plain.script" -- \
    "$bin" run --input "$backend" --duration 5.5 --display headless --record "$b.mlog" --trace "$b.csv" \
    --stats-json "$b.json" >"$b.out" 2>"$b.err"
  rc=$?
  check "$b: run exits 0 (rc $rc: $(grep -v WARNING "$b.err" | grep -v '^$' | tail -2))" test $rc -eq 0
  check "$b: run reads the controller through $shown" grep -q "controller ($shown)" "$b.out"
  # evdev sends a frame only when something changed (2 here); hidraw every report (188).
  check "$b: the pad's samples reached the simulation ($(stat_of "$b.json" samples) samples)" \
    test "$(stat_of "$b.json" samples)" -ge "$([[ $format == hid ]] && echo 50 || echo 2)"
  echo "$b plain: $(stat_of "$b.json" samples) samples, $(stat_of "$b.json" ticks) ticks, $(grep -c . "$b.csv") trace lines"
  "$bin" replay "$b.mlog" --trace "$b.replay.csv" >/dev/null 2>&1
  check "$b: replay of the recording gives exactly the run's trace" cmp -s "$b.csv" "$b.replay.csv"
  check "$b: the puppet walked forward as the program says" \
    python3 "$src/tests/input/check_walk.py" "$b.csv" ref.csv --ref-cuts 3.0 --ref-legs 1
  python3 "$src/tests/input/check_walk.py" "$b.csv" ref.csv --ref-cuts 3.0 --ref-legs 1 | sed "s/^/$b plain: /"

  # Replug: leg 1 (2.5 s lead), unplugged at 7 s (umockdev 0.17 cannot wait for a
  # script to end, and the leg may run late), the next node at 8 s, leg 2 2 s later
  # (SDL2 probes the new node and closes it before it opens it for good).
  firmware "$format" "$pad" leg1.prog "$b.leg1.script" 2500
  firmware "$format" "$pad" leg2.prog "$b.leg2.script" 2000
  if [[ $backend == hidapi ]]; then cp "$data/dualsense_hidraw_replugged.umockdev" "$b.replugged.umockdev"
  else sed "$rename" "$data/$desc" >"$b.replugged.umockdev"; fi
  timeout 60 "$wrapper" "$replug" "$data/$desc" "$node" "$data/$ioctl" "$b.leg1.script" 7 \
    "$b.replugged.umockdev" "$node2" "$b.leg2.script" 8 -- \
    "$bin" run --input "$backend" --duration 13 --display headless --record "$b.r.mlog" --trace "$b.r.csv" \
    --stats-json "$b.r.json" >"$b.r.out" 2>"$b.r.err"
  rc=$?
  check "$b replug: run exits 0 (rc $rc: $(grep -v WARNING "$b.r.err" | grep -v '^$' | tail -2))" test $rc -eq 0
  check "$b replug: the unplug is logged" grep -q "controller disconnected" "$b.r.out"
  check "$b replug: the replug is logged" grep -q "controller connected: resuming" "$b.r.out"
  check "$b replug: 1 disconnect and 1 reconnect counted" \
    test "$(stat_of "$b.r.json" disconnects)/$(stat_of "$b.r.json" reconnects)" = 1/1
  echo "$b replug: $(stat_of "$b.r.json" samples) samples, $(stat_of "$b.r.json" ticks) ticks," \
    "$(stat_of "$b.r.json" disconnects) disconnect(s), $(stat_of "$b.r.json" reconnects) reconnect(s);" \
    "$(grep -E 'controller (dis)?connected' "$b.r.out" | tr '\n' ';')"
  "$bin" replay "$b.r.mlog" --trace "$b.r.replay.csv" >/dev/null 2>&1
  check "$b replug: replay of the recording gives exactly the run's trace" cmp -s "$b.r.csv" "$b.r.replay.csv"
  # Cut the run's travel where the pad went away.
  unplug_s=$(sed -n 's/^\[ *\([0-9.]*\) s\] controller disconnected.*/\1/p' "$b.r.out" | head -1)
  check "$b replug: forward before the unplug, right after the replug, as the program says" \
    python3 "$src/tests/input/check_walk.py" "$b.r.csv" ref.csv --cuts "${unplug_s:-0}" --ref-cuts 3.0
  python3 "$src/tests/input/check_walk.py" "$b.r.csv" ref.csv --cuts "${unplug_s:-0}" --ref-cuts 3.0 | sed "s/^/$b replug: /"
done

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
