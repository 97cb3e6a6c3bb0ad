# SPDX-License-Identifier: MIT
"""The surfaces the render does not show, and a guard band: a helper render of the scene on the
same pixel grid, with Cycles at 1 sample per pixel whatever engine the beauty uses.

It gives, for each pixel, the depth of the 1st, 2nd and 3rd surface hit along the camera ray,
whether each is a back face, and the 1st hit's world-space normal; with a guard band of G pixels
it renders W+2G x H+2G pixels, the frame widened on the same grid.

How (measured facts: docs/blender.md, "Hidden surfaces and overscan"): one view layer whose
material override is a Transparent BSDF for every surface, so that the camera ray passes every
surface, with AOV outputs that write, at the surface whose Light Path > Transparent Depth is
k - 1 (hit k), Camera Data > View Z Depth (Blender's planar Depth) and Geometry > Backfacing.
Cycles writes a camera ray's AOVs at every transparent surface it passes (up to the first
opaque one, and here there is none), and at 1 sample each pixel has one ray. One view layer, so
the scene is synchronised once (every view layer synchronises it again).

The scene, its view layers, its camera and its file are not changed: the render is of a hidden
helper scene `.SSAO layers <scene>` that links the scene's collections, with a camera object of
its own set from the scene's camera. Like recomposite.py's, the helper is kept and reused
(removing a scene in a render handler crashes) and removed before a file is saved."""
import os

import bpy
import numpy as np

from . import compat, multilayer

HELPER_PREFIX = ".SSAO layers "
LAYER_NAME = "SSAO layers"
MATERIAL_NAME = ".SSAO layers override"
MAX_HITS = 3
BACKGROUND = 1e10  # Cycles' Depth pass where there is no surface, Blender's convention

_running = False  # our helper render fires the render handlers too
# scene name -> {settings: layers}: one render serves every recompute of that frame (and each
# of several nodes with other settings gets its own)
_cache = {}
CACHED_PER_SCENE = 2


def is_running():
    return _running


def forget(scene_name=None):
    """Drops the layers kept for `scene_name` (all with None): a new render of it is coming."""
    if scene_name is None:
        _cache.clear()
    else:
        _cache.pop(scene_name, None)


def _aov_names(hits):
    return [f"depth{k}" for k in range(1, hits + 1)] + \
        [f"facing{k}" for k in range(2, hits + 1)] + ["normal"]


def _override_material(hits):
    """Transparent everywhere; AOVs depth<k>, facing<k> (k >= 2) and normal (hit 1) written at
    hit k. Remade when it was made for fewer hits."""
    material = bpy.data.materials.get(MATERIAL_NAME)
    if material is not None and material.get("ssao_hits", 0) >= hits:
        return material
    if material is None:
        material = bpy.data.materials.new(MATERIAL_NAME)
    material["ssao_hits"] = hits
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(nodes.new("ShaderNodeBsdfTransparent").outputs[0], output.inputs["Surface"])
    light_path = nodes.new("ShaderNodeLightPath")
    geometry = nodes.new("ShaderNodeNewGeometry")
    camera = nodes.new("ShaderNodeCameraData")

    def aov(name, socket):
        node = nodes.new("ShaderNodeOutputAOV")
        compat.set_aov_output_name(node, name)
        links.new(socket, node.inputs["Color" if name == "normal" else "Value"])

    for k in range(1, hits + 1):
        # 1 at hit k, 0 elsewhere: Transparent Depth counts the surfaces passed (integers).
        at_hit = nodes.new("ShaderNodeMath")
        at_hit.operation = 'COMPARE'
        at_hit.inputs[1].default_value = k - 1
        at_hit.inputs[2].default_value = 0.5
        links.new(light_path.outputs["Transparent Depth"], at_hit.inputs[0])
        values = [("depth", camera.outputs["View Z Depth"])]
        if k >= 2:
            values.append(("facing", geometry.outputs["Backfacing"]))
        for name, source in values:
            product = nodes.new("ShaderNodeMath")
            product.operation = 'MULTIPLY'
            links.new(at_hit.outputs[0], product.inputs[0])
            links.new(source, product.inputs[1])
            aov(f"{name}{k}", product.outputs[0])
        if k == 1:
            scaled = nodes.new("ShaderNodeVectorMath")
            scaled.operation = 'SCALE'
            links.new(geometry.outputs["Normal"], scaled.inputs[0])
            links.new(at_hit.outputs[0], scaled.inputs["Scale"])
            aov("normal", scaled.outputs[0])
    return material


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


