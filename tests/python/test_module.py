#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The Python module `ssao` (core/python/ssao) against the command-line tool on the bundled
sample, and its answers to bad input, from Debian's python3 with numpy and OpenImageIO.

    /usr/bin/python3 tests/python/test_module.py SSAO_CLI [MODULE_FOLDER]

MODULE_FOLDER (default: core/python of this checkout) is put first on sys.path, so the same
test runs on an installed module (tests/install/test_install.sh passes PREFIX's).
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from image_files import read_image  # noqa: E402

CLI = sys.argv[1] if len(sys.argv) > 1 else ""
MODULE_FOLDER = sys.argv[2] if len(sys.argv) > 2 else os.path.join(HERE, "..", "..", "core",
                                                                    "python")
del sys.argv[1:]
sys.path.insert(0, MODULE_FOLDER)
import ssao  # noqa: E402

SAMPLE = os.path.join(HERE, "..", "data", "sample")


def load_sample():
    names, pixels = read_image(SAMPLE + ".exr")
    index = {name: k for k, name in enumerate(names)}
    depth = pixels[:, :, index["ViewLayer.Depth.Z"]]  # a view: read in place, strided
    k = index["ViewLayer.Normal.X"]
    normals = pixels[:, :, k:k + 3]
    k = index["ViewLayer.Combined.R"]
    beauty = pixels[:, :, k:k + 4]
    with open(SAMPLE + ".camera.json") as f:
        camera = json.load(f)
    return depth, normals, beauty, camera


def run_cli(*args, camera=None):
    """The CLI's output file's channels {name: (H, W)} for the sample (and its camera, or
    `camera` written to a file)."""
    with tempfile.TemporaryDirectory() as folder:
        camera_path = SAMPLE + ".camera.json"
        if camera is not None:
            camera_path = os.path.join(folder, "camera.json")
            with open(camera_path, "w") as f:
                json.dump(camera, f)
        out = os.path.join(folder, "out.exr")
        subprocess.run([CLI, SAMPLE + ".exr", "--camera", camera_path, "-o", out, "--quiet",
                        *args], check=True, stderr=subprocess.DEVNULL if camera else None)
        names, pixels = read_image(out)
    return {name: pixels[:, :, k] for k, name in enumerate(names)}


class AgainstCli(unittest.TestCase):
    """Same inputs, same AO: the bits of the CLI's output."""

    @classmethod
    def setUpClass(cls):
        cls.depth, cls.normals, cls.beauty, cls.camera = load_sample()

    def assert_same_bits(self, a, b):
        self.assertEqual(a.shape, b.shape)
        differ = np.count_nonzero(a.view(np.uint32) != b.view(np.uint32))
        self.assertEqual(differ, 0, f"{differ} pixels differ, max "
                                    f"{np.max(np.abs(a - b)) if differ else 0}")

    def test_radius_and_normal_pass(self):
        ao = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=self.camera,
                                    radius=0.8, edge_colours=self.beauty)
        self.assertEqual((ao.dtype, ao.shape), (np.float32, self.depth.shape))
        self.assertGreater(np.count_nonzero(ao < 0.9), 100)  # there is AO to compare
        self.assert_same_bits(ao, run_cli("--radius", "0.8", "--ao-only")["AO"])

    def test_automatic_radius_variant_and_no_normals(self):
        ao = ssao.ambient_occlusion(self.depth, camera=self.camera, variant="horizon",
                                    samples=12, edge_colours=self.beauty)
        cli = run_cli("--no-normals", "--variant", "horizon", "--samples", "12", "--ao-only")
        self.assert_same_bits(ao, cli["AO"])

    def test_ao_distance_is_the_default_radius(self):
        camera = dict(self.camera, ao_distance=0.5)
        ao = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=camera,
                                    edge_colours=self.beauty)
        self.assert_same_bits(ao, run_cli("--ao-only", camera=camera)["AO"])
        self.assert_same_bits(ao, ssao.ambient_occlusion(self.depth, normals=self.normals,
                                                         camera=self.camera, radius=0.5,
                                                         edge_colours=self.beauty))

    def test_composite(self):
        ao, composite = ssao.ambient_occlusion(self.depth, normals=self.normals,
                                               camera=self.camera, radius=0.8,
                                               beauty=self.beauty)
        cli = run_cli("--radius", "0.8")
        self.assert_same_bits(ao, cli["AO"])
        for c, name in enumerate("RGBA"):
            self.assert_same_bits(np.ascontiguousarray(composite[:, :, c]), cli[name])

    def test_edge_colours_and_ao_only_give_the_composites_ao(self):
        # With edge_coverage = beauty the AO at depth edges reads the beauty's colours: the
        # CLI reads them with --ao-only too, and edge_colours stands in for a white beauty.
        ao, _ = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=self.camera,
                                       radius=0.8, beauty=self.beauty, edge_coverage="beauty")
        plain = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=self.camera,
                                       radius=0.8, edge_coverage="none")
        self.assertGreater(np.count_nonzero(ao != plain), 20)  # the sample has such edges
        white = np.ones_like(self.beauty)
        guided, _ = ssao.ambient_occlusion(
            self.depth, normals=self.normals, camera=self.camera, radius=0.8, beauty=white,
            edge_colours=self.beauty, edge_coverage="beauty")
        self.assert_same_bits(guided, ao)
        for flags in (("--ao-only",), ()):
            self.assert_same_bits(ao, run_cli("--radius", "0.8", "--edge-coverage", "beauty",
                                              *flags)["AO"])
        with self.assertRaises(ssao.SSAOError):
            ssao.ambient_occlusion(self.depth, camera=self.camera, beauty=self.beauty,
                                   edge_colours=self.beauty[:-1])

    def test_docs_example(self):
        # docs/examples/ambient_occlusion.py, as docs/python.md runs it.
        example = os.path.join(HERE, "..", "..", "docs", "examples", "ambient_occlusion.py")
        with tempfile.TemporaryDirectory() as folder:
            out = os.path.join(folder, "ao.exr")
            env = dict(os.environ, PYTHONPATH=os.path.abspath(MODULE_FOLDER))
            subprocess.run([sys.executable, example, SAMPLE + ".exr", SAMPLE + ".camera.json",
                            out, "0.8"], check=True, env=env, stdout=subprocess.DEVNULL)
            names, pixels = read_image(out)
        self.assertEqual(names, ["AO"])
        self.assert_same_bits(pixels[:, :, 0], run_cli("--radius", "0.8", "--ao-only")["AO"])

    def test_input_layout_does_not_change_the_bits(self):
        contiguous = ssao.ambient_occlusion(np.ascontiguousarray(self.depth),
                                            normals=np.ascontiguousarray(self.normals),
                                            camera=self.camera, radius=0.8)
        flipped_twice = self.depth[::-1][::-1]  # a view with a negative step taken back
        bottom_up = np.ascontiguousarray(self.depth[::-1])[::-1]  # rows stored bottom-up
        for depth in (self.depth, flipped_twice, bottom_up):
            ao = ssao.ambient_occlusion(depth, normals=self.normals, camera=self.camera,
                                        radius=0.8)
            self.assert_same_bits(ao, contiguous)


