#!/usr/bin/env bash
# The main job from a fresh checkout: install what is missing, build the optimised
# preset, run the default demo (headless with a simulated controller when there is
# no display and no controller; it ends by itself). Extra arguments go to `run`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release --target marionette
exec build/release/app/marionette run "$@"
