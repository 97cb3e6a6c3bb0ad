#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""End-to-end tests of the ssao command-line tool (build/bin/ssao).

Run with the system Python (numpy + OpenImageIO bindings):
    /usr/bin/python3 tests/cli/test_cli.py --ssao build/bin/ssao --lib build/lib/libssao.so \
        --scratch /tmp/ssao-cli-tests [unittest arguments, e.g. a TestCase name]
The same paths may come from the environment: SSAO_CLI, SSAO_LIB, SSAO_SCRATCH. Set
SSAO_KEEP_SCRATCH=1 to keep each test's folder (inputs, outputs) for inspection.

Every test builds its own inputs: a 64x48 Blender-like multilayer EXR (ViewLayer.Combined.R/G/B/A,
ViewLayer.Depth.Z, ViewLayer.Normal.X/Y/Z) showing a wall 10 units from the camera with a box
whose front face is 2 units closer, and the sky (depth 1e10, normal 0) along the top rows.
"""

import argparse
import ctypes
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from image_files import read_image, write_multipart_exr  # noqa: E402

SSAO = os.environ.get("SSAO_CLI", "")
LIB = os.environ.get("SSAO_LIB", "")
SCRATCH = os.environ.get("SSAO_SCRATCH", "")

WIDTH, HEIGHT = 64, 48
SKY_ROWS = 12                   # rows 0..11 show the sky (background)
BOX_X, BOX_Y = (24, 40), (24, 40)  # the box's front face, pixel ranges [start, end)
WALL_DEPTH, BOX_DEPTH, SKY_DEPTH = 10.0, 8.0, 1e10
RADIUS = 3.0

# Camera: rotated 30 degrees about the world Z axis and moved; normals are written in world
# space (Blender's convention), so the tool must use matrix_world to read them.
_ANGLE = math.radians(30.0)
CAMERA_TO_WORLD = np.array([
    [math.cos(_ANGLE), -math.sin(_ANGLE), 0.0, 1.0],
    [math.sin(_ANGLE), math.cos(_ANGLE), 0.0, 2.0],
    [0.0, 0.0, 1.0, 3.0],
    [0.0, 0.0, 0.0, 1.0],
])

CAMERA = {
    "type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
    "sensor_fit": "AUTO", "shift_x": 0.0, "shift_y": 0.0, "ortho_scale": 6.0,
    "clip_start": 0.1, "clip_end": 1000.0, "matrix_world": CAMERA_TO_WORLD.tolist(),
}

BLENDER_CHANNELS = ["ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                    "ViewLayer.Combined.A", "ViewLayer.Depth.Z", "ViewLayer.Normal.X",
                    "ViewLayer.Normal.Y", "ViewLayer.Normal.Z"]

# Parameters the usage contract names; --help must list them whatever the table holds.
CONTRACT_PARAMS = ["variant", "radius", "samples", "sphere_mode", "denoise", "depth_kind",
                   "normal_space", "bias", "strength", "power", "remap_min", "remap_max", "seed",
                   "threads"]


def make_scene():
    """Returns dict of planes (HEIGHT x WIDTH float32 arrays), keyed by Blender channel name."""
    depth = np.full((HEIGHT, WIDTH), WALL_DEPTH, np.float32)
    depth[:SKY_ROWS, :] = SKY_DEPTH
    depth[BOX_Y[0]:BOX_Y[1], BOX_X[0]:BOX_X[1]] = BOX_DEPTH
    sky = depth == SKY_DEPTH

    # Both visible faces face the camera: +Z in camera space, rotated to world space.
    normal_world = CAMERA_TO_WORLD[:3, :3] @ np.array([0.0, 0.0, 1.0])
    planes = {"ViewLayer.Depth.Z": depth}
    for axis, name in enumerate("XYZ"):
        n = np.full((HEIGHT, WIDTH), normal_world[axis], np.float32)
        n[sky] = 0.0
        planes["ViewLayer.Normal." + name] = n

    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float32)
    planes["ViewLayer.Combined.R"] = (xs + 0.5) / WIDTH
    planes["ViewLayer.Combined.G"] = (ys + 0.5) / HEIGHT
    planes["ViewLayer.Combined.B"] = np.full((HEIGHT, WIDTH), 0.25, np.float32)
    planes["ViewLayer.Combined.A"] = np.where(sky, 0.0, 1.0).astype(np.float32)
    return planes


def write_exr(path, planes, names=None, data_origin=None, display_size=None):
    """The planes as an EXR of their size. data_origin=(x, y) and display_size=(w, h) place the
    data window (the planes) and the display window at (0, 0) apart: overscan, or a data
    window short of the display window."""
    names = list(planes.keys()) if names is None else names
    pixels = np.stack([planes[n] for n in names], axis=-1).astype(np.float32)
    height, width = pixels.shape[:2]
    spec = oiio.ImageSpec(width, height, len(names), oiio.FLOAT)
    spec.channelnames = tuple(names)
    spec.alpha_channel = -1
    spec.attribute("compression", "zip")
    if data_origin is not None:
        spec.x, spec.y = data_origin
        spec.full_x, spec.full_y = 0, 0
        spec.full_width, spec.full_height = display_size
    out = oiio.ImageOutput.create(path)
    assert out is not None, oiio.geterror()
    assert out.open(path, spec), out.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()


def dump_core_table(lib_path):
    """Prints {"names": [...], "version": N} read from libssao through the C API (ctypes)."""
    class ParamDesc(ctypes.Structure):
        _fields_ = [("name", ctypes.c_char_p), ("type", ctypes.c_int),
                    ("default_value", ctypes.c_double), ("min_value", ctypes.c_double),
                    ("max_value", ctypes.c_double), ("default_string", ctypes.c_char_p),
                    ("choices", ctypes.c_char_p), ("count", ctypes.c_size_t),
                    ("unit", ctypes.c_char_p), ("description", ctypes.c_char_p)]
    lib = ctypes.CDLL(lib_path)
    lib.ssao_param_count.restype = ctypes.c_size_t
    lib.ssao_param_info.argtypes = [ctypes.c_size_t, ctypes.POINTER(ParamDesc)]
    names = []
    for i in range(lib.ssao_param_count()):
        desc = ParamDesc()
        assert lib.ssao_param_info(i, ctypes.byref(desc)) == 0
        names.append(desc.name.decode())
    print(json.dumps({"names": names, "version": lib.ssao_version()}))


def core_param_names():
    """(parameter names, ssao_version()) of the core. Read in a child process, so that a library
    built with -DSSAO_SANITIZE=ON can be loaded (ASan must otherwise come first in Python)."""
    env = dict(os.environ, ASAN_OPTIONS="verify_asan_link_order=0:detect_leaks=0")
    proc = subprocess.run([sys.executable, os.path.abspath(__file__), "--dump-core-table", LIB],
                          capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0, proc.stderr
    table = json.loads(proc.stdout)
    return table["names"], table["version"]


class CliTestCase(unittest.TestCase):
    """A fresh folder per test with the standard input and camera."""

    def setUp(self):
        os.makedirs(SCRATCH, exist_ok=True)
        self.dir = tempfile.mkdtemp(prefix=self.id().split(".")[-1] + "-", dir=SCRATCH)
        self.planes = make_scene()
        self.input = self.path("in.exr")
        write_exr(self.input, self.planes, BLENDER_CHANNELS)
        self.camera = self.write_camera(CAMERA)
        self.output = self.path("out.exr")

    def tearDown(self):
        if not os.environ.get("SSAO_KEEP_SCRATCH"):
            shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def write_camera(self, content, name="camera.json"):
        path = self.path(name)
        with open(path, "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))
        return path

    def run_ssao(self, *args, default_paths=True):
        cmd = [SSAO]
        if default_paths:
            cmd += [self.input, "-o", self.output, "--camera", self.camera, "--radius", str(RADIUS)]
        cmd += [str(a) for a in args]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        self.last_command = " ".join(cmd)
        return proc

    def assert_ok(self, proc):
        self.assertEqual(proc.returncode, 0,
                         f"{self.last_command}\nstdout: {proc.stdout}\nstderr: {proc.stderr}")
        self.assertTrue(os.path.isfile(self.output))

    def assert_fails(self, proc, code, *phrases, output=None):
        """Exit status `code`, "ssao: error:" with every phrase on stderr, and no output file."""
        output = self.output if output is None else output
        detail = f"{self.last_command}\nstderr: {proc.stderr}"
        self.assertEqual(proc.returncode, code, detail)
        self.assertIn("ssao: error:", proc.stderr, detail)
        for phrase in phrases:
            self.assertIn(phrase, proc.stderr, detail)
        self.assertFalse(os.path.exists(output), f"{output} exists after a failure\n{detail}")
        folder = os.path.dirname(output)
        leftovers = [f for f in os.listdir(folder) if ".tmp" in f] if os.path.isdir(folder) else []
        self.assertEqual(leftovers, [], "temporary files left behind")


class GoodRunTest(CliTestCase):

    def test_composite_is_beauty_times_ao(self):
        proc = self.run_ssao()
        self.assert_ok(proc)
        names, out = read_image(self.output)
        self.assertEqual(sorted(names), ["A", "AO", "B", "G", "R"])
        ao = out[:, :, names.index("AO")]
        self.assertTrue(np.all(np.isfinite(ao)))
        self.assertGreaterEqual(float(ao.min()), 0.0)
        self.assertLessEqual(float(ao.max()), 1.0)
        for channel in "RGB":
            beauty = self.planes["ViewLayer.Combined." + channel]
            np.testing.assert_allclose(out[:, :, names.index(channel)], beauty * ao, rtol=0,
                                       atol=1e-6, err_msg=channel)
        np.testing.assert_array_equal(out[:, :, names.index("A")],
                                      self.planes["ViewLayer.Combined.A"])

        # Sky: unoccluded.
        np.testing.assert_allclose(ao[:SKY_ROWS, :], 1.0, rtol=0, atol=1e-6)
        # The wall right around the box is occluded by it; the middle of the box's flat front
        # face is not.
        ring = np.zeros((HEIGHT, WIDTH), bool)
        ring[BOX_Y[0] - 3:BOX_Y[1] + 3, BOX_X[0] - 3:BOX_X[1] + 3] = True
        ring[BOX_Y[0]:BOX_Y[1], BOX_X[0]:BOX_X[1]] = False
        box_centre = ao[BOX_Y[0] + 6:BOX_Y[1] - 6, BOX_X[0] + 6:BOX_X[1] - 6]
        self.assertLess(float(ao[ring].mean()), 0.95)
        self.assertGreater(float(box_centre.mean()), 0.9)
        self.assertLess(float(ao[ring].mean()), float(box_centre.mean()) - 0.05)

        # Progress (stderr is a pipe: lines at quarters) and the summary.
        self.assertIn("ssao: 100%", proc.stderr)
        self.assertIn("64x48", proc.stderr)
        self.assertIn("mean AO", proc.stderr)

    def test_radius_from_the_camera_file_or_the_automatic_rule(self):
        def run(*args, camera=None):
            if camera is not None:
                self.camera = self.write_camera(camera)
            if os.path.exists(self.output):
                os.remove(self.output)
            proc = self.run_ssao(self.input, "-o", self.output, "--camera", self.camera, *args,
                                 default_paths=False)
            self.assert_ok(proc)
            names, out = read_image(self.output)
            return proc.stderr, out[:, :, names.index("AO")]

        # No --radius, no ao_distance: 10% of the view's width (36/35 x depth) at the median
        # depth (the wall's, 10; the sky is beyond clip_end). The thickness the same everywhere,
        # so that how far the box reaches depends on the radius alone (shaped by its
        # silhouettes, the box would be deeper: docs/variants.md, hemisphere item 15).
        flat = ("--thickness-profile", "constant")
        expected = 0.1 * WALL_DEPTH * 36.0 / 35.0
        text, automatic = run(*flat)
        self.assertIn("ssao: radius %.4g scene units (10%% of the view's width at the median "
                      "depth; --radius to change)" % expected, text)
        _, given = run("--radius", repr(expected), *flat)
        np.testing.assert_allclose(automatic, given, rtol=0, atol=2e-6)
        # The camera file's ao_distance, unless --radius is given.
        text, from_file = run(*flat, camera=dict(CAMERA, ao_distance=2.5))
        self.assertIn("ssao: radius 2.5 scene units (ao_distance of", text)
        _, given = run("--radius", "2.5", *flat)
        np.testing.assert_array_equal(from_file, given)
        # 2.5 reaches from the box (depth 8) to the wall (10); the automatic 1.03 does not.
        self.assertLess(float(from_file.min()), 0.95)
        self.assertEqual(float(automatic.min()), 1.0)
        text, _ = run("--radius", "1.5")
        self.assertNotIn("ssao: radius", text)
        # A radius that cannot be one.
        os.remove(self.output)
        for bad in (0, -1.0, "2"):
            with self.subTest(ao_distance=bad):
                self.camera = self.write_camera(dict(CAMERA, ao_distance=bad))
                self.assert_fails(self.run_ssao(), 1, "'ao_distance'")

    def test_ao_only_writes_one_channel(self):
        self.assert_ok(self.run_ssao("--ao-only"))
        names, out = read_image(self.output)
        self.assertEqual(names, ["AO"])
        self.assertEqual(out.shape, (HEIGHT, WIDTH, 1))
        np.testing.assert_allclose(out[:SKY_ROWS, :, 0], 1.0, rtol=0, atol=1e-6)

    def test_ao_only_matches_composite_run(self):
        self.assert_ok(self.run_ssao())
        names, full = read_image(self.output)
        os.remove(self.output)
        self.assert_ok(self.run_ssao("--ao-only"))
        _, ao_only = read_image(self.output)
        np.testing.assert_array_equal(ao_only[:, :, 0], full[:, :, names.index("AO")])

    def test_edge_coverage_reads_the_beauty_at_depth_edges(self):
        # A red box before a blue wall. The wall's column just left of the box is, in the
        # beauty, all wall (run "pure") or half box (run "half": the box's edge inside it).
        # --edge-coverage beauty gives that column the wall's AO alone in the first, half the
        # box's in the second; `none`'s pixel filter takes a fixed share of the box. The
        # wall beside the box is darker than the box's face, so pure < default < half there;
        # pixels off the box's depth edges do not change.
        box = np.zeros((HEIGHT, WIDTH), bool)
        box[BOX_Y[0]:BOX_Y[1], BOX_X[0]:BOX_X[1]] = True
        column = BOX_X[0] - 1
        rows = slice(BOX_Y[0] + 2, BOX_Y[1] - 2)
        runs = {}
        for name, box_share in (("pure", 0.0), ("half", 0.5), ("default", 0.0)):
            for c, (wall, red) in zip("RGB", ((0.1, 0.8), (0.2, 0.2), (0.7, 0.1))):
                plane = np.where(box, red, wall).astype(np.float32)
                plane[rows, column] = box_share * red + (1 - box_share) * wall
                self.planes["ViewLayer.Combined." + c] = plane
            write_exr(self.input, self.planes, BLENDER_CHANNELS)
            flags = ["--edge-coverage", "none" if name == "default" else "beauty"]
            self.assert_ok(self.run_ssao(*flags))
            names, out = read_image(self.output)
            runs[name] = out[:, :, names.index("AO")]
            os.remove(self.output)
        pure, half, default = runs["pure"][rows, column], runs["half"][rows, column], \
            runs["default"][rows, column]
        self.assertTrue(np.all(pure < default - 0.005), (pure, default))
        self.assertTrue(np.all(half > default + 0.005), (half, default))
        edge = np.zeros_like(box)
        edge[BOX_Y[0] - 1:BOX_Y[1] + 1, BOX_X[0] - 1:BOX_X[1] + 1] = True
        edge[BOX_Y[0] + 1:BOX_Y[1] - 1, BOX_X[0] + 1:BOX_X[1] - 1] = False
        np.testing.assert_array_equal(runs["half"][~edge], runs["default"][~edge])
        # --ao-only still reads the beauty for the edges: the same AO as with the composite
        # (the file holds the last run's beauty, "pure"'s).
        self.assert_ok(self.run_ssao("--ao-only", "--edge-coverage", "beauty"))
        _, ao_only = read_image(self.output)
        np.testing.assert_array_equal(ao_only[:, :, 0], runs["pure"])  # the file's beauty

    def test_without_alpha_writes_rgb_and_ao(self):
        write_exr(self.input, self.planes,
                  [n for n in BLENDER_CHANNELS if n != "ViewLayer.Combined.A"])
        self.assert_ok(self.run_ssao())
        names, _ = read_image(self.output)
        self.assertEqual(sorted(names), ["AO", "B", "G", "R"])

    def test_result_does_not_depend_on_thread_count(self):
        self.assert_ok(self.run_ssao("--ao-only", "--threads", "1"))
        _, one = read_image(self.output)
        os.remove(self.output)
        self.assert_ok(self.run_ssao("--ao-only", "--threads", "3"))
        _, three = read_image(self.output)
        np.testing.assert_array_equal(one, three)

    def test_strength_zero_gives_no_occlusion(self):
        self.assert_ok(self.run_ssao("--ao-only", "--strength", "0"))
        _, off = read_image(self.output)
        np.testing.assert_allclose(off, 1.0, rtol=0, atol=1e-6)

    def test_no_normals_reconstructs_from_depth(self):
        proc = self.run_ssao("--ao-only", "--no-normals")
        self.assert_ok(proc)
        self.assertIn("normals from depth", proc.stderr)
        _, out = read_image(self.output)
        self.assertTrue(np.all(np.isfinite(out)))
        np.testing.assert_allclose(out[:SKY_ROWS, :, 0], 1.0, rtol=0, atol=1e-6)

    def test_quiet_prints_nothing(self):
        proc = self.run_ssao("--quiet")
        self.assert_ok(proc)
        self.assertEqual(proc.stderr, "")
        self.assertEqual(proc.stdout, "")

    def test_overwrites_an_existing_output(self):
        with open(self.output, "w") as f:
            f.write("old")
        self.assert_ok(self.run_ssao("--ao-only"))
        self.assertEqual(read_image(self.output)[0], ["AO"])

    def test_explicit_channels_and_single_layer_file(self):
        names = {"ViewLayer.Depth.Z": "Z", "ViewLayer.Combined.R": "R",
                 "ViewLayer.Combined.G": "G", "ViewLayer.Combined.B": "B",
                 "ViewLayer.Normal.X": "N.X", "ViewLayer.Normal.Y": "N.Y",
                 "ViewLayer.Normal.Z": "N.Z"}
        write_exr(self.input, {names[k]: v for k, v in self.planes.items() if k in names})
        self.assert_ok(self.run_ssao())
        got, _ = read_image(self.output)
        self.assertEqual(sorted(got), ["AO", "B", "G", "R"])
        os.remove(self.output)
        self.assert_ok(self.run_ssao("--depth-channel", "Z", "--normal-channels", "N.X,N.Y,N.Z",
                                     "--beauty-channels", "B,G,R"))

    def test_multi_part_exr_as_blender_5_writes_it(self):
        # Blender 5.x writes a multilayer EXR as one part per layer: the same result as the
        # single-part file.
        self.assert_ok(self.run_ssao("--ao-only"))
        _, single = read_image(self.output)
        multipart = self.path("multipart.exr")
        write_multipart_exr(multipart, {n: self.planes[n] for n in BLENDER_CHANNELS})
        os.remove(self.output)
        self.assert_ok(self.run_ssao(multipart, "-o", self.output, "--camera", self.camera,
                                     "--radius", RADIUS, "--ao-only", default_paths=False))
        _, parts = read_image(self.output)
        np.testing.assert_array_equal(parts, single)

    def test_layer_choice(self):
        planes = dict(self.planes)
        for name in BLENDER_CHANNELS:
            planes["Other" + name[len("ViewLayer"):]] = self.planes[name]
        write_exr(self.input, planes)
        self.assert_fails(self.run_ssao(), 1, "--layer", "ViewLayer", "Other")
        self.assert_ok(self.run_ssao("--layer", "Other"))


class CameraContractTest(CliTestCase):
    """A camera file may give another renderer's camera: pinhole intrinsics or an OpenGL
    projection matrix instead of Blender's lens and sensor (docs/conventions.md)."""

    def ao_with(self, camera):
        self.camera = self.write_camera(camera)
        proc = self.run_ssao()
        self.assert_ok(proc)
        names, out = read_image(self.output)
        match = re.search(r"mean AO ([0-9.]+) over (\d+) geometry pixels", proc.stderr)
        self.assertIsNotNone(match, proc.stderr)
        return out[:, :, names.index("AO")], float(match.group(1)), int(match.group(2))

    def test_intrinsics_and_matrix_give_the_lens_cameras_ao(self):
        shifted = dict(CAMERA, shift_x=0.1, shift_y=-0.05)
        reference, mean, geometry = self.ao_with(shifted)
        # The same camera in pixels: AUTO fit of a landscape image, the sensor across the width.
        f = WIDTH * CAMERA["lens"] / CAMERA["sensor_width"]
        cx, cy = WIDTH / 2 - 0.1 * WIDTH, HEIGHT / 2 - 0.05 * WIDTH
        common = {k: CAMERA[k] for k in ("clip_start", "clip_end", "matrix_world")}
        intrinsics = dict(common, type="PERSP", projection="intrinsics",
                          intrinsics=[f, f, cx, cy])
        matrix = [[2 * f / WIDTH, 0, 1 - 2 * cx / WIDTH, 0],
                  [0, 2 * f / HEIGHT, 2 * cy / HEIGHT - 1, 0],
                  [0, 0, -1.0002, -0.2], [0, 0, -1, 0]]
        opengl = dict(common, projection="matrix", projection_matrix=matrix)
        unshifted, _, _ = self.ao_with(CAMERA)
        self.assertGreater(float(np.abs(unshifted - reference).max()), 1e-3)  # the shift shows
        for name, camera in (("intrinsics", intrinsics), ("matrix", opengl)):
            with self.subTest(camera=name):
                ao, other_mean, other_geometry = self.ao_with(camera)
                np.testing.assert_allclose(ao, reference, rtol=0, atol=1e-4)
                self.assertAlmostEqual(other_mean, mean, places=3)
                self.assertEqual(other_geometry, geometry)
        self.assertEqual(geometry, int((self.planes["ViewLayer.Depth.Z"] < 1e9).sum()))

    def test_a_contract_camera_needs_its_own_keys(self):
        cases = [
            ({"type": "PERSP", "projection": "intrinsics"}, "missing key 'intrinsics'"),
            ({"projection": "matrix"}, "missing key 'projection_matrix'"),
            ({"type": "PERSP", "projection": "intrinsics", "intrinsics": [50, 50, 32]},
             "array of 4 numbers"),
            ({"projection": "matrix", "matrix_world": CAMERA["matrix_world"],
              "projection_matrix": [[1, 0.5, 0, 0], [0, 1, 0, 0], [0, 0, -1, -0.2],
                                    [0, 0, -1, 0]]},
             "skewed"),
            ({"type": "PERSP", "projection": "pinhole"}, "'projection'"),
        ]
        for content, phrase in cases:
            with self.subTest(phrase=phrase):
                self.camera = self.write_camera(content)
                self.assert_fails(self.run_ssao(), 1, phrase)


