#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Where the edge error lies: the near and the far side of each depth jump, and the far side's
rings of pixels beyond it, one layer against layers + band.

    /usr/bin/python3 benchmarks/edge_sides.py [--kit build/benchmark_kit] [--size 640x360]
        [--eval build/bin/ssao_eval] [--scenes a,b] [--set NAME=VALUE ...]

Edge pixels as ssao_eval's edge_rmse: geometry pixels with a depth jump of more than 5 % of the
nearer depth to a 4-neighbour that is geometry too. A near-side pixel is the nearer of such a
pair (the silhouette's own pixel), a far-side one the farther (the surface just beyond the
silhouette). Ring k (k = 1..4) is the far side's pixels k - 1 steps (4-connected) beyond the
far-side edge pixels, not themselves edges: if ring 4 is as wrong as ring 1, what the far side
lacks is not the edge's anti-aliasing but the occlusion the foreground's hidden part casts on the
surface behind it. Each cell: RMSE (mean signed error, + = too light) against Cycles' AO pass.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from crops import LAYERED, REPO_ROOT, SCENES, find, library_ao, read_channel  # noqa: E402

EDGE_DEPTH_JUMP = 0.05  # ssao_eval's kEdgeDepthJump
RINGS = 4
STEPS = ((0, 1), (0, -1), (1, 0), (-1, 0))


def shifted(image, dy, dx, fill):
    """image[y + dy, x + dx], `fill` outside the frame."""
    h, w = image.shape
    padded = np.pad(image, 1, constant_values=fill)
    return padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]


def edge_sides(depth, geometry):
    """(near, far) masks of the edge pixels."""
    near = np.zeros_like(geometry)
    far = np.zeros_like(geometry)
    for dy, dx in STEPS:
        other = shifted(depth, dy, dx, np.inf)
        jump = (geometry & shifted(geometry, dy, dx, False) &
                (np.abs(other - depth) > EDGE_DEPTH_JUMP * np.minimum(depth, other)))
        near |= jump & (depth < other)
        far |= jump & (depth > other)
    return near, far


def far_rings(near, far, geometry):
    rings, ring, seen = [], far & ~near, near | far
    for _ in range(RINGS):
        rings.append(ring)
        grown = np.zeros_like(ring)
        for dy, dx in STEPS:
            grown |= shifted(ring, dy, dx, False)
        ring = grown & geometry & ~seen
        seen |= ring
    return rings


def cell(error, mask):
    if not mask.any():
        return "-"
    return "%.4f (%+.3f)" % (np.sqrt(np.mean(error[mask] ** 2)), np.mean(error[mask]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kit", default=os.path.join(REPO_ROOT, "build", "benchmark_kit"))
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--eval", default=os.path.join(REPO_ROOT, "build", "bin", "ssao_eval"))
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a libssao parameter for both rows (repeatable)")
    args = parser.parse_args()
    print("| scene | AO | edges | near side | far side | ring 2 | ring 3 | ring 4 |")
    print("|---|---|--:|--:|--:|--:|--:|--:|")
    for scene in args.scenes.split(","):
        folder = find(os.path.join(args.kit, "%s@%s-*s1-*" % (scene, args.size)))
        if folder is None:
            sys.exit("edge_sides: the kit %s has no %s render of %s (scripts/benchmark.sh makes "
                     "them)" % (args.kit, args.size, scene))
        reference = os.path.join(folder, "ref")
        with open(reference + ".json", encoding="utf-8") as f:
            radius = json.load(f)["ao_distance"]
        truth = read_channel(reference + ".exr", "AO.R")
        depth = read_channel(reference + ".exr", "Depth.Z")
        geometry = np.isfinite(depth) & (depth > 0) & (depth < 1e9)
        near, far = edge_sides(depth, geometry)
        rings = far_rings(near, far, geometry)
        layers_folder = find(os.path.join(args.kit, "%s@%s-layers-*" % (scene, args.size)),
                             newest=True)
        rows = [("one layer", args.set, None)]
        if layers_folder:
            rows.append(("layers + band", args.set + LAYERED,
                         os.path.join(layers_folder, "ref.layers.exr")))
        for label, settings, layers in rows:
            error = library_ao(args, reference, radius, settings, layers) - truth
            cells = [cell(error, near | far), cell(error, near & ~far), cell(error, rings[0])]
            cells += [cell(error, ring) for ring in rings[1:]]
            print("| %s | %s | %s |" % (scene, label, " | ".join(cells)))


if __name__ == "__main__":
    main()
