# SPDX-License-Identifier: MIT
"""Every difference between Blender 3.4, 4.x and 5.x that the add-on meets, in one place.
The rest of the add-on calls these and never tests versions or version-dependent attributes
itself; here a difference is found by the attribute or type it concerns where one exists, by
the version number only for a behaviour (compositor_cannot_export).

Checked in Blender 3.4.1, 4.3.2 and 5.2.2 (docs/blender.md, "Blender versions")."""
import bpy


def compositor_tree(scene, in_use_only=True):
    """The scene's compositing node tree: a node-group data-block in 5.0+
    (scene.compositing_node_group), the scene's embedded scene.node_tree before, where
    compositing can be off (scene.use_nodes): None then, unless in_use_only is False."""
    if hasattr(scene, "compositing_node_group"):
        return scene.compositing_node_group
    return scene.node_tree if scene.use_nodes or not in_use_only else None


def ensure_compositor_tree(scene):
    """The scene's compositing tree, made if there is none (empty in 5.x, Blender's default
    Render Layers -> Composite in 3.x/4.x)."""
    if hasattr(scene, "compositing_node_group"):
        if scene.compositing_node_group is None:
            scene.compositing_node_group = bpy.data.node_groups.new(
                "Compositing", "CompositorNodeTree")
        return scene.compositing_node_group
    scene.use_nodes = True
    return scene.node_tree


def set_compositor_tree(scene, tree):
    """Makes `tree` the scene's compositing tree where the tree is a data-block of its own
    (5.x); before 5.0 the tree is embedded in the scene and copied with it."""
    if hasattr(scene, "compositing_node_group"):
        scene.compositing_node_group = tree


def compositor_trees_are_shared():
    """True where a copied scene shares its compositing tree with the original (5.x)."""
    return "compositing_node_group" in bpy.types.Scene.bl_rna.properties


def add_result_output(tree):
    """The node that makes the tree's result: Composite (3.x/4.x) or Group Output with an
    Image socket (5.x). Returns (node, its image input socket)."""
    if hasattr(bpy.types, "CompositorNodeComposite"):
        node = tree.nodes.new("CompositorNodeComposite")
        return node, node.inputs["Image"]
    if not any(item.item_type == 'SOCKET' and item.in_out == 'OUTPUT'
               for item in tree.interface.items_tree):
        new_socket(tree, 'OUTPUT', 'NodeSocketColor', "Image")
    node = tree.nodes.new("NodeGroupOutput")
    return node, node.inputs[0]


def result_output_nodes(tree):
    """The nodes whose input is the tree's result (Composite, or the active Group Output)."""
    return [n for n in tree.nodes if n.bl_idname == "CompositorNodeComposite"
            or (n.bl_idname == "NodeGroupOutput" and getattr(n, "is_active_output", True))]


def new_socket(tree, in_out, socket_type, name):
    """A group socket: tree.interface in 4.0+, tree.inputs/outputs before."""
    if hasattr(tree, "interface"):
        return tree.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
    sockets = tree.inputs if in_out == 'INPUT' else tree.outputs
    return sockets.new(socket_type, name)


def new_multiply(tree):
    """A colour Multiply node: Mix RGB before 5.0, the shared Mix node (colour) after.
    Returns (node, factor input, A input, B input, result output)."""
    if hasattr(bpy.types, "CompositorNodeMixRGB"):
        node = tree.nodes.new("CompositorNodeMixRGB")
        node.blend_type = 'MULTIPLY'
        return node, node.inputs[0], node.inputs[1], node.inputs[2], node.outputs[0]
    node = tree.nodes.new("ShaderNodeMix")
    node.data_type = 'RGBA'
    node.blend_type = 'MULTIPLY'
    inputs = {s.identifier: s for s in node.inputs}
    outputs = {s.identifier: s for s in node.outputs}
    return (node, inputs["Factor_Float"], inputs["A_Color"], inputs["B_Color"],
            outputs["Result_Color"])


def factor_input(mix_node):
    """The factor socket of a node made by new_multiply (either kind)."""
    return mix_node.inputs[0]


# --- File Output ---------------------------------------------------------------------------

def new_file_output(tree, slots):
    """A File Output node with one input per slot: a name, or (name, socket type) with the
    types of 5.x's file_output_items ('RGBA', 'FLOAT', 'VECTOR'); before 5.0 every file slot
    takes any data. Returns the node."""
    node = tree.nodes.new("CompositorNodeOutputFile")
    slots = [(s, 'RGBA') if isinstance(s, str) else s for s in slots]
    if hasattr(node, "file_output_items"):
        node.file_output_items.clear()
        for name, socket_type in slots:
            node.file_output_items.new(socket_type, name)
    else:
        node.file_slots.clear()
        for name, _ in slots:
            node.file_slots.new(name)
    return node


def file_output_target(node):
    """(folder, file name before the frame number) of a File Output node's first image: the
    slot's path before 5.0; in 5.x the node's file name followed by the item's name."""
    if hasattr(node, "file_slots"):
        return node.base_path, node.file_slots[0].path
    return node.directory, node.file_name + node.file_output_items[0].name