class CameraRulesAgreeWithCli(unittest.TestCase):
    """The camera file's rules live in the CLI (core/tools/camera_json.cpp) and in the module:
    for each variant of the sample's camera, both accept it with the same AO, or both refuse
    it."""

    def variants(self, camera):
        intrinsics = {"projection": "intrinsics", "type": "PERSP",
                      "intrinsics": [233.3, 233.3, 120.0, 67.5],
                      "matrix_world": camera["matrix_world"]}
        yield "as is", camera
        for key in ("type", "lens", "sensor_width", "sensor_fit", "shift_x", "shift_y",
                    "sensor_height", "ortho_scale", "clip_start", "clip_end", "matrix_world"):
            yield f"without {key}", {k: v for k, v in camera.items() if k != key}
        yield "ORTHO without ortho_scale", dict(
            {k: v for k, v in camera.items() if k != "ortho_scale"}, type="ORTHO")
        yield "VERTICAL without sensor_height", dict(
            {k: v for k, v in camera.items() if k != "sensor_height"}, sensor_fit="VERTICAL")
        for key, bad in (("lens", 0), ("lens", -1.0), ("lens", "35"), ("lens", True),
                         ("lens", None), ("clip_end", 0), ("clip_start", -0.1),
                         ("ortho_scale", 0), ("pixel_aspect_x", 0), ("shift_x", 2000.0),
                         ("shift_x", "0"), ("type", "FISHEYE"), ("type", 1),
                         ("sensor_fit", "auto"), ("ao_distance", 0), ("ao_distance", -1),
                         ("ao_distance", "1"), ("projection", "pinhole"),
                         ("matrix_world", [[1, 0, 0, 0]] * 3),
                         ("matrix_world", [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]),
                         ("matrix_world", [[1, 0, 0, "0"], [0, 1, 0, 0], [0, 0, 1, 0],
                                           [0, 0, 0, 1]])):
            yield f"{key} = {bad!r}", dict(camera, **{key: bad})
        yield "intrinsics", intrinsics
        yield "intrinsics without type", {k: v for k, v in intrinsics.items() if k != "type"}
        yield "intrinsics without intrinsics", {k: v for k, v in intrinsics.items()
                                                if k != "intrinsics"}
        yield "intrinsics of 3", dict(intrinsics, intrinsics=[233.3, 233.3, 120.0])
        yield "matrix without projection_matrix", dict(camera, projection="matrix")

    def test_same_verdicts_and_bits(self):
        depth, normals, beauty, camera = load_sample()
        verdicts = {True: 0, False: 0}
        for name, variant in self.variants(camera):
            with self.subTest(name):
                try:
                    cli = run_cli("--radius", "0.8", "--ao-only", camera=variant)["AO"]
                except subprocess.CalledProcessError:
                    cli = None
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        ao = ssao.ambient_occlusion(depth, normals=normals, camera=variant,
                                                    radius=0.8, edge_colours=beauty)
                    except ssao.SSAOError:
                        ao = None
                self.assertEqual(ao is None, cli is None,
                                 f"CLI {'refuses' if cli is None else 'accepts'} it, the module "
                                 f"{'refuses' if ao is None else 'accepts'} it")
                if ao is not None and cli is not None:
                    AgainstCli.assert_same_bits(self, ao, cli)
                verdicts[ao is None] += 1
        self.assertGreater(verdicts[False], 3)  # both kinds occur
        self.assertGreater(verdicts[True], 20)


class OtherInputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.depth, cls.normals, cls.beauty, cls.camera = load_sample()

    def test_output_window_is_the_widened_camera_cropped(self):
        # With intrinsics the frame of a window at (x, y) is the whole image with the principal
        # point moved by (x, y): the library's overscan contract, checked independently.
        height, width = self.depth.shape
        fx = 35.0 / 36.0 * width
        camera = {"projection": "intrinsics", "type": "PERSP", "intrinsics":
                  [fx, fx, width / 2, height / 2], "matrix_world": self.camera["matrix_world"]}
        x, y, w, h = 20, 10, 180, 100
        whole = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=camera,
                                       radius=0.8)
        window_camera = dict(camera, intrinsics=[fx, fx, width / 2 - x, height / 2 - y])
        window = ssao.ambient_occlusion(self.depth, normals=self.normals, camera=window_camera,
                                        radius=0.8, output_window=(x, y, w, h))
        self.assertEqual(window.shape, (h, w))
        np.testing.assert_allclose(window, whole[y:y + h, x:x + w], atol=1e-6)

    def test_depth_layers(self):
        behind = self.depth * np.float32(1.02)  # a thin shell behind every surface
        one = ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                     variant="hemisphere")
        two = ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                     variant="hemisphere", depth_layers=[behind])
        self.assertGreater(np.count_nonzero(one != two), 100)
        generator = ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                           variant="hemisphere",
                                           depth_layers=(layer for layer in [behind]))
        np.testing.assert_array_equal(generator, two)  # an iterator is not used up by checks
        for layers in ([self.depth * 0.5], iter([self.depth * 0.5])):
            with self.assertRaisesRegex(ssao.SSAOError, "nearer"):
                ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                       variant="hemisphere", depth_layers=layers)

    def test_progress_and_cancel(self):
        seen = []
        ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8, progress=seen.append)
        self.assertTrue(seen and seen[-1] == 1.0 and seen == sorted(seen), seen)
        for stop in (False, 0, np.False_):
            with self.assertRaisesRegex(ssao.SSAOError, "cancelled"):
                ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                       progress=lambda fraction: stop)

    def test_an_exception_in_progress_is_raised_as_it_was(self):
        calls = []

        def failing(fraction, at):
            calls.append(fraction)
            if fraction >= at:
                raise ValueError(f"stop at {fraction}")

        for at in (0.0, 1.0):  # the first call, and the last (after the AO is complete)
            calls.clear()
            with self.assertRaisesRegex(ValueError, "stop at"):
                ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                       progress=lambda f: failing(f, at))
            self.assertEqual(calls[-1], max(calls))  # not called again after it raised
        with self.assertRaises(KeyboardInterrupt):
            ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8,
                                   progress=lambda f: (_ for _ in ()).throw(KeyboardInterrupt))

    def test_background_pixels(self):
        depth = np.array(self.depth)
        depth[:10] = np.nan  # the library's contract: NaN is background, AO exactly 1
        depth[10:20] = np.inf
        ao = ssao.ambient_occlusion(depth, camera=self.camera, radius=0.8)
        self.assertTrue(np.all(ao[:20] == 1.0))
        self.assertTrue(np.all(np.isfinite(ao)))

    def test_run_stats_and_a_frame_without_geometry(self):
        depth = np.array(self.depth)
        depth[:10] = np.inf
        stats = {}
        ao = ssao.ambient_occlusion(depth, camera=self.camera, radius=0.8, run_stats=stats)
        # The library's count and mean, checked against the background rule's own statement:
        # finite, positive and below background_depth (the camera has clip_end 100).
        geometry = np.isfinite(depth) & (depth > 0) & (depth < 100.0)
        self.assertEqual(stats["geometry_pixels"], int(geometry.sum()))
        self.assertAlmostEqual(stats["mean_ao"], float(ao[geometry].mean()), places=5)
        self.assertLess(stats["mean_ao"], float(ao.mean()))  # the sky's AO 1 is not counted
        sky = np.full_like(depth, np.inf)
        beauty = np.full(depth.shape + (3,), 0.5, np.float32)
        with self.assertRaisesRegex(ssao.SSAOError, "no geometry pixel"):
            ssao.ambient_occlusion(sky, camera=self.camera, radius=0.8)
        for radius in ({"radius": 0.8}, {}):  # without a radius: no automatic one either
            stats = {}
            ao, composite = ssao.ambient_occlusion(sky, camera=self.camera, beauty=beauty,
                                                   require_geometry=False, run_stats=stats,
                                                   **radius)
            self.assertTrue(np.all(ao == 1.0))
            np.testing.assert_array_equal(composite, beauty)
            self.assertEqual(stats, {"geometry_pixels": 0, "mean_ao": 1.0})

    def test_camera_file_path(self):
        with_dict = ssao.ambient_occlusion(self.depth, camera=self.camera, radius=0.8)
        for path in (SAMPLE + ".camera.json", pathlib.Path(SAMPLE + ".camera.json")):
            np.testing.assert_array_equal(
                ssao.ambient_occlusion(self.depth, camera=path, radius=0.8), with_dict)
        with tempfile.TemporaryDirectory() as folder:
            bad = os.path.join(folder, "bad.json")
            for text, pattern in (('{"lens": NaN}', r"malformed JSON: NaN is not JSON"),
                                  ('{"lens": 35', r"malformed JSON"),
                                  ('[1, 2]', r"expected a JSON object, got list")):
                with open(bad, "w") as f:
                    f.write(text)
                with self.assertRaisesRegex(ssao.SSAOError, "camera file '.*bad.json': " + pattern):
                    ssao.ambient_occlusion(self.depth, camera=bad, radius=0.8)
            with self.assertRaisesRegex(ssao.SSAOError, r"camera file '.*none.json': No such file"):
                ssao.ambient_occlusion(self.depth, camera=os.path.join(folder, "none.json"),
                                       radius=0.8)

    def test_a_named_library_is_that_one_or_an_error(self):
        with self.assertRaisesRegex(ssao.SSAOError, "cannot load libssao /typo/libssao.so: "
                                                    "not found"):
            ssao.load_library("/typo/libssao.so")
        env = dict(os.environ, SSAO_LIBRARY="/typo/libssao.so",
                   PYTHONPATH=os.path.abspath(MODULE_FOLDER))
        result = subprocess.run([sys.executable, "-c", "import ssao; ssao.version()"], env=env,
                                capture_output=True, text=True)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("/typo/libssao.so ($SSAO_LIBRARY): not found", result.stderr)

    def test_job_reads_back_parameters(self):
        matrix = [float(v) for v in np.arange(12)] + [0.0, 0.0, 0.0, 1.0]
        with ssao.Job() as job:
            job.set("camera_to_world", np.array(matrix).reshape(4, 4))
            job.set("radius", np.float32(0.5))
            job.set("samples", np.int64(12))
            self.assertEqual(job.get("camera_to_world"), matrix)
            self.assertEqual((job.get("radius"), job.get("samples")), (0.5, 12))

    def test_module_facts(self):
        self.assertRegex(ssao.version(), r"^\d+\.\d+\.\d+$")
        names = {p["name"] for p in ssao.parameters()}
        self.assertTrue({"radius", "variant", "samples", "lens"} <= names)
        self.assertIn("horizon", {v["name"] for v in ssao.variants()})


