#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Run time against error: libssao's variants, the seed tutorial's code and Cycles' own AO pass,
scored against Cycles' ray-traced AO pass on reference scenes made by the project's Blender
scripts. Run through scripts/benchmark.sh; see docs/performance.md.

Stages (each prints a line as it goes):
1. the kit: every scene of scripts/blender/benchmark_scenes.py rendered by Blender with Depth,
   Normal, beauty and the AO pass at many samples (the ground truth), cached by content under
   build/benchmark_kit (the key hashes the two Blender scripts, Blender's version and the
   render arguments), plus a second render of part of one scene with another seed that
   measures the ground truth's own noise;
2. Cycles' AO pass at 1..64 samples, set up the fastest way, each render call timed
   (scripts/blender/cycles_ao_sweep.py), also for the heavy scene at each triangle count;
3. libssao at several settings of every variant, the seed tutorial ports and the ray march,
   in-process through the C API (build/bin/ssao_eval), interleaved rounds, median of --repeat;
   every image, Cycles' included, scored by ssao_eval over the geometry pixels;
4. OUT/speed_error.csv, OUT/complexity.csv, OUT/speed_error.png, OUT/complexity.png,
   OUT/crops.png (benchmarks/crops.py: each scene's worst window beside the reference),
   OUT/performance.md, and per scene the equal-error speed-up over Cycles on stdout.
"""
import argparse
import ast
import csv
import hashlib
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time

import crops  # noqa: E402  (benchmarks/crops.py, beside this file)

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BLENDER_SCRIPTS = os.path.join(REPO_ROOT, "scripts", "blender")
KIT_SCRIPTS = [os.path.join(BLENDER_SCRIPTS, name)
               for name in ("benchmark_scenes.py", "make_reference_scene.py")]
SWEEP_SCRIPT = os.path.join(BLENDER_SCRIPTS, "cycles_ao_sweep.py")
# A frame of a camera move through a kit scene (benchmarks/flicker.py).
SEQUENCE_SCRIPT = os.path.join(BLENDER_SCRIPTS, "benchmark_sequence.py")
MOVING_SCRIPT = os.path.join(BLENDER_SCRIPTS, "benchmark_moving.py")
# The extra depth layers and guard band of a scene (and what their render depends on).
LAYERS_SCRIPT = os.path.join(BLENDER_SCRIPTS, "benchmark_layers.py")
LAYERS_SOURCES = KIT_SCRIPTS + [LAYERS_SCRIPT, os.path.join(BLENDER_SCRIPTS, "render_layers.py")] + [
    os.path.join(REPO_ROOT, "blender_addon", name)
    for name in ("hidden_surfaces.py", "multilayer.py", "compat.py")]
# The layers rows' guard band and extra depth layers: the Blender node's defaults (crops.py).
GUARD_BAND, EXTRA_LAYERS = crops.GUARD_BAND, crops.EXTRA_LAYERS
CSV_COLUMNS = ["scene", "method", "setting", "threads", "time_s", "rmse", "bias", "band",
               "edge_rmse"]

SD, HD = (640, 360), (1920, 1080)
CYCLES_SAMPLES = [1, 2, 4, 8, 16, 64]
# The region of the second, noise-measuring reference render (fractions of the frame).
NOISE_BORDER = (0.25, 0.75, 0.25, 0.75)

# Library rows: (method, setting label, ssao_eval settings). "default" is the product's default.
LIBRARY_FULL = [
    ("hemisphere", "default", []),  # quality=medium, resolution=auto
    ("hemisphere", "resolution=full", ["resolution=full"]),
    ("hemisphere", "resolution=half", ["resolution=half"]),
    ("hemisphere", "quality=low", ["quality=low"]),
    ("hemisphere", "quality=high", ["quality=high"]),
    ("hemisphere", "quality=ultra", ["quality=ultra"]),
    # The default of 45f8526, before the presets: the accuracy the default must keep.
    ("hemisphere", "samples=16,steps=6,clustering=1",
     ["samples=16", "steps=6", "sample_clustering=1"]),
    # The medium preset from f463daf to issue 22 (tuned on this kit; docs/variants.md).
    ("hemisphere", "samples=4,steps=7,clustering=0.6",
     ["samples=4", "steps=7", "sample_clustering=0.6"]),
    ("horizon", "quality=low", ["variant=horizon", "quality=low"]),
    ("horizon", "quality=medium", ["variant=horizon"]),
    ("horizon", "quality=high", ["variant=horizon", "quality=high"]),
    ("horizon", "quality=ultra", ["variant=horizon", "quality=ultra"]),
    ("sphere", "quality=low", ["variant=sphere", "quality=low"]),
    ("sphere", "quality=medium", ["variant=sphere"]),
    ("sphere", "quality=ultra", ["variant=sphere", "quality=ultra"]),
    ("sphere", "classic,quality=medium", ["variant=sphere", "sphere_mode=classic"]),
    ("volumetric", "quality=low", ["variant=volumetric", "quality=low"]),
    ("volumetric", "quality=medium", ["variant=volumetric"]),
    ("volumetric", "quality=ultra", ["variant=volumetric", "quality=ultra"]),
    ("unsharp", "default", ["variant=unsharp"]),
]
LIBRARY_QUICK = [
    ("hemisphere", "default", []),
    ("horizon", "quality=medium", ["variant=horizon"]),
    ("sphere", "quality=medium", ["variant=sphere"]),
]
# The default with what an offline renderer can add (ssao_eval --layers): the 2nd to 5th surface
# hits with their facing, a guard band around the frame, both.
LAYER_ROWS = [("hemisphere", setting, [setting]) for setting in crops.LAYERED] + [
    ("hemisphere", ",".join(crops.LAYERED), crops.LAYERED)]
# The straight ports of the seed tutorials (tests/reference/seed_ports.cpp) and the brute-force
# ray march (the accuracy floor of any depth-buffer method; only at 640x360, it is slow).
SEED_ROWS = [("seed-hemisphere", "samples=16", "seed-hemisphere"),
             ("seed-sphere", "samples=16", "seed-sphere")]
RAYMARCH_ROW = ("raymarch", "rays=128,steps=24", "raymarch")


class Plan:
    """What a run measures: the full benchmark or --quick."""

    def __init__(self, quick, size, hd_samples):
        if quick:
            self.scenes = [("contact", SD), ("thin", SD), ("heavy", SD)]
            self.reference_samples = {SD: 256}
            self.heavy_levels = [0, 1, 2]
            self.repeat = 1
            self.library = LIBRARY_QUICK
            self.seed_rows = SEED_ROWS[:1]
            self.raymarch = False
        else:
            sd_scenes = ["contact", "thin", "cavity", "depth_range", "ortho", "heavy"]
            hd_scenes = ["contact", "thin", "cavity", "depth_range", "ortho"]
            self.scenes = [(s, SD) for s in sd_scenes] + [(s, HD) for s in hd_scenes]
            # 1024 spp at 1920x1080 takes about 17 min per scene on 2 cores: 256 by default.
            self.reference_samples = {SD: 1024, HD: hd_samples}
            self.heavy_levels = [0, 1, 2, 3, 4, 5]
            self.repeat = 3
            self.library = LIBRARY_FULL
            self.seed_rows = SEED_ROWS
            self.raymarch = True
        if size is not None:  # one size for every scene (the smoke test's tiny frames)
            samples = min(self.reference_samples.values())
            self.scenes = [(s, size) for s in dict.fromkeys(name for name, _ in self.scenes)]
            self.reference_samples = {size: samples}
        self.noise_scene = "contact"
        # The frame size whose scenes are cropped beside the reference.
        self.crops_size = "%dx%d" % (size or SD)


def label(scene, size, level=0):
    name = scene if level == 0 else "%s-L%d" % (scene, level)
    return "%s@%dx%d" % (name, size[0], size[1])


def log(message):
    print("[%s] %s" % (time.strftime("%H:%M:%S"), message), flush=True)


def fail(message, status=1):
    print("benchmark: error: " + message, file=sys.stderr, flush=True)
    sys.exit(status)


class StepFailed(Exception):
    """A render or an ssao_eval run failed: the scene it belongs to is reported and skipped."""


def run_logged(command, log_path, what):
    """Runs `command`, its output to `log_path`; raises StepFailed with the log's tail if it
    fails."""
    with open(log_path, "w", encoding="utf-8") as out:
        proc = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, check=False)
    if proc.returncode != 0:
        with open(log_path, encoding="utf-8", errors="replace") as f:
            tail = f.readlines()[-25:]
        raise StepFailed("%s failed (exit %d); the end of %s:\n%s"
                         % (what, proc.returncode, log_path, "".join(tail)))


def blender_command(blender, script, arguments):
    return [blender, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
            "-P", script, "--"] + arguments


# ---------------------------------------------------------------------------------------------
# 1. The kit

def scene_source(text, scene):
    """The part of the scenes script (KIT_SCRIPTS[0]) that a render of `scene` depends on: the
    whole text but the other scenes' layout functions and LAYOUTS entries, so that changing or
    adding one scene re-renders that scene alone (a full kit takes about 80 minutes)."""
    lines = text.splitlines(keepends=True)
    drop = set()
    for node in ast.parse(text).body:
        if (isinstance(node, ast.FunctionDef) and node.name.startswith("layout_") and
                node.name != "layout_" + scene):
            drop.update(range(node.lineno - 1, node.end_lineno))
        elif (isinstance(node, ast.Assign) and isinstance(node.value, ast.Dict) and
              any(isinstance(t, ast.Name) and t.id == "LAYOUTS" for t in node.targets)):
            for key, value in zip(node.value.keys, node.value.values):
                if not (isinstance(key, ast.Constant) and key.value == scene):
                    drop.update(range(key.lineno - 1, value.end_lineno))
    return "".join(line for k, line in enumerate(lines) if k not in drop)


def kit_key(blender_version, arguments, sources, scene):
    """The cache key of a kit render of `scene`: what its pixels depend on (the sources, with
    only `scene`'s part of the scenes script, Blender's version and the arguments)."""
    digest = hashlib.sha256()
    for path in sources:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        if path == KIT_SCRIPTS[0]:
            text = scene_source(text, scene)
        digest.update(text.encode())
    digest.update(blender_version.encode())
    digest.update(" ".join(arguments).encode())
    return digest.hexdigest()[:12]


def kit_render(args, blender_version, scene, size, samples, seed=1, border=None, truck_px=None,
               move=None):
    """The prefix of a cached reference render, rendering it first if it is not there; with
    truck_px, a frame of a camera move (scripts/blender/benchmark_sequence.py); with move
    ("NAME,DX,DY,DZ"), one of a moving object (scripts/blender/benchmark_moving.py)."""
    arguments = ["--scene", scene, "--width", str(size[0]), "--height", str(size[1]),
                 "--samples", str(samples), "--seed", str(seed)]
    if border:
        arguments += ["--border", ",".join(str(v) for v in border)]
    script, sources, move_label = KIT_SCRIPTS[0], KIT_SCRIPTS, ""
    if truck_px is not None:
        arguments += ["--truck-px", repr(float(truck_px))]
        script, sources = SEQUENCE_SCRIPT, KIT_SCRIPTS + [SEQUENCE_SCRIPT]
        move_label = "-truck%g" % truck_px
    elif move is not None:
        arguments += ["--move", move]
        script, sources = MOVING_SCRIPT, KIT_SCRIPTS + [SEQUENCE_SCRIPT, MOVING_SCRIPT]
        move_label = "-move" + move.replace(",", "_")
    # The key leaves out the thread count: it changes the render's speed, not its pixels.
    name = "%s-%ds%d%s%s-%s" % (label(scene, size), samples, seed, "-part" if border else "",
                                move_label, kit_key(blender_version, arguments, sources, scene))
    folder = os.path.join(args.kit, name)
    prefix = os.path.join(folder, "ref")
    if os.path.isfile(prefix + ".json"):
        return prefix
    log("kit: rendering %s at %d spp%s (cached in %s)"
        % (label(scene, size), samples, " (noise check)" if border else "", folder))
    partial = folder + ".partial"
    shutil.rmtree(partial, ignore_errors=True)
    os.makedirs(partial)
    start = time.perf_counter()
    run_logged(blender_command(args.blender, script,
                               arguments + ["--threads", str(args.threads),
                                            "--out", os.path.join(partial, "ref")]),
               os.path.join(partial, "blender.log"), "rendering " + label(scene, size))
    shutil.rmtree(folder, ignore_errors=True)
    os.replace(partial, folder)  # complete renders only, under the final name
    log("kit: %s done in %.0f s" % (label(scene, size), time.perf_counter() - start))
    return prefix


def kit_layers(args, blender_version, scene, size, band=GUARD_BAND, truck_px=None):
    """The path of a scene's cached layers file (extra depth layers and a guard band of `band`
    pixels), rendering it first if it is not there; with truck_px, of a frame of a camera move
    (kit_render's)."""
    arguments = ["--scene", scene, "--width", str(size[0]), "--height", str(size[1]),
                 "--overscan", str(band)]
    sources, move_label = LAYERS_SOURCES, ""
    if truck_px is not None:
        arguments += ["--truck-px", repr(float(truck_px))]
        sources, move_label = LAYERS_SOURCES + [SEQUENCE_SCRIPT], "-truck%g" % truck_px
    name = "%s-layers%s-%s" % (label(scene, size), move_label,
                               kit_key(blender_version, arguments, sources, scene))
    folder = os.path.join(args.kit, name)
    path = os.path.join(folder, "ref.layers.exr")
    if os.path.isfile(path):
        return path
    log("kit: rendering the depth layers and a %d px band of %s%s"
        % (band, label(scene, size), move_label))
    partial = folder + ".partial"
    shutil.rmtree(partial, ignore_errors=True)
    os.makedirs(partial)
    run_logged(blender_command(args.blender, LAYERS_SCRIPT,
                               arguments + ["--threads", str(args.threads),
                                            "--out", os.path.join(partial, "ref")]),
               os.path.join(partial, "blender.log"), "the layers of " + label(scene, size))
    shutil.rmtree(folder, ignore_errors=True)
    os.replace(partial, folder)
    return path


# ---------------------------------------------------------------------------------------------
# 2. Cycles' AO pass at fewer samples

def cycles_sweep(args, plan, scene, size, level):
    folder = os.path.join(args.out, "cycles", label(scene, size, level))
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    prefix = os.path.join(folder, "sweep")
    log("cycles: %s at %s spp, %d run(s) each" % (label(scene, size, level),
                                                   ",".join(map(str, CYCLES_SAMPLES)),
                                                   plan.repeat))
    run_logged(blender_command(args.blender, SWEEP_SCRIPT,
                               ["--scene", scene, "--level", str(level), "--width", str(size[0]),
                                "--height", str(size[1]),
                                "--samples", ",".join(map(str, CYCLES_SAMPLES)),
                                "--repeat", str(plan.repeat), "--threads", str(args.threads),
                                "--out", prefix]),
               os.path.join(folder, "blender.log"), "Cycles sweep of " + label(scene, size, level))
    with open(prefix + ".json", encoding="utf-8") as f:
        sweep = json.load(f)
    for run in sweep["runs"]:
        run["file"] = os.path.join(folder, run["file"])
    return sweep


# ---------------------------------------------------------------------------------------------
# 3. Scoring (and timing the library) with ssao_eval

def run_eval(args, reference, runs, repeat, what, layers=None):
    """ssao_eval on the reference render (with its layers file, if any) with one --run per entry
    of `runs` (method and its settings); returns one dict of the result line's fields per run,
    in order."""
    with open(reference + ".json", encoding="utf-8") as f:
        radius = json.load(f)["ao_distance"]
    command = [args.eval, reference + ".exr", "--camera", reference + ".camera.json",
               "--radius", repr(radius), "--repeat", str(repeat)]
    if layers:
        command += ["--layers", layers]
    for method, settings in runs:
        if any(c.isspace() for c in "".join(settings)):
            fail("ssao_eval takes no white space in a setting: %s (move the kit or the output "
                 "folder to a path without spaces)" % settings)
        command += ["--run", " ".join([method] + settings)]
    proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          check=False)
    results = [dict(field.split("=", 1) for field in line.split(" "))
               for line in proc.stdout.splitlines() if line.startswith("scene=")]
    if proc.returncode != 0 or len(results) != len(runs):
        raise StepFailed("ssao_eval failed on %s (exit %d): %s\n%s%s"
                         % (what, proc.returncode, " ".join(command), proc.stdout, proc.stderr))
    for line in proc.stderr.splitlines():  # warnings, and with --layers the hits it dropped
        log("%s: %s" % (what, line))
    return results


