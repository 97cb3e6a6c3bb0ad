#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Run time vs error of libssao against Cycles' ray-traced AO pass.

For each scene NAME (NAME.exr: Blender multilayer with Depth, Normal and the AO pass;
NAME.camera.json; NAME.json with ao_distance), runs the requested configurations and prints
RMSE over geometry pixels (depth finite and < 0.9 * clip_end) and wall time.

    /usr/bin/python3 benchmarks/cycles_accuracy.py DATA_DIR [--scenes a,b] [--config k=v,k=v ...]
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "blender_addon"))
import ssao_native  # noqa: E402

CAMERA_FLOATS = ("lens", "sensor_width", "sensor_height", "shift_x", "shift_y", "ortho_scale",
                 "clip_start", "clip_end")


def load_scene(data_dir, name):
    buf = oiio.ImageBuf(os.path.join(data_dir, name + ".exr"))
    spec = buf.spec()
    pixels = buf.get_pixels(oiio.FLOAT)
    index = {c: i for i, c in enumerate(spec.channelnames)}
    layer = next(c[: -len(".Depth.Z")] for c in spec.channelnames if c.endswith(".Depth.Z"))
    pick = lambda names: np.ascontiguousarray(pixels[:, :, [index[f"{layer}.{n}"] for n in names]])  # noqa: E731
    with open(os.path.join(data_dir, name + ".camera.json")) as f:
        camera = json.load(f)
    meta = {}
    meta_path = os.path.join(data_dir, name + ".json")
    if os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
    return {
        "name": name,
        "depth": pick(["Depth.Z"])[:, :, 0].copy(),
        "normal": pick(["Normal.X", "Normal.Y", "Normal.Z"]),
        "truth": pick(["AO.R"])[:, :, 0].copy(),
        "camera": camera,
        "radius": float(meta.get("ao_distance", 1.0)),
    }


def apply_camera(job, camera):
    job.set("camera_type", camera["type"])
    for key in CAMERA_FLOATS:
        if key in camera:
            job.set(key, camera[key])
    job.set("sensor_fit", camera.get("sensor_fit", "AUTO"))
    job.set("camera_to_world", [v for row in camera["matrix_world"] for v in row])


def run(lib, scene, config):
    ao = np.zeros_like(scene["depth"])
    with ssao_native.Job(lib) as job:
        apply_camera(job, scene["camera"])
        job.set("radius", scene["radius"])
        use_normals = config.pop("normals", "pass") != "none"
        for key, value in config.items():
            job.set(key, value)
        job.set_image("depth", scene["depth"])
        if use_normals:
            job.set_image("normal", scene["normal"])
        job.set_image("ao", ao)
        start = time.perf_counter()
        job.run()
        seconds = time.perf_counter() - start
    return ao, seconds


def rmse(scene, ao):
    d = scene["depth"]
    mask = np.isfinite(d) & (d < 0.9 * scene["camera"].get("clip_end", 1e9)) & (d > 0)
    diff = ao[mask] - scene["truth"][mask]
    return float(np.sqrt(np.mean(diff * diff))), float(np.mean(diff))


def parse_config(text):
    config = {}
    for item in filter(None, text.split(",")):
        key, value = item.split("=", 1)
        config[key] = value
    return config


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data_dir")
    parser.add_argument("--scenes", default="crates,shelf,arches")
    parser.add_argument("--config", action="append",
                        help="comma-separated parameter=value list; repeat for more rows "
                             "(normals=none reconstructs normals from depth)")
    parser.add_argument("--library", default=None, help="path to libssao.so")
    args = parser.parse_args()
    lib = ssao_native.load_library(args.library)
    configs = args.config or ["variant=hemisphere", "variant=sphere"]
    scenes = [load_scene(args.data_dir, n) for n in args.scenes.split(",")]
    print(f"{'scene':8} {'config':60} {'RMSE':>7} {'bias':>7} {'ms':>8}")
    for text in configs:
        for scene in scenes:
            ao, seconds = run(lib, scene, parse_config(text))
            error, bias = rmse(scene, ao)
            print(f"{scene['name']:8} {text:60} {error:7.4f} {bias:+7.4f} {seconds * 1e3:8.1f}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
