# SPDX-License-Identifier: MIT
"""One frame of a camera move through a benchmark scene, with its ground truth.

The scene of benchmark_scenes.py, its camera moved sideways (along its own x axis, its
orientation kept) so far that a point at the layout's target moves ``--truck-px`` pixels:

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/benchmark_sequence.py -- --scene contact --out seq/f2 \\
        --width 320 --height 180 --samples 1024 --truck-px 3

Frame k of a move is ``--truck-px k * step``; every frame keeps Blender's default seed, as an
animation without an animated seed does. Writes PREFIX.exr, PREFIX.camera.json and PREFIX.json
as benchmark_scenes.py does (``truck_px`` in the metadata). benchmarks/flicker.py renders and
scores the moves.
"""

import os
import sys

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes  # noqa: E402
import export_cameras  # noqa: E402
import make_reference_scene as reference  # noqa: E402


def truck_camera(cam_obj, layout, pixels, width):
    """Moves the camera along its own x axis so far that a point at the layout's target moves
    `pixels` pixels across an image `width` pixels wide."""
    cam = cam_obj.data
    if cam.type == "ORTHO":
        view_width = cam.ortho_scale
    else:
        # The layout's camera, or make_reference_scene's default one.
        target = layout.get("target", reference.CAMERA_TARGET)
        location = layout.get("location", reference.CAMERA_LOCATION)
        distance = (Vector(target) - Vector(location)).length
        view_width = distance * cam.sensor_width / cam.lens
    step = cam_obj.matrix_world.to_3x3() @ Vector((pixels * view_width / width, 0.0, 0.0))
    cam_obj.matrix_world = Matrix.Translation(step) @ cam_obj.matrix_world


def main():
    argv = export_cameras.script_argv()
    truck = 0.0
    if "--truck-px" in argv:
        at = argv.index("--truck-px")
        if at + 1 >= len(argv):
            raise SystemExit("benchmark_sequence.py: --truck-px needs a number of pixels")
        truck = float(argv[at + 1])
        del argv[at:at + 2]
    args = benchmark_scenes.parse_args(argv)
    scene = bpy.context.scene
    cam_obj, layout = benchmark_scenes.build_scene(scene, args.scene, args.level)
    truck_camera(cam_obj, layout, truck, args.width)
    args.ao_distance = layout["ao_distance"]
    args.camera = layout["kind"]
    reference.render_reference(scene, cam_obj, args, os.path.abspath(args.out), args.scene,
                               {"level": args.level, "truck_px": truck})


if __name__ == "__main__":
    export_cameras.run_script(main, "benchmark_sequence")
