#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The dark fringe a composite leaves on silhouettes against the sky, with two builds of libssao.

    /usr/bin/python3 benchmarks/silhouette_fringe.py SCENE.exr --camera CAM.json --radius R \\
        --baseline OLD/libssao.so [--candidate build/lib/libssao.so] [--crop OUT.png]

Reads Depth, Normal and Combined from a Blender multilayer EXR (opaque film), composites the
Combined pass with each library and looks at the silhouette pixels: geometry pixels (depth
below the background) with a background pixel among their 8 neighbours. There the Normal
pass's length is the surface's share c of the pixel (Cycles averages unit normals with the
sky's zeros). It prints, over those pixels, the mean c, and per library the mean darkening
1 - composite / beauty next to what the surface's share alone would get, c (1 - AO): the
excess is the fringe (the sky's share darkened). --crop writes the most fringed 64x64 region:
beauty, baseline composite, candidate composite, side by side.
"""
import argparse
import os
import sys

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "python"))
import ssao  # noqa: E402
from compare_libraries import camera_parameters, read_passes  # noqa: E402

BACKGROUND = 1e9  # Cycles writes 1e10 on the sky


def read_beauty(path):
    image = oiio.ImageInput.open(path)
    names = list(image.spec().channelnames)
    pixels = image.read_image(format="float")
    image.close()
    index = [next((i for i, n in enumerate(names) if n.endswith(f"Combined.{c}")), None)
             for c in "RGBA"]
    if None in index[:3]:
        sys.exit(f"silhouette_fringe: {path} has no Combined pass")
    index = [i for i in index if i is not None]
    return np.ascontiguousarray(pixels[:, :, index])


def composite(library, params, depth, normal, beauty):
    lib = ssao.load_library(library)
    out = np.zeros_like(beauty)
    ao = np.zeros(depth.shape, np.float32)
    with ssao.Job(lib) as job:
        for name, value in params.items():
            job.set(name, value)
        job.set_image("depth", depth)
        job.set_image("normal", normal)
        job.set_image("beauty", beauty)
        job.set_image("composite", out)
        job.set_image("ao", ao)
        job.run()
    return out, ao


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--camera", required=True)
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--baseline", required=True)
    parser.add_argument("--candidate", default=None)
    parser.add_argument("--crop", default=None, metavar="OUT.png")
    args = parser.parse_args()

    depth, normal, _ = read_passes(args.scene)
    beauty = read_beauty(args.scene)
    params = camera_parameters(args.camera)
    params.update(radius=args.radius, threads=2)
    geometry = depth < BACKGROUND
    padded = np.pad(geometry, 1, constant_values=True)
    beside_sky = np.zeros_like(geometry)
    h, w = depth.shape
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            beside_sky |= ~padded[dy:dy + h, dx:dx + w]
    edge = geometry & beside_sky
    coverage = np.clip(np.linalg.norm(normal, axis=2), 0.0, 1.0)
    luminance = beauty[:, :, :3].mean(axis=2)
    lit = edge & (luminance > 1e-4)
    print(f"{os.path.basename(args.scene)} {w}x{h}: {int(edge.sum())} silhouette pixels against "
          f"the sky, mean coverage {coverage[edge].mean():.3f}")
    results = {}
    for name, library in (("baseline", args.baseline), ("candidate", args.candidate)):
        out, ao = composite(library, params, depth, normal, beauty)
        darkening = 1.0 - out[:, :, :3].mean(axis=2)[lit] / luminance[lit]
        surface_share = (coverage * (1.0 - ao))[lit]
        results[name] = out
        print(f"  {name:9s} mean darkening {darkening.mean():.4f}, the surface's share alone "
              f"{surface_share.mean():.4f}, fringe (excess) {(darkening - surface_share).mean():+.4f}")
    if args.crop:
        excess = np.zeros(depth.shape)
        base = results["baseline"][:, :, :3].mean(axis=2)
        excess[lit] = (luminance[lit] - base[lit]) * (1.0 - coverage[lit])
        y, x = np.unravel_index(np.argmax(excess), excess.shape)
        y0, x0 = min(max(y - 32, 0), h - 64), min(max(x - 32, 0), w - 64)
        tiles = [beauty[y0:y0 + 64, x0:x0 + 64, :3], results["baseline"][y0:y0 + 64, x0:x0 + 64, :3],
                 results["candidate"][y0:y0 + 64, x0:x0 + 64, :3]]
        strip = np.clip(np.concatenate(tiles, axis=1), 0.0, 1.0) ** (1 / 2.2)
        strip = np.repeat(np.repeat(strip, 4, axis=0), 4, axis=1)  # nearest, to see pixels
        spec = oiio.ImageSpec(strip.shape[1], strip.shape[0], 3, oiio.UINT8)
        out = oiio.ImageOutput.create(args.crop)
        out.open(args.crop, spec)
        out.write_image(np.ascontiguousarray(strip, np.float32))
        out.close()
        print(f"  crop at ({x0}, {y0}) written to {args.crop}: beauty | baseline | candidate")


if __name__ == "__main__":
    main()
