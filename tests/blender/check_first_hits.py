# SPDX-License-Identifier: MIT
"""Compares the add-on's helper render (blender_addon/hidden_surfaces.py) with the user's own
render of the open .blend: the helper's first surface against the beauty's Depth pass, inside
the frame and, with a guard band of --overscan pixels, against a render of the scene widened by
that band (its camera widened on the same pixel grid, as the helper's). Writes --out JSON:
{"inside": fraction of pixels that agree, "band": the same over the band's pixels, "pixels":
counts}. Agree: both background, or both geometry within 1e-4 relative.

    blender -b --factory-startup --addons ssao_compositor SCENE.blend \\
        -P tests/blender/check_first_hits.py -- --out RESULT.json [--overscan 16]
"""
import argparse
import importlib
import json
import os
import sys
import tempfile

import bpy
import numpy as np


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--overscan", type=int, default=16)
    return parser.parse_args(argv)


def addon_module(name):
    package = next(n for n in sys.modules if n.endswith("ssao_compositor"))
    return importlib.import_module(f"{package}.{name}")


def user_depth(scene, folder, multilayer, compat):
    """The Depth pass of a render of `scene` as it is set now (row 0 on top)."""
    bpy.ops.render.render(scene=scene.name)
    path = os.path.join(folder, "user.exr")
    compat.set_image_format(scene.render.image_settings, 'OPEN_EXR_MULTILAYER', color_depth='32',
                            codec='ZIP')
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    planes, _ = multilayer.read(path)
    return next(planes[n] for n in planes if n.endswith(".Depth.Z") or n.endswith(".Depth.V"))


def agree(helper, user, background):
    helper_geometry = helper < background * 0.5
    user_geometry = (user > 0) & (user < background * 0.5)
    close = np.abs(helper - user) <= 1e-4 * np.abs(user)
    return (helper_geometry == user_geometry) & (~user_geometry | close)


def main():
    args = parse_args()
    hidden_surfaces = addon_module("hidden_surfaces")
    multilayer = addon_module("multilayer")
    compat = addon_module("compat")
    camera = addon_module("camera")
    scene = bpy.context.scene
    scene.frame_set(scene.frame_start)
    scene.render.use_compositing = False  # the user's passes only, no node
    folder = tempfile.mkdtemp(prefix="first_hits_")
    inside = user_depth(scene, folder, multilayer, compat)
    layers = hidden_surfaces.render_layers(scene, hidden_surfaces.MAX_HITS, args.overscan,
                                           folder=folder)
    band = args.overscan
    helper = layers["depth"]
    height, width = inside.shape
    inner = agree(helper[band:band + height, band:band + width], inside,
                  hidden_surfaces.BACKGROUND)
    # The same scene rendered wider by the band, as the helper widens its own camera.
    data = scene.camera.data
    for name, value in camera.cropped({name: getattr(data, name) for name in camera.CROPPED},
                                      scene.render, band).items():
        setattr(data, name, value)
    scene.render.resolution_x, scene.render.resolution_y = width + 2 * band, height + 2 * band
    scene.render.resolution_percentage = 100
    scene.render.use_border = False
    wide = user_depth(scene, folder, multilayer, compat)
    whole = agree(helper, wide, hidden_surfaces.BACKGROUND)
    in_band = np.ones(whole.shape, bool)
    in_band[band:band + height, band:band + width] = False
    result = {"inside": float(inner.mean()), "band": float(whole[in_band].mean()),
              "pixels": {"inside": int(inner.size), "band": int(in_band.sum()),
                         "inside_disagree": int((~inner).sum()),
                         "band_disagree": int((~whole[in_band]).sum())}}
    print(f"[measure] {bpy.app.version_string}: helper's first surface vs the user's Depth pass: "
          f"{result}", flush=True)
    with open(args.out, "w") as f:
        json.dump(result, f)


main()
