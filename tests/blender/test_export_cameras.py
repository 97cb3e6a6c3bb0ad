#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""scripts/blender/export_cameras.py in a real Blender, headless, against values computed here.

    /usr/bin/python3 tests/blender/test_export_cameras.py --blender blender --cli build/bin/ssao \
        [unittest arguments]

The same file, run by Blender (-P ... -- --generate OUT.blend --render-output PATTERN), builds
the scene: its keyframes are LINEAR between the values of ANIM and MARKER below, so that every
exported field of every frame is known here without Blender:

* scene "Shot", frames 1-8, pixel aspect 1.5 x 1.2, World > AO distance 0.7, a floor and a box;
* "AnimCam" (perspective), parented to "Rig" (an empty, turned and moved): location, rotation,
  lens, sensor width, shift_y and clip_end keyframed over frames 1-11, shift_x driven by the
  expression frame / 100;
* "MarkerCam" (orthographic): location keyframed, held by a Limit Location constraint
  (x <= 2), ortho_scale keyframed, sensor fit VERTICAL;
* "PanoCam" (panoramic, which the library does not support);
* timeline markers: frame 1 -> AnimCam, 6 -> MarkerCam, 10 -> PanoCam;
* scene "Other": AnimCam and Rig linked, no markers, no world, pixel aspect 1;
* scene "Empty": no camera, no world.

