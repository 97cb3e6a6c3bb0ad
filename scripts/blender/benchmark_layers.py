# SPDX-License-Identifier: MIT
"""A benchmark scene's extra depth layers and guard band, on its reference render's pixel grid:

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/benchmark_layers.py -- --scene thin --out kit/thin \\
        --width 640 --height 360 --overscan 64

builds the scene as scripts/blender/benchmark_scenes.py does and writes PREFIX.layers.exr, the
file scripts/blender/render_layers.py writes (the 2nd to 5th hits with their facing, the 1-spp
Depth and Normal passes, the band as overscan), and PREFIX.layers.json (its render time).
benchmarks/speed_error.py scores the library with them (ssao_eval --layers). With
``--truck-px P``, a frame of the camera move of scripts/blender/benchmark_sequence.py
(benchmarks/flicker.py's layered rows).
"""

import argparse
import json
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes  # noqa: E402
import benchmark_sequence  # noqa: E402
import export_cameras  # noqa: E402
import make_reference_scene as reference  # noqa: E402
import render_layers  # noqa: E402

HITS = render_layers.addon_module("hidden_surfaces").MAX_HITS  # as the add-on's node


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="benchmark_layers.py", description=__doc__.split("\n")[0])
    parser.add_argument("--scene", choices=sorted(benchmark_scenes.LAYOUTS), required=True)
    parser.add_argument("--out", required=True, help="output prefix")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--level", type=int, default=0)
    parser.add_argument("--overscan", type=int, default=64, help="guard band, pixels a side")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--truck-px", type=float, default=None,
                        help="a frame of benchmark_sequence.py's camera move")
    args = parser.parse_args(argv)
    if args.width < 1 or args.height < 1 or args.threads < 1 or args.overscan < 0:
        parser.error("--width, --height and --threads must be positive, --overscan >= 0")
    return args


def main():
    args = parse_args(export_cameras.script_argv())
    scene = bpy.context.scene
    cam_obj, layout = benchmark_scenes.build_scene(scene, args.scene, args.level)
    if args.truck_px is not None:
        benchmark_sequence.truck_camera(cam_obj, layout, args.truck_px, args.width)
    prefix = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(prefix), exist_ok=True)
    # The reference render's settings (engine, seed, resolution, threads): the same pixel grid
    # and the same sample-0 jitter, so hit 1 here is the reference's Depth pass.
    args.border, args.no_ao_pass, args.samples, args.seed = None, True, 1, 1
    reference.ENGINES["cycles"](scene, args)
    reference.configure_render(scene, args, prefix + ".unused.exr")
    start = time.perf_counter()
    render_layers.write_layers_file(scene, prefix + ".layers.exr", "ViewLayer", HITS,
                                    args.overscan)
    seconds = time.perf_counter() - start
    with open(prefix + ".layers.json", "w", encoding="utf-8") as f:
        json.dump({"scene": args.scene, "width": args.width, "height": args.height,
                   "overscan": args.overscan, "hits": HITS, "truck_px": args.truck_px,
                   "render_seconds": round(seconds, 3),
                   "blender_version": bpy.app.version_string}, f, indent=1)
    print("benchmark_layers: wrote %s.layers.exr (%dx%d + %d px band) in %.2f s"
          % (prefix, args.width, args.height, args.overscan, seconds))


if __name__ == "__main__":
    export_cameras.run_script(main, "benchmark_layers")
