#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Quick start, step 1: installs what is missing, builds, and runs the command-line tool on the
# bundled sample render, writing build/sample_ao.exr (beauty x AO plus an AO channel) and
# build/sample_ao.png (the same, for any image viewer).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
sample="$root/tests/data/sample"
"$root/build/bin/ssao" "$sample.exr" --camera "$sample.camera.json" --radius 0.8 \
  -o "$root/build/sample_ao.exr"
"$root/build/bin/ssao" "$sample.exr" --camera "$sample.camera.json" --radius 0.8 \
  -o "$root/build/sample_ao.png" --quiet
echo "setup: open $root/build/sample_ao.png (or build/sample_ao.exr)"