Frames 1-3 of Shot are also rendered (Cycles, 1 sample, 64x48, Depth pass, multilayer EXR):
the exported cameras must reproduce the rendered depth of the floor (Blender's projection,
written out below), and build/bin/ssao must process the sequence with them.
"""
import argparse
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest
from concurrent.futures import ThreadPoolExecutor

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
EXPORT = os.path.join(HERE, "..", "..", "scripts", "blender", "export_cameras.py")
CONFIG = {}

WIDTH, HEIGHT = 64, 48
PIXEL_ASPECT = (1.5, 1.2)
AO_DISTANCE = 0.7
FRAMES = (1, 8)  # the scene's frame range
KEYS = (1, 11)  # the frames of the first and last keyframes
RIG = {"location": (1.0, -2.0, 0.5), "rotation_z": 10.0}  # degrees
ANIM = {  # AnimCam: (value at KEYS[0], value at KEYS[1]); rotations in degrees, XYZ Euler
    "location": ((0.0, -8.0, 3.0), (2.0, -6.0, 4.0)),
    "rotation": ((45.0, 12.0, -5.0), (55.0, 2.0, 15.0)),
    "lens": (24.0, 54.0),
    "sensor_width": (32.0, 40.0),
    "shift_y": (-0.1, 0.1),
    "clip_end": (80.0, 120.0),
}
ANIM_STATIC = {"sensor_height": 20.0, "sensor_fit": "AUTO", "clip_start": 0.2,
               "ortho_scale": 6.0, "shift_x_per_frame": 0.01}
MARKER = {  # MarkerCam
    "location": ((-4.0, -10.0, 6.0), (6.0, -10.0, 6.0)),
    "max_x": 2.0,  # Limit Location
    "rotation": (60.0, 0.0, 0.0),
    "ortho_scale": (8.0, 13.0),
}
MARKER_STATIC = {"lens": 50.0, "sensor_width": 36.0, "sensor_height": 27.0,
                 "sensor_fit": "VERTICAL", "shift_x": 0.0, "shift_y": 0.0, "clip_start": 0.5,
                 "clip_end": 200.0}
MARKERS = ((1, "AnimCam"), (6, "MarkerCam"), (10, "PanoCam"))
FIELDS = {"type", "lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x", "shift_y",
          "ortho_scale", "clip_start", "clip_end", "matrix_world", "pixel_aspect_x",
          "pixel_aspect_y", "ao_distance"}


# ---------------------------------------------------------------------------
# The scene (run inside Blender)

def generate(out_blend, render_output):
    import bpy

    def linear(id_data):
        """Every keyframe of id_data's action LINEAR (4.4+ keeps F-curves in slots)."""
        anim = id_data.animation_data
        if hasattr(anim.action, "layers"):
            from bpy_extras import anim_utils
            fcurves = anim_utils.action_get_channelbag_for_slot(anim.action,
                                                                anim.action_slot).fcurves
        else:
            fcurves = anim.action.fcurves
        for fcurve in fcurves:
            for key in fcurve.keyframe_points:
                key.interpolation = 'LINEAR'

    def keyframes(id_data, prop, values, convert=lambda v: v):
        for frame, value in zip(KEYS, values):
            setattr(id_data, prop, convert(value))
            id_data.keyframe_insert(prop, frame=frame)

    radians = lambda v: [math.radians(a) for a in v]  # noqa: E731
    scene = bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene.name = "Shot"
    scene.frame_start, scene.frame_end = FRAMES
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = WIDTH, HEIGHT, 100
    r.pixel_aspect_x, r.pixel_aspect_y = PIXEL_ASPECT
    if scene.world is None:
        scene.world = bpy.data.worlds.new("World")
    scene.world.light_settings.distance = AO_DISTANCE

    floor = bpy.data.meshes.new("Floor")
    s = 200.0
    floor.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    scene.collection.objects.link(bpy.data.objects.new("Floor", floor))
    box = bpy.data.meshes.new("Box")
    box.from_pydata([(x, y, z) for z in (0, 1) for y in (-5.5, -4.5) for x in (1, 2)], [],
                    [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2),
                     (1, 3, 7, 5)])
    scene.collection.objects.link(bpy.data.objects.new("Box", box))

    rig = bpy.data.objects.new("Rig", None)
    rig.location = RIG["location"]
    rig.rotation_euler = (0.0, 0.0, math.radians(RIG["rotation_z"]))
    scene.collection.objects.link(rig)

    anim = bpy.data.objects.new("AnimCam", bpy.data.cameras.new("AnimCam"))
    scene.collection.objects.link(anim)
    anim.parent = rig  # matrix_parent_inverse stays the identity
    keyframes(anim, "location", ANIM["location"])
    keyframes(anim, "rotation_euler", ANIM["rotation"], radians)
    linear(anim)
    cam = anim.data
    cam.type = 'PERSP'
    cam.sensor_height = ANIM_STATIC["sensor_height"]
    cam.sensor_fit = ANIM_STATIC["sensor_fit"]
    cam.clip_start = ANIM_STATIC["clip_start"]
    cam.ortho_scale = ANIM_STATIC["ortho_scale"]
    for prop in ("lens", "sensor_width", "shift_y", "clip_end"):
        keyframes(cam, prop, ANIM[prop])
    linear(cam)
    driver = cam.driver_add("shift_x").driver
    driver.type = 'SCRIPTED'
    driver.expression = "frame * %r" % ANIM_STATIC["shift_x_per_frame"]  # a simple expression

    marker = bpy.data.objects.new("MarkerCam", bpy.data.cameras.new("MarkerCam"))
    scene.collection.objects.link(marker)
    keyframes(marker, "location", MARKER["location"])
    linear(marker)
    marker.rotation_euler = radians(MARKER["rotation"])
    limit = marker.constraints.new('LIMIT_LOCATION')
    limit.use_max_x, limit.max_x = True, MARKER["max_x"]
    cam = marker.data
    cam.type = 'ORTHO'
    for prop, value in MARKER_STATIC.items():
        setattr(cam, prop, value)
    keyframes(cam, "ortho_scale", MARKER["ortho_scale"])
    linear(cam)

    pano = bpy.data.objects.new("PanoCam", bpy.data.cameras.new("PanoCam"))
    pano.data.type = 'PANO'
    scene.collection.objects.link(pano)
    for frame, name in MARKERS:
        scene.timeline_markers.new(name, frame=frame).camera = bpy.data.objects[name]
    scene.camera = anim

    # Frames 1-3 as the e2e test renders them: Cycles, 1 sample at the pixel centre, Depth.
    r.engine = 'CYCLES'
    cycles = scene.cycles
    cycles.device = 'CPU'
    cycles.samples = 1
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.filter_width = 0.01
    r.threads_mode, r.threads = 'FIXED', 2
    r.use_compositing = False
    r.use_sequencer = False
    scene.view_layers[0].use_pass_z = True
    img = r.image_settings
    if hasattr(img, "media_type"):  # 5.0+
        img.media_type = 'MULTI_LAYER_IMAGE'
    img.file_format = 'OPEN_EXR_MULTILAYER'
    img.color_depth = '32'
    r.filepath = render_output
    r.use_file_extension = True

    # Another scene with the same camera (linked), pixel aspect 1, no world and no markers: not
    # the file's current scene, so only the evaluated depsgraph has its animated values.
    other = bpy.data.scenes.new("Other")
    for name in ("Rig", "AnimCam"):
        other.collection.objects.link(bpy.data.objects[name])
    other.camera = anim
    bpy.data.scenes.new("Empty")  # no camera, no world
    bpy.ops.wm.save_as_mainfile(filepath=out_blend)
    print("test_export_cameras: saved", out_blend)


