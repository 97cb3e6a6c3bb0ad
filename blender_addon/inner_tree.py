# SPDX-License-Identifier: MIT
"""The node's inner tree, made of built-in nodes only, so that a .blend saved with the node still
composites (with the last computed AO) where the add-on is not installed:

  Group Input (Image, Depth, Normal)
    Normal -> Separate Color -> R, G, B ┐
    Depth  ------------------------> A  ┴ Combine Color -> File Output "SSAO Export"
                                          (a lossless 32-bit EXR, read back by compute.py)
    Image  ------------------------------------------> File Output "SSAO Export Alpha"
                                          (RGBA, the same file name in the folder image/ beside
                                          it: the composite's coverage and edge_colours)
  Image node "SSAO AO" (filled by compute.py) -> Separate Color "SSAO Channels"
    Red:   the AO                                           -> Output AO
    Green: the composite's factor -> Multiply with Image    -> Output Image

The factor is libssao's composite of a white image with the Image's alpha: the AO, except on a
silhouette against the sky, where only the surface's share of the pixel is darkened (ssao.h,
"composite"). The Image is multiplied by it in the compositor, so the Image output is the
library's composite of the Image (the same float products) and follows changes upstream of the
node without a recompute; the factor itself follows the Image's alpha of the last render.
"""
import os
import uuid

import bpy
import numpy as np

from . import compat

NODE_IDNAME = "CompositorNodeSSAO"
EXPORT_NODE, AO_NODE, MULTIPLY_NODE = "SSAO Export", "SSAO AO", "SSAO Multiply"
# Added for the library's composite (issue 33); trees saved before get them in upgrade(). The
# Image's export was named when it wrote the alpha alone (from ALPHA_NODE's Alpha output).
CHANNELS_NODE, ALPHA_NODE, IMAGE_EXPORT_NODE = \
    "SSAO Channels", "SSAO Image Alpha", "SSAO Export Alpha"
IMAGE_FOLDER = "image"  # the Image export's folder, inside the passes export's
# The two exports are written by one compositor run: an Image file older than its passes file
# by more than this is from another render (and is not used).
IMAGE_EXPORT_SLACK_SECONDS = 60.0


def build(ssao_id):
    tree = bpy.data.node_groups.new(".SSAO " + ssao_id, "CompositorNodeTree")
    compat.new_socket(tree, 'INPUT', 'NodeSocketColor', "Image")
    compat.new_socket(tree, 'INPUT', 'NodeSocketFloat', "Depth")
    compat.new_socket(tree, 'INPUT', 'NodeSocketVector', "Normal")
    compat.new_socket(tree, 'OUTPUT', 'NodeSocketColor', "Image")
    compat.new_socket(tree, 'OUTPUT', 'NodeSocketFloat', "AO")

    nodes, links = tree.nodes, tree.links
    group_in = nodes.new("NodeGroupInput")
    group_in.location = (-600, 0)
    group_out = nodes.new("NodeGroupOutput")
    group_out.location = (400, 0)

    # The vector reaches Separate Color as a colour (x, y, z, 1) in every version.
    separate = nodes.new("CompositorNodeSeparateColor")
    separate.location = (-350, -250)
    combine = nodes.new("CompositorNodeCombineColor")
    combine.location = (-150, -250)
    separate.mode = combine.mode = 'RGB'
    exporter = compat.new_file_output(tree, ["Passes"])
    exporter.name = exporter.label = EXPORT_NODE
    exporter.location = (100, -250)
    links.new(group_in.outputs["Normal"], separate.inputs[0])
    for channel in ("Red", "Green", "Blue"):
        links.new(separate.outputs[channel], combine.inputs[channel])
    links.new(group_in.outputs["Depth"], combine.inputs["Alpha"])
    links.new(combine.outputs[0], exporter.inputs[0])

    ao = nodes.new("CompositorNodeImage")
    ao.name = ao.label = AO_NODE
    ao.location = (-350, 200)
    multiply, factor, image_in, ao_in, result = compat.new_multiply(tree)
    multiply.name = multiply.label = MULTIPLY_NODE
    multiply.location = (150, 100)
    factor.default_value = 1.0
    links.new(group_in.outputs["Image"], image_in)
    links.new(result, group_out.inputs["Image"])
    _add_channels(tree, ao_in)
    _add_image_export(tree)
    return tree


