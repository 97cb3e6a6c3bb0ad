# SPDX-License-Identifier: MIT
"""Checks that the Windows build of libssao computes the same bits as the Linux build.

Runs tests/windows/raw_ao.c built for Linux and for Windows (MinGW-w64, run through wine) on the
bundled sample (SAMPLE/sample.exr, its camera SAMPLE/sample.camera.json, its radius the
"ao_distance" of SAMPLE/sample.json), for threads=1 and threads=0 (all cores), for every AO
variant the library lists (or those of --variants) and for each SIMD target of --simd-targets
($SSAO_SIMD_TARGET, the same on both sides: each target's kernels sum in their own order), and
checks that the AO files are byte-identical: Linux against Windows, and threads=1 against
threads=0 on each. As a check that
raw_ao passes its inputs and parameters right, the Linux output is also compared with the
Python module's (core/python/ssao on build/lib, or $SSAO_LIBRARY). One `[measure]` line per
comparison; exit status 1 if any differs or any run fails.

    /usr/bin/python3 tests/windows/compare_ao.py --linux build/bin/raw_ao \
        --windows build-windows/bin/raw_ao.exe --sample tests/data --work /tmp/compare_ao

wine runs (through scripts/wine_run.sh, as the cross build's tests) with WINEDEBUG=-all and the
caller's WINEPREFIX (~/.wine if not set), whose server scripts/start_wine.sh starts first; each
run's output goes to a file, never a pipe that a Wine process started by the run could hold
open (start_wine.sh says why).
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "core", "python"))
import ssao  # noqa: E402  (the source tree's module, found through the path above)


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--linux", required=True, help="raw_ao built for Linux")
    parser.add_argument("--windows", required=True, help="raw_ao.exe built with MinGW-w64")
    parser.add_argument("--wine", default=os.path.join(ROOT, "scripts", "wine_run.sh"),
                        help="command that runs a Windows program (default: wine through "
                             "scripts/wine_run.sh, which runs it again when Wine did not launch "
                             "it)")
    parser.add_argument("--sample", required=True, help="folder of sample.exr and its camera")
    parser.add_argument("--work", required=True, help="folder for the raw inputs and outputs")
    parser.add_argument("--variants", help="comma-separated variants (default: all)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="another library parameter for both sides (repeatable)")
    parser.add_argument("--simd-targets", default="default,sse4",
                        help="comma-separated $SSAO_SIMD_TARGET values both sides run with "
                             "(default: the CPU's widest, then SSE4)")
    parser.add_argument("--timeout", type=float, default=600, help="seconds per run")
    return parser.parse_args()


def find_channels(names, suffixes):
    """Indices of the first channels ending with each suffix (the CLI's "<layer>.Depth.Z"...)."""
    indices = []
    for suffix in suffixes:
        found = [i for i, name in enumerate(names) if name == suffix or name.endswith("." + suffix)]
        if not found:
            raise SystemExit(f"compare_ao: no channel *{suffix} among {names}")
        indices.append(found[0])
    return indices


def read_sample(path):
    """(depth (H, W), normals (H, W, 3)) of a single-part EXR without overscan, float32."""
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SystemExit(f"compare_ao: cannot read {path}: {oiio.geterror()}")
    spec = inp.spec()
    if (spec.x, spec.y, spec.width, spec.height) != (spec.full_x, spec.full_y, spec.full_width,
                                                     spec.full_height):
        raise SystemExit(f"compare_ao: {path} has overscan, which raw_ao does not handle")
    pixels = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT), np.float32)
    inp.close()
    pixels = pixels.reshape(spec.height, spec.width, spec.nchannels)
    names = list(spec.channelnames)
    (z,) = find_channels(names, ["Depth.Z"])
    normal = find_channels(names, ["Normal.X", "Normal.Y", "Normal.Z"])
    return np.ascontiguousarray(pixels[:, :, z]), np.ascontiguousarray(pixels[:, :, normal])


def as_argument(value):
    """A parameter value as raw_ao reads it; repr() of a float is its shortest exact form."""
    if isinstance(value, (list, tuple)):
        return ",".join(repr(float(v)) for v in value)
    return repr(value) if isinstance(value, float) else str(value)


def run(label, command, work, out, pixels, timeout, env=None):
    """Runs one raw_ao; returns the AO (float32, flat) or None after printing why it failed."""
    if os.path.exists(os.path.join(work, out)):
        os.remove(os.path.join(work, out))  # a stale output must not pass for this run's
    with tempfile.TemporaryFile("w+") as stderr:
        try:
            done = subprocess.run(command, cwd=work, env=env, stdin=subprocess.DEVNULL,
                                  stdout=subprocess.DEVNULL, stderr=stderr, timeout=timeout)
        except (OSError, subprocess.TimeoutExpired) as error:
            print(f"[measure] {label}: FAILED: {error}\n    {shlex.join(command)}")
            return None
        stderr.seek(0)
        message = stderr.read()
    if done.returncode != 0:
        why = (message.strip().splitlines() or ["(no message)"])[-1]
        print(f"[measure] {label}: FAILED: exit {done.returncode}: {why}\n    {shlex.join(command)}")
        return None
    ao = np.fromfile(os.path.join(work, out), np.float32)
    if ao.size != pixels:
        print(f"[measure] {label}: FAILED: {out} holds {ao.size} floats, expected {pixels}")
        return None
    return ao


