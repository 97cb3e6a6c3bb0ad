#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Tests of the POV-Ray bridge (build/bin/povray-ssao) and of its opt-in include
povray_bridge/pov/ssao_passes.inc, with POV-Ray 3.7 rendering everything in the test.

Run with the system Python (numpy + OpenImageIO bindings):
    /usr/bin/python3 tests/povray/test_povray.py --bridge build/bin/povray-ssao \
        --scratch /tmp/ssao-povray-tests [--povray /usr/bin/povray] [unittest arguments]
The same paths may come from the environment: SSAO_POVRAY_BRIDGE, SSAO_SCRATCH, POVRAY. Set
SSAO_KEEP_SCRATCH=1 to keep each test's folder (scenes, passes, outputs) for inspection.

References are independent of the bridge: analytic ray casting with POV-Ray's camera model
(depth, normals), the closed-form sky visibility of a sphere on a plane, and POV-Ray's own
radiosity render of white clay under a white sky (ssao_passes.inc, SSAOPass=2). Shipped example
scenes come from the povray-examples package (/usr/share/povray-3.7/scenes). Every threshold is
a measurement with headroom; the measured value is written next to it (docs/povray.md has them
all).
"""

import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from image_files import read_image  # noqa: E402
from povray_process import STARTUP_TIMEOUT, run_povray  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "scenes")
POV_INCLUDES = os.path.join(os.path.dirname(os.path.dirname(HERE)), "povray_bridge", "pov")
EXAMPLES = "/usr/share/povray-3.7/scenes"

BRIDGE = os.environ.get("SSAO_POVRAY_BRIDGE", "")
SCRATCH = os.environ.get("SSAO_SCRATCH", "")
POVRAY = os.environ.get("POVRAY", "") or shutil.which("povray") or ""

W, H = 160, 120

# sphere_on_plane.pov: a unit sphere resting on y = 0 at the origin, and its camera.
SOP_CAMERA = dict(location=(2.0, 4.5, -6.0), look_at=(0.0, 0.5, 0.0), angle=55.0)
SOP_SPHERE = ((0.0, 1.0, 0.0), 1.0)

# analytic.pov: a disc of radius 8 on y = 0 and three spheres.
AN_CAMERA = dict(location=(3.0, 2.5, -7.0), look_at=(0.0, 1.0, 2.0), angle=60.0)
AN_SPHERES = [((0.0, 1.0, 0.0), 1.0), ((2.2, 0.8, 1.5), 0.8), ((-3.0, 2.0, 6.0), 2.0)]
AN_DISC_RADIUS = 8.0


# ----------------------------------------------------------------------------------------------
# Images and POV-Ray's camera model

def channel(names, pixels, name):
    assert name in names, f"no channel {name} in {names}"
    return pixels[:, :, names.index(name)]


def camera_rays(location, look_at, angle, width=W, height=H):
    """POV-Ray 3.7's perspective camera { location look_at angle right x*W/H up y } (parse.cpp,
    tracepixel.cpp): the unit ray of every pixel centre (row 0 at the top), the cosine between
    the ray and the view axis, and the camera basis (right, up, forward) as unit vectors."""
    loc = np.asarray(location, float)
    forward = np.asarray(look_at, float) - loc
    forward /= np.linalg.norm(forward)
    right = np.cross([0.0, 1.0, 0.0], forward)  # sky x direction (left-handed)
    right /= np.linalg.norm(right)
    up = np.cross(forward, right)
    right_len = width / height
    dir_len = right_len / (2.0 * math.tan(math.radians(angle) / 2.0))
    j, i = np.mgrid[0:height, 0:width].astype(float)
    x0 = (i + 0.5) / width - 0.5
    y0 = 0.5 - (j + 0.5) / height
    rays = forward * dir_len + x0[..., None] * right * right_len + y0[..., None] * up
    length = np.linalg.norm(rays, axis=-1)
    return loc, rays / length[..., None], dir_len / length, (right, up, forward)


def trace(origin, rays, spheres, disc_radius=None):
    """Nearest hit of every ray with the plane y = 0 (or the disc of that radius at the origin)
    and the spheres. Returns (distance, unit normal facing the ray, object index: -1 sky,
    0 plane, k sphere k, margin): margin is how far (scene units) the pixel's ray is from any
    silhouette or the disc's rim, to leave out pixels whose classification depends on rounding."""
    shape = rays.shape[:2]
    dist = np.full(shape, np.inf)
    normal = np.zeros(shape + (3,))
    obj = np.full(shape, -1)
    margin = np.full(shape, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_plane = -origin[1] / rays[..., 1]
    t_plane[~(t_plane > 0)] = np.inf
    if disc_radius is not None:
        hit = origin + t_plane[..., None] * rays
        rim = np.hypot(hit[..., 0], hit[..., 2])
        rim_distance = np.abs(rim - disc_radius)
        margin = np.where(np.isfinite(t_plane), rim_distance, margin)
        t_plane[~(rim <= disc_radius)] = np.inf
    dist[:] = t_plane
    obj[np.isfinite(t_plane)] = 0
    normal[np.isfinite(t_plane)] = (0.0, 1.0, 0.0)
    for k, (centre, radius) in enumerate(spheres, start=1):
        oc = origin - np.asarray(centre, float)
        b = rays @ oc
        disc = b * b - (oc @ oc - radius * radius)
        closest = np.sqrt(np.maximum(oc @ oc - b * b, 0.0))
        margin = np.minimum(margin, np.abs(closest - radius))
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        hit = (disc > 0) & (t > 0) & (t < dist)
        dist[hit] = t[hit]
        obj[hit] = k
        points = origin + t[..., None] * rays
        normal[hit] = ((points - np.asarray(centre)) / radius)[hit]
    facing_away = np.sum(normal * rays, axis=-1) > 0
    normal[facing_away] *= -1.0
    return dist, normal, obj, margin


def sphere_on_plane_visibility(points, radius=1.0):
    """Cosine-weighted sky visibility of points on the plane y = 0 next to a sphere of `radius`
    resting on it at the origin: V = 1 - r^3 / (rho^2 + r^2)^(3/2)."""
    rho2 = points[..., 0] ** 2 + points[..., 2] ** 2
    return 1.0 - radius ** 3 / (rho2 + radius ** 2) ** 1.5


def intersect(origins, rays, plane=True, spheres=(), boxes=(), t_min=1e-5):
    """Nearest hit distance of rays (any leading shape) with the plane y = 0, spheres
    (centre, radius) and axis-aligned boxes (low corner, high corner); inf for a miss. Also
    returns the unit normal at the hit (not turned towards the ray) and the object index:
    -1 nothing, 0 the plane, then the spheres, then the boxes."""
    shape = rays.shape[:-1]
    origins = np.broadcast_to(origins, rays.shape)
    best = np.full(shape, np.inf)
    normal = np.zeros(rays.shape)
    obj = np.full(shape, -1)
    safe = np.where(np.abs(rays) < 1e-300, 1e-300, rays)
    if plane:
        t = -origins[..., 1] / safe[..., 1]
        hit = (t > t_min) & (t < best)
        best[hit], obj[hit] = t[hit], 0
        normal[hit] = (0.0, 1.0, 0.0)
    for k, (centre, radius) in enumerate(spheres):
        oc = origins - np.asarray(centre, float)
        b = np.sum(rays * oc, axis=-1)
        disc = b * b - (np.sum(oc * oc, axis=-1) - radius * radius)
        root = np.sqrt(np.maximum(disc, 0.0))
        t = np.where(-b - root > t_min, -b - root, -b + root)
        hit = (disc > 0) & (t > t_min) & (t < best)
        best[hit], obj[hit] = t[hit], 1 + k
        normal[hit] = ((origins + t[..., None] * rays - np.asarray(centre)) / radius)[hit]
    for k, (low, high) in enumerate(boxes):
        t1 = (np.asarray(low, float) - origins) / safe
        t2 = (np.asarray(high, float) - origins) / safe
        near, far = np.minimum(t1, t2), np.maximum(t1, t2)
        t_near, t_far = near.max(axis=-1), far.min(axis=-1)
        entering = t_near > t_min
        t = np.where(entering, t_near, t_far)
        hit = (t_near <= t_far) & (t > t_min) & (t < best)
        axis = np.where(entering, near.argmax(axis=-1), far.argmin(axis=-1))
        best[hit], obj[hit] = t[hit], 1 + len(spheres) + k
        n = np.zeros(rays.shape)
        np.put_along_axis(n, axis[..., None], 1.0, axis=-1)
        n *= -np.sign(safe)  # against the ray when entering (the only case the tests see)
        normal[hit] = n[hit]
    return best, normal, obj


def cosine_directions(count):
    """`count` directions spread evenly over the cosine-weighted hemisphere around +z (Fibonacci
    points on the unit disc, lifted: Malley's method)."""
    k = np.arange(count) + 0.5
    r = np.sqrt(k / count)
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - r * r)], axis=-1)


def sky_visibility(points, normals, radius, count=512, chunk=1500, **scene):
    """Cosine-weighted visibility of points (n x 3, with unit normals) in the scene given to
    intersect(): (within `radius`, unbounded), both by `count` rays per point. Cycles' AO with
    distance `radius` and, unbounded, what ssao_passes.inc's pass 2 renders."""
    local = cosine_directions(count)
    limited, unbounded = np.empty(len(points)), np.empty(len(points))
    for s in range(0, len(points), chunk):
        p, n = points[s:s + chunk], normals[s:s + chunk]
        helper = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        t1 = np.cross(n, helper)
        t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
        t2 = np.cross(n, t1)
        rays = (t1[:, None, :] * local[None, :, 0:1] + t2[:, None, :] * local[None, :, 1:2]
                + n[:, None, :] * local[None, :, 2:3])
        dist, _, _ = intersect((p + 1e-5 * n)[:, None, :], rays, **scene)
        limited[s:s + chunk] = 1.0 - np.mean(dist <= radius, axis=-1)
        unbounded[s:s + chunk] = 1.0 - np.mean(np.isfinite(dist), axis=-1)
    return limited, unbounded


def interior(obj):
    """Pixels whose 8 neighbours show the same object: away from silhouettes and creases."""
    same = np.ones(obj.shape, bool)
    padded = np.pad(obj, 1, mode="edge")
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            same &= padded[1 + dy:1 + dy + obj.shape[0], 1 + dx:1 + dx + obj.shape[1]] == obj
    return same


def decode_normals(pixels):
    """ssao_passes.inc's pass 1: n = sin(pi (v - 1/2)) per channel, renormalised."""
    n = np.sin(np.pi * (pixels[..., :3].astype(np.float64) - 0.5))
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def frame_of_pass(pixels, width=W, height=H):
    """The frame of a data pass povray-ssao kept (--keep): depth and normals are rendered with a
    guard band of G pixels on every side (--overscan), the frame in the middle."""
    band_x, band_y = pixels.shape[1] - width, pixels.shape[0] - height
    assert band_x == band_y and band_x >= 0 and band_x % 2 == 0, pixels.shape
    band = band_x // 2
    return pixels[band:band + height, band:band + width]