def set_file_output_target(node, folder, prefix):
    """Where a File Output node writes: folder/prefix####.ext."""
    if hasattr(node, "file_slots"):
        node.base_path = folder.rstrip("/\\") + "/"
        node.file_slots[0].path = prefix
    else:
        node.directory = folder
        node.file_name = prefix


def set_image_format(settings, file_format, color_depth=None, codec=None, color_mode=None):
    """Sets an image format (render output, File Output). 5.0 added media_type: a multilayer
    EXR is media_type MULTI_LAYER_IMAGE, then file_format OPEN_EXR_MULTILAYER (5.2)."""
    if hasattr(settings, "media_type"):
        multilayer = file_format == 'OPEN_EXR_MULTILAYER'
        settings.media_type = 'MULTI_LAYER_IMAGE' if multilayer else 'IMAGE'
        offered = settings.bl_rna.properties["file_format"].enum_items.keys()
        if file_format not in offered:  # 5.2 names it OPEN_EXR_MULTILAYER, 5.0 OPEN_EXR
            file_format = 'OPEN_EXR'
    settings.file_format = file_format
    if color_mode is not None:
        settings.color_mode = color_mode
    if color_depth is not None:
        settings.color_depth = color_depth
    if codec is not None:
        settings.exr_codec = codec


def image_format(settings):
    """The format as set_image_format takes it (OPEN_EXR_MULTILAYER for a multilayer EXR)."""
    if getattr(settings, "media_type", None) == 'MULTI_LAYER_IMAGE' or \
            settings.file_format == 'OPEN_EXR_MULTILAYER':
        return 'OPEN_EXR_MULTILAYER'
    return settings.file_format


def is_movie(settings):
    """A movie output format (5.x: media_type VIDEO; before: FFMPEG or AVI)."""
    if getattr(settings, "media_type", None) == 'VIDEO':
        return True
    return settings.file_format in {'FFMPEG', 'AVI_JPEG', 'AVI_RAW'}


FORMAT_ATTRIBUTES = ("media_type", "file_format", "color_mode", "color_depth", "exr_codec",
                     "compression", "quality", "use_preview")


def copy_image_format(source, target):
    """Copies an image format's settings (the order matters: media type first)."""
    for attribute in FORMAT_ATTRIBUTES:
        if hasattr(source, attribute):
            try:
                setattr(target, attribute, getattr(source, attribute))
            except (TypeError, ValueError):  # a value the target's format does not offer
                pass


# --- everything else -----------------------------------------------------------------------

# The compositor's Filter menu: nodeitems category menu in 3.x, menu classes in 4.x and later.
_FILTER_MENUS = ("NODE_MT_category_CMP_OP_FILTER", "NODE_MT_category_COMP_FILTER",
                 "NODE_MT_category_compositor_filter")


def filter_menu():
    for name in _FILTER_MENUS:
        menu = getattr(bpy.types, name, None)
        if menu is not None:
            return menu
    return None


def is_eevee(scene):
    """EEVEE is BLENDER_EEVEE in 3.x and 5.x, BLENDER_EEVEE_NEXT in 4.2 to 4.5."""
    return scene.render.engine.startswith("BLENDER_EEVEE")


def compositor_device(scene):
    """'CPU' or 'GPU' (4.2+ may composite on the GPU; before, always the CPU)."""
    return getattr(scene.render, "compositor_device", 'CPU')


def compositor_cannot_export(scene):
    """Why this scene's compositor cannot feed the node its passes, or None. Blender 4.x's GPU
    compositor runs no File Output node inside a node group (measured in 4.3.2: nothing is
    written; 5.2.2 writes them)."""
    if compositor_device(scene) == 'GPU' and bpy.app.version < (5, 0, 0):
        return ("Blender 4.x's GPU compositor does not run the node's inner File Output: set "
                "Render Properties > Performance > Compositor > Device to CPU")
    return None


def set_aov_output_name(node, name):
    """The AOV an AOV Output shader node writes: `aov_name` in 4.0+, the node's `name` (which
    that type redefines) before."""
    if hasattr(node, "aov_name"):
        node.aov_name = name
    else:
        node.name = name


def render_view_layers_only(scene):
    """Turns off a new scene's compositing (before 5.0 scene.use_nodes; in 5.x a new scene has
    no compositing node group) and its sequencer, so that rendering it renders only its view
    layer."""
    if hasattr(scene, "compositing_node_group"):
        scene.compositing_node_group = None
    else:
        scene.use_nodes = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False



def layer_collection(view_layer):
    """A view layer's layer collection tree. In 5.2 a new scene's view layer has none (None)
    until its depsgraph is updated once; after that, collections linked later appear in it.
    Update while the scene is empty (cheap: nothing to evaluate)."""
    if view_layer.layer_collection is None:
        view_layer.update()
    return view_layer.layer_collection


def displacement_method(material):
    """'BUMP', 'DISPLACEMENT' or 'BOTH': material.displacement_method in 4.1+, its Cycles
    settings' before."""
    if hasattr(material, "displacement_method"):
        return material.displacement_method
    return material.cycles.displacement_method
