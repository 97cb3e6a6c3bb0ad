# SPDX-License-Identifier: MIT
"""The node's AO against Cycles' AO pass of the same render, per node setting, in one Blender
(docs/blender.md, "Hidden surfaces and overscan"): renders the open .blend once (a scene from
tests/blender/build_ssao_scene.py with --ao-pass and --passes-dir), then recomputes the node's
AO from that render's passes with each setting and prints one `[measure]` line each: RMSE over
geometry pixels against the AO pass (its own noise included), and over the pixels where the
depth jumps (edges) and the rest.

    blender -b --factory-startup --addons ssao_compositor SCENE.blend \\
        -P tests/blender/measure_node_accuracy.py -- --passes DIR/0001.exr \\
        [--settings NONE:0 PEELED:0 NONE:64 PEELED:64] [--save DIR]
"""
import argparse
import importlib
import sys

import bpy
import numpy as np


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--passes", required=True,
                        help="the EXR the scene's File Output node writes for frame 1")
    parser.add_argument("--settings", nargs="+",
                        default=["NONE:0", "PEELED:0", "NONE:64", "PEELED:64"],
                        help="hidden_surfaces:overscan pairs (overscan: pixels, or 'radius' "
                             "for the band that follows the radius)")
    parser.add_argument("--save", default=None,
                        help="also save each setting's AO and the reference as DIR/*.npy")
    return parser.parse_args(argv)


def addon():
    name = next(n for n in sys.modules if n.endswith("ssao_compositor"))
    return importlib.import_module(name)


def main():
    args = parse_args()
    ssao = addon()
    scene = bpy.context.scene
    scene.frame_set(1)
    bpy.ops.render.render(scene=scene.name)
    planes, _ = importlib.import_module(ssao.__name__ + ".multilayer").read(args.passes)
    reference = next(planes[n] for n in planes if n in ("AO.R", "AO.V"))
    depth = planes["Depth.V"] if "Depth.V" in planes else planes["Depth.Z"]
    geometry = np.isfinite(depth) & (depth > 0) & (depth < 1e9)
    jump = np.zeros_like(geometry)
    for axis in (0, 1):
        for shift in (1, -1):
            other = np.roll(depth, shift, axis)
            jump |= np.abs(other - depth) > 0.05 * np.minimum(other, depth)
    edges = geometry & jump
    node = ssao.compute.ssao_nodes(scene)[0]
    for setting in args.settings:
        hidden, overscan = setting.split(":")
        node.hidden_surfaces = hidden
        if overscan == "radius":
            node.overscan_mode = 'RADIUS'
        else:
            node.overscan = int(overscan)  # sets overscan_mode to 'PIXELS'
        band = ssao.compute.band_width(node, scene, depth) if overscan == "radius" else ""
        ao = ssao.compute.compute_ao(scene, node, render=False)
        if args.save:
            np.save(f"{args.save}/ao_{hidden}_{overscan}.npy", ao)
            np.save(f"{args.save}/reference.npy", reference)
        error = ao - reference
        rmse = {name: float(np.sqrt(np.mean(error[mask] ** 2))) for name, mask in
                (("all", geometry), ("edges", edges), ("rest", geometry & ~edges))}
        print(f"[measure] {bpy.app.version_string} {scene.render.resolution_x}x"
              f"{scene.render.resolution_y} hidden_surfaces={hidden} overscan={overscan}"
              f"{f' ({band} px)' if band != '' else ''}: "
              f"RMSE {rmse['all']:.4f} (edges {rmse['edges']:.4f}, rest {rmse['rest']:.4f}), "
              f"mean AO {float(ao[geometry].mean()):.4f} vs {float(reference[geometry].mean()):.4f}",
              flush=True)


main()
