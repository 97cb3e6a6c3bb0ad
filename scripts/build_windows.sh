#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The library for windows-x64: cross-builds ssao.dll (with its import library libssao.dll.a) and
# the library's own tests with MinGW-w64 (scripts/mingw-w64-x86_64.cmake), checks that the DLL
# needs no DLL beside Windows' own, and with --run-tests runs the tests under Wine. Needs
# g++-mingw-w64-x86-64-posix, googletest and libhwy-dev, and wine and wine64 for the tests
# (scripts/install_deps.sh installs them). docs/install.md, "Windows".
#
#   scripts/build_windows.sh [--no-tests] [--run-tests]
#
# Into build-windows/ (SSAO_WINDOWS_BUILD_DIR: another folder; the main build's add-on uses
# build/windows). Without Wine the tests are not built (GoogleTest lists them by running them).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${SSAO_WINDOWS_BUILD_DIR:-$root/build-windows}
tests=ON
run_tests=0
for arg in "$@"; do
  case "$arg" in
    --no-tests) tests=OFF ;;
    --run-tests) run_tests=1 ;;
    *) echo "usage: $0 [--no-tests] [--run-tests]" >&2; exit 2 ;;
  esac
done
for tool in x86_64-w64-mingw32-g++-posix x86_64-w64-mingw32-objdump; do
  command -v "$tool" >/dev/null || {
    echo "build_windows: $tool not found (apt-get install g++-mingw-w64-x86-64-posix)" >&2
    exit 1
  }
done
if ! command -v wine >/dev/null; then
  [[ $run_tests == 0 ]] || { echo "build_windows: wine not found (apt-get install wine wine64)" >&2; exit 1; }
  [[ $tests == OFF ]] || echo "build_windows: no wine: the tests are not built"
  tests=OFF
fi

# Wine runs the tests (and GoogleTest's listing at build time) in a prefix of the build's own,
# made on first use (a few seconds). No Mono or Gecko: the tests need neither.
export WINEPREFIX=${WINEPREFIX:-$build/wineprefix} WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="

if [[ $tests == ON && ! -f "$WINEPREFIX/system.reg" ]]; then
  # Made once, before the build lists the tests with several Wine processes at a time.
  mkdir -p "$build"
  wineboot --init </dev/null >/dev/null 2>&1 || { echo "build_windows: wineboot --init failed" >&2; exit 1; }
fi
# The build lists the tests by running them, capturing their output: Wine's server must not
# hold those pipes (scripts/start_wine.sh says why).
[[ $tests == OFF ]] || "$root/scripts/start_wine.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="$root/scripts/mingw-w64-x86_64.cmake" \
  -DSSAO_BUILD_TOOLS=OFF -DSSAO_BUILD_BENCHMARKS=OFF -DSSAO_BUILD_TESTS=$tests >/dev/null
cmake --build "$build"

# What the DLL imports must all be Windows' own: KERNEL32 and the C runtime every Windows has.
dll=$build/bin/ssao.dll
imports=$(x86_64-w64-mingw32-objdump -p "$dll" | sed -n 's/^\s*DLL Name: //p' | sort -u)
echo "build_windows: $dll imports: $(echo $imports)"
for name in $imports; do
  case "${name,,}" in
    kernel32.dll | msvcrt.dll | api-ms-win-*.dll) ;;
    *) echo "build_windows: error: ssao.dll needs $name, which Windows does not have" >&2; exit 1 ;;
  esac
done

if [[ $run_tests == 1 ]]; then
  [[ $tests == ON ]] || { echo "build_windows: --run-tests with --no-tests" >&2; exit 2; }
  "$root/scripts/start_wine.sh"  # ctest captures each test's output (start_wine.sh)
  ctest --test-dir "$build" --output-on-failure -j "$(nproc)"
fi
