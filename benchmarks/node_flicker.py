#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Blender node's temporal filter in an animation render: flicker and error with the
filter (the node's default temporal_frames) and without it (temporal_frames = 1), against
Cycles' AO pass of the same render.

    benchmarks/node_flicker.py [--blender blender] [--zip build/blender/ssao_compositor.zip]
        [--frames 6] [--samples 256] [--width 320 --height 180] [--out DIR]

Builds the add-on's test scene (tests/blender/build_ssao_scene.py: the camera moves and turns
over the frames, Cycles' AO pass on) with the node at its defaults, renders it headless with
-a twice (the add-on from --zip, installed in a scripts folder of its own) and reads each
frame's SSAO.AO layer and the render's AO and Depth from the multilayer output. Flicker is
benchmarks/flicker.py's (each frame's AO carried to the next frame's pixels through depth and
both cameras; RMS of the difference over all pixels, and over the occluded ones, reference AO
< 0.9); RMSE is against the AO pass, whose own noise at --samples shows in its flicker row.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import zipfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import flicker  # noqa: E402  (benchmarks/flicker.py: read_channels, View, flicker, rmse)

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD_SCENE = os.path.join(REPO_ROOT, "tests", "blender", "build_ssao_scene.py")
# Run in Blender before -a: every SSAO node computes each frame alone.
EACH_FRAME_ALONE = (
    "import sys\n"
    "compute = next(m for n, m in sys.modules.items() if n.endswith('ssao_compositor.compute'))\n"
    "for _, node in compute.all_ssao_nodes():\n"
    "    node.temporal_frames = 1\n")


def blender(args, scripts, *arguments):
    command = [args.blender, "-b", "--factory-startup", "-noaudio", "--addons",
               "ssao_compositor", *arguments]
    result = subprocess.run(command, env=dict(os.environ, BLENDER_USER_SCRIPTS=scripts),
                            capture_output=True, text=True, check=False)
    if result.returncode != 0 or "Traceback" in result.stdout + result.stderr:
        raise SystemExit(f"{' '.join(command)} failed:\n{result.stdout}{result.stderr}")
    return result.stdout


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--zip", default=os.path.join(REPO_ROOT, "build", "blender",
                                                      "ssao_compositor.zip"))
    parser.add_argument("--frames", type=int, default=6)
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--height", type=int, default=180)
    parser.add_argument("--out", default=None, help="keep the renders here (default: a "
                        "temporary folder)")
    args = parser.parse_args()
    if args.frames < 2:
        parser.error("--frames must be at least 2")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.abspath(args.out or tmp)
        scripts = os.path.join(tmp, "scripts")
        with zipfile.ZipFile(args.zip) as archive:
            archive.extractall(os.path.join(scripts, "addons"))
        blend = os.path.join(out, "scene.blend")
        blender(args, scripts, "--python-exit-code", "1", "-P", BUILD_SCENE, "--",
                "--out", blend, "--width", str(args.width), "--height", str(args.height),
                "--samples", str(args.samples), "--frames", str(args.frames), "--ao-pass",
                "--format", "OPEN_EXR_MULTILAYER",
                "--output", os.path.join(out, "filtered", "out_####.exr"))
        blender(args, scripts, blend, "-a")
        blender(args, scripts, blend, "--python-expr", EACH_FRAME_ALONE,
                "-o", os.path.join(out, "alone", "out_####"), "-a")
        frames, reference, filtered, alone = [], [], [], []
        for frame in range(1, args.frames + 1):
            name = f"out_{frame:04d}.exr"
            try:
                depth, ao_pass, ao = flicker.read_channels(os.path.join(out, "filtered", name),
                                                           ["Depth.Z", "AO.R", "SSAO.AO.V"])
                alone += flicker.read_channels(os.path.join(out, "alone", name), ["SSAO.AO.V"])
            except flicker.kit.StepFailed as error:
                raise SystemExit(str(error)) from None
            frames.append((depth, flicker.View(os.path.join(out, f"scene.camera.{frame:04d}.json"),
                                               args.width, args.height)))
            reference.append(np.where(flicker.geometry(depth), ao_pass, 1.0))
            filtered.append(ao)
        print(f"{args.frames} frames, {args.width}x{args.height}, Cycles AO pass at "
              f"{args.samples} spp, {os.path.basename(args.blender)}")
        print("| AO | RMSE vs AO pass | flicker | flicker, occluded |")
        print("|---|--:|--:|--:|")
        for name, aos in (("node, temporal filter (default)", filtered),
                          ("node, each frame alone (temporal_frames 1)", alone),
                          (f"Cycles AO pass, {args.samples} spp (its own noise)", reference)):
            error = np.mean([flicker.rmse(a, r, f[0])
                             for a, r, f in zip(aos, reference, frames)])
            everywhere, occluded = flicker.flicker(frames, aos, reference)
            print(f"| {name} | {error:.4f} | {everywhere:.4f} | {occluded:.4f} |")


if __name__ == "__main__":
    main()
