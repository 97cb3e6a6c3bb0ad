#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Run time against error: libssao's variants, the seed tutorial code and Cycles' own AO pass on
# reference scenes rendered by Blender. On a machine set up by the README (scripts/setup.sh):
#   scripts/benchmark.sh [--quick] [--out DIR]        (default DIR: build/benchmark)
# writes DIR/speed_error.csv, speed_error.png, complexity.csv, complexity.png, performance.md.
# Options: scripts/benchmark.sh --help. What it measures and how: docs/performance.md.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
for arg in "$@"; do
  case "$arg" in -h|--help) exec /usr/bin/python3 "$root/benchmarks/speed_error.py" --help ;; esac
done
# The library and ssao_eval as of the current sources (a no-op when they are up to date), in
# build/ or SSAO_BUILD_DIR.
build_dir=${SSAO_BUILD_DIR:-$root/build}
if [[ -f "$build_dir/CMakeCache.txt" ]]; then
  cmake --build "$build_dir" --target ssao ssao_eval -- -j"$(nproc)"
else
  SSAO_BUILD_DIR="$build_dir" "$root/scripts/build.sh"
fi
exec /usr/bin/python3 "$root/benchmarks/speed_error.py" --eval "$build_dir/bin/ssao_eval" "$@"