def angle_degrees(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


# ----------------------------------------------------------------------------------------------

class PovTestCase(unittest.TestCase):
    """A fresh folder per test; helpers to run POV-Ray and the bridge."""

    def setUp(self):
        os.makedirs(SCRATCH, exist_ok=True)
        self.dir = tempfile.mkdtemp(prefix=self.id().split(".")[-1] + "-", dir=SCRATCH)

    def tearDown(self):
        if not os.environ.get("SSAO_KEEP_SCRATCH"):
            shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, *names):
        return os.path.join(self.dir, *names)

    def copy_scene(self, name, text=None):
        """Copies tests/povray/scenes/NAME (or writes `text` under NAME) into the test folder."""
        target = self.path(name)
        if text is None:
            shutil.copy(os.path.join(SCENES, name), target)
        else:
            with open(target, "w") as f:
                f.write(text)
        return target

    def copy_example(self, relative, extra=()):
        """Copies a povray-examples scene (and local includes next to it) into the test folder."""
        source = os.path.join(EXAMPLES, relative)
        if not os.path.isfile(source):
            self.skipTest(f"{source} missing (Debian package povray-examples)")
        shutil.copy(source, self.dir)
        for name in extra:
            shutil.copy(os.path.join(os.path.dirname(source), name), self.dir)
        return self.path(os.path.basename(relative))

    def povray(self, scene, output, *options, timeout=300):
        """Renders with POV-Ray directly (not through the bridge); returns the output path."""
        cmd = [POVRAY, "+I" + scene, "+O" + output, f"+W{W}", f"+H{H}", "-D", "-P", "-V",
               "+L" + POV_INCLUDES, "+L" + os.path.dirname(scene)] + list(options)
        proc = run_povray(cmd, timeout=timeout, cwd=os.path.dirname(scene))
        self.assertEqual(proc.returncode, 0, " ".join(cmd) + "\n" + proc.stderr[-3000:])
        self.assertTrue(os.path.isfile(output), output)
        return output

    def run_bridge(self, *args, timeout=300):
        cmd = [BRIDGE] + [str(a) for a in args]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=self.dir)
        self.last_command = " ".join(cmd)
        return proc

    def detail(self, proc):
        return (f"{self.last_command}\nexit {proc.returncode}\nstdout: {proc.stdout[-3000:]}\n"
                f"stderr: {proc.stderr[-3000:]}")

    def assert_ok(self, proc, *outputs):
        self.assertEqual(proc.returncode, 0, self.detail(proc))
        for output in outputs:
            self.assertTrue(os.path.isfile(output), f"{output} missing\n{self.detail(proc)}")

    def assert_fails(self, proc, *phrases, outputs=(), code=1):
        """Exit status `code` (1: failure), an error message holding every phrase, no output
        file and no temporary file left next to the outputs."""
        detail = self.detail(proc)
        self.assertEqual(proc.returncode, code, detail)
        text = (proc.stderr + proc.stdout).lower()
        self.assertIn("error", text, detail)
        for phrase in phrases:
            self.assertIn(phrase.lower(), text, detail)
        for output in outputs:
            self.assertFalse(os.path.exists(output), f"{output} exists after a failure\n{detail}")
            folder = os.path.dirname(output)
            base = os.path.basename(output)
            leftovers = [f for f in os.listdir(folder) if f != base and f.startswith(base)]
            self.assertEqual(leftovers, [], f"temporary files left behind\n{detail}")

    def bridge_exr(self, scene, *args, name="out", size=(W, H)):
        """Runs the bridge with --exr and --keep; returns (proc, names, pixels, keep folder)."""
        png, exr = self.path(name + ".png"), self.path(name + ".exr")
        keep = self.path(name + "-keep")
        proc = self.run_bridge(scene, "-o", png, "--exr", exr, "--keep", keep, f"+W{size[0]}",
                               f"+H{size[1]}", *args)
        self.assert_ok(proc, png, exr)
        names, pixels = read_image(exr)
        self.assertEqual(pixels.shape[:2], (size[1], size[0]))
        return proc, names, pixels, keep


# ----------------------------------------------------------------------------------------------

class IncludeTest(PovTestCase):
    """ssao_passes.inc with POV-Ray alone."""

    def test_normal_pass_is_exact(self):
        scene = self.copy_scene("sphere_on_plane.pov")
        exr = self.povray(scene, self.path("normals.exr"), "Declare=SSAOPass=1", "+Q6", "-A", "+FE")
        _, pixels = read_image(exr)
        origin, rays, _, (right, up, forward) = camera_rays(**SOP_CAMERA)
        dist, normal_world, obj, margin = trace(origin, rays, [SOP_SPHERE])
        truth = np.stack([normal_world @ right, normal_world @ up, normal_world @ forward], -1)
        decoded = decode_normals(pixels)
        raw_length = np.linalg.norm(np.sin(np.pi * (pixels[..., :3] - 0.5)), axis=-1)
        inside = margin > 0.01  # not on the sphere's silhouette
        for k, what in [(0, "plane"), (1, "sphere")]:
            mask = inside & (obj == k)
            self.assertGreater(int(mask.sum()), 1000, what)
            error = angle_degrees(decoded[mask], truth[mask])
            # Measured: plane 0.000 deg, sphere max 0.056 mean 0.020 deg (half-float steps).
            self.assertLess(float(error.max()), 0.1, what)
            self.assertLess(float(error.mean()), 0.04, what)
            # The undecoded length is within half-float rounding of 1 (measured 6.7e-4).
            self.assertLess(float(np.abs(raw_length[mask] - 1.0).max()), 2e-3, what)
        # Camera space faces the camera: n_z < 0 everywhere on geometry.
        self.assertTrue(np.all(decoded[inside & (obj >= 0)][:, 2] < 0))

    def test_normals_face_the_camera_from_below(self):
        # The plane seen from below: the geometric normal +y faces away from the camera and the
        # pass must give -y (in camera space: pointing down and towards the camera).
        scene = self.copy_scene("below.pov", """#version 3.7;
#include "ssao_passes.inc"
SSAOCamera(<0, -2, -6>, <0, 0, 3>, 50)
plane { y, 0 SSAOTexture(texture { pigment { rgb 1 } }) }
""")
        _, pixels = read_image(self.povray(scene, self.path("n.exr"), "Declare=SSAOPass=1",
                                           "+Q6", "-A", "+FE"))
        origin, rays, _, (right, up, forward) = camera_rays((0, -2, -6), (0, 0, 3), 50)
        dist, normal_world, obj, _ = trace(origin, rays, [])
        truth = np.stack([normal_world @ right, normal_world @ up, normal_world @ forward], -1)
        mask = obj == 0
        self.assertGreater(int(mask.sum()), 1000)
        self.assertLess(float(angle_degrees(decode_normals(pixels)[mask], truth[mask]).max()), 0.1)
        self.assertTrue(np.all(truth[mask][:, 1] < 0))  # the test itself: -y in camera space

    def test_basis_from_the_command_line(self):
        # Declare=SSAOBasis...=v (nine floats) gives the basis when the scene declares none,
        # and takes precedence over the scene's SSAOCameraBasis.
        with open(os.path.join(SCENES, "sphere_on_plane.pov")) as f:
            text = f.read()
        without = self.copy_scene("nobasis.pov", text.replace(
            "SSAOCameraBasis(CamLocation, CamLookAt)", ""))
        wrong = self.copy_scene("wrongbasis.pov", text.replace(
            "SSAOCameraBasis(CamLocation, CamLookAt)", "SSAOCameraBasis(<0, 9, -1>, 0)"))
        origin, rays, _, basis = camera_rays(**SOP_CAMERA)
        declares = [f"Declare=SSAOBasis{name}{axis}={value:.17g}"
                    for name, vector in zip(["Right", "Up", "Forward"], basis)
                    for axis, value in zip("XYZ", vector)]
        dist, normal_world, obj, margin = trace(origin, rays, [SOP_SPHERE])
        truth = np.stack([normal_world @ b for b in basis], -1)
        inside = margin > 0.01
        for scene in (without, wrong):
            _, pixels = read_image(self.povray(scene, self.path("n.exr"), "Declare=SSAOPass=1",
                                               "+Q6", "-A", "+FE", *declares))
            error = angle_degrees(decode_normals(pixels)[inside], truth[inside])
            self.assertLess(float(error.max()), 0.1, scene)

    def test_camera_macro_matches_a_camera_block(self):
        # SSAOCamera(...) must give the same image as the equivalent camera block (which
        # sphere_on_plane.pov has) in the beauty pass and in the normal pass.
        block = self.copy_scene("sphere_on_plane.pov")
        with open(block) as f:
            text = f.read()
        start, end = text.index("camera {"), text.index("SSAOCameraBasis(CamLocation, CamLookAt)")
        macro = self.copy_scene("macro.pov", text[:start] + "SSAOCamera(CamLocation, CamLookAt, 55)"
                                + text[end + len("SSAOCameraBasis(CamLocation, CamLookAt)"):])
        for options in [("+FE", "-A"), ("Declare=SSAOPass=1", "+Q6", "-A", "+FE")]:
            _, a = read_image(self.povray(block, self.path("block.exr"), *options))
            _, b = read_image(self.povray(macro, self.path("macro.exr"), *options))
            np.testing.assert_array_equal(a, b, err_msg=str(options))

    def test_beauty_pass_keeps_the_scene(self):
        # SSAOPass undefined: the scene's own textures and lights (an orange lit sphere, a
        # checker floor, a blue sky), not the emissive normal code or the clay.
        scene = self.copy_scene("sphere_on_plane.pov")
        _, pixels = read_image(self.povray(scene, self.path("beauty.exr"), "+FE", "-A"))
        origin, rays, _, _ = camera_rays(**SOP_CAMERA)
        _, _, obj, margin = trace(origin, rays, [SOP_SPHERE])
        sphere = pixels[(obj == 1) & (margin > 0.05)].mean(axis=0)
        self.assertGreater(sphere[0], 1.3 * sphere[2])  # orange: red well above blue
        floor = pixels[(obj == 0) & (margin > 0.05), 0]
        self.assertGreater(float(np.percentile(floor, 90) - np.percentile(floor, 10)), 0.1)

    def test_ao_reference_matches_closed_form(self):
        # Pass 2 (white clay, white sky, radiosity, one thread for a deterministic result)
        # against V = 1 - r^3/(rho^2+r^2)^(3/2) on the plane.
        scene = self.copy_scene("sphere_on_plane.pov")
        _, pixels = read_image(self.povray(scene, self.path("ref.exr"), "Declare=SSAOPass=2",
                                           "-A", "+FE", "+WT1"))
        stats = self.reference_error(pixels)
        # Measured (160x120, count 800, error 0.05): rho < 1.2: rms 0.007 max 0.025;
        # 1.2..2: rms 0.003; 2..4: rms 0.0012; beyond 4: rms 0.0007.
        limits = {(0.0, 1.2): (0.015, 0.06), (1.2, 2.0): (0.008, 0.03), (2.0, 4.0): (0.003, 0.012),
                  (4.0, 99.0): (0.002, 0.008)}
        for band, (rms_limit, max_limit) in limits.items():
            rms, worst, count = stats[band]
            self.assertGreater(count, 300, band)
            self.assertLess(rms, rms_limit, band)
            self.assertLess(worst, max_limit, band)

    @staticmethod
    def reference_error(pixels):
        """{(rho_lo, rho_hi): (rms, max abs error, pixels)} of a pass-2 render of
        sphere_on_plane.pov against the closed form, plane pixels only."""
        origin, rays, _, _ = camera_rays(**SOP_CAMERA)
        dist, _, obj, margin = trace(origin, rays, [SOP_SPHERE])
        points = origin + np.where(np.isfinite(dist), dist, 0.0)[..., None] * rays
        rho = np.hypot(points[..., 0], points[..., 2])
        error = pixels[..., 0] - sphere_on_plane_visibility(points)
        plane = (obj == 0) & (margin > 0.02)
        stats = {}
        for band in [(0.0, 1.2), (1.2, 2.0), (2.0, 4.0), (4.0, 99.0)]:
            m = plane & (rho >= band[0]) & (rho < band[1])
            e = error[m]
            stats[band] = (float(np.sqrt(np.mean(e ** 2))), float(np.abs(e).max()), int(m.sum()))
        return stats

    def test_bad_pass_and_missing_camera_basis(self):
        scene = self.copy_scene("sphere_on_plane.pov")
        cmd = [POVRAY, "+I" + scene, "+O" + self.path("x.exr"), "+W8", "+H6", "-D", "+FE",
               "+L" + POV_INCLUDES, "Declare=SSAOPass=3"]
        proc = run_povray(cmd, timeout=60)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("SSAOPass must be 0, 1 or 2", proc.stderr)
        nobasis = self.copy_scene("nobasis.pov", """#version 3.7;
#include "ssao_passes.inc"
camera { location <0, 1, -5> look_at 0 }
sphere { 0, 1 SSAOTexture(texture { pigment { rgb 1 } }) }
""")
        cmd = [POVRAY, "+I" + nobasis, "+O" + self.path("y.exr"), "+W8", "+H6", "-D", "+FE",
               "+L" + POV_INCLUDES, "Declare=SSAOPass=1"]
        proc = run_povray(cmd, timeout=60)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("SSAOCamera", proc.stderr)
        # ... while the beauty pass of the same scene needs no camera basis.
        self.povray(nobasis, self.path("z.png"))


