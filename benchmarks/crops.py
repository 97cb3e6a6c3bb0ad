#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Crops of the benchmark's scenes beside Cycles' reference: what a mean error does not show.

For each scene of the kit (640x360 unless --size), the window of 0.3 x the frame (192 x 108 px
at 640x360) where the library's default has
its largest band error (G(1) - G(6), as ssao_eval's `band`) is cut from: Cycles' AO pass (the
reference), the default with one layer, the default with the 2nd to 5th hits and the 64 px band,
and Cycles' AO pass at 16 spp when the benchmark's sweep has it. Called by speed_error.py
(OUT/crops.png); runnable alone on a kit:

    /usr/bin/python3 benchmarks/crops.py [--kit build/benchmark_kit] [--out crops.png]
        [--eval build/bin/ssao_eval] [--cycles build/benchmark/cycles] [--size 640x360]
        [--scenes a,b] [--baseline-lib DIR]   (DIR's libssao.so too: before/after)
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CROP_FRACTION = 0.3  # of the frame's width and height
# The layers column: the Blender node's defaults, 5 hits (blender_addon/compute.py,
# HITS['PEELED']) and a 64 px guard band. benchmarks/speed_error.py's layers rows use the same.
EXTRA_LAYERS, GUARD_BAND = 4, 64
LAYERED = ["layers=%d" % EXTRA_LAYERS, "band=%d" % GUARD_BAND]
SCENES = ["contact", "thin", "cavity", "depth_range", "ortho", "heavy"]


def read_channel(path, suffix):
    image = oiio.ImageInput.open(path)
    if image is None:
        raise RuntimeError("cannot open %s: %s" % (path, oiio.geterror()))
    names = list(image.spec().channelnames)
    pixels = image.read_image(format="float")
    image.close()
    index = next((i for i, n in enumerate(names) if n.endswith(suffix)), None)
    if index is None:
        index = 0 if len(names) == 1 else None
    if index is None:
        raise RuntimeError("%s has no channel ending in %s" % (path, suffix))
    return np.asarray(pixels[:, :, index], dtype=np.float64)


def gaussian(image, sigma):
    """Separable Gaussian blur truncated at 3 sigma, clamp-to-edge (as ssao_eval's band)."""
    radius = int(np.ceil(3 * sigma))
    taps = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    taps /= taps.sum()
    padded = np.pad(image, ((0, 0), (radius, radius)), mode="edge")
    rows = sum(t * padded[:, k:k + image.shape[1]] for k, t in enumerate(taps))
    padded = np.pad(rows, ((radius, radius), (0, 0)), mode="edge")
    return sum(t * padded[k:k + image.shape[0], :] for k, t in enumerate(taps))


def crop_size(image):
    return (max(1, int(round(CROP_FRACTION * image.shape[1]))),
            max(1, int(round(CROP_FRACTION * image.shape[0]))))


def worst_window(ours, reference, geometry):
    """Top-left corner of the crop window with the largest summed squared band-pass error."""
    def band(image):
        return gaussian(image, 1.0) - gaussian(image, 6.0)
    error = np.where(geometry, (band(ours) - band(reference)) ** 2, 0.0)
    table = np.pad(error.cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    w, h = crop_size(ours)
    sums = table[h:, w:] - table[:-h, w:] - table[h:, :-w] + table[:-h, :-w]
    y, x = np.unravel_index(np.argmax(sums), sums.shape)
    return int(x), int(y)


def library_ao(args, reference, radius, settings, layers=None, library_dir=None):
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "ao.exr")
        command = [args.eval, reference + ".exr", "--camera", reference + ".camera.json",
                   "--radius", repr(radius), "--method", "ssao", "--write-ao", out]
        if layers:
            command += ["--layers", layers]
        for setting in settings:
            command += ["--set", setting]
        env = dict(os.environ)
        if library_dir:
            env["LD_LIBRARY_PATH"] = library_dir
        proc = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
        if proc.returncode != 0:
            raise RuntimeError("ssao_eval failed: %s\n%s" % (" ".join(command), proc.stderr))
        return read_channel(out, "AO")


def find(pattern, newest=False):
    """The first folder matching `pattern` by name, or with newest the last one written: a kit
    keeps the layers of earlier sources beside the current ones (speed_error.kit_layers keys
    them by their sources), and the benchmark has just written the current one."""
    found = sorted(p for p in glob.glob(pattern) if not p.endswith(".partial"))
    if newest:
        found.sort(key=os.path.getmtime, reverse=True)
    return found[0] if found else None


def scene_columns(args, scene):
    """[(title, image)] for one scene, and the crop window; None when the kit lacks the scene."""
    folder = find(os.path.join(args.kit, "%s@%s-*s1-*" % (scene, args.size)))
    if folder is None or "-part-" in folder:
        return None
    reference = os.path.join(folder, "ref")
    with open(reference + ".json", encoding="utf-8") as f:
        settings = json.load(f)
    radius = settings["ao_distance"]
    layers_folder = find(os.path.join(args.kit, "%s@%s-layers-*" % (scene, args.size)),
                         newest=True)
    layers = os.path.join(layers_folder, "ref.layers.exr") if layers_folder else None
    truth = read_channel(reference + ".exr", "AO.R")
    depth = read_channel(reference + ".exr", "Depth.Z")
    geometry = np.isfinite(depth) & (depth > 0) & (depth < 1e9)
    truth = np.where(geometry, truth, 1.0)
    columns = [("Cycles %d spp (reference)" % settings["samples"], truth)]
    if args.baseline_lib:
        columns.append(("before: default",
                        library_ao(args, reference, radius, [], library_dir=args.baseline_lib)))
    default = library_ao(args, reference, radius, [])
    columns.append(("default, one layer", default))
    if layers:
        if args.baseline_lib:
            columns.append(("before: layers + band",
                            library_ao(args, reference, radius, LAYERED, layers,
                                       args.baseline_lib)))
        columns.append(("default, layers + band",
                        library_ao(args, reference, radius, LAYERED, layers)))
    sweep = os.path.join(args.cycles, "%s@%s" % (scene, args.size), "sweep.json")
    if os.path.isfile(sweep):
        with open(sweep, encoding="utf-8") as f:
            runs = json.load(f)["runs"]
        sixteen = next((r for r in runs if r["samples"] == 16), None)
        if sixteen:
            image = read_channel(os.path.join(os.path.dirname(sweep), sixteen["file"]), "AO.R")
            columns.append(("Cycles 16 spp", image))
    columns = [(title, np.where(geometry, image, 1.0)) for title, image in columns]
    return columns, worst_window(default, truth, geometry)


def write_crops(args, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = []
    for scene in getattr(args, "scenes", None) or SCENES:
        result = scene_columns(args, scene)
        if result is not None:
            scenes.append((scene, *result))
    if not scenes:
        raise RuntimeError("no %s scene in %s" % (args.size, args.kit))
    count = max(len(columns) for _, columns, _ in scenes)
    figure, axes = plt.subplots(len(scenes), count, figsize=(2.6 * count, 1.75 * len(scenes)),
                                squeeze=False)
    for row, (scene, columns, (x, y)) in enumerate(scenes):
        w, h = crop_size(columns[0][1])
        for col in range(count):
            axis = axes[row][col]
            axis.set_xticks([])
            axis.set_yticks([])
            if col >= len(columns):
                axis.axis("off")
                continue
            title, image = columns[col]
            axis.imshow(image[y:y + h, x:x + w], cmap="gray", vmin=0.0, vmax=1.0,
                        interpolation="nearest")
            if row == 0:
                axis.set_title(title, fontsize=8)
            if col == 0:
                axis.set_ylabel("%s\n(%d, %d)" % (scene, x, y), fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return [scene for scene, _, _ in scenes]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kit", default=os.path.join(REPO_ROOT, "build", "benchmark_kit"))
    parser.add_argument("--out", default=os.path.join(REPO_ROOT, "build", "crops.png"))
    parser.add_argument("--eval", default=os.path.join(REPO_ROOT, "build", "bin", "ssao_eval"))
    parser.add_argument("--cycles", default=os.path.join(REPO_ROOT, "build", "benchmark", "cycles"))
    parser.add_argument("--size", default="640x360", metavar="WxH",
                        help="the kit's frame size to crop (default 640x360)")
    parser.add_argument("--scenes", default=None, type=lambda text: text.split(","),
                        help="comma-separated scenes (default: %s)" % ",".join(SCENES))
    parser.add_argument("--baseline-lib", default=None, metavar="DIR",
                        help="folder of another libssao.so whose default is shown too")
    args = parser.parse_args()
    if not os.path.isfile(args.eval):
        sys.exit("crops: no %s: build the project first" % args.eval)
    try:
        scenes = write_crops(args, args.out)
    except RuntimeError as error:
        sys.exit("crops: %s" % error)
    print("crops: %s (%s)" % (args.out, ", ".join(scenes)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
