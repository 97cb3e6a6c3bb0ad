# SPDX-License-Identifier: MIT
"""Getting the passes out, computing AO, and getting it back into the compositor.

During a render the node's inner File Output ("exporter") writes the Depth and Normal it is fed
(normal in R, G, B, depth in A; a lossless 32-bit EXR) to a per-process folder. After the render:
  - headless (blender -b ... -f/-a, or a script): render_post reads the export, computes AO with
    libssao, fills the node's AO image, saves the Render Result's passes and re-runs only the
    compositor (a hidden helper scene whose Render Layers nodes read those passes; no 3D render),
    and render_write writes that result over the frame's output file;
  - in the UI: render_post only records the frame (it runs in the render thread); a main-thread
    timer computes the AO and nudges the compositor, which re-composites the existing render.
Changing a node property recomputes from the exported passes, without rendering.
(Measured facts behind this design: shared docs/blender-notes.md; ours: docs/blender.md.)
"""
import atexit
import os
import shutil
import tempfile
import time

import bpy
import numpy as np

from . import camera as camera_module
from . import ssao_native

NODE_IDNAME = "CompositorNodeSSAO"
# Where exporters write (per process; $SSAO_COMPOSITOR_EXPORT_DIR overrides it, e.g. to keep
# the passes for the command-line tool). Saved files carry SAVED_EXPORT_DIR instead, a folder
# that exists for any session on the machine, with or without the add-on.
SAVED_EXPORT_DIR = os.path.join(tempfile.gettempdir(), "ssao_compositor")
EXPORT_DIR = os.environ.get("SSAO_COMPOSITOR_EXPORT_DIR") or \
    os.path.join(tempfile.gettempdir(), f"ssao_compositor_{os.getpid()}")
# EEVEE writes its Depth pass as half floats with 65504 (the largest half) on the background.
EEVEE_BACKGROUND_DEPTH = 65504.0

_library = None
_last_ao = {}           # node id -> AO of its last computation, (height, width), row 0 on top
_pending_frames = []    # UI: (scene name, frame) rendered, waiting for the main-thread timer
_recomposited = set()   # (scene name, frame) whose Render Result holds the AO composite
_busy = False           # guard: our own nested renders fire the handlers again


def library():
    """The bundled libssao (lib/ beside this file), loaded once."""
    global _library
    if _library is None:
        _library = ssao_native.load_library()
    return _library


def report(message, error=False):
    print(f"ssao_compositor: {'error: ' if error else ''}{message}", flush=True)


# --- nodes and their inner parts ------------------------------------------------------------

def compositor_tree(scene):
    """The scene's compositing node tree (Blender 5 made it a separate datablock)."""
    tree = getattr(scene, "compositing_node_group", None)
    return tree if tree is not None else getattr(scene, "node_tree", None)


def ssao_nodes(scene):
    tree = compositor_tree(scene)
    if tree is None or not scene.use_nodes:
        return []
    return [n for n in tree.nodes if n.bl_idname == NODE_IDNAME and not n.mute]


def _inner(node, name):
    return node.node_tree.nodes.get(name) if node.node_tree is not None else None


def export_path(node, frame):
    """Where the node's exporter writes `frame`, from its own settings (a file saved by another
    session, or opened before the add-on was enabled, keeps the folder it was saved with)."""
    from .node import EXPORT_NODE
    exporter = _inner(node, EXPORT_NODE)
    if hasattr(exporter, "file_slots"):
        folder, name = exporter.base_path, exporter.file_slots[0].path
    else:  # Blender 5.0+
        folder, name = exporter.directory, exporter.file_name
    return os.path.join(bpy.path.abspath(folder), f"{name}{frame:04d}.exr")


def ao_image(node, width, height):
    """The node's AO image (float, non-colour data), created or resized as needed."""
    from .node import AO_NODE
    holder = _inner(node, AO_NODE)
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


