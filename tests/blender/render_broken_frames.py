# SPDX-License-Identifier: MIT
"""Renders the open file's frames one at a time (each a one-frame animation, as -a writes it),
breaking the SSAO node's inputs, parameters or library in a different way on some frames, and
writes each frame's node status to a JSON report. Run headless by tests/blender/test_addon.py:

    blender -b --addons ssao_compositor SCENE.blend --python render_broken_frames.py -- \
        REPORT.json FRAME=CASE ...

CASE is one of the names in CASES; frames not named render as the file has them. The file must
be the one tests/blender/build_ssao_scene.py makes (Render Layers -> SSAO, radius 0.8). Each
frame is a render of its own because the render composites the tree as it was when it started
(links changed in a frame-change handler reach the render one frame late: measured in 3.4)."""
import json
import sys

import bpy
import numpy as np

addon = {name.rsplit(".", 1)[-1]: module for name, module in sys.modules.items()
         if name.split(".")[-2:-1] == ["ssao_compositor"]}
native = addon["ssao"]
scene = bpy.context.scene
tree = addon["compat"].compositor_tree(scene)
node = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeSSAO")
# Each frame alone, as the test compares it: every frame here is a job of its own, which the
# temporal filter would otherwise give the frames before it (rendered first: warm_up.py).
node.temporal_frames = 1
render_layers = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers")
layer = scene.view_layers[0]
width, height = scene.render.resolution_x, scene.render.resolution_y

# An image with no positive value: 0, -1 and NaN in turn (NaN reaches the node: measured).
no_depth = bpy.data.images.new("no depth", width, height, float_buffer=True)
values = np.resize(np.array([0.0, -1.0, np.nan], np.float32), width * height)
no_depth.pixels.foreach_set(np.repeat(values, 4))
no_depth_node = tree.nodes.new("CompositorNodeImage")
no_depth_node.image = no_depth

run = native.Job.run


def failing_run(self, progress=None):
    raise native.SSAOError("ssao_job_run: simulated library failure")


def link(source, target):
    for old in list(target.links):
        tree.links.remove(old)
    if source is not None:
        tree.links.new(source, target)


CASES = {
    "depth unlinked": lambda: link(None, node.inputs["Depth"]),
    "normal from image": lambda: link(render_layers.outputs["Image"], node.inputs["Normal"]),
    "no depth": lambda: link(no_depth_node.outputs["Image"], node.inputs["Depth"]),
    "library fails": lambda: setattr(native.Job, "run", failing_run),
    # Blender keeps NaN in a float property (it clamps only numbers out of range).
    "radius nan": lambda: setattr(node, "radius", float("nan")),
    "normal pass off": lambda: setattr(layer, "use_pass_normal", False),
    "depth pass off": lambda: setattr(layer, "use_pass_z", False),
}


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    report_path, cases = argv[0], dict(a.split("=", 1) for a in argv[1:])
    first, last = scene.frame_start, scene.frame_end
    report = {}
    for frame in range(first, last + 1):
        # The file's own setup, then this frame's break.
        layer.use_pass_z = layer.use_pass_normal = True
        link(render_layers.outputs["Depth"], node.inputs["Depth"])
        link(render_layers.outputs["Normal"], node.inputs["Normal"])
        node.radius = 0.8
        native.Job.run = run
        case = cases.get(str(frame))
        if case:
            CASES[case]()
        print(f"render_broken_frames: frame {frame}: {case or 'as saved'}", flush=True)
        scene.frame_start = scene.frame_end = frame
        bpy.ops.render.render(animation=True)
        report[frame] = {"case": case, "status": node.status}
    native.Job.run = run
    scene.frame_start, scene.frame_end = first, last
    with open(report_path, "w") as f:
        json.dump(report, f, indent=1)


main()
