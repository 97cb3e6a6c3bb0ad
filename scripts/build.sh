#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds into build/ (Release, warnings as errors). Extra arguments go to cmake.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${SSAO_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" -- -j"$(nproc)"
