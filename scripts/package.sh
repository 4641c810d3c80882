#!/usr/bin/env bash
# Builds the Debian package (docs/deploy.md): a RelWithDebInfo build of the
# `marionette` command only (tests and benchmarks off) in build/package with
# the /usr prefix, then CPack's DEB generator (Depends from dpkg-shlibdeps,
# maintainer scripts from packaging/debian). Uses ccache when it is installed;
# with CCACHE_BASEDIR at the source tree and CCACHE_NOHASHDIR=1 it reuses the
# objects of build/release (same flags). Progress goes to stderr; the last line
# on stdout is the .deb's path.
# Usage: bash scripts/package.sh [BUILD_DIR]   (default build/package; CMAKE_BUILD_PARALLEL_LEVEL
# limits the build's jobs, else nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
build=${1:-build/package}
if [[ -z "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]] && command -v ccache >/dev/null 2>&1; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$src} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
fi
for tool in cpack dpkg-deb dpkg-shlibdeps fakeroot; do
  command -v "$tool" >/dev/null 2>&1 || { echo "package: $tool is missing (bash scripts/setup.sh installs it)" >&2; exit 1; }
done
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=g++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_INSTALL_PREFIX=/usr -DMARIONETTE_BUILD_TESTS=OFF -DMARIONETTE_BUILD_BENCH=OFF >&2
cmake --build "$build" -j "${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}" --target marionette >&2
rm -f "$build"/marionette_*.deb
(cd "$build" && cpack -G DEB >&2)
debs=("$build"/marionette_*.deb)
[[ -f "${debs[0]}" ]] || { echo "package: cpack wrote no .deb in $build" >&2; exit 1; }
echo "$src/${debs[0]}"
