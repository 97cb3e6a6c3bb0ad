#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""AO of a Blender render's EXR from Python, read and written with OpenImageIO (docs/python.md).

    /usr/bin/python3 ambient_occlusion.py RENDER.exr CAMERA.json OUT.exr [RADIUS]

RENDER.exr holds Blender's ViewLayer.Depth.Z and ViewLayer.Normal.X/Y/Z passes, and may hold
the beauty (ViewLayer.Combined.R/G/B: it says how much of an edge pixel each surface covers, as
the command-line tool reads it); CAMERA.json is its camera file
(scripts/blender/export_cameras.py). OUT.exr gets one channel, AO.
"""
import json
import sys

import numpy as np
import OpenImageIO as oiio

import ssao


def read_exr(path):
    """{channel name: float32 (height, width)} of a single-part EXR."""
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit(f"cannot read {path}: {oiio.geterror()}")
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)  # (height, width, channels), row 0 on top
    image.close()
    return {name: pixels[:, :, k] for k, name in enumerate(spec.channelnames)}


def main(render, camera_file, out, radius=None):
    channels = read_exr(render)
    depth = channels["ViewLayer.Depth.Z"]
    normals = np.stack([channels["ViewLayer.Normal." + axis] for axis in "XYZ"], axis=-1)
    colours = [channels.get("ViewLayer.Combined." + c) for c in "RGB"]
    if all(c is not None for c in colours):  # the library's default edge_coverage reads them
        parameters = {"edge_colours": np.stack(colours, axis=-1)}
    else:
        parameters = {}
    with open(camera_file) as f:
        camera = json.load(f)
    # Without a radius: the camera file's ao_distance, else the library's automatic one.
    if radius is not None:
        parameters["radius"] = float(radius)
    try:
        ao = ssao.ambient_occlusion(depth, normals=normals, camera=camera, **parameters)
    except ssao.SSAOError as error:
        sys.exit(f"ssao: {error}")

    spec = oiio.ImageSpec(ao.shape[1], ao.shape[0], 1, oiio.FLOAT)
    spec.channelnames = ("AO",)
    output = oiio.ImageOutput.create(out)
    # (height, width, channels): Debian 12's OpenImageIO 2.4 writes garbage from a 2-D array.
    pixels = ao[:, :, np.newaxis]
    if output is None or not output.open(out, spec) or not output.write_image(pixels):
        sys.exit(f"cannot write {out}: {oiio.geterror()}")
    output.close()
    print(f"{out}: {ao.shape[1]}x{ao.shape[0]}, mean AO {ao.mean():.4f}")


if __name__ == "__main__":
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    main(*sys.argv[1:])
