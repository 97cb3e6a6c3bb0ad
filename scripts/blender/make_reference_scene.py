"""Build a small test scene in Blender and render a ray-traced reference.

Writes, for ``--out PREFIX``:

* ``PREFIX.exr``          OpenEXR multilayer, 32-bit float, ZIP: the passes
                          ``ViewLayer.Combined.{R,G,B,A}``, ``ViewLayer.Depth.Z``,
                          ``ViewLayer.Normal.{X,Y,Z}`` and, unless ``--no-ao-pass``,
                          ``ViewLayer.AO.{R,G,B}`` (Cycles' ray-traced ambient
                          occlusion within ``--ao-distance``: the ground truth).
* ``PREFIX.camera.json``  the camera, in the format of docs/conventions.md.
* ``PREFIX.json``         render metadata (size, samples, ao_distance, timing,
                          Blender version, and Blender's own projection matrix).

The scene is built from scratch: a floor and a back wall meeting at a right
angle (a concave corner), a box touching the wall, two stacked boxes, a
rotated box and a sphere resting on the floor, all plain grey diffuse, lit by
a sun, seen by a rotated camera that shows a strip of sky.

Run (Blender 3.4 and 4.x):

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/make_reference_scene.py -- --out /tmp/ref/scene

Only Cycles on the CPU is supported for now; the engine is chosen through
``ENGINES`` so that another one (EEVEE) can be added next to it.
"""

import argparse
import math
import os
import sys
import time

import bpy
import bmesh
from mathutils import Euler, Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# The camera JSON and the script helpers live in export_cameras.py (the camera exporter for
# users' scenes); the scripts that import this module use them through it too.
from export_cameras import (camera_description, matrix_rows, run_script,  # noqa: E402,F401
                            script_argv, write_json)

VIEW_LAYER_NAME = "ViewLayer"

# Scene layout, in metres, Z up. The floor is z = 0, the back wall is the
# plane y = WALL_Y facing -Y; they share the edge y = WALL_Y, z = 0.
FLOOR_X = (-7.0, 5.0)
FLOOR_Y = (-7.0, 2.0)
WALL_Y = 2.0
WALL_HEIGHT = 2.0

# Camera: rotated about Z (not looking along an axis) and tilted down.
CAMERA_LOCATION = Vector((2.7, -4.3, 2.2))
CAMERA_TARGET = Vector((-0.2, 0.6, 0.75))
CAMERA_LENS = 35.0
CAMERA_SENSOR_WIDTH = 36.0
CAMERA_CLIP = (0.1, 100.0)

GREY = (0.6, 0.6, 0.6, 1.0)
WORLD_COLOR = (0.45, 0.55, 0.75, 1.0)


# ---------------------------------------------------------------------------
# Command line

def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="make_reference_scene.py",
        description="Render the test scene with Blender into PREFIX.exr, "
                    "PREFIX.camera.json and PREFIX.json.")
    parser.add_argument("--out", required=True,
                        help="output prefix (writes PREFIX.exr, PREFIX.camera.json, PREFIX.json)")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=90)
    parser.add_argument("--samples", type=int, default=256,
                        help="samples per pixel (default 256)")
    parser.add_argument("--ao-distance", type=float, default=0.8,
                        help="AO ray length, world.light_settings.distance (default 0.8)")
    parser.add_argument("--camera", choices=("persp", "ortho"), default="persp")
    parser.add_argument("--engine", choices=sorted(ENGINES), default="cycles")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1, help="Cycles seed (default 1)")
    parser.add_argument("--no-ao-pass", action="store_true",
                        help="do not render the AO pass (for a small sample image)")
    parser.add_argument("--scene-name", default=None,
                        help="name stored in the metadata (default: basename of --out)")
    args = parser.parse_args(argv)
    if args.width < 1 or args.height < 1:
        parser.error("--width and --height must be positive")
    if args.samples < 1:
        parser.error("--samples must be positive")
    if not args.ao_distance > 0.0:
        parser.error("--ao-distance must be positive")
    if args.threads < 1:
        parser.error("--threads must be positive")
    if "#" in os.path.basename(args.out):
        parser.error("--out must not contain '#' (Blender reads it as a frame number)")
    return args


