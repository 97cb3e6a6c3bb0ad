# SPDX-License-Identifier: MIT
"""The cost of the node's helper render (blender_addon/hidden_surfaces.py) against the beauty
render, on the test scene (light) and on the same scene with a mesh of about 2M triangles
(docs/blender.md, "Hidden surfaces and overscan"):

    blender -b --factory-startup -P tests/blender/measure_hidden_surfaces.py -- \\
        [--width 640 --height 360 --samples 16 --triangles 2000000 --rounds 3] [--cutouts]
        [--baseline CHECKOUT | --compare-hits A,B]

Prints one `[measure]` line per case: the beauty render's time (Cycles, CPU) and the helper's
(the node's hits, with and without a guard band), medians of --rounds after one warm-up, in one
Blender.
With --baseline CHECKOUT (e.g. a `git worktree` of an earlier commit), the helper of that
checkout's blender_addon/ and this one's instead, interleaved, and their ratio. --cutouts adds
the cut-out scene's fence, leaves and curtain. With --compare-hits A,B, the helper (no band)
recording A hits and B hits instead, interleaved, and their ratio.
"""
import argparse
import importlib
import os
import statistics
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts", "blender"))
sys.path.insert(0, os.path.join(HERE, "..", ".."))
import make_reference_scene as reference  # noqa: E402

hidden_surfaces = importlib.import_module("blender_addon.hidden_surfaces")


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--triangles", type=int, default=2000000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--overscan", type=int, default=32)
    parser.add_argument("--persistent", action="store_true",
                        help="Render Properties > Performance > Persistent Data on")
    parser.add_argument("--cutouts", action="store_true",
                        help="add make_reference_scene.build_cutouts (alpha: the helper runs the "
                             "materials' own outputs)")
    parser.add_argument("--baseline", default=None, metavar="CHECKOUT",
                        help="instead, compare the helper (3 hits) with another checkout's "
                             "blender_addon/, interleaved (A B A B), medians of --rounds")
    parser.add_argument("--compare-hits", default=None, metavar="A,B",
                        help="instead, the helper recording A hits against B hits (no band), "
                             "interleaved, medians of --rounds")
    args = parser.parse_args(argv)
    if args.compare_hits is not None:
        args.compare_hits = tuple(int(v) for v in args.compare_hits.split(","))
    return args


def heavy_mesh(scene, triangles):
    """A displaced grid of about `triangles` triangles in view, behind the test objects."""
    side = int((triangles / 2) ** 0.5)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=side, y_subdivisions=side, size=6,
                                    location=(0, 3, 1.5), rotation=(1.2, 0, 0))
    grid = bpy.context.active_object
    mesh = grid.data
    import numpy as np
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    co[:, 2] += 0.05 * np.sin(co[:, 0] * 40) * np.cos(co[:, 1] * 40)
    mesh.vertices.foreach_set("co", co.ravel())
    mesh.update()
    if grid.name not in scene.objects:
        scene.collection.objects.link(grid)
    return sum(len(p.vertices) - 2 for p in mesh.polygons)


def timed(function, rounds):
    function()  # warm-up (kernels, caches)
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(scene, label, args):
    beauty = timed(lambda: bpy.ops.render.render(), args.rounds)
    results = {}
    hits = hidden_surfaces.MAX_HITS  # what the node's 'PEELED' asks for
    for count, overscan in ((hits, 0), (hits, args.overscan), (1, args.overscan)):
        def helper():
            hidden_surfaces.forget()
            hidden_surfaces.render_layers(scene, count, overscan)
        results[count, overscan] = timed(helper, args.rounds)
    print(f"[measure] {label}: beauty {beauty:.2f} s; helper {hits} hits {results[hits, 0]:.2f} s, "
          f"{hits} hits + {args.overscan} px {results[hits, args.overscan]:.2f} s, band only "
          f"{results[1, args.overscan]:.2f} s (Blender {bpy.app.version_string})", flush=True)


def interleaved(timed_run, keys, rounds):
    """{key: median seconds of timed_run(key)}: one warm-up each, then `rounds` rounds of every
    key in turn (A B A B)."""
    times = {key: [] for key in keys}
    for key in keys:
        timed_run(key)
    for _ in range(rounds):
        for key in keys:
            times[key].append(timed_run(key))
    return {key: statistics.median(values) for key, values in times.items()}


def compare_hits(scene, label, args):
    """The helper render (no band) recording args.compare_hits[0] hits against [1], interleaved."""
    def helper(count):
        hidden_surfaces.forget()
        start = time.perf_counter()
        hidden_surfaces.render_layers(scene, count, 0)
        return time.perf_counter() - start

    medians = interleaved(helper, args.compare_hits, args.rounds)
    a, b = (medians[c] for c in args.compare_hits)
    print(f"[measure] {label}: helper {args.compare_hits[0]} hits {a:.3f} s, "
          f"{args.compare_hits[1]} hits {b:.3f} s (ratio {b / a:.3f}; medians of {args.rounds}, "
          f"interleaved; Blender {bpy.app.version_string})", flush=True)


def compare(scene, label, args, baseline):
    """The helper render (3 hits, no band) of this checkout against `baseline`'s, interleaved."""
    modules = {"baseline": baseline, "this": hidden_surfaces}

    def helper(name):
        for module in modules.values():
            module.remove_helpers()
        start = time.perf_counter()
        modules[name].render_layers(scene, 3, 0)
        return time.perf_counter() - start

    medians = interleaved(helper, list(modules), args.rounds)
    base, this = medians["baseline"], medians["this"]
    print(f"[measure] {label}: helper 3 hits, baseline {base:.3f} s, this {this:.3f} s "
          f"(ratio {this / base:.3f}; medians of {args.rounds}, interleaved; Blender "
          f"{bpy.app.version_string})", flush=True)


def baseline_module(checkout):
    """blender_addon.hidden_surfaces of another checkout, imported beside this one's."""
    import importlib.util
    folder = os.path.join(os.path.abspath(checkout), "blender_addon")
    spec = importlib.util.spec_from_file_location(
        "baseline_addon", os.path.join(folder, "__init__.py"), submodule_search_locations=[folder])
    package = importlib.util.module_from_spec(spec)
    sys.modules["baseline_addon"] = package
    # Only the modules hidden_surfaces needs (the package's __init__ registers the add-on).
    return importlib.import_module("baseline_addon.hidden_surfaces")


def main():
    args = parse_args()
    scene = bpy.context.scene
    reference.clear_scene(scene)
    reference.build_geometry(scene)
    reference.setup_world(scene, 0.8)
    reference.add_sun(scene)
    reference.add_camera(scene, "persp")
    render = scene.render
    render.resolution_x, render.resolution_y = args.width, args.height
    render.resolution_percentage = 100
    render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    render.use_persistent_data = args.persistent
    size = f"{args.width}x{args.height}, {args.samples} spp" + \
        (", persistent data" if args.persistent else "")
    if args.cutouts:
        reference.build_cutouts(scene)
    run = measure if args.baseline is None else \
        (lambda s, label, a, b=baseline_module(args.baseline): compare(s, label, a, b))
    if args.compare_hits is not None:
        run = compare_hits
    name = "test scene" + (" with cut-outs" if args.cutouts else "")
    run(scene, f"{name} ({size})", args)
    triangles = heavy_mesh(scene, args.triangles)
    run(scene, f"{name} + {triangles / 1e6:.1f}M triangles ({size})", args)


if __name__ == "__main__":
    main()
