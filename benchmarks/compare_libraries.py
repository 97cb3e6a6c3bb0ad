#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Times two builds of libssao on the same frame in one process: before/after figures for a
change to a hot path.

    /usr/bin/python3 benchmarks/compare_libraries.py --baseline OLD/libssao.so \\
        [--candidate build/lib/libssao.so] SCENE.exr --camera CAM.json --radius R \\
        [--threads 2] [--repeat 7] [--set NAME=VALUE ...] [--baseline-set NAME=VALUE ...]

Reads Depth and Normal from a Blender multilayer EXR (as ssao_eval does), runs the baseline and
the candidate in interleaved rounds (B C B C ...) after one untimed round each, and prints the
median and fastest time of each, their ratio, and the largest AO difference between the two.
--set applies to both libraries, --baseline-set / --candidate-set to one.
The beauty (<layer>.Combined.R/G/B), when the file has one, is attached too, as the command
line attaches it (edge_coverage reads it; --no-beauty leaves it out).
--baseline-layers N / --candidate-layers N attach the scene's first N extra depth layers
(<layer>.Depth2.Z with .Facing2.V, ..., as scripts/blender/render_layers.py writes them) to one
library: with the same .so for both, the ratio is what the layers cost.
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "core", "python"))
import ssao  # noqa: E402


def read_passes(path):
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit(f"compare_libraries: cannot open {path}: {oiio.geterror()}")
    names = list(image.spec().channelnames)
    pixels = image.read_image(format="float")
    image.close()

    def find(suffixes):
        for suffix in suffixes:
            for i, name in enumerate(names):
                if name.endswith(suffix):
                    return i
        sys.exit(f"compare_libraries: {path} has no channel ending in {suffixes[0]}")
    depth = np.ascontiguousarray(pixels[:, :, find(["Depth.Z", "Depth.V"])])
    normal = np.ascontiguousarray(pixels[:, :, [find(["Normal.X"]), find(["Normal.Y"]),
                                                find(["Normal.Z"])]])
    layers = []  # (depth, facing or None) of hits 2, 3, ... up to the first missing
    for hit in range(2, 6):
        depth_index = next((i for i, n in enumerate(names) if n.endswith(f"Depth{hit}.Z")), None)
        if depth_index is None:
            break
        facing_index = next((i for i, n in enumerate(names) if n.endswith(f"Facing{hit}.V")),
                            None)
        layers.append((np.ascontiguousarray(pixels[:, :, depth_index]),
                       None if facing_index is None
                       else np.ascontiguousarray(pixels[:, :, facing_index])))
    colour = [next((i for i, n in enumerate(names) if n.endswith(f"Combined.{c}")), None)
              for c in "RGB"]
    beauty = None if None in colour else np.ascontiguousarray(pixels[:, :, colour])
    return depth, normal, layers, beauty


def camera_parameters(path):
    """A camera file's library parameters, as the CLI and the module read it."""
    with open(path) as f:
        return ssao.camera_parameters(json.load(f))


def parse_sets(items):
    out = {}
    for item in items:
        name, _, value = item.partition("=")
        out[name] = value
    return out


class Runner:
    def __init__(self, path, params, depth, normal, layers, beauty, sequence=False):
        self.lib = ssao.load_library(path)
        self.ao = np.zeros(depth.shape, np.float32)
        self.job = ssao.Job(self.lib)
        types = {p["name"]: p["type"] for p in ssao.parameters(self.lib)}
        # --sequence: every run is the next frame of a sequence (a library without the frame
        # parameter runs them as it always did).
        self.next_frame = 0 if sequence and "frame" in types else None
        for name, value in params.items():
            if types.get(name) == ssao.PARAM_INT:
                value = int(value)
            elif types.get(name) == ssao.PARAM_FLOAT:
                value = float(value)
            self.job.set(name, value)
        self.job.set_image("depth", depth)
        self.job.set_image("normal", normal)
        for hit, (layer_depth, facing) in enumerate(layers, start=2):
            self.job.set_image(f"depth{hit}", layer_depth)
            if facing is not None:
                self.job.set_image(f"facing{hit}", facing)
        self.job.set_image("ao", self.ao)
        if beauty is not None:  # with the composite, as the command line runs
            self.composite = np.zeros(beauty.shape, np.float32)
            self.job.set_image("beauty", beauty)
            self.job.set_image("composite", self.composite)
        self.times = []

    def run(self, timed=True):
        if self.next_frame is not None:
            self.job.set("frame", self.next_frame)
            self.next_frame += 1
        start = time.perf_counter()
        self.job.run()
        if timed:
            self.times.append(time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--baseline", required=True, help="the libssao.so to compare against")
    parser.add_argument("--candidate", default=None, help="default: build/lib/libssao.so")
    parser.add_argument("--camera", required=True)
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--set", action="append", default=[])
    parser.add_argument("--baseline-set", action="append", default=[])
    parser.add_argument("--candidate-set", action="append", default=[])
    parser.add_argument("--baseline-layers", type=int, default=0, metavar="N")
    parser.add_argument("--candidate-layers", type=int, default=0, metavar="N")
    parser.add_argument("--no-beauty", action="store_true",
                        help="leave the scene's beauty (Combined) out")
    parser.add_argument("--sequence", action="store_true",
                        help="run each library's job as consecutive frames of a sequence "
                             "(parameter frame 0, 1, 2, ...): the cost of a frame whose "
                             "temporal filter has its earlier frames")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")

    depth, normal, layers, beauty = read_passes(args.scene)
    if args.no_beauty:
        beauty = None
    for flag, count in (("--baseline-layers", args.baseline_layers),
                        ("--candidate-layers", args.candidate_layers)):
        if not 0 <= count <= len(layers):
            parser.error(f"{flag} {count}: {args.scene} has {len(layers)} extra depth layers")
    common = camera_parameters(args.camera)
    common.update(radius=args.radius, threads=args.threads)
    common.update(parse_sets(args.set))
    candidate = args.candidate or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                               "build", "lib", "libssao.so")
    runners = {"baseline": Runner(args.baseline, {**common, **parse_sets(args.baseline_set)},
                                  depth, normal, layers[:args.baseline_layers], beauty,
                                  args.sequence),
               "candidate": Runner(candidate, {**common, **parse_sets(args.candidate_set)},
                                   depth, normal, layers[:args.candidate_layers], beauty,
                                   args.sequence)}
    for r in runners.values():
        r.run(timed=False)
    for _ in range(args.repeat):
        for r in runners.values():
            r.run()
    height, width = depth.shape
    print(f"frame {width}x{height}, threads {args.threads}, {args.repeat} interleaved rounds, "
          f"extra depth layers: baseline {args.baseline_layers}, "
          f"candidate {args.candidate_layers}; beauty "
          f"{'attached (with the composite)' if beauty is not None else 'none'}")
    for name, r in runners.items():
        print(f"{name:9s} median {1e3 * statistics.median(r.times):9.2f} ms  "
              f"min {1e3 * min(r.times):9.2f} ms")
    b, c = (statistics.median(runners[k].times) for k in ("baseline", "candidate"))
    diff = float(np.abs(runners["baseline"].ao - runners["candidate"].ao).max())
    print(f"speed-up {b / c:.2f}x (median baseline / median candidate); "
          f"max |AO difference| {diff:.4g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
