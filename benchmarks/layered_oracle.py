#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""What any screen-space estimator could reach with the same depth layers: a brute-force AO ray
march through a kit scene's layers file, scored against the scene's Cycles AO pass.

    benchmarks/layered_oracle.py KIT_FOLDER/ref LAYERS.exr [--rays 256] [--steps 48]
        [--stride 4] [--thickness 0.5] [--one-layer] [--compare AO.exr ...]
        [--write-ao OUT.exr]

For every stride-th pixel (in x and y) that shows geometry (depth below 0.9 x clip_end),
`rays` cosine-weighted rays of the scene's AO distance (ref.json's ao_distance) leave the
surface (depth and Normal pass of ref.exr) and each is marched in `steps` jittered steps.
A step is occupied where its pixel's ray is inside a solid: from a front face to the back face
that closes it, the hits as LAYERS.exr holds them (the guard band included; hits not behind
the frame's depth dropped and the later ones moved up, as the Blender add-on does); behind a
last front face `thickness` (a fraction of the AO distance) deep; in front of the visible
surface or behind a back face, free. A ray is blocked by its first occupied step, as Cycles'
binary AO rays are. With --one-layer only the frame's depth is known (no band, no hits
behind): behind the visible surface is solid for `thickness`.

Prints the march's RMSE against the reference AO over those pixels, raw and with its own noise
(binary rays: mean p(1 - p) / (rays - 1)) taken out, its bias, and the same pixels' RMSE and
bias of each --compare image (an AO image of the frame, e.g. ssao_eval --write-ao). The march
takes each pixel at its centre, as one depth sample (no pixel filter), so it is not a bound at
edges; over a scene it says how much of an estimator's error the layers leave unexplained.
About 40 s a scene at 640x360 with the defaults (numpy, one thread).
"""

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import flicker  # noqa: E402  (the kit's camera JSON, EXR channels and layers files)


def parse_args(argv=None):
    parser = argparse.ArgumentParser(prog="layered_oracle.py",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("reference",
                        help="the kit render's prefix (PREFIX.exr, .camera.json, .json)")
    parser.add_argument("layers", help="its layers file (scripts/blender/benchmark_layers.py)")
    parser.add_argument("--rays", type=int, default=256)
    parser.add_argument("--steps", type=int, default=48)
    parser.add_argument("--stride", type=int, default=4, help="every n-th pixel in x and y")
    parser.add_argument("--thickness", type=float, default=0.5,
                        help="depth of a solid behind a last front face, in AO distances")
    parser.add_argument("--one-layer", action="store_true",
                        help="the frame's depth alone: no hits behind it, no guard band")
    parser.add_argument("--compare", action="append", default=[], metavar="AO.exr")
    parser.add_argument("--write-ao", metavar="OUT.exr")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    if args.rays < 2 or args.steps < 1 or args.stride < 1 or not args.thickness > 0:
        parser.error("--rays must be at least 2, --steps and --stride positive, --thickness > 0")
    return args


def read_layers(path, depth, one_layer):
    """The layers file's visible depth (the frame's own inside it), its deeper hits behind that
    depth (flicker.hits_behind: NO_HIT where none) and whether each is a back face, on the
    file's whole window; and the band's width."""
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(path)
    if image is None:
        raise SystemExit("layered_oracle.py: cannot open %s: %s" % (path, oiio.geterror()))
    band = -image.spec().x
    image.close()
    extra = range(2, flicker.hit_count(path) + 1)
    planes = flicker.read_channels(path, ["Depth.Z"] + ["Depth%d.Z" % k for k in extra] +
                                   ["Facing%d.V" % k for k in extra])
    visible = flicker.merged_with_band(planes[0], depth, band)
    hits, facing = flicker.hits_behind(visible, planes[1:len(extra) + 1], planes[len(extra) + 1:])
    back = facing > 0.5
    if one_layer:  # no hits behind (a NO_HIT entry would read as a face closing the solid)
        hits, back = hits[..., :0], back[..., :0]
        inside = np.zeros(visible.shape, bool)
        inside[band:band + depth.shape[0], band:band + depth.shape[1]] = True
        visible = np.where(inside, visible, flicker.NO_HIT)
    return visible, hits, back, band


def occupied(view, visible, hits, back, band, points, thickness):
    """Whether each world point lies inside a solid as the layers describe it."""
    u, v, z = view.project(points)
    height, width = visible.shape
    col = np.floor(np.nan_to_num(u, nan=-1e9)).astype(np.int64) + band
    row = np.floor(np.nan_to_num(v, nan=-1e9)).astype(np.int64) + band
    known = np.isfinite(z) & (z > 0) & (col >= 0) & (col < width) & (row >= 0) & (row < height)
    col, row = np.where(known, col, 0), np.where(known, row, 0)
    entry = visible[row, col]
    pending = known & (entry < 1e9) & (z >= entry)  # behind the visible surface, a front face
    solid = np.ones(len(z), bool)  # after the hit passed last: inside a solid
    last = entry.copy()
    inside = np.zeros(len(z), bool)
    for k in range(hits.shape[-1]):
        hit, leaves = hits[row, col, k], back[row, col, k]
        here = pending & (z < hit)
        inside |= here & solid
        pending &= ~here
        solid = np.where(pending, ~leaves, solid)
        last = np.where(pending, hit, last)
    return inside | (pending & solid & (z - last < thickness))


def march(args, view, depth, normals, radius, visible, hits, back, band, far):
    ys, xs = np.nonzero(flicker.geometry(depth) & (depth < far))
    keep = (ys % args.stride == 0) & (xs % args.stride == 0)
    ys, xs = ys[keep], xs[keep]
    origin = view.world_points(np.where(flicker.geometry(depth), depth, 1.0))[ys, xs]
    normal = normals[ys, xs].astype(np.float64)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-12
    helper = np.where(np.abs(normal[:, :1]) > 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    tangent = np.cross(normal, helper)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    bitangent = np.cross(normal, tangent)
    origin = origin + normal * (1e-3 * depth[ys, xs, None] + 1e-4)  # off the surface
    rng = np.random.default_rng(args.seed)
    blocked_rays = np.zeros(len(ys))
    thickness = args.thickness * radius
    for _ in range(args.rays):
        u1, u2 = rng.random(len(ys)), rng.random(len(ys))
        r, phi = np.sqrt(u1), 2 * np.pi * u2
        direction = (tangent * (r * np.cos(phi))[:, None] + bitangent * (r * np.sin(phi))[:, None]
                     + normal * np.sqrt(np.maximum(0.0, 1.0 - u1))[:, None])
        jitter = rng.random(len(ys))
        blocked = np.zeros(len(ys), bool)
        for step in range(args.steps):
            t = (step + jitter) / args.steps * radius
            blocked |= occupied(view, visible, hits, back, band, origin + direction * t[:, None],
                                thickness)
        blocked_rays += blocked
    return ys, xs, 1.0 - blocked_rays / args.rays


def main(argv=None):
    args = parse_args(argv)
    depth, nx, ny, nz, truth = flicker.read_channels(
        args.reference + ".exr", ["Depth.Z", "Normal.X", "Normal.Y", "Normal.Z", "AO.R"])
    with open(args.reference + ".json", encoding="utf-8") as f:
        radius = json.load(f)["ao_distance"]
    height, width = depth.shape
    view = flicker.View(args.reference + ".camera.json", width, height)
    visible, hits, back, band = read_layers(args.layers, depth, args.one_layer)
    with open(args.reference + ".camera.json", encoding="utf-8") as f:
        far = 0.9 * json.load(f)["clip_end"]  # geometry as ssao_eval counts it
    ys, xs, ao = march(args, view, depth, np.stack([nx, ny, nz], -1), radius, visible, hits, back,
                       band, far)
    error = ao - truth[ys, xs]
    noise = np.mean(ao * (1 - ao)) / (args.rays - 1)
    print("%s: %d pixels (every %d-th), %d rays x %d steps, thickness %g x %g%s"
          % (args.reference, len(ys), args.stride, args.rays, args.steps, args.thickness, radius,
             ", one layer" if args.one_layer else ", layers + %d px band" % band))
    print("march    RMSE %.4f (without its noise %.4f; noise %.4f) bias %+.4f"
          % (np.sqrt(np.mean(error ** 2)), np.sqrt(max(0.0, np.mean(error ** 2) - noise)),
             np.sqrt(noise), np.mean(error)))
    for path in args.compare:
        (other,) = flicker.read_channels(path, ["AO"])
        e = other[ys, xs] - truth[ys, xs]
        print("%-8s RMSE %.4f bias %+.4f  (%s)" % ("compare", np.sqrt(np.mean(e ** 2)), np.mean(e),
                                                  path))
    if args.write_ao:
        import OpenImageIO as oiio
        image = np.ones((height, width), np.float32)
        image[ys, xs] = ao
        out = oiio.ImageOutput.create(args.write_ao)
        out.open(args.write_ao, oiio.ImageSpec(width, height, 1, oiio.FLOAT))
        out.write_image(image[..., None])
        out.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
