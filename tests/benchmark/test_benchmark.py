#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Smoke test of scripts/benchmark.sh: runs `--quick` at a tiny size with the real Blender and
ssao_eval, then checks the files it writes, their columns and what the measurements must show
whatever the machine (no timing is asserted). Also checks the speed-up interpolation on
made-up curves.

    /usr/bin/python3 tests/benchmark/test_benchmark.py --build-dir build --scratch DIR [-v]
"""
import argparse
import csv
import glob
import math
import os
import subprocess
import sys
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO_ROOT, "benchmarks"))
import speed_error  # noqa: E402

SIZE = "64x36"
SCENES = ["contact@%s" % SIZE, "thin@%s" % SIZE, "heavy@%s" % SIZE]
OPTIONS = {}


def run_benchmark(*extra):
    env = dict(os.environ, SSAO_BUILD_DIR=OPTIONS["build_dir"])
    return subprocess.run([os.path.join(REPO_ROOT, "scripts", "benchmark.sh")] + list(extra),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                          check=False)


class QuickRunTest(unittest.TestCase):
    """One `--quick --size 64x36` run, checked from every side."""

    @classmethod
    def setUpClass(cls):
        cls.out = os.path.join(OPTIONS["scratch"], "out")
        cls.kit = os.path.join(OPTIONS["scratch"], "kit")
        cls.proc = run_benchmark("--quick", "--size", SIZE, "--out", cls.out, "--kit", cls.kit)
        if cls.proc.returncode != 0:
            raise AssertionError("benchmark.sh failed (exit %d):\n%s\n%s"
                                 % (cls.proc.returncode, cls.proc.stdout, cls.proc.stderr))
        with open(os.path.join(cls.out, "speed_error.csv"), encoding="utf-8") as f:
            cls.header = f.readline().strip()
            f.seek(0)
            cls.rows = list(csv.DictReader(f))
        with open(os.path.join(cls.out, "complexity.csv"), encoding="utf-8") as f:
            cls.complexity = list(csv.DictReader(f))

    def rows_of(self, scene, method):
        return [r for r in self.rows if r["scene"] == scene and r["method"] == method]

    def test_files_exist(self):
        for name in ("speed_error.csv", "speed_error.png", "complexity.csv", "complexity.png",
                     "crops.png", "performance.md"):
            path = os.path.join(self.out, name)
            self.assertTrue(os.path.isfile(path), path)
            self.assertGreater(os.path.getsize(path), 100, path)
        for name in ("speed_error.png", "complexity.png"):
            with open(os.path.join(self.out, name), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", name)

    def test_csv_columns_and_values(self):
        self.assertEqual(self.header,
                         "scene,method,setting,threads,time_s,rmse,bias,band,edge_rmse")
        self.assertGreater(len(self.rows), 20)
        for r in self.rows:
            self.assertNotIn(None, r.values(), r)
            self.assertGreaterEqual(int(r["threads"]), 1, r)
            self.assertGreater(float(r["time_s"]), 0.0, r)
            self.assertTrue(0.0 <= float(r["rmse"]) <= 1.0, r)
            self.assertTrue(-1.0 <= float(r["bias"]) <= 1.0, r)
            self.assertLessEqual(abs(float(r["bias"])), float(r["rmse"]) + 1e-6, r)
            # Finite (a comparison with nan is false), >= 0, and no method matches the
            # reference exactly.
            self.assertTrue(0.0 < float(r["band"]) <= 1.0, r)
            self.assertTrue(0.0 < float(r["edge_rmse"]) <= 1.0, r)

    def test_band_of_noise_is_below_its_rmse(self):
        # Cycles at 1 spp is mostly per-pixel noise, which G(1) smooths away (white noise keeps
        # about 0.27 of its RMS in G(1) - G(6)): its band must lie well below its RMSE. A band
        # computed without the blur, or of the wrong images, would not.
        for scene in SCENES:
            (one,) = [r for r in self.rows_of(scene, "cycles") if r["setting"] == "samples=1"]
            self.assertLess(float(one["band"]), 0.6 * float(one["rmse"]), one)

    def test_reference_against_itself_scores_zero(self):
        # The reference's AO pass scored as the method: every figure 0, through run_eval's
        # parsing as the benchmark reads it.
        # The kit is cached by the content of its scripts: a kit made by earlier scripts may
        # lie beside this run's, which is the newest.
        reference = max(glob.glob(os.path.join(self.kit, "contact@%s-*s1-*" % SIZE, "ref.exr")),
                        key=os.path.getmtime)
        args = argparse.Namespace(eval=os.path.join(OPTIONS["build_dir"], "bin", "ssao_eval"))
        (result,) = speed_error.run_eval(args, reference[:-len(".exr")],
                                         [("image", ["path=" + reference])], 1, "self")
        for field in ("rmse", "band", "edge_rmse"):
            self.assertEqual(float(result[field]), 0.0, result)

    def test_every_scene_has_every_method(self):
        scenes = {r["scene"] for r in self.rows}
        for scene in SCENES:
            self.assertIn(scene, scenes)
            defaults = [r for r in self.rows_of(scene, "hemisphere") if r["setting"] == "default"]
            self.assertEqual(len(defaults), 1, scene)
            self.assertTrue(self.rows_of(scene, "sphere"), scene)
            self.assertTrue(self.rows_of(scene, "seed-hemisphere"), scene)
            cycles = sorted(int(r["setting"].split("=")[1]) for r in self.rows_of(scene, "cycles"))
            self.assertEqual(cycles, speed_error.CYCLES_SAMPLES, scene)
        for level in (1, 2):
            self.assertTrue(self.rows_of("heavy-L%d@%s" % (level, SIZE), "cycles"))

    def test_cycles_fast_setup_writes_a_correct_ao_pass(self):
        # Rendered the fast way (no bounces, no lights, material override, AO pass only), the AO
        # pass must converge to the ground truth: unbiased, and 64 spp far closer than 1 spp.
        for scene in SCENES + ["heavy-L2@%s" % SIZE]:
            by_samples = {int(r["setting"].split("=")[1]): r for r in self.rows_of(scene, "cycles")}
            self.assertLess(float(by_samples[64]["rmse"]), 0.5 * float(by_samples[1]["rmse"]),
                            scene)
            self.assertLess(abs(float(by_samples[64]["bias"])), 0.02, scene)
            for figure in ("band", "edge_rmse"):
                self.assertLess(float(by_samples[64][figure]), 0.5 * float(by_samples[1][figure]),
                                (scene, figure))

    def test_complexity_grows_by_four_per_level(self):
        triangles = {}
        for r in self.complexity:
            triangles[int(r["level"])] = int(r["triangles"])
        self.assertEqual(sorted(triangles), [0, 1, 2])
        self.assertTrue(8000 <= triangles[0] <= 12000, triangles)
        for level in (1, 2):
            self.assertTrue(3.5 <= triangles[level] / triangles[level - 1] <= 4.2, triangles)
        methods = {r["method"] for r in self.complexity}
        self.assertEqual(methods, {"cycles", "libssao"})

    def test_report_and_summary(self):
        with open(os.path.join(self.out, "performance.md"), encoding="utf-8") as f:
            text = f.read()
        self.assertIn("scripts/benchmark.sh --quick --size %s" % SIZE, text)
        # The plots sit beside this copy of the page (docs/performance.md links images/).
        self.assertIn("(speed_error.png)", text)
        self.assertIn("(complexity.png)", text)
        self.assertIn("Equal-error speed-up over Cycles' AO pass", self.proc.stdout)
        self.assertIn("| RMSE | band | edge RMSE |", text)  # the speed-up table's header
        self.assertIn("| RMSE | bias | band | edge RMSE |", text)  # every row's
        for scene in SCENES:
            self.assertIn("| %s |" % scene, text)
            self.assertRegex(self.proc.stdout, r"\| %s \| [0-9.]+ ms \| 0\.\d{4} \|" % scene)

    def test_kit_is_cached(self):
        proc = run_benchmark("--quick", "--size", SIZE, "--kit", self.kit, "--kit-only")
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("kit ready", proc.stdout)
        self.assertNotIn("kit: rendering", proc.stdout)


class KitKeyTest(unittest.TestCase):
    """A kit render's key covers its own scene's layout, not the others' (editing one scene
    re-renders that scene alone)."""

    def setUp(self):
        with open(speed_error.KIT_SCRIPTS[0], encoding="utf-8") as f:
            self.text = f.read()

    def test_editing_a_layout_changes_only_its_scene(self):
        edited = self.text.replace('"Post%02d" % i, (0.05,', '"Post%02d" % i, (0.06,')
        self.assertNotEqual(edited, self.text)  # the thin fence's posts
        for scene in speed_error.crops.SCENES:
            same = speed_error.scene_source(self.text, scene) == \
                speed_error.scene_source(edited, scene)
            self.assertEqual(same, scene != "thin", scene)

    def test_shared_code_changes_every_scene(self):
        edited = self.text.replace("def add_floor_and_wall(", "def add_floor_and_wall_(")
        self.assertNotEqual(edited, self.text)
        for scene in ("contact", "cavity"):
            self.assertNotEqual(speed_error.scene_source(self.text, scene),
                                speed_error.scene_source(edited, scene))

    def test_a_scene_keeps_its_layout_and_entry(self):
        text = speed_error.scene_source(self.text, "cavity")
        self.assertIn("def layout_cavity(", text)
        self.assertIn('"cavity": layout_cavity', text)
        self.assertNotIn("def layout_thin(", text)
        self.assertNotIn('"thin": layout_thin', text)


class UsageTest(unittest.TestCase):
    def test_bad_size(self):
        proc = run_benchmark("--size", "3x3", "--out", os.path.join(OPTIONS["scratch"], "bad"))
        self.assertEqual(proc.returncode, 2)
        self.assertIn("--size", proc.stderr)
        self.assertFalse(os.path.exists(os.path.join(OPTIONS["scratch"], "bad")))

    def test_unknown_option(self):
        proc = run_benchmark("--frobnicate")
        self.assertEqual(proc.returncode, 2)
        self.assertIn("unrecognized arguments", proc.stderr)


class SpeedupTest(unittest.TestCase):
    """The equal-error interpolation on made-up Cycles curves."""

    CYCLES = [{"time_s": 1.0, "rmse": 0.4}, {"time_s": 2.0, "rmse": 0.2},
              {"time_s": 3.0, "rmse": 0.25},  # slower and worse: off the Pareto front
              {"time_s": 4.0, "rmse": 0.1}]

    def test_on_a_measured_point(self):
        self.assertEqual(speed_error.cycles_time_to(0.2, self.CYCLES), (2.0, "="))

    def test_between_points_in_log_log(self):
        seconds, relation = speed_error.cycles_time_to(math.sqrt(0.2 * 0.1), self.CYCLES)
        self.assertEqual(relation, "=")
        self.assertAlmostEqual(seconds, math.sqrt(8.0), places=9)

    def test_outside_the_measured_range(self):
        self.assertEqual(speed_error.cycles_time_to(0.5, self.CYCLES), (1.0, "<="))
        self.assertEqual(speed_error.cycles_time_to(0.05, self.CYCLES), (4.0, ">="))

    def test_pareto_front(self):
        front = speed_error.pareto_front([(r["time_s"], r["rmse"]) for r in self.CYCLES])
        self.assertEqual(front, [(1.0, 0.4), (2.0, 0.2), (4.0, 0.1)])

    def test_csv_quotes_settings_with_commas(self):
        path = os.path.join(OPTIONS["scratch"], "quoted.csv")
        rows = [{"scene": "s@64x36", "method": "hemisphere", "setting": label, "threads": 2,
                 "time_s": 0.5, "rmse": 0.05, "bias": -0.01, "band": 0.02, "edge_rmse": 0.1}
                for _, label, _ in speed_error.LIBRARY_FULL]
        speed_error.write_csv(path, speed_error.CSV_COLUMNS, rows)
        with open(path, encoding="utf-8", newline="") as f:
            back = list(csv.DictReader(f))
        self.assertEqual([r["setting"] for r in back], [r["setting"] for r in rows])
        self.assertTrue(all(r["rmse"] == "0.05" and None not in r.values() for r in back))
        self.assertIn("samples=16,steps=6,clustering=1", [r["setting"] for r in back])

    def test_unmeasurable_rmse(self):
        self.assertEqual(speed_error.cycles_time_to(float("nan"), self.CYCLES)[1], "?")
        self.assertEqual(speed_error.cycles_time_to(0.0, self.CYCLES), (4.0, ">="))

    def test_speedups_per_scene(self):
        rows = [dict(r, scene="s", method="cycles", setting="samples=1") for r in self.CYCLES]
        rows.append({"scene": "s", "method": "hemisphere", "setting": "default",
                     "time_s": 0.02, "rmse": 0.2, "band": 0.05, "edge_rmse": 0.3})
        (result,) = speed_error.speedups(rows)
        self.assertAlmostEqual(result["speedup"], 100.0)
        self.assertEqual(result["relation"], "=")


class CropsTest(unittest.TestCase):
    """benchmarks/crops.py picks the window where the band error is, on made-up images."""

    def test_window_holds_the_blotch(self):
        import numpy as np
        import crops
        reference = np.full((90, 160), 0.8)
        ours = reference.copy()
        ours[60:66, 120:126] -= 0.3  # a blotch of 6 px: band-pass scale
        x, y = crops.worst_window(ours, reference, np.ones_like(reference, dtype=bool))
        w, h = crops.crop_size(ours)
        self.assertEqual((w, h), (48, 27))
        self.assertTrue(x <= 120 and 126 <= x + w and y <= 60 and 66 <= y + h, (x, y))

    def test_a_smooth_offset_is_not_band_error(self):
        import numpy as np
        import crops
        ramp = np.tile(np.linspace(0.2, 1.0, 160), (90, 1))
        # A constant offset passes G(1) - G(6) only at the clamped borders: nothing inside.
        band = crops.gaussian(ramp + 0.1, 1.0) - crops.gaussian(ramp + 0.1, 6.0)
        reference = crops.gaussian(ramp, 1.0) - crops.gaussian(ramp, 6.0)
        self.assertLess(float(np.abs(band - reference)[10:-10, 10:-10].max()), 1e-9)


class EdgeSidesTest(unittest.TestCase):
    """benchmarks/edge_sides.py sorts edge pixels by side and rings, on a made-up depth image."""

    def test_a_square_in_front_of_a_wall(self):
        import numpy as np
        import edge_sides
        depth = np.full((40, 60), 10.0)
        depth[10:20, 20:30] = 5.0  # a square nearer than the wall
        depth[:, 59] = np.inf  # sky down the right side: a jump to it is no edge
        geometry = np.isfinite(depth)
        near, far = edge_sides.edge_sides(depth, geometry)
        # The square's border (36 pixels) is the near side, the wall's 40 pixels along it the far.
        self.assertEqual(int(near.sum()), 36)
        self.assertEqual(int(far.sum()), 40)
        self.assertTrue(near[10, 20] and far[9, 20] and far[15, 30] and not far[9, 19])
        self.assertFalse((near | far)[:, 55:].any())
        rings = edge_sides.far_rings(near, far, geometry)
        self.assertEqual(len(rings), edge_sides.RINGS)
        # Ring k: the wall k - 1 steps (4-connected) out from the square's outline.
        self.assertTrue(rings[1][8, 25] and rings[3][6, 25] and rings[1][9, 19])
        self.assertFalse(rings[1][9, 25] or rings[2][8, 25])
        for a in range(len(rings)):
            for b in range(a + 1, len(rings)):
                self.assertFalse((rings[a] & rings[b]).any())
            self.assertFalse((rings[a] & near).any())


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build-dir", required=True)
    parser.add_argument("--scratch", required=True)
    args, rest = parser.parse_known_args()
    OPTIONS["build_dir"] = os.path.abspath(args.build_dir)
    OPTIONS["scratch"] = os.path.abspath(args.scratch)
    os.makedirs(OPTIONS["scratch"], exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest)


if __name__ == "__main__":
    main()