def measure_scene(args, plan, reference, scene, size, sweeps, layers=None):
    """CSV rows for one scene and size: the library (with the layers file, if any), the seed
    ports, the ray march, Cycles."""
    entries = []  # (the row's fields known before scoring, the ssao_eval run that scores it)
    for method, setting, settings in plan.library + (LAYER_ROWS if layers else []):
        entries.append(({"method": method, "setting": setting},
                        ("ssao", settings + ["threads=%d" % args.threads])))
    for method, setting, eval_method in plan.seed_rows:
        entries.append(({"method": method, "setting": setting}, (eval_method, [])))
    if plan.raymarch and size == SD:
        entries.append(({"method": RAYMARCH_ROW[0], "setting": RAYMARCH_ROW[1]},
                        (RAYMARCH_ROW[2], [])))
    timed = len(entries)
    for level, sweep in sweeps:
        for run in sweep["runs"]:
            entries.append(({"scene": label(scene, size, level), "method": "cycles",
                             "setting": "samples=%d" % run["samples"],
                             "time_s": run["median_s"], "threads": sweep["threads"]},
                            ("image", ["path=" + run["file"]])))
    log("library: %s, %d configurations x %d run(s), and %d Cycles images"
        % (label(scene, size), timed, plan.repeat, len(entries) - timed))
    try:
        results = run_eval(args, reference, [run for _, run in entries], plan.repeat,
                           label(scene, size), layers)
    except StepFailed as error:
        if not layers:
            raise
        # A layers file that ssao_eval or the library refuses costs the layer rows only, not
        # the scene. (A hit nearer than the reference's depth on a silhouette, where the helper
        # render's first hit differs from the reference's sample 0, is no longer one: ssao_eval
        # drops it as the add-on does. A file of another frame or grid still is.)
        log("layers refused on %s, measured without the layer rows: %s"
            % (label(scene, size), str(error).splitlines()[-1]))
        entries = [entry for entry in entries
                   if (entry[0]["method"], entry[0]["setting"]) not in
                   {(method, setting) for method, setting, _ in LAYER_ROWS}]
        results = run_eval(args, reference, [run for _, run in entries], plan.repeat,
                           label(scene, size))
    rows = []
    for (known, _), result in zip(entries, results):
        row = {"scene": label(scene, size), "time_s": float(result["time_ms"]) / 1000.0,
               "threads": int(result["threads"])}
        row.update(known)
        row.update(rmse=float(result["rmse"]), bias=float(result["mean_error"]),
                   band=float(result["band"]), edge_rmse=float(result["edge_rmse"]))
        rows.append(row)
    return rows


