# SPDX-License-Identifier: MIT
"""Computing the AO: the node's exported passes in, libssao, the node's AO image out."""
import os
import tempfile
import time

import bpy
import numpy as np

from . import camera as camera_module
from . import compat, inner_tree, ssao_native

# Where exporters write (per process; $SSAO_COMPOSITOR_EXPORT_DIR or the add-on's preference
# override it, e.g. to keep the passes for the command-line tool). Saved files carry
# SAVED_EXPORT_DIR instead, a folder that exists for any session on the machine, with or
# without the add-on.
SAVED_EXPORT_DIR = os.path.join(tempfile.gettempdir(), "ssao_compositor")
PROCESS_EXPORT_DIR = os.path.join(tempfile.gettempdir(), f"ssao_compositor_{os.getpid()}")
# EEVEE writes its Depth pass as half floats with 65504 (the largest half) on the background
# in 3.x; 4.x writes the clip end and 5.x 1e10, which the camera's clip_end covers, so setting
# 65504 for every EEVEE render is harmless there.
EEVEE_BACKGROUND_DEPTH = 65504.0

# The library parameters the node exposes, by their library names (the rest are set here:
# camera, conventions, threads).
NODE_PARAMETERS = ("variant", "radius", "quality", "resolution", "samples", "slices", "steps",
                   "bias", "thickness", "sample_clustering", "sphere_mode", "denoise", "strength",
                   "power", "remap_min", "remap_max", "seed")

HELPER_SCENE_PREFIX = ".SSAO recomposite "  # recomposite.py's hidden scenes

_library = None
preferred_export_dir = ""  # set by preferences.py


def library():
    """The bundled libssao (lib/ beside this file), loaded once."""
    global _library
    if _library is None:
        _library = ssao_native.load_library()
    return _library


def report(message, error=False):
    print(f"ssao_compositor: {'error: ' if error else ''}{message}", flush=True)


def export_dir():
    return (os.environ.get("SSAO_COMPOSITOR_EXPORT_DIR") or preferred_export_dir
            or PROCESS_EXPORT_DIR)


def ssao_nodes(scene):
    """The scene's active (unmuted) SSAO nodes."""
    tree = compat.compositor_tree(scene)
    if tree is None:
        return []
    return [n for n in tree.nodes if n.bl_idname == inner_tree.NODE_IDNAME and not n.mute]


def compositor_trees():
    """(scene, tree) for each compositing tree once (by pointer: before 5.0 every scene's tree
    has the same name), helper scenes left out."""
    seen = set()
    for scene in bpy.data.scenes:
        tree = compat.compositor_tree(scene, in_use_only=False)
        if tree is None or tree.as_pointer() in seen or \
                scene.name.startswith(HELPER_SCENE_PREFIX):
            continue
        seen.add(tree.as_pointer())
        yield scene, tree


def all_ssao_nodes():
    """(scene, node) for every SSAO node of every scene, muted ones too."""
    for scene, tree in list(compositor_trees()):
        for node in [n for n in tree.nodes if n.bl_idname == inner_tree.NODE_IDNAME]:
            yield scene, node


def scene_of_tree(tree):
    return next((scene for scene, t in compositor_trees() if t == tree), None)


def configure_node(node, folder=None):
    """Points the node's exporter at this session's export folder (paths saved in a .blend
    belong to the session that saved it) and makes sure it has an AO image of the render's
    size."""
    scene = node.id_data and scene_of_tree(node.id_data)
    size = camera_module.render_size(scene) if scene is not None else None
    inner_tree.configure(node, folder or export_dir(), size)


def read_export(path):
    """The exported passes as a bottom-up (height, width, 4) float32 array."""
    image = bpy.data.images.load(path, check_existing=False)
    try:
        image.colorspace_settings.name = 'Non-Color'
        width, height = image.size
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def node_parameters(node):
    return {name: getattr(node, name) for name in NODE_PARAMETERS if hasattr(node, name)}


