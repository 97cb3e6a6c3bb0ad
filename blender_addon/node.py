# SPDX-License-Identifier: MIT
"""The compositor node CompositorNodeSSAO: a custom group node (its inner tree: inner_tree.py)
whose properties are libssao's parameters, with the library's names, defaults and ranges."""
import bpy

from . import compat, compute, handlers, inner_tree, session, ssao

# The node's face (draw_buttons): what an artist changes, as on Blender's own nodes; with the
# add-on's settings (compute.NODE_SETTINGS), Recompute and the status. The sidebar (N panel,
# Node tab: draw_buttons_ext) shows every property, grouped as the library groups them.
FACE_PARAMETERS = ("radius", "strength", "quality")
# The sidebar's box titles: the library's groups, in compute.NODE_GROUPS's order, then the
# add-on's settings.
GROUP_TITLES = {"ao": "Occlusion", "quality": "Quality and cost", "shaping": "Shaping",
                "execution": "Animation",  # of execution, only temporal_frames
                "input": "Edges"}  # of input, only edge_coverage
SETTINGS_TITLE = "Helper render"
# Chosen from the costs and gains measured in docs/blender.md, "Hidden surfaces and overscan".
DEFAULT_HIDDEN_SURFACES = 'PEELED'
DEFAULT_OVERSCAN = 64


def _on_parameter_changed(node, context):
    # The node's own scene (the context's may be another one showing a pinned tree).
    handlers.parameter_changed(node, compute.scene_of_tree(node.id_data) or
                               (context.scene if context else None))


def _on_overscan_changed(node, context):
    # A band given in pixels (from the UI or a script: node.overscan = 16) is used as given;
    # a saved file's settings put back (saved_form.py) keep their own overscan_mode.
    if node.overscan_mode != 'PIXELS' and not session.current.restoring_settings:
        node.overscan_mode = 'PIXELS'  # its own update recomputes
        return
    _on_parameter_changed(node, context)


# Where the library's description speaks of its own calls, what the parameter means on the node.
NODE_DESCRIPTIONS = {
    "temporal_frames": "In an animation render (Ctrl+F12, blender -a), the AO averages this "
                       "many frames: this one and the ones just before it, carried to its "
                       "pixels through depth and camera; pixels the earlier frame did not see, "
                       "near something that moved, or whose AO changed much take no part. "
                       "Steadies the pattern's crawl on camera moves. 1: each frame alone (a "
                       "still always is)",
    "edge_coverage": "Beauty: where one surface passes in front of another, the AO mixes the "
                     "two surfaces' AO by the share of the pixel each covers, read from the "
                     "Image's colours (the last render's), the Normal pass or the Depth's "
                     "staircase, as Cycles' AO pass does; none for an "
                     "Image whose edges are not the Depth's (blurred before the node: Defocus, "
                     "or depth of field and motion blur rendered into it)",
}


def _property_for(desc):
    """A bpy property with the library's default, range, unit and description."""
    title = desc["name"].replace("_", " ").capitalize()
    text = NODE_DESCRIPTIONS.get(desc["name"], desc["description"]) + \
        (f" ({desc['unit']})" if desc["unit"] else "")
    if desc["type"] == ssao.PARAM_STRING:
        items = [(c, c.replace("_", " ").capitalize(), "") for c in desc["choices"]]
        return bpy.props.EnumProperty(name=title, description=text, items=items,
                                      default=desc["default_string"],
                                      update=_on_parameter_changed)
    if desc["type"] == ssao.PARAM_INT:
        return bpy.props.IntProperty(name=title, description=text, default=int(desc["default"]),
                                     min=int(desc["min"]), max=int(desc["max"]),
                                     update=_on_parameter_changed)
    kwargs = {}
    if desc["unit"] == "scene units":
        kwargs["subtype"] = 'DISTANCE'
    return bpy.props.FloatProperty(name=title, description=text, default=desc["default"],
                                   min=desc["min"], max=min(desc["max"], 1e9),
                                   update=_on_parameter_changed, **kwargs)


