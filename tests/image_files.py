# SPDX-License-Identifier: MIT
"""Reading image files in the Python tests (cli, povray, blender): one reader for all."""
import numpy as np
import OpenImageIO as oiio


def read_image(path):
    """(channel names, float32 array height x width x channels) of any file OpenImageIO reads;
    the parts of a multi-part EXR (Blender 5.x writes one part per layer) are joined.
    ImageInput, not ImageBuf: ImageBuf's cache would return stale pixels for a file rewritten
    under the same name."""
    inp = oiio.ImageInput.open(path)
    assert inp is not None, f"cannot read {path}: {oiio.geterror()}"
    names, planes, part = [], [], 0
    while inp.seek_subimage(part, 0):
        spec = inp.spec()
        pixels = inp.read_image(part, 0, 0, spec.nchannels, oiio.FLOAT)
        assert pixels is not None, f"cannot read {path}: {inp.geterror()}"
        names += list(spec.channelnames)
        planes.append(np.asarray(pixels, np.float32).reshape(spec.height, spec.width,
                                                             spec.nchannels))
        part += 1
    inp.close()
    return names, np.concatenate(planes, axis=2)


def write_multipart_exr(path, planes):
    """Writes {layer.pass.channel: (height, width) array} as a multi-part EXR, one part per
    layer.pass, as Blender 5.x writes multilayer files."""
    parts = {}
    for name in planes:
        parts.setdefault(name.rsplit(".", 1)[0], []).append(name)
    height, width = next(iter(planes.values())).shape
    specs = []
    for part, names in parts.items():
        spec = oiio.ImageSpec(width, height, len(names), oiio.FLOAT)
        spec.channelnames = tuple(names)
        spec.attribute("name", part)
        spec.attribute("compression", "zip")
        specs.append(spec)
    out = oiio.ImageOutput.create(path)
    assert out is not None and out.open(path, specs), oiio.geterror()
    for i, names in enumerate(parts.values()):
        if i:
            assert out.open(path, specs[i], "AppendSubimage"), out.geterror()
        assert out.write_image(np.stack([planes[n] for n in names], axis=-1).astype(np.float32))
    out.close()
