#!/usr/bin/env bash
# End-to-end checks of `marionette render` and of `marionette run` with a window
# under Xvfb. Usage: render_cli_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$1
src=$2
source "$src/tests/cli/check_lib.sh"
png_size() { python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print('%dx%d' % struct.unpack('>II', d[16:24]))" "$1"; }

"$bin" record --program "$src/config/programs/walk_stop.prog" -o walk.mlog >/dev/null

# 1.0 s .. 1.5 s at 10 fps: 6 frames, numbered from 0, at the requested size.
"$bin" render walk.mlog --out frames --size 320x200 --fps 10 --from 1 --to 1.5 >render.txt
check "render exits 0 and reports 6 frames" grep -q "rendered 6 frames (320x200" render.txt
check "render wrote frame_00000..00005" test -f frames/frame_00000.png -a -f frames/frame_00005.png -a ! -e frames/frame_00006.png
check "frames have the requested size" test "$(png_size frames/frame_00003.png)" = 320x200
check "consecutive frames differ (the puppet walks)" bash -c '! cmp -s frames/frame_00000.png frames/frame_00005.png'
# The same request twice gives the same pixels (offline rendering is deterministic on one machine).
"$bin" render walk.mlog --out again --size 320x200 --fps 10 --from 1 --to 1.5 >/dev/null
check "rendering twice gives identical frames" cmp -s frames/frame_00004.png again/frame_00004.png
"$bin" render walk.mlog --out tail --size 64x40 --fps 2 --from 6 >tail.txt
check "without --to it renders to the log's end (6.75 s: frames at 6.0 and 6.5)" grep -q "rendered 2 frames" tail.txt

expect_error "bad --size" 2 "--size: expected WIDTHxHEIGHT" "$bin" render walk.mlog --out x --size big
expect_error "--to before --from" 2 "--to 1 is before --from 2" "$bin" render walk.mlog --out x --from 2 --to 1
expect_error "no output" 2 "nothing to write" "$bin" render walk.mlog
expect_error "unknown overlay" 2 "unknown overlay 'bones'" "$bin" render walk.mlog --out x --overlays bones
printf '[display]\nmsaa_samples = 99\n' >bad_render.toml
expect_error "bad render settings name file, line and key" 2 "bad_render.toml:2: display.msaa_samples" \
  "$bin" render walk.mlog --out x --render-config bad_render.toml
# [render] character: the shipped glTF character draws (relative to the settings
# file's folder); a missing or truncated file exits 2 naming it.
mkdir -p chars
cp "$src/config/characters/blocky.gltf" chars/
printf '[render]\ncharacter = "blocky.gltf"\n' >chars/character.toml
"$bin" render walk.mlog --out character --size 320x200 --fps 2 --from 5 --to 5 --render-config chars/character.toml >character.txt
check "render with [render] character writes its frame" test -f character/frame_00000.png
head -c 4000 "$src/config/characters/blocky.gltf" >chars/cut.gltf
printf '[render]\ncharacter = "cut.gltf"\n' >chars/cut.toml
expect_error "a truncated glTF character names the file" 2 "chars/cut.gltf: not a readable glTF file" \
  "$bin" render walk.mlog --out x --render-config chars/cut.toml
printf '[render]\ncharacter = "nobody.glb"\n' >chars/missing.toml
expect_error "a missing glTF character names the file" 2 "chars/nobody.glb: cannot open the file" \
  "$bin" render walk.mlog --out x --render-config chars/missing.toml
printf 'garbage' >bad.mlog
expect_error "a malformed log" 2 "bad.mlog" "$bin" render bad.mlog --out x
if ! command -v ffmpeg >/dev/null; then
  expect_error "--video without ffmpeg says so" 1 "needs ffmpeg, which is not installed" "$bin" render walk.mlog --video v.mp4
fi

# `run` opens a window under Xvfb (auto picks it from DISPLAY) and closes at the end.
if command -v xvfb-run >/dev/null; then
  xvfb-run -a -s "-screen 0 800x600x24" "$bin" run --input "sim:$src/config/programs/walk_stop.prog" --duration 1 >run.txt 2>run.err
  check "run under Xvfb exits 0" test $? -eq 0
  check "run under Xvfb opened a window" grep -q "^display: window (SDL x11" run.txt
  check "run under Xvfb finished the demo" grep -q "demo finished" run.txt
  check "run under Xvfb reported no lost contexts" test ! -s run.err
fi
env -u DISPLAY -u WAYLAND_DISPLAY "$bin" run --fast --duration 0.5 >nodisplay.txt </dev/null
check "run without a display stays a console program" bash -c '! grep -q "^display:" nodisplay.txt'

echo "$passes passed, $failures failed"
[[ $failures -eq 0 ]]
