# SPDX-License-Identifier: MIT
"""The surfaces the render does not show, and a guard band: a helper render of the scene on the
same pixel grid, with Cycles at 1 sample per pixel whatever engine the beauty uses.

It gives, for each pixel, the surfaces along the camera ray as the beauty's rays meet them
(alpha holes skipped, material displacement applied, ending at a holdout), each a front or a
back face, an open surface (a card) with something behind it as a front and a back face at its
depth, and the 1st surface's world-space normal; with a guard band of G pixels it renders
W+2G x H+2G pixels, the frame (or the render border's crop) widened on the same grid.

How (measured facts: docs/blender.md, "Hidden surfaces and overscan"): one view layer, every
surface running one node group (_hits_group): a Transparent BSDF, so that the camera ray passes
every surface, with AOV outputs written at the surface whose Light Path > Transparent Depth is
j. Cycles writes a camera ray's AOVs at every transparent surface it passes (up to the first
opaque one, and here there is none), and at 1 sample each pixel has one ray. The group runs as
the view layer's material override, or, when a material's alpha or displacement matters, from
an output added to every material for the render only (_MaterialOutputs). One view layer, so
the scene is synchronised once (every view layer synchronises it again).

The scene, its view layers, its camera and its file are not changed: the render is of a hidden
helper scene `.SSAO layers <scene>` that links the scene's collections, with a camera object of
its own set from the scene's camera; what it adds to materials and holdout objects for the
render is removed after it. Like recomposite.py's, the helper is kept and reused (removing a
scene in a render handler crashes) and removed before a file is saved."""
import concurrent.futures
import os

import bpy
import mathutils
import numpy as np

from . import camera as camera_module
from . import compat, multilayer, session

HELPER_PREFIX = ".SSAO layers "
LAYER_NAME = "SSAO layers"
MATERIAL_NAME = ".SSAO layers override"
GROUP_NAME = ".SSAO layers hits"
# The custom property that marks a holdout object while the helper renders (_Holdouts).
HOLDOUT_PROPERTY = "ssao_helper_holdout"
MAX_HITS = 5  # the library reads up to depth5 (docs/api.md)
# The open-surface test (_hits_group): inside rays per surface, and how far they look (scene
# units; a closed mesh is met within its own size).
OPEN_SAMPLES = 1
# Transparent depths recorded beyond `hits` (_slots).
EXTRA_SLOTS = 1
OPEN_DISTANCE = 1e4
BACKGROUND = 1e10  # Cycles' Depth pass where there is no surface, Blender's convention
# Layers kept per scene (session.current.kept_layers): one render serves every recompute of that
# frame, and each of several nodes with other settings gets its own.
CACHED_PER_SCENE = 2
# surfaces() orders the surfaces of this many rows at a time: a 4448 x 2768 helper render on 2
# cores took 3.1 s and 1.4 GB more memory in blocks of 128 rows, against 6.8 s and 2.2 GB at
# once (docs/blender.md, "Overhead per frame").
SURFACE_BLOCK_ROWS = 128
# Blocks ordered at once, at most: each holds ~190 bytes a pixel of intermediates (~110 MB for
# 128 rows of a 4560 px wide helper frame), so more would bring back the whole frame's.
SURFACE_MAX_THREADS = 8


def forget(scene_name=None):
    """Drops the layers kept for `scene_name` (all with None): a new render of it is coming."""
    if scene_name is None:
        session.current.kept_layers.clear()
    else:
        session.current.kept_layers.pop(scene_name, None)


def _slots(hits):
    """Transparent depths the helper records: `hits` surfaces, plus room for an alpha hole
    passed before them (each takes a transparent bounce). More room (3) changed nothing on the
    cut-out scene (docs/blender.md) and costs shading."""
    return hits + EXTRA_SLOTS


def _aov_names(hits):
    return [f"hit{j}" for j in range(_slots(hits))] + ["open", "stop", "normal"]