# ---------------------------------------------------------------------------
# Scene construction

def clear_scene(scene):
    """Remove every object (and its data) that the startup file put there."""
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for collection in (bpy.data.meshes, bpy.data.cameras, bpy.data.lights,
                       bpy.data.materials):
        for block in list(collection):
            if block.users == 0:
                collection.remove(block)


def grey_material():
    mat = bpy.data.materials.new("Grey")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = GREY
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    mat.diffuse_color = GREY
    return mat


def add_mesh_object(scene, name, verts, faces, material, smooth=False):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    mesh.validate()
    mesh.update()
    for poly in mesh.polygons:
        poly.use_smooth = smooth
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def add_quad(scene, name, corners, material):
    """A single quad; corners are given counter-clockwise seen from the front."""
    return add_mesh_object(scene, name, corners, [(0, 1, 2, 3)], material)


def add_box(scene, name, size, center, material, rotation_z_deg=0.0):
    """An axis-aligned box of size (sx, sy, sz), rotated about Z, at center."""
    sx, sy, sz = (0.5 * s for s in size)
    verts = [Vector((x, y, z)) for z in (-sz, sz) for y in (-sy, sy) for x in (-sx, sx)]
    # Vertex index = ix + 2*iy + 4*iz. Faces wound counter-clockwise seen from outside.
    faces = [
        (0, 2, 3, 1),  # bottom (-Z)
        (4, 5, 7, 6),  # top (+Z)
        (0, 1, 5, 4),  # front (-Y)
        (2, 6, 7, 3),  # back (+Y)
        (0, 4, 6, 2),  # left (-X)
        (1, 3, 7, 5),  # right (+X)
    ]
    rot = Matrix.Rotation(math.radians(rotation_z_deg), 3, "Z")
    verts = [rot @ v + Vector(center) for v in verts]
    return add_mesh_object(scene, name, verts, faces, material)


def add_bmesh_object(scene, name, bm, material, smooth):
    """An object made of the bmesh `bm` (which is freed)."""
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    for poly in mesh.polygons:
        poly.use_smooth = smooth
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def add_sphere(scene, name, radius, center, material, segments=48, rings=24, smooth=True):
    bm = bmesh.new()
    # bmesh's create_uvsphere takes 'radius' since Blender 3.0 ('diameter' before).
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bmesh.ops.translate(bm, vec=Vector(center), verts=bm.verts)
    return add_bmesh_object(scene, name, bm, material, smooth)


def build_geometry(scene):
    mat = grey_material()
    x0, x1 = FLOOR_X
    y0, y1 = FLOOR_Y
    add_quad(scene, "Floor",
             [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)], mat)
    # The wall faces -Y (towards the camera) and shares the floor's back edge.
    add_quad(scene, "Wall",
             [(x0, WALL_Y, 0.0), (x1, WALL_Y, 0.0),
              (x1, WALL_Y, WALL_HEIGHT), (x0, WALL_Y, WALL_HEIGHT)], mat)
    # A box standing on the floor, its back face touching the wall.
    add_box(scene, "BoxAtWall", (1.0, 0.9, 1.1), (-1.6, WALL_Y - 0.45, 0.55), mat)
    # Two stacked boxes: the top one is smaller and set off-centre.
    add_box(scene, "StackBottom", (1.1, 1.0, 0.7), (0.9, 0.9, 0.35), mat)
    add_box(scene, "StackTop", (0.6, 0.6, 0.5), (0.75, 0.85, 0.95), mat,
            rotation_z_deg=12.0)
    # A box rotated about Z, standing alone on the floor.
    add_box(scene, "RotatedBox", (0.8, 0.8, 0.8), (-0.5, -0.6, 0.4), mat,
            rotation_z_deg=-20.0)
    # A sphere resting on the floor (curved contact).
    add_sphere(scene, "Sphere", 0.5, (1.2, -0.35, 0.5), mat)


