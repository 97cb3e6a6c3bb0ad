#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Accuracy and run time of libssao and the reference methods against Cycles' AO pass.

For every scene NAME in DATA_DIR (NAME.exr: Blender multilayer with Depth, Normal and the AO
pass; NAME.camera.json; NAME.json with "ao_distance", the AO radius), runs build/bin/ssao_eval
for each configuration below and prints one Markdown table:

    scene | method | samples | RMSE | mean error | time (ms) | threads | time / default

RMSE and mean signed error (method - truth) are over the pixels with a finite depth below
0.9 x clip_end. Times are the best of --repeat runs of the AO computation alone; "time / default"
is the row's time divided by that of libssao's default configuration (hemisphere) on the same
scene in the same run (below 1 = faster). The seed ports run on one thread, libssao and the ray
march on every core unless --threads is given (it applies to libssao only).

    /usr/bin/python3 benchmarks/run_cycles_benchmark.py [DATA_DIR] [--repeat 3]
        [--scenes crates,shelf] [--config variant=sphere,samples=32 ...]

DATA_DIR defaults to ../shared/data relative to the repository root. Exit status: 0 success,
1 a run of ssao_eval failed, 2 a usage error (no data folder, no scenes, no ssao_eval).
"""
import argparse
import json
import os
import subprocess
import sys

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_DATA_DIR = os.path.normpath(os.path.join(REPO_ROOT, "..", "shared", "data"))
DEFAULT_EVAL = os.path.join(REPO_ROOT, "build", "bin", "ssao_eval")

# (label, ssao_eval method, --set arguments, samples column). The first row is the default
# configuration the time ratios refer to.
CONFIGS = [
    ("ssao hemisphere (defaults)", "ssao", [], None),
    ("ssao hemisphere", "ssao", ["variant=hemisphere", "samples=8"], None),
    ("ssao hemisphere", "ssao", ["variant=hemisphere", "samples=32"], None),
    ("ssao sphere (defaults)", "ssao", ["variant=sphere"], None),
    ("seed-hemisphere", "seed-hemisphere", [], None),
    ("seed-sphere", "seed-sphere", [], None),
    ("raymarch", "raymarch", [], "128 rays x 24 steps"),
]


def fail_usage(message):
    print("run_cycles_benchmark: error: " + message, file=sys.stderr)
    sys.exit(2)


def parse_args():
    parser = argparse.ArgumentParser(
        description="Accuracy and run time of libssao and the reference methods against "
                    "Cycles' AO pass (see the module docstring).")
    parser.add_argument("data_dir", nargs="?", default=None,
                        help="folder with NAME.exr, NAME.camera.json, NAME.json "
                             "(default: ../shared/data relative to the repository root)")
    parser.add_argument("--scenes", default=None,
                        help="comma-separated scene names (default: every NAME.exr in DATA_DIR "
                             "with its NAME.camera.json and NAME.json)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="time this many runs, report the fastest (default 3)")
    parser.add_argument("--threads", type=int, default=0,
                        help="threads for libssao (default 0: every core)")
    parser.add_argument("--config", action="append", default=[],
                        help="an extra libssao row: comma-separated NAME=VALUE core parameters, "
                             "e.g. variant=sphere,samples=32; normals=none ignores the Normal "
                             "pass (repeatable)")
    parser.add_argument("--eval", default=DEFAULT_EVAL,
                        help="path to ssao_eval (default: build/bin/ssao_eval)")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    if args.threads < 0:
        parser.error("--threads must not be negative")
    return args


def find_scenes(data_dir, names):
    if names is None:
        names = sorted(f[:-len(".exr")] for f in os.listdir(data_dir) if f.endswith(".exr"))
        names = [n for n in names
                 if os.path.isfile(os.path.join(data_dir, n + ".camera.json"))
                 and os.path.isfile(os.path.join(data_dir, n + ".json"))]
        if not names:
            fail_usage("no scene in '%s' (expected NAME.exr with NAME.camera.json and NAME.json)"
                       % data_dir)
    else:
        names = [n for n in names.split(",") if n]
    scenes = []
    for name in names:
        exr = os.path.join(data_dir, name + ".exr")
        camera = os.path.join(data_dir, name + ".camera.json")
        meta_path = os.path.join(data_dir, name + ".json")
        for path in (exr, camera, meta_path):
            if not os.path.isfile(path):
                fail_usage("scene '%s': no file '%s'" % (name, path))
        with open(meta_path, encoding="utf-8") as f:
            meta = json.load(f)
        if "ao_distance" not in meta:
            fail_usage("'%s' has no \"ao_distance\" (the AO radius)" % meta_path)
        scenes.append({"name": name, "exr": exr, "camera": camera,
                       "radius": float(meta["ao_distance"])})
    return scenes


def extra_configs(texts):
    """The --config rows: (label, method, --set arguments, samples column)."""
    configs = []
    for text in texts:
        settings = [item.strip() for item in text.split(",") if item.strip()]
        for item in settings:
            if "=" not in item:
                fail_usage("--config '%s': '%s' is not NAME=VALUE" % (text, item))
        configs.append(("ssao " + ",".join(settings), "ssao", settings, None))
    return configs


def run_eval(args, scene, method, settings):
    command = [args.eval, scene["exr"], "--camera", scene["camera"],
               "--radius", repr(scene["radius"]), "--method", method,
               "--repeat", str(args.repeat)]
    if "normals=none" in settings:
        settings = [s for s in settings if s != "normals=none"]
        command.append("--no-normals")
    if method == "ssao" and args.threads:
        settings = settings + ["threads=%d" % args.threads]
    for setting in settings:
        command += ["--set", setting]
    proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          check=False)
    if proc.returncode != 0:
        print("run_cycles_benchmark: ssao_eval failed (exit %d): %s\n%s%s"
              % (proc.returncode, " ".join(command), proc.stdout, proc.stderr), file=sys.stderr)
        sys.exit(1)
    for line in proc.stdout.splitlines():
        if line.startswith("scene="):
            # key=value fields separated by spaces; the value may contain '=' (settings).
            return dict(field.split("=", 1) for field in line.split(" "))
    print("run_cycles_benchmark: no result line from: %s\n%s" % (" ".join(command), proc.stdout),
          file=sys.stderr)
    sys.exit(1)


def samples_column(method, result, fixed):
    if fixed:
        return fixed
    settings = dict(item.split("=", 1) for item in result["settings"].split(","))
    return settings.get("samples", "")


def main():
    args = parse_args()
    data_dir = args.data_dir
    if data_dir is None:
        data_dir = DEFAULT_DATA_DIR
        if not os.path.isdir(data_dir):
            fail_usage("no data folder given and the default '%s' does not exist; pass the "
                       "folder with the scenes (NAME.exr, NAME.camera.json, NAME.json)"
                       % data_dir)
    elif not os.path.isdir(data_dir):
        fail_usage("no folder '%s'" % data_dir)
    if not (os.path.isfile(args.eval) and os.access(args.eval, os.X_OK)):
        fail_usage("no ssao_eval at '%s': build it first (cmake --build build --target "
                   "ssao_eval) or pass --eval" % args.eval)
    scenes = find_scenes(data_dir, args.scenes)
    configs = CONFIGS + extra_configs(args.config)

    header = ["scene", "method", "samples", "RMSE", "mean error", "time (ms)", "threads",
              "time / default"]
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join(["---"] * 2 + ["--:"] * (len(header) - 2)) + "|")
    sys.stdout.flush()
    rmse_sums = {}
    for scene in scenes:
        default_ms = None
        for label, method, settings, fixed_samples in configs:
            result = run_eval(args, scene, method, settings)
            ms = float(result["time_ms"])
            if default_ms is None:
                default_ms = ms
            samples = samples_column(method, result, fixed_samples)
            ratio = ms / default_ms if default_ms > 0 else float("nan")
            print("| %s | %s | %s | %.4f | %+.4f | %.1f | %s | %.2f |"
                  % (scene["name"], label, samples, float(result["rmse"]),
                     float(result["mean_error"]), ms, result["threads"], ratio))
            sys.stdout.flush()
            key = (label, samples)
            rmse_sums.setdefault(key, []).append(float(result["rmse"]))
    if len(scenes) > 1:
        print()
        print("| method | samples | mean RMSE over %d scenes |" % len(scenes))
        print("|---|--:|--:|")
        for (label, samples), values in rmse_sums.items():
            print("| %s | %s | %.4f |" % (label, samples, sum(values) / len(values)))


if __name__ == "__main__":
    main()