# ----------------------------------------------------------------------------------------------

class DepthTest(PovTestCase):
    """--depth-only against analytic distances (half-float EXR limits)."""

    def check_depth(self, exr):
        names, pixels = read_image(exr)
        self.assertEqual(sorted(names), ["Radial", "Z"])
        self.assertEqual(pixels.shape[:2], (H, W))
        radial, planar = channel(names, pixels, "Radial"), channel(names, pixels, "Z")
        origin, rays, cosine, _ = camera_rays(**AN_CAMERA)
        dist, _, obj, margin = trace(origin, rays, AN_SPHERES, disc_radius=AN_DISC_RADIUS)
        clear = margin > 0.03  # rays not grazing a silhouette or the disc's rim
        sky = clear & ~np.isfinite(dist)
        geometry = clear & np.isfinite(dist)
        self.assertGreater(int(sky.sum()), 1000)
        self.assertTrue(np.all(np.isposinf(radial[sky])), "sky must be +inf in Radial")
        self.assertTrue(np.all(np.isposinf(planar[sky])), "sky must be +inf in Z")
        self.assertTrue(np.all(np.isfinite(radial[geometry])), "geometry with infinite depth")
        errors = {}
        for name, values, truth in [("Radial", radial, dist), ("Z", planar, dist * cosine)]:
            rel = np.abs(values[geometry] / truth[geometry] - 1.0)
            errors[name] = float(rel.max())
            # Measured mean 2.3e-4 (160x120 and 640x480).
            self.assertLess(float(rel.mean()), 3.5e-4, name)
            for k in range(0, 4):  # every object, the glass sphere included (its front face)
                m = (obj[geometry] == k)
                self.assertGreater(int(m.sum()), 100, f"object {k}")
        return errors, dist, geometry

    def test_depth_matches_analytic_distances(self):
        scene = self.copy_scene("analytic.pov")
        out = self.path("depth.exr")
        proc = self.run_bridge(scene, "--depth-only", "-o", out, f"+W{W}", f"+H{H}")
        self.assert_ok(proc, out)
        errors, dist, geometry = self.check_depth(out)
        # Measured max 5.7e-4 at 160x120 (6.0e-4 at 640x480), both channels: half floats step
        # by 2^-11 = 4.9e-4 relative.
        for name, error in errors.items():
            self.assertLess(error, MAX_DEPTH_REL_ERROR, f"{name}: max relative error {error:.2e}")

    def test_size_spellings(self):
        # -W/-H and --width/--height give the same image size as +W/+H.
        scene = self.copy_scene("analytic.pov")
        for size_args in (["-W80", "-H60"], ["--width", "80", "--height", "60"]):
            out = self.path("d.exr")
            proc = self.run_bridge(scene, "--depth-only", "-o", out, *size_args)
            self.assert_ok(proc, out)
            self.assertEqual(read_image(out)[1].shape[:2], (60, 80), size_args)
            os.remove(out)


MAX_DEPTH_REL_ERROR = 1e-3


# ----------------------------------------------------------------------------------------------

class ExampleScenesTest(PovTestCase):
    """End to end on scenes shipped with POV-Ray (povray-examples): image maps, wood and
    marble textures, glass, mirrors, focal blur, radiosity, a mirrored camera, a local
    include."""

    def run_example(self, relative, extra=(), size=(W, H), args=()):
        """Runs the bridge on a copy of the example; checks what holds for any scene and returns
        (AO, Z, beauty, proc)."""
        scene = self.copy_example(relative, extra)
        proc, names, pixels, keep = self.bridge_exr(scene, "--apply-to", "beauty", *args,
                                                    size=size)
        for name in ["R", "G", "B", "A", "AO", "Z", "Radial"]:
            self.assertIn(name, names)
        ao = channel(names, pixels, "AO")
        z = channel(names, pixels, "Z")
        self.assertTrue(np.all(np.isfinite(ao)))
        self.assertGreaterEqual(float(ao.min()), 0.0)
        self.assertLessEqual(float(ao.max()), 1.0)
        geometry = np.isfinite(z)
        self.assertGreater(int(geometry.sum()), 0)
        self.assertTrue(np.all(z[geometry] > 0))
        self.assertLess(float(ao[geometry].mean()), 0.99, "no occlusion at all")
        self.assertGreater(float(ao[geometry].mean()), 0.8, "implausibly dark")
        # Background: AO exactly 1.
        np.testing.assert_array_equal(ao[~geometry], 1.0)
        beauty = self.kept_beauty(keep)
        self.assertEqual(beauty.shape[:2], ao.shape)
        rgb = np.stack([channel(names, pixels, c) for c in "RGB"], -1)
        # The output is the beauty times AO: never brighter, unchanged where AO = 1 (the
        # background among them).
        self.assertTrue(np.all(rgb <= beauty[..., :3] * (1 + 1e-6) + 1e-6),
                        "output brighter than the beauty")
        np.testing.assert_allclose(rgb, beauty[..., :3] * ao[..., None], rtol=1e-5, atol=1e-6)
        open_sky = ~geometry
        np.testing.assert_array_equal(rgb[open_sky], beauty[..., :3][open_sky])
        return ao, z, beauty, proc

    def kept_beauty(self, keep):
        """The beauty render the bridge kept in --keep DIR (beauty.exr, linear)."""
        path = os.path.join(keep, "beauty.exr")
        self.assertTrue(os.path.isfile(path), f"no beauty.exr in {keep}: {os.listdir(keep)}")
        return read_image(path)[1]

    @staticmethod
    def region(values, box):
        """Mean of values over the pixel box (x0, x1, y0, y1): [x0, x1) x [y0, y1)."""
        x0, x1, y0, y1 = box
        return float(values[y0:y1, x0:x1].mean())

    def assert_contact_darker(self, ao, contact, open_area, margin=0.15):
        dark, light = self.region(ao, contact), self.region(ao, open_area)
        self.assertGreater(light, 0.97, f"open area {open_area}")
        self.assertLess(dark, light - margin, f"contact {contact}: {dark:.3f}, open {light:.3f}")

    def test_woodbox(self):
        ao, z, _, _ = self.run_example("advanced/woodbox.pov")
        # Under the copper ball in front of the box (measured 0.62) vs the open floor (1.00).
        self.assert_contact_darker(ao, (55, 70, 98, 106), (120, 155, 100, 118))

    def test_chess2_focal_blur(self):
        ao, z, beauty, proc = self.run_example("advanced/chess2.pov")
        self.assertIn("focal blur", proc.stdout + proc.stderr)
        # The board around the bases of the front pawns (measured 0.70) vs the empty squares at
        # the right (1.00).
        self.assert_contact_darker(ao, (35, 60, 99, 103), (120, 160, 70, 85))
        # The green backdrop above the pieces, far behind the board (depth 2000 to 10000): no
        # occlusion.
        np.testing.assert_array_equal(ao[0:12, :], 1.0)

    def test_cornell_radiosity_mirrored_camera(self):
        # The scene's camera has right <-1,0,0> and |right|/|up| = 1: render it square.
        ao, z, _, _ = self.run_example("radiosity/cornell.pov", size=(120, 120))
        # The floor at the short box's base (measured 0.66) vs the open floor in front (1.00).
        self.assert_contact_darker(ao, (65, 90, 109, 113), (25, 50, 108, 118))

    def test_glasschess_local_include(self):
        # Glass pieces on a mirror floor; chesspiece1.inc lies next to the scene.
        ao, z, _, _ = self.run_example("advanced/glasschess/glasschess.pov", ("chesspiece1.inc",),
                                       args=("--radius", "0.5"))
        # Its "sky" is hollow cloud spheres of radius 4000-5000: read as surfaces ~3500 away,
        # far beyond any radius, so they get no occlusion.
        far = ~np.isfinite(z) | (z > 1000)
        self.assertGreater(int(far.sum()), 200, "glasschess shows its sky")
        # Away from the pieces' silhouettes: there the pixel filter mixes both surfaces' AO, as
        # an anti-aliased render does.
        padded = np.pad(far, 1, constant_values=True)
        clear = np.ones_like(far)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                clear &= padded[1 + dy:1 + dy + far.shape[0], 1 + dx:1 + dx + far.shape[1]]
        self.assertGreater(int(clear.sum()), 200, "glasschess shows its sky away from the pieces")
        np.testing.assert_array_equal(ao[clear], 1.0)
        # The floor at the base of the front piece (measured 0.60) vs open floor (1.00).
        self.assert_contact_darker(ao, (75, 95, 110, 120), (110, 150, 100, 120))


# ----------------------------------------------------------------------------------------------

