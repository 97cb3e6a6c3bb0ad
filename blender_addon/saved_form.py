# SPDX-License-Identifier: MIT
"""How a .blend file carries the node: as a built-in group node (CompositorNodeGroup) using the
node's inner tree, its settings kept in an ID property. A Blender without the add-on then
composites with the last AO: Blender 5.x gives an undefined (unregistered) node's outputs no
value at all (measured in 5.2.2: a black composite), where 3.4 and 4.3 still ran its inner
tree. The add-on turns the group nodes back into SSAO nodes when a file loads or when it is
enabled, and turns its nodes into group nodes just before saving and back just after."""
import bpy

from . import compute, inner_tree

SETTINGS_KEY = "ssao_compositor"  # the ID property on the group node
_restoring = False                # no recompute while settings are put back


def is_restoring():
    return _restoring


def _replace(old, idname):
    """A node of type `idname` in old's place: same name, look, links; old is removed."""
    tree = old.id_data
    new = tree.nodes.new(idname)
    for attribute in ("label", "location", "width", "mute", "hide", "parent", "select"):
        setattr(new, attribute, getattr(old, attribute))
    if tree.nodes.active == old:
        tree.nodes.active = new
    return tree, new


def _relink(tree, old, new):
    for sockets_old, sockets_new in ((old.inputs, new.inputs), (old.outputs, new.outputs)):
        for socket_old, socket_new in zip(sockets_old, sockets_new):
            if socket_old.is_output:
                for link in list(socket_old.links):
                    tree.links.new(socket_new, link.to_socket)
            else:
                for link in list(socket_old.links):
                    tree.links.new(link.from_socket, socket_new)
            if hasattr(socket_old, "default_value") and hasattr(socket_new, "default_value"):
                try:
                    socket_new.default_value = socket_old.default_value
                except (TypeError, ValueError, AttributeError):
                    pass


def to_group_node(node):
    """The SSAO node `node`, replaced by a built-in group node on the same inner tree."""
    tree, group = _replace(node, "CompositorNodeGroup")
    group.node_tree = node.node_tree
    settings = {"ssao_id": node.ssao_id}
    settings.update(compute.node_parameters(node))
    group[SETTINGS_KEY] = settings
    _relink(tree, node, group)
    name = node.name
    tree.nodes.remove(node)
    group.name = name
    return group


def from_group_node(group):
    """The group node `group` (made by to_group_node), replaced by an SSAO node again."""
    global _restoring
    settings = dict(group[SETTINGS_KEY])
    inner = group.node_tree
    tree, node = _replace(group, inner_tree.NODE_IDNAME)
    fresh = node.node_tree  # init() made a new inner tree: use the saved one instead
    node.node_tree = inner
    if fresh is not None and fresh != inner and fresh.users == 0:
        bpy.data.node_groups.remove(fresh)
    _restoring = True
    try:
        node.ssao_id = settings.pop("ssao_id", node.ssao_id)
        for name, value in settings.items():
            try:
                setattr(node, name, value)
            except (AttributeError, TypeError, ValueError):
                pass  # a setting this version of the add-on does not have
    finally:
        _restoring = False
    _relink(tree, group, node)
    name = group.name
    tree.nodes.remove(group)
    node.name = name
    compute.configure_node(node)
    return node


def _trees():
    from . import compat
    seen = set()
    for scene in bpy.data.scenes:
        tree = compat.compositor_tree(scene)
        if tree is not None and tree.as_pointer() not in seen:
            seen.add(tree.as_pointer())
            yield tree


def to_group_nodes():
    for tree in _trees():
        for node in [n for n in tree.nodes if n.bl_idname == inner_tree.NODE_IDNAME]:
            to_group_node(node)


def from_group_nodes():
    """Every group node that was an SSAO node becomes one again; returns how many."""
    count = 0
    for tree in _trees():
        for group in [n for n in tree.nodes
                      if n.bl_idname == "CompositorNodeGroup" and SETTINGS_KEY in n.keys()]:
            from_group_node(group)
            count += 1
    return count
