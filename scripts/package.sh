#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the Debian package ssao_VERSION_ARCH.deb (core/packaging.cmake, docs/install.md).
#
#   scripts/package.sh [--build-dir DIR] [--output DIR] [-- CMAKE_ARGS...]
#
# In a build tree of its own (default build-deb/; Release, no tests or benchmarks) configured
# with the prefix /usr: GNUInstallDirs then puts the library in lib/x86_64-linux-gnu, as Debian
# does, and the installed tools' run path follows. (build/ keeps the prefix /usr/local and its
# lib/, so `cmake --install build --prefix P` is unchanged.) The package goes to --output
# (default DIR/package); its path is the last line printed on stdout.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=$root/build-deb
output=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --output) output=$2; shift 2 ;;
    --) shift; break ;;
    -h | --help) sed -n '3,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "package: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
build_dir=$(realpath -m "$build_dir")
output=$(realpath -m "${output:-$build_dir/package}")
for tool in cpack dpkg-deb dpkg-shlibdeps; do
  command -v "$tool" > /dev/null ||
    { echo "package: $tool is missing (apt-get install cmake dpkg-dev)" >&2; exit 1; }
done

cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DSSAO_BUILD_TESTS=OFF -DSSAO_BUILD_BENCHMARKS=OFF "$@" > /dev/null
cmake --build "$build_dir" -- -j"$(nproc)" >&2
mkdir -p "$output"
rm -f "$output"/ssao_*.deb
cpack --config "$build_dir/CPackConfig.cmake" -B "$output" > "$output/cpack.log" 2>&1 ||
  { cat "$output/cpack.log" >&2; echo "package: cpack failed ($output/cpack.log)" >&2; exit 1; }
deb=$(find "$output" -maxdepth 1 -name 'ssao_*.deb' | head -n 1)
[[ -n "$deb" ]] || { echo "package: cpack wrote no ssao_*.deb in $output" >&2; exit 1; }
echo "$deb"