def compare(label, a, b):
    """Prints one [measure] line; True when a and b are byte-identical."""
    if a is None or b is None:
        print(f"[measure] {label}: not compared (a run failed)")
        return False
    differing = int(np.count_nonzero(a.view(np.uint32) != b.view(np.uint32)))
    diff = np.abs(a.astype(np.float64) - b.astype(np.float64))
    max_diff = float(np.nanmax(diff)) if np.isfinite(diff).any() else float("nan")
    same = a.tobytes() == b.tobytes()
    print(f"[measure] {label}: max_abs_diff {max_diff:.3g} differing_pixels {differing}/{a.size} "
          f"mean_ao {float(np.mean(a)):.6f} {'identical' if same else 'DIFFERENT'}")
    return same


def compare_variant(variant, target, settings, width, height, linux, windows, env, wine_env,
                    work, timeout):
    """Runs `variant` on both systems with 1 thread and all; True when all four agree."""
    results = {}
    for threads in (1, 0):
        params = [f"{k}={as_argument(v)}" for k, v in settings.items()]
        params += [f"variant={variant}", f"threads={threads}"]
        for system, program, system_env in (("linux", linux, env),
                                            ("windows", windows, wine_env)):
            out = f"ao_{variant}_{target}_{system}_t{threads}.f32"
            command = program + [str(width), str(height), "depth.f32", "normal.f32", out]
            label = f"{variant} {target} threads={threads} {system}"
            results[system, threads] = run(label, command + params, work, out, width * height,
                                           timeout, system_env)
    ok = True
    for threads in (1, 0):
        ok &= compare(f"{variant} {target} threads={threads} linux vs windows",
                      results["linux", threads], results["windows", threads])
    for system in ("linux", "windows"):
        ok &= compare(f"{variant} {target} {system} threads=1 vs threads=0",
                      results[system, 1], results[system, 0])
    return ok


def main():
    args = parse_args()
    work = os.path.abspath(args.work)
    os.makedirs(work, exist_ok=True)
    sample = os.path.join(args.sample, "sample")
    depth, normals = read_sample(sample + ".exr")
    height, width = depth.shape
    depth.astype("<f4").tofile(os.path.join(work, "depth.f32"))
    normals.astype("<f4").tofile(os.path.join(work, "normal.f32"))

    camera = ssao.read_camera(sample + ".camera.json")
    with open(sample + ".json", encoding="utf-8") as f:
        radius = float(json.load(f)["ao_distance"])
    settings = dict(ssao.camera_parameters(camera), radius=radius)
    settings.update(item.split("=", 1) for item in args.set)
    variants = args.variants.split(",") if args.variants else [v["name"] for v in ssao.variants()]

    linux = [os.path.abspath(args.linux)]
    windows = shlex.split(args.wine) + [os.path.abspath(args.windows)]
    prefix = os.environ.get("WINEPREFIX") or os.path.expanduser("~/.wine")
    subprocess.run(["bash", os.path.join(ROOT, "scripts", "start_wine.sh")], check=True,
                   env=dict(os.environ, WINEPREFIX=prefix), stdin=subprocess.DEVNULL)
    ok = True
    for target in args.simd_targets.split(","):
        # The kernels of each SIMD target sum in their own order: both sides run the same one.
        env = dict(os.environ)
        env.pop("SSAO_SIMD_TARGET", None)
        if target != "default":
            env["SSAO_SIMD_TARGET"] = target
        wine_env = dict(env, WINEDEBUG="-all", WINEPREFIX=prefix)
        for variant in variants:
            ok &= compare_variant(variant, target, settings, width, height, linux, windows, env,
                                  wine_env, work, args.timeout)
            if target != "default":
                continue
            try:  # this process's library runs the default target
                reference = ssao.ambient_occlusion(depth, normals=normals, camera=camera,
                                                   radius=radius, variant=variant).ravel()
            except ssao.SSAOError as error:
                print(f"[measure] {variant} python module: FAILED: {error}")
                reference = None
            linux_ao = os.path.join(work, f"ao_{variant}_{target}_linux_t0.f32")
            ok &= compare(f"{variant} linux raw_ao vs python module",
                          np.fromfile(linux_ao, np.float32) if os.path.exists(linux_ao)
                          else None, reference)
    print("compare_ao: " + ("all identical" if ok else "FAILED: see the lines above"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