class AOAccuracyTest(PovTestCase):
    """The bridge's AO against POV-Ray's own radiosity AO (ssao_passes.inc pass 2) and the
    same scene's visibility integrated by ray casting in the test.

    The POV-Ray reference is unbounded-distance AO while --radius R limits the distance, as
    Cycles' AO does. So: (1) the reference is checked against the unbounded visibility cast in
    the test (and the closed form on the plane), which validates both; (2) the bridge's AO is
    compared with the POV-Ray reference only where the unbounded and the R-limited visibility
    differ by less than 0.02; (3) everywhere, it is compared with the R-limited visibility."""

    def reference(self, scene):
        _, pixels = read_image(self.povray(scene, self.path("reference.exr"), "Declare=SSAOPass=2",
                                           "-A", "+FE", "+WT1"))
        return pixels[..., 0].astype(np.float64)

    def compare(self, scene_file, camera, radius, geometry):
        """Returns {name: rms} for the checks above, per object kind."""
        scene = self.copy_scene(scene_file)
        reference = self.reference(scene)
        proc, names, pixels, _ = self.bridge_exr(scene, "--radius", radius)
        self.assertIn("normals from the normal pass", proc.stdout + proc.stderr, self.detail(proc))
        ao = channel(names, pixels, "AO").astype(np.float64)
        origin, rays, _, _ = camera_rays(**camera)
        dist, normal, obj = intersect(origin, rays, **geometry)
        normal[np.sum(normal * rays, axis=-1) > 0] *= -1.0
        mask = interior(obj) & np.isfinite(dist)
        points = (origin + dist[..., None] * rays)[mask]
        limited, unbounded = sky_visibility(points, normal[mask], radius, **geometry)
        kinds = obj[mask]
        comparable = np.abs(limited - unbounded) < 0.02
        result = {}

        def rms(a, b, m):
            return float(np.sqrt(np.mean((a[m] - b[m]) ** 2))) if m.any() else 0.0
        for kind in np.unique(kinds):
            m = kinds == kind
            result[("reference", kind)] = rms(reference[mask], unbounded, m)
            result[("ao-vs-reference", kind)] = rms(ao[mask], reference[mask], m & comparable)
            result[("ao-vs-limited", kind)] = rms(ao[mask], limited, m)
            result[("comparable pixels", kind)] = int((m & comparable).sum())
        result["all"] = rms(ao[mask], limited, np.ones(len(limited), bool))
        lines = [f"{scene_file}, radius {radius}, RMS per object (0 = floor): "
                 f"all {result['all']:.4f}"]
        for kind in np.unique(kinds):
            lines.append(f"  object {kind}: reference vs cast unbounded "
                         f"{result[('reference', kind)]:.4f}, AO vs reference "
                         f"{result[('ao-vs-reference', kind)]:.4f} on "
                         f"{result[('comparable pixels', kind)]} pixels, AO vs cast limited "
                         f"{result[('ao-vs-limited', kind)]:.4f}")
        print("\n" + "\n".join(lines), file=sys.stderr)
        result["masks"] = (mask, points, reference)
        return result

    def test_sphere_on_plane(self):
        geometry = dict(plane=True, spheres=[SOP_SPHERE])
        r = self.compare("sphere_on_plane.pov", SOP_CAMERA, 2.0, geometry)
        mask, points, reference = r.pop("masks")
        # (1) The reference against the closed form on the plane and the cast visibility.
        # Measured: plane 0.0026, sphere 0.0055 (radiosity count 800, error_bound 0.05).
        closed = sphere_on_plane_visibility(points)
        plane = points[:, 1] < 1e-6
        self.assertLess(float(np.sqrt(np.mean((reference[mask][plane] - closed[plane]) ** 2))),
                        0.006)
        self.assertLess(r[("reference", 0)], 0.006)
        self.assertLess(r[("reference", 1)], 0.012)
        # (2) Where limited and unbounded agree (the plane: 13000 pixels; the sphere's top).
        # Measured at radius 2: plane 0.015 (exact normals), sphere 0.011 (38 pixels).
        self.assertGreater(r[("comparable pixels", 0)], 10000)
        self.assertLess(r[("ao-vs-reference", 0)], 0.03)
        # (3) Against the radius-limited visibility everywhere. Measured: plane 0.011, sphere
        # 0.011 (0.020 to 0.024 with normals reconstructed from depth).
        self.assertLess(r[("ao-vs-limited", 0)], 0.025)
        self.assertLess(r[("ao-vs-limited", 1)], 0.03)

    def test_box_in_a_corner(self):
        geometry = dict(plane=True, spheres=[BC_SPHERE], boxes=BC_BOXES)
        r = self.compare("box_corner.pov", BC_CAMERA, BC_RADIUS, geometry)
        r.pop("masks")
        # (1) Measured: 0.0023 to 0.0057 on every object (floor, ball, walls, box).
        for kind in (0, 1, 2, 3, 4):
            self.assertLess(r[("reference", kind)], 0.012, kind)
        # (2) Only floor pixels far enough from the walls compare (1537); measured 0.0072 with
        # the default guard band (0.022 with --overscan 0: the walls run out of the frame).
        self.assertGreater(r[("comparable pixels", 0)], 1000)
        self.assertLess(r[("ao-vs-reference", 0)], 0.035)
        # (3) Measured at radius 1.5 with the default guard band: all 0.033; floor 0.020, ball
        # 0.014, left wall 0.014, back wall 0.058 (the crease behind the ball is hidden from the
        # camera: a screen-space limit), box 0.027. With --overscan 0: all 0.036, floor 0.027.
        self.assertLess(r["all"], 0.055)
        self.assertLess(r[("ao-vs-limited", 0)], 0.04)
        self.assertLess(r[("ao-vs-limited", 1)], 0.025)
        self.assertLess(r[("ao-vs-limited", 2)], 0.03)
        self.assertLess(r[("ao-vs-limited", 3)], 0.09)
        self.assertLess(r[("ao-vs-limited", 4)], 0.05)


# box_corner.pov: floor, two walls, a box in the corner, a ball; its SSAOCamera.
BC_CAMERA = dict(location=(3.2, 3.6, -5.5), look_at=(-0.6, 0.7, 1.0), angle=55.0)
BC_SPHERE = ((0.9, 0.6, 0.3), 0.6)
BC_BOXES = [((-3.2, 0.0, -2.0), (-3.0, 3.0, 3.2)), ((-3.2, 0.0, 3.0), (3.0, 3.0, 3.2)),
            ((-3.0, 0.0, 1.8), (-1.8, 1.2, 3.0))]
BC_RADIUS = 1.5


# ----------------------------------------------------------------------------------------------

# edge_occluders.pov: a floor, three boxes just outside the frame at 160x120 (below the bottom
# edge, left and right of the side edges) and one box inside it; its SSAOCamera.
EO_CAMERA = dict(location=(0.0, 4.0, -6.0), look_at=(0.0, 0.0, 0.0), angle=60.0)
EO_BOXES = [((-1.5, 0.0, -4.4), (1.5, 0.25, -3.62)), ((-5.8, 0.0, -2.0), (-4.75, 1.5, 0.0)),
            ((4.75, 0.0, -2.0), (5.8, 1.5, 0.0)), ((-0.6, 0.0, 1.0), (0.6, 1.0, 2.0))]
EO_RADIUS = 1.0
DEFAULT_BAND = 16  # povray-ssao's default guard band at 160x120: 10% of the larger side


def parse_camera_blocks(text):
    """The camera { } blocks --print-camera prints: [{location, direction, right, up}]."""
    blocks = []
    for body in re.findall(r"camera \{(.*?)\}", text, re.S):
        block = {}
        for key in ("location", "direction", "right", "up"):
            found = re.search(key + r" <([^>]*)>", body)
            block[key] = np.array([float(v) for v in found.group(1).split(",")])
        blocks.append(block)
    return blocks


def block_rays(block, width, height):
    """Unit rays of every pixel of a camera { } block: POV-Ray's D + x0 R + y0 U."""
    j, i = np.mgrid[0:height, 0:width].astype(float)
    x0 = (i + 0.5) / width - 0.5
    y0 = 0.5 - (j + 0.5) / height
    rays = block["direction"] + x0[..., None] * block["right"] + y0[..., None] * block["up"]
    return rays / np.linalg.norm(rays, axis=-1, keepdims=True)


class GuardBandTest(PovTestCase):
    """--overscan G (default 10% of the larger side): the depth and normal passes are rendered
    G pixels larger on every side on the same pixel grid, and libssao computes the frame's AO
    from all of them (its output window). The outputs keep the frame's size."""

    def test_camera_is_widened_on_the_same_pixel_grid(self):
        # The depth passes' camera block: right x (W + 2G) / W, up x (H + 2G) / H; its inner
        # W x H rays are the frame's (POV-Ray's camera model, evaluated here in double).
        scene = self.copy_scene("edge_occluders.pov")
        proc = self.run_bridge(scene, "-o", self.path("x.png"), f"+W{W}", f"+H{H}",
                               "--print-camera")
        self.assert_ok(proc)
        self.assertIn(f"{W + 2 * DEFAULT_BAND}x{H + 2 * DEFAULT_BAND} with a {DEFAULT_BAND}-pixel "
                      "guard band", proc.stdout, self.detail(proc))
        frame, wide = parse_camera_blocks(proc.stdout)
        band = DEFAULT_BAND
        inner = block_rays(wide, W + 2 * band, H + 2 * band)[band:band + H, band:band + W]
        # Measured 2e-16: the same rays up to double rounding.
        self.assertLess(float(np.abs(inner - block_rays(frame, W, H)).max()), 1e-12)
        # And the frame's rays are the scene camera's (the test's own model of SSAOCamera).
        _, rays, _, _ = camera_rays(**EO_CAMERA)
        self.assertLess(float(np.abs(block_rays(frame, W, H) - rays).max()), 1e-9)
        # --overscan 0: one camera for every pass.
        proc = self.run_bridge(scene, "-o", self.path("x.png"), f"+W{W}", f"+H{H}",
                               "--print-camera", "--overscan", "0")
        self.assert_ok(proc)
        self.assertEqual(len(parse_camera_blocks(proc.stdout)), 1, self.detail(proc))
        self.assertIn("every pass is rendered with", proc.stdout)

    def test_print_camera_shows_the_intrinsics_the_library_uses(self):
        # A 60-degree camera at 640x480 (issue 35: the line showed the library's unset default,
        # a 50 mm lens): fx = 320 / tan(30 deg) = 554.256 pixels, centre (320, 240), which is a
        # 31.18 mm lens on a 36 mm sensor; fy = 554.256 x 1.33 / (4 / 3) = 552.871, POV-Ray's
        # default right being 1.33 x, not 4/3. An orthographic camera 4 units wide: fx = 160
        # pixels per unit.
        for camera, expected in (("angle 60", "fx 554.256258 fy 552.870618 cx 320 cy 240 "
                                               "pixels: a 31.18 mm lens"),
                                 ("orthographic right x*4 up y*3",
                                  "fx 160 fy 160 cx 320 cy 240 pixels per unit: 4 units")):
            scene = self.copy_scene("camera.pov", "camera { %s location <0,1,-3> "
                                    "look_at <0,0,0> }\n"
                                    "sphere { 0, 1 pigment { rgb 1 } }\n" % camera)
            proc = self.run_bridge(scene, "-o", self.path("x.png"), "+W640", "+H480",
                                   "--print-camera")
            self.assert_ok(proc)
            line = next(l for l in proc.stdout.splitlines() if l.startswith("libssao (640x480)"))
            self.assertIn("projection intrinsics", line, self.detail(proc))
            self.assertIn(expected, line, self.detail(proc))

    def test_band_equals_a_larger_frame_cropped(self):
        # The default band against a run on the larger frame (W + 2G) x (H + 2G) without a band,
        # its horizontal angle widened to the same pixel grid, cropped: the same passes and the
        # same AO, bit for bit (measured: identical).
        scene = self.copy_scene("edge_occluders.pov")
        band = DEFAULT_BAND
        proc, names, framed, keep = self.bridge_exr(scene, "--radius", EO_RADIUS, name="band")
        self.assertIn(f"guard band {band} pixels", proc.stdout, self.detail(proc))
        for name, size in [("depth.exr", (H + 2 * band, W + 2 * band)),
                           ("normals.exr", (H + 2 * band, W + 2 * band)),
                           ("beauty.exr", (H, W)), ("ambient.exr", (H, W))]:
            self.assertEqual(read_image(os.path.join(keep, name))[1].shape[:2], size, name)
        angle = math.degrees(2.0 * math.atan((W + 2 * band) / W
                                             * math.tan(math.radians(EO_CAMERA["angle"] / 2))))
        big_size = (W + 2 * band, H + 2 * band)
        proc2, names2, big, keep2 = self.bridge_exr(
            scene, "--radius", EO_RADIUS, "--overscan", "0", "--camera-angle", repr(angle),
            name="big", size=big_size)
        self.assertNotIn("guard band", proc2.stdout)
        for name in ("depth.exr", "normals.exr"):
            padded = read_image(os.path.join(keep, name))[1]
            larger = read_image(os.path.join(keep2, name))[1]
            np.testing.assert_array_equal(padded, larger, err_msg=name)
        crop = big[band:band + H, band:band + W]
        for c in ("AO", "Z", "Radial"):
            np.testing.assert_array_equal(channel(names, framed, c), channel(names2, crop, c),
                                          err_msg=c)
        # Without the band the frame's AO differs along its edges (measured: by up to 0.13), so
        # the comparison above can fail.
        proc3, names3, plain, _ = self.bridge_exr(scene, "--radius", EO_RADIUS, "--overscan",
                                                  "0", name="plain")
        difference = np.abs(channel(names3, plain, "AO") - channel(names, framed, "AO"))
        self.assertGreater(float(difference.max()), 0.05)

    def test_occluders_outside_the_frame_darken_its_edges(self):
        # Against the visibility within the radius ray-cast in the test (512 rays a pixel), over
        # the pixels within 16 pixels of the frame's edges: the boxes outside the frame occlude
        # the floor there, which the AO sees only through the band.
        scene = self.copy_scene("edge_occluders.pov")
        geometry = dict(plane=True, boxes=EO_BOXES)
        origin, rays, _, _ = camera_rays(**EO_CAMERA)
        dist, normal, obj = intersect(origin, rays, **geometry)
        normal[np.sum(normal * rays, axis=-1) > 0] *= -1.0
        # The first three boxes are outside the frame, the fourth inside.
        self.assertEqual([int((obj == k).sum()) for k in (1, 2, 3)], [0, 0, 0])
        self.assertGreater(int((obj == 4).sum()), 100)
        mask = interior(obj) & np.isfinite(dist)
        points = (origin + dist[..., None] * rays)[mask]
        limited, _ = sky_visibility(points, normal[mask], EO_RADIUS, **geometry)
        rows, columns = np.nonzero(mask)
        border = np.minimum(np.minimum(rows, H - 1 - rows), np.minimum(columns, W - 1 - columns))
        border = border < 16
        occluded = border & (limited < 0.95)  # the floor the outside boxes darken
        self.assertGreater(int(occluded.sum()), 150)
        results = {}
        for label, band in [("band", []), ("no band", ["--overscan", "0"])]:
            proc, names, pixels, _ = self.bridge_exr(scene, "--radius", EO_RADIUS, *band,
                                                     name=label.replace(" ", "-"))
            self.assertEqual(pixels.shape[:2], (H, W))
            ao = channel(names, pixels, "AO")[mask].astype(np.float64)
            results[label] = dict(
                all=float(np.sqrt(np.mean((ao - limited) ** 2))),
                border=float(np.sqrt(np.mean((ao - limited)[border] ** 2))),
                too_bright=float(np.mean((ao - limited)[occluded])))
        print(f"\nedge_occluders, radius {EO_RADIUS}, AO vs cast visibility: " + "; ".join(
            f"{label}: RMS all {r['all']:.4f}, border {r['border']:.4f}, mean AO - cast on the "
            f"floor the outside boxes darken {r['too_bright']:+.3f}"
            for label, r in results.items()), file=sys.stderr)
        # Measured: with the band RMS 0.0069 over all pixels and 0.0069 on the border, the
        # occluded border floor 0.008 too bright; without: 0.0217, 0.0326 and 0.095 too bright.
        self.assertLess(results["band"]["border"], 0.012)
        self.assertLess(results["band"]["all"], 0.012)
        self.assertLess(abs(results["band"]["too_bright"]), 0.02)
        self.assertGreater(results["no band"]["border"], 0.025)
        self.assertGreater(results["no band"]["too_bright"], 0.06)


