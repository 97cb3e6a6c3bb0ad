# SPDX-License-Identifier: MIT
"""The benchmark's reference scenes, built in Blender from scratch, and their ground truth.

Each scene is a layout of plain grey geometry chosen for one way SSAO goes wrong:

* ``contact``      boxes and a sphere on a floor against a wall (the test scene of
                   make_reference_scene.py): contact shadows and a concave corner.
* ``thin``         a fence of thin posts and rails 0.25 m in front of a wall, and free-standing
                   thin columns: occluders much thinner than the AO distance.
* ``cavity``       a bookcase of 2 cm boards with deep cells and an open crate in a room
                   corner: enclosed spaces.
* ``depth_range``  objects 3 to 5 m from the camera against buildings up to 300 m away and a
                   horizon: projected AO radii from hundreds of pixels to about two.
* ``ortho``        blocks, steps, a torus and a sphere under an orthographic camera.
* ``heavy``        spheres, tori and a floor grid of about 10k triangles, flat shaded, whose
                   triangles are split in four ``--level`` times (simple subdivision: the shape,
                   the passes and the AO stay the same while the triangle count grows to ~10M).

Reference mode (the ground truth; also Combined, Depth and Normal passes):

    blender -b --factory-startup -noaudio --python-exit-code 1 \\
        -P scripts/blender/benchmark_scenes.py -- --scene thin --out kit/thin \\
        --width 640 --height 360 --samples 1024

writes PREFIX.exr, PREFIX.camera.json (export_cameras.py's camera description) and PREFIX.json
as make_reference_scene.py does, with ``ao_distance`` (the radius an artist would choose for the
layout) and ``triangles`` in the metadata. scripts/blender/cycles_ao_sweep.py renders the same
scenes the fast way.
"""

import argparse
import math
import os
import sys

import bmesh
import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import export_cameras  # noqa: E402
import make_reference_scene as reference  # noqa: E402


# ---------------------------------------------------------------------------
# Shapes the layouts need beyond make_reference_scene's boxes, quads and spheres

def add_cylinder(scene, name, radius, height, base_center, material, segments=16):
    """An upright closed cylinder standing on base_center."""
    bm = bmesh.new()
    # create_cone takes radius1/radius2 since Blender 3.0 (diameter1/2 before).
    bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=False, segments=segments,
                          radius1=radius, radius2=radius, depth=height)
    bmesh.ops.translate(bm, vec=Vector(base_center) + Vector((0.0, 0.0, 0.5 * height)),
                        verts=bm.verts)
    return reference.add_bmesh_object(scene, name, bm, material, smooth=True)


def add_torus(scene, name, major, minor, center, material, rotation=None, segments=48,
              rings=16, smooth=True):
    """A torus around the local Z axis, rotated by the 3x3 `rotation`, at center."""
    verts = []
    for i in range(segments):
        u = 2.0 * math.pi * i / segments
        for j in range(rings):
            v = 2.0 * math.pi * j / rings
            r = major + minor * math.cos(v)
            verts.append(Vector((r * math.cos(u), r * math.sin(u), minor * math.sin(v))))
    faces = []
    for i in range(segments):
        for j in range(rings):
            a = i * rings + j
            b = ((i + 1) % segments) * rings + j
            c = ((i + 1) % segments) * rings + (j + 1) % rings
            d = i * rings + (j + 1) % rings
            faces.append((a, b, c, d))
    rot = rotation if rotation is not None else Matrix.Identity(3)
    verts = [rot @ v + Vector(center) for v in verts]
    return reference.add_mesh_object(scene, name, verts, faces, material, smooth=smooth)


def add_grid(scene, name, x_range, y_range, cuts, material):
    """A floor quad at z = 0 split into cuts x cuts quads."""
    (x0, x1), (y0, y1) = x_range, y_range
    verts = [(x0 + (x1 - x0) * i / cuts, y0 + (y1 - y0) * j / cuts, 0.0)
             for j in range(cuts + 1) for i in range(cuts + 1)]
    faces = [(j * (cuts + 1) + i, j * (cuts + 1) + i + 1, (j + 1) * (cuts + 1) + i + 1,
              (j + 1) * (cuts + 1) + i) for j in range(cuts) for i in range(cuts)]
    return reference.add_mesh_object(scene, name, verts, faces, material)


