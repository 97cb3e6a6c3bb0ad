# SPDX-License-Identifier: MIT
"""One frame of a benchmark scene in which an object moved, the camera still, with its ground
truth: benchmark_sequence.py's frame with ``--move NAME,DX,DY,DZ`` (an object of the layout moved
by that much, world units; frame k of a move gives k times a step):

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/benchmark_moving.py -- --scene contact --out seq/f2 \\
        --width 320 --height 180 --samples 1024 --move RotatedBox,0.2,0,0

benchmarks/flicker.py renders and scores it (a script of its own, so that the camera moves'
cached renders keep their keys).
"""

import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes  # noqa: E402
import benchmark_sequence  # noqa: E402
import export_cameras  # noqa: E402
import make_reference_scene as reference  # noqa: E402


def main():
    argv = export_cameras.script_argv()
    if "--move" not in argv or argv.index("--move") + 1 >= len(argv):
        raise SystemExit("benchmark_moving.py: --move NAME,DX,DY,DZ is required")
    at = argv.index("--move")
    move = argv[at + 1]
    del argv[at:at + 2]
    args = benchmark_scenes.parse_args(argv)
    scene = bpy.context.scene
    cam_obj, layout = benchmark_scenes.build_scene(scene, args.scene, args.level)
    name, *offset = move.split(",")
    if name not in scene.objects or len(offset) != 3:
        raise SystemExit("benchmark_moving.py: --move NAME,DX,DY,DZ with an object of the "
                         "layout, got '%s'" % move)
    scene.objects[name].location += Vector(tuple(float(v) for v in offset))
    args.ao_distance = layout["ao_distance"]
    args.camera = layout["kind"]
    reference.render_reference(scene, cam_obj, args, os.path.abspath(args.out), args.scene,
                               {"level": args.level, "move": move})


if __name__ == "__main__":
    export_cameras.run_script(main, "benchmark_moving")
