#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Quick start, step 2 (and CI): installs what is missing, builds, and runs every test: the
# release build (every label), then the unit, stress, cli and povray tests again in an
# AddressSanitizer + UndefinedBehaviorSanitizer build; the C API and concurrency tests in two
# ThreadSanitizer builds (build-tsan, build-tsan-std); and about a minute of fuzzing
# (scripts/fuzz.sh, build-fuzz), which first replays every committed regression input. The
# release build cross-builds the Windows DLL (build/windows); its tests run under Wine among the
# release tests (label windows).
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
  ctest --test-dir "$root/build-asan" -L "unit|stress|cli|povray" --output-on-failure -j"$jobs" || status=1
echo "== ThreadSanitizer builds and tests"
# Only what runs under it: the C API tests and several jobs on several threads at once
# (tests/unit/test_concurrency.cpp), with the tiles on oneTBB (build-tsan) and on std::thread
# (build-tsan-std: the Windows DLL's threads). tests/tsan.supp says why oneTBB's internals are
# suppressed; the canary, a deliberate race between tiles, proves that a race in code the tile
# pool runs is still reported. setarch -R: GCC 12's TSan maps its shadow memory at fixed
# addresses, which kernels with more mmap randomisation (vm.mmap_rnd_bits = 32) may have taken.
for threads in tbb std; do
  tsan_dir="$root/build-tsan"
  [[ $threads == tbb ]] || tsan_dir="$root/build-tsan-$threads"
  cmake -S "$root" -B "$tsan_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSSAO_TSAN=ON \
    -DSSAO_THREADS=$threads -DSSAO_BUILD_TOOLS=OFF -DSSAO_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$tsan_dir" --target ssao_api_tests ssao_concurrency_tests ssao_tsan_canary \
    -- -j"$jobs"
  tsan_options="suppressions=$root/tests/tsan.supp history_size=7"
  for tests in ssao_api_tests ssao_concurrency_tests; do
    TSAN_OPTIONS=$tsan_options setarch "$(uname -m)" -R "$tsan_dir/bin/$tests" --gtest_brief=1 ||
      status=1
  done
  if TSAN_OPTIONS=$tsan_options setarch "$(uname -m)" -R "$tsan_dir/bin/ssao_tsan_canary" \
    >"$tsan_dir/canary.log" 2>&1 || ! grep -q "ThreadSanitizer: data race" "$tsan_dir/canary.log"; then
    echo "tsan canary ($threads): the deliberate race was not reported (see $tsan_dir/canary.log)"
    status=1
  else
    echo "tsan canary ($threads): the deliberate race was reported, as it must be"
  fi
done
echo "== fuzzing (scripts/fuzz.sh)"
"$root/scripts/fuzz.sh" 15 || status=1
echo "== release tests"
ctest --test-dir "$root/build" --output-on-failure -j"$jobs" || status=1
exit $status