def configure_node(node):
    """Points the node's exporter at this process's folder (paths saved in a .blend belong to
    the process that saved it) and makes sure it has an AO image."""
    from .node import EXPORT_NODE
    exporter = _inner(node, EXPORT_NODE)
    if exporter is None:
        return
    _point_exporter(exporter, EXPORT_DIR, node.ssao_id)
    settings = exporter.format
    settings.file_format = 'OPEN_EXR'
    settings.color_mode = 'RGBA'
    settings.color_depth = '32'
    settings.exr_codec = 'ZIP'
    exporter.mute = False
    scene = node.id_data and _scene_of_tree(node.id_data)
    if scene is not None:
        ao_image(node, *camera_module.render_size(scene))


def _point_exporter(exporter, folder, ssao_id):
    # No folder is made here: the File Output node makes it when it first writes.
    if hasattr(exporter, "file_slots"):  # Blender 3.x and 4.x
        exporter.base_path = folder + os.sep
        exporter.file_slots[0].path = f"ssao_{ssao_id}_"
    else:  # Blender 5.0 renamed them (not tested here: no 5.x on Debian)
        exporter.directory = folder
        exporter.file_name = f"ssao_{ssao_id}_"


def _point_exporters(folder):
    from .node import EXPORT_NODE
    for _, node in _all_ssao_nodes():
        exporter = _inner(node, EXPORT_NODE)
        if exporter is not None:
            _point_exporter(exporter, folder, node.ssao_id)


def forget_node(node):
    _last_ao.pop(node.ssao_id, None)


def _scene_of_tree(tree):
    for scene in bpy.data.scenes:
        if compositor_tree(scene) == tree:
            return scene
    return None


def _all_ssao_nodes():
    for scene in bpy.data.scenes:
        tree = compositor_tree(scene)
        if tree is not None:
            for node in tree.nodes:
                if node.bl_idname == NODE_IDNAME:
                    yield scene, node


def _set_exporters_muted(muted):
    from .node import EXPORT_NODE
    for _, node in _all_ssao_nodes():
        exporter = _inner(node, EXPORT_NODE)
        if exporter is not None:
            exporter.mute = muted


# --- computing ------------------------------------------------------------------------------

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
    from .node import NODE_PARAMETERS
    return {name: getattr(node, name) for name in NODE_PARAMETERS if hasattr(node, name)}


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
        if scene.render.engine.startswith("BLENDER_EEVEE"):
            job.set("background_depth", EEVEE_BACKGROUND_DEPTH)
        for name, value in node_parameters(node).items():
            job.set(name, value)
        # Blender's rows run bottom-up: flipped views read and write in place.
        job.set_image("depth", passes[::-1, :, 3])
        if node.inputs["Normal"].is_linked:
            job.set_image("normal", passes[::-1, :, 0:3])
        job.set_image("ao", rgba[::-1])
        job.run()
    image = ao_image(node, width, height)
    image.pixels.foreach_set(rgba.ravel())
    image.update()
    ao = np.ascontiguousarray(rgba[::-1, :, 0])
    _last_ao[node.ssao_id] = ao
    return ao


def compute_frame(scene, frame):
    """Computes every SSAO node of `scene` from its export of `frame`. Returns how many nodes
    got a new AO; errors are reported on the node and in the console."""
    done = 0
    for node in ssao_nodes(scene):
        path = export_path(node, frame)
        try:
            if not os.path.exists(path):
                raise RuntimeError(f"no exported passes for frame {frame} (is the node's output "
                                   "connected to the Composite node?)")
            start = time.perf_counter()
            ao = compute_node(node, scene, read_export(path))
            seconds = time.perf_counter() - start
            node.status = f"Frame {frame}: {ao.shape[1]}x{ao.shape[0]} in {seconds * 1e3:.0f} ms"
            report(f"{scene.name} frame {frame} node '{node.name}': {node.status}, "
                   f"mean AO {float(ao.mean()):.4f}")
            done += 1
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
    path = export_path(node, scene.frame_current)
    if not os.path.exists(path):
        raise RuntimeError(f"no exported passes for frame {scene.frame_current}: render first")
    return compute_node(node, scene, read_export(path))


def parameter_changed(node, scene):
    """A node property changed: recompute from the last export, then re-composite (UI)."""
    if _busy or bpy.app.background or scene is None:
        return
    path = export_path(node, scene.frame_current)
    if not os.path.exists(path):
        node.status = "Render (F12) to compute the AO"
        return
    try:
        compute_node(node, scene, read_export(path))
        node.status = f"Frame {scene.frame_current}: recomputed"
        nudge_compositor(node)
    except Exception as error:
        node.status = f"Error: {error}"
        report(str(error), error=True)