def add_floor_and_wall(scene, mat, x_range, y_range, wall_height):
    """A floor at z = 0 and a back wall at y = y_range[1] facing -Y, meeting at a crease."""
    (x0, x1), (y0, y1) = x_range, y_range
    reference.add_quad(scene, "Floor", [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0),
                                        (x0, y1, 0.0)], mat)
    reference.add_quad(scene, "Wall", [(x0, y1, 0.0), (x1, y1, 0.0), (x1, y1, wall_height),
                                       (x0, y1, wall_height)], mat)


# ---------------------------------------------------------------------------
# Layouts. Each builds its geometry and returns the camera settings and the AO distance.

def layout_contact(scene, mat):
    reference.build_geometry(scene)
    return {"kind": "persp", "ao_distance": 0.8}


def layout_thin(scene, mat):
    add_floor_and_wall(scene, mat, (-6.0, 6.0), (-6.0, 2.0), 2.5)
    # A fence 0.25 m in front of the wall: 5 cm posts every 25 cm, two 4 cm rails.
    for i in range(17):
        x = -2.0 + 0.25 * i
        reference.add_box(scene, "Post%02d" % i, (0.05, 0.05, 1.1), (x, 1.75, 0.55), mat)
    for k, z in enumerate((0.5, 1.08)):
        reference.add_box(scene, "Rail%d" % k, (4.1, 0.04, 0.04), (0.0, 1.72, z), mat)
    # Free-standing thin columns in the open, a bench of slats and a box for scale.
    for i in range(7):
        add_cylinder(scene, "Column%d" % i, 0.03, 1.5, (-1.2 + 0.4 * i, 0.1, 0.0), mat)
    for i in range(6):
        reference.add_box(scene, "Slat%d" % i, (1.2, 0.06, 0.03), (1.3, -1.0 + 0.09 * i, 0.45),
                          mat)
    for i, (x, y) in enumerate(((0.75, -1.0), (1.85, -1.0), (0.75, -0.55), (1.85, -0.55))):
        reference.add_box(scene, "Leg%d" % i, (0.04, 0.04, 0.45), (x, y, 0.225), mat)
    reference.add_box(scene, "Box", (0.5, 0.5, 0.5), (-1.8, -0.8, 0.25), mat, 25.0)
    return {"kind": "persp", "ao_distance": 0.5, "location": (1.9, -3.6, 1.6),
            "target": (-0.1, 1.0, 0.6)}


def layout_cavity(scene, mat):
    # A room corner: floor, back wall (y = 2) and left wall (x = -2.5).
    add_floor_and_wall(scene, mat, (-2.5, 5.0), (-6.0, 2.0), 2.6)
    reference.add_quad(scene, "LeftWall", [(-2.5, -6.0, 0.0), (-2.5, 2.0, 0.0),
                                           (-2.5, 2.0, 2.6), (-2.5, -6.0, 2.6)], mat)
    # A bookcase in the corner: 2 cm boards, 5 shelves of 36 cm, a divider, 35 cm deep cells,
    # open at the back (the wall closes it). No two boards overlap: a ray tracer's rays leaving
    # a face that lies inside another coplanar face hit it at once, which drew false dark
    # stripes on the sides' outer faces and along the front edges where the shelves used to
    # run through the sides and the divider.
    x0, x1, y0, y1, top = -2.48, -0.88, 1.63, 1.98, 1.82
    board = 0.02
    middle = (x0 + x1) / 2
    for k, x in enumerate((x0 + board / 2, x1 - board / 2, middle)):
        reference.add_box(scene, "Side%d" % k, (board, y1 - y0, top), (x, (y0 + y1) / 2, top / 2),
                          mat)
    # Each shelf in two halves, between a side and the divider.
    for k in range(6):
        z = board / 2 + k * (top - board) / 5
        for half, (left, right) in enumerate(((x0 + board, middle - board / 2),
                                              (middle + board / 2, x1 - board))):
            reference.add_box(scene, "Shelf%d%s" % (k, "ab"[half]), (right - left, y1 - y0, board),
                              (0.5 * (left + right), 0.5 * (y0 + y1), z), mat)
    # Boxes standing in two cells.
    reference.add_box(scene, "Book0", (0.25, 0.25, 0.22), (-2.2, 1.85, 0.13), mat)
    reference.add_box(scene, "Book1", (0.2, 0.3, 0.3), (-1.15, 1.8, 0.527), mat)
    # An open crate on the floor, s on a side: bottom and top whole, between them the back,
    # the front and one side (open towards the camera's side, +X), 2 cm boards that abut.
    cx, cy, s = 0.3, 0.9, 0.6
    inner = s - 2 * board
    reference.add_box(scene, "CrateBottom", (s, s, board), (cx, cy, board / 2), mat)
    reference.add_box(scene, "CrateTop", (s, s, board), (cx, cy, s - board / 2), mat)
    reference.add_box(scene, "CrateBack", (s, board, inner), (cx, cy + (s - board) / 2, s / 2),
                      mat)
    reference.add_box(scene, "CrateFront", (s, board, inner), (cx, cy - (s - board) / 2, s / 2),
                      mat)
    reference.add_box(scene, "CrateSide", (board, s - 2 * board, inner),
                      (cx - (s - board) / 2, cy, s / 2), mat)
    reference.add_sphere(scene, "Ball", 0.2, (cx, cy, 0.2 + board), mat)
    return {"kind": "persp", "ao_distance": 0.5, "location": (2.2, -2.6, 1.5),
            "target": (-1.2, 1.4, 0.7)}