def threads(scene):
    """The render's thread count when it is fixed (Render Properties > Performance), else 0:
    every core."""
    render = scene.render
    return render.threads if render.threads_mode == 'FIXED' else 0


def compute_node(node, scene, passes):
    """AO of `node` from exported `passes` (bottom-up RGBA: normal xyz, depth); fills the node's
    AO image and returns the AO with row 0 on top."""
    if not node.inputs["Depth"].is_linked:
        raise RuntimeError("the Depth input is not linked (connect the Render Layers' Depth)")
    height, width = passes.shape[:2]
    rgba = np.empty((height, width, 4), np.float32)
    with ssao_native.Job(library()) as job:
        for name, value in camera_module.camera_params(scene).items():
            job.set(name, value)
        if compat.is_eevee(scene):
            job.set("background_depth", EEVEE_BACKGROUND_DEPTH)
        job.set("threads", threads(scene))
        for name, value in node_parameters(node).items():
            job.set(name, value)
        # Blender's rows run bottom-up: flipped views read and write in place.
        job.set_image("depth", passes[::-1, :, 3])
        if node.inputs["Normal"].is_linked:
            job.set_image("normal", passes[::-1, :, 0:3])
        job.set_image("ao", rgba[::-1])
        job.run()
    image = inner_tree.ao_image(node, width, height)
    image.pixels.foreach_set(rgba.ravel())
    image.update()
    # 5.x's GPU compositor keeps its own copy of the image: tag it, or the UI compositor
    # re-composites with the old AO (measured in 5.2.2).
    image.update_tag()
    return np.ascontiguousarray(rgba[::-1, :, 0])


def compute_frame(scene, frame, since=0.0):
    """Computes every SSAO node of `scene` from its export of `frame` written since `since` (a
    time.time(); a render that started before the add-on turned a saved file's group nodes
    back into SSAO nodes exports where the file was saved). Returns {node name: AO}; errors
    are reported on the node and in the console."""
    done = {}
    for node in ssao_nodes(scene):
        # A render of this session may have exported where a saved file points (see above).
        path = inner_tree.export_path(node, frame, (SAVED_EXPORT_DIR,) if since else (), since)
        try:
            if path is None:
                raise RuntimeError(compat.compositor_cannot_export(scene) or
                                   f"no exported passes for frame {frame} (is the node's output "
                                   "connected to the compositor's output?)")
            start = time.perf_counter()
            ao = compute_node(node, scene, read_export(path))
            seconds = time.perf_counter() - start
            node.status = f"Frame {frame}: {ao.shape[1]}x{ao.shape[0]} in {seconds * 1e3:.0f} ms"
            report(f"{scene.name} frame {frame} node '{node.name}': {node.status}, "
                   f"mean AO {float(ao.mean()):.4f}")
            done[node.name] = ao
        except Exception as error:
            node.status = f"Error: {error}"
            report(f"{scene.name} frame {frame} node '{node.name}': {error}", error=True)
    return done


def compute_ao(scene=None, node=None, render=True):
    """Scripting entry point: the AO of `scene`'s SSAO node (the first, unless `node` is given)
    as a float32 numpy array (height, width), row 0 on top. With render=True (default) the scene
    is rendered first (which also applies the AO to the composite); with render=False the AO is
    recomputed from the passes exported by the last render of the current frame."""
    scene = scene or bpy.context.scene
    nodes = [node] if node is not None else ssao_nodes(scene)
    if not nodes:
        raise RuntimeError(f"scene '{scene.name}' has no Ambient Occlusion (SSAO) node in its "
                           "compositor (or compositing is off)")
    node = nodes[0]
    if render:
        bpy.ops.render.render(scene=scene.name)
    path = inner_tree.export_path(node, scene.frame_current)
    if path is None:
        raise RuntimeError(f"no exported passes for frame {scene.frame_current}: render first")
    return compute_node(node, scene, read_export(path))
