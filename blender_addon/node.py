# SPDX-License-Identifier: MIT
"""The compositor node CompositorNodeSSAO: a custom group node whose inner tree is made of
built-in nodes only, so that a .blend saved with it still composites (with the last computed AO)
where the add-on is not installed.

Inner tree:  Group Input (Image, Depth, Normal)
               Depth, Normal -> Combine Color (R, G, B = normal, A = depth) -> File Output
                                (the "exporter": 32-bit EXR read back by pipeline.py)
             AO image (filled by pipeline.py) -> Multiply with Image -> Group Output Image
                                              -> Group Output AO
"""
import uuid

import bpy

from . import pipeline, ssao_native

# Library parameters the node exposes, by their library names (the rest are set by the add-on:
# camera, conventions, threads).
NODE_PARAMETERS = ("variant", "radius", "quality", "resolution", "samples", "slices", "steps",
                   "bias", "thickness", "sample_clustering", "sphere_mode", "denoise", "strength",
                   "power", "remap_min", "remap_max", "seed")

EXPORT_NODE, AO_NODE, MULTIPLY_NODE = "SSAO Export", "SSAO AO", "SSAO Multiply"

# Why the library's parameter table could not be read (shown on the node), or None.
LIBRARY_ERROR = None
# Variant name -> the parameters only it reads (the node hides them for other variants).
VARIANT_PARAMETERS = {}


def _on_parameter_changed(node, context):
    pipeline.parameter_changed(node, context.scene if context else None)


def _property_for(desc):
    """A bpy property with the library's default, range, unit and description."""
    title = desc["name"].replace("_", " ").capitalize()
    text = desc["description"] + (f" ({desc['unit']})" if desc["unit"] else "")
    if desc["type"] == ssao_native.PARAM_STRING:
        items = [(c, c.replace("_", " ").capitalize(), "") for c in desc["choices"]]
        return bpy.props.EnumProperty(name=title, description=text, items=items,
                                      default=desc["default_string"],
                                      update=_on_parameter_changed)
    if desc["type"] == ssao_native.PARAM_INT:
        return bpy.props.IntProperty(name=title, description=text, default=int(desc["default"]),
                                     min=int(desc["min"]), max=int(desc["max"]),
                                     update=_on_parameter_changed)
    kwargs = {}
    if desc["unit"] == "scene units":
        kwargs["subtype"] = 'DISTANCE'
    return bpy.props.FloatProperty(name=title, description=text, default=desc["default"],
                                   min=desc["min"], max=min(desc["max"], 1e9),
                                   update=_on_parameter_changed, **kwargs)


def _parameter_table():
    global LIBRARY_ERROR
    try:
        table = {p["name"]: p for p in ssao_native.parameters(pipeline.library())}
        VARIANT_PARAMETERS.update({v["name"]: set(v["parameters"])
                                   for v in ssao_native.variants(pipeline.library())})
    except Exception as error:  # the node must still register so .blend files open
        LIBRARY_ERROR = str(error)
        return {}
    return {name: table[name] for name in NODE_PARAMETERS if name in table}


def _new_socket(tree, in_out, socket_type, name):
    """Group sockets: tree.interface in Blender 4.0+, tree.inputs/outputs before."""
    if hasattr(tree, "interface"):
        return tree.interface.new_socket(name, in_out=in_out, socket_type=socket_type)
    sockets = tree.inputs if in_out == 'INPUT' else tree.outputs
    return sockets.new(socket_type, name)


class CompositorNodeSSAO(bpy.types.CompositorNodeCustomGroup):
    """Screen-space ambient occlusion from the Depth (and Normal) pass, computed by libssao"""

    bl_idname = "CompositorNodeSSAO"
    bl_label = "Ambient Occlusion (SSAO)"
    bl_width_default = 200

    ssao_id: bpy.props.StringProperty(name="Node id", options={'HIDDEN'})
    status: bpy.props.StringProperty(name="Status", options={'SKIP_SAVE'})

    def init(self, context):
        self.ssao_id = uuid.uuid4().hex[:12]
        self.node_tree = _build_inner_tree(self.ssao_id)
        pipeline.configure_node(self)

    def copy(self, node):
        # A node copied into another tree (a copied scene, such as the re-compositing helper)
        # keeps sharing the inner tree and AO image; a duplicate in the same tree gets its own.
        if self.id_data != node.id_data:
            return
        self.ssao_id = uuid.uuid4().hex[:12]
        self.node_tree = node.node_tree.copy()
        pipeline.configure_node(self)

    def free(self):
        pipeline.forget_node(self)
        if self.node_tree is not None and self.node_tree.users <= 1:
            bpy.data.node_groups.remove(self.node_tree)

    def draw_buttons(self, context, layout):
        if LIBRARY_ERROR:
            layout.label(text="libssao missing (see console)", icon='ERROR')
        variant_specific = set().union(*VARIANT_PARAMETERS.values())
        active = VARIANT_PARAMETERS.get(getattr(self, "variant", ""), variant_specific)
        for name in self.bl_rna.properties.keys():
            if name in NODE_PARAMETERS and (name not in variant_specific or name in active):
                layout.prop(self, name)
        layout.operator("ssao.recompute", icon='FILE_REFRESH')
        if self.status:
            layout.label(text=self.status, icon='ERROR' if self.status.startswith("Error")
                         else 'INFO')


