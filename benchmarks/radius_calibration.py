#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The automatic radius's calibration: for scenes whose AO distance an artist chose, that
distance over the view's width (along the image's larger side) at the median depth.

    /usr/bin/python3 benchmarks/radius_calibration.py [--kit build/benchmark_kit]
        [--scene DIR_OR_EXR ...]

Reads the reference renders of scripts/benchmark.sh (build/benchmark_kit/NAME@640x360-1024s1-*:
ref.exr with the Depth pass, ref.camera.json, ref.json with "ao_distance"), and any --scene
NAME.exr with NAME.camera.json and NAME.json beside it. Prints one row per scene and the
geometric mean of the ratios, which libssao's rule uses (ssao_job_auto_radius: 0.1).
"""
import argparse
import glob
import json
import math
import os
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def depth_plane(path):
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit("radius_calibration.py: cannot read %s: %s" % (path, oiio.geterror()))
    spec = image.spec()
    names = list(spec.channelnames)
    pixels = image.read_image(0, 0, 0, spec.nchannels, "float")
    image.close()
    for i, name in enumerate(names):
        if name == "Z" or name.endswith("Depth.Z"):
            return pixels[..., i]
    sys.exit("radius_calibration.py: %s has no depth channel (%s)" % (path, ", ".join(names)))


def view_width(camera, depth, width, height):
    """Extent of the view along the image's larger side at `depth`, as Blender fits the sensor
    (AUTO: sensor_width on the larger side)."""
    fit = camera.get("sensor_fit", "AUTO")
    if fit == "AUTO":
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
    if camera["type"] == "ORTHO":
        fitted = camera.get("ortho_scale", 6.0)
    else:
        sensor = camera.get("sensor_width", 36.0) if camera.get("sensor_fit", "AUTO") == "AUTO" \
            or fit == "HORIZONTAL" else camera.get("sensor_height", 24.0)
        fitted = depth * sensor / camera["lens"]
    # fitted spans the width (HORIZONTAL) or the height (VERTICAL); scale to the larger side.
    span = width if fit == "HORIZONTAL" else height
    return fitted * max(width, height) / span


def row(name, exr, camera_file, meta_file):
    depth = depth_plane(exr)
    camera = json.load(open(camera_file))
    distance = json.load(open(meta_file))["ao_distance"]
    values = depth[np.isfinite(depth) & (depth > 0) & (depth < min(1e9, camera.get("clip_end", 1e9)))]
    median = float(np.median(values))
    height, width = depth.shape
    extent = view_width(camera, median, width, height)
    return name, distance, median, extent, distance / extent


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kit", default=os.path.join(ROOT, "build", "benchmark_kit"))
    parser.add_argument("--scene", action="append", default=[],
                        help="NAME.exr with NAME.camera.json and NAME.json beside it")
    args = parser.parse_args()
    items = []
    for ref in sorted(glob.glob(os.path.join(args.kit, "*@640x360-1024s1-*", "ref.exr"))):
        folder = os.path.dirname(ref)
        items.append((os.path.basename(folder).split("@")[0], ref,
                      os.path.join(folder, "ref.camera.json"), os.path.join(folder, "ref.json")))
    for exr in args.scene:
        stem = exr[:-len(".exr")] if exr.endswith(".exr") else exr
        items.append((os.path.basename(stem), stem + ".exr", stem + ".camera.json", stem + ".json"))
    if not items:
        sys.exit("radius_calibration.py: no scenes (run scripts/benchmark.sh first, or give "
                 "--scene)")
    rows = [row(*item) for item in items]
    print("| scene | AO distance | median depth | view width there | ratio |")
    print("|---|--:|--:|--:|--:|")
    for name, distance, median, extent, ratio in rows:
        print("| %s | %.2f | %.2f | %.2f | %.3f |" % (name, distance, median, extent, ratio))
    ratios = [r[4] for r in rows]
    print("\ngeometric mean %.3f, median %.3f, range %.3f .. %.3f over %d scenes" % (
        math.exp(sum(math.log(r) for r in ratios) / len(ratios)), float(np.median(ratios)),
        min(ratios), max(ratios), len(ratios)))


if __name__ == "__main__":
    main()
