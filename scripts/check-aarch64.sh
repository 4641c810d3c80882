#!/usr/bin/env bash
# Bit-identical replay on aarch64 (docs/determinism.md): installs Debian's cross
# toolchain, the :arm64 -dev packages and qemu user-mode emulation, cross-builds
# the golden tests (the deterministic core only) and runs them under qemu: every
# golden trace (gait, motion graph and motion matching) must match bit for bit. Ends with a line
# saying how many goldens were identical.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
arm64_packages=(libxxhash-dev:arm64 zlib1g-dev:arm64 libfmt-dev:arm64 libtomlplusplus-dev:arm64 libopenblas-dev:arm64 libxml2-dev:arm64)
host_packages=(g++-aarch64-linux-gnu qemu-user-static catch2 libglm-dev)
missing=()
for p in "${arm64_packages[@]}" "${host_packages[@]}"; do
  [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" == "install ok installed" ]] || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=()
  [[ $(id -u) -eq 0 ]] || sudo=(sudo)
  if ! dpkg --print-foreign-architectures | grep -qx arm64; then "${sudo[@]}" dpkg --add-architecture arm64; fi
  echo "check-aarch64: installing ${missing[*]}"
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# OpenBLAS worker threads hang at exit under qemu user-mode emulation; one thread
# gives the same graph bytes (the graph build does not depend on BLAS threads).
export OPENBLAS_NUM_THREADS=1
dir=build/check-aarch64
cmake -S . -B "$dir" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$PWD/cmake/toolchain-aarch64-linux-gnu.cmake" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMARIONETTE_WERROR=ON -DMARIONETTE_CORE_ONLY=ON -DMARIONETTE_BUILD_BENCH=OFF >/dev/null
cmake --build "$dir" -j "$(nproc)" --target marionette_golden_tests
qemu=$(command -v qemu-aarch64-static || command -v qemu-aarch64)
echo "== check-aarch64: golden tests under $(basename "$qemu")"
# Under emulation glibc's pthread_create was seen to spin for minutes once a thread
# had exited, so the run starts none (OPENBLAS_NUM_THREADS=1 above; the golden
# test builds its graph with one builder thread); a hang fails after 10 min.
out=$(cd "$dir/tests" && timeout 600 "$qemu" -L /usr/aarch64-linux-gnu ./marionette_golden_tests 2>&1) || {
  echo "$out" | tail -40
  echo "check-aarch64: FAILED: the golden traces differ on aarch64 (or the tests failed)"
  exit 1
}
echo "$out" | tail -3
if grep -q "not the one the golden traces were made with" <<<"$out"; then
  echo "check-aarch64: FAILED: aarch64 builds another default motion graph, so the graph goldens could not be compared"
  exit 1
fi
goldens=$(ls tests/golden/*.trace.csv | wc -l)
echo "check-aarch64: ${goldens} of ${goldens} golden traces identical on aarch64 under qemu ($(($(date +%s) - start)) s)"