class BackgroundDepthTest(CliTestCase):

    def test_nan_inf_and_negative_depth_are_background(self):
        depth = self.planes["ViewLayer.Depth.Z"]
        bad = {(40, 5): np.nan, (41, 5): np.inf, (42, 5): -np.inf, (43, 5): -1.0, (44, 5): 0.0,
               (30, 30): np.nan, (20, 50): -3.0}
        for (y, x), value in bad.items():
            depth[y, x] = value
        write_exr(self.input, self.planes, BLENDER_CHANNELS)
        proc = self.run_ssao()
        self.assert_ok(proc)
        names, out = read_image(self.output)
        ao = out[:, :, names.index("AO")]
        self.assertTrue(np.all(np.isfinite(ao)), "AO has non-finite values")
        for (y, x) in bad:
            self.assertAlmostEqual(float(ao[y, x]), 1.0, places=6, msg=f"pixel ({x}, {y})")
        self.assertTrue(np.all(np.isfinite(out[:, :, names.index("R")])))

    def test_beyond_clip_end_is_background(self):
        camera = dict(CAMERA, clip_end=9.0)  # the wall (10) is now beyond clip_end
        self.camera = self.write_camera(camera)
        self.assert_ok(self.run_ssao("--ao-only"))
        _, out = read_image(self.output)
        wall = self.planes["ViewLayer.Depth.Z"] == WALL_DEPTH
        np.testing.assert_allclose(out[:, :, 0][wall], 1.0, rtol=0, atol=1e-6)


