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
