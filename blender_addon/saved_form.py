# SPDX-License-Identifier: MIT
"""How a .blend file carries the node: as a built-in group node (CompositorNodeGroup) using the
node's inner tree, its settings kept in an ID property. A Blender without the add-on then
composites with the last AO: Blender 5.x gives an undefined (unregistered) node's outputs no
value at all (measured in 5.2.2: a black composite), where 3.4 and 4.3 still ran its inner
tree. The add-on turns the group nodes back into SSAO nodes when a file loads or when it is
enabled, and turns its nodes into group nodes just before saving and back just after."""
import bpy

from . import compute, inner_tree, session

SETTINGS_KEY = "ssao_compositor"  # the ID property on the group node
# On an SSAO node: settings this add-on could not apply (a setting it does not have, or all of
# them while libssao is missing), kept for the next save.
UNAPPLIED_KEY = "ssao_compositor_unapplied"


def _replace(old, idname):
    """A new node of type `idname` beside `old`, with its look (label, frame, place, width,
    colour, state); the caller relinks, removes `old` and takes its name."""
    tree = old.id_data
    new = tree.nodes.new(idname)
    # The frame first: a node's location is relative to its frame.
    for attribute in ("parent", "label", "location", "width", "mute", "hide", "select",
                      "use_custom_color", "color"):
        setattr(new, attribute, getattr(old, attribute))
    if tree.nodes.active == old:
        tree.nodes.active = new
    return tree, new


def _relink(tree, old, new):
    for sockets_old, sockets_new in ((old.inputs, new.inputs), (old.outputs, new.outputs)):
        for socket_old, socket_new in zip(sockets_old, sockets_new):
            for link in list(socket_old.links):
                if socket_old.is_output:
                    new_link = tree.links.new(socket_new, link.to_socket)
                else:
                    new_link = tree.links.new(link.from_socket, socket_new)
                if hasattr(link, "is_muted"):
                    new_link.is_muted = link.is_muted
            socket_new.hide = socket_old.hide
            if hasattr(socket_old, "default_value") and hasattr(socket_new, "default_value"):
                try:
                    socket_new.default_value = socket_old.default_value
                except (TypeError, ValueError, AttributeError):
                    pass


def to_group_node(node):
    """The SSAO node `node`, replaced by a built-in group node on the same inner tree."""
    tree, group = _replace(node, "CompositorNodeGroup")
    group.node_tree = node.node_tree
    settings = dict(node.get(UNAPPLIED_KEY, {}))
    settings["ssao_id"] = node.ssao_id
    settings.update(compute.node_parameters(node))
    settings.update(compute.node_settings(node))
    group[SETTINGS_KEY] = settings
    _relink(tree, node, group)
    name = node.name
    tree.nodes.remove(node)
    group.name = name
    return group


def from_group_node(group):
    """The group node `group` (made by to_group_node), replaced by an SSAO node again."""
    settings = dict(group[SETTINGS_KEY])
    inner = group.node_tree
    tree, node = _replace(group, inner_tree.NODE_IDNAME)
    # init() made a new inner tree and AO image: use the saved ones instead.
    fresh_tree, fresh_image = node.node_tree, inner_tree.ao_image_if_any(node)
    node.node_tree = inner
    if fresh_tree is not None and fresh_tree != inner and fresh_tree.users == 0:
        bpy.data.node_groups.remove(fresh_tree)
    if fresh_image is not None and fresh_image.users == 0:
        bpy.data.images.remove(fresh_image)
    unapplied = {}
    with session.current.doing("restoring_settings"):  # no recompute per setting
        node.ssao_id = settings.pop("ssao_id", node.ssao_id)
        for name, value in settings.items():
            try:
                setattr(node, name, value)
            except (AttributeError, TypeError, ValueError):
                unapplied[name] = value
    if unapplied:
        node[UNAPPLIED_KEY] = unapplied
    _relink(tree, group, node)
    name = group.name
    tree.nodes.remove(group)
    node.name = name
    compute.configure_node(node)
    return node


def _convert(kind, idname, convert, condition=lambda node: True):
    """convert(node) on every node of type `idname` of every compositing tree; returns how
    many were converted (one node's failure is reported, the others go on)."""
    count = 0
    for scene, tree in list(compute.compositor_trees()):
        if tree.library is not None:
            continue  # a linked tree is not ours to change
        for node in [n for n in tree.nodes if n.bl_idname == idname and condition(n)]:
            try:
                convert(node)
                count += 1
            except Exception as error:
                compute.report(f"node '{node.name}' of scene '{scene.name}': turning it into "
                               f"{kind} failed: {error}", error=True)
    return count


def to_group_nodes():
    return _convert("a group node", inner_tree.NODE_IDNAME, to_group_node,
                    lambda node: node.node_tree is not None)


def from_group_nodes():
    """Every group node that was an SSAO node becomes one again; returns how many."""
    return _convert("an SSAO node", "CompositorNodeGroup", from_group_node,
                    lambda node: SETTINGS_KEY in node.keys() and node.node_tree is not None)
