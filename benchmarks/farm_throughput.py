#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Frames per minute of a shot on a Slurm cluster on localhost (the farm test's cluster) against
one serial ssao process, and what a 1000-frame shot would take on N such machines.

    /usr/bin/python3 benchmarks/farm_throughput.py --ssao build/bin/ssao \\
        [--frames 40] [--chunk-size 10] [--size 1920x1080] [--rounds 2] [--scratch DIR]

The shot is the bundled sample render resampled to --size, each frame's depth scaled a little
(tests/farm/test_slurm.py write_shot); ssao writes beauty x AO + AO as float EXR. Serial: one
process over every frame with --threads 2. Farm: scripts/farm/submit_ssao.sh with 1 core per task,
so the node's 2 cores run two tasks at once, timed from submission until no task is left.
The two alternate (serial, farm, serial, farm, ...); medians reported. Needs root (slurmd).
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "farm"))
from test_slurm import SUBMIT, LocalSlurm, write_shot  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ssao", default=os.path.join(ROOT, "build", "bin", "ssao"))
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--chunk-size", type=int, default=10)
    parser.add_argument("--size", default="1920x1080")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--scratch", default="/tmp/ssao_farm_throughput")
    args = parser.parse_args()
    if os.geteuid() != 0:
        sys.exit("farm_throughput: run as root (slurmd starts the jobs)")
    width, height = (int(v) for v in args.size.split("x"))
    ssao = os.path.abspath(args.ssao)
    shutil.rmtree(args.scratch, ignore_errors=True)
    shot = os.path.join(args.scratch, "shot")
    os.makedirs(shot)
    frames = list(range(1001, 1001 + args.frames))
    print(f"farm_throughput: writing {len(frames)} frames of {width}x{height}...", flush=True)
    write_shot(shot, frames, (width, height))
    ssao_args = [os.path.join(shot, "render.####.exr"), "--camera",
                 os.path.join(shot, "render.camera.json"), "--radius", "0.8",
                 "--frames", f"{frames[0]}-{frames[-1]}"]

    cluster = LocalSlurm(os.path.join(args.scratch, "slurm"))
    serial_times, farm_times = [], []
    try:
        cluster.start()
        env = dict(cluster.env, SSAO_BIN=ssao)
        for round_index in range(args.rounds):
            out = os.path.join(args.scratch, f"serial{round_index}")
            os.makedirs(out)
            start = time.monotonic()
            subprocess.run([ssao, *ssao_args, "-o", os.path.join(out, "ao.####.exr"),
                            "--threads", "2", "--quiet"], check=True)
            serial_times.append(time.monotonic() - start)

            out = os.path.join(args.scratch, f"farm{round_index}")
            os.makedirs(out)
            start = time.monotonic()
            job = cluster.run([SUBMIT, "--chunk-size", str(args.chunk_size), "--cpus-per-task",
                               "1", "--log-dir", os.path.join(out, "logs"), "--", *ssao_args,
                               "-o", os.path.join(out, "ao.####.exr")], env=env).stdout.strip()
            tasks = cluster.wait_for_job(job)
            farm_times.append(time.monotonic() - start)
            bad = {t: state for t, state in tasks.items() if state != ("COMPLETED", "0:0")}
            if bad:
                sys.exit(f"farm_throughput: job {job} had failed tasks: {bad}")
            print(f"  round {round_index + 1}: serial {serial_times[-1]:.1f} s, farm "
                  f"{farm_times[-1]:.1f} s", flush=True)
    finally:
        cluster.stop()

    serial, farm = statistics.median(serial_times), statistics.median(farm_times)
    chunks = -(-len(frames) // args.chunk_size)
    print(f"\n{len(frames)} frames of {width}x{height} (beauty x AO + AO, float EXR), 2 cores, "
          f"median of {args.rounds} rounds:")
    print("| run | wall | frames per minute |\n|---|--:|--:|")
    print(f"| serial, 1 process, --threads 2 | {serial:.1f} s | {60 * len(frames) / serial:.1f} |")
    print(f"| Slurm array, {chunks} chunks of {args.chunk_size}, 1 core per task | {farm:.1f} s | "
          f"{60 * len(frames) / farm:.1f} |")
    per_frame = farm / len(frames)
    print(f"\nA 1000-frame shot by this measure: {1000 * per_frame / 60:.1f} min on one such "
          f"2-core machine; {1000 * per_frame / 60 / 10:.1f} min on 10, "
          f"{1000 * per_frame / 60 / 50:.2f} min on 50 (chunks permitting; reading and writing "
          f"the EXRs over a shared file system not included).")


if __name__ == "__main__":
    main()
