#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Two costs of a frame that the speed/error benchmark does not show: how much a frame that is
mostly sky costs next to the same frame fully covered, and the library's peak memory on a 4K
frame.

    /usr/bin/python3 benchmarks/frame_costs.py SCENE.exr --camera CAM.json --radius R \\
        [--library build/lib/libssao.so] [--threads 2] [--repeat 7] [--sky 0.8]

Sky: the scene's frame with every background pixel moved onto the farthest surface (100%
geometry), against the same frame with its top --sky fraction of rows made background; the two
run in interleaved rounds after an untimed one, medians reported.
Memory: in a fresh process, the frame repeated to 3840x2160; the rise of the process's peak
resident memory over one run, after the inputs are allocated and a small warm-up run has started
the library's threads. Reported in MB and in float buffers of the image size.
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "python"))
import ssao  # noqa: E402
from compare_libraries import camera_parameters, read_passes  # noqa: E402


def make_job(lib, params, depth, normal):
    job = ssao.Job(lib)
    for name, value in params.items():
        job.set(name, value)
    ao = np.zeros(depth.shape, np.float32)
    job.set_image("depth", depth)
    job.set_image("normal", normal)
    job.set_image("ao", ao)
    return job, ao


def sky_ratio(lib, params, depth, normal, sky, repeat):
    finite = np.isfinite(depth) & (depth > 0) & (depth < 1e9)
    covered = np.where(finite, depth, depth[finite].max()).astype(np.float32)
    skyward = covered.copy()
    skyward[: int(round(sky * depth.shape[0])), :] = np.inf
    jobs = {"covered": make_job(lib, params, covered, normal)[0],
            "sky": make_job(lib, params, skyward, normal)[0]}
    times = {name: [] for name in jobs}
    for job in jobs.values():
        job.run()
    for _ in range(repeat):
        for name, job in jobs.items():
            start = time.perf_counter()
            job.run()
            times[name].append(time.perf_counter() - start)
    medians = {name: statistics.median(t) for name, t in times.items()}
    geometry = 1.0 - float(np.isinf(skyward).mean())
    print(f"sky: frame {depth.shape[1]}x{depth.shape[0]}, threads {params['threads']}, "
          f"{repeat} interleaved rounds")
    print(f"  fully covered        median {1e3 * medians['covered']:8.2f} ms")
    print(f"  {100 * (1 - geometry):.0f}% sky, {100 * geometry:.0f}% geometry "
          f"median {1e3 * medians['sky']:8.2f} ms")
    print(f"  ratio {medians['sky'] / medians['covered']:.3f} (sky / covered)")


def memory_peak(lib_path, params, depth, normal):
    """Runs in a child process so that nothing else has raised its peak."""
    lib = ssao.load_library(lib_path)
    big_depth = np.ascontiguousarray(np.repeat(np.repeat(depth, 2, 0), 2, 1))
    big_normal = np.ascontiguousarray(np.repeat(np.repeat(normal, 2, 0), 2, 1))
    small, _ = make_job(lib, params, depth[:64, :64].copy(), normal[:64, :64].copy())
    small.run()  # starts the thread pool
    job, ao = make_job(lib, params, big_depth, big_normal)
    ao[:] = 0.0  # touch every output page before measuring
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    job.run()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    height, width = big_depth.shape
    buffer = width * height * 4
    rise = peak - before
    print(f"memory: frame {width}x{height}, threads {params['threads']}: peak resident memory "
          f"rose by {rise / 1e6:.1f} MB over one run = {rise / buffer:.2f} float buffers of the "
          f"image size ({buffer / 1e6:.1f} MB each)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--camera", required=True)
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--library", default=None, help="default: build/lib/libssao.so")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--sky", type=float, default=0.8, help="fraction of rows made sky")
    parser.add_argument("--memory-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if not 0.0 < args.sky < 1.0:
        parser.error("--sky must be in (0, 1)")
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    depth, normal = read_passes(args.scene)
    params = camera_parameters(args.camera)
    params.update(radius=args.radius, threads=args.threads)
    if args.memory_child:
        memory_peak(args.library, params, depth, normal)
        return 0
    sky_ratio(ssao.load_library(args.library), params, depth, normal, args.sky, args.repeat)
    child = subprocess.run([sys.executable, os.path.abspath(__file__), "--memory-child",
                            *sys.argv[1:]], check=False)
    return child.returncode


if __name__ == "__main__":
    sys.exit(main())