# ----------------------------------------------------------------------------------------------

class NormalPassTest(PovTestCase):
    """A scene that includes ssao_passes.inc gets the exact normal pass."""

    def test_exact_normals_are_used(self):
        scene = self.copy_scene("sphere_on_plane.pov")
        proc, names, exact, keep = self.bridge_exr(scene, "--radius", "1.5", name="exact")
        text = proc.stdout + proc.stderr
        self.assertIn("normal pass", text, self.detail(proc))
        self.assertIn("normals from the normal pass", text, self.detail(proc))
        # The pass the bridge rendered is the include's, with the scene's camera: exact normals.
        normals = frame_of_pass(read_image(os.path.join(keep, "normals.exr"))[1])
        origin, rays, _, (right, up, forward) = camera_rays(**SOP_CAMERA)
        dist, normal_world, obj, margin = trace(origin, rays, [SOP_SPHERE])
        truth = np.stack([normal_world @ right, normal_world @ up, normal_world @ forward], -1)
        inside = margin > 0.01
        error = angle_degrees(decode_normals(normals)[inside], truth[inside])
        self.assertLess(float(error.max()), 0.1)  # measured 0.056

        # The same scene with the include under another name: the bridge does not see
        # "ssao_passes.inc" and reconstructs the normals from depth.
        with open(os.path.join(POV_INCLUDES, "ssao_passes.inc")) as f:
            self.copy_scene("renamed_passes.inc", f.read())
        with open(scene) as f:
            text = f.read().replace("ssao_passes.inc", "renamed_passes.inc")
        other = self.copy_scene("reconstructed.pov", text)
        proc2, names2, rebuilt, keep2 = self.bridge_exr(other, "--radius", "1.5", name="rebuilt")
        self.assertIn("normals from depth", proc2.stdout + proc2.stderr, self.detail(proc2))
        self.assertFalse(os.path.exists(os.path.join(keep2, "normals.exr")))
        ao_exact, ao_rebuilt = channel(names, exact, "AO"), channel(names2, rebuilt, "AO")
        # On the plane both agree closely (measured: mean |difference| 0.0007, max 0.022 away
        # from the sphere's silhouette; 0 on open floor) ...
        plane = (obj == 0) & (margin > 0.05)
        diff = np.abs(ao_exact - ao_rebuilt)
        self.assertLess(float(diff[plane].mean()), 0.005)
        # ... but the exact run did use other normals: on the sphere they differ (measured:
        # mean 0.0032, max 0.036; exactly 0 if the normal pass were ignored).
        sphere = (obj == 1) & (margin > 0.05)
        self.assertGreater(float(diff[sphere].mean()), 0.001)


    def test_camera_override_keeps_normals_exact(self):
        # --camera-location moves the camera away from the one the scene's
        # SSAOCameraBasis describes: the normal pass must still be in the basis of the camera
        # every pass is rendered with (ssao_passes.inc reads it from
        # Declare=SSAOBasis{Right,Up,Forward}{X,Y,Z}=...).
        scene = self.copy_scene("sphere_on_plane.pov")
        camera = dict(SOP_CAMERA, location=(-3.0, 3.0, -5.0))
        proc, names, pixels, keep = self.bridge_exr(
            scene, "--radius", "1.5", "--camera-location", "-3,3,-5")
        self.assertIn("normals from the normal pass", proc.stdout + proc.stderr)
        normals = frame_of_pass(read_image(os.path.join(keep, "normals.exr"))[1])
        origin, rays, _, basis = camera_rays(**camera)
        dist, normal_world, obj, margin = trace(origin, rays, [SOP_SPHERE])
        truth = np.stack([normal_world @ b for b in basis], -1)
        inside = margin > 0.01
        error = angle_degrees(decode_normals(normals)[inside], truth[inside])
        self.assertLess(float(error.max()), 0.1, "normal pass not in the rendered camera's basis")


# ----------------------------------------------------------------------------------------------

class AnimationTest(PovTestCase):
    """+KFI/+KFF: every frame rendered at its own clock, its own camera and depth pass, named
    as POV-Ray names its frames."""

    # The camera moves towards a wall (z = 0) along the view axis: clock c puts it 6 - 2c away.
    # frame_number is read by the scene too (the failure case), as POV-Ray gives it.
    SCENE = """#version 3.7;
global_settings { assumed_gamma 1.0 }
#ifndef (Fail) #declare Fail = 0; #end
#if (Fail & frame_number = 2) #error "frame 2 is broken on purpose" #end
camera { location <0, 1, -6 + 2 * clock> look_at <0, 1, 0> angle 60 }
light_source { <3, 6, -8> rgb 1 }
plane { -z, 0 pigment { rgb 0.8 } }  // the normal faces the camera: it must not be inside
plane { y, 0 pigment { rgb 0.6 } }
box { <0.6, 0, -1.5>, <1.6, 1, -0.5> pigment { rgb <0.9, 0.4, 0.3> } }  // off the view axis
"""
    SIZE = ("+W64", "+H48")

    def wall_distance(self, exr):
        """The Z (planar depth) at the image centre, where the view axis meets the wall."""
        names, pixels = read_image(exr)
        z = channel(names, pixels, "Z")
        return float(z[23:25, 31:33].mean())

    def test_each_frame_has_its_own_clock_and_camera(self):
        scene = self.copy_scene("moving.pov", self.SCENE)
        proc = self.run_bridge(scene, *self.SIZE, "+KFI1", "+KFF3", "--radius", "0.5", "-o",
                               self.path("out.png"), "--exr", self.path("out.exr"))
        outputs = [self.path(f"out{n}.{ext}") for n in (1, 2, 3) for ext in ("png", "exr")]
        self.assert_ok(proc, *outputs)
        self.assertIn("3 of 3 frames written", proc.stdout, self.detail(proc))
        # POV-Ray's clock: 0, 0.5, 1 over frames 1-3 (the default Initial/Final_Clock 0 and 1).
        for frame, clock in ((1, 0.0), (2, 0.5), (3, 1.0)):
            self.assertAlmostEqual(self.wall_distance(self.path(f"out{frame}.exr")),
                                   6.0 - 2.0 * clock, delta=(6.0 - 2.0 * clock) * 2e-3)
        # A frame equals the still rendered at its clock, bit for bit.
        still = self.run_bridge(scene, *self.SIZE, "+K0.5", "--radius", "0.5", "-o",
                                self.path("still.png"), "--exr", self.path("still.exr"))
        self.assert_ok(still)
        frame_names, frame_pixels = read_image(self.path("out2.exr"))
        still_names, still_pixels = read_image(self.path("still.exr"))
        self.assertEqual(frame_names, still_names)
        np.testing.assert_array_equal(frame_pixels, still_pixels)

    def test_subset_padding_and_patterns(self):
        scene = self.copy_scene("moving.pov", self.SCENE)
        # Frames 9 and 10 of 1-10: two digits as POV-Ray pads them; a #### pattern takes four.
        proc = self.run_bridge(scene, *self.SIZE, "+KFI1", "+KFF10", "+SF9", "+EF10", "--radius",
                               "0.5", "-o", self.path("out.png"), "--exr",
                               self.path("z.####.exr"))
        self.assert_ok(proc, self.path("out09.png"), self.path("out10.png"),
                       self.path("z.0009.exr"), self.path("z.0010.exr"))
        self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith(("out", "z."))),
                         ["out09.png", "out10.png", "z.0009.exr", "z.0010.exr"])
        # Frame 9 of 1..10: clock 8/9.
        self.assertAlmostEqual(self.wall_distance(self.path("z.0009.exr")), 6.0 - 16.0 / 9.0,
                               delta=5e-3)

    def test_a_failed_frame_leaves_the_others(self):
        scene = self.copy_scene("moving.pov", self.SCENE)
        proc = self.run_bridge(scene, *self.SIZE, "+KFI1", "+KFF3", "Declare=Fail=1",
                               "--radius", "0.5", "-o", self.path("out.png"))
        self.assertEqual(proc.returncode, 1, self.detail(proc))
        self.assertIn("frame 2: error", proc.stderr, self.detail(proc))
        self.assertIn("is broken on purpose", proc.stderr, self.detail(proc))
        self.assertIn("1 of 3 frames failed: 2", proc.stderr, self.detail(proc))
        self.assertTrue(os.path.isfile(self.path("out1.png")))
        self.assertTrue(os.path.isfile(self.path("out3.png")))
        self.assertFalse(os.path.exists(self.path("out2.png")))

    def test_animation_usage_errors(self):
        scene = self.copy_scene("moving.pov", self.SCENE)
        cases = [(("+KFI1", "+KFF3"), "needs --radius"),
                 (("+KFI5", "+KFF3", "--radius", "1"), "runs backwards"),
                 (("+KFI1", "+KFF3", "+SF7", "--radius", "1"), "holds no frame"),
                 (("+KFI1", "+KFF30", "+SF0.5", "--radius", "1"), "whole frame numbers")]
        for args, phrase in cases:
            with self.subTest(phrase=phrase):
                out = self.path("out.png")
                proc = self.run_bridge(scene, *self.SIZE, *args, "-o", out)
                self.assert_fails(proc, phrase, code=2)
                self.assertEqual([f for f in os.listdir(self.dir) if f.startswith("out")], [])


