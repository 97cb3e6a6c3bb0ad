#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The ctypes binding (core/python/ssao/_binding.py) against the built library, without Blender.

    /usr/bin/python3 tests/python/test_native.py LIBRARY [WINDOWS_DLL]
"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "core", "python"))
import ssao  # noqa: E402

LIBRARY = None
WINDOWS_DLL = None


def corner_scene(width=64, height=48):
    """Planar depth of two walls meeting at 90 degrees 6 units ahead (lens 35 mm, 36 mm)."""
    xs = ((np.arange(width) + 0.5) / width - 0.5) * 36.0 / 35.0
    depth = np.minimum(6.0 / (1.0 - xs), 6.0 / (1.0 + xs)).astype(np.float32)
    return np.ascontiguousarray(np.tile(depth, (height, 1)))


class NativeBindingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.lib = ssao.load_library(LIBRARY)

    def run_ao(self, depth, **params):
        ao = np.full(depth.shape, -1.0, np.float32)
        with ssao.Job(self.lib) as job:
            job.set("lens", 35.0)
            for key, value in params.items():
                job.set(key, value)
            job.set_image("depth", depth)
            job.set_image("ao", ao)
            job.run()
        return ao

    def test_parameter_table_has_the_documented_defaults(self):
        params = {p["name"]: p for p in ssao.parameters(self.lib)}
        self.assertEqual(params["variant"]["default_string"], "hemisphere")
        self.assertEqual(params["radius"]["unit"], "scene units")
        self.assertEqual(params["camera_to_world"]["count"], 16)

    def test_errors_raise_with_the_library_message(self):
        with ssao.Job(self.lib) as job:
            with self.assertRaisesRegex(ssao.SSAOError, "unknown parameter 'radus'"):
                job.set("radus", 1.0)
            with self.assertRaisesRegex(ssao.SSAOError, "must be in"):
                job.set("radius", -2.0)
            with self.assertRaisesRegex(ssao.SSAOError, "no depth image"):
                job.run()
            with self.assertRaisesRegex(ssao.SSAOError, "float32"):
                job.set_image("depth", np.zeros((4, 4), np.float64))

    def test_last_run_counts_geometry_and_its_mean_ao(self):
        depth = corner_scene()
        depth[:, :6] = np.inf       # sky
        depth[5, 30] = np.nan       # hostile values are background too
        depth[6, 30] = -1.0
        ao = np.full(depth.shape, -1.0, np.float32)
        with ssao.Job(self.lib) as job:
            job.set("lens", 35.0)
            job.set("radius", 1.0)
            job.set_image("depth", depth)
            job.set_image("ao", ao)
            with self.assertRaisesRegex(ssao.SSAOError, "no successful run"):
                job.last_run()
            job.run()
            geometry, mean = job.last_run()
        mask = np.isfinite(depth) & (depth > 0)
        self.assertEqual(geometry, int(mask.sum()))
        self.assertAlmostEqual(mean, float(ao[mask].astype(np.float64).mean()), places=6)
        self.assertLess(mean, 1.0)

    def test_corner_is_darker_at_the_crease(self):
        depth = corner_scene()
        ao = self.run_ao(depth, radius=1.0)
        crease = ao[:, 31:33].mean()
        walls = np.concatenate([ao[:, :8], ao[:, -8:]], axis=1).mean()
        self.assertLess(crease, 0.75)
        self.assertGreater(walls, 0.97)

    def test_flipped_view_reads_in_place(self):
        depth = corner_scene()
        top_down = self.run_ao(depth)
        stored_bottom_up = np.ascontiguousarray(depth[::-1])
        view = stored_bottom_up[::-1]  # negative row stride, no copy
        self.assertLess(view.strides[0], 0)
        np.testing.assert_array_equal(self.run_ao(view), top_down)

    def test_progress_callback_and_cancel(self):
        depth = corner_scene()
        seen = []
        ao = np.zeros_like(depth)
        with ssao.Job(self.lib) as job:
            job.set_image("depth", depth)
            job.set_image("ao", ao)
            job.run(progress=lambda f: seen.append(f) is None)
            self.assertEqual(seen[-1], 1.0)
            self.assertEqual(seen, sorted(seen))
            with self.assertRaisesRegex(ssao.SSAOError, "cancelled"):
                job.run(progress=lambda f: False)

    def test_output_window_takes_the_frame_out_of_a_larger_depth(self):
        # The corner scene as a guard band around its middle: the window's AO is the whole
        # run's, cropped, since the camera is the same on the same pixel grid.
        depth = corner_scene()
        whole = self.run_ao(depth, radius=1.0)
        frame = np.zeros((48 - 2 * 8, 64 - 2 * 8), np.float32)
        with ssao.Job(self.lib) as job:
            job.set("radius", 1.0)
            job.set("lens", 35.0)
            job.set("sensor_width", 36.0 * 48 / 64)  # the frame is 48 of the 64 px wide
            job.set_image("depth", depth)
            job.set_image("ao", frame)
            job.set_output_window(8, 8)
            job.run()
            np.testing.assert_array_equal(frame, whole[8:40, 8:56])
            job.set_output_window(17, 8)
            with self.assertRaisesRegex(ssao.SSAOError, "does not fit in the 64x48"):
                job.run()


class LibraryFileTest(unittest.TestCase):
    """Which file the binding loads on each platform (the add-on bundles lib/libssao.so and
    lib/ssao.dll), and what a library it cannot load gives: an SSAOError naming the file and the
    loader's reason, never a crash."""

    def candidates(self, platform):
        saved = sys.platform
        sys.platform = platform
        try:
            return list(ssao._binding._candidate_paths())
        finally:
            sys.platform = saved

    def test_each_platform_looks_for_its_own_file_in_the_bundled_lib_folder(self):
        bundled = os.path.normpath(os.path.join(os.path.dirname(ssao._binding.__file__), "..",
                                                "lib"))
        for platform, name in (("linux", "libssao.so"), ("win32", "ssao.dll"),
                               ("darwin", "libssao.dylib")):
            self.assertEqual(self.candidates(platform)[0], os.path.join(bundled, name), platform)

    def test_a_library_of_another_platform_is_an_error_not_a_crash(self):
        # The real ssao.dll on Linux stands for any library the loader refuses (the wrong
        # platform, a damaged file): the error names it and says why.
        if WINDOWS_DLL is None:
            self.skipTest("no Windows DLL given (build/windows/bin/ssao.dll)")
        with self.assertRaisesRegex(ssao.SSAOError, r"cannot load libssao .*ssao\.dll: .*"
                                                    r"invalid ELF header"):
            ssao.load_library(WINDOWS_DLL)


if __name__ == "__main__":
    LIBRARY = sys.argv.pop(1) if len(sys.argv) > 1 else None
    WINDOWS_DLL = sys.argv.pop(1) if len(sys.argv) > 1 else None
    unittest.main()
