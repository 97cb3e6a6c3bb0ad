# SPDX-License-Identifier: MIT
"""Reading image files in the Python tests (cli, povray, blender): one reader for all."""
import numpy as np
import OpenImageIO as oiio


def read_image(path):
    """(channel names, float32 array height x width x channels) of any file OpenImageIO reads.
    ImageInput, not ImageBuf: ImageBuf's cache would return stale pixels for a file rewritten
    under the same name."""
    inp = oiio.ImageInput.open(path)
    assert inp is not None, f"cannot read {path}: {oiio.geterror()}"
    spec = inp.spec()
    pixels = inp.read_image(oiio.FLOAT)
    assert pixels is not None, f"cannot read {path}: {inp.geterror()}"
    inp.close()
    return list(spec.channelnames), np.asarray(pixels, np.float32).reshape(
        spec.height, spec.width, spec.nchannels)
