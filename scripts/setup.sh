#!/usr/bin/env bash
# Installs the Debian 12 packages marionette needs, when missing. Idempotent;
# runs as root or through sudo; downloads nothing but Debian packages.
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config make git ca-certificates python3
  # runtime and tools
  libglm-dev libxxhash-dev zlib1g-dev libtomlplusplus-dev libcli11-dev libfmt-dev libspdlog-dev
  # tests and benchmarks
  catch2 libbenchmark-dev
  # input: evdev, raw HID, SDL2; umockdev and evemu run the evdev path without hardware
  libevdev-dev libhidapi-dev libsdl2-dev umockdev libumockdev-dev evemu-tools
  # render_es: EGL + GLES 3, KMS/GBM, seat access, PNG output; Mesa's llvmpipe for headless runs
  libegl-dev libgles-dev libgbm-dev libdrm-dev libseat-dev libstb-dev libegl-mesa0 libgl1-mesa-dri xvfb xauth
  # the in-app tuning UI (app/ui/, docs/ui.md): Dear ImGui 1.86, static library and headers
  libimgui-dev
  # your own character (render_es/character/, docs/render.md): glTF 2.0 loading,
  # header-only tinygltf and the JSON library it uses
  libtinygltf-dev nlohmann-json3-dev
  # motion graph: BLAS for the distance matrix
  libopenblas-dev
  # key-pose graphs saved and loaded as XML (graph_builder/key_pose_xml.cpp)
  libxml2-dev
  # structure check (scripts/check_structure.py): function extents
  universal-ctags
  # fuzz targets (scripts/fuzz.sh, the `fuzz` preset): clang 14 and its runtime
  # libraries (libFuzzer, ASan, UBSan), which clang-14 only recommends
  clang-14 libclang-rt-14-dev
  # packaging (scripts/package.sh, tests/packaging): dpkg-shlibdeps, fakeroot, ccache;
  # systemd-analyze verify and udevadm for the units' and rules' checks
  dpkg-dev fakeroot ccache systemd udev
  # sd_notify for the service's READY=1 / WATCHDOG=1 (app/live/service_notify.cpp)
  libsystemd-dev
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [[ $(id -u) -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "setup: need root (or sudo) to install: ${missing[*]}" >&2
  exit 1
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