def layout_depth_range(scene, mat):
    reference.add_quad(scene, "Ground", [(-400.0, -10.0, 0.0), (400.0, -10.0, 0.0),
                                         (400.0, 400.0, 0.0), (-400.0, 400.0, 0.0)], mat)
    # Near: a box, a sphere and a step 3 to 5.5 m from the camera.
    reference.add_box(scene, "NearBox", (0.5, 0.5, 0.5), (-0.6, 2.2, 0.25), mat, 30.0)
    reference.add_sphere(scene, "NearSphere", 0.3, (0.5, 2.8, 0.3), mat)
    reference.add_box(scene, "Step", (2.0, 0.6, 0.2), (0.0, 4.5, 0.1), mat)
    # Far: blocks of buildings from 20 m to 300 m.
    for k, (x, y, w, h) in enumerate(((-6.0, 20.0, 4.0, 6.0), (5.0, 28.0, 3.0, 9.0),
                                      (-25.0, 60.0, 10.0, 15.0), (15.0, 75.0, 8.0, 25.0),
                                      (-60.0, 150.0, 20.0, 30.0), (40.0, 180.0, 15.0, 40.0),
                                      (-10.0, 300.0, 40.0, 35.0), (110.0, 260.0, 30.0, 20.0))):
        reference.add_box(scene, "Block%d" % k, (w, w, h), (x, y, h / 2), mat, 10.0 * k)
    return {"kind": "persp", "ao_distance": 1.0, "location": (0.0, -0.8, 1.3),
            "target": (0.0, 8.0, -0.1), "clip": (0.1, 1000.0)}


