# SPDX-License-Identifier: MIT
"""Builds the test scene (scripts/blender/make_reference_scene.py's geometry) with an
Ambient Occlusion (SSAO) node in the compositor and saves it as a .blend.

    blender -b --factory-startup --addons ssao_compositor --python-exit-code 1 \
        -P tests/blender/build_ssao_scene.py -- --out scene.blend [--engine cycles|eevee]
        [--camera persp|ortho] [--width 160 --height 90 --samples 16] [--frames 1]
        [--output //render_####.png] [--ao-pass] [--radius 0.8] [--cutouts | --render-features]
        [--border MIN_X MAX_X MIN_Y MAX_Y]

The compositor: Render Layers (Image, Depth, Normal) -> SSAO -> Composite (Group Output in 5.x);
the SSAO node's AO output also goes to a Viewer. With --frames N the camera moves and turns
over frames 1..N, and each frame's camera is written too (OUT.camera.NNNN.json). The compositor is built the way of the running Blender through the add-on's own version
shims (its compat module), which this also tests.
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
    parser.add_argument("--compositor-device", choices=("default", "CPU", "GPU"),
                        default="default", help="render.compositor_device (Blender 4.2+)")
    parser.add_argument("--format", choices=("auto", "OPEN_EXR_MULTILAYER"), default="auto",
                        help="output format (auto: from --output's extension)")
    parser.add_argument("--ao-pass", action="store_true", help="also render Cycles' AO pass")
    parser.add_argument("--hidden-surfaces", choices=("NONE", "PEELED"), default=None,
                        help="the node's hidden_surfaces (default: the node's default)")
    parser.add_argument("--overscan", type=int, default=None,
                        help="the node's overscan in pixels (default: the node's default)")
    parser.add_argument("--cutouts", action="store_true",
                        help="add open surfaces with alpha cut-outs: a lattice fence, leaf "
                             "cards, a curtain (make_reference_scene.build_cutouts)")
    parser.add_argument("--render-features", action="store_true",
                        help="--cutouts, and material displacement, holdouts (an object, a "
                             "collection) and an object hidden from the camera "
                             "(make_reference_scene.build_render_features)")
    parser.add_argument("--border", type=float, nargs=4, default=None,
                        metavar=("MIN_X", "MAX_X", "MIN_Y", "MAX_Y"),
                        help="render only this border (fractions of the frame), cropped to it")
    parser.add_argument("--passes-dir", default=None,
                        help="also write Image, Depth, Normal (and AO) of every frame to "
                             "DIR/####.exr with a top-level File Output node")
    return parser.parse_args(argv)


def addon_compat():
    return next(m for n, m in sys.modules.items() if n.endswith("ssao_compositor.compat"))


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
    if args.render_features:
        reference.build_render_features(scene)
    elif args.cutouts:
        reference.build_cutouts(scene)
    reference.setup_world(scene, args.radius)
    reference.add_sun(scene)
    camera = reference.add_camera(scene, args.camera)
    render = scene.render
    render.resolution_x, render.resolution_y = args.width, args.height
    render.resolution_percentage = 100
    if args.border:
        render.use_border = render.use_crop_to_border = True
        (render.border_min_x, render.border_max_x, render.border_min_y,
         render.border_max_y) = args.border
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
    compat = addon_compat()
    file_format = args.format if args.format != "auto" else \
        'PNG' if args.output.endswith(".png") else 'OPEN_EXR'
    compat.set_image_format(render.image_settings, file_format, color_mode='RGBA',
                            color_depth='8' if file_format == 'PNG' else '32')
    render.filepath = args.output
    render.use_file_extension = True
    # Linear output, so that tests can compare pixels with the passes.
    scene.view_settings.view_transform = 'Standard'
    if args.compositor_device != "default":
        render.compositor_device = args.compositor_device
    scene.frame_start, scene.frame_end = 1, args.frames
    if args.frames > 1:
        # The camera moves and turns: each frame's AO needs that frame's camera.
        camera.location.x -= 0.2
        camera.rotation_euler.z -= 0.08
        camera.keyframe_insert("location", frame=1)
        camera.keyframe_insert("rotation_euler", frame=1)
        camera.location.x += 0.4
        camera.rotation_euler.z += 0.16
        camera.keyframe_insert("location", frame=args.frames)
        camera.keyframe_insert("rotation_euler", frame=args.frames)

    tree = compat.ensure_compositor_tree(scene)
    tree.nodes.clear()
    rl = tree.nodes.new("CompositorNodeRLayers")
    ssao = tree.nodes.new("CompositorNodeSSAO")
    ssao.radius = args.radius
    if args.hidden_surfaces is not None:
        ssao.hidden_surfaces = args.hidden_surfaces
    if args.overscan is not None:
        ssao.overscan = args.overscan
    composite, composite_input = compat.add_result_output(tree)
    viewer = tree.nodes.new("CompositorNodeViewer")
    rl.location, ssao.location = (-300, 0), (0, 0)
    composite.location, viewer.location = (300, 100), (300, -150)
    tree.links.new(rl.outputs["Image"], ssao.inputs["Image"])
    tree.links.new(rl.outputs["Depth"], ssao.inputs["Depth"])
    tree.links.new(rl.outputs["Normal"], ssao.inputs["Normal"])
    tree.links.new(ssao.outputs["Image"], composite_input)
    tree.links.new(ssao.outputs["AO"], viewer.inputs["Image"])
    if args.passes_dir:
        slots = [("Image", 'RGBA'), ("Depth", 'FLOAT'), ("Normal", 'VECTOR')]
        if args.ao_pass:
            slots.append(("AO", 'RGBA'))
        # The node's own AO output: written again, with the computed AO, by the re-composite.
        passes = compat.new_file_output(tree, slots + [("SSAO", 'FLOAT')])
        passes.location = (0, -300)
        compat.set_file_output_target(passes, os.path.abspath(args.passes_dir), "")
        compat.set_image_format(passes.format, 'OPEN_EXR_MULTILAYER', color_depth='32')
        for name, _ in slots:
            # Cycles' AO pass is "AO" on Render Layers before 5.0, "Ambient Occlusion" after.
            source = rl.outputs.get(name) or rl.outputs["Ambient Occlusion"]
            tree.links.new(source, passes.inputs[name])
        tree.links.new(ssao.outputs["AO"], passes.inputs["SSAO"])
    out_prefix = os.path.splitext(os.path.abspath(args.out))[0]
    reference.write_json(out_prefix + ".camera.json", reference.camera_description(camera))
    if args.frames > 1:  # and each frame's camera, as out_prefix.camera.NNNN.json
        for frame in range(1, args.frames + 1):
            scene.frame_set(frame)
            reference.write_json(f"{out_prefix}.camera.{frame:04d}.json",
                                 reference.camera_description(camera))
        scene.frame_set(1)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.out))
    print(f"build_ssao_scene: saved {args.out} ({args.engine}, {args.camera}, "
          f"{args.width}x{args.height}, {args.frames} frame(s))")


if __name__ == "__main__":
    main()