# --- re-compositing -------------------------------------------------------------------------

def nudge_compositor(node):
    """Changing a built-in node's value makes the UI compositor run again on the existing render
    (Python properties and update_tag() do not)."""
    from .node import MULTIPLY_NODE
    multiply = _inner(node, MULTIPLY_NODE)
    if multiply is not None:
        fac = multiply.inputs[0]
        fac.default_value = 0.999
        fac.default_value = 1.0


def _helper_scene(scene):
    """A hidden copy of `scene` whose Render Layers nodes read the saved passes instead: rendering
    it runs only the compositor. Kept and reused (removing a scene in a render handler crashes)."""
    name = f".SSAO recomposite {scene.name}"
    helper = bpy.data.scenes.get(name)
    if helper is None:
        helper = scene.copy()
        helper.name = name
        helper.use_fake_user = False
    helper.frame_current = scene.frame_current
    # Output and colour settings follow the source scene's current ones.
    for attribute in ("file_format", "color_mode", "color_depth", "exr_codec", "compression",
                      "quality", "use_preview"):
        if hasattr(scene.render.image_settings, attribute):
            setattr(helper.render.image_settings, attribute,
                    getattr(scene.render.image_settings, attribute))
    for attribute in ("view_transform", "look", "exposure", "gamma"):
        setattr(helper.view_settings, attribute, getattr(scene.view_settings, attribute))
    helper.display_settings.display_device = scene.display_settings.display_device
    return helper


def _read_passes_from(helper, passes_path, source_scene):
    """Replaces the helper's Render Layers nodes by Image nodes reading `passes_path`
    (a multilayer EXR of the source render), relinking every output by name."""
    tree = compositor_tree(helper)
    image = bpy.data.images.get(".SSAO passes " + source_scene.name)
    if image is None or image.filepath != passes_path:
        image = bpy.data.images.load(passes_path, check_existing=False)
        image.name = ".SSAO passes " + source_scene.name
    else:
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


def save_passes(scene, path):
    """Writes every pass of `scene`'s Render Result (and its Composite) to a 32-bit multilayer
    EXR. save_render takes the render of the scene it is given, with that scene's output
    settings: switch them briefly."""
    result = bpy.data.images.get("Render Result")
    if result is None:
        raise RuntimeError("no Render Result")
    settings = scene.render.image_settings
    saved = (settings.file_format, settings.color_depth, settings.exr_codec)
    try:
        settings.file_format = 'OPEN_EXR_MULTILAYER'
        settings.color_depth = '32'
        settings.exr_codec = 'ZIP'
        result.save_render(path, scene=scene)
    finally:
        settings.file_format, settings.color_depth, settings.exr_codec = saved


def recomposite(scene):
    """Re-runs only the compositor of `scene` on its last render (headless)."""
    global _busy
    helper = _helper_scene(scene)
    os.makedirs(EXPORT_DIR, exist_ok=True)
    passes_path = os.path.join(EXPORT_DIR, f"passes_{abs(hash(scene.name))}.exr")
    save_passes(scene, passes_path)
    _read_passes_from(helper, passes_path, scene)
    _busy = True
    _set_exporters_muted(True)
    try:
        bpy.ops.render.render(scene=helper.name, write_still=False)
    finally:
        _set_exporters_muted(False)
        _busy = False


# --- handlers -------------------------------------------------------------------------------

@bpy.app.handlers.persistent
def _on_render_post(scene, *_):
    if _busy or not ssao_nodes(scene):
        return
    if not bpy.app.background:
        _pending_frames.append((scene.name, scene.frame_current))
        if not bpy.app.timers.is_registered(_process_pending):
            bpy.app.timers.register(_process_pending, first_interval=0.1)
        return
    if compute_frame(scene, scene.frame_current) == 0:
        return
    try:
        if scene.render.image_settings.file_format == 'OPEN_EXR_MULTILAYER':
            report("the output format is OpenEXR MultiLayer: its Composite layer keeps the "
                   "render without AO; use a single-layer format or a File Output node",
                   error=True)
            return
        recomposite(scene)
        _recomposited.add((scene.name, scene.frame_current))
    except Exception as error:
        report(f"re-compositing frame {scene.frame_current} failed: {error}", error=True)