def layout_ortho(scene, mat):
    add_floor_and_wall(scene, mat, (-6.0, 6.0), (-6.0, 2.5), 1.5)
    # Steps against the wall, a 3 x 3 grid of blocks, a torus lying flat and a sphere.
    for k in range(4):
        reference.add_box(scene, "Step%d" % k, (1.2, 0.4 * (4 - k), 0.25),
                          (-2.2, 2.5 - 0.2 * (4 - k), 0.125 + 0.25 * k), mat)
    heights = (0.3, 0.9, 0.5, 1.2, 0.4, 0.7, 0.6, 0.2, 1.0)
    for k, h in enumerate(heights):
        x, y = 0.2 + 0.55 * (k % 3), 0.2 + 0.55 * (k // 3)
        reference.add_box(scene, "Block%d" % k, (0.4, 0.4, h), (x, y, h / 2), mat)
    add_torus(scene, "Torus", 0.45, 0.12, (-1.0, -0.8, 0.12), mat)
    reference.add_sphere(scene, "Sphere", 0.35, (1.0, -1.2, 0.35), mat)
    return {"kind": "ortho", "ao_distance": 0.6, "location": (5.0, -5.5, 5.0),
            "target": (-0.2, 0.4, 0.4), "ortho_scale": 7.5}


def layout_heavy(scene, mat):
    # About 10k triangles, flat shaded so that subdividing changes no normal.
    add_grid(scene, "Floor", (-5.0, 5.0), (-5.0, 4.0), 50, mat)
    for k, (x, y, r) in enumerate(((-1.2, 0.5, 0.5), (0.2, 1.2, 0.7), (1.4, -0.2, 0.4))):
        reference.add_sphere(scene, "Sphere%d" % k, r, (x, y, r), mat, segments=32, rings=16,
                             smooth=False)
    stand = Matrix.Rotation(math.radians(90.0), 3, "X")
    add_torus(scene, "TorusFlat", 0.5, 0.15, (-0.3, -0.9, 0.15), mat, segments=32, rings=12,
              smooth=False)
    add_torus(scene, "TorusUp", 0.5, 0.15, (1.3, 1.6, 0.65), mat, rotation=stand, segments=32,
              rings=12, smooth=False)
    reference.add_box(scene, "Box", (0.6, 0.6, 0.6), (-2.2, -0.3, 0.3), mat, 20.0)
    return {"kind": "persp", "ao_distance": 0.8, "location": (2.7, -4.3, 2.2),
            "target": (-0.2, 0.6, 0.6)}


LAYOUTS = {
    "contact": layout_contact,
    "thin": layout_thin,
    "cavity": layout_cavity,
    "depth_range": layout_depth_range,
    "ortho": layout_ortho,
    "heavy": layout_heavy,
}


def subdivide(scene, level):
    """Splits every face of every mesh `level` times (simple subdivision, applied), so the
    render call pays for the triangles and not for evaluating a modifier."""
    if level <= 0:
        return
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in [o for o in scene.objects if o.type == "MESH"]:
        mod = obj.modifiers.new("Split", "SUBSURF")
        mod.subdivision_type = "SIMPLE"
        mod.levels = mod.render_levels = level
        depsgraph.update()
        mesh = bpy.data.meshes.new_from_object(obj.evaluated_get(depsgraph))
        obj.modifiers.remove(mod)
        old, obj.data = obj.data, mesh
        bpy.data.meshes.remove(old)


def triangle_count(scene):
    count = 0
    for obj in scene.objects:
        if obj.type == "MESH":
            obj.data.calc_loop_triangles()
            count += len(obj.data.loop_triangles)
    return count


def build_scene(scene, name, level=0):
    """Clears `scene`, builds layout `name` (subdivided `level` times) with the world, the sun
    and the camera. Returns (camera object, layout settings)."""
    reference.clear_scene(scene)
    layout = LAYOUTS[name](scene, reference.grey_material())
    reference.setup_world(scene, layout["ao_distance"])
    reference.add_sun(scene)
    keys = ("location", "target", "clip", "ortho_scale")
    cam_obj = reference.add_camera(scene, layout["kind"],
                                   **{k: layout[k] for k in keys if k in layout})
    subdivide(scene, level)
    return cam_obj, layout


# ---------------------------------------------------------------------------
# Command line (reference mode)

def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="benchmark_scenes.py",
        description="Render a benchmark scene with its ground truth (Cycles' AO pass) into "
                    "PREFIX.exr, PREFIX.camera.json and PREFIX.json.")
    parser.add_argument("--scene", choices=sorted(LAYOUTS), required=True)
    parser.add_argument("--out", required=True, help="output prefix")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--samples", type=int, default=1024, help="samples per pixel")
    parser.add_argument("--level", type=int, default=0,
                        help="times every face is split in four (heavy scene)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--border", default=None,
                        help="MIN_X,MAX_X,MIN_Y,MAX_Y: render only this region (fractions)")
    args = parser.parse_args(argv)
    if args.width < 1 or args.height < 1 or args.samples < 1 or args.threads < 1:
        parser.error("--width, --height, --samples and --threads must be positive")
    if not 0 <= args.level <= 6:
        parser.error("--level must be in 0..6")
    if args.border is not None:
        try:
            args.border = tuple(float(v) for v in args.border.split(","))
        except ValueError:
            parser.error("--border: expected four numbers")
        if len(args.border) != 4 or not all(0.0 <= v <= 1.0 for v in args.border):
            parser.error("--border: expected four fractions in [0, 1]")
    args.engine = "cycles"
    args.no_ao_pass = False
    return args


def main():
    args = parse_args(export_cameras.script_argv())
    scene = bpy.context.scene
    cam_obj, layout = build_scene(scene, args.scene, args.level)
    args.ao_distance = layout["ao_distance"]
    args.camera = layout["kind"]
    reference.render_reference(scene, cam_obj, args, os.path.abspath(args.out), args.scene,
                               {"level": args.level, "triangles": triangle_count(scene),
                                "border": args.border})


if __name__ == "__main__":
    export_cameras.run_script(main, "benchmark_scenes")