def reference_noise(args, reference, part):
    """RMS per-pixel noise of one reference render: the difference of two renders with other
    seeds over the region both hold, divided by sqrt(2)."""
    with open(part + ".json", encoding="utf-8") as f:
        border = json.load(f)["border"]
    result = run_eval(args, reference, [("image", ["path=" + part + ".exr",
                                                   "region=" + ",".join(map(str, border))])],
                      1, "the noise check")[0]
    return float(result["rmse"]) / math.sqrt(2.0), int(result["pixels"])


# ---------------------------------------------------------------------------------------------
# 4. Results

def pareto_front(points):
    """The points (time, rmse) that no other point beats in both, by increasing time."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def cycles_time_to(rmse, cycles_rows):
    """Time Cycles needs to reach `rmse`, interpolated (log time against log RMSE) along its
    Pareto front; returns (seconds, relation) with relation '<=' or '>=' when `rmse` lies
    outside the measured range."""
    front = pareto_front([(r["time_s"], r["rmse"]) for r in cycles_rows
                          if math.isfinite(r["rmse"]) and r["rmse"] > 0.0])
    if not front or not math.isfinite(rmse):
        return math.nan, "?"
    if rmse >= front[0][1]:
        return front[0][0], "<="
    if rmse <= front[-1][1]:
        return front[-1][0], ">="
    for (t0, e0), (t1, e1) in zip(front, front[1:]):
        if e1 <= rmse <= e0:
            f = (math.log(rmse) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), "="
    raise AssertionError("unreachable")


def speedups(rows):
    """Per scene: our default's time and RMSE, Cycles' time to that RMSE, the ratio."""
    out = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        ours = [r for r in rows if r["scene"] == scene and r["setting"] == "default"]
        cycles = [r for r in rows if r["scene"] == scene and r["method"] == "cycles"]
        if not ours or not cycles:
            continue
        t_cycles, relation = cycles_time_to(ours[0]["rmse"], cycles)
        out.append({"scene": scene, "time_s": ours[0]["time_s"], "rmse": ours[0]["rmse"],
                    "band": ours[0]["band"], "edge_rmse": ours[0]["edge_rmse"],
                    "cycles_s": t_cycles, "relation": relation,
                    "speedup": t_cycles / ours[0]["time_s"]})
    return out


def write_csv(path, columns, rows):
    """RFC 4180 CSV (a setting such as "samples=8,steps=3" is quoted), written atomically."""
    with open(path + ".tmp", "w", encoding="utf-8", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(columns)
        for r in rows:
            writer.writerow([format_value(r[c]) for c in columns])
    os.replace(path + ".tmp", path)


def format_value(value):
    if isinstance(value, float):
        return "%.6g" % value
    return str(value)


def pyplot():
    """matplotlib's pyplot drawing into files (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def series_name(row):
    """The curve a library row belongs to: its variant, plus any setting other than the sample
    count ("hemisphere", "hemisphere steps=3", "sphere classic"), so that a curve varies the
    samples only. Other methods are one curve each."""
    if row["method"] not in ("hemisphere", "sphere", "horizon", "volumetric", "unsharp"):
        return row["method"]
    extra = [part for part in row["setting"].split(",")
             if part != "default"
             and not part.startswith(("samples=", "quality=", "steps=", "resolution="))
             and not part.startswith("clustering=")]
    return " ".join([row["method"]] + extra)


