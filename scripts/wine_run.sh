#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs a Windows program under Wine for ctest and GoogleTest's test discovery (the cross build's
# CMAKE_CROSSCOMPILING_EMULATOR, scripts/mingw-w64-x86_64.cmake), and runs it again, up to 3
# runs, when Wine did not start it at all: a non-zero exit with nothing written to stdout or
# stderr. Every test program prints before it can fail (GoogleTest's "Running main() from ..."),
# so that is Wine failing to launch, seen once in CI with the machine loaded (2026-12-02: one of
# 125 tests, exit != 0 in 0.03 s, no output). Anything the program prints is passed on as it
# came, stdout and stderr apart, and its exit status is returned.
#
#   scripts/wine_run.sh PROGRAM.exe [ARGUMENTS...]
set -uo pipefail
out=$(mktemp) err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
for run in 1 2 3; do
  wine "$@" >"$out" 2>"$err"
  status=$?
  if [[ $status == 0 || -s $out || -s $err || $run == 3 ]]; then
    cat "$out"
    cat "$err" >&2
    exit $status
  fi
  sleep $run
done
