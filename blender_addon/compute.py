# SPDX-License-Identifier: MIT
"""Computing the AO: the node's exported passes in, libssao, the node's AO image out."""
import functools
import json
import math
import os
import secrets
import tempfile
import time
import types

import bpy
import numpy as np

from . import camera as camera_module
from . import compat, helper_process, hidden_surfaces, inner_tree, session, ssao

# Where exporters write (per process; $SSAO_COMPOSITOR_EXPORT_DIR or the add-on's preference
# override it, e.g. to keep the passes for the command-line tool). Saved files carry
# SAVED_EXPORT_DIR instead, a folder that exists for any session on the machine, with or
# without the add-on. The process id alone does not name a session: Blender processes in
# containers sharing one $TMPDIR (a farm's scratch) can have the same one, and this folder's
# files are removed (earlier frames, and all of it when Blender quits); hence the random part.
SAVED_EXPORT_DIR = os.path.join(tempfile.gettempdir(), "ssao_compositor")
PROCESS_EXPORT_DIR = os.path.join(tempfile.gettempdir(),
                                  f"ssao_compositor_{os.getpid()}_{secrets.token_hex(8)}")
# EEVEE writes its Depth pass as half floats with 65504 (the largest half) on the background
# in 3.x; 4.x writes the clip end and 5.x 1e10, which the camera's clip_end covers, so setting
# 65504 for every EEVEE render is harmless there.
EEVEE_BACKGROUND_DEPTH = 65504.0

# The library parameters the node exposes, by their library names (the rest are set here:
# camera, conventions, threads).
# The library's parameter groups (ssao_param_group) the node shows: every parameter that
# changes the look. The input, camera and execution groups the add-on sets itself.
NODE_GROUPS = ("ao", "quality", "shaping")
# Beyond those groups: of the execution group, the temporal filter's length, how many frames
# of an animation render the AO averages (Sequences below; 1: each frame alone); of the input
# group, whether the Image's colours place the edges (off for an Image blurred before the node).
NODE_EXTRA_PARAMETERS = ("temporal_frames", "edge_coverage")


@functools.lru_cache(maxsize=1)
def library_table():
    """libssao's parameter and variant tables as the add-on uses them, read once (raises when
    the library cannot be loaded; a later call tries again):
      parameters: {name: description (ssao.parameters)}, in the library's order;
      node_parameter_names: the names the node shows (NODE_GROUPS and
        NODE_EXTRA_PARAMETERS), in the library's order;
      variant_parameters: {variant: the names only that variant reads}."""
    lib = library()
    parameters = {p["name"]: p for p in ssao.parameters(lib)}
    return types.SimpleNamespace(
        parameters=parameters,
        node_parameter_names=tuple(name for name, p in parameters.items()
                                   if p["group"] in NODE_GROUPS or
                                   name in NODE_EXTRA_PARAMETERS),
        variant_parameters={v["name"]: set(v["parameters"]) for v in ssao.variants(lib)})


def node_parameter_names():
    """The names of the library's parameters the node shows, in the table's order; none
    without the library (the node shows its error, a .blend still saves)."""
    try:
        return library_table().node_parameter_names
    except Exception:
        return ()

# The node's own settings (not library parameters): what the add-on renders for the library
# beyond the user's passes (hidden_surfaces.py). Saved with the node's parameters.
NODE_SETTINGS = ("hidden_surfaces", "overscan_mode", "overscan")
# The guard band that follows the radius (overscan_mode 'RADIUS'): this fraction of the radius's
# reach in pixels beyond the frame's edges, in whole multiples of 8, at most MAX_BAND. Measured
# on the test scene (docs/blender.md): at 640x360 a band of 0.54 of the reach got all of the
# gain of a wider one, at 3840x2160 0.36 of it 94.5 %.
BAND_OF_REACH = 0.5
MAX_BAND = 1024
# Relative depth difference within which the helper's surface and the user's are one (measured:
# 1.2e-6 between Cycles' Depth pass and the helper's; docs/blender.md).
SAME_SURFACE = 1e-4
# hidden_surfaces -> surface hits per pixel the helper render records.
HITS = {'NONE': 1, 'PEELED': hidden_surfaces.MAX_HITS}

HELPER_SCENE_PREFIX = ".SSAO recomposite "  # recomposite.py's hidden scenes