class BadInputTest(PovTestCase):

    def test_missing_scene(self):
        out = self.path("out.png")
        proc = self.run_bridge(self.path("nothing-here.pov"), "-o", out, "+W32", "+H24")
        self.assert_fails(proc, "nothing-here.pov", outputs=[out])
        self.assertIn("povray-ssao: error:", proc.stderr, self.detail(proc))

    def test_syntax_error(self):
        scene = self.copy_scene("broken.pov", """#version 3.7;
camera { location <0, 1, -5> look_at 0 angle 50 }
light_source { <5, 5, -5> rgb 1 }
sphere { 0, 1 pigment { rgb 1 }
box { -1 1 frobnicate }
""")
        out, exr = self.path("out.png"), self.path("out.exr")
        proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W32", "+H24")
        self.assert_fails(proc, outputs=[out, exr])
        # POV-Ray's own diagnosis must reach the user: "File 'broken.pov' line 5: Parse Error:
        # No matching } in 'sphere', box found instead".
        self.assertIn("povray-ssao: error:", proc.stderr, self.detail(proc))
        self.assertIn("Parse Error", proc.stderr, self.detail(proc))
        self.assertIn("broken.pov' line 5", proc.stderr, self.detail(proc))

    def test_syntax_error_where_the_camera_is_read(self):
        # Syntax errors that the camera scan trips over first (an unclosed block that swallows
        # the camera, an unclosed comment, a broken camera), or that POV-Ray reports after the
        # scene's last line (a block left open at its end, read on into povray-ssao's wrapper):
        # the user must get POV-Ray's own diagnosis, in the scene's file, not "no camera".
        camera = "camera { location <0, 1, -5> look_at 0 angle 50 }\n"
        rest = "light_source { <5, 5, -5> rgb 1 }\nsphere { 0, 1 pigment { rgb 1 } }\n"
        cases = [
            ("#declare T = texture { pigment { rgb 1 }\n" + camera + rest,
             ["File 'broken.pov' line 3: Parse Error: No matching } in 'texture', camera found"]),
            ("/* a comment left open\n" + camera + rest,
             ["File 'broken.pov' line ", "Parse Error: No */ closing comment found"]),
            ("camera { location <0, 1, -5 look_at 0 angle 50 }\n" + rest,
             ["File 'broken.pov' line 2: Parse Error: Expected '>', look_at found instead"]),
            (camera + rest + "box { -1, 1\n",
             ["File 'broken.pov', after its last line: Parse Error: No matching } in 'box'",
              "a missing } or #end"]),
            (rest + "box { -1, 1\n",  # no camera either
             ["File 'broken.pov', after its last line: Parse Error: No matching } in 'box'"]),
        ]
        for text, phrases in cases:
            with self.subTest(scene=text.splitlines()[0]):
                scene = self.copy_scene("broken.pov", "#version 3.7;\n" + text)
                out, exr = self.path("out.png"), self.path("out.exr")
                proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W32", "+H24")
                self.assert_fails(proc, outputs=[out, exr])
                self.assertIn("povray-ssao: error: POV-Ray cannot parse the scene", proc.stderr,
                              self.detail(proc))
                for phrase in phrases:
                    self.assertIn(phrase, proc.stderr, self.detail(proc))
                self.assertNotIn("no camera", proc.stderr, self.detail(proc))
                self.assertEqual(sorted(os.listdir(self.dir)), ["broken.pov"])

    def test_camera_inside_a_non_hollow_plane(self):
        # plane { z, 10 } behind the scene: the camera is inside its half-space, POV-Ray renders
        # no fog there and the depth pass would read the scene's colours as tiny depths. Both
        # ways to the fog distances (look_at, and the pre-pass without it) must refuse.
        for camera in ("look_at <0, 1, 0>", "direction z"):
            with self.subTest(camera=camera):
                scene = self.copy_scene("inside.pov", f"""#version 3.7;
camera {{ location <0, 1, -5> {camera} angle 60 }}
light_source {{ <3, 6, -8> rgb 1 }}
plane {{ z, 10 pigment {{ rgb 0.8 }} }}
plane {{ y, 0 pigment {{ rgb 0.6 }} }}
sphere {{ <0, 1, 0>, 1 pigment {{ rgb 1 }} }}
""")
                out, exr = self.path("out.png"), self.path("out.exr")
                proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W32", "+H24")
                self.assert_fails(proc, "measured no usable distances", "hollow",
                                  outputs=[out, exr])
        # The same scene with the plane hollow: distances as they are (the sphere's front at 4).
        text = open(scene).read().replace("rgb 0.8 } }", "rgb 0.8 } hollow }")
        scene = self.copy_scene("hollow.pov", text)
        proc, names, pixels, _ = self.bridge_exr(scene, size=(32, 24))
        z = channel(names, pixels, "Z")
        self.assertAlmostEqual(float(z[11:13, 15:17].min()), 4.0, delta=0.05, msg=self.detail(proc))

    def test_absurd_sizes_and_parameters_are_refused(self):
        # Refused before POV-Ray starts (a 60000 x 60000 render would run for hours first).
        scene = self.copy_scene("sunlit_wall.pov")
        out = self.path("out.png")
        ini = self.path("huge.ini")
        with open(ini, "w") as f:
            f.write("Width=60000\nHeight=60000\n")
        cases = [
            (("+W0", "+H24"), 2, "must be 1..65536"),
            (("+W32", "+H-5"), 2, "must be 1..65536"),
            (("+W99999", "+H24"), 2, "must be 1..65536"),
            (("+W32", "+H1.5"), 2, "expects an integer"),
            (("--ini", ini), 1, "67108864 pixels"),
            (("+W32", "+H24", "--radius", "nan"), 2, "finite"),
            (("+W32", "+H24", "--radius", "-1"), 2, "'radius' must be in"),
            (("+W32", "+H24", "--samples", "-3"), 2, "'samples' must be in"),
            (("+W32", "+H24", "--strength", "2"), 2, "'strength' must be in"),
            (("+W32", "+H24", "--bias", "inf"), 2, "finite"),
            (("+W32", "+H24", "--overscan", "-1"), 2, "must be 0..65536"),
            (("+W32", "+H24", "--overscan", "1e3"), 2, "expects an integer"),
            (("+W32", "+H24", "--overscan", "40000"), 1, "the data passes would be 80032x80024"),
            (("+W8000", "+H8000", "--overscan", "100"), 1, "67108864 pixels"),
        ]
        for args, code, phrase in cases:
            with self.subTest(args=args):
                proc = self.run_bridge(scene, "-o", out, *args, timeout=60)
                self.assert_fails(proc, phrase, outputs=[out], code=code)

    def test_unwritable_outputs_are_refused_before_rendering(self):
        scene = self.copy_scene("sunlit_wall.pov")
        blocker = self.path("a-file")
        with open(blocker, "w") as f:
            f.write("not a folder")
        exr = self.path("out.exr")
        for out in (os.path.join(blocker, "out.png"), self.path("no/such/folder/out.png"),
                    self.path("out.xyz")):
            with self.subTest(out=out):
                proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W32", "+H24",
                                       timeout=60)
                self.assertNotEqual(proc.returncode, 0, self.detail(proc))
                self.assertIn("povray-ssao: error:", proc.stderr, self.detail(proc))
                self.assertFalse(os.path.exists(out))
                self.assertFalse(os.path.exists(exr), "the --exr output of a failed run")
        self.assertEqual(sorted(os.listdir(self.dir)), sorted(["a-file", "sunlit_wall.pov"]),
                         "files left behind")

    def test_killed_bridge_leaves_no_render_running(self):
        # SIGKILL (a test's or a farm's time limit) gives povray-ssao no chance to stop its
        # renders: they must not go on rendering for nothing.
        scene = self.copy_scene("sunlit_wall.pov")
        bridge = subprocess.Popen([BRIDGE, scene, "-o", self.path("out.png"), "+W3000",
                                   "+H3000"], cwd=self.dir, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)

        def renders():
            found = []
            for pid in filter(str.isdigit, os.listdir("/proc")):
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        words = f.read().split(b"\0")
                except OSError:
                    continue
                if words and os.path.basename(words[0]) == b"povray" and \
                        any(self.dir.encode() in w for w in words):
                    found.append(int(pid))
            return found

        try:
            deadline = time.monotonic() + 30
            while len(renders()) < 3 and time.monotonic() < deadline:
                time.sleep(0.05)
            self.assertEqual(len(renders()), 3, "the three passes never started")
        finally:
            bridge.kill()
            bridge.wait()
        deadline = time.monotonic() + 10
        while renders() and time.monotonic() < deadline:
            time.sleep(0.05)
        left = renders()
        for pid in left:
            os.kill(pid, 9)
        self.assertEqual(left, [], "POV-Ray renders outlived a killed povray-ssao")

    def busy_povray(self, failures):
        """A povray whose first `failures` runs of each pass fail as POV-Ray 3.7 does when its
        worker thread starts too late on a loaded machine; the runs after them are POV-Ray's."""
        script = self.path("busy-povray")
        with open(script, "w") as f:
            f.write(f"""#!/bin/sh
for arg in "$@"; do case "$arg" in +O*) out="${{arg#+O}}";; esac; done
count="{self.dir}/$(basename "$out").failures"
n=$(cat "$count" 2>/dev/null || echo 0)
if [ "$n" -lt {failures} ]; then
  echo $((n + 1)) > "$count"
  echo "{STARTUP_TIMEOUT}" >&2
  exit 1
fi
exec {POVRAY} "$@"
""")
        os.chmod(script, 0o755)
        return script

    def test_povray_startup_timeout_is_run_again(self):
        # Seen in CI under load: POV-Ray gives its worker thread a few seconds to start, then
        # exits having rendered nothing. Such a run is not the scene's fault: run it again.
        scene = self.copy_scene("sphere_on_plane.pov")
        reference = self.path("reference.exr")
        self.assert_ok(self.run_bridge(scene, "-o", self.path("reference.png"), "--exr",
                                       reference, "+W48", "+H36"), reference)
        out, exr, keep = self.path("out.png"), self.path("out.exr"), self.path("keep")
        proc = self.run_bridge(scene, "-o", out, "--exr", exr, "--keep", keep, "+W48", "+H36",
                               "--povray", self.busy_povray(2))
        self.assert_ok(proc, out, exr)
        names, pixels = read_image(exr)
        names_ref, pixels_ref = read_image(reference)
        self.assertEqual(names, names_ref)
        self.assertEqual(np.abs(pixels - pixels_ref).max(), 0.0, self.detail(proc))
        with open(os.path.join(keep, "depth.log")) as f:
            log = f.read()
        self.assertIn("run 3 of 4", log)
        self.assertEqual(log.count(STARTUP_TIMEOUT), 2)

    def test_povray_that_never_starts_fails_clearly(self):
        scene = self.copy_scene("sphere_on_plane.pov")
        out, exr = self.path("out.png"), self.path("out.exr")
        proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W48", "+H36",
                               "--povray", self.busy_povray(99))
        self.assert_fails(proc, "failed on the", "run 4 times", STARTUP_TIMEOUT,
                          outputs=[out, exr])

    def test_fisheye_camera(self):
        scene = self.copy_scene("fisheye.pov", """#version 3.7;
camera { fisheye location <0, 1, -5> look_at 0 angle 180 }
light_source { <5, 5, -5> rgb 1 }
sphere { 0, 1 pigment { rgb 1 } }
plane { y, -1 pigment { rgb 0.5 } }
""")
        out = self.path("out.png")
        proc = self.run_bridge(scene, "-o", out, "+W32", "+H24")
        self.assert_fails(proc, "fisheye", "fisheye.pov:2", outputs=[out])
        self.assertIn("povray-ssao: error:", proc.stderr, self.detail(proc))


