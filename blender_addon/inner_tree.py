# SPDX-License-Identifier: MIT
"""The node's inner tree, made of built-in nodes only, so that a .blend saved with the node still
composites (with the last computed AO) where the add-on is not installed:

  Group Input (Image, Depth, Normal)
    Normal -> Separate Color -> R, G, B ┐
    Depth  ------------------------> A  ┴ Combine Color -> File Output "SSAO Export"
                                          (a lossless 32-bit EXR, read back by compute.py)
  Image node "SSAO AO" (the AO, filled by compute.py) -> Multiply with Image -> Output Image
                                                     -> Output AO
"""
import os
import uuid

import bpy
import numpy as np

from . import compat

NODE_IDNAME = "CompositorNodeSSAO"
EXPORT_NODE, AO_NODE, MULTIPLY_NODE = "SSAO Export", "SSAO AO", "SSAO Multiply"


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
    ao.location = (-150, 200)
    multiply, factor, image_in, ao_in, result = compat.new_multiply(tree)
    multiply.name = multiply.label = MULTIPLY_NODE
    multiply.location = (150, 100)
    factor.default_value = 1.0
    links.new(group_in.outputs["Image"], image_in)
    links.new(ao.outputs["Image"], ao_in)
    links.new(result, group_out.inputs["Image"])
    links.new(ao.outputs["Image"], group_out.inputs["AO"])
    return tree


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


def point_exporter(node, folder):
    """Points the node's exporter at `folder` (no folder is made: File Output makes it when it
    first writes)."""
    exporter = inner(node, EXPORT_NODE)
    if exporter is not None:
        compat.set_file_output_target(exporter, folder, f"ssao_{node.ssao_id}_")


def configure(node, folder, size=None):
    """The exporter writes lossless 32-bit RGBA EXR into `folder`; the AO image exists (and has
    `size`, when given)."""
    exporter = inner(node, EXPORT_NODE)
    if exporter is None:
        return
    point_exporter(node, folder)
    compat.set_image_format(exporter.format, 'OPEN_EXR', color_depth='32', codec='ZIP',
                            color_mode='RGBA')
    exporter.mute = False
    if size is not None:
        ao_image(node, *size)


def set_exporter_muted(node, muted):
    exporter = inner(node, EXPORT_NODE)
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


def blank_ao(node, width, height):
    """Sets the node's AO image to 1, so that the node passes its Image through unchanged: what
    a frame whose AO could not be computed gets, rather than the AO of another frame."""
    image = ao_image(node, width, height)
    image.pixels.foreach_set(np.ones(width * height * 4, np.float32))
    image.update()
    image.update_tag()  # 5.x's GPU compositor keeps its own copy (see compute.py)


def nudge(node):
    """Changing a built-in node's value makes the UI compositor run again on the existing render
    (Python properties and update_tag() do not)."""
    multiply = inner(node, MULTIPLY_NODE)
    if multiply is not None:
        factor = compat.factor_input(multiply)
        factor.default_value = 0.999
        factor.default_value = 1.0