def _camera_copy(scene, helper, overscan):
    """The helper's camera: the scene's active camera as it is now (matrix and settings, not its
    animation), widened by `overscan` pixels on every side on the same pixel grid."""
    source = scene.camera
    if source is None:
        raise RuntimeError(f"scene '{scene.name}' has no active camera")
    name = HELPER_PREFIX + "camera " + scene.name
    data = bpy.data.cameras.get(name) or bpy.data.cameras.new(name)
    obj = bpy.data.objects.get(name) or bpy.data.objects.new(name, data)
    obj.data = data
    settings = source.data
    for attribute in ("type", "lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x",
                      "shift_y", "ortho_scale", "clip_start", "clip_end"):
        setattr(data, attribute, getattr(settings, attribute))
    data.dof.use_dof = False  # the depth of the pixel's centre ray, not of a lens sample
    obj.matrix_world = source.matrix_world.copy()
    if overscan:
        _widen(data, scene.render, overscan)
    return obj


def _widen(data, render, overscan):
    """Widens the camera by `overscan` pixels on every side, on the same pixel grid. The frame's
    fitted side (sensor_fit; AUTO: the larger side, aspect included) spans sensor size or
    ortho_scale over its pixels: that grows by (L + 2G) / L. Shift is a fraction of that side,
    so it shrinks by the same factor to stay the same distance."""
    width, height = render_size(render)
    aspect_x, aspect_y = render.pixel_aspect_x, render.pixel_aspect_y
    fit = data.sensor_fit
    if fit == 'AUTO':
        fit = 'HORIZONTAL' if width * aspect_x >= height * aspect_y else 'VERTICAL'
        size = data.sensor_width  # AUTO fits sensor_width to the larger side
        data.sensor_fit = fit
        if fit == 'VERTICAL':
            data.sensor_height = size
    pixels = width if fit == 'HORIZONTAL' else height
    factor = (pixels + 2 * overscan) / pixels
    if fit == 'HORIZONTAL':
        data.sensor_width *= factor
    else:
        data.sensor_height *= factor
    data.ortho_scale *= factor
    data.shift_x /= factor
    data.shift_y /= factor


def render_size(render):
    scale = render.resolution_percentage / 100.0
    return int(render.resolution_x * scale), int(render.resolution_y * scale)


def _view_layer(scene):
    """The view layer the layers follow: the first one rendered."""
    return next((layer for layer in scene.view_layers if layer.use), scene.view_layers[0])


def helper_scene(scene, hits, overscan):
    """The hidden scene that renders the layers of `scene` (made once, then brought up to date:
    collections, camera, size, sampling)."""
    name = HELPER_PREFIX + scene.name
    helper = bpy.data.scenes.get(name)
    if helper is None:
        helper = bpy.data.scenes.new(name)
        compat.render_view_layers_only(helper)
        compat.layer_collection(helper.view_layers[0])  # while the scene is empty (compat)
    camera = _camera_copy(scene, helper, overscan)
    _sync_collections(helper, scene, camera)
    helper.camera = camera
    helper.background_set = scene.background_set  # the beauty renders the set's objects too
    helper.world = None
    helper.frame_current = scene.frame_current
    layer = helper.view_layers[0]
    layer.name = LAYER_NAME
    _copy_layer_flags(compat.layer_collection(_view_layer(scene)),
                      compat.layer_collection(layer))
    layer.use_pass_z = layer.use_pass_normal = False
    for aov in _aov_names(hits):
        if aov not in layer.aovs:
            item = layer.aovs.add()
            item.name = aov
            item.type = 'COLOR' if aov == "normal" else 'VALUE'
    layer.material_override = _override_material(hits)
    _render_settings(scene, helper, hits, overscan)
    return helper