# ----------------------------------------------------------------------------------------------

SW_AMBIENT = 0.8 * 0.2 * 1.5  # sunlit_wall.pov: pigment x finish ambient x ambient_light


class AmbientModeTest(PovTestCase):
    """--apply-to ambient (the default where the scene has ambient light): AO darkens only the
    ambient term, rendered as its own pass; sunlit_wall.pov's is 0.24 everywhere."""

    def run_mode(self, scene, mode, *args):
        proc, names, pixels, keep = self.bridge_exr(scene, "--apply-to", mode, "--radius", "1",
                                                    *args, name=mode)
        rgb = np.stack([channel(names, pixels, c) for c in "RGB"], -1).astype(np.float64)
        beauty = read_image(os.path.join(keep, "beauty.exr"))[1][..., :3].astype(np.float64)
        ao = channel(names, pixels, "AO").astype(np.float64)
        return proc, rgb, beauty, ao, np.isfinite(channel(names, pixels, "Z"))

    def test_only_the_ambient_light_darkens(self):
        scene = self.copy_scene("sunlit_wall.pov")
        proc, out, beauty, ao, geometry = self.run_mode(scene, "auto")
        text = proc.stdout + proc.stderr
        self.assertIn("applied to the ambient light", text, self.detail(proc))
        self.assertIn("ambient_light <1.5, 1.5, 1.5>", text, self.detail(proc))
        self.assertNotIn("pre-pass", text)  # the camera's look_at places the fogs
        # The darkening is (1 - AO) x the ambient term, which the scene fixes at 0.24.
        occluded = geometry & (ao < 0.9)
        self.assertGreater(int(occluded.sum()), 200)
        ambient = (beauty - out)[occluded] / (1.0 - ao[occluded, None])
        # Measured: 0.2400 +- 2e-4 (half floats in the passes).
        np.testing.assert_allclose(ambient, SW_AMBIENT, rtol=0, atol=3e-3)
        # Against --apply-to beauty (the whole image times AO): in the block's shadow the
        # beauty is the ambient term alone, so both agree; in sunlight, the ambient mode darkens
        # by a fraction 0.24 / beauty of the multiply mode's darkening.
        proc, multiplied, _, ao_b, _ = self.run_mode(scene, "beauty")
        self.assertIn("applied to the whole image", proc.stdout, self.detail(proc))
        np.testing.assert_array_equal(ao, ao_b)
        np.testing.assert_allclose(multiplied, beauty * ao[..., None], rtol=1e-5, atol=1e-6)
        lum = beauty.mean(-1)
        shade = occluded & (np.abs(lum - SW_AMBIENT) < 2e-3)
        sun = occluded & (lum > 2.0 * SW_AMBIENT)
        self.assertGreater(int(shade.sum()), 30, "no occluded pixel in the block's shadow")
        self.assertGreater(int(sun.sum()), 100, "no occluded pixel in sunlight")
        np.testing.assert_allclose(out[shade], multiplied[shade], rtol=0, atol=2e-3)
        dark_ambient = (beauty - out).mean(-1)[sun]
        dark_multiplied = (beauty - multiplied).mean(-1)[sun]
        np.testing.assert_allclose(dark_ambient / dark_multiplied, SW_AMBIENT / lum[sun],
                                   rtol=0.02)

    def test_working_gamma(self):
        # With assumed_gamma 2.2 POV-Ray writes (working value)^2.2: in the shadow the output is
        # (0.24 AO)^2.2, i.e. the beauty times AO^2.2.
        scene = self.copy_scene("sunlit_wall.pov")
        proc, out, beauty, ao, geometry = self.run_mode(scene, "ambient", "Declare=Gamma=2.2")
        lum = beauty.mean(-1)
        shade = geometry & (ao < 0.9) & (np.abs(lum - SW_AMBIENT ** 2.2) < 2e-3)
        self.assertGreater(int(shade.sum()), 30, self.detail(proc))
        np.testing.assert_allclose(out[shade], beauty[shade] * ao[shade, None] ** 2.2, rtol=3e-3)

    def test_scenes_without_ambient_light_multiply(self):
        cases = [
            ("radiosity", "global_settings { radiosity { } }", "uses radiosity"),
            ("unreadable", "global_settings { ambient_light rgbf <1, 1, 1, 0> }",
             "cannot read the scene's ambient_light"),
            ("dark", "#default { finish { ambient 0 } }", "almost no ambient light"),
        ]
        for name, settings, phrase in cases:
            with self.subTest(name):
                scene = self.copy_scene(name + ".pov", f"""#version 3.7;
{settings}
camera {{ location <0, 2, -5> look_at <0, 0.5, 0> angle 50 }}
light_source {{ <5, 8, -5> rgb 1 }}
plane {{ y, 0 pigment {{ rgb 0.8 }} }}
sphere {{ <0, 1, 0>, 1 pigment {{ rgb 0.8 }} }}
""")
                png = self.path(name + ".png")
                proc = self.run_bridge(scene, "-o", png, "+W64", "+H48")
                self.assert_ok(proc, png)
                self.assertIn(phrase, proc.stdout + proc.stderr, self.detail(proc))
                self.assertIn("applied to the whole image", proc.stdout, self.detail(proc))
                if name != "dark":
                    out = self.path(name + "-ambient.png")
                    proc = self.run_bridge(scene, "-o", out, "+W64", "+H48", "--apply-to",
                                           "ambient")
                    self.assert_fails(proc, "--apply-to ambient", phrase, outputs=[out])

    def test_default_radius_rule(self):
        # 10% of the view's width at the median planar depth: 2 tan(55/2) x median x 0.1.
        scene = self.copy_scene("sunlit_wall.pov")
        png, exr = self.path("r.png"), self.path("r.exr")
        proc = self.run_bridge(scene, "-o", png, "--exr", exr, f"+W{W}", f"+H{H}")
        self.assert_ok(proc, png, exr)
        names, pixels = read_image(exr)
        z = channel(names, pixels, "Z")
        median = float(np.median(z[np.isfinite(z)]))
        expected = 0.1 * 2.0 * math.tan(math.radians(55.0) / 2.0) * median
        match = re.search(r"radius ([0-9.]+) scene units \(10% of the view's width at the "
                          r"median depth; --radius to change\)", proc.stdout)
        self.assertIsNotNone(match, self.detail(proc))
        self.assertAlmostEqual(float(match.group(1)), expected, delta=0.002 * expected)


# ----------------------------------------------------------------------------------------------

class PostProcessTest(PovTestCase):
    """--beauty IMAGE --depth DEPTH.exr: the AO of the full run from the same passes."""

    def test_post_process_matches_full_run(self):
        scene = self.copy_scene("analytic.pov")
        # The post-process mode has no guard band (its depth file is the frame): compare with a
        # full run without one.
        proc, names, full, keep = self.bridge_exr(scene, "--radius", "1.5", "--apply-to", "beauty",
                                                  "--overscan", "0")
        beauty = os.path.join(keep, "beauty.exr")
        for depth_channel, kind in [("Radial", "radial"), ("Z", "planar")]:
            out, exr = self.path(f"post-{kind}.png"), self.path(f"post-{kind}.exr")
            proc = self.run_bridge("--beauty", beauty, "--depth", self.path("out.exr"),
                                   "--depth-channel", depth_channel, "--depth-kind", kind,
                                   "--camera-angle", "60", "-o", out, "--exr", exr,
                                   "--radius", "1.5")
            self.assert_ok(proc, out, exr)
            post_names, post = read_image(exr)
            ao, ao_full = channel(post_names, post, "AO"), channel(names, full, "AO")
            # Radial: the same input as the full run (measured: identical). Planar: Z was
            # computed from Radial in float, so the AO moves by rounding only: a last-bit change
            # of depth can flip one sample's tangent-plane test, and a sample in front of a
            # surface counts by the part of its cone behind it, up to half (measured max 4.1e-3,
            # mean far below 1e-4).
            tolerance = 1e-6 if kind == "radial" else 1e-2
            self.assertLess(float(np.abs(ao - ao_full).max()), tolerance, kind)
            self.assertLess(float(np.abs(ao - ao_full).mean()), 1e-4, kind)
            for c in "RGB":
                np.testing.assert_allclose(channel(post_names, post, c), channel(names, full, c),
                                           rtol=1e-5, atol=1e-5 + tolerance, err_msg=c)
        origin, rays, _, _ = camera_rays(**AN_CAMERA)
        dist, _, obj, margin = trace(origin, rays, AN_SPHERES, disc_radius=AN_DISC_RADIUS)
        sky = ~np.isfinite(dist) & (margin > 0.03)
        np.testing.assert_array_equal(ao[sky], 1.0)
        self.assertLess(float(ao[np.isfinite(dist)].mean()), 0.99)


# ----------------------------------------------------------------------------------------------

# POV-Ray 3.7's default camera (what it renders a scene without a camera with): perspective at the
# origin, looking along +z, right 1.33 whatever the image's aspect.
DEFAULT_CAMERA = ("camera { perspective location <0, 0, 0> direction <0, 0, 1> "
                  "right <1.33, 0, 0> up <0, 1, 0> }\n")