class SequenceOfFrames(unittest.TestCase):
    """ssao.Sequence: a shot's frames in one job, whose temporal filter averages each frame
    with those before it: the bits of the CLI's --frames run of the same shot."""

    @classmethod
    def setUpClass(cls):
        cls.depth, cls.normals, cls.beauty, camera = load_sample()
        # The camera trucks 2 cm a frame along the world's x: the pattern lands elsewhere.
        cls.cameras = []
        for k in range(3):
            moved = json.loads(json.dumps(camera))
            moved["matrix_world"][0][3] += 0.02 * k
            cls.cameras.append(moved)

    def cli_sequence(self, *args):
        """The CLI's AO of frames 1-3: the sample's passes with the moving cameras."""
        with tempfile.TemporaryDirectory() as folder:
            for k, camera in enumerate(self.cameras, start=1):
                os.symlink(os.path.abspath(SAMPLE + ".exr"),
                           os.path.join(folder, f"shot.{k:04d}.exr"))
                with open(os.path.join(folder, f"camera.{k:04d}.json"), "w") as f:
                    json.dump(camera, f)
            subprocess.run([CLI, os.path.join(folder, "shot.####.exr"), "--frames", "1-3",
                            "--camera", os.path.join(folder, "camera.####.json"),
                            "-o", os.path.join(folder, "ao.####.exr"), "--radius", "0.8",
                            "--ao-only", "--quiet", *args], check=True,
                           stderr=subprocess.DEVNULL)
            return [read_image(os.path.join(folder, f"ao.{k:04d}.exr"))[1][:, :, 0]
                    for k in (1, 2, 3)]

    def sequence(self, first_frame=1, **parameters):
        with ssao.Sequence() as shot:
            return [shot.ambient_occlusion(self.depth, normals=self.normals, camera=camera,
                                           radius=0.8, edge_colours=self.beauty,
                                           frame=first_frame + k, **parameters)
                    for k, camera in enumerate(self.cameras)]

    def test_frames_are_the_cli_sequence(self):
        cli = self.cli_sequence()
        alone = [ssao.ambient_occlusion(self.depth, normals=self.normals, camera=camera,
                                        radius=0.8, edge_colours=self.beauty)
                 for camera in self.cameras]
        for first_frame in (1, -1):  # Blender's frames may be negative
            aos = self.sequence(first_frame)
            for k in range(3):
                AgainstCli.assert_same_bits(self, aos[k], cli[k])
        AgainstCli.assert_same_bits(self, aos[0], alone[0])  # nothing before it
        for k in (1, 2):  # the filter acts
            self.assertGreater(np.count_nonzero(np.abs(aos[k] - alone[k]) > 1e-3), 1000)

    def test_one_temporal_frame_is_each_frame_alone(self):
        cli = self.cli_sequence("--temporal-frames", "1")
        for k, ao in enumerate(self.sequence(temporal_frames=1)):
            AgainstCli.assert_same_bits(self, ao, cli[k])
            AgainstCli.assert_same_bits(self, ao, ssao.ambient_occlusion(
                self.depth, normals=self.normals, camera=self.cameras[k], radius=0.8,
                edge_colours=self.beauty))

    def test_a_frame_again_uses_only_the_frames_before_it(self):
        with ssao.Sequence() as shot:
            run = [shot.ambient_occlusion(self.depth, normals=self.normals, camera=camera,
                                          radius=0.8, frame=k + 1)
                   for k, camera in enumerate(self.cameras)]
            again = shot.ambient_occlusion(self.depth, normals=self.normals,
                                           camera=self.cameras[2], radius=0.8, frame=3)
            AgainstCli.assert_same_bits(self, again, run[2])
            first = shot.ambient_occlusion(self.depth, normals=self.normals,
                                           camera=self.cameras[0], radius=0.8, frame=1)
            AgainstCli.assert_same_bits(self, first, run[0])

    def test_bad_frames_and_inputs(self):
        with ssao.Sequence() as shot:
            for frame in (True, 1.0, "1", 2 ** 30, -2 ** 30, None):
                with self.assertRaisesRegex(ssao.SSAOError, "frame must be an int"):
                    shot.ambient_occlusion(self.depth, camera=self.cameras[0], frame=frame)
            with self.assertRaisesRegex(ssao.SSAOError, "normals has shape"):
                shot.ambient_occlusion(self.depth, normals=self.normals[:10],
                                       camera=self.cameras[0], frame=1)
            # A frame's images and output window are not the next frame's: frame 1 again
            # (nothing before it) without normals and window is frame 1 alone without them.
            height, width = self.depth.shape
            shot.ambient_occlusion(self.depth, normals=self.normals, camera=self.cameras[0],
                                   radius=0.8, frame=1,
                                   output_window=(4, 4, width - 8, height - 8))
            ao = shot.ambient_occlusion(self.depth, camera=self.cameras[0], radius=0.8, frame=1)
            AgainstCli.assert_same_bits(self, ao, ssao.ambient_occlusion(
                self.depth, camera=self.cameras[0], radius=0.8))