def _math(tree, operation, a, b=None):
    """A Math node of `operation` on a (and b): sockets are linked, numbers are set."""
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    for socket, value in zip(node.inputs, (a, b)):
        if value is None:
            continue
        if isinstance(value, (int, float)):
            socket.default_value = value
        else:
            tree.links.new(value, socket)
    return node.outputs[0]


def cutout_material(name, kind):
    """Grey diffuse with an alpha cut-out, as artists make them: `lattice` is a Mix Shader of
    a Transparent BSDF and the diffuse by a mask of slats (a third of the card solid); `leaf`
    is a Principled BSDF whose Alpha is an ellipse inscribed in the card."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    coords = tree.nodes.new("ShaderNodeTexCoord")
    xyz = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(coords.outputs["UV"], xyz.inputs[0])
    u, v = xyz.outputs["X"], xyz.outputs["Y"]
    if kind == "lattice":
        # Slats along both axes: solid where either fraction is below 0.18 (about a third).
        slat_u = _math(tree, 'LESS_THAN', _math(tree, 'FRACT', _math(tree, 'MULTIPLY', u, 9.0)),
                       0.18)
        slat_v = _math(tree, 'LESS_THAN', _math(tree, 'FRACT', _math(tree, 'MULTIPLY', v, 6.0)),
                       0.18)
        alpha = _math(tree, 'MAXIMUM', slat_u, slat_v)
        diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = GREY
        mix = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(alpha, mix.inputs["Fac"])
        tree.links.new(tree.nodes.new("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[1])
        tree.links.new(diffuse.outputs[0], mix.inputs[2])
        tree.links.new(mix.outputs[0], out.inputs["Surface"])
    else:
        du = _math(tree, 'SUBTRACT', u, 0.5)
        dv = _math(tree, 'SUBTRACT', v, 0.5)
        radius = _math(tree, 'ADD', _math(tree, 'MULTIPLY', du, du),
                       _math(tree, 'MULTIPLY', _math(tree, 'MULTIPLY', dv, dv), 0.45))
        alpha = _math(tree, 'LESS_THAN', radius, 0.25 * 0.45)
        bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
        bsdf.inputs["Base Color"].default_value = GREY
        tree.links.new(alpha, bsdf.inputs["Alpha"])
        tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    mat.diffuse_color = GREY
    return mat


def add_card(scene, name, size, center, rotation, material):
    """A single plane (no thickness, no back face of its own) of `size` (x, y) with UVs over
    [0, 1], rotated by the Euler angles `rotation` (degrees) about its centre."""
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")  # create_grid fills it (calc_uvs)
    bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=0.5, calc_uvs=True)
    bmesh.ops.scale(bm, vec=(size[0], size[1], 1.0), verts=bm.verts)
    obj = add_bmesh_object(scene, name, bm, material, smooth=False)
    obj.rotation_euler = Euler([math.radians(a) for a in rotation])
    obj.location = Vector(center)
    return obj


def add_curtain(scene, name, width, height, center, material, folds=5, depth=0.12):
    """An open, folded sheet hanging in the XZ plane (a curtain): a grid waved along X."""
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_grid(bm, x_segments=60, y_segments=12, size=0.5, calc_uvs=True)
    for vert in bm.verts:
        x, y = vert.co.x * width, vert.co.y * height
        vert.co = Vector((x, depth * math.sin(2.0 * math.pi * folds * (x / width + 0.5)), y))
    bmesh.ops.translate(bm, vec=Vector(center), verts=bm.verts)
    return add_bmesh_object(scene, name, bm, material, smooth=True)


def build_cutouts(scene):
    """Open surfaces with alpha cut-outs, as real scenes have them (issue 33): a lattice fence
    (one plane, two thirds of it holes) 1 m in front of the wall, leaf cards facing the camera
    or away from it (single planes, alpha-cut ellipses), and a folded curtain (an open sheet)."""
    lattice = cutout_material("Lattice", "lattice")
    leaf = cutout_material("Leaf", "leaf")
    grey = bpy.data.materials.get("Grey") or grey_material()
    add_card(scene, "Fence", (4.0, 1.4), (-1.3, WALL_Y - 1.0, 0.7), (90.0, 0.0, 0.0), lattice)
    for index, (center, rotation) in enumerate((
            ((-0.9, 1.6, 1.45), (70.0, 0.0, 25.0)),     # front towards the camera
            ((-0.55, 1.45, 1.25), (110.0, 0.0, -30.0)),  # seen from its back
            ((0.25, 1.7, 1.55), (80.0, 15.0, 160.0)),   # seen from its back
            ((1.95, 0.2, 0.25), (20.0, 0.0, 40.0)),     # lying near the floor
            ((-0.15, -0.15, 0.95), (60.0, 0.0, -15.0)))):
        add_card(scene, f"Leaf{index}", (0.45, 0.3), center, rotation, leaf)
    add_curtain(scene, "Curtain", 1.4, 1.6, (2.9, 1.5, 0.85), grey)


def build_render_features(scene):
    """What decides which surface a camera ray meets besides the geometry (issue 33): alpha
    cut-outs under each blend method (Cycles ignores it), material displacement that moves the
    surface, a holdout object, an object hidden from the camera, and a collection that is a
    holdout in the view layer. Adds the cut-outs of build_cutouts."""
    build_cutouts(scene)
    for material, method in ((bpy.data.materials["Lattice"], 'HASHED'),
                             (bpy.data.materials["Leaf"], 'BLEND')):
        try:  # EEVEE's setting; 4.2+ keeps it for files but may refuse some values
            material.blend_method = method
        except (AttributeError, TypeError):
            pass
    # A plane of ripples made by the material's displacement alone (Cycles' true
    # displacement on a finely divided grid).
    bumpy = bpy.data.materials.new("Displaced")
    bumpy.use_nodes = True
    tree = bumpy.node_tree
    out = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    wave = tree.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 3.0
    displacement = tree.nodes.new("ShaderNodeDisplacement")
    displacement.inputs["Scale"].default_value = 0.25
    displacement.inputs["Midlevel"].default_value = 0.0
    tree.links.new(wave.outputs["Fac"], displacement.inputs["Height"])
    tree.links.new(displacement.outputs[0], out.inputs["Displacement"])
    if hasattr(bumpy, "displacement_method"):
        bumpy.displacement_method = 'DISPLACEMENT'
    else:
        bumpy.cycles.displacement_method = 'DISPLACEMENT'
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_grid(bm, x_segments=96, y_segments=96, size=0.7, calc_uvs=True)
    bmesh.ops.translate(bm, vec=Vector((2.3, -1.4, 0.02)), verts=bm.verts)
    add_bmesh_object(scene, "Displaced", bm, bumpy, smooth=True)
    grey = bpy.data.materials["Grey"]
    holdout = add_sphere(scene, "Holdout", 0.3, (0.3, -1.3, 0.3), grey, segments=24, rings=12)
    holdout.is_holdout = True
    hidden = add_box(scene, "HiddenFromCamera", (0.6, 0.6, 0.6), (-1.0, -1.6, 0.3), grey)
    hidden.visible_camera = False
    collection = bpy.data.collections.new("HoldoutCollection")
    scene.collection.children.link(collection)
    box = add_box(scene, "InHoldoutCollection", (0.4, 0.4, 0.9), (2.0, 1.2, 0.45), grey)
    scene.collection.objects.unlink(box)
    collection.objects.link(box)
    for layer in scene.view_layers:
        layer.layer_collection.children[collection.name].holdout = True


def setup_world(scene, ao_distance):
    world = scene.world
    if world is None:
        world = bpy.data.worlds.new("World")
        scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    nodes.clear()
    bg = nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = WORLD_COLOR
    bg.inputs["Strength"].default_value = 0.6
    out = nodes.new("ShaderNodeOutputWorld")
    world.node_tree.links.new(bg.outputs["Background"], out.inputs["Surface"])
    world.color = WORLD_COLOR[:3]
    # Cycles' AO pass counts occluders within this distance.
    world.light_settings.distance = ao_distance
    return world


def add_sun(scene):
    light = bpy.data.lights.new("Sun", type="SUN")
    light.energy = 2.0
    light.angle = math.radians(3.0)
    obj = bpy.data.objects.new("Sun", light)
    # Sun from behind the camera, high on its left: shadows fall right and back.
    obj.rotation_euler = Euler((math.radians(40.0), 0.0, math.radians(-35.0)), "XYZ")
    scene.collection.objects.link(obj)
    return obj


def add_camera(scene, kind, location=CAMERA_LOCATION, target=CAMERA_TARGET, lens=CAMERA_LENS,
               clip=CAMERA_CLIP, ortho_scale=None):
    """The scene's camera at `location` looking at `target`. An orthographic camera shows, by
    default, what the perspective one shows at the target's distance."""
    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    cam.sensor_width = CAMERA_SENSOR_WIDTH
    cam.sensor_fit = "AUTO"
    cam.shift_x = 0.0
    cam.shift_y = 0.0
    cam.clip_start, cam.clip_end = clip
    location, target = Vector(location), Vector(target)
    direction = target - location
    if kind == "ortho":
        cam.type = "ORTHO"
        # With sensor fit AUTO the sensor width spans the larger image side.
        cam.ortho_scale = ortho_scale or direction.length * cam.sensor_width / cam.lens
    else:
        cam.type = "PERSP"
    obj = bpy.data.objects.new("Camera", cam)
    rot = direction.to_track_quat("-Z", "Y").to_matrix().to_4x4()
    obj.matrix_world = Matrix.Translation(location) @ rot
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


