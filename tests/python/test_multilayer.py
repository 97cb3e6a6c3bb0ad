#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Blender add-on's EXR reader/writer (blender_addon/multilayer.py) against OpenImageIO:
what one writes the other reads back, for every codec and depth, single- and multi-part, and
hostile files are refused with a message."""
import os
import shutil
import struct
import sys
import tempfile
import unittest

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "blender_addon"))
sys.path.insert(0, os.path.join(HERE, ".."))
import multilayer  # noqa: E402
from image_files import read_image, write_multipart_exr  # noqa: E402


def sample_planes(height=37, width=53):
    rng = np.random.default_rng(7)
    planes = {f"ViewLayer.Combined.{c}": rng.random((height, width), np.float32) for c in "RGBA"}
    planes["ViewLayer.Depth.Z"] = rng.random((height, width), np.float32) * 1000
    planes["ViewLayer.Normal.X"] = rng.standard_normal((height, width)).astype(np.float32)
    return planes


def _offset_table(data):
    """Where the offset table of a file written by multilayer.write starts (its last header
    attribute is screenWindowWidth, a float)."""
    at = data.index(b"screenWindowWidth\0float\0")
    return at + len(b"screenWindowWidth\0float\0") + 4 + 4 + 1


def _with_bad_offsets(data):
    """The file with its first chunk offset pointing past the end."""
    at = _offset_table(data)
    return data[:at] + (2 ** 40).to_bytes(8, "little") + data[at + 8:]


def _with_data_window(data, width, height):
    """The file claiming a data window of width x height pixels."""
    at = data.index(b"dataWindow\0box2i\0") + len(b"dataWindow\0box2i\0") + 4
    return data[:at] + struct.pack("<4i", 0, 0, width - 1, height - 1) + data[at + 16:]


def _with_first_offset_repeated(data):
    """The file with its second chunk offset pointing at the first chunk (rows left empty)."""
    at = _offset_table(data)
    return data[:at + 8] + data[at:at + 8] + data[at + 16:]


class MultilayerTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="ssao_multilayer_")
        self.planes = sample_planes()

    def tearDown(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.folder, name)

    def test_written_files_read_back_in_openimageio(self):
        for codec in ("NONE", "ZIPS", "ZIP"):
            for half in (False, True):
                with self.subTest(codec=codec, half=half):
                    path = self.path(f"{codec}_{half}.exr")
                    multilayer.write(path, self.planes, half=half, codec=codec)
                    names, pixels = read_image(path)
                    self.assertEqual(sorted(names), sorted(self.planes))
                    for name, plane in self.planes.items():
                        # half: colour channels in 16 bits (11-bit mantissa), the rest 32.
                        colour = name.rsplit(".", 1)[-1] in "RGBA"
                        tolerance = float(np.abs(plane).max()) * 2 ** -10 if half and colour \
                            else 0
                        np.testing.assert_allclose(pixels[:, :, names.index(name)], plane,
                                                   rtol=0, atol=tolerance)
                    spec = oiio.ImageInput.open(path).spec()
                    self.assertEqual(spec.get_string_attribute("compression"), codec.lower())

    def test_reads_single_and_multi_part_files_openimageio_wrote(self):
        names = sorted(self.planes)
        path = self.path("multipart.exr")
        write_multipart_exr(path, self.planes)  # one part per layer, as Blender 5.x writes
        planes, _ = multilayer.read(path)
        self.assertEqual(sorted(planes), names)
        for name in names:
            np.testing.assert_array_equal(planes[name], self.planes[name])

    def test_rewrite_replaces_the_composite_and_adds_the_ao(self):
        passes = dict(self.planes)
        passes.update({f"Composite.Combined.{c}": np.zeros_like(passes["ViewLayer.Depth.Z"])
                       for c in "RGBA"})
        multilayer.write(self.path("passes.exr"), passes, codec="ZIP")
        composite = {c: np.full_like(passes["ViewLayer.Depth.Z"], 0.25 * (i + 1))
                     for i, c in enumerate("RGBA")}
        multilayer.write(self.path("composite.exr"), composite, codec="NONE")
        ao = np.linspace(0, 1, passes["ViewLayer.Depth.Z"].size, dtype=np.float32).reshape(
            passes["ViewLayer.Depth.Z"].shape)
        multilayer.rewrite(self.path("passes.exr"), self.path("composite.exr"),
                           {"SSAO.AO": ao}, self.path("out.exr"))
        names, pixels = read_image(self.path("out.exr"))
        for i, c in enumerate("RGBA"):
            np.testing.assert_array_equal(pixels[:, :, names.index(f"Composite.Combined.{c}")],
                                          0.25 * (i + 1))
        np.testing.assert_array_equal(pixels[:, :, names.index("SSAO.AO.V")], ao)
        np.testing.assert_array_equal(pixels[:, :, names.index("ViewLayer.Depth.Z")],
                                      self.planes["ViewLayer.Depth.Z"])

    def test_hostile_files_are_refused_with_a_message(self):
        multilayer.write(self.path("good.exr"), self.planes, codec="ZIP")
        with open(self.path("good.exr"), "rb") as f:
            data = f.read()
        cases = {"empty": (b"", "not an OpenEXR"),
                 "not_exr": (b"P6\n1 1\n255\n\0\0\0", "not an OpenEXR"),
                 "truncated_header": (data[:40], "truncated"),
                 "truncated_data": (data[:len(data) // 2], "truncated"),
                 "bad_offsets": (_with_bad_offsets(data), "truncated"),
                 "huge_window": (_with_data_window(data, 1 << 24, 37), "data window"),
                 "missing_rows": (_with_first_offset_repeated(data), "rows have no data")}
        for name, (content, message) in cases.items():
            with self.subTest(name):
                with open(self.path(name), "wb") as f:
                    f.write(content)
                with self.assertRaisesRegex(multilayer.ExrError, message):
                    multilayer.read(self.path(name))


if __name__ == "__main__":
    unittest.main(verbosity=2)