class BadInput(unittest.TestCase):
    """Every bad input is an ssao.SSAOError with a message that says what is wrong."""

    @classmethod
    def setUpClass(cls):
        cls.depth, cls.normals, cls.beauty, cls.camera = load_sample()
        cls.contiguous = np.ascontiguousarray(cls.depth)

    def refused(self, pattern, depth=None, **kwargs):
        kwargs.setdefault("camera", self.camera)
        if kwargs.setdefault("radius", 0.8) is None:
            del kwargs["radius"]  # the automatic radius
        with self.assertRaisesRegex(ssao.SSAOError, pattern):
            ssao.ambient_occlusion(self.contiguous if depth is None else depth, **kwargs)

    def test_dtype(self):
        self.refused(r"depth must be float32.*got float64", self.contiguous.astype(np.float64))
        self.refused(r"depth must be float32.*got int32", np.zeros((135, 240), np.int32))
        self.refused(r"depth must be float32.*got >f4", self.contiguous.astype(">f4"))
        self.refused(r"normals must be float32", normals=self.normals.astype(np.float16))
        self.refused(r"depth must be a numpy array, got list", self.contiguous.tolist())

    def test_shape(self):
        self.refused(r"must have 2 dimensions.*got shape \(32400,\)", self.contiguous.ravel())
        self.refused(r"depth must have 1 channels", self.normals)
        self.refused(r"normals has shape \(135, 239\), the depth \(135, 240\)",
                     normals=self.normals[:, 1:])
        self.refused(r"normals must have 3 or 4 channels", normals=self.normals[:, :, :2])
        self.refused(r"depth_layers\[0\] has shape", depth_layers=[self.contiguous[1:]])
        self.refused(r"beauty has shape", beauty=self.beauty[1:])
        self.refused(r"output_window must be \(x, y, width, height\)", output_window=(1, 2))
        self.refused(r"output_window must be .* whole pixels", output_window=(20.7, 0, 10, 10))
        self.refused(r"output window.*does not fit", output_window=(200, 0, 100, 100))
        self.refused(r"output window.*does not fit", output_window=(2**32 + 20, 0, 10, 10))
        self.refused(r"output window.*does not fit", output_window=(0, 0, 200000, 200000))
        self.refused(r"output window.*does not fit", output_window=(0, 0, -10, 10))

    def test_layouts_the_library_cannot_read_in_place(self):
        self.refused(r"depth.*transposed.*np.ascontiguousarray", self.contiguous.T.T.T)
        self.refused(r"depth.*reversed.*np.ascontiguousarray", self.contiguous[:, ::-1])
        self.refused(r"depth.*broadcast", np.broadcast_to(self.contiguous[:1], (135, 240)))
        self.refused(r"normals.*channels are not adjacent",
                     normals=np.ascontiguousarray(self.normals.transpose(2, 0, 1))
                     .transpose(1, 2, 0))
        raw = np.zeros(self.contiguous.nbytes + 1, np.uint8)[1:]
        unaligned = raw.view(np.float32).reshape(self.contiguous.shape)
        unaligned[...] = self.contiguous
        self.refused(r"not aligned", unaligned)
        self.refused(r"masked array", np.ma.masked_invalid(self.contiguous))

    def test_nan_and_out_of_range_values(self):
        self.refused(r"'radius' must be finite, got nan", radius=float("nan"))
        self.refused(r"threads.*must be in", threads=-3)
        self.refused(r"'threads' is out of range", threads=2**40)
        self.refused(r"'threads' must be an int, got float", threads=2.0)
        self.refused(r"'radius' must be a number, got str", radius="0.8")
        self.refused(r"camera file 'camera': key 'lens' must be a finite number, got nan",
                     camera=dict(self.camera, lens=float("nan")))
        self.refused(r"key 'lens' must be a finite number",
                     camera=dict(self.camera, lens=10**400))
        self.refused(r"'radius' is out of range", radius=10**400)
        self.refused(r"key 'clip_end' must be positive, got 0",  # the CLI's rule
                     camera=dict(self.camera, clip_end=0))
        self.refused(r"key 'clip_start' must not be negative",
                     camera=dict(self.camera, clip_start=-1.0))
        self.refused(r"key 'ao_distance' must be a finite number",
                     camera=dict(self.camera, ao_distance=float("inf")), radius=None)
        self.refused(r"key 'lens' must be positive", camera=dict(self.camera, lens=-35.0))
        self.refused(r"camera file 'camera': .*'shift_x' must be in", camera=dict(self.camera, shift_x=5000))
        self.refused(r"no geometry pixel", np.full_like(self.contiguous, np.nan))
        self.refused(r"no geometry pixel", np.full_like(self.contiguous, np.nan), radius=None)

    def test_parameters_and_camera(self):
        self.refused(r"unknown parameter 'radus'", radus=1.0)
        self.refused(r"variant.*must be one of", variant="nope")
        self.refused(r"missing key 'lens'", camera={k: v for k, v in self.camera.items()
                                                    if k != "lens"})
        self.refused(r"missing key 'ortho_scale'", camera=dict(
            {k: v for k, v in self.camera.items() if k != "ortho_scale"}, type="ORTHO"))
        self.refused(r"'matrix_world' must be a 4x4 matrix", camera=dict(
            self.camera, matrix_world=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]))
        self.refused(r"'matrix_world' must be an affine transform", camera=dict(
            self.camera, matrix_world=[[1, 0, 0, 0]] * 4))
        no_matrix = {k: v for k, v in self.camera.items() if k != "matrix_world"}
        self.refused(r"missing key 'matrix_world'.* which world-space normals need",
                     normals=self.normals, camera=no_matrix)
        self.refused(r"missing key 'matrix_world' \(or the parameter camera_to_world\)", normals=self.normals, camera=None,
                     lens=35.0)
        self.refused(r"key 'intrinsics\[0\]' must be a number, got a string", camera={
            "projection": "intrinsics", "type": "PERSP", "intrinsics": ["100", 100, 120, 67]})
        self.refused(r"key 'matrix_world\[0\]\[0\]' must be a number, got a boolean", camera=dict(
            self.camera, matrix_world=[[True, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0],
                                       [0, 0, 0, 1]]))
        self.refused(r"'camera_to_world' must be a sequence of numbers, got set",
                     camera=no_matrix, camera_to_world={1.0, 2.0})
        # The matrix as a parameter (any array shape of 16 numbers) stands for the camera's.
        matrix = np.array(self.camera["matrix_world"])
        np.testing.assert_array_equal(
            ssao.ambient_occlusion(self.contiguous, normals=self.normals, camera=no_matrix,
                                   camera_to_world=matrix, radius=0.8),
            ssao.ambient_occlusion(self.contiguous, normals=self.normals, camera=self.camera,
                                   radius=0.8))
        self.refused(r"camera must be a dict .* or a camera file's path, got int", camera=3)
        self.refused(r"key 'shift_x' must be a number, got a string",
                     camera=dict(self.camera, shift_x="0"))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ssao.ambient_occlusion(self.contiguous, camera=dict(self.camera, focus=3.0),
                                   radius=0.8)
        self.assertIn("unknown key 'focus' ignored", str(caught[0].message))

    def test_any_view_is_read_right_or_refused(self):
        # Views of every kind numpy makes: each gives the AO of its contiguous copy, bit for
        # bit, or an SSAOError; never a crash, never another image.
        rng = np.random.default_rng(24)
        base = np.ascontiguousarray(self.depth[:64, :96])
        normals = np.ascontiguousarray(self.normals[:64, :96])
        read, refused = 0, 0
        for _ in range(60):
            rows = slice(None, None, int(rng.choice([1, 2, 3, -1, -2])))
            cols = slice(None, None, int(rng.choice([1, 2, -1, 3])))
            depth, normal = base[rows, cols], normals[rows, cols]
            if rng.random() < 0.2:
                depth, normal = depth.T, normal.transpose(1, 0, 2)
            if rng.random() < 0.2:
                normal = np.ascontiguousarray(normal[..., ::-1])[..., ::-1]
            try:
                ao = ssao.ambient_occlusion(depth, normals=normal, camera=self.camera,
                                            radius=0.8)
            except ssao.SSAOError as error:
                self.assertRegex(str(error), "np.ascontiguousarray")
                refused += 1
                continue
            expected = ssao.ambient_occlusion(np.ascontiguousarray(depth),
                                              normals=np.ascontiguousarray(normal),
                                              camera=self.camera, radius=0.8)
            self.assert_same_bits(ao, expected)
            read += 1
        self.assertGreater(read, 10)
        self.assertGreater(refused, 5)

    assert_same_bits = AgainstCli.assert_same_bits

    def test_empty_images(self):
        self.refused(r"depth must have 2 dimensions", np.zeros((0,), np.float32))
        self.refused(r"no geometry pixel", np.zeros((0, 5), np.float32))
        self.refused(r"no geometry pixel", np.zeros((0, 0), np.float32))
        self.refused(r"no geometry pixel", np.zeros((0, 0), np.float32), radius=None)


if __name__ == "__main__":
    if not CLI:
        sys.exit("usage: test_module.py SSAO_CLI [MODULE_FOLDER]")
    unittest.main(verbosity=1)
