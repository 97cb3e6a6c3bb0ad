#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""What povray-ssao's guard band (--overscan) is worth: AO against the visibility within the
radius ray-cast by tests/povray/test_povray.py's helpers (512 cosine-distributed rays per
pixel), for several band widths. The rows of docs/povray.md, "Guard band".

    /usr/bin/python3 tests/povray/measure_guard_band.py [--bridge build/bin/povray-ssao]
        [--size 160x120] [--bands 0,8,16,32] [--scenes edge_occluders,box_corner,...]
        [--radius R] [--work DIR]

Per scene and band: RMS of AO - cast visibility over the geometry pixels away from silhouettes
(all), and over those within 10% of the width from an edge (border). Without --radius, the
radius povray-ssao chooses (printed). Exit status 0, 1 if a run fails.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, ".."))
import test_povray as T  # noqa: E402
from image_files import read_image  # noqa: E402

SCENES = {
    "edge_occluders": (T.EO_CAMERA, dict(plane=True, boxes=T.EO_BOXES)),
    "box_corner": (T.BC_CAMERA, dict(plane=True, spheres=[T.BC_SPHERE], boxes=T.BC_BOXES)),
    "sphere_on_plane": (T.SOP_CAMERA, dict(plane=True, spheres=[T.SOP_SPHERE])),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bridge", default=os.path.join(HERE, "..", "..", "build", "bin",
                                                         "povray-ssao"))
    parser.add_argument("--size", default="160x120")
    parser.add_argument("--bands", default="0,8,16,32")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--radius", type=float)
    parser.add_argument("--work")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    work = args.work or tempfile.mkdtemp(prefix="guard-band-")
    os.makedirs(work, exist_ok=True)
    for name in args.scenes.split(","):
        camera, geometry = SCENES[name]
        with open(os.path.join(T.SCENES, name + ".pov")) as f, \
                open(os.path.join(work, name + ".pov"), "w") as g:
            g.write(f.read())
        origin, rays, _, _ = T.camera_rays(**camera, width=width, height=height)
        dist, normal, obj = T.intersect(origin, rays, **geometry)
        normal[np.sum(normal * rays, axis=-1) > 0] *= -1.0
        mask = T.interior(obj) & np.isfinite(dist)
        points = (origin + dist[..., None] * rays)[mask]
        rows, columns = np.nonzero(mask)
        edge = np.minimum(np.minimum(rows, height - 1 - rows),
                          np.minimum(columns, width - 1 - columns))
        border = edge < 0.1 * width
        cast = {}
        for band in (int(b) for b in args.bands.split(",")):
            exr = os.path.join(work, f"{name}-{band}.exr")
            cmd = [args.bridge, name + ".pov", "-o", exr, f"+W{width}", f"+H{height}",
                   "--overscan", str(band)]
            if args.radius:
                cmd += ["--radius", repr(args.radius)]
            proc = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
            if proc.returncode != 0:
                sys.exit(f"{' '.join(cmd)} failed:\n{proc.stderr}")
            radius = args.radius
            if radius is None:
                line = next(l for l in proc.stdout.splitlines() if "scene units" in l)
                radius = float(line.split("radius ")[1].split()[0])
            if radius not in cast:
                cast[radius], _ = T.sky_visibility(points, normal[mask], radius, **geometry)
            names, pixels = read_image(exr)
            error = pixels[..., names.index("AO")][mask].astype(np.float64) - cast[radius]
            rms_all = np.sqrt(np.mean(error ** 2))
            rms_border = np.sqrt(np.mean(error[border] ** 2))
            print(f"{name} {width}x{height} radius {radius:.4g} band {band} "
                  f"({100.0 * band / width:.1f}% of W): RMS all {rms_all:.4f}, "
                  f"border {rms_border:.4f}", flush=True)


if __name__ == "__main__":
    main()
