# SPDX-License-Identifier: MIT
"""Running the scene's compositor again on a finished render, without rendering again, and
writing its result where the render wrote its frame.

A hidden helper scene, a copy of the scene whose Render Layers nodes are replaced by Image nodes
reading the render's passes saved as a multilayer EXR: rendering it runs only the compositor
(Blender renders no view layer that no Render Layers node reads)."""
import os

import bpy

from . import compat, compute, inner_tree, multilayer, session

HELPER_PREFIX = compute.HELPER_SCENE_PREFIX
PASSES_IMAGE_PREFIX = ".SSAO passes "


# Render settings the re-composite takes from the scene each time (the helper is a copy made
# once per session, 5.x aside).
_RENDER_SETTINGS = ("resolution_x", "resolution_y", "resolution_percentage", "pixel_aspect_x",
                    "pixel_aspect_y", "use_border", "use_crop_to_border", "border_min_x",
                    "border_max_x", "border_min_y", "border_max_y", "film_transparent",
                    "use_file_extension")


def passes_path(scene, frame):
    """Where the passes of `scene`'s render of `frame` are saved for re-compositing."""
    return os.path.join(compute.export_dir(),
                        f"passes_{bpy.path.clean_name(scene.name)}_{frame:04d}.exr")


def save_passes(scene, path):
    """Writes every pass of `scene`'s Render Result (and its Composite) to a 32-bit multilayer
    EXR."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    _save_render_as(scene, path, 'OPEN_EXR_MULTILAYER', color_depth='32', codec='ZIP')


def _save_render_as(scene, path, file_format, **settings):
    """Saves `scene`'s Render Result to `path` in the given format. save_render takes the render
    of the scene it is given, with that scene's output settings: switch them briefly."""
    result = bpy.data.images.get("Render Result")
    if result is None:
        raise RuntimeError("no Render Result")
    image_settings = scene.render.image_settings
    saved = {a: getattr(image_settings, a) for a in compat.FORMAT_ATTRIBUTES
             if hasattr(image_settings, a)}
    try:
        compat.set_image_format(image_settings, file_format, **settings)
        result.save_render(path, scene=scene)
    finally:
        for attribute, value in saved.items():  # media_type first: it decides file_format's
            setattr(image_settings, attribute, value)


def helper_scene(scene):
    """The hidden copy of `scene` that re-composites it. Kept and reused (removing a scene in a
    render handler crashes); in 5.x its compositing tree, a data-block the copy would share, is
    copied afresh each time so that it follows the scene's."""
    name = HELPER_PREFIX + scene.name
    helper = bpy.data.scenes.get(name)
    if helper is None:
        with session.current.doing("copying_helper"):  # the copy's SSAO nodes share AO
            helper = scene.copy()
        helper.name = name
        helper.use_fake_user = False
    if compat.compositor_trees_are_shared():
        old = compat.compositor_tree(helper)
        with session.current.doing("copying_helper"):
            copy = compat.compositor_tree(scene).copy()
        copy.name = HELPER_PREFIX + scene.name
        compat.set_compositor_tree(helper, copy)
        if old is not None and old != compat.compositor_tree(scene) and old.users == 0:
            bpy.data.node_groups.remove(old)
    # Size, output and colour settings follow the source scene's current ones.
    for attribute in _RENDER_SETTINGS:
        setattr(helper.render, attribute, getattr(scene.render, attribute))
    compat.copy_image_format(scene.render.image_settings, helper.render.image_settings)
    for attribute in ("view_transform", "look", "exposure", "gamma"):
        setattr(helper.view_settings, attribute, getattr(scene.view_settings, attribute))
    helper.display_settings.display_device = scene.display_settings.display_device
    return helper


def helper_scene_if_any(scene):
    """The helper scene as the last re-composite left it (its Render Result is that one's)."""
    return bpy.data.scenes.get(HELPER_PREFIX + scene.name)


