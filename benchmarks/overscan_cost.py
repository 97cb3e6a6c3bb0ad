#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""What a guard band (overscan) costs: the frame computed with a band of --band pixels around
it (ssao_job_set_output_window) against the same frame alone, in one process, interleaved.

    /usr/bin/python3 benchmarks/overscan_cost.py SCENE.exr --camera CAM.json --radius R \\
        [--band 64] [--library build/lib/libssao.so] [--threads 2] [--repeat 9]

SCENE.exr stands for the render with its band: its middle, --band pixels in from each side, is
the frame (the camera file's sensor width is narrowed to it on the same pixel grid). Prints the
median time of each, their ratio, and how much the band changes the frame's AO.
"""
import argparse
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "python"))
import ssao  # noqa: E402
from compare_libraries import camera_parameters, read_passes  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--camera", required=True)
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--band", type=int, default=64)
    parser.add_argument("--library", default=None)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=9)
    args = parser.parse_args()
    lib = ssao.load_library(args.library)
    depth, normal = read_passes(args.scene)
    height, width = depth.shape
    band = args.band
    if not 0 <= 2 * band < min(width, height):
        sys.exit(f"overscan_cost: a band of {band} px does not fit {width}x{height}")
    frame_width, frame_height = width - 2 * band, height - 2 * band
    params = camera_parameters(args.camera)
    # The frame's camera: the sensor spans the frame's width on the same pixel grid.
    params["sensor_width"] = params["sensor_width"] * frame_width / width
    params.update(radius=args.radius, threads=args.threads)

    def job_for(depth_image, normal_image):
        job = ssao.Job(lib)
        for name, value in params.items():
            job.set(name, value)
        job.set_image("depth", depth_image)
        job.set_image("normal", normal_image)
        ao = np.zeros((frame_height, frame_width), np.float32)
        job.set_image("ao", ao)
        return job, ao

    inner = (slice(band, band + frame_height), slice(band, band + frame_width))
    alone, alone_ao = job_for(np.ascontiguousarray(depth[inner]),
                              np.ascontiguousarray(normal[inner]))
    banded, banded_ao = job_for(depth, normal)
    banded.set_output_window(band, band)
    times = {"frame alone": [], "frame + band": []}
    for job in (alone, banded):
        job.run()  # untimed: threads, tables
    for _ in range(args.repeat):
        for name, job in (("frame alone", alone), ("frame + band", banded)):
            start = time.perf_counter()
            job.run()
            times[name].append(time.perf_counter() - start)
    print(f"frame {frame_width}x{frame_height}, band {band} px ({width}x{height} in all), "
          f"threads {args.threads}, {args.repeat} interleaved rounds")
    for name, values in times.items():
        print(f"{name:13s} median {1e3 * statistics.median(values):8.2f} ms  "
              f"min {1e3 * min(values):8.2f} ms")
    ratio = statistics.median(times["frame + band"]) / statistics.median(times["frame alone"])
    print(f"the band costs {ratio:.2f}x the frame alone; pixels {width * height / (frame_width * frame_height):.2f}x")
    difference = np.abs(banded_ao - alone_ao)
    print(f"|AO with band - AO alone|: mean {difference.mean():.4f}, max {difference.max():.4f}; "
          f"{100.0 * (difference > 0.01).mean():.1f}% of the frame's pixels differ by > 0.01")
    alone.close()
    banded.close()


if __name__ == "__main__":
    main()