# A linked Normal input is refused when fewer than this fraction of the pixels where the depth
# describes a smooth surface have a plausible normal there: of length above 0 and at most 1 (a
# pass averages unit normals) and on the camera's side of that surface. Measured on the test
# scene in Blender 3.4, 4.3 and 5.2: the Render Layers' Normal pass (Cycles, EEVEE) 99.9 to 100 %,
# also under a sub-pixel bump, which shortens Cycles' averaged normals to 0.6-0.7 and turns
# EEVEE 4.3's up to 90 degrees from the surface (so neither the length nor a tight angle can
# tell); the Image pass linked instead, 43 %.
NORMAL_PLAUSIBLE_MIN = 0.75
NORMAL_CHECK_SAMPLES = 4096  # pixels on a grid: a few ms at any size
NORMAL_CHECK_MIN_PIXELS = 64  # fewer smooth surface pixels than this: nothing to judge by

def library():
    """The bundled libssao (the zip's lib/, beside the ssao module), loaded once."""
    return ssao.library()


def report(message, error=False):
    print(f"ssao_compositor: {'error: ' if error else ''}{message}", flush=True)


def export_dir():
    return (os.environ.get("SSAO_COMPOSITOR_EXPORT_DIR") or session.current.export_dir
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
    if node.is_property_set("overscan") and not node.is_property_set("overscan_mode"):
        # Saved before the band could follow the radius, with a band in pixels: kept.
        node.overscan_mode = 'PIXELS'
    inner_tree.configure(node, folder or export_dir(), size)


def read_export(path):
    """The exported passes as a bottom-up float32 array (height, width, 4): normal xyz, depth;
    (height, width, 8) with the Image's RGBA when it was exported with them (its alpha is the
    composite's coverage on a transparent film, its colours the library's edge_colours;
    inner_tree.py)."""
    passes = _read_rgba(path)
    image_path = inner_tree.image_export_path(path)
    image = _read_rgba(image_path) if image_path is not None else None
    if image is None or image.shape != passes.shape:
        return passes
    return np.concatenate([passes, image], axis=2)


def _read_rgba(path):
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
    return {name: getattr(node, name) for name in node_parameter_names() if hasattr(node, name)}


def node_settings(node):
    return {name: getattr(node, name) for name in NODE_SETTINGS if hasattr(node, name)}


def check_parameters(node):
    """Blender clamps a property set out of its range but keeps NaN (measured in 3.4, 4.3 and
    5.2: radius = inf gives 1e9, -5 gives 1e-6, nan stays nan): say which property it is."""
    for name, value in node_parameters(node).items():
        if isinstance(value, float) and not math.isfinite(value):
            prop = node.bl_rna.properties[name]
            raise RuntimeError(f"the node's property '{name}' is {value}: set a number from "
                               f"{prop.hard_min:g} to {prop.hard_max:g}")


def input_source(node, name):
    """The output socket that feeds the node's input `name`, through reroutes; None when nothing
    does (no link, or a muted one, which passes nothing)."""
    socket = node.inputs[name]
    while True:
        links = [link for link in socket.links if not link.is_muted]
        if not links:
            return None
        source = links[0].from_socket
        if source.node.bl_idname != "NodeReroute":
            return source
        socket = source.node.inputs[0]


def check_inputs(node):
    """Raises when the Depth input is missing or an input is fed by an output the render does
    not make (a Render Layers pass that is off: the compositor then feeds 0, or in 3.4 and 4.3
    runs no export at all). Returns whether the Normal input is fed."""
    depth, normal = input_source(node, "Depth"), input_source(node, "Normal")
    if depth is None:
        raise RuntimeError("the Depth input is not linked (connect the Render Layers' Depth)")
    for name, source, pass_name in (("Depth", depth, "Z"), ("Normal", normal, "Normal")):
        if source is not None and not source.enabled:
            where = f"'{source.name}' of '{source.node.name}'"
            if source.node.bl_idname == "CompositorNodeRLayers":
                raise RuntimeError(f"the {name} input is linked to {where}, a pass this render "
                                   "does not make: turn it on in View Layer Properties > "
                                   f"Passes > Data > {pass_name}")
            raise RuntimeError(f"the {name} input is linked to {where}, which is unavailable "
                               f"(connect the Render Layers' {name})")
    return normal is not None


def check_depth(depth):
    """A Depth input with no positive depth anywhere (0, negative or NaN: an unlinked-like,
    black or broken input) would give an AO of 1 everywhere, silently."""
    if not np.any(depth > 0):  # NaN compares false
        raise RuntimeError("the Depth input carries no depth (every pixel is 0, negative or not "
                           "a number): connect the Render Layers' Depth (View Layer Properties "
                           "> Passes > Data > Z)")


def _smooth(forward, backward):
    """Where the surface continues alike on both sides of a pixel (no depth edge)."""
    a, b = np.linalg.norm(forward, axis=-1), np.linalg.norm(backward, axis=-1)
    return (np.linalg.norm(forward - backward, axis=-1) <= 0.25 * np.maximum(a, b)) & \
        (a > 0) & (b > 0)


def plausible_normals(scene, passes, background):
    """(pixels checked, the fraction of them with a plausible normal: length in (0, 1.01] and on
    the camera's side of the surface the depth describes there), on a grid of pixels where the
    depth describes a smooth surface nearer than `background`. Positions come from Blender's
    own camera frame (view_frame)."""
    height, width = passes.shape[:2]
    left, right, bottom, top, distance, ortho = camera_module.view_frame(scene)
    step = max(1, int(math.ceil(math.sqrt(width * height / NORMAL_CHECK_SAMPLES))))
    ys = np.arange(step, height - step, step)[:, None]
    xs = np.arange(step, width - step, step)[None, :]

    def position(x, y):  # camera space (rows bottom-up, as Blender's passes)
        depth = passes[y, x, 3]
        u = left + (x + 0.5) / width * (right - left)
        v = bottom + (y + 0.5) / height * (top - bottom)
        if not ortho:
            u, v = u * depth / distance, v * depth / distance
        return np.stack(np.broadcast_arrays(u, v, -depth), -1)

    with np.errstate(invalid="ignore", over="ignore"):
        centre = position(xs, ys)
        dx1, dx0 = position(xs + step, ys) - centre, centre - position(xs - step, ys)
        dy1, dy0 = position(xs, ys + step) - centre, centre - position(xs, ys - step)
        depth = passes[ys, xs, 3]
        checked = np.isfinite(depth) & (depth > 0) & (depth < background) & \
            _smooth(dx1, dx0) & _smooth(dy1, dy0)
        surface = np.cross(dx1 + dx0, dy1 + dy0)
        # Its side towards the camera (the normal pass's side).
        towards = np.array([0.0, 0.0, 1.0]) if ortho else -centre
        surface *= np.where(np.sum(surface * towards, -1) < 0, -1.0, 1.0)[..., None]
        normal = passes[ys, xs, 0:3] @ np.array(camera_module.rotation(scene))  # world->camera
        length = np.linalg.norm(normal, axis=-1)
        plausible = checked & (length > 0) & (length <= 1.01) & \
            (np.sum(surface * normal, -1) > 0)
    count = int(checked.sum())
    return count, (float(plausible.sum()) / count if count else 1.0)


def check_normals(scene, passes, background):
    count, fraction = plausible_normals(scene, passes, background)
    if count >= NORMAL_CHECK_MIN_PIXELS and fraction < NORMAL_PLAUSIBLE_MIN:
        raise RuntimeError(
            f"the Normal input does not carry this render's normals: {100 * fraction:.0f}% of "
            f"{count} surface pixels have a normal of length at most 1 on the camera's side of "
            "the surface the Depth describes (a Normal pass: 99% or more). Connect the Render "
            "Layers' Normal (View Layer Properties > Passes > Data > Normal), or unlink Normal "
            "to rebuild the normals from the depth")


def library_default(name):
    """A float parameter's default, from the library's table (never repeated here)."""
    return library_table().parameters[name]["default"]


def without_ao(node, scene):
    """A node whose AO could not be computed passes its Image through (AO 1) rather than keep
    the AO of another frame or of earlier settings."""
    try:
        inner_tree.blank_ao(node, *camera_module.render_size(scene))
    except Exception as error:
        report(f"node '{node.name}': resetting its AO to 1 failed: {error}", error=True)


class Sequences:
    """The frames of one animation render, computed in frame order (handlers.py: headless from
    render_init to render_complete; in the UI the frames written, after the job): an
    ssao.Sequence per SSAO node, in which the library's temporal filter (the node's
    temporal_frames) averages each frame with the frames before it, carried through depth and
    camera. A frame seen through another camera object than the one before (a cut by camera
    markers) starts the node's sequence again.

    With `record_to` (a folder) each frame's library inputs are also saved there, in order, for
    replay() to give another process's Sequences (warm_up.py: the frames before a farm chunk).
    `warmed_up` is warm_up.py's: whether the frames before the first were given."""

    def __init__(self, record_to=None):
        self._shots = {}  # (scene name, node name) -> (camera name, ssao.Sequence)
        self._record_to = record_to
        self._recorded = 0
        self.warmed_up = False

    def shot(self, scene, node):
        """The frames' library call for `node` at the scene's frame: ambient_occlusion(depth,
        frame=, **arguments) of the node's ssao.Sequence (recorded when recording)."""
        camera = scene.camera.name if scene.camera is not None else ""
        sequence = self._sequence(scene.name, node.name, camera)
        if self._record_to is None:
            return sequence
        return types.SimpleNamespace(ambient_occlusion=functools.partial(
            self._record, sequence, (scene.name, node.name, camera)))

    def _sequence(self, scene_name, node_name, camera):
        key = (scene_name, node_name)
        kept = self._shots.get(key)
        if kept is None or kept[0] != camera:
            if kept is not None:
                kept[1].close()
            kept = self._shots[key] = (camera, ssao.Sequence(library()))
        return kept[1]

    def _record(self, sequence, names, depth, *, frame, **arguments):
        """Saves one frame's inputs (arrays as arrays, the rest as JSON; run_stats is an
        output), then computes it."""
        arrays = {"depth": depth}
        values = {}
        for name, value in arguments.items():
            if isinstance(value, np.ndarray):
                arrays[name] = value
            elif isinstance(value, list) and value and isinstance(value[0], np.ndarray):
                arrays.update({f"{name}.{i}": v for i, v in enumerate(value)})
                values[name] = {"arrays": len(value)}
            elif name != "run_stats":
                values[name] = {"value": value.item() if isinstance(value, np.generic)
                                else value}
        meta = {"names": names, "frame": frame, "values": values}
        path = os.path.join(self._record_to, f"{self._recorded:05d}.npz")
        np.savez(path, meta=np.array(json.dumps(meta)), **arrays)
        self._recorded += 1
        return sequence.ambient_occlusion(depth, frame=frame, **arguments)

    def replay(self, folder):
        """Computes the frames another process's Sequences recorded in `folder`, in their
        order, as if this one had: the temporal filter then has them for the frames after.
        Returns how many; a frame the library refused takes no part, as it did there."""
        paths = sorted(p for p in os.listdir(folder) if p.endswith(".npz"))
        for name in paths:
            with np.load(os.path.join(folder, name), allow_pickle=False) as stored:
                meta = json.loads(str(stored["meta"]))
                arguments = {}
                for key, value in meta["values"].items():
                    arguments[key] = [stored[f"{key}.{i}"] for i in range(value["arrays"])] \
                        if "arrays" in value else value["value"]
                arguments.update({key: stored[key] for key in stored.files
                                  if key not in ("meta", "depth") and "." not in key})
                depth = stored["depth"]
            try:
                self._sequence(*meta["names"]).ambient_occlusion(depth, frame=meta["frame"],
                                                                 **arguments)
            except ssao.SSAOError:
                pass
        return len(paths)

    def close(self):
        for _, shot in self._shots.values():
            shot.close()
        self._shots.clear()


def compute_node(node, scene, passes, wait=True, run_stats=None, sequences=None):
    """AO of `node` from exported `passes` (read_export's: normal xyz, depth[, the Image's
    RGBA]); fills the node's AO image (with the composite's factor: inner_tree.py) and returns
    the AO with row 0 on top. Raises, leaving the AO image as it was, when the inputs, the
    parameters or the library cannot give this frame's AO. With wait=False (the UI) a helper
    render the node needs is asked of helper_process and, until its layers come, the AO is
    computed without them (waiting_status()). run_stats (a dict, optional) gets what the
    library saw: "geometry_pixels" and their "mean_ao" (ssao.ambient_occlusion's). With
    `sequences` (an animation render's Sequences) the scene's current frame is the next frame
    of the node's sequence; without, it is computed alone."""
    use_normals = check_inputs(node)
    check_parameters(node)
    library()  # before the helper render (library_inputs): a missing library renders none
    camera = camera_module.camera_params(scene)
    background = EEVEE_BACKGROUND_DEPTH if compat.is_eevee(scene) else \
        library_default("background_depth")
    check_depth(passes[:, :, 3])
    if use_normals:
        check_normals(scene, passes, min(background, camera["clip_end"] or math.inf))
    beauty = inner_tree.white_beauty(passes)
    # Blender's rows run bottom-up, the library's top-down: flipped views read in place.
    images, overscan = library_inputs(node, scene, passes, use_normals, wait)
    height, width = beauty.shape[:2]
    layers = range(2, 2 + sum(name.startswith("facing") for name in images))  # depth2, ...
    run = ssao.ambient_occlusion if sequences is None else functools.partial(
        sequences.shot(scene, node).ambient_occlusion, frame=scene.frame_current)
    # A frame without geometry (only sky) is AO 1, not an error: an animation goes on.
    ao, composite = run(
        images["depth"], normals=images.get("normal"), camera=None,
        depth_layers=[images[f"depth{k}"] for k in layers],
        facing_layers=[images[f"facing{k}"] for k in layers], beauty=beauty,
        edge_colours=inner_tree.image_colours(passes),
        output_window=(overscan, overscan, width, height) if overscan else None,
        require_geometry=False, run_stats=run_stats,
        **camera, background_depth=background,  # the same as the Normal check's
        threads=camera_module.render_threads(scene), **node_parameters(node))
    inner_tree.store_outputs(node, ao, composite)
    return ao


def library_inputs(node, scene, passes, use_normals, wait=True):
    """({library image name: array, row 0 on top}, overscan in pixels) for `passes`: the
    user's Depth (and Normal), and, when the node asks for hidden surfaces or a guard band, the
    helper render's layers of the scene's current frame (hidden_surfaces.py; with wait=False
    and the helper in its own process, only once helper_process has them). In the band the
    helper's depth and normal stand in for the user's; inside it the user's passes are kept."""
    depth, normal = passes[::-1, :, 3], passes[::-1, :, 0:3]
    hits = HITS[getattr(node, "hidden_surfaces", 'NONE')]
    overscan = band_width(node, scene, depth)
    user_passes = {"depth": depth, **({"normal": normal} if use_normals else {})}
    if hits == 1 and not overscan:
        helper_process.withdraw(scene.name, node.name)
        return user_passes, 0
    if wait or not session.current.use_helper_process:
        layers = hidden_surfaces.render_layers(scene, hits, overscan, folder=export_dir())
    else:
        layers = helper_process.layers_or_request(scene, hits, overscan, node.name)
        if layers is None:
            return user_passes, 0
    height, width = depth.shape
    inside = (slice(overscan, overscan + height), slice(overscan, overscan + width))
    full_depth = layers["depth"].copy()
    full_depth[inside] = depth
    images = {"depth": full_depth}
    if use_normals:
        full_normal = layers["normal"].copy()
        full_normal[inside] = normal
        images["normal"] = full_normal
    if hits > 1:
        images.update(_extra_layers(full_depth, layers, hits))
    return images, overscan


def band_width(node, scene, depth):
    """The guard band in pixels per side: the node's `overscan` (overscan_mode 'PIXELS'), or
    BAND_OF_REACH of how far the radius reaches beyond the frame's edges, in pixels: the largest
    over the geometry pixels of the radius's size in pixels at their depth less their distance
    to the nearest edge (`depth`: the user's pass, row 0 on top)."""
    if getattr(node, "overscan_mode", 'PIXELS') != 'RADIUS':
        return getattr(node, "overscan", 0)
    left, right, _, _, distance, orthographic = camera_module.view_frame(scene)
    full_width = camera_module.full_size(scene.render)[0]
    per_unit = full_width / (right - left)  # pixels per scene unit (at `distance`)
    height, width = depth.shape
    geometry = np.isfinite(depth) & (depth > 0) & (depth < library_default("background_depth"))
    if not geometry.any():
        return 0
    reach = node.radius * per_unit * (1.0 if orthographic else distance / depth[geometry])
    y, x = np.nonzero(geometry)
    to_edge = np.minimum(np.minimum(x, width - 1 - x), np.minimum(y, height - 1 - y))
    beyond = float(np.max(reach - to_edge))
    if beyond <= 0:
        return 0
    return int(min(MAX_BAND, 8 * math.ceil(BAND_OF_REACH * beyond / 8)))


def _extra_layers(depth, layers, hits):
    """depth2.. and facing2.. behind the depth the library is given: the helper's 2nd and
    later surfaces that lie behind it (an open surface's twin lies at its own depth: within
    SAME_SURFACE counts as behind). Inside the frame that depth is the user's pass, which can
    disagree with the helper's 1st surface (EEVEE's half floats, a surface the helper does not
    see as the beauty does): an entry not behind it is dropped and the later ones move up, so
    the layers stay in depth order (the library refuses a layer nearer than the one before
    it)."""
    behind = np.stack([layers[f"depth{k}"] for k in range(2, hits + 1)])
    facing = np.stack([layers[f"facing{k}"] for k in range(2, hits + 1)])
    behind = np.where(behind >= depth * np.float32(1.0 - SAME_SURFACE), behind,
                      np.float32(np.inf))
    order = np.argsort(behind, axis=0, kind="stable")
    behind = np.take_along_axis(behind, order, axis=0)
    facing = np.take_along_axis(facing, order, axis=0)
    missing = ~np.isfinite(behind)
    behind[missing] = hidden_surfaces.BACKGROUND
    facing[missing] = 0.0
    images = {}
    for k in range(2, hits + 1):
        images[f"depth{k}"] = np.ascontiguousarray(behind[k - 2])
        images[f"facing{k}"] = np.ascontiguousarray(facing[k - 2])
    return images


WAITING_STATUS = "Rendering hidden surfaces for frame {frame}; the AO without them meanwhile"


def waiting_status(node, scene, frame):
    """The node's status while helper_process renders the layers it asked for, else None."""
    if helper_process.waiting(scene.name, node.name):
        return WAITING_STATUS.format(frame=frame)
    return None


def compute_frame(scene, frame, since=0.0, outcome="written", wait=True, sequences=None):
    """Computes every SSAO node of `scene` from its export of `frame` (the scene's current
    frame) written since `since` (a time.time(); a render that started before the add-on turned
    a saved file's group nodes back into SSAO nodes exports where the file was saved). Returns
    {node name: AO, or None where it failed}. A node that failed gets an AO of 1 (the frame is
    `outcome` without its AO), and the error is reported on the node and in the console. wait,
    sequences: compute_node's."""
    done = {}
    for node in ssao_nodes(scene):
        # A render of this session may have exported where a saved file points (see above).
        path = inner_tree.export_path(node, frame, (SAVED_EXPORT_DIR,) if since else (), since)
        try:
            # Before the export: a Render Layers pass that is off can stop the export in 3.4
            # and 4.3, and the node should say which.
            check_inputs(node)
            if path is None:
                raise RuntimeError(compat.compositor_cannot_export(scene) or
                                   f"no exported passes for frame {frame} (is the node's output "
                                   "connected to the compositor's output?)")
            start = time.perf_counter()
            stats = {}
            ao = compute_node(node, scene, read_export(path), wait, run_stats=stats,
                              sequences=sequences)
            seconds = time.perf_counter() - start
            node.status = waiting_status(node, scene, frame) or \
                f"Frame {frame}: {ao.shape[1]}x{ao.shape[0]} in {seconds * 1e3:.0f} ms"
            # The library's figure: the mean over the geometry pixels (1 without any).
            report(f"{scene.name} frame {frame} node '{node.name}': {node.status}, "
                   f"mean AO {stats['mean_ao']:.4f} over {stats['geometry_pixels']} geometry "
                   "pixels")
            done[node.name] = ao
        except Exception as error:
            done[node.name] = None
            without_ao(node, scene)
            node.status = f"Error: {error}"
            report(f"{scene.name} frame {frame} node '{node.name}': {outcome} WITHOUT AO: "
                   f"{error}", error=True)
        if sequences is not None and path is not None:
            _remove_earlier_exports(node, path)
    return done


def _remove_earlier_exports(node, path):
    """In an animation render (its frames computed in order) the node's exports of the frames
    before the one at `path` are of no more use: removed, when they are in this session's own
    export folder (a folder the user chose keeps every frame, and the one saved files point at
    is shared with other sessions). A failure costs the frame nothing: it is reported."""
    if os.path.realpath(os.path.dirname(path)) != os.path.realpath(PROCESS_EXPORT_DIR):
        return
    try:
        inner_tree.remove_earlier_exports(node, path)
    except Exception as error:
        report(f"node '{node.name}': removing the exports of earlier frames failed: {error}",
               error=True)


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
    try:
        return compute_node(node, scene, read_export(path))
    except Exception:
        without_ao(node, scene)
        raise
