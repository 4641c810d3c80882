#!/usr/bin/env bash
# Regenerates the golden images of the headless render tests
# (tests/render/golden/*.png) after an intended change to the renderer, its
# default settings (config/render.toml) or the simulation. Look at the images
# before committing them (any PNG viewer), and say why in the commit message.
# Usage: scripts/update-render-golden.sh [PRESET]   (default: release)
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
[[ -d build/$preset ]] || cmake --preset "$preset"
cmake --build --preset "$preset" -j2 --target marionette_render_tests
cd "build/$preset/tests"
LIBGL_ALWAYS_SOFTWARE=1 MARIONETTE_UPDATE_RENDER_GOLDEN=1 ./marionette_render_tests "[golden]"
git -C ../../.. status --short tests/render/golden