def plot_speed_error(path, rows, truth):
    plt = pyplot()
    scenes = [s for s in dict.fromkeys(r["scene"] for r in rows) if "-L" not in s]
    columns = min(3, len(scenes))
    lines = (len(scenes) + columns - 1) // columns
    fig, axes = plt.subplots(lines, columns, figsize=(5.2 * columns, 4.0 * lines), squeeze=False)
    styles = {"hemisphere": ("C0", "o"), "sphere": ("C1", "s"), "cycles": ("C3", "^"),
              "horizon": ("C5", "P"), "volumetric": ("C6", "X"), "unsharp": ("C7", "*"),
              "seed-hemisphere": ("C2", "D"), "seed-sphere": ("C4", "v"),
              "raymarch": ("C5", "P")}
    for ax, scene in zip(axes.flat, scenes):
        mine = [r for r in rows if r["scene"] == scene]
        for name in dict.fromkeys(series_name(r) for r in mine):
            colour, marker = styles.get(name.split(" ")[0], ("k", "x"))
            points = sorted((r["time_s"], r["rmse"]) for r in mine if series_name(r) == name)
            ax.plot([p[0] for p in points], [p[1] for p in points], marker=marker,
                    color=colour, linestyle="-" if len(points) > 1 else "none", label=name,
                    markersize=5, markerfacecolor=colour if name in styles else "none")
        for r in mine:
            if r["setting"] == "default":
                ax.plot([r["time_s"]], [r["rmse"]], marker="*", color="k", markersize=13,
                        linestyle="none", label="default")
        front = pareto_front([(r["time_s"], r["rmse"]) for r in mine])
        ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="0.5",
                linewidth=3, alpha=0.35, label="Pareto front")
        ax.set_xscale("log")
        ax.set_title(scene)
        ax.set_xlabel("run time (s, log)")
        ax.set_ylabel("RMSE")
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("Run time against RMSE (ground truth: %s; lower left is better)" % truth)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.3 / (4.0 * lines)))
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_complexity(path, complexity):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for samples, colour in zip(sorted({r["samples"] for r in complexity if r["samples"]}),
                               ["C%d" % i for i in range(3, 10)]):
        points = sorted((r["triangles"], r["time_s"]) for r in complexity
                        if r["samples"] == samples)
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="^", color=colour,
                label="Cycles AO pass, %d spp" % samples)
    ours = sorted((r["triangles"], r["time_s"]) for r in complexity if not r["samples"])
    ax.plot([p[0] for p in ours], [p[1] for p in ours], marker="*", color="k", markersize=10,
            label="libssao default")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("triangles in the scene")
    ax.set_ylabel("run time (s)")
    ax.set_title("heavy scene, %s" % complexity[0]["size"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def machine_description(args, blender_version):
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    commit = subprocess.run(["git", "-C", REPO_ROOT, "describe", "--always", "--dirty"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            check=False).stdout.strip()
    return ("%s, %d cores seen (%d threads used), %s; %s; commit %s; %s"
            % (cpu, os.cpu_count() or 0, args.threads, platform.platform(), blender_version,
               commit or "unknown", time.strftime("%Y-%m-%d")))


def markdown_table(header, lines):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in line) + " |" for line in lines]
    return "\n".join(out)


def speedup_table(table):
    """The equal-error speed-up per scene, as a Markdown table."""
    lines = []
    for s in table:
        if s["relation"] == "?":
            cycles, speedup = "n/a", "n/a"
        else:
            relation = "" if s["relation"] == "=" else s["relation"] + " "
            cycles = "%s%.2f s" % (relation, s["cycles_s"])
            speedup = "%s%.1fx" % (relation, s["speedup"])
        lines.append([s["scene"], "%.1f ms" % (1000 * s["time_s"]), "%.4f" % s["rmse"],
                      "%.4f" % s["band"], "%.4f" % s["edge_rmse"], cycles, speedup])
    return markdown_table(["scene", "libssao default", "RMSE", "band", "edge RMSE",
                           "Cycles to the same RMSE", "speed-up"], lines)


def ground_truth(plan):
    """"1024 spp at 640x360, 256 spp at 1920x1080": the reference renders' samples."""
    return ", ".join("%d spp at %dx%d" % (n, w, h)
                     for (w, h), n in sorted(plan.reference_samples.items()))


def rmse_by_size(rows):
    """{"640x360": [rmse, ...], ...} in the order the sizes first appear."""
    by_size = {}
    for r in rows:
        by_size.setdefault(r["scene"].split("@")[1], []).append(r["rmse"])
    return by_size


def error_cell(values, bold=False):
    """"RMSE / band / edge RMSE" of (rmse, band, edge_rmse), as one table cell."""
    text = " / ".join("%.4f" % v for v in values)
    return "**%s**" % text if bold else text


def layers_table(rows):
    """Per scene: the default's RMSE / band / edge RMSE alone, with the extra depth layers, with
    the guard band and with both, and the time with layers and band over the default's; then the
    means."""
    settings = ["default"] + [setting for _, setting, _ in LAYER_ROWS]
    measures = ("rmse", "band", "edge_rmse")
    lines, means = [], {s: [] for s in settings}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        found = {r["setting"]: r for r in rows
                 if r["scene"] == scene and r["method"] == "hemisphere" and r["setting"] in settings}
        if len(found) != len(settings):
            continue
        for s in settings:
            means[s].append([found[s][m] for m in measures])
        lines.append([scene] + [error_cell(found[s][m] for m in measures) for s in settings] +
                     ["%.2fx" % (found[LAYER_ROWS[-1][1]]["time_s"] / found["default"]["time_s"])])
    if not lines:
        return "(no scene has its layers file)"
    lines.append(["**mean**"] + [error_cell((statistics.mean(column) for column in zip(*means[s])),
                                            bold=True) for s in settings] + [""])
    return markdown_table(["scene", "one layer (default)", "+ 2nd to %dth hits" % (EXTRA_LAYERS + 1),
                           "+ %d px band" % GUARD_BAND, "+ both", "time with layers"], lines)


def write_markdown(path, images, args, plan, rows, table, complexity, noise, machine, command,
                   failed):
    """The report; `images` is the folder of the plots relative to it ("" or "images/")."""
    default_rows = [r for r in rows if r["setting"] == "default"]
    lines = [
        "# Performance: run time against error",
        "",
        "Generated by `%s` on %s." % (command, machine),
        "Every figure below comes from that one run; rerun the command to regenerate the page "
        "(the kit of reference renders is cached by content in `build/benchmark_kit`).",
        "",
        "RMSE and bias (mean of method - truth; positive = too little occlusion) are over the "
        "pixels that show geometry (depth finite and below 0.9 x clip_end), against Cycles' AO "
        "pass at %s. Its own per-pixel noise (RMS), measured as the difference of a second "
        "render of the middle of `%s` with another seed, divided by sqrt(2): %s. "
        % (ground_truth(plan), plan.noise_scene,
           ", ".join("%.4f at %s (%d pixels)" % entry for entry in noise)),
        "Times are medians of %d interleaved run(s) of the AO computation alone (libssao "
        "through the C API, %d threads; the seed ports on one thread; each timed run right "
        "after an untimed run of the same method, so that none pays for the one before it) "
        "and of the Cycles "
        "render call (scene sync, BVH build and sampling; %d threads). A Cycles row with "
        "`samples=N` is its AO pass rendered the fastest correct way at N samples per pixel."
        % (plan.repeat, args.threads, args.threads),
        "",
        MEASURES_NOTE,
        "",
        "## Equal-error speed-up over Cycles' AO pass",
        "",
        "The time Cycles needs to reach our default's RMSE (interpolated, log time against "
        "log RMSE, along its Pareto front) over our default's time. `<=` means Cycles at 1 "
        "sample per pixel is already as accurate, so its 1-spp time is an upper bound.",
        "",
        speedup_table(table),
        "",
        "![run time against RMSE](%sspeed_error.png)" % images,
        "",
        "## Beyond one depth layer",
        "",
        "The default with what an offline renderer can add: the 2nd to %dth surface hits "
        "along each pixel's ray with their facing (`depth2` to `depth%d`, `facing2` to "
        "`facing%d`, as the Blender node's default `hidden_surfaces` renders them) and a "
        "%d-pixel guard band around the frame (overscan), rendered by the add-on's helper render "
        "(`scripts/blender/benchmark_layers.py`: Cycles, 1 sample per pixel) on the reference's "
        "pixel grid; as the add-on does, a hit not behind the reference's depth (on a "
        "silhouette the helper's one sample can see the nearer surface) is dropped and the "
        "later ones move up. Each cell: RMSE / band / edge RMSE against the same reference as "
        "above; "
        "the time ratio is the AO computation with %d extra layers and the band over the "
        "default's, the same run." % ((EXTRA_LAYERS + 1,) * 3 + (GUARD_BAND, EXTRA_LAYERS)),
        "",
        layers_table(rows),
        "",
    ]
    if os.path.isfile(os.path.join(args.out, "crops.png")):
        lines += [
            "## Crops beside the reference",
            "",
            "What a mean error does not show: per %s scene, the window of %.1f x the frame "
            "where the default has its largest band error, cut from Cycles' AO pass (the "
            "reference), the default with one layer, the default with the layers and the band, "
            "and Cycles' AO pass at 16 spp (`benchmarks/crops.py`; the window's corner under "
            "the scene's name)." % (plan.crops_size, crops.CROP_FRACTION),
            "",
            "![crops of each method beside the reference](%scrops.png)" % images,
            "",
        ]
    lines += [
        "## Scene complexity",
        "",
        "The heavy scene with every face split in four 0 to %d times: the same shape, so the "
        "same depth and normal passes and the same AO. Cycles' cost grows with the triangles; "
        "libssao reads only the passes, so its time is the one measured on the scene."
        % max(plan.heavy_levels),
        "",
        complexity_table(complexity),
        "",
        "![time against triangle count](%scomplexity.png)" % images,
        "",
        "## Every row",
        "",
        "The same figures as `speed_error.csv` (columns %s)." % ", ".join(CSV_COLUMNS),
        "",
        markdown_table(["scene", "method", "setting", "threads", "time (ms)", "RMSE", "bias",
                        "band", "edge RMSE"],
                       [[r["scene"], r["method"],
                         "**default**" if r["setting"] == "default" else r["setting"],
                         r["threads"], "%.1f" % (1000 * r["time_s"]), "%.4f" % r["rmse"],
                         "%+.4f" % r["bias"], "%.4f" % r["band"], "%.4f" % r["edge_rmse"]]
                        for r in rows]),
        "",
        "Mean RMSE of the default: %s." % "; ".join(
            "%.4f over the %d scene(s) at %s" % (statistics.mean(errors), len(errors), size)
            for size, errors in rmse_by_size(default_rows).items()),
        "",
    ] + METHOD_NOTES
    if failed:
        lines[2:2] = ["", "**Incomplete run: %s failed (see the run's output).**"
                      % ", ".join(failed)]
    # Sections that other benchmarks measure (after KEPT_MARKER) stay as they are.
    if os.path.isfile(path):
        with open(path, encoding="utf-8") as f:
            old = f.read()
        if KEPT_MARKER in old:
            lines += ["", KEPT_MARKER + old.split(KEPT_MARKER, 1)[1].rstrip("\n")]
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    os.replace(path + ".tmp", path)


KEPT_MARKER = "<!-- Below: measured by other benchmarks; speed_error.py keeps it as it is. -->"

# What band and edge RMSE are (ssao_eval --help says the same).
MEASURES_NOTE = (
    "band and edge RMSE say where the error lies, over the same geometry pixels and against the "
    "same reference. band is the RMSE of the difference of the band-passes G(1) - G(6) of the two "
    "images (G(s): a Gaussian blur of sigma s pixels, separable, truncated at 3 sigma, clamp-to-"
    "edge; every pixel that is not geometry set to AO 1 in both images, where Cycles writes 0 in "
    "the sky), over the geometry pixels whose whole 7x7 square (every pixel within 3 px, inside "
    "the frame) is geometry: the error at the scale of contact shadows and creases, without the "
    "large-scale bias that dominates the RMSE (G(1) also smooths away most per-pixel noise: white "
    "noise keeps about a quarter of its RMS). edge RMSE is the RMSE over the geometry pixels with "
    "a depth jump of more than 5 % to a 4-neighbour that is geometry too (|d - d_n| > 0.05 x "
    "min(d, d_n); edges against the sky do not count): the silhouettes, where a depth buffer does "
    "not say what lies behind. Both are 0 for the reference scored against itself.")


METHOD_NOTES = """## How it is measured

`scripts/benchmark.sh [--quick] [--out DIR]` (default DIR `build/benchmark`; `--help` for the
rest) runs `benchmarks/speed_error.py`, which writes `speed_error.csv`, `speed_error.png`,
`complexity.csv`, `complexity.png` and this page into DIR; `--update-docs` copies them into
`docs/`. On 2 cores the full run takes about 40 minutes, plus about 65 minutes the first time
for the reference renders (cached in `build/benchmark_kit`, keyed by the Blender scripts,
Blender's version and the render settings); `--quick` (3 scenes at 640x360, 256-spp
references, fewer settings, one run each) about 2 minutes the first time, 40 s after that.

The scenes (`scripts/blender/benchmark_scenes.py`, plain grey geometry built from scratch; AO
distance = the radius, chosen as an artist would for each layout):

| scene | what it tests | AO distance |
|---|---|---|
| contact | boxes and a sphere on a floor against a wall: contact shadows, a concave corner | 0.8 |
| thin | a fence of 5 cm posts and rails 25 cm in front of a wall, free-standing 6 cm columns, a bench of slats | 0.5 |
| cavity | a bookcase of 2 cm boards with 35 cm deep cells and an open crate in a room corner | 0.5 |
| depth_range | objects 3 to 5 m from the camera against buildings up to 300 m away and the horizon | 1.0 |
| ortho | steps, a grid of blocks, a torus and a sphere under an orthographic camera | 0.6 |
| heavy | spheres, tori and a floor grid, about 9.4k triangles, each face split in four 0-5 times | 0.8 |

- Ground truth: one Cycles render per scene and size with Depth, Normal, Combined (the beauty)
  and the AO pass at 1024 spp at 640x360 and, by default, 256 spp at 1920x1080 (`--hd-samples
  1024` takes about 17 minutes per scene on 2 cores; the noise figure above says what the
  lower count costs: an independent noise of sigma adds in quadrature, so an RMSE of 0.05
  against a reference with sigma = 0.01 reads 0.051).
- Cycles as the alternative (`scripts/blender/cycles_ao_sweep.py`): the same scene rendered for
  the AO pass alone, the fastest way that still writes a correct AO pass: no bounces, lights
  hidden, a plain diffuse material override, only the AO pass (no Combined, Depth or Normal),
  no denoising, no adaptive sampling, no persistent data, another seed than the reference. One
  untimed warm-up render, then the sample counts 1, 2, 4, 8, 16, 64 in interleaved rounds;
  each `bpy.ops.render.render()` call is timed (scene sync, BVH build, sampling; not the file
  write). Its images are scored by the same code as ours. The smoke test checks that this
  set-up's AO pass converges to the ground truth (bias under 0.02 at 64 spp).
- libssao: every configuration in the table through the C API in one `build/bin/ssao_eval`
  process per scene, interleaved rounds (A B C .. A B C ..), median; the time of
  `ssao_job_run` alone (no file I/O). `seed-hemisphere` and `seed-sphere` are line-for-line
  ports of the seed tutorials' code (`tests/reference/seed_ports.cpp`, one thread); `raymarch`
  is the brute-force depth-buffer ray march (128 rays x 24 steps), roughly the accuracy floor
  of any method that sees only the depth buffer (640x360 only).
- Plots with Debian's `python3-matplotlib` (installed by `scripts/install_deps.sh`): the
  standard Python plotting library, already packaged, nothing to download.

Analytic-geometry accuracy and the Cycles test render of the test suite are in
`docs/accuracy.md`.
""".splitlines()


def complexity_table(complexity):
    """Run time against triangle count, as a Markdown table."""
    lines = []
    for triangles in sorted({r["triangles"] for r in complexity}):
        mine = {r["samples"]: r["time_s"] for r in complexity if r["triangles"] == triangles}
        lines.append(["{:,}".format(triangles)]
                     + ["%.2f s" % mine[n] if n in mine else "" for n in CYCLES_SAMPLES]
                     + ["%.1f ms" % (1000 * mine[0])])
    return markdown_table(["triangles"] + ["Cycles %d spp" % n for n in CYCLES_SAMPLES]
                          + ["libssao default"], lines)


# ---------------------------------------------------------------------------------------------

def parse_args():
    parser = argparse.ArgumentParser(
        prog="benchmark.sh",
        description="Run time against error of libssao, the seed tutorial code and Cycles' AO "
                    "pass on reference scenes rendered by Blender (see docs/performance.md).")
    parser.add_argument("--quick", action="store_true",
                        help="3 scenes at 640x360, fewer settings, one run each (about 2 min)")
    parser.add_argument("--out", default=os.path.join(REPO_ROOT, "build", "benchmark"),
                        help="output folder (default build/benchmark)")
    parser.add_argument("--size", default=None, metavar="WxH",
                        help="render every scene at this one size instead (for smoke tests)")
    parser.add_argument("--kit", default=os.path.join(REPO_ROOT, "build", "benchmark_kit"),
                        help="cache of the reference renders (default build/benchmark_kit)")
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                        help="threads for libssao and Cycles (default: every core)")
    parser.add_argument("--hd-samples", type=int, default=256,
                        help="samples per pixel of the 1920x1080 ground truth (default 256; "
                             "640x360 has 1024)")
    parser.add_argument("--kit-only", action="store_true",
                        help="only render (or find) the reference scenes")
    parser.add_argument("--update-docs", action="store_true",
                        help="also copy performance.md and the plots into docs/")
    parser.add_argument("--blender", default=shutil.which("blender") or "blender")
    parser.add_argument("--eval", default=os.path.join(REPO_ROOT, "build", "bin", "ssao_eval"))
    args = parser.parse_args()
    if args.size is not None:
        try:
            w, h = (int(v) for v in args.size.lower().split("x"))
        except ValueError:
            parser.error("--size: expected WxH, e.g. 96x54")
        if not (8 <= w <= 8192 and 8 <= h <= 8192):
            parser.error("--size: width and height must be in 8..8192")
        args.size = (w, h)
    if args.threads < 1:
        parser.error("--threads must be positive")
    if args.hd_samples < 1:
        parser.error("--hd-samples must be positive")
    if not os.path.isfile(args.eval):
        fail("no %s: build the project first (scripts/setup.sh or scripts/build.sh)" % args.eval)
    if shutil.which(args.blender) is None:
        fail("Blender not found ('%s'): install it (scripts/install_deps.sh) or pass --blender"
             % args.blender)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        fail("matplotlib missing: install python3-matplotlib (scripts/install_deps.sh)")
    args.out = os.path.abspath(args.out)
    args.kit = os.path.abspath(args.kit)
    return args


