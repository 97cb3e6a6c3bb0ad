# SPDX-License-Identifier: MIT
"""Times Cycles' own AO pass, rendered the fastest way that still writes a correct AO pass,
at several sample counts: what a Blender user would do instead of SSAO.

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/cycles_ao_sweep.py -- --scene contact --out sweep/contact \\
        --width 640 --height 360 --samples 1,2,4,8,16,64 --repeat 3 [--level L]

Builds the scene of benchmark_scenes.py, then sets up the render for the AO pass alone: no
bounces, lights hidden, one plain diffuse material override, only the AO pass (no Combined,
Depth or Normal), no denoising, no adaptive sampling, no persistent data, a seed other than
the reference's. After one untimed warm-up render, renders every sample count `--repeat`
times, interleaved (1 2 4 .. 1 2 4 ..), and times each `bpy.ops.render.render()` call:
scene synchronisation, BVH build and sampling, not the file write. Writes the AO of each count
to PREFIX.sNNNN.exr (multilayer, 32-bit float) and the timings to PREFIX.json:

    {"scene", "level", "triangles", "width", "height", "threads", "blender_version",
     "runs": [{"samples", "file", "times_s": [...], "median_s"}]}
"""

import argparse
import os
import statistics
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes as kit  # noqa: E402
import make_reference_scene as reference  # noqa: E402


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="cycles_ao_sweep.py",
                                     description="Time Cycles' AO pass at several sample counts.")
    parser.add_argument("--scene", choices=sorted(kit.LAYOUTS), required=True)
    parser.add_argument("--out", required=True, help="output prefix")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--samples", default="1,2,4,8,16,64",
                        help="comma-separated sample counts (default 1,2,4,8,16,64)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--level", type=int, default=0)
    parser.add_argument("--seed", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args(argv)
    try:
        args.samples = [int(v) for v in args.samples.split(",")]
    except ValueError:
        parser.error("--samples: expected comma-separated integers")
    if not args.samples or min(args.samples) < 1:
        parser.error("--samples: counts must be positive")
    if min(args.width, args.height, args.repeat, args.threads) < 1:
        parser.error("--width, --height, --repeat and --threads must be positive")
    return args


def configure_fast_ao(scene, layer, args):
    """The cheapest render whose AO pass is still Cycles' AO pass."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.use_adaptive_sampling = False
    c.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    c.seed = args.seed
    c.use_animated_seed = False
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "volume_bounces", "transparent_max_bounces"):
        setattr(c, name, 0)
    c.caustics_reflective = False
    c.caustics_refractive = False
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = args.width, args.height, 100
    r.threads_mode = "FIXED"
    r.threads = args.threads
    r.use_persistent_data = False
    r.use_compositing = False
    r.use_sequencer = False
    r.film_transparent = False
    reference.use_multilayer_exr(r.image_settings)
    layer.use_pass_combined = False
    layer.use_pass_z = False
    layer.use_pass_normal = False
    layer.use_pass_ambient_occlusion = True
    layer.material_override = bpy.data.materials.new("PlainDiffuse")
    for obj in scene.objects:
        if obj.type == "LIGHT":
            obj.hide_render = True


def render_seconds(scene):
    start = time.perf_counter()
    result = bpy.ops.render.render(write_still=False, scene=scene.name)
    seconds = time.perf_counter() - start
    if "FINISHED" not in result:
        raise RuntimeError("render.render returned %s" % (result,))
    return seconds


def main():
    args = parse_args(reference.script_argv())
    prefix = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(prefix), exist_ok=True)
    scene = bpy.context.scene
    kit.build_scene(scene, args.scene, args.level)
    layer = reference.single_view_layer(scene)
    configure_fast_ao(scene, layer, args)
    triangles = kit.triangle_count(scene)

    scene.cycles.samples = 1
    render_seconds(scene)  # warm-up: kernels, textures, first allocation
    times = {n: [] for n in args.samples}
    files = {n: "%s.s%04d.exr" % (prefix, n) for n in args.samples}
    for rep in range(args.repeat):
        for n in args.samples:
            scene.cycles.samples = n
            times[n].append(render_seconds(scene))
            if rep == 0:  # the image does not change between repeats (fixed seed)
                bpy.data.images["Render Result"].save_render(files[n], scene=scene)
            print("cycles_ao_sweep: %s level %d, %d spp: %.3f s"
                  % (args.scene, args.level, n, times[n][-1]), flush=True)
    runs = [{"samples": n, "file": os.path.basename(files[n]), "times_s": times[n],
             "median_s": statistics.median(times[n])} for n in args.samples]
    reference.write_json(prefix + ".json", {
        "scene": args.scene, "level": args.level, "triangles": triangles,
        "width": args.width, "height": args.height, "threads": args.threads,
        "seed": args.seed, "blender_version": bpy.app.version_string, "runs": runs})
    print("cycles_ao_sweep: wrote %s.json (%d triangles)" % (prefix, triangles))


if __name__ == "__main__":
    reference.run_script(main, "cycles_ao_sweep")