# ---------------------------------------------------------------------------
# Expected values, computed here

def lerp(frame, values):
    """LINEAR keyframes at KEYS, constant before and after (Blender's default extrapolation)."""
    t = min(max((frame - KEYS[0]) / (KEYS[1] - KEYS[0]), 0.0), 1.0)
    a, b = np.asarray(values[0], float), np.asarray(values[1], float)
    return a + (b - a) * t


def translation(v):
    m = np.eye(4)
    m[:3, 3] = v
    return m


def rotation_xyz(degrees):
    """Blender's XYZ Euler: X first, then Y, then Z."""
    x, y, z = np.radians(degrees)
    rx = np.array([[1, 0, 0], [0, math.cos(x), -math.sin(x)], [0, math.sin(x), math.cos(x)]])
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rz = np.array([[math.cos(z), -math.sin(z), 0], [math.sin(z), math.cos(z), 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    return m


def expected_anim(frame):
    rig = translation(RIG["location"]) @ rotation_xyz((0.0, 0.0, RIG["rotation_z"]))
    local = translation(lerp(frame, ANIM["location"])) @ rotation_xyz(lerp(frame,
                                                                            ANIM["rotation"]))
    return {
        "type": "PERSP",
        "lens": lerp(frame, ANIM["lens"]),
        "sensor_width": lerp(frame, ANIM["sensor_width"]),
        "sensor_height": ANIM_STATIC["sensor_height"],
        "sensor_fit": ANIM_STATIC["sensor_fit"],
        "shift_x": frame * ANIM_STATIC["shift_x_per_frame"],  # the driver
        "shift_y": lerp(frame, ANIM["shift_y"]),
        "ortho_scale": ANIM_STATIC["ortho_scale"],
        "clip_start": ANIM_STATIC["clip_start"],
        "clip_end": lerp(frame, ANIM["clip_end"]),
        "matrix_world": rig @ local,
        "pixel_aspect_x": PIXEL_ASPECT[0],
        "pixel_aspect_y": PIXEL_ASPECT[1],
        "ao_distance": AO_DISTANCE,
    }


def expected_marker(frame):
    location = lerp(frame, MARKER["location"])
    location[0] = min(location[0], MARKER["max_x"])  # the Limit Location constraint
    return dict(MARKER_STATIC, **{
        "type": "ORTHO",
        "ortho_scale": lerp(frame, MARKER["ortho_scale"]),
        "matrix_world": translation(location) @ rotation_xyz(MARKER["rotation"]),
        "pixel_aspect_x": PIXEL_ASPECT[0],
        "pixel_aspect_y": PIXEL_ASPECT[1],
        "ao_distance": AO_DISTANCE,
    })


def marker_camera(frame):
    """The camera the markers bind at `frame` (frames before the first marker: the first)."""
    name = MARKERS[0][1]
    for marker_frame, marker_name in MARKERS:
        if marker_frame <= frame:
            name = marker_name
    return name


def floor_depth(camera, width, height):
    """(height, width) planar depth of the plane z = 0 seen through `camera` (a camera JSON),
    top row first, by Blender's projection (BKE_camera_params_compute_viewplane): the view
    plane spans the resolution, y scaled by pixel_aspect_y / pixel_aspect_x; the sensor (its
    width, or its height for sensor_fit VERTICAL) spans x (fit HORIZONTAL, or AUTO with the
    wider aspect-corrected side) or y; shifts are in units of that side. inf where the ray
    misses the plane or goes beyond clip_end."""
    ax, ay = camera["pixel_aspect_x"], camera["pixel_aspect_y"]
    ycor = ay / ax
    fit = camera["sensor_fit"]
    if fit == "AUTO":
        fit = "HORIZONTAL" if ax * width >= ay * height else "VERTICAL"
    viewfac = width if fit == "HORIZONTAL" else ycor * height
    sensor = camera["sensor_height"] if camera["sensor_fit"] == "VERTICAL" \
        else camera["sensor_width"]
    assert camera["type"] == "PERSP"
    size = sensor / camera["lens"] / viewfac  # view-plane units per pixel at distance 1
    i = np.arange(width) + 0.5
    j = (np.arange(height) + 0.5)[::-1]  # rows from the top; Blender's y goes up
    x = (-0.5 * width + camera["shift_x"] * viewfac + i) * size
    y = (-0.5 * ycor * height + camera["shift_y"] * viewfac + j * ycor) * size
    xx, yy = np.meshgrid(x, y)
    rays = np.stack([xx, yy, -np.ones_like(xx)], axis=-1)  # camera space, depth 1
    m = np.asarray(camera["matrix_world"], float)
    directions = rays @ m[:3, :3].T
    origin = m[:3, 3]
    with np.errstate(divide="ignore"):
        t = -origin[2] / directions[..., 2]
    return np.where((t > 0) & (t < camera["clip_end"]), t, np.inf)


# ---------------------------------------------------------------------------
# The tests

def blender_command(*args):
    return shlex.split(CONFIG["blender"]) + ["-b", "--factory-startup", "-noaudio"] + \
        [str(a) for a in args]


def run(command, cwd, timeout=120):
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    result.output = result.stdout + result.stderr
    return result


class ExportCamerasTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="ssao_export_cameras_", dir="/tmp")
        cls.blend = os.path.join(cls.root, "shot.blend")
        made = run(blender_command("--python-exit-code", "1", "-P", os.path.abspath(__file__),
                                   "--", "--generate", cls.blend, "--render-output",
                                   os.path.join(cls.root, "render", "render.####")), cls.root)
        assert made.returncode == 0 and os.path.isfile(cls.blend), made.output
        with open(os.path.join(cls.root, "blocker"), "w"):
            pass  # a file where an output folder should be
        # Every Blender run at once: the render, the exports, the errors.
        runs = {
            "render": blender_command(cls.blend, "-s", "1", "-e", "3", "-a"),
            "help": ["--help"],
            # The scene's frames (1-8), its active camera through the markers.
            "default": ["-o", "cams/render.####.camera.json"],
            # --camera over the markers; steps, a list, negative frames, '@', no ao_distance.
            "anim": ["--camera", "AnimCam", "--frames", "-2,1-11x5,3", "-o", "anim/cam.@@.json",
                     "--no-ao-distance", "-q"],
            # One frame: a name without a placeholder, relative to the .blend ('//').
            "single": ["--frames", "4", "-o", "//single/cam.json"],
            # Another scene than the file's current one.
            "printf": ["--scene", "Other", "--frames", "7", "-o", "printf/cam.%03d.json"],
            "no_camera": ["--scene", "Empty", "--frames", "1", "-o", "err/no_camera.json"],
            "not_camera": ["--camera", "Rig", "-o", "err/not_camera.####.json"],
            "no_object": ["--camera", "Nobody", "-o", "err/no_object.####.json"],
            "pano": ["--camera", "PanoCam", "-o", "err/pano.####.json"],
            "pano_marker": ["--frames", "8-10", "-o", "err/pano_marker.####.json"],
            "backwards": ["--frames", "5-1", "-o", "err/backwards.####.json"],
            "negative_backwards": ["--frames=-1--3", "-o", "err/negative_backwards.####.json"],
            "bad_step": ["--frames", "1-5x0", "-o", "err/bad_step.####.json"],
            "no_placeholder": ["--frames", "1-3", "-o", "err/cam.json"],
            "no_placeholder_scene": ["-o", "err/scene.json"],
            "two_placeholders": ["--frames", "1-3", "-o", "err/cam.##.##.json"],
            "unwritable": ["--frames", "1-2", "-o", "blocker/cam.####.json"],
        }
        commands = {name: args if name == "render" else
                    blender_command(cls.blend, "-P", os.path.abspath(EXPORT), "--", *args)
                    for name, args in runs.items()}
        with ThreadPoolExecutor(max_workers=4) as pool:
            futures = {name: pool.submit(run, command, cls.root)
                       for name, command in commands.items()}
            cls.results = {name: future.result() for name, future in futures.items()}

    @classmethod
    def tearDownClass(cls):
        if not os.environ.get("SSAO_KEEP_SCRATCH"):
            shutil.rmtree(cls.root, ignore_errors=True)

    def path(self, *parts):
        return os.path.join(self.root, *parts)

    def succeeded(self, name):
        result = self.results[name]
        self.assertEqual(result.returncode, 0, result.output)
        self.assertNotIn("Traceback", result.output)
        return result.output

    def failed(self, name, status, message):
        result = self.results[name]
        self.assertEqual(result.returncode, status, result.output)
        self.assertIn("export_cameras: error: ", result.stderr)
        self.assertIn(message, result.stderr)
        self.assertNotIn("Traceback", result.output)

    def read(self, *parts):
        with open(self.path(*parts)) as f:
            return json.load(f)

    def assert_camera(self, camera, expected, where):
        self.assertEqual(set(camera), set(expected), where)
        for key, value in expected.items():
            if isinstance(value, str):
                self.assertEqual(camera[key], value, f"{where}: {key}")
            else:
                np.testing.assert_allclose(np.asarray(camera[key], float), value, rtol=1e-5,
                                           atol=2e-6, err_msg=f"{where}: {key}")

    def test_scene_frames_follow_the_markers(self):
        output = self.succeeded("default")
        self.assertEqual(sorted(os.listdir(self.path("cams"))),
                         [f"render.{f:04d}.camera.json" for f in range(FRAMES[0], FRAMES[1] + 1)])
        for frame in range(FRAMES[0], FRAMES[1] + 1):
            camera = self.read("cams", f"render.{frame:04d}.camera.json")
            name = marker_camera(frame)
            expected = expected_anim(frame) if name == "AnimCam" else expected_marker(frame)
            self.assert_camera(camera, expected, f"frame {frame} ({name})")
            self.assertIn(f"export_cameras: frame {frame}: {name} ", output)
        self.assertIn("export_cameras: wrote 8 camera files", output)
        # Both cameras are used, and the constraint holds MarkerCam from frame 7 on.
        self.assertLess(expected_marker(8)["matrix_world"][0, 3],
                        lerp(8, MARKER["location"])[0])

    def test_camera_option_frames_list_negative_frames_and_padding(self):
        output = self.succeeded("anim")
        self.assertNotIn("export_cameras: frame", output)  # -q
        self.assertIn("export_cameras: wrote 5 camera files", output)
        frames = (-2, 1, 6, 11, 3)
        names = {f"cam.{'-' if f < 0 else ''}{abs(f):02d}.json": f for f in frames}
        self.assertEqual(sorted(os.listdir(self.path("anim"))), sorted(names))
        for file_name, frame in names.items():
            expected = expected_anim(frame)
            del expected["ao_distance"]  # --no-ao-distance
            self.assert_camera(self.read("anim", file_name), expected, file_name)

    def test_single_frame_and_printf_pattern(self):
        self.succeeded("single")
        self.assertEqual(os.listdir(self.path("single")), ["cam.json"])
        self.assert_camera(self.read("single", "cam.json"), expected_anim(4), "frame 4")

    def test_another_scene(self):
        output = self.succeeded("printf")
        self.assertIn("no ao_distance (the scene has no world", output)
        self.assertEqual(os.listdir(self.path("printf")), ["cam.007.json"])
        expected = dict(expected_anim(7), pixel_aspect_x=1.0, pixel_aspect_y=1.0)
        del expected["ao_distance"]
        self.assert_camera(self.read("printf", "cam.007.json"), expected, "frame 7")

    def test_help(self):
        output = self.succeeded("help")
        for option in ("--frames", "-o", "--camera", "--scene", "--no-ao-distance"):
            self.assertIn(option, output)

    def test_errors_exit_non_zero_with_a_message_and_write_nothing(self):
        self.failed("no_camera", 1, "scene 'Empty' has no active camera")
        self.failed("not_camera", 1, "'Rig' is not a camera but an object of type EMPTY")
        self.failed("no_object", 1, "no object named 'Nobody'")
        self.failed("pano", 1, "is PANO: only PERSP and ORTHO cameras are supported")
        # Frames 8 and 9 are fine, 10 is PanoCam's: nothing is written.
        self.failed("pano_marker", 1, "camera 'PanoCam' at frame 10 is PANO")
        self.failed("backwards", 2, "'5-1' runs backwards")
        self.failed("negative_backwards", 2, "'-1--3' runs backwards")
        self.failed("bad_step", 2, "the step after 'x' must be a positive number")
        self.failed("no_placeholder", 2, "has no frame placeholder")
        self.failed("no_placeholder_scene", 2, "for the scene's 8 frames 1-8")
        self.failed("two_placeholders", 2, "more than one frame placeholder")
        self.failed("unwritable", 1, "cannot create the folder")
        self.assertFalse(os.path.exists(self.path("err")), os.listdir(self.root))

    def test_rendered_depth_matches_the_exported_cameras_and_the_cli_runs(self):
        sys.path.insert(0, os.path.join(HERE, ".."))
        from image_files import read_image
        self.succeeded("render")
        self.succeeded("default")
        frames = (1, 2, 3)
        for frame in frames:
            names, pixels = read_image(self.path("render", f"render.{frame:04d}.exr"))
            depth_names = [n for n in names if n.endswith("Depth.Z")]
            self.assertEqual(len(depth_names), 1, names)
            depth = pixels[:, :, names.index(depth_names[0])]
            self.assertEqual(depth.shape, (HEIGHT, WIDTH))
            camera = self.read("cams", f"render.{frame:04d}.camera.json")
            floor = floor_depth(camera, WIDTH, HEIGHT)
            self.assertTrue(np.isfinite(floor).all(), f"frame {frame}: the view must be floor")
            # The floor where it is seen; the box only in front of it.
            seen = np.abs(depth - floor) <= 1e-3 * floor
            self.assertGreater(seen.mean(), 0.6, f"frame {frame}")
            self.assertTrue((seen | (depth < floor)).all(), f"frame {frame}")
            self.assertGreater((~seen).sum(), 20, f"frame {frame}: the box is in view")

        cli = CONFIG["cli"]
        for folder in ("ao", "ao_auto", "ao_given"):
            os.makedirs(self.path(folder))
        sequence = [self.path("render", "render.####.exr"), "--camera",
                    self.path("cams", "render.####.camera.json"), "--frames", "1-3", "--ao-only"]
        result = run([cli] + sequence + ["-o", self.path("ao", "ao.####.exr"), "--radius", "0.5"],
                     self.root)
        self.assertEqual(result.returncode, 0, result.output)
        self.assertEqual(sorted(os.listdir(self.path("ao"))),
                         [f"ao.{f:04d}.exr" for f in frames])
        for frame in frames:
            names, ao = read_image(self.path("ao", f"ao.{frame:04d}.exr"))
            self.assertEqual(names, ["AO"])
            self.assertTrue(np.isfinite(ao).all() and ao.min() >= 0 and ao.max() <= 1)
            self.assertLess(ao.min(), 0.9, f"frame {frame}: the box occludes the floor")
        # Without --radius the camera files' ao_distance is the radius: the same frames as with
        # that radius given.
        distance = self.read("cams", "render.0001.camera.json")["ao_distance"]
        for name, extra in (("ao_auto", []), ("ao_given", ["--radius", repr(distance)])):
            result = run([cli] + sequence + ["-o", self.path(name, "ao.####.exr")] + extra,
                         self.root)
            self.assertEqual(result.returncode, 0, result.output)
        for frame in frames:
            auto = read_image(self.path("ao_auto", f"ao.{frame:04d}.exr"))[1]
            given = read_image(self.path("ao_given", f"ao.{frame:04d}.exr"))[1]
            np.testing.assert_array_equal(auto, given)
            other = read_image(self.path("ao", f"ao.{frame:04d}.exr"))[1]
            self.assertFalse(np.array_equal(auto, other), "the radius must matter")


def main():
    if "--generate" in sys.argv:  # inside Blender
        parser = argparse.ArgumentParser()
        parser.add_argument("--generate", required=True)
        parser.add_argument("--render-output", required=True)
        args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:])
        generate(args.generate, args.render_output)
        return
    parser = argparse.ArgumentParser()
    parser.add_argument("--blender", default="blender", help="Blender command (may have args)")
    parser.add_argument("--cli", required=True)
    args, rest = parser.parse_known_args()
    CONFIG.update(vars(args))
    CONFIG["cli"] = os.path.abspath(args.cli)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