def _alpha_threshold(scene):
    """Cycles writes a pixel's Depth and Normal at the first surface whose alpha is at least the
    view layer's Alpha Threshold (0: the first surface, whatever its alpha)."""
    return float(getattr(_view_layer(scene), "pass_alpha_threshold", 0.5))


def _hits_group(hits, threshold):
    """The node group every helper surface runs: a Transparent BSDF (the camera ray passes every
    surface) and AOV outputs written at the surface `Light Path > Transparent Depth` = j:
      hit<j>: its planar depth (Camera Data > View Z Depth), negated on a back face, 0 where that
        surface is not solid (its alpha, the group's input, is below `threshold`: a hole);
      stop: the sum of 2^j over the solid surfaces of holdout objects (the ray ends there);
      open: the sum of 2^j over the solid surfaces that are open (a card, a sheet): the
        Ambient Occlusion node traced inside the surface against its own object only escapes
        (a closed mesh always meets its other side);
      normal: the sum of the solid surfaces' world normals, each weighted by 0.001^j, so that
        the first solid surface's dominates (1e-3 relative at most).
    Made again when made for other slots or another threshold."""
    slots = _slots(hits)
    group = bpy.data.node_groups.get(GROUP_NAME)
    if group is not None and group.get("ssao_slots") == slots and \
            group.get("ssao_threshold") == threshold:
        return group
    if group is None:
        group = bpy.data.node_groups.new(GROUP_NAME, "ShaderNodeTree")
        compat.new_socket(group, 'INPUT', 'NodeSocketFloat', "Alpha")
        compat.new_socket(group, 'OUTPUT', 'NodeSocketShader', "Shader")
    group["ssao_slots"], group["ssao_threshold"] = slots, threshold
    nodes, links = group.nodes, group.links
    nodes.clear()
    inputs, outputs = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    links.new(nodes.new("ShaderNodeBsdfTransparent").outputs[0], outputs.inputs[0])
    light_path = nodes.new("ShaderNodeLightPath")
    geometry = nodes.new("ShaderNodeNewGeometry")
    camera = nodes.new("ShaderNodeCameraData")
    depth = light_path.outputs["Transparent Depth"]

    def math(operation, a, b=None, c=None):
        node = nodes.new("ShaderNodeMath")
        node.operation = operation
        for socket, value in zip(node.inputs, (a, b, c)):
            if isinstance(value, (int, float)):
                socket.default_value = value
            elif value is not None:
                links.new(value, socket)
        return node.outputs[0]

    def aov(name, socket):
        node = nodes.new("ShaderNodeOutputAOV")
        compat.set_aov_output_name(node, name)
        links.new(socket, node.inputs["Color" if name == "normal" else "Value"])

    # Cycles counts a surface as solid where its alpha >= the threshold.
    solid = math('GREATER_THAN', inputs.outputs["Alpha"], threshold - 1e-6) if threshold > 0 \
        else 1.0
    # A solid holdout ends the beauty's ray with no Depth (measured): `stop` marks it
    # (_Holdouts), and it is no surface.
    holdout = nodes.new("ShaderNodeAttribute")
    holdout.attribute_type, holdout.attribute_name = 'OBJECT', HOLDOUT_PROPERTY
    aov("stop", math('MULTIPLY', math('MULTIPLY', holdout.outputs["Fac"], solid),
                     math('POWER', 2.0, depth)))
    solid = math('MULTIPLY', solid, math('SUBTRACT', 1.0, holdout.outputs["Fac"]))
    sign = math('MULTIPLY_ADD', geometry.outputs["Backfacing"], -2.0, 1.0)  # -1 on a back face
    signed_depth = math('MULTIPLY', math('MULTIPLY', camera.outputs["View Z Depth"], sign),
                        solid)
    for j in range(slots):
        aov(f"hit{j}", math('MULTIPLY', math('COMPARE', depth, float(j), 0.5), signed_depth))
    # Inside = behind the surface as modelled: Geometry > Normal faces the ray, so it is turned
    # back on a back face.
    outward = nodes.new("ShaderNodeVectorMath")
    outward.operation = 'SCALE'
    links.new(geometry.outputs["Normal"], outward.inputs[0])
    links.new(sign, outward.inputs["Scale"])
    inside = nodes.new("ShaderNodeAmbientOcclusion")
    inside.inside, inside.only_local, inside.samples = True, True, OPEN_SAMPLES
    inside.inputs["Distance"].default_value = OPEN_DISTANCE
    links.new(outward.outputs[0], inside.inputs["Normal"])
    is_open = math('GREATER_THAN', inside.outputs["AO"], 0.5)
    aov("open", math('MULTIPLY', math('MULTIPLY', is_open, solid), math('POWER', 2.0, depth)))
    weighted = nodes.new("ShaderNodeVectorMath")
    weighted.operation = 'SCALE'
    links.new(geometry.outputs["Normal"], weighted.inputs[0])
    links.new(math('MULTIPLY', math('POWER', 0.001, depth), solid), weighted.inputs["Scale"])
    aov("normal", weighted.outputs[0])
    return group


