# SPDX-License-Identifier: MIT
"""Builds the test scene (scripts/blender/make_reference_scene.py's geometry) with an
Ambient Occlusion (SSAO) node in the compositor and saves it as a .blend.

    blender -b --factory-startup --addons ssao_compositor --python-exit-code 1 \
        -P tests/blender/build_ssao_scene.py -- --out scene.blend [--engine cycles|eevee]
        [--camera persp|ortho] [--width 160 --height 90 --samples 16] [--frames 1]
        [--output //render_####.png] [--ao-pass] [--radius 0.8]

The compositor: Render Layers (Image, Depth, Normal) -> SSAO -> Composite; the SSAO node's AO
output also goes to a Viewer. With --frames N the camera moves over frames 1..N.
"""
import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "scripts", "blender"))
import make_reference_scene as reference  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--engine", choices=("cycles", "eevee"), default="cycles")
    parser.add_argument("--camera", choices=("persp", "ortho"), default="persp")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=90)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--frames", type=int, default=1)
    parser.add_argument("--radius", type=float, default=0.8)
    parser.add_argument("--output", default="//render_####.png")
    parser.add_argument("--ao-pass", action="store_true", help="also render Cycles' AO pass")
    parser.add_argument("--passes-dir", default=None,
                        help="also write Image, Depth, Normal (and AO) of every frame to "
                             "DIR/####.exr with a top-level File Output node")
    return parser.parse_args(argv)


def eevee_engine_name():
    """EEVEE is BLENDER_EEVEE_NEXT in Blender 4.2 to 4.x, BLENDER_EEVEE before and after."""
    engines = {item.identifier for item in
               bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items}
    return "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in engines else "BLENDER_EEVEE"


def main():
    args = parse_args()
    scene = bpy.context.scene
    reference.clear_scene(scene)
    reference.build_geometry(scene)
    reference.setup_world(scene, args.radius)
    reference.add_sun(scene)
    camera = reference.add_camera(scene, args.camera)
    render = scene.render
    render.resolution_x, render.resolution_y = args.width, args.height
    render.resolution_percentage = 100
    if args.engine == "cycles":
        render.engine = 'CYCLES'
        scene.cycles.device = 'CPU'
        scene.cycles.samples = args.samples
        scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.seed = 1
    else:
        render.engine = eevee_engine_name()
        scene.eevee.taa_render_samples = args.samples
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    layer.use_pass_normal = True
    layer.use_pass_ambient_occlusion = args.ao_pass
    render.image_settings.file_format = 'PNG' if args.output.endswith(".png") else 'OPEN_EXR'
    if render.image_settings.file_format == 'OPEN_EXR':
        render.image_settings.color_depth = '32'
    render.image_settings.color_mode = 'RGBA'
    render.filepath = args.output
    render.use_file_extension = True
    # Linear output, so that tests can compare pixels with the passes.
    scene.view_settings.view_transform = 'Standard'
    scene.frame_start, scene.frame_end = 1, args.frames
    if args.frames > 1:
        camera.location.x -= 0.2
        camera.keyframe_insert("location", frame=1)
        camera.location.x += 0.4
        camera.keyframe_insert("location", frame=args.frames)

    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    rl = tree.nodes.new("CompositorNodeRLayers")
    ssao = tree.nodes.new("CompositorNodeSSAO")
    ssao.radius = args.radius
    composite = tree.nodes.new("CompositorNodeComposite")
    viewer = tree.nodes.new("CompositorNodeViewer")
    rl.location, ssao.location = (-300, 0), (0, 0)
    composite.location, viewer.location = (300, 100), (300, -150)
    tree.links.new(rl.outputs["Image"], ssao.inputs["Image"])
    tree.links.new(rl.outputs["Depth"], ssao.inputs["Depth"])
    tree.links.new(rl.outputs["Normal"], ssao.inputs["Normal"])
    tree.links.new(ssao.outputs["Image"], composite.inputs["Image"])
    tree.links.new(ssao.outputs["AO"], viewer.inputs["Image"])
    if args.passes_dir:
        passes = tree.nodes.new("CompositorNodeOutputFile")
        passes.location = (0, -300)
        passes.base_path = os.path.abspath(args.passes_dir) + os.sep
        passes.format.file_format = 'OPEN_EXR_MULTILAYER'
        passes.format.color_depth = '32'
        passes.file_slots.clear()
        for name in ("Image", "Depth", "Normal") + (("AO",) if args.ao_pass else ()):
            passes.file_slots.new(name)
            tree.links.new(rl.outputs[name], passes.inputs[name])
        # The node's own AO output: written again, with the computed AO, by the re-composite.
        passes.file_slots.new("SSAO")
        tree.links.new(ssao.outputs["AO"], passes.inputs["SSAO"])
    out_prefix = os.path.splitext(os.path.abspath(args.out))[0]
    reference.write_json(out_prefix + ".camera.json", reference.camera_description(camera))
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.out))
    print(f"build_ssao_scene: saved {args.out} ({args.engine}, {args.camera}, "
          f"{args.width}x{args.height}, {args.frames} frame(s))")


if __name__ == "__main__":
    main()
