#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Where a sequence frame's time goes in build/bin/ssao on a production-sized EXR: a 1920x1080
Blender multilayer file with 32 channels (color passes half, data passes float, ZIP, about
49 MB), run as `ssao IN.####.exr -o OUT.####.exr --camera cam.json --frames 1-N`.

    # the input: N copies of one synthetic frame, and its camera file
    /usr/bin/python3 benchmarks/exr_frame_cost.py make --out /tmp/exr_cost [--frames 8]
        [--multipart] [--width 1920 --height 1080]
    # per-frame wall time of one or more builds, interleaved rounds, median
    /usr/bin/python3 benchmarks/exr_frame_cost.py time --dir /tmp/exr_cost \\
        --ssao before=/tmp/ssao_before/bin/ssao --ssao after=build/bin/ssao [--rounds 5]
        [--threads 2] [-- extra ssao flags, e.g. --ao-only]
    # the stages of a frame, from perf samples (CPU time, ms per frame)
    /usr/bin/python3 benchmarks/exr_frame_cost.py profile --dir /tmp/exr_cost \\
        --ssao after=build/bin/ssao [--threads 2]

The scene (synthesized, so that the script needs no renders): a floor, a back wall and spheres
and boxes under a sky, seen by a perspective camera; Depth, Normal (world space), Vector, Mist and
IndexOB are exact, the color passes carry independent noise like a path tracer's at a few
hundred samples, which is what makes them compress about as badly as real renders do.

`time` runs each build (`--ssao LABEL=PATH`; each build's `lib/` beside its `bin/` comes first on
LD_LIBRARY_PATH, so a copied tree loads its own image codec module) on frames 1-N once per round,
in turn (A B A B ...), and reports the median over rounds of the per-frame time: the total wall
time of the process less that of a one-frame run, over N - 1 frames, so the process start and
the first frame (whose read nothing overlaps) drop out.