@bpy.app.handlers.persistent
def _on_render_write(scene, *_):
    """The frame file was written before the AO existed: write the re-composited result."""
    key = (scene.name, scene.frame_current)
    if _busy or key not in _recomposited:
        return
    _recomposited.discard(key)
    path = _written_output(scene)
    if path is None:
        report("cannot find the file this render wrote; it keeps the composite without AO",
               error=True)
        return
    # Each scene has its own render result: the re-composited one is the helper's.
    helper = _helper_scene(scene)
    bpy.data.images["Render Result"].save_render(path, scene=helper)
    report(f"wrote {path} with AO")


def _written_output(scene):
    """The file Blender just wrote for this frame: the frame path (-f, -a) or, for a still
    written from a script (render(write_still=True)), the output path without frame number."""
    render = scene.render
    still = bpy.path.abspath(render.filepath)
    if render.use_file_extension and not still.lower().endswith(render.file_extension.lower()):
        still += render.file_extension
    candidates = [p for p in (render.frame_path(frame=scene.frame_current), still)
                  if os.path.isfile(p)]
    return max(candidates, key=os.path.getmtime) if candidates else None


def _process_pending():
    """UI: main-thread work after a render (handlers run in the render thread there)."""
    if bpy.app.is_job_running('RENDER'):
        return 0.2
    while _pending_frames:
        scene_name, frame = _pending_frames.pop(0)
        scene = bpy.data.scenes.get(scene_name)
        if scene is not None and compute_frame(scene, frame) > 0:
            for node in ssao_nodes(scene):
                nudge_compositor(node)
            if not _compositor_editor_open():
                message = ("AO computed; open a compositor Node Editor (and an Image Editor "
                           "showing Render Result) to see it applied")
                for node in ssao_nodes(scene):
                    node.status = message
                report(message)
    return None


def _compositor_editor_open():
    """Blender 3.4 re-composites only from a visible compositor Node Editor."""
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            for space in area.spaces:
                if space.type == 'NODE_EDITOR' and space.tree_type == "CompositorNodeTree":
                    return True
    return False


@bpy.app.handlers.persistent
def _on_load_post(*_):
    for _, node in _all_ssao_nodes():
        configure_node(node)


@bpy.app.handlers.persistent
def _on_save_pre(*_):
    # The AO must travel inside the .blend; exporters point at a folder every session has, so
    # that a file opened without the add-on (or before it is enabled) writes somewhere harmless
    # and, with the add-on, where it will look.
    from .node import AO_NODE
    # The re-compositing helpers are rebuilt when needed: keep them out of the user's file.
    for helper in [s for s in bpy.data.scenes if s.name.startswith(".SSAO recomposite ")]:
        bpy.data.scenes.remove(helper)
    for image in [i for i in bpy.data.images if i.name.startswith(".SSAO passes ")]:
        bpy.data.images.remove(image)
    images = {_inner(node, AO_NODE).image for _, node in _all_ssao_nodes()}
    for image in images:
        # Pack what is in memory; packing an unchanged packed image again would re-read a file
        # that does not exist and drop the pixels.
        if image is not None and image.has_data and (image.is_dirty or not image.packed_file):
            image.pack()
    _point_exporters(SAVED_EXPORT_DIR)


@bpy.app.handlers.persistent
def _on_save_post(*_):
    _point_exporters(EXPORT_DIR)


_HANDLERS = (("render_post", _on_render_post), ("render_write", _on_render_write),
             ("load_post", _on_load_post), ("save_pre", _on_save_pre),
             ("save_post", _on_save_post))


def register():
    for name, handler in _HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)
    if not os.environ.get("SSAO_COMPOSITOR_EXPORT_DIR"):
        # This session's exports are of no use to any other: remove them when Blender quits.
        atexit.register(shutil.rmtree, EXPORT_DIR, ignore_errors=True)
    # Nodes of a file that is already open (enabling the add-on after loading).
    try:
        for _, node in _all_ssao_nodes():
            configure_node(node)
    except AttributeError:  # bpy.data is restricted while add-ons register at start-up
        pass


def unregister():
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