class SequenceTest(CliTestCase):
    """--frames: patterns, independent frames, --skip-existing, --progress json."""

    LAYER_CHANNELS = property(lambda self: DepthLayersTest.LAYER_CHANNELS)  # for layer_planes

    def write_frames(self, frames, pattern="in.{:04d}.exr", step=0.3):
        """Frames whose box sits at a different depth each (so that they differ), `step`
        farther each frame."""
        for frame in frames:
            planes = {k: v.copy() for k, v in self.planes.items()}
            box = planes["ViewLayer.Depth.Z"] == BOX_DEPTH
            planes["ViewLayer.Depth.Z"][box] = BOX_DEPTH + step * frame
            write_exr(self.path(pattern.format(frame)), planes, BLENDER_CHANNELS)

    def run_sequence(self, *args, inp="in.####.exr", out="out.####.exr"):
        return self.run_ssao(self.path(inp), "-o", self.path(out), "--camera", self.camera,
                             "--radius", str(RADIUS), *args, default_paths=False)

    def test_frames_are_independent_and_match_single_runs(self):
        self.write_frames([1, 2, 4])
        whole = open(self.path("in.0001.exr"), "rb").read()
        with open(self.path("in.0005.exr"), "wb") as f:  # a truncated frame
            f.write(whole[:len(whole) // 2])
        # Each frame alone (the temporal filter averages earlier frames in: test below).
        proc = self.run_sequence("--frames", "1-5", "--temporal-frames", "1")
        self.assertEqual(proc.returncode, 1, proc.stderr)
        self.assertIn("frame 3 (3/5): error: cannot read", proc.stderr)
        self.assertIn("frame 5 (5/5): error: cannot read", proc.stderr)
        self.assertIn("ssao: 3 of 5 frames written", proc.stderr)
        self.assertIn("failed: 3,5", proc.stderr)
        self.assertIn("frame 2 (2/5): " + self.path("out.0002.exr"), proc.stderr)
        self.assertFalse(os.path.exists(self.path("out.0003.exr")))
        self.assertFalse(os.path.exists(self.path("out.0005.exr")))
        self.assertEqual([f for f in os.listdir(self.dir) if ".tmp" in f], [])
        # Each frame equals the same frame run alone, bit for bit.
        previous = None
        for frame in (1, 2, 4):
            single = self.path(f"single.{frame}.exr")
            alone = self.run_ssao(self.path(f"in.{frame:04d}.exr"), "-o", single, "--camera",
                                  self.camera, "--radius", str(RADIUS), "--threads", "1",
                                  default_paths=False)
            self.assertEqual(alone.returncode, 0, alone.stderr)
            names, a = read_image(self.path(f"out.{frame:04d}.exr"))
            _, b = read_image(single)
            np.testing.assert_array_equal(a, b, err_msg=f"frame {frame}")
            ao = a[:, :, names.index("AO")]
            if previous is not None:
                self.assertFalse(np.array_equal(ao, previous), "frames should differ")
            previous = ao

    def test_temporal_filter_chunks_equal_a_serial_run(self):
        # The default averages each frame with the two before it (temporal_frames 3); a chunk
        # computes the frames before its first one without writing them, so every chunk size
        # writes what the serial run writes, bit for bit. The box moves by 0.2 % of its depth
        # a frame: its AO changes by less than noise does, so the frames average.
        self.write_frames([1, 2, 3, 4, 5, 6, 7], step=0.01)
        self.assertEqual(self.run_sequence("--frames", "1-7").returncode, 0)
        for size in (1, 3):
            for index in range((7 + size - 1) // size):
                proc = self.run_sequence("--frames", "1-7", "--chunk-size", str(size),
                                         "--chunk-index", str(index),
                                         out=f"chunk{size}_{index}.####.exr")
                self.assertEqual(proc.returncode, 0, proc.stderr)
                first = 1 + index * size
                if first > 1:
                    self.assertIn(f"frame {first - 1} computed first (not written)", proc.stderr)
                    self.assertFalse(os.path.exists(
                        self.path(f"chunk{size}_{index}.{first - 1:04d}.exr")))
            for frame in range(1, 8):
                _, serial = read_image(self.path(f"out.{frame:04d}.exr"))
                _, chunked = read_image(self.path(f"chunk{size}_{(frame - 1) // size}."
                                                  f"{frame:04d}.exr"))
                np.testing.assert_array_equal(chunked, serial, f"frame {frame}, chunks of {size}")
        # The first frame has nothing before it: the frame alone. Later ones average the box's
        # AO over the frames.
        for frame, same in ((1, True), (4, False)):
            alone = self.path(f"alone.{frame}.exr")
            proc = self.run_ssao(self.path(f"in.{frame:04d}.exr"), "-o", alone, "--camera",
                                 self.camera, "--radius", str(RADIUS), default_paths=False)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            _, serial = read_image(self.path(f"out.{frame:04d}.exr"))
            _, single = read_image(alone)
            self.assertEqual(np.array_equal(serial, single), same, f"frame {frame}")

    def test_sequence_frames_with_other_passes_and_sizes(self):
        # Buffers pass from frame to frame, and the job from run to run: a frame without
        # normals, layers or alpha after one with them, and a smaller frame between larger
        # ones, must each be what a run on that file alone writes.
        layers = DepthLayersTest.layer_planes(self)
        no_normals = [n for n in BLENDER_CHANNELS if ".Normal." not in n and n[-2:] != ".A"]
        small = {n: v[4:40, 8:56] for n, v in layers.items()}
        frames = {1: (layers, sorted(layers)), 2: (self.planes, no_normals),
                  3: (small, sorted(small)), 4: (layers, sorted(layers)),
                  5: (self.planes, BLENDER_CHANNELS)}
        for frame, (planes, names) in frames.items():
            write_exr(self.path(f"in.{frame:04d}.exr"), planes, names)
        for args in ((), ("--ao-only",)):
            proc = self.run_ssao(self.path("in.####.exr"), "-o", self.path("out.####.exr"),
                                 "--camera", self.camera, "--radius", RADIUS, "--frames", "1-5",
                                 "--temporal-frames", "1", *args, default_paths=False)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            for frame in frames:
                alone = self.path(f"alone.{frame}.exr")
                proc = self.run_ssao(self.path(f"in.{frame:04d}.exr"), "-o", alone, "--camera",
                                     self.camera, "--radius", RADIUS, *args, default_paths=False)
                self.assertEqual(proc.returncode, 0, proc.stderr)
                got, expected = read_image(self.path(f"out.{frame:04d}.exr")), read_image(alone)
                self.assertEqual(got[0], expected[0], f"frame {frame} {args}")
                np.testing.assert_array_equal(got[1], expected[1], f"frame {frame} {args}")

    def test_skip_existing_and_json_progress(self):
        self.write_frames([1, 2, 3])
        self.assertEqual(self.run_sequence("--frames", "1-3").returncode, 0)
        os.remove(self.path("out.0002.exr"))
        kept = os.stat(self.path("out.0001.exr")).st_mtime_ns
        proc = self.run_sequence("--frames", "1-3", "--skip-existing", "--progress", "json")
        self.assertEqual(proc.returncode, 0, proc.stderr)
        lines = [json.loads(line) for line in proc.stderr.splitlines() if line.startswith("{")]
        self.assertEqual([(r["frame"], r["status"]) for r in lines],
                         [(1, "skipped"), (2, "ok"), (3, "skipped")])
        self.assertEqual([r["index"] for r in lines], [1, 2, 3])
        self.assertTrue(all(r["total"] == 3 for r in lines))
        self.assertGreater(lines[1]["seconds"], 0.0)
        self.assertIsNotNone(lines[1]["mean_ao"])
        self.assertTrue(os.path.isfile(self.path("out.0002.exr")))
        self.assertEqual(os.stat(self.path("out.0001.exr")).st_mtime_ns, kept)

    def test_steps_lists_and_placeholders(self):
        self.write_frames([1, 3, 5, 12], pattern="in.{:03d}.exr")
        proc = self.run_sequence("--frames", "1-5x2,12", inp="in.%03d.exr", out="o.@@@@.png")
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith("o.")),
                         ["o.0001.png", "o.0003.png", "o.0005.png", "o.0012.png"])
        self.assertIn("4 of 4 frames written", proc.stderr)
        self.assertIn("frames per minute", proc.stderr)

    def test_chunks_split_the_frames_for_farms(self):
        # 5 frames in chunks of 2: the last chunk holds one frame.
        proc = self.run_ssao("--frames", "1-3,7,9", "--chunk-size", "2", "--list-chunks",
                             default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(proc.stdout, "0 1-2\n1 3,7\n2 9\n")
        self.write_frames([1, 2, 3])
        proc = self.run_sequence("--frames", "1-3", "--chunk-size", "2", "--chunk-index", "1")
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith("out.")),
                         ["out.0003.exr"])
        self.assertIn("1 of 1 frames written", proc.stderr)
        cases = [
            (("--frames", "1-3", "--chunk-size", "2", "--chunk-index", "2"),
             "chunk 2 does not exist: 3 frames in chunks of 2 make 2 chunks (0-1)"),
            (("--chunk-size", "2"), "--chunk-size applies to sequences"),
            (("--frames", "1-3", "--chunk-index", "0"), "need --chunk-size"),
            (("--frames", "1-3", "--chunk-size", "0"), "at least 1"),
            (("--frames", "1-3", "--chunk-size", "2", "--chunk-index", "-1"), "0 or more"),
        ]
        for args, phrase in cases:
            with self.subTest(phrase=phrase):
                proc = self.run_sequence(*args)
                self.assertEqual(proc.returncode, 2, proc.stderr)
                self.assertIn(phrase, proc.stderr)

    def test_sequence_usage_errors(self):
        self.write_frames([1])
        cases = [
            (("--frames", "5-1"), {}, "runs backwards"),
            (("--frames", "1-2"), {"out": "out.exr"}, "-o needs a frame placeholder"),
            (("--frames", "1"), {"inp": "in.0001.exr"}, "the input needs a frame placeholder"),
            (("--frames", "1-3,2"), {}, "frame 2 is given twice"),
            (("--frames", "1", "--progress", "xml"), {}, "text or json"),
        ]
        for args, paths, phrase in cases:
            with self.subTest(phrase=phrase):
                proc = self.run_sequence(*args, **paths)
                self.assertEqual(proc.returncode, 2, proc.stderr)
                self.assertIn(phrase, proc.stderr)
        proc = self.run_ssao("--skip-existing")
        self.assertEqual(proc.returncode, 2)
        self.assertIn("apply to sequences", proc.stderr)
        # Without --radius the frames need the camera file's ao_distance.
        proc = self.run_ssao(self.path("in.####.exr"), "-o", self.path("o.####.exr"),
                             "--camera", self.camera, "--frames", "1", default_paths=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("a sequence needs --radius", proc.stderr)
        self.camera = self.write_camera(dict(CAMERA, ao_distance=RADIUS))
        proc = self.run_ssao(self.path("in.####.exr"), "-o", self.path("o.####.exr"),
                             "--camera", self.camera, "--frames", "1", default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)


class OverscanTest(CliTestCase):
    """An EXR whose data window is larger than its display window (overscan, a guard band on the
    same pixel grid): AO for the display window from all of the data window. The standard 64x48
    scene is the data window; the display window is its middle, BAND pixels in from each side."""

    BAND = 8

    def write_overscan_exr(self, path, data_x=None, data_y=None):
        """The standard scene as an EXR with data window 64x48 at (-BAND, -BAND) (or the given
        origin) and display window (WIDTH - 2 BAND) x (HEIGHT - 2 BAND) at (0, 0)."""
        write_exr(path, self.planes, BLENDER_CHANNELS,
                  data_origin=(-self.BAND if data_x is None else data_x,
                               -self.BAND if data_y is None else data_y),
                  display_size=(WIDTH - 2 * self.BAND, HEIGHT - 2 * self.BAND))
        return path

    def frame_camera(self):
        """The display window's camera: the standard camera narrowed to the frame on the same
        pixel grid (the sensor spans the width: it shrinks with it)."""
        return self.write_camera(dict(CAMERA, sensor_width=CAMERA["sensor_width"] *
                                      (WIDTH - 2 * self.BAND) / WIDTH), "frame_camera.json")

    def crop(self, image):
        return image[self.BAND:HEIGHT - self.BAND, self.BAND:WIDTH - self.BAND]

    def test_the_frame_gets_the_ao_of_the_whole_data_window_cropped(self):
        self.assert_ok(self.run_ssao())  # the whole 64x48 image with the standard camera
        names, whole = read_image(self.output)
        overscan = self.write_overscan_exr(self.path("overscan.exr"))
        frame_output = self.path("frame.exr")
        proc = self.run_ssao(overscan, "-o", frame_output, "--camera", self.frame_camera(),
                             "--radius", RADIUS, default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        frame_names, frame = read_image(frame_output)
        self.assertEqual(frame_names, names)
        self.assertEqual(frame.shape, (HEIGHT - 2 * self.BAND, WIDTH - 2 * self.BAND, len(names)))
        # Both runs see the same pixels through the same camera: the same AO and composite.
        np.testing.assert_allclose(frame, self.crop(whole), rtol=0, atol=1e-6)
        ao = frame[:, :, names.index("AO")]
        self.assertLess(float(ao.min()), 0.9, "the frame has occlusion to compare")
        self.assertIn(f"{WIDTH - 2 * self.BAND}x{HEIGHT - 2 * self.BAND}", proc.stderr)
        # Cropped to the display window first, the frame loses the occluders in the band.
        cropped = self.path("cropped.exr")
        write_exr(cropped, {n: self.crop(self.planes[n]) for n in BLENDER_CHANNELS})
        cropped_output = self.path("cropped_out.exr")
        self.assertEqual(self.run_ssao(cropped, "-o", cropped_output, "--camera",
                                       self.frame_camera(), "--radius", RADIUS, "--ao-only",
                                       default_paths=False).returncode, 0)
        _, without_band = read_image(cropped_output)
        self.assertGreater(float(np.abs(without_band[:, :, 0] - ao).max()), 0.01,
                           "the band holds occluders the frame's edge pixels see")

    def test_sequences_and_chunks_read_overscan(self):
        for frame in (1, 2):
            self.write_overscan_exr(self.path(f"shot.{frame:04d}.exr"))
        camera = self.frame_camera()
        proc = self.run_ssao(self.path("shot.####.exr"), "-o", self.path("ao.####.exr"),
                             "--camera", camera, "--radius", RADIUS, "--ao-only", "--frames",
                             "1-2", "--chunk-size", "1", "--chunk-index", "1",
                             "--temporal-frames", "1", default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertFalse(os.path.exists(self.path("ao.0001.exr")), "chunk 1 is frame 2 alone")
        _, sequence_frame = read_image(self.path("ao.0002.exr"))
        self.assertEqual(self.run_ssao(self.path("shot.0002.exr"), "-o", self.path("one.exr"),
                                       "--camera", camera, "--radius", RADIUS, "--ao-only",
                                       default_paths=False).returncode, 0)
        _, single = read_image(self.path("one.exr"))
        np.testing.assert_array_equal(sequence_frame, single)
        self.assertEqual(single.shape[:2], (HEIGHT - 2 * self.BAND, WIDTH - 2 * self.BAND))

    def test_a_data_window_short_of_the_display_window_is_refused(self):
        short = self.write_overscan_exr(self.path("short.exr"), data_x=1, data_y=0)
        proc = self.run_ssao(short, "-o", self.output, "--camera", self.camera, "--radius",
                             RADIUS, default_paths=False)
        self.assert_fails(proc, 1, "does not cover its display window")


class DepthLayersTest(CliTestCase):
    """Extra depth layers: the standard scene's box is a plate 0.2 thick (its back face is the
    2nd hit), the wall behind it the 3rd. With them the gap between the plate and the wall is
    free space, so the wall around the plate is less occluded than the one-layer thickness rule
    makes it."""

    LAYER_CHANNELS = ["ViewLayer.Depth2.Z", "ViewLayer.Facing2.V", "ViewLayer.Depth3.Z",
                      "ViewLayer.Facing3.V"]

    def layer_planes(self, base=None):
        planes = dict(self.planes if base is None else base)
        depth = planes["ViewLayer.Depth.Z"]
        plate = depth == BOX_DEPTH
        sky = depth == SKY_DEPTH
        planes["ViewLayer.Depth2.Z"] = np.where(plate, BOX_DEPTH + 0.2, SKY_DEPTH).astype(np.float32)
        planes["ViewLayer.Facing2.V"] = np.where(plate, 1.0, 0.0).astype(np.float32)
        planes["ViewLayer.Depth3.Z"] = np.where(plate, WALL_DEPTH, SKY_DEPTH).astype(np.float32)
        planes["ViewLayer.Facing3.V"] = np.zeros_like(depth)
        for name in self.LAYER_CHANNELS:
            planes[name][sky] = SKY_DEPTH if "Depth" in name else 0.0
        return planes

    def ring_mean(self, ao):
        """Mean AO of the wall within 6 pixels of the plate."""
        ring = np.zeros((HEIGHT, WIDTH), bool)
        ring[BOX_Y[0] - 6:BOX_Y[1] + 6, BOX_X[0] - 6:BOX_X[1] + 6] = True
        ring[BOX_Y[0]:BOX_Y[1], BOX_X[0]:BOX_X[1]] = False
        return float(ao[ring].mean())

    def run_ao(self, path, *args, output=None):
        output = output or self.path("ao_" + os.path.basename(path))
        proc = self.run_ssao(path, "-o", output, "--camera", self.camera, "--radius", RADIUS,
                             "--ao-only", *args, default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        return read_image(output)[1][:, :, 0], proc

    def test_layers_are_found_by_name_and_change_the_ao(self):
        layered = self.path("layered.exr")
        write_exr(layered, self.layer_planes(), BLENDER_CHANNELS + self.LAYER_CHANNELS)
        one, _ = self.run_ao(self.input)
        three, proc = self.run_ao(layered)
        self.assertIn("depth layers 3", proc.stderr)
        self.assertGreater(self.ring_mean(three), self.ring_mean(one) + 0.02,
                           "the gap behind the plate is free space with layers")
        # --no-depth-layers: exactly the one-layer run.
        ignored, proc = self.run_ao(layered, "--no-depth-layers", output=self.path("ignored.exr"))
        self.assertIn("depth layers 1", proc.stderr)
        np.testing.assert_array_equal(ignored, one)
        # The same layers under other names, named with --depth-layer: the same AO.
        planes = self.layer_planes()
        renamed = {"hit2": planes["ViewLayer.Depth2.Z"], "back2": planes["ViewLayer.Facing2.V"],
                   "hit3": planes["ViewLayer.Depth3.Z"]}
        other = self.path("other_names.exr")
        write_exr(other, {**self.planes, **renamed}, BLENDER_CHANNELS + list(renamed))
        named, _ = self.run_ao(other, "--depth-layer", "hit2:back2", "--depth-layer", "hit3")
        np.testing.assert_array_equal(named, three)  # hit 3 without facing: a front face, as given

    def test_layers_with_overscan_in_a_sequence_chunk(self):
        band = OverscanTest.BAND
        for frame in (1, 2):
            write_exr(self.path(f"shot.{frame:04d}.exr"), self.layer_planes(),
                      BLENDER_CHANNELS + self.LAYER_CHANNELS, data_origin=(-band, -band),
                      display_size=(WIDTH - 2 * band, HEIGHT - 2 * band))
        camera = self.write_camera(dict(CAMERA, sensor_width=CAMERA["sensor_width"] *
                                        (WIDTH - 2 * band) / WIDTH), "frame_camera.json")
        proc = self.run_ssao(self.path("shot.####.exr"), "-o", self.path("ao.####.exr"),
                             "--camera", camera, "--radius", RADIUS, "--ao-only", "--frames",
                             "1-2", "--chunk-size", "1", "--chunk-index", "1", "--skip-existing",
                             default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        _, frame = read_image(self.path("ao.0002.exr"))
        self.assertEqual(frame.shape[:2], (HEIGHT - 2 * band, WIDTH - 2 * band))
        # The whole data window with layers, cropped: the same AO.
        whole = self.path("whole.exr")
        write_exr(whole, self.layer_planes(), BLENDER_CHANNELS + self.LAYER_CHANNELS)
        full, _ = self.run_ao(whole)
        np.testing.assert_allclose(frame[:, :, 0], full[band:HEIGHT - band, band:WIDTH - band],
                                   rtol=0, atol=1e-6)

    def test_bad_layers_are_refused(self):
        layered = self.path("layered.exr")
        write_exr(layered, self.layer_planes(), BLENDER_CHANNELS + self.LAYER_CHANNELS)
        self.assert_fails(self.run_ssao(layered, "-o", self.output, "--camera", self.camera,
                                        "--depth-layer", "Nope.Z", default_paths=False),
                          1, "no channel 'Nope.Z'", "depth layer")
        for spec in ("Depth2.Z:", ":Facing2.V"):
            self.assert_fails(self.run_ssao("--depth-layer", spec), 2, "--depth-layer")
        self.assert_fails(self.run_ssao("--no-depth-layers", "--depth-layer", "a"), 2,
                          "contradict")
        self.assert_fails(self.run_ssao(*[a for _ in range(5) for a in ("--depth-layer", "d")]),
                          2, "more than 4")
        # A 2nd hit in front of the visible surface: the library's message, no output.
        planes = self.layer_planes()
        planes["ViewLayer.Depth2.Z"][30, 30] = BOX_DEPTH - 1.0
        wrong = self.path("wrong.exr")
        write_exr(wrong, planes, BLENDER_CHANNELS + self.LAYER_CHANNELS)
        self.assert_fails(self.run_ssao(wrong, "-o", self.output, "--camera", self.camera,
                                        default_paths=False),
                          1, "'depth2' at pixel (30, 30) is nearer than 'depth'")


class ChannelReadTest(CliTestCase):
    """The tool reads only the channels it uses, straight into its buffers (a production EXR
    holds 30 and more; core/tools/image_codec.cpp read_channels): whatever else a file holds,
    where its passes sit (other parts, between other channels, half or float, tiles, any
    compression, overscan), the output is the one of a file holding just those passes."""

    LAYER_CHANNELS = DepthLayersTest.LAYER_CHANNELS
    # Names that sort before, between and after the passes the tool reads, as Blender's do.
    EXTRA = ["ViewLayer.AO.R", "ViewLayer.AO.G", "ViewLayer.AO.B", "ViewLayer.DiffCol.R",
             "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.B", "ViewLayer.Emit.R", "ViewLayer.Emit.G",
             "ViewLayer.Emit.B", "ViewLayer.IndexOB.X", "ViewLayer.Mist.Z", "ViewLayer.Vector.X",
             "ViewLayer.Vector.Y", "ViewLayer.Vector.Z", "ViewLayer.Vector.W"]

    def extra_planes(self, seed=3):
        rng = np.random.default_rng(seed)
        planes = {name: rng.normal(0.0, 5.0, (HEIGHT, WIDTH)).astype(np.float32)
                  for name in self.EXTRA}
        planes["ViewLayer.Mist.Z"][3, 4] = np.nan
        return planes

    def write(self, path, planes, names, formats=None, compression="zip", tile=None,
              data_origin=None, display_size=None):
        """An EXR with per-channel formats (default float), tiles and a data window."""
        height, width = planes[names[0]].shape
        spec = oiio.ImageSpec(width, height, len(names), oiio.FLOAT)
        spec.channelnames = tuple(names)
        spec.channelformats = tuple(formats.get(n, oiio.FLOAT) for n in names) if formats \
            else ()
        spec.alpha_channel = -1
        spec.attribute("compression", compression)
        if tile:
            spec.tile_width = spec.tile_height = tile
        if data_origin is not None:
            spec.x, spec.y = data_origin
            spec.full_x, spec.full_y = 0, 0
            spec.full_width, spec.full_height = display_size
        out = oiio.ImageOutput.create(path)
        self.assertTrue(out is not None and out.open(path, spec), oiio.geterror())
        self.assertTrue(out.write_image(np.stack([planes[n] for n in names], axis=-1)),
                        out.geterror())
        out.close()
        return path

    def write_parts(self, path, planes, data_origin=None, display_size=None):
        """One part per pass (layer.pass), as Blender 5.x writes them: each part the tool reads
        is read whole in one call, the simplest way there is; the reference of these tests."""
        parts = {}
        for name in planes:
            parts.setdefault(name.rsplit(".", 1)[0], []).append(name)
        specs = []
        for part, names in parts.items():
            height, width = planes[names[0]].shape
            spec = oiio.ImageSpec(width, height, len(names), oiio.FLOAT)
            spec.channelnames = tuple(names)
            spec.attribute("name", part)
            spec.attribute("compression", "zip")
            if data_origin is not None:
                spec.x, spec.y = data_origin
                spec.full_x, spec.full_y = 0, 0
                spec.full_width, spec.full_height = display_size
            specs.append(spec)
        out = oiio.ImageOutput.create(path)
        self.assertTrue(out is not None and out.open(path, specs), oiio.geterror())
        for i, names in enumerate(parts.values()):
            if i:
                self.assertTrue(out.open(path, specs[i], "AppendSubimage"), out.geterror())
            self.assertTrue(out.write_image(np.stack([planes[n] for n in names], axis=-1)))
        out.close()
        return path

    def outputs(self, path, *args, camera=None):
        """(composite run, --ao-only run) of `path`, as arrays."""
        got = []
        for extra in ((), ("--ao-only",)):
            output = self.path("out_%d.exr" % len(os.listdir(self.dir)))
            proc = self.run_ssao(path, "-o", output, "--camera", camera or self.camera,
                                 "--radius", RADIUS, *args, *extra, default_paths=False)
            self.assertEqual(proc.returncode, 0, f"{self.last_command}\n{proc.stderr}")
            got.append(read_image(output))
        return got

    def assert_same_outputs(self, got, expected, what):
        for (names, pixels), (ref_names, ref_pixels) in zip(got, expected):
            self.assertEqual(names, ref_names, what)
            np.testing.assert_array_equal(pixels, ref_pixels, err_msg=what)

    def test_extra_channels_formats_tiles_and_compressions_change_nothing(self):
        layers = DepthLayersTest.layer_planes(self)
        expected = self.outputs(self.write_parts(self.path("parts.exr"), layers))
        planes = {**layers, **self.extra_planes()}
        names = sorted(planes)  # the passes interleaved with the others
        half = {n: oiio.HALF for n in self.EXTRA}
        cases = [("zip", {}, None), ("zip", half, None), ("zips", half, None),
                 ("piz", half, None), ("none", {}, None), ("rle", half, None),
                 ("zip", half, 16), ("piz", {}, 32)]
        for compression, formats, tile in cases:
            what = f"{compression}, {'half' if formats else 'float'} extras, tiles {tile}"
            with self.subTest(what):
                path = self.write(self.path(f"{compression}_{len(formats)}_{tile}.exr"), planes,
                                  names, formats, compression, tile)
                self.assert_same_outputs(self.outputs(path), expected, what)
        # Just the passes, next to each other in the file.
        self.assert_same_outputs(self.outputs(self.write(self.path("needed.exr"), layers,
                                                         sorted(layers))), expected, "needed")
        # Named channels in another order than the file's: the colour channels swapped.
        path = self.write(self.path("named.exr"), planes, names, half)
        got = self.outputs(path, "--beauty-channels",
                           "ViewLayer.Combined.B,ViewLayer.Combined.G,ViewLayer.Combined.R")
        swapped = dict(layers)
        del swapped["ViewLayer.Combined.A"]
        swapped["ViewLayer.Combined.R"], swapped["ViewLayer.Combined.B"] = (
            layers["ViewLayer.Combined.B"], layers["ViewLayer.Combined.R"])
        self.assert_same_outputs(got, self.outputs(self.write_parts(self.path("swapped.exr"),
                                                                    swapped)), "B,G,R")
        # Two passes of the same width next to each other in the file (a layer's depth, then
        # its facing): each into its own buffer.
        plain = {"Combined.R": layers["ViewLayer.Combined.R"],
                 "Combined.G": layers["ViewLayer.Combined.G"],
                 "Combined.B": layers["ViewLayer.Combined.B"],
                 "Depth.Z": layers["ViewLayer.Depth.Z"], "hit2": layers["ViewLayer.Depth2.Z"],
                 "hit2b": layers["ViewLayer.Facing2.V"]}
        path = self.write(self.path("adjacent.exr"), plain, sorted(plain))
        got = self.outputs(path, "--no-normals", "--depth-layer", "hit2:hit2b")
        reference = self.write_parts(self.path("adjacent_parts.exr"), plain)
        self.assert_same_outputs(got, self.outputs(reference, "--no-normals", "--depth-layer",
                                                   "hit2:hit2b"), "hit2:hit2b")

    def test_passes_in_other_parts_of_a_multi_part_file(self):
        layers = DepthLayersTest.layer_planes(self)
        expected = self.outputs(self.write_parts(self.path("parts.exr"), layers))
        # Parts in this order: others first, the passes the tool reads scattered among them,
        # several passes in one part.
        extra = self.extra_planes()
        order = [["ViewLayer.AO", "ViewLayer.Vector"], ["ViewLayer.Normal"], ["ViewLayer.Mist"],
                 ["ViewLayer.Facing2", "ViewLayer.Combined", "ViewLayer.DiffCol"],
                 ["ViewLayer.Depth3"], ["ViewLayer.Depth", "ViewLayer.Facing3", "ViewLayer.Emit"],
                 ["ViewLayer.Depth2", "ViewLayer.IndexOB"]]
        everything = {**layers, **extra}
        specs, groups = [], []
        for part in order:
            names = [n for n in sorted(everything) if n.rsplit(".", 1)[0] in part]
            spec = oiio.ImageSpec(WIDTH, HEIGHT, len(names), oiio.FLOAT)
            spec.channelnames = tuple(names)
            spec.channelformats = tuple(oiio.HALF if n in extra else oiio.FLOAT for n in names)
            spec.attribute("name", part[0])
            spec.attribute("compression", "zip")
            specs.append(spec)
            groups.append(names)
        self.assertEqual(sum(len(g) for g in groups), len(everything))
        multipart = self.path("multipart.exr")
        out = oiio.ImageOutput.create(multipart)
        self.assertTrue(out.open(multipart, specs), out.geterror())
        for i, names in enumerate(groups):
            if i:
                self.assertTrue(out.open(multipart, specs[i], "AppendSubimage"), out.geterror())
            self.assertTrue(out.write_image(np.stack([everything[n] for n in names], axis=-1)))
        out.close()
        self.assert_same_outputs(self.outputs(multipart), expected, "multi-part")

    def test_overscan_and_other_formats(self):
        band = OverscanTest.BAND
        window = dict(data_origin=(-band, -band), display_size=(WIDTH - 2 * band,
                                                                HEIGHT - 2 * band))
        camera = self.write_camera(dict(CAMERA, sensor_width=CAMERA["sensor_width"] *
                                        (WIDTH - 2 * band) / WIDTH), "frame_camera.json")
        expected = self.outputs(self.write_parts(self.path("parts.exr"), self.planes, **window),
                                camera=camera)
        planes = {**self.planes, **self.extra_planes()}
        for compression in ("zips", "zip"):
            path = self.write(self.path(f"overscan_{compression}.exr"), planes, sorted(planes),
                              {n: oiio.HALF for n in self.EXTRA}, compression, **window)
            self.assert_same_outputs(self.outputs(path, camera=camera), expected,
                                     f"overscan, {compression}")
        # Not an EXR: a float TIFF (R, G, B, A and a 5th channel OpenImageIO names channel4).
        tiff = self.path("in.tif")
        names = ["ViewLayer.Combined." + c for c in "RGBA"] + ["ViewLayer.Depth.Z"]
        spec = oiio.ImageSpec(WIDTH, HEIGHT, 5, oiio.FLOAT)
        out = oiio.ImageOutput.create(tiff)
        self.assertTrue(out.open(tiff, spec), oiio.geterror())
        out.write_image(np.stack([self.planes[n] for n in names], axis=-1))
        out.close()
        exr = self.write_parts(self.path("rgbaz.exr"), {c: self.planes[n] for c, n in
                                                        zip(["R", "G", "B", "A", "Z"], names)})
        self.assert_same_outputs(self.outputs(tiff, "--depth-channel", "channel4"),
                                 self.outputs(exr), "TIFF")


class HelpTest(CliTestCase):

    def test_help_lists_every_parameter(self):
        proc = self.run_ssao("--help", default_paths=False)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        table, _ = core_param_names()
        self.assertGreater(len(table), 10)
        for name in set(table) | set(CONTRACT_PARAMS):
            self.assertIn("--" + name.replace("_", "-") + " ", proc.stdout, name)
        for flag in ["-o", "--camera", "--ao-only", "--layer", "--depth-channel",
                     "--normal-channels", "--beauty-channels", "--no-normals", "--quiet",
                     "--version", "horizon|hemisphere|sphere", "low|medium|high|ultra"]:
            self.assertIn(flag, proc.stdout)

    def test_version(self):
        proc = self.run_ssao("--version", default_paths=False)
        self.assertEqual(proc.returncode, 0)
        _, version = core_param_names()
        expected = f"{version // 10000}.{version // 100 % 100}.{version % 100}"
        self.assertEqual(proc.stdout.strip(), "ssao " + expected)

    def test_every_parameter_is_accepted(self):
        # A value from the help's own defaults would be ideal; these are valid for the contract.
        values = {"variant": "sphere", "radius": "2.5", "samples": "8", "sphere_mode": "classic",
                  "denoise": "box4", "depth_kind": "planar", "normal_space": "world",
                  "bias": "0.05", "strength": "0.8", "power": "1.5", "remap_min": "0.1",
                  "remap_max": "0.9", "seed": "7", "threads": "2"}
        args = []
        for name, value in values.items():
            args += ["--" + name.replace("_", "-"), value]
        self.assert_ok(self.run_ssao("--ao-only", *args))
        _, out = read_image(self.output)
        geometry = out[SKY_ROWS:, :, 0]  # the sky stays at 1 whatever the remapping
        self.assertTrue(np.all((geometry >= 0.1 - 1e-6) & (geometry <= 0.9 + 1e-6)))


class BadInputTest(CliTestCase):

    def test_missing_input_file(self):
        self.input = self.path("nothing-here.exr")
        self.assert_fails(self.run_ssao(), 1, "nothing-here.exr", "no such file")

    def test_truncated_exr(self):
        with open(self.input, "rb") as f:
            data = f.read()
        with open(self.input, "wb") as f:
            f.write(data[:len(data) // 2])
        self.assert_fails(self.run_ssao(), 1, "in.exr", "truncated or corrupt")

    def test_not_an_image(self):
        with open(self.input, "w") as f:
            f.write("this is not an EXR file\n" * 20)
        self.assert_fails(self.run_ssao(), 1, "in.exr", "not an image")

    def test_missing_depth_channel_lists_channels(self):
        write_exr(self.input, self.planes, [n for n in BLENDER_CHANNELS if "Depth" not in n])
        proc = self.run_ssao()
        self.assert_fails(proc, 1, "no depth channel", "ViewLayer.Combined.R",
                          "ViewLayer.Normal.Z")

    def test_named_channel_missing_lists_channels(self):
        self.assert_fails(self.run_ssao("--depth-channel", "Depth"), 1, "'Depth'",
                          "ViewLayer.Depth.Z")
        self.assert_fails(self.run_ssao("--normal-channels", "a,b,c"), 1, "'a'",
                          "ViewLayer.Normal.X")

    def test_no_beauty_without_ao_only(self):
        write_exr(self.input, self.planes, [n for n in BLENDER_CHANNELS if "Combined" not in n])
        self.assert_fails(self.run_ssao(), 1, "--ao-only", "--beauty-channels")
        self.assert_ok(self.run_ssao("--ao-only"))

    def test_malformed_camera_json(self):
        self.camera = self.write_camera('{"type": "PERSP", "lens": 35.0,')
        self.assert_fails(self.run_ssao(), 1, "camera.json", "malformed JSON")

    def test_camera_lens_is_a_string(self):
        self.camera = self.write_camera(dict(CAMERA, lens="35mm"))
        self.assert_fails(self.run_ssao(), 1, "camera.json", "'lens'", "must be a number")

    def test_camera_problems(self):
        cases = [
            ({k: v for k, v in CAMERA.items() if k != "type"}, "missing key 'type'"),
            (dict(CAMERA, type="PANO"), "'type'"),
            (dict(CAMERA, matrix_world=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]), "4x4"),
            (dict(CAMERA, sensor_fit=3), "'sensor_fit'"),
            (dict(CAMERA, lens=-5.0), "lens"),  # rejected by the core's range check
            ("[1, 2, 3]", "JSON object"),
            ('{"type": "PERSP", "lens": 1e999}', "1e999"),
        ]
        for content, phrase in cases:
            with self.subTest(phrase=phrase):
                self.camera = self.write_camera(content)
                self.assert_fails(self.run_ssao(), 1, phrase)
        self.camera = self.path("no-camera.json")
        self.assert_fails(self.run_ssao(), 1, "no-camera.json", "no such file")

    def test_camera_without_a_value_the_run_depends_on_is_refused(self):
        # A default in place of a missing value would give a plausible, wrong image.
        without = lambda camera, key: {k: v for k, v in camera.items() if k != key}
        ortho = dict(CAMERA, type="ORTHO")
        vertical = dict(CAMERA, sensor_fit="VERTICAL")
        singular = CAMERA_TO_WORLD.copy()
        singular[:3, 1] = singular[:3, 0]  # two parallel axes
        projective = CAMERA_TO_WORLD.copy()
        projective[3, 2] = 0.5
        cases = [
            (without(CAMERA, "lens"), "missing key 'lens'"),
            (without(CAMERA, "sensor_width"), "missing key 'sensor_width'"),
            (without(vertical, "sensor_height"), "missing key 'sensor_height'"),
            (without(CAMERA, "sensor_fit"), "missing key 'sensor_fit'"),
            (without(CAMERA, "shift_x"), "missing key 'shift_x'"),
            (without(CAMERA, "shift_y"), "missing key 'shift_y'"),
            (without(ortho, "ortho_scale"), "missing key 'ortho_scale'"),
            (dict(CAMERA, lens=0.0), "'lens' must be positive"),
            (dict(CAMERA, sensor_width=-36.0), "'sensor_width' must be positive"),
            (dict(ortho, ortho_scale=0.0), "'ortho_scale' must be positive"),
            (dict(CAMERA, pixel_aspect_y=-1.0), "'pixel_aspect_y' must be positive"),
            (dict(CAMERA, clip_end=0.0), "'clip_end' must be positive"),
            (dict(CAMERA, clip_start=-0.1), "'clip_start' must not be negative"),
            (dict(CAMERA, ao_distance=0.0), "'ao_distance' must be positive"),
            (dict(CAMERA, lens=None), "'lens' must be a number, got null"),
            ('{"type": "PERSP", "lens": NaN}', "malformed JSON"),
            (dict(CAMERA, matrix_world=projective.tolist()), "affine"),
            (without(CAMERA, "matrix_world"), "missing key 'matrix_world'"),  # normals from pass
        ]
        for content, phrase in cases:
            with self.subTest(phrase=phrase):
                self.camera = self.write_camera(content)
                self.assert_fails(self.run_ssao(), 1, "camera.json", phrase)
        # The core refuses a singular matrix when world-space normals need it.
        self.camera = self.write_camera(dict(CAMERA, matrix_world=singular.tolist()))
        self.assert_fails(self.run_ssao(), 1, "camera_to_world", "singular")
        self.assert_ok(self.run_ssao("--no-normals"))
        os.remove(self.output)
        # What is not needed is not required: an ORTHO camera has no lens, a HORIZONTAL fit no
        # sensor height, a run without world-space normals no matrix.
        lean = without(without(without(CAMERA, "sensor_height"), "clip_start"), "clip_end")
        for content, args in [(without(without(ortho, "lens"), "sensor_width"), ()),
                              (dict(lean, sensor_fit="HORIZONTAL"), ()),
                              (without(CAMERA, "matrix_world"), ("--no-normals",)),
                              (without(CAMERA, "matrix_world"), ("--normal-space", "camera"))]:
            with self.subTest(content=content, args=args):
                self.camera = self.write_camera(content)
                self.assert_ok(self.run_ssao(*args))
                os.remove(self.output)

    def test_missing_clip_end_does_not_cut_far_geometry(self):
        # Before, a missing clip_end became 1000 and geometry beyond it turned to background
        # (AO 1) without a word. Scaled by 1e3, the scene's geometry lies beyond 1000.
        scaled = {k: (v * np.float32(1000.0) if "Depth" in k else v)
                  for k, v in self.planes.items()}
        write_exr(self.input, scaled, BLENDER_CHANNELS)
        camera = {k: v for k, v in CAMERA.items() if k != "clip_end"}
        self.camera = self.write_camera(camera)
        self.assert_ok(self.run_ssao("--ao-only", "--radius", RADIUS * 1000.0))
        far = read_image(self.output)[1]
        write_exr(self.input, self.planes, BLENDER_CHANNELS)
        os.remove(self.output)
        self.assert_ok(self.run_ssao("--ao-only"))
        near = read_image(self.output)[1]
        self.assertLess(float(near.min()), 0.9)  # the scene has occlusion to lose
        np.testing.assert_allclose(far, near, atol=1e-3)

    def test_missing_camera_flag(self):
        proc = self.run_ssao(self.input, "-o", self.output, default_paths=False)
        self.assert_fails(proc, 2, "--camera")

    def test_missing_output_flag(self):
        proc = self.run_ssao(self.input, "--camera", self.camera, default_paths=False)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("-o", proc.stderr)
        self.assertEqual(sorted(os.listdir(self.dir)), ["camera.json", "in.exr"])

    def test_unknown_flag(self):
        self.assert_fails(self.run_ssao("--frobnicate", "3"), 2, "unknown option '--frobnicate'")
        self.assert_fails(self.run_ssao("--radiuss", "3"), 2, "did you mean --radius")

    def test_bad_values(self):
        cases = [
            (["--samples", "abc"], "--samples", "integer"),
            (["--samples", "1.5"], "--samples", "integer"),
            (["--radius", "nan"], "--radius", "finite"),
            (["--radius", "inf"], "--radius", "finite"),
            (["--radius", "-1"], "--radius", "radius"),   # the core's range check
            (["--samples", "-1"], "--samples", "samples"),  # the core's range check
            (["--variant", "foo"], "--variant", "hemisphere"),
            (["--radius"], "--radius", "requires a value"),
            (["--normal-channels", "X,Y"], "--normal-channels", "3"),
            (["--no-normals", "--normal-channels", "a,b,c"], "--no-normals", "--normal-channels"),
        ]
        for args, *phrases in cases:
            with self.subTest(args=args):
                self.assert_fails(self.run_ssao(*args), 2, *phrases)

    def test_output_is_input(self):
        with open(self.input, "rb") as f:
            before = f.read()
        proc = self.run_ssao(self.input, "-o", self.input, "--camera", self.camera,
                             default_paths=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("is the input file", proc.stderr)
        with open(self.input, "rb") as f:
            self.assertEqual(f.read(), before)
        # The same file through another spelling of its path.
        other = os.path.join(self.dir, ".", "in.exr")
        proc = self.run_ssao(self.input, "-o", other, "--camera", self.camera, default_paths=False)
        self.assertEqual(proc.returncode, 2, proc.stderr)

    def test_unwritable_output_leaves_nothing(self):
        self.output = self.path("missing-folder/out.exr")
        self.assert_fails(self.run_ssao(), 1, "cannot write", "missing-folder")


def main():
    global SSAO, LIB, SCRATCH
    if len(sys.argv) == 3 and sys.argv[1] == "--dump-core-table":
        dump_core_table(sys.argv[2])
        return
    parser = argparse.ArgumentParser(add_help=False)
    parser.add_argument("--ssao", default=SSAO)
    parser.add_argument("--lib", default=LIB)
    parser.add_argument("--scratch", default=SCRATCH)
    args, rest = parser.parse_known_args()
    SSAO, LIB = os.path.abspath(args.ssao), os.path.abspath(args.lib)
    SCRATCH = os.path.abspath(args.scratch or tempfile.mkdtemp(prefix="ssao-cli-tests-"))
    if not os.access(SSAO, os.X_OK) or not os.path.isfile(LIB):
        sys.exit(f"test_cli.py: need --ssao BINARY and --lib LIBSSAO (got '{SSAO}', '{LIB}')")
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
