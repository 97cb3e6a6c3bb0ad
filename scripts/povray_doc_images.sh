#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The before/after images of docs/povray.md: for each scene, the plain beauty (--strength 0,
# through the same 8-bit sRGB output), the default (AO on the ambient light where the scene has
# some) and --apply-to beauty (the whole image multiplied), 320x240, default radius.
#   scripts/povray_doc_images.sh [OUT_DIR]        (default: docs/images)
# Needs build/bin/povray-ssao (scripts/build.sh) and Debian's povray-examples.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(cd "${1:-$root/docs/images}" && pwd)
bridge=$root/build/bin/povray-ssao
[[ -x $bridge ]] || { echo "povray_doc_images.sh: build first (scripts/build.sh)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
examples=/usr/share/povray-3.7/scenes
for scene in "$examples/advanced/woodbox.pov" "$examples/advanced/pawns.pov" \
             "$root/tests/povray/scenes/sunlit_wall.pov"; do
  [[ -f $scene ]] || { echo "povray_doc_images.sh: no $scene (povray-examples)" >&2; exit 1; }
  name=$(basename "$scene" .pov)
  cp "$scene" "$work/"
  for mode in before ambient beauty; do
    case $mode in
      before) extra=(--strength 0) ;;
      ambient) extra=() ;;
      beauty) extra=(--apply-to beauty) ;;
    esac
    "$bridge" "$work/$name.pov" -o "$out/povray_${name}_$mode.png" +W320 +H240 +A0.3 \
      "${extra[@]}" --quiet
  done
  echo "wrote $out/povray_${name}_{before,ambient,beauty}.png"
done
