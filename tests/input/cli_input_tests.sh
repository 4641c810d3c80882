#!/usr/bin/env bash
# End-to-end checks of `marionette sim-pad` and `marionette input decode`:
# rates, byte-exact decoding of the four formats, faults, and error messages.
# Usage: cli_input_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"

cat >known.prog <<'P'
hold 10ms lx=1 ly=-1 rx=-1 ry=1 lt=1 rt=0
press south 10ms
press dpad_up 10ms
hold 10ms lx=0 ly=0 rx=0 ry=0 lt=0
P

for format in ds4 dualsense switchpro steamdeck; do
  for rate in 125 1000 8000; do
    "$bin" sim-pad --format $format --rate $rate --program builtin:walk_stop --out $format.$rate.bin >/dev/null
    # walk_stop lasts 6.75 s: rate * 6.75 reports of 64 bytes.
    want=$(python3 -c "print(round($rate * 6.75) * 64)")
    check "$format at $rate Hz: $want bytes" test "$(stat -c %s $format.$rate.bin)" -eq "$want"
  done
  "$bin" sim-pad --format $format --rate 1000 --program known.prog --out $format.bin --json >sum.json
  check "$format: summary counts 40 reports" grep -q '"reports":40' sum.json
  "$bin" input decode --format $format $format.bin --json >$format.json 2>dec.err
  check "$format: decode exits 0 and decodes 40 reports" grep -q "40 reports decoded, 0 rejected" dec.err
  check "$format: 40 JSON lines" test "$(wc -l <$format.json)" -eq 40
  first=$(head -1 $format.json)
  check "$format: full deflections decode exactly ($first)" grep -q '"lx":1,"ly":-1,"rx":-1,"ry":1,"lt":1,"rt":0,"buttons":\[\]' <<<"$first"
  check "$format: south press in reports 10-19" test "$(grep -c '"buttons":\["south"\]' $format.json)" -eq 10
  check "$format: d-pad up in reports 20-29" test "$(grep -c '"buttons":\["dpad_up"\]' $format.json)" -eq 10
  check "$format: last report at rest" grep -q '"lx":0,"ly":0,"rx":0,"ry":0,"lt":0,"rt":0,"buttons":\[\]' <<<"$(tail -1 $format.json)"
  check "$format: t_ns follows the report index" grep -q '"t_ns":39000000,' <<<"$(tail -1 $format.json)"

  # Corrupted reports are rejected with their byte offset, the rest decode.
  "$bin" sim-pad --format $format --rate 1000 --program builtin:walk_stop --faults corrupt=0.01,seed=4 --out c.bin --json >c.json
  corrupted=$(sed -E 's/.*"corrupted":([0-9]+).*/\1/' c.json)
  "$bin" input decode --format $format c.bin >/dev/null 2>c.err
  check "$format: every corrupted report rejected ($corrupted)" grep -q "$((6750 - corrupted)) reports decoded, $corrupted rejected" c.err
  check "$format: rejections name the byte" grep -q "c.bin: at byte [0-9]*: report [0-9]* rejected" c.err
done

# Bluetooth reports (78 bytes, CRC) decode the same way.
"$bin" sim-pad --format dualsense --bluetooth --rate 1000 --program known.prog --out bt.bin >/dev/null
check "dualsense bluetooth: 40 reports of 78 bytes" test "$(stat -c %s bt.bin)" -eq $((40 * 78))
"$bin" input decode --format dualsense bt.bin --json >bt.json 2>/dev/null
check "dualsense bluetooth decodes like USB" cmp -s bt.json dualsense.json

# Dropped and duplicated reports show in the device counter.
"$bin" sim-pad --format steamdeck --rate 1000 --program known.prog --faults dup=0.2,seed=3 --out d.bin --json >d.json
dups=$(sed -E 's/.*"duplicated":([0-9]+).*/\1/' d.json)
"$bin" input decode --format steamdeck d.bin --json >d.out 2>/dev/null
check "dup: $dups repeated sequence numbers" test "$(grep -o '"seq":[0-9]*' d.out | uniq -d | wc -l)" -eq "$dups"

# evemu streams.
"$bin" sim-pad --format evemu --pad dualsense --rate 8000 --program known.prog --out pad.events >/dev/null
check "evemu: header names the DualSense" grep -q "^N: Sony Interactive Entertainment DualSense Wireless Controller" pad.events
check "evemu: 4 frames (sticks, press, release + d-pad, d-pad release + rest)" test "$(grep -c ' 0000 0000 0$' pad.events)" -eq 4
check "evemu: ABS_X full right is 255" grep -q "^E: 0.000000 0003 0000 255$" pad.events

# Errors: exit 2 and a message naming what was wrong.
head -c 100 ds4.bin >short.bin
expect_error "decode: a partial report at the end" 2 "short.bin: at byte 64: 36 bytes left, expected a whole 64-byte ds4 report" \
  "$bin" input decode --format ds4 short.bin
expect_error "decode: unknown format" 2 "'xbox': expected ds4, dualsense, switchpro or steamdeck" "$bin" input decode --format xbox ds4.bin
expect_error "decode: missing file" 2 "missing.bin" "$bin" input decode --format ds4 missing.bin
expect_error "sim-pad: rate out of range" 2 "--rate: 50 Hz: expected 125 to 8000 Hz" \
  "$bin" sim-pad --format ds4 --rate 50 --program known.prog --out x.bin
expect_error "sim-pad: bad fault" 2 "--faults: 'drop=2': expected a probability in [0, 1]" \
  "$bin" sim-pad --format ds4 --program known.prog --faults drop=2 --out x.bin
expect_error "sim-pad: bad program" 2 "bad.prog:1" \
  bash -c "echo 'jump 1s' >bad.prog; '$bin' sim-pad --format ds4 --program bad.prog --out x.bin"
printf '[ds4]\nstick_curve = 9\n' >bad.toml
expect_error "monitor: bad calibration file" 2 "bad.toml:2: ds4.stick_curve: 9.0 is out of range" \
  "$bin" input monitor --input-config bad.toml --backend evdev --evdev-dir "$work" --count 1 --timeout 0.1

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