# ---------------------------------------------------------------------------
# Render settings

def configure_cycles(scene, args):
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args.samples
    cycles.use_adaptive_sampling = False
    # Debian's Blender is built without OpenImageDenoise: denoising must be off.
    cycles.use_denoising = False
    cycles.seed = args.seed
    cycles.use_animated_seed = False
    # The AO pass does not depend on the bounces; the Combined pass needs few.
    cycles.max_bounces = 4
    cycles.diffuse_bounces = 4


# Engines that can render the reference. An EEVEE entry would set its own
# options here (and its depth background is 65504, not 1e10).
ENGINES = {
    "cycles": configure_cycles,
}


def use_multilayer_exr(img):
    """Image settings that write every pass losslessly: multilayer EXR, 32-bit float, ZIP."""
    img.file_format = "OPEN_EXR_MULTILAYER"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    return img


def single_view_layer(scene):
    """Removes every view layer but the first, names it ViewLayer and returns it."""
    while len(scene.view_layers) > 1:
        scene.view_layers.remove(scene.view_layers[-1])
    layer = scene.view_layers[0]
    layer.name = VIEW_LAYER_NAME
    return layer


def configure_render(scene, args, exr_path):
    r = scene.render
    r.resolution_x = args.width
    r.resolution_y = args.height
    r.resolution_percentage = 100
    r.pixel_aspect_x = 1.0
    r.pixel_aspect_y = 1.0
    r.film_transparent = False
    # --border: render a region only (the rest of the image stays empty), for a second render
    # that measures the reference's own noise at a fraction of the cost.
    border = getattr(args, "border", None)
    r.use_border = border is not None
    if border is not None:
        r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = border
        r.use_crop_to_border = False
    r.threads_mode = "FIXED"
    r.threads = args.threads
    # Write the render result itself: no compositing, no sequencer.
    r.use_compositing = False
    r.use_sequencer = False
    # The EXR gets no paths, dates or timings, so that it is reproducible.
    for flag in ("use_stamp_date", "use_stamp_time", "use_stamp_render_time",
                 "use_stamp_frame", "use_stamp_frame_range", "use_stamp_memory",
                 "use_stamp_hostname", "use_stamp_filename", "use_stamp_marker",
                 "use_stamp_sequencer_strip", "use_stamp_note"):
        if hasattr(r, flag):
            setattr(r, flag, False)
    r.use_stamp_camera = True
    r.use_stamp_scene = True
    r.use_stamp_lens = False

    img = use_multilayer_exr(r.image_settings)
    if hasattr(img, "use_preview"):
        img.use_preview = False
    # The path already ends in .exr; with the extension option on, Blender keeps it.
    r.use_file_extension = True
    r.filepath = exr_path

    # Exactly one view layer, named ViewLayer, with the passes we need.
    layer = single_view_layer(scene)
    layer.use = True
    layer.use_pass_combined = True
    layer.use_pass_z = True
    layer.use_pass_normal = True
    layer.use_pass_ambient_occlusion = not args.no_ao_pass
    return layer