def build_kit(args, plan, blender_version):
    """The reference renders: {(scene, size): (prefix, layers file or None)}, {size: noise-check
    prefix}, failures."""
    references, noise_parts, failed = {}, {}, []
    for scene, size in plan.scenes:
        try:
            prefix = kit_render(args, blender_version, scene, size, plan.reference_samples[size])
        except StepFailed as error:
            log("FAILED: %s" % error)
            failed.append(label(scene, size))
            continue
        try:
            layers = kit_layers(args, blender_version, scene, size)
        except StepFailed as error:
            log("FAILED (the depth layers; the scene is measured without them): %s" % error)
            failed.append(label(scene, size) + " layers")
            layers = None
        references[(scene, size)] = (prefix, layers)
    for size in plan.reference_samples:
        try:
            noise_parts[size] = kit_render(args, blender_version, plan.noise_scene, size,
                                           plan.reference_samples[size], seed=2,
                                           border=NOISE_BORDER)
        except StepFailed as error:
            log("FAILED (the noise check): %s" % error)
    return references, noise_parts, failed


def measure(args, plan, references):
    """Cycles sweeps and ssao_eval runs, scene by scene: (rows, complexity rows, failures). A
    scene that fails is reported and skipped; the others are still measured."""
    rows, complexity, failed = [], [], []
    for (scene, size), (reference, layers) in references.items():
        levels = plan.heavy_levels if scene == "heavy" else [0]
        try:
            sweeps = [(level, cycles_sweep(args, plan, scene, size, level)) for level in levels]
            scene_rows = measure_scene(args, plan, reference, scene, size, sweeps, layers)
        except StepFailed as error:
            log("FAILED: %s" % error)
            failed.append(label(scene, size))
            continue
        rows += scene_rows
        if scene == "heavy":
            ours = next(r for r in scene_rows if r["setting"] == "default")
            for level, sweep in sweeps:
                common = {"size": "%dx%d" % size, "level": level,
                          "triangles": sweep["triangles"]}
                for run in sweep["runs"]:
                    complexity.append(dict(common, method="cycles", samples=run["samples"],
                                           time_s=run["median_s"]))
                complexity.append(dict(common, method="libssao", samples=0,
                                       time_s=ours["time_s"]))
    return rows, complexity, failed