def _draw_property(node, layout, name, stacked=False):
    """A property. A menu gets its name on the left half, or on a line above it when `stacked`
    (the sidebar, narrower than the node): Blender's own "Name: value" leaves a few letters
    of the name in either."""
    prop = node.bl_rna.properties[name]
    if prop.type != 'ENUM':
        layout.prop(node, name)
    elif stacked:
        column = layout.column(align=True)
        column.label(text=prop.name)
        column.prop(node, name, text="")
    else:
        split = layout.split(factor=0.5)
        split.label(text=prop.name)
        split.prop(node, name, text="")


def _parameter_table():
    """The library's parameters the node shows, {name: description}; {} without the library
    (the error is kept in the session and shown on the node)."""
    try:
        table = compute.library_table()
    except Exception as error:  # the node must still register so .blend files open
        session.current.library_error = str(error)
        return {}
    return {name: table.parameters[name] for name in table.node_parameter_names}


class CompositorNodeSSAO(bpy.types.CompositorNodeCustomGroup):
    """Screen-space ambient occlusion from the Depth (and Normal) pass, computed by libssao"""

    bl_idname = inner_tree.NODE_IDNAME
    bl_label = "Ambient Occlusion (SSAO)"
    bl_width_default = 200

    ssao_id: bpy.props.StringProperty(name="Node id", options={'HIDDEN'})
    status: bpy.props.StringProperty(name="Status", options={'SKIP_SAVE'})
    # The add-on's own settings (compute.NODE_SETTINGS): a helper render of the surfaces behind
    # the visible ones and of a guard band (hidden_surfaces.py; costs: docs/blender.md).
    hidden_surfaces: bpy.props.EnumProperty(
        name="Hidden surfaces",
        description="What the AO knows of the surfaces behind the visible ones (a helper render "
                    "with Cycles at 1 sample per pixel, whatever the render engine)",
        items=[('NONE', "None", "The Depth pass only: behind it, the thickness guess"),
               ('PEELED', "Peeled", "The 2nd to 5th surface hit along each pixel's "
                                    "ray, and whether each is a back face")],
        default=DEFAULT_HIDDEN_SURFACES, update=_on_parameter_changed)
    # The band's width follows the radius unless given in pixels (setting `overscan` gives it;
    # compute.band_width).
    overscan_mode: bpy.props.EnumProperty(
        name="Band",
        description="How wide the guard band is",
        items=[('RADIUS', "From radius",
                "As wide as half the radius spans in pixels at the frame's edges (a helper "
                "render; grows with the resolution)"),
               ('PIXELS', "Pixels", "Overscan pixels per side (0: no band)")],
        default='RADIUS', update=_on_parameter_changed)
    overscan: bpy.props.IntProperty(
        name="Overscan", subtype='PIXEL', min=0, max=4096, soft_max=256,
        default=DEFAULT_OVERSCAN,
        description="Guard band rendered around the frame, in pixels per side, so that "
                    "occluders just outside the frame count (0: off; a helper render). "
                    "Setting it sets Band to Pixels",
        update=_on_overscan_changed)

    def init(self, context):
        self.ssao_id = inner_tree.new_id()
        self.node_tree = inner_tree.build(self.ssao_id)
        compute.configure_node(self)

    def copy(self, node):
        # The re-compositing helper's copy shares the inner tree and AO image (it composites
        # with that AO); any other copy (Shift+D, a scene's Full Copy) gets its own id, inner
        # tree and AO image, or the two would overwrite each other's export and AO.
        if session.current.copying_helper:
            return
        self.ssao_id = inner_tree.new_id()
        self.node_tree = node.node_tree.copy() if node.node_tree is not None else \
            inner_tree.build(self.ssao_id)
        inner_tree.forget_ao_image(self)
        compute.configure_node(self)

    def free(self):
        if self.node_tree is not None and self.node_tree.users <= 1:
            bpy.data.node_groups.remove(self.node_tree)

    def shown_parameters(self):
        """The library parameters the node shows, in the table's order: those its variant
        reads (the library lists them, ssao_variant_info) and those every variant reads."""
        if session.current.library_error:
            return []
        table = compute.library_table()
        variant_specific = set().union(*table.variant_parameters.values())
        active = table.variant_parameters.get(getattr(self, "variant", ""), variant_specific)
        return [name for name in table.node_parameter_names
                if name in self.bl_rna.properties and
                (name not in variant_specific or name in active)]

    def _draw_problems(self, context, layout):
        if session.current.library_error:
            layout.label(text="libssao missing (see console)", icon='ERROR')
        problem = context.scene and compat.compositor_cannot_export(context.scene)
        if problem:
            layout.label(text="GPU compositor: set the compositor device to CPU", icon='ERROR')

    def _draw_recompute_and_status(self, layout):
        layout.operator("ssao.recompute", icon='FILE_REFRESH')
        if self.status:
            layout.label(text=self.status, icon='ERROR' if self.status.startswith("Error")
                         else 'INFO')

    def draw_buttons(self, context, layout):
        """The node's face: radius, strength, quality, the add-on's settings, the status."""
        self._draw_problems(context, layout)
        shown = self.shown_parameters()
        for name in FACE_PARAMETERS:
            if name in shown:
                _draw_property(self, layout, name)
        self._draw_settings(layout)
        self._draw_recompute_and_status(layout)

    def _draw_settings(self, layout, stacked=False):
        for name in compute.NODE_SETTINGS:
            row = layout.row()
            row.active = name != "overscan" or self.overscan_mode == 'PIXELS'
            _draw_property(self, row, name, stacked)

    def draw_buttons_ext(self, context, layout):
        """The sidebar (N panel, Node tab, Properties): every property, a box per library
        group, then the add-on's settings."""
        self._draw_problems(context, layout)
        shown = self.shown_parameters()
        groups = list(compute.NODE_GROUPS)
        table = compute.library_table().parameters if shown else {}
        group_of = {name: table[name]["group"] for name in shown}
        groups += sorted(set(group_of.values()) - set(groups))
        for group in groups:  # a group the add-on does not know yet comes after its own
            names = [name for name in shown if group_of[name] == group]
            if names:
                box = layout.box()
                box.label(text=GROUP_TITLES.get(group, group.capitalize() or "Other"))
                column = box.column()
                for name in names:
                    _draw_property(self, column, name, stacked=True)
        box = layout.box()
        box.label(text=SETTINGS_TITLE)
        self._draw_settings(box.column(), stacked=True)
        self._draw_recompute_and_status(layout)


