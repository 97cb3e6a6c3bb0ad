#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Starts Wine's server and its system processes for $WINEPREFIX, detached from every caller's
# output, before anything captures a Windows program's output (ctest, Python's subprocess).
#
# Why: the first Wine process of a prefix starts wineserver and the system processes
# (services.exe, winedevice.exe, ...), which inherit its standard output and error. A caller
# that reads those pipes to their end then waits for the server to exit, and the server lives
# as long as any other Wine process of the prefix runs: two tests running Wine side by side
# kept each other waiting until their timeouts (CI, 2026-11-28). Started here with /dev/null,
# they hold no caller's pipe. The server stays 60 s after its last client, then exits.
#
#   WINEPREFIX=... scripts/start_wine.sh
set -euo pipefail
[[ -n ${WINEPREFIX:-} ]] || { echo "start_wine: set WINEPREFIX" >&2; exit 2; }
export WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
# Exit status 2: a server of this prefix already runs, which is as good.
wineserver -p60 </dev/null >/dev/null 2>&1 || [[ $? == 2 ]] ||
  { echo "start_wine: wineserver did not start" >&2; exit 1; }
wine cmd /c exit </dev/null >/dev/null 2>&1 ||
  { echo "start_wine: wine cannot run a program in $WINEPREFIX" >&2; exit 1; }
