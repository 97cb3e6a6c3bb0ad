#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The host's Debian archive URI, read from its apt sources (one-line and deb822), for the
# debootstrap folders of other suites (scripts/blender/debian-blender.sh,
# tests/install/test_deb.sh): those download from the mirror the host already uses.
# $SSAO_DEBIAN_MIRROR overrides it. Sourced, it only defines host_mirror (the caller's shell
# options stay as they are); run, it prints the URI:
#   source scripts/debian_mirror.sh; mirror=$(host_mirror)    or    scripts/debian_mirror.sh
host_mirror() {
  if [[ -n "${SSAO_DEBIAN_MIRROR:-}" ]]; then
    echo "${SSAO_DEBIAN_MIRROR%/}"
    return
  fi
  local files=() f
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [[ -r "$f" ]] && files+=("$f")
  done
  {
    [[ ${#files[@]} -gt 0 ]] && awk '
      $1 == "deb" {
        i = 2
        if ($2 ~ /^\[/) { while (i <= NF && $i !~ /\]$/) i++; i++ }
        if (i <= NF) print $i
      }' "${files[@]}"
    for f in /etc/apt/sources.list.d/*.sources; do
      [[ -r "$f" ]] || continue
      awk '
        BEGIN { RS = ""; FS = "\n" }
        {
          types = ""; uris = ""; enabled = "yes"; key = ""
          for (i = 1; i <= NF; i++) {
            line = $i
            if (line ~ /^#/) continue
            if (match(line, /^[A-Za-z0-9-]+:/)) {
              key = tolower(substr(line, 1, RLENGTH - 1)); val = substr(line, RLENGTH + 1)
            } else if (line ~ /^[ \t]/) { val = line } else continue
            if (key == "types") types = types " " val
            else if (key == "uris") uris = uris " " val
            else if (key == "enabled") enabled = val
          }
          if (types ~ /(^|[ \t])deb([ \t]|$)/ && tolower(enabled) !~ /no/) {
            n = split(uris, a, /[ \t]+/)
            for (j = 1; j <= n; j++) if (a[j] != "") print a[j]
          }
        }' "$f"
    done
  } | grep -E '^(https?|file)://[^[:space:]]*/debian/?$' | head -n 1 | sed 's:/*$::'
}

if [[ "${BASH_SOURCE[0]}" == "$0" ]]; then
  set -euo pipefail
  mirror=$(host_mirror) || true
  [[ -n "$mirror" ]] ||
    { echo "debian_mirror: no Debian archive in the host's apt sources" >&2; exit 1; }
  echo "$mirror"
fi