def _group_nodes(tree):
    return (next(n for n in tree.nodes if n.bl_idname == "NodeGroupInput"),
            next(n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"))


def _add_channels(tree, factor_in):
    """The AO image's Red to the AO output, its Green (the composite's factor) to the Multiply's
    input `factor_in`: exact channels (a colour linked to a float socket is averaged)."""
    ao = tree.nodes[AO_NODE]
    _, group_out = _group_nodes(tree)
    channels = tree.nodes.new("CompositorNodeSeparateColor")
    channels.mode = 'RGB'
    channels.name = channels.label = CHANNELS_NODE
    channels.location = (-150, 200)
    for link in list(ao.outputs["Image"].links):
        tree.links.remove(link)
    tree.links.new(ao.outputs["Image"], channels.inputs[0])
    tree.links.new(channels.outputs["Green"], factor_in)
    tree.links.new(channels.outputs["Red"], group_out.inputs["AO"])


def _add_image_export(tree):
    """The Image (colour and alpha), written beside the passes (read back by compute.py: its
    alpha is the composite's coverage on a transparent film, its colours the library's
    edge_colours)."""
    # Its one input has the exporter's name: 5.x names files file name + input name.
    exporter = compat.new_file_output(tree, ["Passes"])
    exporter.name = exporter.label = IMAGE_EXPORT_NODE
    exporter.location = (100, -450)
    _link_image_export(tree)


def _link_image_export(tree):
    """The Image straight into its exporter; a tree saved when the exporter wrote the Image's
    alpha alone (through ALPHA_NODE) loses that node."""
    group_in, _ = _group_nodes(tree)
    exporter = tree.nodes[IMAGE_EXPORT_NODE]
    if ALPHA_NODE in tree.nodes:
        tree.nodes.remove(tree.nodes[ALPHA_NODE])
    for link in list(exporter.inputs[0].links):
        tree.links.remove(link)
    tree.links.new(group_in.outputs["Image"], exporter.inputs[0])


def upgrade(node):
    """Adds what a tree saved by an earlier version of the add-on lacks (its AO image's Green is
    the AO: it composites Image x AO until the next computation)."""
    tree = node.node_tree
    if tree is None or tree.library is not None or AO_NODE not in tree.nodes or \
            MULTIPLY_NODE not in tree.nodes:
        return
    if CHANNELS_NODE not in tree.nodes:
        # Before: the AO image's colour linked straight to the Multiply and the AO output.
        multiplied = [link.to_socket for link in tree.nodes[AO_NODE].outputs["Image"].links
                      if link.to_node == tree.nodes[MULTIPLY_NODE]]
        if not multiplied:
            return  # edited by hand: left alone
        _add_channels(tree, multiplied[0])
    if IMAGE_EXPORT_NODE not in tree.nodes:
        _add_image_export(tree)
    elif ALPHA_NODE in tree.nodes:
        _link_image_export(tree)


def new_id():
    """A node's id: names its export files, inner tree and AO image."""
    return uuid.uuid4().hex[:12]


def inner(node, name):
    return node.node_tree.nodes.get(name) if node.node_tree is not None else None


def export_path(node, frame, extra_folders=(), since=0.0):
    """Where the node's exporter wrote `frame`, from its own settings (a file saved by another
    session, or opened before the add-on was enabled, keeps the folder it was saved with): the
    newest file written at or after `since` (a time.time()) in that folder or `extra_folders`;
    None when there is none."""
    folder, prefix = compat.file_output_target(inner(node, EXPORT_NODE))
    folders = [bpy.path.abspath(folder)] + list(extra_folders)
    # 5.x writes a still render's File Output files without the frame number.
    candidates = [os.path.join(f, name) for f in folders
                  for name in (f"{prefix}{frame:04d}.exr", f"{prefix}.exr")]
    existing = [p for p in candidates if os.path.isfile(p) and os.path.getmtime(p) >= since]
    return max(existing, key=os.path.getmtime) if existing else None


def image_export_path(passes_path):
    """The Image exported with the passes at `passes_path` (the same file name in the folder
    image/ beside it), or None when it was not written with them."""
    path = os.path.join(os.path.dirname(passes_path), IMAGE_FOLDER,
                        os.path.basename(passes_path))
    if not os.path.isfile(path) or os.path.getmtime(path) < \
            os.path.getmtime(passes_path) - IMAGE_EXPORT_SLACK_SECONDS:
        return None
    return path


def remove_earlier_exports(node, kept_path):
    """Removes the node's exports of the frames before the one at `kept_path` (passes and
    Image) from the folder that holds it: an animation adds them for each frame (about 25 MB
    at 1920x1080), computes its frames in order, and reads none again once it is past it."""
    folder, name = os.path.split(kept_path)
    prefix = compat.file_output_target(inner(node, EXPORT_NODE))[1]

    def frame_of(file_name):  # None for another file, or a still's (no number)
        number = file_name[len(prefix):-len(".exr")]
        return int(number) if file_name.startswith(prefix) and file_name.endswith(".exr") \
            and number.isascii() and number.isdigit() else None

    kept = frame_of(name)
    if kept is None:
        return
    for where in (folder, os.path.join(folder, IMAGE_FOLDER)):
        try:
            names = os.listdir(where)
        except OSError:
            continue
        for other in names:
            frame = frame_of(other)
            if frame is not None and frame < kept:
                try:
                    os.remove(os.path.join(where, other))
                except OSError:
                    pass


def point_exporter(node, folder):
    """Points the node's exporters at `folder` (no folder is made: File Output makes it when it
    first writes)."""
    exporter, image = inner(node, EXPORT_NODE), inner(node, IMAGE_EXPORT_NODE)
    if exporter is not None:
        compat.set_file_output_target(exporter, folder, f"ssao_{node.ssao_id}_")
    if image is not None:
        compat.set_file_output_target(image, os.path.join(folder, IMAGE_FOLDER),
                                      f"ssao_{node.ssao_id}_")


def configure(node, folder, size=None):
    """The tree upgraded (upgrade()); the exporter writes lossless 32-bit RGBA EXR into
    `folder`, the Image exporter 32-bit RGBA into its image/ folder; the AO image exists (and
    has `size`, when given)."""
    exporter = inner(node, EXPORT_NODE)
    if exporter is None:
        return
    upgrade(node)
    point_exporter(node, folder)
    compat.set_image_format(exporter.format, 'OPEN_EXR', color_depth='32', codec='ZIP',
                            color_mode='RGBA')
    image = inner(node, IMAGE_EXPORT_NODE)
    if image is not None:
        compat.set_image_format(image.format, 'OPEN_EXR', color_depth='32', codec='ZIP',
                                color_mode='RGBA')
    set_exporter_muted(node, False)
    if size is not None:
        ao_image(node, *size)


def set_exporter_muted(node, muted):
    for name in (EXPORT_NODE, IMAGE_EXPORT_NODE):
        exporter = inner(node, name)
        if exporter is not None:
            exporter.mute = muted


def forget_ao_image(node):
    """The node's inner AO image node lets go of its image (a copied node makes its own)."""
    holder = inner(node, AO_NODE)
    if holder is not None:
        holder.image = None


def ao_image_if_any(node):
    holder = inner(node, AO_NODE)
    return holder.image if holder is not None else None


def ao_image(node, width, height):
    """The node's AO image (float, non-colour data), made or resized as needed."""
    holder = inner(node, AO_NODE)
    if holder is None:
        raise RuntimeError(f"the node's inner tree has no '{AO_NODE}' image node (was it "
                           "edited?): delete the node and add it again")
    image = holder.image
    if image is None:
        image = bpy.data.images.new(f".SSAO AO {node.ssao_id}", width, height, alpha=False,
                                    float_buffer=True)
        image.colorspace_settings.name = 'Non-Color'
        # Until an AO is computed the node leaves the image as it is (not black).
        image.pixels.foreach_set(np.ones(width * height * 4, np.float32))
        holder.image = image
    elif tuple(image.size) != (width, height):
        image.scale(width, height)
    return image


def white_beauty(passes):
    """The beauty of a run on `passes` (compute.py's bottom-up export: normal xyz, depth and,
    when it was exported, the Image's RGBA): white with the Image's alpha, row 0 on top. Its
    composite is the factor the composite applies to the Image (store_outputs)."""
    height, width = passes.shape[:2]
    white = np.ones((height, width, 4), np.float32)
    if passes.shape[2] > 4:
        white[:, :, 3] = passes[::-1, :, 7]
    return white


def image_colours(passes):
    """The Image's colours of `passes` (as white_beauty()'s), a view with row 0 on top: the
    library's "edge_colours" (the white beauty says nothing of where an edge lies). None when
    the Image was not exported."""
    return passes[::-1, :, 4:7] if passes.shape[2] > 4 else None


def store_outputs(node, ao, composite):
    """Fills and tags the AO image from a run's `ao` (height, width) and the `composite` of
    white_beauty(), both row 0 on top: Red (and Blue) the AO, Green the composite's factor,
    alpha 1, rows bottom-up as Blender's. Returns the image."""
    height, width = ao.shape
    pixels = np.empty((height, width, 4), np.float32)
    pixels[:, :, 0] = pixels[:, :, 2] = ao[::-1]
    pixels[:, :, 1] = composite[::-1, :, 0]
    pixels[:, :, 3] = 1.0
    image = ao_image(node, width, height)
    image.pixels.foreach_set(pixels.ravel())
    image.update()
    # 5.x's GPU compositor keeps its own copy of the image: tag it, or the UI compositor
    # re-composites with the old AO (measured in 5.2.2).
    image.update_tag()
    return image


def blank_ao(node, width, height):
    """Sets the node's AO image to 1 (the AO and the composite's factor), so that the node
    passes its Image through unchanged: what a frame whose AO could not be computed gets,
    rather than the AO of another frame."""
    image = ao_image(node, width, height)
    image.pixels.foreach_set(np.ones(width * height * 4, np.float32))
    image.update()
    image.update_tag()  # 5.x's GPU compositor keeps its own copy (see store_outputs)


def nudge(node):
    """Changing a built-in node's value makes the UI compositor run again on the existing render
    (Python properties and update_tag() do not)."""
    multiply = inner(node, MULTIPLY_NODE)
    if multiply is not None:
        factor = compat.factor_input(multiply)
        factor.default_value = 0.999
        factor.default_value = 1.0