# In front of it: a sphere whose nearest point is 4 away on the view axis, on a floor, and a box.
NO_CAMERA_SCENE = """#version 3.7;
global_settings { assumed_gamma 1.0 }
light_source { <3, 6, -4> rgb 1 }
plane { y, -1 pigment { checker rgb 0.8 rgb 0.5 } }
sphere { <0, 0, 5>, 1 pigment { rgb <0.9, 0.6, 0.4> } }
box { <1.2, -1, 4>, <2.2, 0.5, 5> pigment { rgb 0.7 } }
"""


class DefaultCameraTest(PovTestCase):
    """A scene without a camera: POV-Ray renders it with its default camera, and so must the
    passes, after checking that POV-Ray does (a camera the scan cannot see must not be
    replaced)."""

    def test_no_camera_is_the_default_camera(self):
        bare = self.copy_scene("bare.pov", NO_CAMERA_SCENE)
        explicit = self.copy_scene("explicit.pov", NO_CAMERA_SCENE + DEFAULT_CAMERA)
        proc, names, pixels, keep = self.bridge_exr(bare, "--radius", "0.5", name="bare")
        self.assertIn("POV-Ray's default camera", proc.stdout, self.detail(proc))
        self.assertIn("renders it with its default camera", proc.stdout, self.detail(proc))
        _, explicit_names, explicit_pixels, _ = self.bridge_exr(explicit, "--radius", "0.5",
                                                                name="explicit")
        # The same camera, so the same passes, AO and composite (measured: identical).
        self.assertEqual(names, explicit_names)
        np.testing.assert_array_equal(pixels, explicit_pixels)
        ao = channel(names, pixels, "AO")
        self.assertLess(float(ao[np.isfinite(channel(names, pixels, "Z"))].mean()), 0.99)
        # The beauty is POV-Ray's own render of the scene, and the camera looks along +z: the
        # sphere's front is 4 away at the centre.
        direct = read_image(self.povray(bare, self.path("direct.exr"), "+FE"))[1]
        np.testing.assert_array_equal(read_image(os.path.join(keep, "beauty.exr"))[1], direct)
        z = channel(names, pixels, "Z")
        self.assertAlmostEqual(float(z[H // 2 - 1:H // 2 + 1, W // 2 - 1:W // 2 + 1].mean()), 4.0,
                               delta=0.02)

    def test_a_camera_the_scan_cannot_see_is_refused(self):
        # A camera made by a macro: the reader does not expand macros, but sees that this one
        # makes the camera, and names it.
        scene = self.copy_scene("macro.pov", NO_CAMERA_SCENE + """#macro MyCamera(L)
  camera { location L look_at <0, 0, 5> angle 50 }
#end
MyCamera(<2, 3, -3>)
""")
        out, exr = self.path("out.png"), self.path("out.exr")
        proc = self.run_bridge(scene, "-o", out, "--exr", exr, "+W32", "+H24")
        self.assert_fails(proc, "the camera is made by the macro 'MyCamera'", "--camera-location",
                          outputs=[out, exr])
        # A camera the text does not show at all (parsed from a string): POV-Ray itself renders
        # another view than the default one. Declaring the default camera after the scene
        # would silently replace it.
        hidden = self.copy_scene("hidden.pov", NO_CAMERA_SCENE + """#include "strings.inc"
Parse_String("camera { location <2, 3, -3> look_at <0, 0, 5> angle 50 }")
""")
        proc = self.run_bridge(hidden, "-o", out, "--exr", exr, "+W32", "+H24")
        self.assert_fails(proc, "another camera than its default one", "--camera-location",
                          outputs=[out, exr])
        # The flags give the camera: then the scene's own does not matter.
        proc = self.run_bridge(scene, "-o", out, "+W32", "+H24", "--camera-location", "2,3,-3",
                               "--camera-look-at", "0,0,5", "--camera-angle", "50")
        self.assert_ok(proc, out)


class FileWritingSceneTest(PovTestCase):
    """A scene that writes a file as it parses (strings.inc's Parse_String writes
    parse_string.tmp in the scene's folder and includes it): its passes run one after another.
    At once, they would read it half-written from each other: measured on four POV-Rays started
    together on a scene calling Parse_String 300 times, 15 of 20 runs failed to parse and one
    never ended."""

    def test_passes_run_one_after_another(self):
        camera = "camera { location <2, 3, -3> look_at <0, 0, 5> angle 50 }\n"
        box = "box { <-2.2, -1, 4>, <-1.2, 0.3, 5> pigment { rgb 0.7 } }"
        written = self.copy_scene("written.pov", NO_CAMERA_SCENE + camera + box + "\n")
        parsed = self.copy_scene("parsed.pov", NO_CAMERA_SCENE + camera +
                                 '#include "strings.inc"\nParse_String("' + box + '")\n')
        proc, names, pixels, _ = self.bridge_exr(parsed, "--radius", "0.5", name="parsed")
        call_line = len(NO_CAMERA_SCENE.splitlines()) + 3
        self.assertIn(f"parsed.pov:{call_line} calls Parse_String(), which opens a file for "
                      "writing at strings.inc:", proc.stdout, self.detail(proc))
        self.assertIn("one after another", proc.stdout, self.detail(proc))
        self.assertNotIn("at once", proc.stdout, self.detail(proc))
        # The same image as the scene with the box written out (rendered at once).
        proc, written_names, written_pixels, _ = self.bridge_exr(written, "--radius", "0.5",
                                                                 name="written")
        self.assertIn("at once", proc.stdout, self.detail(proc))
        self.assertEqual(names, written_names)
        np.testing.assert_array_equal(pixels, written_pixels)


# Focal blur: in focus at the sphere (6.1 from the camera), the floor in front and the box far
# behind out of focus.
FOCAL_BLUR_SCENE = """#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 2, -6> look_at <0, 0.8, 0> angle 50
         aperture 0.6 focal_point <0, 1, 0> blur_samples 12 }
light_source { <3, 6, -8> rgb 1 }
plane { y, 0 pigment { checker rgb 0.8 rgb 0.3 } }
sphere { <0, 1, 0>, 1 pigment { rgb <0.9, 0.5, 0.3> } }
box { <-3, 0, 3>, <-1.5, 2, 5> pigment { rgb 0.7 } }
sphere { <2, 0.5, -2.5>, 0.5 pigment { rgb <0.3, 0.6, 0.9> } }
"""


class FocalBlurTest(PovTestCase):
    """A camera with focal blur: the beauty (and the ambient pass) as POV-Ray renders them,
    blurred; AO from sharp depth and normal passes."""

    SIZE = (96, 72)

    def run_scene(self, text, name, *args):
        scene = self.copy_scene(name + ".pov", text)
        proc, names, pixels, keep = self.bridge_exr(scene, "--radius", "0.6", *args, name=name,
                                                    size=self.SIZE)
        kept = {p: read_image(os.path.join(keep, p + ".exr"))[1]
                for p in ("beauty", "depth", "ambient")
                if os.path.isfile(os.path.join(keep, p + ".exr"))}
        return scene, proc, names, pixels, kept

    def test_beauty_keeps_focal_blur_and_ao_is_sharp(self):
        scene, proc, names, pixels, kept = self.run_scene(FOCAL_BLUR_SCENE, "blurred")
        self.assertIn("focal blur: the beauty and the ambient pass keep", proc.stdout,
                      self.detail(proc))
        self.assertIn("edge_coverage none", proc.stdout, self.detail(proc))
        sharp_text = FOCAL_BLUR_SCENE.replace("aperture 0.6", "aperture 0")
        # The blurred beauty's edges are not the depth's: the bridge reads none of them
        # (edge_coverage none), so the AO is the sharp scene's without them.
        _, _, sharp_names, sharp_pixels, sharp_kept = self.run_scene(
            sharp_text, "sharp", "--edge-coverage", "none")
        # The beauty is POV-Ray's own render of the scene, focal blur included (measured:
        # identical), and visibly not the sharp one.
        size = (f"+W{self.SIZE[0]}", f"+H{self.SIZE[1]}")
        direct = read_image(self.povray(scene, self.path("direct.exr"), "+FE", *size))[1]
        np.testing.assert_array_equal(kept["beauty"], direct)
        self.assertGreater(float(np.abs(kept["beauty"] - sharp_kept["beauty"]).max()), 0.1)
        # So is the ambient pass, which is composited per pixel with it.
        self.assertGreater(float(np.abs(kept["ambient"] - sharp_kept["ambient"]).max()), 100.0)
        # The depth pass is the sharp scene's, bit for bit, and so are Z and AO.
        np.testing.assert_array_equal(kept["depth"], sharp_kept["depth"])
        for c in ("Z", "AO"):
            np.testing.assert_array_equal(channel(names, pixels, c),
                                          channel(sharp_names, sharp_pixels, c), err_msg=c)
        ao = channel(names, pixels, "AO")
        self.assertLess(float(ao[np.isfinite(channel(names, pixels, "Z"))].mean()), 0.99)
        # Without focal blur the sharp beauty places the edges (edge_coverage beauty, the
        # library's default), which changes the AO there: what the blurred run would get wrong.
        _, _, edge_names, edge_pixels, _ = self.run_scene(sharp_text, "sharp_edges",
                                                          "--edge-coverage", "beauty")
        edges = np.abs(channel(edge_names, edge_pixels, "AO") - channel(names, pixels, "AO"))
        self.assertGreater(int(np.count_nonzero(edges > 1e-3)), 5)

    def test_multiplied_beauty_and_camera_flags(self):
        _, proc, names, pixels, kept = self.run_scene(FOCAL_BLUR_SCENE, "beauty", "--apply-to",
                                                      "beauty")
        rgb = np.stack([channel(names, pixels, c) for c in "RGB"], -1)
        ao = channel(names, pixels, "AO")
        np.testing.assert_allclose(rgb, kept["beauty"][..., :3] * ao[..., None], rtol=1e-5,
                                   atol=1e-6)
        # --camera-* flags replace the scene's camera, focal blur included: every pass is sharp.
        _, proc, _, _, flagged = self.run_scene(FOCAL_BLUR_SCENE, "flags", "--camera-location",
                                                "0,2,-6")
        self.assertIn("which the --camera-* flags replace", proc.stderr, self.detail(proc))
        sharp = self.copy_scene("sharp.pov", FOCAL_BLUR_SCENE.replace("aperture 0.6",
                                                                      "aperture 0"))
        size = (f"+W{self.SIZE[0]}", f"+H{self.SIZE[1]}")
        direct = read_image(self.povray(sharp, self.path("direct.exr"), "+FE", *size))[1]
        np.testing.assert_allclose(flagged["beauty"], direct, atol=2e-3)


# ----------------------------------------------------------------------------------------------

def main():
    global BRIDGE, SCRATCH, POVRAY
    parser = argparse.ArgumentParser(add_help=False)
    parser.add_argument("--bridge", default=BRIDGE)
    parser.add_argument("--scratch", default=SCRATCH)
    parser.add_argument("--povray", default=POVRAY)
    args, rest = parser.parse_known_args()
    BRIDGE, POVRAY = os.path.abspath(args.bridge), args.povray
    SCRATCH = os.path.abspath(args.scratch or tempfile.mkdtemp(prefix="ssao-povray-tests-"))
    if not os.access(BRIDGE, os.X_OK) or not POVRAY or not os.access(POVRAY, os.X_OK):
        sys.exit(f"test_povray.py: need --bridge POVRAY_SSAO and --povray POVRAY "
                 f"(got '{BRIDGE}', '{POVRAY}')")
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
