# SPDX-License-Identifier: MIT
"""The Flamenco job type scripts/farm/flamenco/ssao-sequence.js (ctest label "farm"): compiled
with node as a Flamenco Manager would (tests/farm/flamenco_job.js), its tasks' commands run for
real: every frame written, equal bit for bit to a serial run; bad settings refused.

    /usr/bin/python3 tests/farm/test_flamenco.py --ssao build/bin/ssao --scratch DIR
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_slurm import FRAMES, ROOT, read_image, report, write_shot  # noqa: E402

JOB_TYPE = os.path.join(ROOT, "scripts", "farm", "flamenco", "ssao-sequence.js")
HARNESS = os.path.join(HERE, "flamenco_job.js")


def compile_job(settings):
    return subprocess.run(["node", HARNESS, JOB_TYPE, json.dumps(settings)], capture_output=True,
                          text=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ssao", required=True)
    parser.add_argument("--scratch", required=True)
    args = parser.parse_args()
    failures = []
    if shutil.which("node") is None:
        print("FAIL: node is not installed (scripts/install_deps.sh installs nodejs)")
        return 1
    syntax = subprocess.run(["node", "--check", JOB_TYPE], capture_output=True, text=True)
    if syntax.returncode != 0:
        print(f"FAIL: {JOB_TYPE} does not parse:\n{syntax.stderr}")
        return 1

    scratch = os.path.abspath(args.scratch)
    shutil.rmtree(scratch, ignore_errors=True)
    shot, farm, serial = (os.path.join(scratch, d) for d in ("shot", "flamenco", "serial"))
    for folder in (shot, farm, serial):
        os.makedirs(folder)
    write_shot(shot)
    frames = f"{FRAMES[0]}-{FRAMES[-1]}"
    common = {"ssao": os.path.abspath(args.ssao), "input": os.path.join(shot, "render.####.exr"),
              "camera": os.path.join(shot, "render.camera.json"), "frames": frames,
              "chunk_size": 4, "radius": 0.8, "extra_args": "--threads 1  --quiet"}
    compiled = compile_job(dict(common, output=os.path.join(farm, "ao.####.exr")))
    if compiled.returncode != 0:
        print(f"FAIL: compileJob failed:\n{compiled.stderr}")
        return 1
    tasks = json.loads(compiled.stdout)["tasks"]
    names = [t["name"] for t in tasks]
    if names != ["ssao-1001-1004", "ssao-1005-1008", "ssao-1009-1011"]:
        failures.append(f"tasks {names}")
    for task in tasks:
        for command in task["commands"]:
            if command["type"] != "exec":
                failures.append(f"{task['name']}: command type {command['type']}")
                continue
            p = command["parameters"]
            run = subprocess.run([p["exe"], *p["args"]], capture_output=True, text=True)
            if run.returncode != 0:
                failures.append(f"{task['name']}: exit {run.returncode}: {run.stderr}")

    subprocess.run([args.ssao, common["input"], "--camera", common["camera"], "--radius", "0.8",
                    "--frames", frames, "-o", os.path.join(serial, "ao.####.exr"), "--quiet"],
                   check=True)
    for frame in FRAMES:
        name = f"ao.{frame:04d}.exr"
        if not os.path.isfile(os.path.join(farm, name)):
            failures.append(f"frame {frame}: no {name}")
            continue
        a_names, a = read_image(os.path.join(farm, name))
        b_names, b = read_image(os.path.join(serial, name))
        if a_names != b_names or not np.array_equal(a, b):
            failures.append(f"frame {frame}: differs from the serial run")

    for bad, phrase in (({"extra_args": "--frames 1-3"}, "set by the job type"),
                        ({"chunk_size": 0}, "chunk_size must be at least 1"),
                        ({"radius": -1}, "radius must be 0 or more")):
        result = compile_job(dict(common, output=os.path.join(farm, "x.####.exr"), **bad))
        if result.returncode == 0 or phrase not in result.stderr:
            failures.append(f"settings {bad}: expected '{phrase}', got exit {result.returncode}: "
                            f"{result.stderr}")

    print(f"flamenco: {len(tasks)} tasks for frames {frames} in chunks of 4, every frame equal "
          "to the serial run" if not failures else "flamenco: failures")
    return report("flamenco", failures)


if __name__ == "__main__":
    sys.exit(main())