def _draw_add_menu(self, context):
    space = context.space_data
    if getattr(space, "tree_type", None) != "CompositorNodeTree":
        return
    item = self.layout.operator("node.add_node", text=CompositorNodeSSAO.bl_label)
    item.type = CompositorNodeSSAO.bl_idname
    item.use_transform = True


def register():
    table = _parameter_table()
    for name, desc in table.items():
        CompositorNodeSSAO.__annotations__[name] = _property_for(desc)
    bpy.utils.register_class(CompositorNodeSSAO)
    menu = compat.filter_menu()
    if menu is not None:
        menu.append(_draw_add_menu)
    else:
        print("ssao_compositor: warning: no compositor Filter menu found; add the node from "
              "Python: tree.nodes.new('CompositorNodeSSAO')")
    if session.current.library_error:
        print(f"ssao_compositor: error: {session.current.library_error}")


def _drop_evaluated_nodes():
    """Every view layer's evaluated copy (its depsgraph's) of the scene brought up to date
    before the node type goes: it still holds the SSAO nodes that unregister made group nodes
    (handlers.py), and freeing one after the type is unregistered crashed Blender when it quit
    (3.4.1: every time after the add-on was disabled with a file's nodes; 4.3.2: 7 of 121)."""
    for scene in bpy.data.scenes:
        for view_layer in scene.view_layers:
            depsgraph = view_layer.depsgraph
            if depsgraph is not None:
                depsgraph.update()


def unregister():
    try:
        _drop_evaluated_nodes()
    except Exception as error:  # the type must go all the same
        compute.report(f"updating the evaluated scenes failed: {error}", error=True)
    menu = compat.filter_menu()
    if menu is not None:
        menu.remove(_draw_add_menu)
    bpy.utils.unregister_class(CompositorNodeSSAO)
