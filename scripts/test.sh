#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Quick start, step 2 (and CI): installs what is missing, builds, and runs every test: the
# release build (every label), then the unit, cli and povray tests again in an
# AddressSanitizer + UndefinedBehaviorSanitizer build.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"

echo "== release build"
"$root/scripts/build.sh"
echo "== sanitizer build (ASan + UBSan)"
SSAO_BUILD_DIR="$root/build-asan" "$root/scripts/build.sh" -DCMAKE_BUILD_TYPE=Debug \
  -DSSAO_SANITIZE=ON -DSSAO_BUILD_BENCHMARKS=OFF

jobs=$(nproc)
status=0
echo "== sanitizer tests"
# Python test helpers would need the sanitizer runtime preloaded; the C++ tests and the CLI are
# what the sanitizers are for.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir "$root/build-asan" -L "unit|cli|povray" --output-on-failure -j"$jobs" || status=1
echo "== release tests"
ctest --test-dir "$root/build" --output-on-failure -j"$jobs" || status=1
exit $status