def _render_settings(scene, helper, hits, overscan):
    render, source = helper.render, scene.render
    width, height = render_size(source)
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
    # Passing hit k takes k transparent bounces.
    cycles.transparent_max_bounces = hits
    cycles.max_bounces = 0
    # The same sample positions as a Cycles beauty's first sample (its Depth pass).
    for attribute in ("seed", "use_animated_seed", "filter_width", "pixel_filter_type",
                      "device"):
        setattr(cycles, attribute, getattr(user, attribute))
    compat.set_image_format(render.image_settings, 'OPEN_EXR_MULTILAYER', color_depth='32',
                            codec='ZIP')


def _render(helper, path):
    """Renders the helper and saves its Render Result (each scene has its own) to `path`."""
    global _running
    _running = True
    try:
        bpy.ops.render.render(scene=helper.name)
    finally:
        _running = False
    result = bpy.data.images.get("Render Result")
    if result is None:
        raise RuntimeError("the hidden-surface render made no Render Result")
    result.save_render(path, scene=helper)


def _planes(path, hits):
    """{aov name: (height, width[, channels]) float32 array, row 0 on top} of the saved file."""
    planes, _ = multilayer.read(path)
    layers = {}
    for aov in _aov_names(hits):
        prefix = f"{LAYER_NAME}.{aov}."
        channels = sorted((name for name in planes if name.startswith(prefix)),
                          key=lambda name: "XYZWRGBA".find(name[-1]))
        if not channels:
            raise RuntimeError(f"the hidden-surface render has no '{aov}' pass "
                               f"(channels: {', '.join(sorted(planes))})")
        if aov == "normal":
            layers[aov] = np.stack([planes[c] for c in channels[:3]], axis=-1)
        else:
            layers[aov] = planes[channels[0]]
    return layers


def render_layers(scene, hits=MAX_HITS, overscan=0, folder=None):
    """Renders `scene`'s hidden-surface layers at its current frame (set it first with
    scene.frame_set: the camera is read as it is). Returns {name: float32 array, row 0 on top},
    of the render's size + 2 * overscan on each axis:
      "depth": hit 1's planar depth (BACKGROUND where the ray hits nothing), "normal": its
      world-space normal (height, width, 3), and for k = 2..hits "depth<k>" (BACKGROUND where
      there is no k-th hit) and "facing<k>" (1 = back face, 0 = front face or no hit).
    The result is kept for the scene and frame until forget(): a recompute does not render."""
    if not 1 <= hits <= MAX_HITS:
        raise ValueError(f"hits must be 1 to {MAX_HITS}, not {hits}")
    if overscan < 0:
        raise ValueError(f"overscan must be 0 or more pixels, not {overscan}")
    camera = scene.camera
    key = (scene.frame_current, hits, overscan, render_size(scene.render),
           camera and tuple(map(tuple, camera.matrix_world)))
    cached = _cache.setdefault(scene.name, {})
    if key in cached:
        return cached[key]
    helper = helper_scene(scene, hits, overscan)
    folder = folder or bpy.app.tempdir
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, f"layers_{bpy.path.clean_name(scene.name)}_"
                                f"{scene.frame_current:04d}.exr")
    try:
        _render(helper, path)
        raw = _planes(path, hits)
    finally:
        if os.path.exists(path):
            os.remove(path)
    layers = {"normal": raw["normal"]}
    for k in range(1, hits + 1):
        depth = raw[f"depth{k}"]
        hit = depth > 0  # a hit's View Z Depth is positive; no hit leaves the AOV at 0
        name = "depth" if k == 1 else f"depth{k}"
        layers[name] = np.where(hit, depth, np.float32(BACKGROUND)).astype(np.float32)
        if k >= 2:
            layers[f"facing{k}"] = np.where(hit, raw[f"facing{k}"], 0).astype(np.float32)
    while len(cached) >= CACHED_PER_SCENE:  # an animation's frames must not pile up
        cached.pop(next(iter(cached)))
    cached[key] = layers
    return layers


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