def main():
    args = parse_args()
    plan = Plan(args.quick, args.size, args.hd_samples)
    start = time.perf_counter()
    version = subprocess.run([args.blender, "--version"], stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL, text=True, check=False).stdout.split("\n")
    blender_version = version[0].strip()
    if not blender_version.startswith("Blender"):
        fail("'%s --version' does not say which Blender it is" % args.blender)
    os.makedirs(args.kit, exist_ok=True)
    references, noise_parts, failed = build_kit(args, plan, blender_version)
    if args.kit_only:
        if failed:
            fail("the kit is incomplete: %s failed" % ", ".join(failed))
        log("kit ready in %s (%.0f s)" % (args.kit, time.perf_counter() - start))
        return 0

    noise = []
    for size, part in sorted(noise_parts.items()):
        if (plan.noise_scene, size) in references:
            try:
                sigma, pixels = reference_noise(args, references[(plan.noise_scene, size)][0],
                                                part)
                noise.append((sigma, "%dx%d" % size, pixels))
            except StepFailed as error:
                log("FAILED (the noise check): %s" % error)
    rows, complexity, failed_scenes = measure(args, plan, references)
    failed += failed_scenes
    if not rows:
        fail("nothing was measured: %s failed" % ", ".join(failed))

    os.makedirs(args.out, exist_ok=True)
    write_csv(os.path.join(args.out, "speed_error.csv"), CSV_COLUMNS, rows)
    write_csv(os.path.join(args.out, "complexity.csv"),
              ["size", "level", "triangles", "method", "samples", "time_s"], complexity)
    try:
        crops.write_crops(argparse.Namespace(kit=args.kit, eval=args.eval, size=plan.crops_size,
                                             cycles=os.path.join(args.out, "cycles"),
                                             baseline_lib=None),
                          os.path.join(args.out, "crops.png"))
    except RuntimeError as error:
        log("FAILED (the crops): %s" % error)
        failed.append("crops")
    plot_speed_error(os.path.join(args.out, "speed_error.png"), rows,
                     "Cycles' AO pass at " + ground_truth(plan))
    if complexity:
        plot_complexity(os.path.join(args.out, "complexity.png"), complexity)
    table = speedups(rows)
    machine = machine_description(args, blender_version)
    command = "scripts/benchmark.sh" + (" --quick" if args.quick else "") + (
        " --size %dx%d" % args.size if args.size else "")
    report = (args, plan, rows, table, complexity, noise, machine)
    write_markdown(os.path.join(args.out, "performance.md"), "", *report, command, failed)
    if args.update_docs and failed:
        log("docs/ left as they were: %s failed" % ", ".join(failed))
    elif args.update_docs:
        for name in ("speed_error.png", "complexity.png", "crops.png"):
            if os.path.isfile(os.path.join(args.out, name)):
                shutil.copy(os.path.join(args.out, name), os.path.join(REPO_ROOT, "docs", "images"))
        write_markdown(os.path.join(REPO_ROOT, "docs", "performance.md"), "images/", *report,
                       command + " --update-docs", failed)

    print()
    print("Equal-error speed-up over Cycles' AO pass (%s):" % machine)
    print(speedup_table(table))
    if complexity:
        print()
        print("Scene complexity (heavy scene, %s):" % complexity[0]["size"])
        print(complexity_table(complexity))
    print()
    log("wrote %s/{speed_error.csv,speed_error.png,complexity.csv,complexity.png,crops.png,"
        "performance.md} in %.0f s" % (args.out, time.perf_counter() - start))
    if failed:
        fail("incomplete: %s failed (the files hold the rest)" % ", ".join(failed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