# ---------------------------------------------------------------------------
# Output

def render_reference(scene, cam_obj, args, prefix, scene_name, extra_meta=None):
    """Renders `scene` with the passes of args into PREFIX.exr and writes PREFIX.camera.json
    and PREFIX.json (metadata, plus `extra_meta`)."""
    out_dir = os.path.dirname(prefix)
    os.makedirs(out_dir, exist_ok=True)
    exr_path = prefix + ".exr"
    camera_path = prefix + ".camera.json"
    meta_path = prefix + ".json"
    for path in (exr_path, camera_path, meta_path):
        if os.path.exists(path):
            os.remove(path)

    scene.frame_set(1)
    ENGINES[args.engine](scene, args)
    layer = configure_render(scene, args, exr_path)
    if bpy.context.view_layer is not None:
        bpy.context.view_layer.update()

    t0 = time.perf_counter()
    result = bpy.ops.render.render(write_still=True, scene=scene.name)
    render_seconds = time.perf_counter() - t0
    if "FINISHED" not in result:
        raise RuntimeError("render.render returned %s" % (result,))
    if not os.path.isfile(exr_path):
        listing = sorted(os.listdir(out_dir))
        raise RuntimeError("expected %s after rendering; the folder holds %s"
                           % (exr_path, listing))

    depsgraph = bpy.context.evaluated_depsgraph_get()
    projection = cam_obj.calc_matrix_camera(
        depsgraph, x=args.width, y=args.height, scale_x=1.0, scale_y=1.0)

    camera = camera_description(cam_obj)
    write_json(camera_path, camera)
    passes = ["Combined", "Depth", "Normal"] + ([] if args.no_ao_pass else ["AO"])
    meta = {
        "scene": scene_name,
        "width": args.width,
        "height": args.height,
        "samples": args.samples,
        "ao_distance": args.ao_distance,
        "render_seconds": round(render_seconds, 3),
        "engine": args.engine.upper(),
        "camera_type": camera["type"],
        "seed": args.seed,
        "threads": args.threads,
        "view_layer": layer.name,
        "passes": passes,
        "blender_version": bpy.app.version_string,
        "projection": matrix_rows(projection),
    }
    meta.update(extra_meta or {})
    write_json(meta_path, meta)

    print("make_reference_scene: wrote %s (%dx%d, %d spp, %s %s, passes %s, "
          "ao_distance %g) in %.2f s render time, %d bytes"
          % (exr_path, args.width, args.height, args.samples, args.engine,
             camera["type"], "+".join(passes), args.ao_distance, render_seconds,
             os.path.getsize(exr_path)))


def main():
    args = parse_args(script_argv())
    prefix = os.path.abspath(args.out)
    scene = bpy.context.scene
    clear_scene(scene)
    build_geometry(scene)
    setup_world(scene, args.ao_distance)
    add_sun(scene)
    cam_obj = add_camera(scene, args.camera)
    render_reference(scene, cam_obj, args, prefix, args.scene_name or os.path.basename(prefix))


if __name__ == "__main__":
    run_script(main, "make_reference_scene")