`profile` records the same sequence with `perf record --call-graph dwarf` and sorts every sample
by what it was doing: EXR decode (OpenEXR, zlib inflate, OpenImageIO's conversion to float under
the read), EXR encode (the write, zlib deflate), AO (libssao), ours (the tool's own code: pass
extraction, output assembly, its buffers' page faults and zeroing), start-up (the dynamic loader,
OpenImageIO's plugin set-up), other. CPU time, so stages that overlap (the next frame is read
while this one computes) are counted in full.
"""
import argparse
import collections
import json
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

# Blender's pass names and components; color passes are half when Blender writes "Float
# (Half)", data passes stay float. 32 channels.
PASSES = [
    ("Combined", "RGBA", "half"),
    ("Depth", "Z", "float"),
    ("Mist", "Z", "float"),
    ("Normal", "XYZ", "float"),
    ("Vector", "XYZW", "float"),
    ("IndexOB", "X", "float"),
    ("AO", "RGB", "half"),
    ("DiffCol", "RGB", "half"),
    ("DiffDir", "RGB", "half"),
    ("DiffInd", "RGB", "half"),
    ("GlossCol", "RGB", "half"),
    ("GlossDir", "RGB", "half"),
]
LAYER = "ViewLayer"
SKY_DEPTH = 1e10
CAMERA_TO_WORLD = [[1.0, 0.0, 0.0, 0.0],
                   [0.0, 0.3420201433, -0.9396926208, -10.0],
                   [0.0, 0.9396926208, 0.3420201433, 4.0],
                   [0.0, 0.0, 0.0, 1.0]]  # looking along +Y, 20 degrees down, from 4 up
CAMERA = {"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
          "sensor_fit": "AUTO", "shift_x": 0.0, "shift_y": 0.0, "ortho_scale": 6.0,
          "clip_start": 0.1, "clip_end": 100.0, "matrix_world": CAMERA_TO_WORLD,
          "ao_distance": 0.8}


def channel_names():
    return [f"{LAYER}.{name}.{c}" for name, components, _ in PASSES for c in components]


def synthesize(width, height, seed=1):
    """{channel name: height x width float32} of the scene."""
    rng = np.random.default_rng(seed)
    m = np.array(CAMERA_TO_WORLD)
    rot, origin = m[:3, :3], m[:3, 3]
    # Rays through pixel centres, camera space (-Z forward), sensor fit AUTO on the width.
    half_w = 0.5 * CAMERA["sensor_width"] / CAMERA["lens"]
    half_h = half_w * height / width
    xs = ((np.arange(width) + 0.5) / width * 2.0 - 1.0) * half_w
    ys = (1.0 - (np.arange(height) + 0.5) / height * 2.0) * half_h
    cx, cy = np.meshgrid(xs, ys)
    cam_dir = np.stack([cx, cy, -np.ones_like(cx)], axis=-1)  # z = -1: t is planar depth
    world_dir = cam_dir @ rot.T
    t = np.full((height, width), np.inf)
    normal = np.zeros((height, width, 3))
    index = np.zeros((height, width))
    albedo = np.zeros((height, width, 3))

    def hit(t_new, n_new, idx, colour):
        closer = (t_new > 0.1) & (t_new < t)
        t[closer] = t_new[closer]
        normal[closer] = n_new[closer] if n_new.ndim == 3 else n_new
        index[closer] = idx
        albedo[closer] = colour
    # floor z = 0, back wall y = 14 up to z = 3
    with np.errstate(divide="ignore", invalid="ignore"):
        hit(-origin[2] / world_dir[..., 2], np.array([0.0, 0.0, 1.0]), 1, (0.6, 0.55, 0.5))
        t_wall = (14.0 - origin[1]) / world_dir[..., 1]
        hit(np.where(origin[2] + t_wall * world_dir[..., 2] < 3.0, t_wall, np.inf),
            np.array([0.0, -1.0, 0.0]), 2, (0.7, 0.7, 0.75))
    for k in range(24):  # spheres resting on the floor
        r = rng.uniform(0.3, 1.4)
        c = np.array([rng.uniform(-9, 9), rng.uniform(-2, 12), r])
        oc = origin - c
        b = world_dir @ oc
        a = np.einsum("ijk,ijk->ij", world_dir, world_dir)
        disc = b * b - a * (oc @ oc - r * r)
        with np.errstate(invalid="ignore"):
            tt = np.where(disc > 0, (-b - np.sqrt(np.maximum(disc, 0))) / a, np.inf)
        p = origin + world_dir * tt[..., None]
        n = (p - c) / r
        hit(tt, n, 3 + k, rng.uniform(0.1, 0.9, 3))
    for k in range(10):  # axis-aligned boxes on the floor
        lo = np.array([rng.uniform(-10, 8), rng.uniform(-2, 12), 0.0])
        hi = lo + np.array([rng.uniform(0.5, 2.5), rng.uniform(0.5, 2.5), rng.uniform(0.5, 3)])
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (lo - origin) / world_dir
            t2 = (hi - origin) / world_dir
        tmin = np.minimum(t1, t2)
        near = tmin.max(axis=-1)
        far = np.maximum(t1, t2).min(axis=-1)
        tt = np.where((near < far) & (near > 0), near, np.inf)
        axis = tmin.argmax(axis=-1)
        n = np.zeros((height, width, 3))
        for ax in range(3):
            sel = axis == ax
            n[sel, ax] = -np.sign(world_dir[sel, ax])
        hit(tt, n, 30 + k, rng.uniform(0.1, 0.9, 3))

    geometry = np.isfinite(t)
    depth = np.where(geometry, t, SKY_DEPTH)
    light = np.array([0.4, -0.3, 0.85])
    light /= np.linalg.norm(light)
    lambert = np.clip(normal @ light, 0.0, None)
    ao = np.clip(0.55 + 0.45 * normal[..., 2] + 0.0 * depth, 0.0, 1.0) * geometry

    def noisy(image, sigma):
        return (image * (1.0 + sigma * rng.standard_normal(image.shape))).astype(np.float32)
    sky = np.stack([np.full_like(t, 0.35), np.full_like(t, 0.5), np.full_like(t, 0.8)], -1)
    diff_dir = noisy(lambert[..., None] * np.ones(3) * geometry[..., None], 0.03)
    diff_ind = np.clip(noisy((0.25 * ao)[..., None] * np.ones(3), 0.06), 0.0, None)
    highlight = np.clip(lambert, 0, 1)[..., None] ** 24 * geometry[..., None] * np.ones(3)
    gloss = np.abs(noisy(highlight, 0.1))
    gloss_col = (0.04 + 0.2 * albedo) * geometry[..., None]
    combined = np.where(geometry[..., None], albedo * (diff_dir + diff_ind) + 0.3 * gloss, sky)
    mist = np.clip((depth - 5.0) / 25.0, 0.0, 1.0) ** 2
    # a locked-off camera: motion on the objects that move (half of the spheres), an image-space
    # flow that shrinks with depth
    moving = (geometry & (index >= 3) & (index < 27) & (index % 2 == 0))[..., None]
    fx, fy = np.meshgrid(np.linspace(-1, 1, width), np.linspace(-1, 1, height))
    vec = np.stack([(3.0 + 2.0 * fx) / np.maximum(depth, 1e-3) * 10,
                    (1.0 - fy) / np.maximum(depth, 1e-3) * 10,
                    (2.5 + 2.0 * fx) / np.maximum(depth, 1e-3) * 10,
                    (0.5 - fy) / np.maximum(depth, 1e-3) * 10], -1) * moving

    values = {
        "Combined": np.concatenate([combined, geometry[..., None].astype(float)], -1),
        "Depth": depth[..., None], "Mist": mist[..., None], "Normal": normal,
        "Vector": vec, "IndexOB": index[..., None],
        "AO": noisy(ao[..., None], 0.02) * np.ones(3),  # grey, as Blender writes it
        "DiffCol": albedo * geometry[..., None], "DiffDir": diff_dir, "DiffInd": diff_ind,
        "GlossCol": gloss_col, "GlossDir": gloss,
    }
    planes = {}
    for name, components, _ in PASSES:
        for i, c in enumerate(components):
            planes[f"{LAYER}.{name}.{c}"] = values[name][..., i].astype(np.float32)
    return planes


def write_frame(path, planes, multipart):
    import OpenImageIO as oiio
    names = channel_names()
    kinds = {f"{LAYER}.{n}.{c}": (oiio.HALF if k == "half" else oiio.FLOAT)
             for n, comps, k in PASSES for c in comps}
    groups = ([[n for n in names if n.rsplit(".", 1)[0] == f"{LAYER}.{p}"] for p, _, _ in PASSES]
              if multipart else [names])
    specs = []
    for group in groups:
        spec = oiio.ImageSpec(planes[group[0]].shape[1], planes[group[0]].shape[0], len(group),
                              oiio.HALF)
        spec.channelnames = tuple(group)
        spec.channelformats = tuple(kinds[n] for n in group)
        spec.alpha_channel = -1
        spec.attribute("compression", "zip")
        if multipart:
            spec.attribute("name", group[0].rsplit(".", 1)[0])
        specs.append(spec)
    out = oiio.ImageOutput.create(path)
    assert out is not None, oiio.geterror()
    assert out.open(path, specs) if multipart else out.open(path, specs[0]), out.geterror()
    for i, group in enumerate(groups):
        if i:
            assert out.open(path, specs[i], "AppendSubimage"), out.geterror()
        assert out.write_image(np.stack([planes[n] for n in group], -1)), out.geterror()
    out.close()


def make(args):
    os.makedirs(args.out, exist_ok=True)
    planes = synthesize(args.width, args.height)
    first = os.path.join(args.out, "in.0001.exr")
    write_frame(first, planes, args.multipart)
    for frame in range(2, args.frames + 1):
        shutil.copyfile(first, os.path.join(args.out, f"in.{frame:04d}.exr"))
    with open(os.path.join(args.out, "cam.json"), "w") as f:
        json.dump(CAMERA, f, indent=1)
    size = os.path.getsize(first)
    print(f"exr_frame_cost: {args.frames} frames of {args.width}x{args.height}, "
          f"{len(channel_names())} channels, {'multi' if args.multipart else 'single'}-part, "
          f"{size / 1e6:.1f} MB each, in {args.out}")


def build_env(ssao):
    lib = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(ssao))), "lib")
    env = dict(os.environ)
    env["LD_LIBRARY_PATH"] = lib + (":" + env["LD_LIBRARY_PATH"]
                                    if env.get("LD_LIBRARY_PATH") else "")
    return env


def sequence_command(ssao, folder, frames, threads, extra, out_dir):
    return [ssao, os.path.join(folder, "in.####.exr"),
            "-o", os.path.join(out_dir, "out.####.exr"),
            "--camera", os.path.join(folder, "cam.json"), "--frames", f"1-{frames}",
            "--threads", str(threads), "--quiet"] + extra


def count_frames(folder):
    return len([f for f in os.listdir(folder) if re.fullmatch(r"in\.\d{4}\.exr", f)])


def parse_builds(items):
    builds = []
    for item in items:
        label, _, path = item.partition("=")
        if not path:
            label, path = os.path.basename(os.path.dirname(os.path.dirname(item))), item
        builds.append((label, path))
    return builds


def timed(cmd, env):
    """(wall seconds, CPU seconds: user + system of the process and its threads)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        sys.exit(f"exr_frame_cost: {' '.join(cmd)} failed:\n{proc.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return elapsed, cpu


def time_builds(args):
    frames = count_frames(args.dir)
    builds = parse_builds(args.ssao)
    wall = {label: [] for label, _ in builds}
    cpu = {label: [] for label, _ in builds}
    with tempfile.TemporaryDirectory(prefix="exr_cost_", dir=args.scratch) as out_dir:
        for label, ssao in builds:  # one untimed run each: page cache, module loading
            timed(sequence_command(ssao, args.dir, 1, args.threads, args.extra, out_dir),
                  build_env(ssao))
        for _ in range(args.rounds):
            for label, ssao in builds:
                env = build_env(ssao)
                whole = timed(sequence_command(ssao, args.dir, frames, args.threads, args.extra,
                                               out_dir), env)
                one = timed(sequence_command(ssao, args.dir, 1, args.threads, args.extra,
                                             out_dir), env)
                wall[label].append((whole[0] - one[0]) / (frames - 1))
                cpu[label].append((whole[1] - one[1]) / (frames - 1))
    print(f"exr_frame_cost: {frames} frames, {args.threads} threads, extra flags "
          f"{' '.join(args.extra) or '(none)'}; ms per frame, median of {args.rounds} rounds "
          f"(min-max)")
    first = None
    for label, _ in builds:
        median = statistics.median(wall[label]) * 1e3
        first = first or median
        print(f"  {label:12s} wall {median:7.1f} ({min(wall[label]) * 1e3:.0f}-"
              f"{max(wall[label]) * 1e3:.0f}), {first / median:.2f}x the first;  CPU "
              f"{statistics.median(cpu[label]) * 1e3:7.1f} ({min(cpu[label]) * 1e3:.0f}-"
              f"{max(cpu[label]) * 1e3:.0f})")


# Sample classification for `profile`. A sample's owner is the first frame from the leaf that
# is neither the kernel nor the C/C++ runtime: the codec libraries (OpenEXR, zlib, OpenImageIO),
# the tool's own code, or libssao. Its context is what the stack shows it was called for: the
# read, the write, the AO run. OpenEXR's worker threads carry no caller of ours: their task
# (stripped, [unknown]) is placed by the exported symbol that follows it, which lies in
# OutputFile's code for the write and in ScanLineInputFile's for the read.
RUNTIME = re.compile(r"kernel|libc\.so|libstdc\+\+|libm\.so|libgcc|ld-linux|libtbbmalloc")
CODEC = re.compile(r"libz\.so|libOpenEXR|libIlmThread|libImath|libOpenImageIO|libdeflate")
OURS = re.compile(r"/ssao$|libssao_image_codec")
AO = re.compile(r"libssao\.so|libtbb")
CONTEXTS = [  # searched in this order over the whole stack
    ("start-up", re.compile(r"_dl_relocate|_dl_map_object|dl_open_worker|_dl_start|_dl_init|"
                            r"catalog_all_plugins|preload_image_io")),
    ("ao", re.compile(r"ssao_job_run|ssao_job_auto_radius")),
    ("write", re.compile(r"write_exr_file|write_preview_file|write_atomically|ImageOutput::|"
                         r"\[in OutputFile\]|\bdeflate|(?<!un)compress2")),
    ("read", re.compile(r"ssao_tools::\(anonymous namespace\)::read\b|read_channels|"
                        r"ImageInput::|ScanLineInputFile|\[in ScanLineInputFile\]|\binflate|"
                        r"uncompress|convert_type<Imath_3_1::half, float>")),
    ("extract", re.compile(r"load_inputs|attach_images")),
    ("assemble", re.compile(r"write_output")),
    ("summary", re.compile(r"mean_ao|print_summary")),
]
STAGES = [  # (label, owner, context)
    ("EXR decode (OpenEXR, zlib, OIIO)", "codec", "read"),
    ("ours: reading (buffers, merging)", "ours", "read"),
    ("ours: pass extraction", "ours", "extract"),
    ("AO (libssao)", "ao", None),
    ("ours: output assembly", "ours", "assemble"),
    ("EXR encode (OpenEXR, zlib, OIIO)", "codec", "write"),
    ("ours: writing (buffers)", "ours", "write"),
    ("ours: mean AO for the progress line", "ours", "summary"),
    ("start-up (loading, plugins)", None, "start-up"),
]


class Symbolizer:
    """Names the stripped frames of OpenEXR by the exported symbol that follows them."""

    def __init__(self):
        self.tables = {}

    def annotate(self, dso, address, symbol):
        if symbol != "[unknown]" or "libOpenEXR" not in dso:
            return symbol
        if dso not in self.tables:
            out = subprocess.run(["nm", "-D", "--defined-only", "-C", dso], capture_output=True,
                                 text=True).stdout
            rows = sorted((int(line.split()[0], 16), " ".join(line.split()[2:]))
                          for line in out.splitlines() if len(line.split()) >= 3)
            self.tables[dso] = ([a for a, _ in rows], [n for _, n in rows])
        addresses, names = self.tables[dso]
        import bisect
        i = bisect.bisect_right(addresses, address)
        following = names[i] if i < len(names) else ""
        for cls in ("OutputFile", "ScanLineInputFile"):
            if following.startswith(f"Imf_3_1::{cls}::"):
                return f"[in {cls}]"
        return symbol


def classify(frames):
    """frames: (symbol, dso) from the leaf. Returns the stage label."""
    owner = "other"
    for symbol, dso in frames:
        if RUNTIME.search(dso):
            continue
        owner = ("codec" if CODEC.search(dso) else "ours" if OURS.search(dso)
                 else "ao" if AO.search(dso) else "other")
        break
    text = "\n".join(symbol for symbol, _ in frames)
    context = next((name for name, pattern in CONTEXTS if pattern.search(text)), None)
    if context == "start-up":
        return STAGES[-1][0]
    if owner == "ao" or context == "ao":
        return "AO (libssao)"
    if owner == "other" and context in ("read", "write"):  # the kernel's and libc's part
        owner = "ours" if any(OURS.search(d) for _, d in frames[:3]) else "codec"
    if owner == "other" and context in ("extract", "assemble", "summary"):
        owner = "ours"
    for label, o, c in STAGES:
        if o == owner and c == context:
            return label
    return "other"


def perf_samples(data):
    symbolizer = Symbolizer()
    script = subprocess.run(["perf", "script", "-i", data, "-F", "comm,tid,ip,sym,dso",
                             "--no-inline"], capture_output=True, text=True).stdout
    for sample in script.split("\n\n"):
        frames = []
        for line in sample.strip().splitlines()[1:]:
            m = re.match(r"\s*([0-9a-f]+)\s+(.*?)\s+\((.*)\)$", line)
            if m:
                frames.append((symbolizer.annotate(m.group(3), int(m.group(1), 16), m.group(2)),
                               m.group(3)))
        if frames:
            yield frames


def profile(args):
    frames = count_frames(args.dir)
    builds = parse_builds(args.ssao)
    counts = {label: collections.Counter() for label, _ in builds}
    detail = {label: collections.Counter() for label, _ in builds}
    walls = {label: [] for label, _ in builds}
    for _ in range(args.rounds):
        for label, ssao in builds:
            wall = record(args, ssao, frames, counts[label], detail[label])
            walls[label].append(wall)
    for label, _ in builds:
        ms = 1e3 / args.frequency / frames / args.rounds
        total = sum(counts[label].values())
        print(f"exr_frame_cost: {label}: {frames} frames, {args.threads} threads, {args.rounds} "
              f"runs (median wall {statistics.median(walls[label]):.2f} s under perf); CPU ms "
              f"per frame ({total} samples at {args.frequency} Hz)")
        for stage in [s[0] for s in STAGES] + ["other"]:
            print(f"  {stage:38s} {counts[label][stage] * ms:8.1f}")
        print(f"  {'total':38s} {total * ms:8.1f}")
        for (stage, dso, sym), n in detail[label].most_common(args.detail):
            print(f"    {n * ms:7.1f}  {stage[:24]:24s} {dso[:24]:24s} {sym}")


def record(args, ssao, frames, counts, detail):
    """One perf run of the sequence; adds its samples by stage; returns its wall time."""
    with tempfile.TemporaryDirectory(prefix="exr_cost_", dir=args.scratch) as out_dir:
        data = os.path.join(out_dir, "perf.data")
        cmd = ["perf", "record", "-q", "-F", str(args.frequency), "-g", "--call-graph",
               "dwarf,16384", "-o", data, "--"] + sequence_command(
                   ssao, args.dir, frames, args.threads, args.extra, out_dir)
        start = time.perf_counter()
        proc = subprocess.run(cmd, env=build_env(ssao), capture_output=True, text=True)
        wall = time.perf_counter() - start
        if proc.returncode != 0:
            sys.exit(f"exr_frame_cost: {' '.join(cmd)} failed:\n{proc.stderr}")
        for stack in perf_samples(data):
            stage = classify(stack)
            counts[stage] += 1
            leaf = re.sub(r"\+0x[0-9a-f]+$", "", stack[0][0])
            detail[(stage, os.path.basename(stack[0][1]), leaf[:60])] += 1
    return wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("make", help="write the input frames and the camera file")
    p.add_argument("--out", required=True)
    p.add_argument("--frames", type=int, default=8)
    p.add_argument("--width", type=int, default=1920)
    p.add_argument("--height", type=int, default=1080)
    p.add_argument("--multipart", action="store_true",
                   help="one part per pass, as Blender 5.x writes multilayer files")
    for name in ("time", "profile"):
        p = sub.add_parser(name)
        p.add_argument("--dir", required=True, help="the folder `make` wrote")
        p.add_argument("--ssao", action="append", required=True, help="LABEL=PATH/bin/ssao")
        p.add_argument("--threads", type=int, default=2)
        p.add_argument("--scratch", default=None, help="folder for the outputs (default /tmp)")
        p.add_argument("extra", nargs="*", help="after --: more ssao flags")
        if name == "time":
            p.add_argument("--rounds", type=int, default=5)
        else:
            p.add_argument("--rounds", type=int, default=3)
            p.add_argument("--frequency", type=int, default=499)
            p.add_argument("--detail", type=int, default=0,
                           help="also list the N heaviest leaf functions")
    args = parser.parse_args()
    {"make": make, "time": time_builds, "profile": profile}[args.command](args)


if __name__ == "__main__":
    main()
