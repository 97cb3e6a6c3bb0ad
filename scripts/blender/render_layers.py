# SPDX-License-Identifier: MIT
"""Renders a scene's hidden-surface layers and guard band into one multilayer EXR that
`build/bin/ssao` reads without flags (a farm runs this before the CLI):

    blender -b --factory-startup SCENE.blend --python scripts/blender/render_layers.py -- \\
        --output OUT.exr [--hits 5] [--overscan G] [--frame N] [--camera-json CAMERA.json]
    build/bin/ssao OUT.exr --camera CAMERA.json --ao-only -o AO.exr

The render is the add-on's helper render (blender_addon/hidden_surfaces.py: Cycles at 1 sample
per pixel, whatever engine the scene uses; the scene and its file are not changed). The add-on
module is the installed one when Blender has it enabled (--addons ssao_compositor), else
blender_addon/ imported from this repository.

The file's channels, named after the scene's first rendered view layer L (the CLI's contract):
L.Depth.Z (planar depth, 1e10 where the ray hits nothing), L.Normal.X/Y/Z (world space), and
for hits k = 2 to 5 L.Depth<k>.Z and L.Facing<k>.V (L.Depth2.Z, L.Facing2.V, ...: depth of
the k-th surface hit along the camera ray, 1e10 when there is none; facing 1 = back face, 0 =
front face or no hit). 32-bit float, ZIP. With --overscan G the data window is the display
window (the render's W x H at (0, 0)) grown by G pixels on each side: (-G, -G) to
(W + G - 1, H + G - 1).
--camera-json writes the camera of that frame (scripts/blender/export_cameras.py's format; it
describes the display window). Errors print `render_layers: error: ...` and exit with 1.
"""
import argparse
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import export_cameras  # noqa: E402

PROG = "render_layers"


def addon_module(name):
    """The add-on's module `name`: the enabled add-on's (legacy or extension) if loaded, else the
    repository's blender_addon package."""
    for module_name, module in list(sys.modules.items()):
        if module_name.endswith("ssao_compositor." + name):
            return module
    sys.path.insert(0, os.path.join(HERE, "..", ".."))
    import importlib
    return importlib.import_module("blender_addon." + name)


def parse_args(argv):
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", "-o", required=True, help="the multilayer EXR to write")
    parser.add_argument("--hits", type=int, default=5, choices=(1, 2, 3, 4, 5),
                        help="surface hits per pixel (1: depth and normal only; default 5, as "
                             "the add-on's node)")
    parser.add_argument("--overscan", type=int, default=0, metavar="G",
                        help="guard band in pixels on each side (default 0)")
    parser.add_argument("--frame", type=int, default=None,
                        help="the frame (default: the file's current frame)")
    parser.add_argument("--scene", default=None, help="the scene (default: the file's current)")
    parser.add_argument("--camera-json", default=None, metavar="PATH",
                        help="also write the frame's camera JSON for the CLI's --camera")
    args = parser.parse_args(argv)
    if args.overscan < 0:
        parser.error("--overscan must be 0 or more pixels")
    return args


def channels(layer_name, layers, hits):
    """The file's channels ({name: (height, width) array, row 0 on top})."""
    planes = {f"{layer_name}.Depth.Z": layers["depth"]}
    for i, axis in enumerate("XYZ"):
        planes[f"{layer_name}.Normal.{axis}"] = layers["normal"][:, :, i]
    for k in range(2, hits + 1):
        planes[f"{layer_name}.Depth{k}.Z"] = layers[f"depth{k}"]
        planes[f"{layer_name}.Facing{k}.V"] = layers[f"facing{k}"]
    return planes


def write_layers_file(scene, output, layer_name, hits, overscan):
    """Renders `scene`'s layers (the add-on's helper render) and writes them to `output` with
    the channels of `layer_name`; returns the layers."""
    hidden_surfaces = addon_module("hidden_surfaces")
    multilayer = addon_module("multilayer")
    layers = hidden_surfaces.render_layers(scene, hits, overscan,
                                           folder=os.path.dirname(os.path.abspath(output)))
    # Blender's own image save writes no data window and no channel names of ours: the add-on's
    # EXR writer (checked against OpenImageIO) does both.
    multilayer.write(output, channels(layer_name, layers, hits), codec="ZIP", overscan=overscan)
    return layers


def main():
    args = parse_args(export_cameras.script_argv())
    scene = export_cameras.find_scene(args.scene)
    frame = scene.frame_current if args.frame is None else args.frame
    scene.frame_set(frame)
    view_layer = next((layer for layer in scene.view_layers if layer.use),
                      scene.view_layers[0])
    if args.camera_json:
        _, description = export_cameras.frame_camera(scene, view_layer, None, frame, True)
    output = bpy.path.abspath(args.output)
    os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    layers = write_layers_file(scene, output, view_layer.name, args.hits, args.overscan)
    if args.camera_json:
        export_cameras.write_json(bpy.path.abspath(args.camera_json), description)
    height, width = layers["depth"].shape
    print(f"{PROG}: wrote {output} (scene '{scene.name}', frame {frame}, view layer "
          f"'{view_layer.name}', {width - 2 * args.overscan}x{height - 2 * args.overscan} + "
          f"{args.overscan} px overscan, {args.hits} hit(s))", flush=True)


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as error:  # noqa: BLE001 - one line, not a traceback, for farm logs
        import traceback
        traceback.print_exc()
        print(f"{PROG}: error: {error}", file=sys.stderr, flush=True)
        sys.exit(1)