def _override_material(group):
    """The view layer's material override where no material needs its own (every surface
    solid): the hits group on every surface."""
    material = bpy.data.materials.get(MATERIAL_NAME) or bpy.data.materials.new(MATERIAL_NAME)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    if not any(n.bl_idname == "ShaderNodeGroup" and n.node_tree == group for n in nodes):
        nodes.clear()
        node = nodes.new("ShaderNodeGroup")
        node.node_tree = group
        node.inputs["Alpha"].default_value = 1.0
        links.new(node.outputs[0], nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    return material


# Each material's alpha, as Cycles' camera rays see it (transparency = the weight of its
# Transparent BSDF closures): an expression over the material's own sockets, folded where
# constant. A term is a float, an output socket, or (operation, term, term).
def _transparency(socket, seen=0):
    """Transparency of the shader output `socket` (None: an unlinked shader input: none)."""
    if socket is None or seen > 32:
        return 0.0
    node = socket.node
    kind = node.bl_idname
    if kind == "NodeReroute":
        return _transparency(_linked(node.inputs[0]), seen + 1)
    if kind == "ShaderNodeBsdfTransparent":
        color = node.inputs["Color"]
        return 1.0 if color.is_linked else sum(color.default_value[:3]) / 3.0
    if kind == "ShaderNodeMixShader":
        fac = _value(node.inputs[0])
        first = _transparency(_linked(node.inputs[1]), seen + 1)
        second = _transparency(_linked(node.inputs[2]), seen + 1)
        return _op('ADD', first, _op('MULTIPLY', fac, _op('SUBTRACT', second, first)))
    if kind == "ShaderNodeAddShader":
        return _op('ADD', _transparency(_linked(node.inputs[0]), seen + 1),
                   _transparency(_linked(node.inputs[1]), seen + 1))
    if kind == "ShaderNodeBsdfPrincipled" and "Alpha" in node.inputs:
        return _op('SUBTRACT', 1.0, _value(node.inputs["Alpha"]))
    return 0.0  # any other shader (and a group's: not looked into) is opaque


def _linked(socket):
    return socket.links[0].from_socket if socket.is_linked and socket.links else None


def _value(socket):
    source = _linked(socket)
    if source is not None:
        return source
    value = socket.default_value
    return float(value) if isinstance(value, (int, float)) else float(sum(value[:3]) / 3.0)


def _op(operation, a, b):
    if isinstance(a, float) and isinstance(b, float):
        return {'ADD': a + b, 'SUBTRACT': a - b, 'MULTIPLY': a * b}[operation]
    if operation == 'MULTIPLY' and (a == 0.0 or b == 0.0):
        return 0.0
    if operation == 'ADD' and (a == 0.0 or b == 0.0):
        return b if a == 0.0 else a
    return (operation, a, b)


def _alpha(material):
    """(alpha term, Cycles output node) of a node material, or None where it has none."""
    if not material.use_nodes or material.node_tree is None:
        return None
    output = material.node_tree.get_output_node('CYCLES')
    if output is None:
        return None
    transparency = _transparency(_linked(output.inputs["Surface"]))
    return _op('SUBTRACT', 1.0, transparency), output


def _needs_own(material):
    """Whether the helper must run `material`'s own tree: a surface alpha that is not 1
    everywhere, or displacement that moves the surface."""
    found = _alpha(material)
    if found is None:
        return False
    alpha, output = found
    moved = output.inputs["Displacement"].is_linked and \
        compat.displacement_method(material) != 'BUMP'
    return moved or not (isinstance(alpha, float) and alpha >= 1.0)


def _editable_materials():
    """The materials the helper may give an output of its own: the file's own (a library's
    cannot be edited), not the helper's override."""
    return [m for m in bpy.data.materials if m.library is None and m.name != MATERIAL_NAME]


class _Holdouts:
    """While open, the objects that are holdouts in the user's view layer (their own setting
    or their collection's) carry HOLDOUT_PROPERTY = 1, which the hits group reads (an
    Attribute node of type Object): the helper's surfaces are transparent, so Cycles' holdout
    does not end its rays as it ends the beauty's. Closing removes the property."""

    def __init__(self, scene):
        self.scene = scene
        self.marked = []

    def __enter__(self):
        layer = _view_layer(self.scene)
        for obj in self.scene.objects:
            if obj.library is None and obj.holdout_get(view_layer=layer):
                obj[HOLDOUT_PROPERTY] = 1.0
                self.marked.append(obj)
        return self

    def __exit__(self, *exc):
        for obj in self.marked:
            if HOLDOUT_PROPERTY in obj:
                del obj[HOLDOUT_PROPERTY]
        self.marked.clear()
        return False


class _MaterialOutputs:
    """While open, every editable node material the scene may show has, beside its own nodes, a
    Material Output for Cycles (made the active one) running the hits group with the material's
    own alpha and its own displacement; closing removes what was added and makes the outputs
    active again as they were. The user's materials are otherwise untouched (docs/blender.md)."""

    def __init__(self, group):
        self.group = group
        self.added = []  # (material, nodes added, {output node name: was active})

    def __enter__(self):
        try:
            for material in _editable_materials():
                self._add(material)
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _add(self, material):
        found = _alpha(material)
        if found is None:
            return
        alpha, output = found
        tree = material.node_tree
        outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
        entry = (material, [], {n.name: n.is_active_output for n in outputs})
        self.added.append(entry)
        made = entry[1]

        def build(term):
            if isinstance(term, float) or not isinstance(term, tuple):
                return term
            node = tree.nodes.new("ShaderNodeMath")
            made.append(node)
            node.operation = term[0]
            for socket, part in zip(node.inputs, term[1:]):
                part = build(part)
                if isinstance(part, float):
                    socket.default_value = part
                else:
                    tree.links.new(part, socket)
            return node.outputs[0]

        hits = tree.nodes.new("ShaderNodeGroup")
        made.append(hits)
        hits.node_tree = self.group
        alpha = build(alpha)
        if isinstance(alpha, float):
            hits.inputs["Alpha"].default_value = alpha
        else:
            tree.links.new(alpha, hits.inputs["Alpha"])
        ours = tree.nodes.new("ShaderNodeOutputMaterial")
        made.append(ours)
        ours.target = 'CYCLES'
        tree.links.new(hits.outputs[0], ours.inputs["Surface"])
        displacement = _linked(output.inputs["Displacement"])
        if displacement is not None:
            tree.links.new(displacement, ours.inputs["Displacement"])
        ours.is_active_output = True

    def __exit__(self, *exc):
        for material, made, active in reversed(self.added):
            tree = material.node_tree
            for node in made:
                tree.nodes.remove(node)
            for name, was_active in active.items():
                if was_active and name in tree.nodes:
                    tree.nodes[name].is_active_output = True
        self.added.clear()
        return False


def _sync_collections(helper, scene, camera):
    """The helper's master collection holds what the scene's does (the same collections and
    objects, linked, not copied) and the helper's camera."""
    wanted = list(scene.collection.children)
    for child in list(helper.collection.children):
        if child not in wanted:
            helper.collection.children.unlink(child)
    for child in wanted:
        if child not in helper.collection.children.values():
            helper.collection.children.link(child)
    objects = list(scene.collection.objects) + [camera]
    for obj in list(helper.collection.objects):
        if obj not in objects:
            helper.collection.objects.unlink(obj)
    for obj in objects:
        if obj.name not in helper.collection.objects:
            helper.collection.objects.link(obj)


def _copy_layer_flags(source, target):
    """The view layer's per-collection settings that decide what the camera sees."""
    for child in target.children:
        match = source.children.get(child.name)
        if match is None:
            continue
        child.exclude = match.exclude
        if hasattr(child, "indirect_only"):
            child.indirect_only = match.indirect_only
        if not child.exclude:
            _copy_layer_flags(match, child)


def _camera_copy(scene, helper, overscan, matrix=None):
    """The helper's camera: the scene's active camera as it is now (matrix and settings, not its
    animation; `matrix`, its matrix_world as rows, in place of its own), widened by `overscan`
    pixels on every side on the same pixel grid."""
    source = scene.camera
    if source is None:
        raise RuntimeError(f"scene '{scene.name}' has no active camera")
    name = HELPER_PREFIX + "camera " + scene.name
    data = bpy.data.cameras.get(name) or bpy.data.cameras.new(name)
    obj = bpy.data.objects.get(name) or bpy.data.objects.new(name, data)
    obj.data = data
    settings = source.data
    for attribute in ("type", "lens", "clip_start", "clip_end"):
        setattr(data, attribute, getattr(settings, attribute))
    data.dof.use_dof = False  # the depth of the pixel's centre ray, not of a lens sample
    # The rendered image (the crop of a render cropped to its border) widened by the band, as a
    # frame of its own on the same pixel grid.
    framed = camera_module.cropped(
        {name: getattr(settings, name) for name in camera_module.CROPPED}, scene.render, overscan)
    for name, value in framed.items():
        setattr(data, name, value)
    obj.matrix_world = source.matrix_world.copy() if matrix is None else \
        mathutils.Matrix(matrix)
    return obj


def _view_layer(scene):
    """The view layer the layers follow: the first one rendered."""
    return next((layer for layer in scene.view_layers if layer.use), scene.view_layers[0])


def helper_scene(scene, hits, overscan, own_materials, camera_matrix=None):
    """The hidden scene that renders the layers of `scene` (made once, then brought up to date:
    collections, camera, size, sampling). `own_materials`: the surfaces run their materials'
    own Cycles outputs (_MaterialOutputs) rather than the view layer's override."""
    name = HELPER_PREFIX + scene.name
    helper = bpy.data.scenes.get(name)
    if helper is None:
        helper = bpy.data.scenes.new(name)
        compat.render_view_layers_only(helper)
        compat.layer_collection(helper.view_layers[0])  # while the scene is empty (compat)
    camera = _camera_copy(scene, helper, overscan, camera_matrix)
    _sync_collections(helper, scene, camera)
    helper.camera = camera
    helper.background_set = scene.background_set  # the beauty renders the set's objects too
    helper.world = None
    helper.frame_current = scene.frame_current
    layer = helper.view_layers[0]
    layer.name = LAYER_NAME
    _copy_layer_flags(compat.layer_collection(_view_layer(scene)),
                      compat.layer_collection(layer))
    # With the materials' own outputs, a surface without one (no material, a linked or
    # non-node material) stops the ray as in the beauty: its depth and normal are the passes'.
    layer.use_pass_z = layer.use_pass_normal = own_materials
    threshold = _alpha_threshold(scene)
    layer.pass_alpha_threshold = threshold
    for aov in _aov_names(hits):
        if aov not in layer.aovs:
            item = layer.aovs.add()
            item.name = aov
            item.type = 'COLOR' if aov == "normal" else 'VALUE'
    group = _hits_group(hits, threshold)
    layer.material_override = None if own_materials else _override_material(group)
    _render_settings(scene, helper, hits, overscan)
    return helper, group


def _render_settings(scene, helper, hits, overscan):
    render, source = helper.render, scene.render
    width, height = camera_module.render_size(scene)
    render.engine = 'CYCLES'
    render.resolution_x, render.resolution_y = width + 2 * overscan, height + 2 * overscan
    render.resolution_percentage = 100
    render.pixel_aspect_x, render.pixel_aspect_y = source.pixel_aspect_x, source.pixel_aspect_y
    render.use_border = False
    render.use_motion_blur = False
    render.film_transparent = True
    render.threads_mode, render.threads = source.threads_mode, source.threads
    # Kept synchronised between renders when the user keeps the beauty's (a second copy of the
    # scene in memory; measured: docs/blender.md).
    render.use_persistent_data = source.use_persistent_data
    cycles, user = helper.cycles, scene.cycles
    cycles.samples = 1  # each pixel's AOVs come from its one camera ray
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    # Passing the surface at transparent depth j takes j + 1 transparent bounces.
    cycles.transparent_max_bounces = _slots(hits)
    cycles.max_bounces = 0
    # The same sample positions as a Cycles beauty's first sample (its Depth pass).
    for attribute in ("seed", "use_animated_seed", "filter_width", "pixel_filter_type",
                      "device"):
        setattr(cycles, attribute, getattr(user, attribute))
    compat.set_image_format(render.image_settings, 'OPEN_EXR_MULTILAYER', color_depth='32',
                            codec='ZIP')


def _render(helper, path):
    """Renders the helper and saves its Render Result (each scene has its own) to `path`."""
    with session.current.doing("rendering_layers"):  # the render fires the render handlers
        bpy.ops.render.render(scene=helper.name)
    result = bpy.data.images.get("Render Result")
    if result is None:
        raise RuntimeError("the hidden-surface render made no Render Result")
    result.save_render(path, scene=helper)


def _planes(path, hits, own_materials, threads=0):
    """{aov or pass name: (height, width[, channels]) float32 array, row 0 on top} of the saved
    file, read on `threads` threads (0: one per core)."""
    planes, _ = multilayer.read(path, threads)
    names = _aov_names(hits) + (["Depth", "Normal"] if own_materials else [])
    layers = {}
    for aov in names:
        prefix = f"{LAYER_NAME}.{aov}."
        channels = sorted((name for name in planes if name.startswith(prefix)),
                          key=lambda name: "XYZWRGBA".find(name[-1]))
        if not channels:
            raise RuntimeError(f"the hidden-surface render has no '{aov}' pass "
                               f"(channels: {', '.join(sorted(planes))})")
        if aov in ("normal", "Normal"):
            layers[aov] = np.stack([planes[c] for c in channels[:3]], axis=-1)
        else:
            layers[aov] = planes[channels[0]]
    return layers


def _bit_planes(plane, slots):
    """(slots, height, width) booleans: bit j of an AOV that sums 2^j over the surfaces."""
    bits = np.clip(np.rint(plane), 0, 255).astype(np.uint8)  # slots <= 8
    return np.unpackbits(bits[None], axis=0, bitorder="little")[:slots].view(bool)


def surfaces(raw, hits, own_materials, threads=0):
    """The surfaces along each pixel's ray from the helper's planes, in order: (depth, facing)
    arrays of shape (hits, height, width), BACKGROUND / 0 past the last, and the first
    surface's normal (height, width, 3).

    Holes (alpha below the threshold) are not surfaces, and the ray ends at a holdout (the
    stop AOV). A solid surface is a front face (facing 0) or a back face (1), as met. An open
    one (a card, a sheet: the open AOV) with another surface behind it is handed on as a front
    face and a back face at the same depth, whichever way it faces: a solid of no thickness,
    so that the space between it and what lies behind reads as free (docs/conventions.md).
    An open surface that is the ray's last known one is a front face: what lies behind it
    (the far side of a floor or a wall) is reached only through it, which the library's
    thickness rule stands for. A surface that stopped the ray (own_materials: the Depth pass
    beyond the AOVs' hits) is a front face. At most `hits` entries, twins included (a twin
    takes the place of a farther surface: with 5 entries rather than 3 the cut-out scene's
    AO was no closer to Cycles', docs/blender.md). On `threads` threads (0: one per core),
    at most SURFACE_MAX_THREADS."""
    # Each pixel's list is its own, so blocks of rows give the same result: they spread over
    # the cores (numpy lets go of Python's lock), and their intermediates take the memory of
    # a block, not of the frame (SURFACE_BLOCK_ROWS).
    def block(top):
        return _block_surfaces({name: plane[top:top + SURFACE_BLOCK_ROWS]
                                for name, plane in raw.items()}, hits, own_materials)

    workers = min(multilayer.thread_count(threads), SURFACE_MAX_THREADS)
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        blocks = list(pool.map(block, range(0, raw["hit0"].shape[0], SURFACE_BLOCK_ROWS)))
    depth, facing, normal = zip(*blocks)
    return (np.concatenate(depth, axis=1), np.concatenate(facing, axis=1),
            np.concatenate(normal, axis=0))


def _block_surfaces(raw, hits, own_materials):
    """surfaces() of the rows in `raw`, on this thread."""
    slots = _slots(hits)
    signed = np.stack([raw[f"hit{j}"] for j in range(slots)])
    is_open = _bit_planes(raw["open"], slots)
    found = signed != 0
    # The ray ends at its first holdout: nothing from there on is seen.
    ended = np.logical_or.accumulate(_bit_planes(raw["stop"], slots), axis=0)
    found &= ~ended
    depth = np.abs(signed)
    # Something behind each slot: a later slot's surface, or the surface that stopped the ray.
    later = np.zeros_like(found)
    later[:-1] = np.flip(np.logical_or.accumulate(np.flip(found[1:], 0), axis=0), 0)
    if own_materials:
        stop = np.where(ended[-1], 0, raw["Depth"])
        stopped = (stop > 0) & (stop < BACKGROUND * 0.5)
        later |= stopped[None]
    back = (signed < 0) & ~is_open  # an open surface is never read as leaving a solid
    is_open &= later
    # Slot by slot, its surface then its card twin (a back face at the same depth), in ray
    # order; then the surface that stopped the ray.
    rows = (-1,) + depth.shape[1:]
    order_found = np.stack([found, found & is_open], axis=1).reshape(rows)
    normal = raw["normal"]
    if own_materials:
        order_found = np.concatenate([order_found, stopped[None]])
        normal = np.where(~found.any(axis=0)[..., None], raw["Normal"], normal)
    # Entry i of a pixel's list is its (i + 1)-th found one in that order: the number of
    # entries before which fewer than i + 1 are found (len(order_found): none). Counted, not
    # sorted: a sort took seconds at 2K x 1.5K.
    seen = np.cumsum(order_found, axis=0, dtype=np.uint8)
    first = np.stack([(seen <= i).sum(axis=0, dtype=np.uint8) for i in range(hits)])
    kept = first < len(order_found)
    slot = np.minimum(first // 2, slots - 1)
    out_depth = np.take_along_axis(depth, slot, axis=0)
    out_facing = np.where(first % 2 == 1, True, np.take_along_axis(back, slot, axis=0))
    if own_materials:
        stopped_entry = first == 2 * slots
        out_depth = np.where(stopped_entry, stop[None], out_depth)
        out_facing &= ~stopped_entry
    out_depth = np.where(kept, out_depth, np.float32(BACKGROUND)).astype(np.float32)
    out_facing = (kept & out_facing).astype(np.float32)
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    normal = np.where(length > 0, normal / np.maximum(length, 1e-30), 0).astype(np.float32)
    return out_depth, out_facing, normal


def layers_key(scene, hits, overscan):
    """What the layers of `scene` as it is now depend on, beyond its contents: the frame, the
    hits and band asked for, the render's size and the camera's placement."""
    camera = scene.camera
    return (scene.frame_current, hits, overscan, camera_module.render_size(scene),
            camera and tuple(map(tuple, camera.matrix_world)))


def kept_layers(scene_name, key):
    """The layers rendered for `key` (layers_key) and kept, or None."""
    return session.current.kept_layers.get(scene_name, {}).get(key)


def keep(scene_name, key, layers):
    """Keeps `layers` for `key` until forget(); the oldest go beyond CACHED_PER_SCENE."""
    cached = session.current.kept_layers.setdefault(scene_name, {})
    while len(cached) >= CACHED_PER_SCENE:  # an animation's frames must not pile up
        cached.pop(next(iter(cached)))
    cached[key] = layers


def render_layers(scene, hits=MAX_HITS, overscan=0, folder=None, camera_matrix=None):
    """Renders `scene`'s hidden-surface layers at its current frame (set it first with
    scene.frame_set: the camera is read as it is, or its matrix_world is `camera_matrix`, rows).
    Returns {name: float32 array, row 0 on top}, of the render's size + 2 * overscan on each
    axis:
      "depth": the 1st surface's planar depth (BACKGROUND where the ray meets none), "normal":
      its world-space normal (height, width, 3), and for k = 2..hits "depth<k>" (BACKGROUND
      where there is no k-th entry) and "facing<k>" (1 = back face, 0 = front face or none):
      the surfaces behind it, an open surface as two entries (surfaces()).
    Surfaces are as Cycles' camera rays see them: alpha below the view layer's threshold is a
    hole, material displacement is applied (both where some material needs it: its own
    outputs are run, _MaterialOutputs).
    The result is kept for the scene and frame until forget(): a recompute does not render.
    This renders in Blender's own process; helper_process.py renders the same in another."""
    check_request(hits, overscan)
    key = layers_key(scene, hits, overscan)
    layers = kept_layers(scene.name, key)
    if layers is not None:
        return layers
    own_materials = any(_needs_own(m) for m in _editable_materials())
    threads = camera_module.render_threads(scene)
    helper, group = helper_scene(scene, hits, overscan, own_materials, camera_matrix)
    folder = folder or bpy.app.tempdir
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, f"layers_{bpy.path.clean_name(scene.name)}_"
                                f"{scene.frame_current:04d}.exr")
    try:
        with _Holdouts(scene):
            if own_materials:
                with _MaterialOutputs(group):
                    _render(helper, path)
            else:
                _render(helper, path)
        raw = _planes(path, hits, own_materials, threads)
    finally:
        if os.path.exists(path):
            os.remove(path)
    depth, facing, normal = surfaces(raw, hits, own_materials, threads)
    layers = {"depth": depth[0], "normal": normal}
    for k in range(2, hits + 1):
        layers[f"depth{k}"] = depth[k - 1]
        layers[f"facing{k}"] = facing[k - 1]
    keep(scene.name, key, layers)
    return layers


def check_request(hits, overscan):
    if not 1 <= hits <= MAX_HITS:
        raise ValueError(f"hits must be 1 to {MAX_HITS}, not {hits}")
    if overscan < 0:
        raise ValueError(f"overscan must be 0 or more pixels, not {overscan}")


def remove_helpers():
    """Keeps the helpers out of the user's file (they are made again when needed)."""
    forget()
    for helper in [s for s in bpy.data.scenes if s.name.startswith(HELPER_PREFIX)]:
        bpy.data.scenes.remove(helper)
    for obj in [o for o in bpy.data.objects if o.name.startswith(HELPER_PREFIX)]:
        bpy.data.objects.remove(obj)
    for camera in [c for c in bpy.data.cameras if c.name.startswith(HELPER_PREFIX)]:
        bpy.data.cameras.remove(camera)
    material = bpy.data.materials.get(MATERIAL_NAME)
    if material is not None:
        bpy.data.materials.remove(material)
    group = bpy.data.node_groups.get(GROUP_NAME)
    if group is not None:
        bpy.data.node_groups.remove(group)