def _build_inner_tree(ssao_id):
    tree = bpy.data.node_groups.new(".SSAO " + ssao_id, "CompositorNodeTree")
    _new_socket(tree, 'INPUT', 'NodeSocketColor', "Image")
    _new_socket(tree, 'INPUT', 'NodeSocketFloat', "Depth")
    _new_socket(tree, 'INPUT', 'NodeSocketVector', "Normal")
    _new_socket(tree, 'OUTPUT', 'NodeSocketColor', "Image")
    _new_socket(tree, 'OUTPUT', 'NodeSocketFloat', "AO")

    nodes, links = tree.nodes, tree.links
    group_in = nodes.new("NodeGroupInput")
    group_in.location = (-600, 0)
    group_out = nodes.new("NodeGroupOutput")
    group_out.location = (400, 0)

    separate = nodes.new("CompositorNodeSeparateXYZ")
    separate.location = (-350, -250)
    combine = nodes.new("CompositorNodeCombineColor")
    combine.location = (-150, -250)
    combine.mode = 'RGB'
    exporter = nodes.new("CompositorNodeOutputFile")
    exporter.name = exporter.label = EXPORT_NODE
    exporter.location = (100, -250)
    links.new(group_in.outputs["Normal"], separate.inputs[0])
    for axis, channel in zip(("X", "Y", "Z"), ("Red", "Green", "Blue")):
        links.new(separate.outputs[axis], combine.inputs[channel])
    links.new(group_in.outputs["Depth"], combine.inputs["Alpha"])
    if not exporter.inputs and hasattr(exporter, "file_output_items"):  # Blender 5.0+
        exporter.file_output_items.new('RGBA', "Passes")
    links.new(combine.outputs[0], exporter.inputs[0])

    ao = nodes.new("CompositorNodeImage")
    ao.name = ao.label = AO_NODE
    ao.location = (-150, 200)
    multiply = nodes.new("CompositorNodeMixRGB")
    multiply.name = multiply.label = MULTIPLY_NODE
    multiply.blend_type = 'MULTIPLY'
    multiply.location = (150, 100)
    links.new(group_in.outputs["Image"], multiply.inputs[1])
    links.new(ao.outputs["Image"], multiply.inputs[2])
    links.new(multiply.outputs[0], group_out.inputs["Image"])
    links.new(ao.outputs["Image"], group_out.inputs["AO"])
    return tree


def _draw_add_menu(self, context):
    space = context.space_data
    if getattr(space, "tree_type", None) != "CompositorNodeTree":
        return
    item = self.layout.operator("node.add_node", text=CompositorNodeSSAO.bl_label)
    item.type = CompositorNodeSSAO.bl_idname
    item.use_transform = True


# The compositor's Filter menu: nodeitems category menu in 3.x, menu classes in 4.x and later.
_FILTER_MENUS = ("NODE_MT_category_CMP_OP_FILTER", "NODE_MT_category_COMP_FILTER",
                 "NODE_MT_category_compositor_filter")


def _filter_menu():
    for name in _FILTER_MENUS:
        menu = getattr(bpy.types, name, None)
        if menu is not None:
            return menu
    return None


def register():
    table = _parameter_table()
    for name, desc in table.items():
        CompositorNodeSSAO.__annotations__[name] = _property_for(desc)
    bpy.utils.register_class(CompositorNodeSSAO)
    menu = _filter_menu()
    if menu is not None:
        menu.append(_draw_add_menu)
    else:
        print("ssao_compositor: warning: no compositor Filter menu found; add the node from "
              "Python: tree.nodes.new('CompositorNodeSSAO')")
    if LIBRARY_ERROR:
        print(f"ssao_compositor: error: {LIBRARY_ERROR}")


def unregister():
    menu = _filter_menu()
    if menu is not None:
        menu.remove(_draw_add_menu)
    bpy.utils.unregister_class(CompositorNodeSSAO)