def _read_passes_from(helper, path, source_scene):
    """Replaces the helper's Render Layers nodes by Image nodes reading `path` (a multilayer EXR
    of the source render), relinking every output by name."""
    tree = compat.compositor_tree(helper)
    name = PASSES_IMAGE_PREFIX + source_scene.name
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.load(path, check_existing=False)
        image.name = name
    else:
        # The same data-block, re-read: the readers made for an earlier frame keep reading it.
        image.filepath = path
        image.reload()
    for rl in [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"]:
        reader = tree.nodes.new("CompositorNodeImage")
        reader.image = image
        reader.layer = rl.layer
        reader.location = rl.location
        for output in rl.outputs:
            # The combined pass is "Image" on Render Layers and "Combined" on a multilayer image.
            name = "Combined" if output.name == "Image" else output.name
            target = reader.outputs.get(name)
            for link in list(output.links):
                if target is not None:
                    tree.links.new(target, link.to_socket)
        tree.nodes.remove(rl)


def recomposite(scene, path):
    """Re-runs only the compositor of `scene` on the passes saved at `path`; returns the helper
    scene, whose Render Result is the new composite."""
    helper = helper_scene(scene)
    _read_passes_from(helper, path, scene)
    nodes = [node for _, node in compute.all_ssao_nodes()]
    # A one-frame animation, not a still: File Output nodes downstream of the SSAO node then
    # write their frame's file again, named as in the render (5.x names a still's files without
    # the frame number). The helper's own frame file goes to a temporary name, then away.
    frame = scene.frame_current
    helper.frame_start = helper.frame_end = helper.frame_current = frame
    helper.render.filepath = os.path.join(compute.export_dir(), "recomposite_####")
    with session.current.doing("recompositing"):  # the render fires the render handlers again
        try:
            for node in nodes:
                inner_tree.set_exporter_muted(node, True)
            bpy.ops.render.render(animation=True, scene=helper.name)
            written = helper.render.frame_path(frame=frame)
            if os.path.isfile(written):
                os.remove(written)
        finally:
            for node in nodes:
                inner_tree.set_exporter_muted(node, False)
    return helper


def write_output(scene, helper, path, passes, ao_layers):
    """Writes the re-composited frame to `path` in `scene`'s output format. A multilayer EXR gets
    every pass of the render (`passes`, the saved passes file), the new Composite and one layer
    per SSAO node that computed (`ao_layers`: {layer name: AO array, row 0 on top}); any other
    format gets the composite (each scene has its own Render Result: the new one is the
    helper's)."""
    if compat.image_format(scene.render.image_settings) == 'OPEN_EXR_MULTILAYER':
        composite_path = path + ".composite.exr"
        _save_render_as(helper, composite_path, 'OPEN_EXR', color_depth='32', codec='NONE',
                        color_mode='RGBA')
        try:
            multilayer.rewrite(passes, composite_path, ao_layers, path,
                               half=scene.render.image_settings.color_depth == '16',
                               codec=scene.render.image_settings.exr_codec)
        finally:
            os.remove(composite_path)
    else:
        # Through a temporary file (the same extension): a write that fails half-way leaves
        # the frame Blender wrote, not a partial file (multilayer.write does the same).
        root, extension = os.path.splitext(path)
        temporary = f"{root}.ssao-partial{extension}"
        try:
            bpy.data.images["Render Result"].save_render(temporary, scene=helper)
            os.replace(temporary, path)
        finally:
            if os.path.exists(temporary):
                os.remove(temporary)
    # No layer: every node failed (their AO is 1), which compute_frame has reported.
    compute.report(f"wrote {path} " + ("with AO" if ao_layers else "WITHOUT AO"))


def remove_helpers():
    """The helpers are rebuilt when needed: keep them out of the user's file."""
    for helper in [s for s in bpy.data.scenes if s.name.startswith(HELPER_PREFIX)]:
        tree = compat.compositor_tree(helper) if compat.compositor_trees_are_shared() else None
        bpy.data.scenes.remove(helper)
        if tree is not None and tree.name.startswith(HELPER_PREFIX) and tree.users == 0:
            bpy.data.node_groups.remove(tree)
    for image in [i for i in bpy.data.images if i.name.startswith(PASSES_IMAGE_PREFIX)]:
        bpy.data.images.remove(image)
