# SPDX-License-Identifier: MIT
"""libssao from Python: screen-space ambient occlusion of a render's depth (and normal) pass.

    import ssao
    ao = ssao.ambient_occlusion(depth, normals=normals, camera=camera_dict, radius=0.8)

`depth` is a float32 numpy array (height, width), row 0 on top; `camera` the dict of a camera
file (what `ssao --camera FILE` reads, e.g. json.load(open("shot.camera.json"))); the other
keywords are the library's parameters (ssao.parameters()). The result is the AO, float32
(height, width), 1 = unoccluded: the same bits `build/bin/ssao` writes for the same inputs.
Every library error is an ssao.SSAOError carrying the library's message. docs/python.md.
"""
import json
import math
import numbers
import os
import warnings

from ._binding import (PARAM_FLOAT, PARAM_FLOATS, PARAM_INT, PARAM_STRING, Job, SSAOError,
                       image_layout_error, library, load_library)
from . import _binding

__all__ = ["ambient_occlusion", "Sequence", "read_camera", "camera_parameters", "parameters",
           "variants", "version", "library", "load_library", "Job", "SSAOError",
           "image_layout_error", "PARAM_INT", "PARAM_FLOAT", "PARAM_STRING", "PARAM_FLOATS"]
_NO_GEOMETRY = ("the depth has no geometry pixel (every value is NaN, infinite, <= 0, or at "
                "least background_depth or clip_end): is it the depth pass?")


def version():
    """The loaded library's version as "major.minor.patch"."""
    number = library().ssao_version()
    return f"{number // 10000}.{number // 100 % 100}.{number % 100}"


def parameters(lib=None):
    """The library's parameters: a list of dicts (group, name, type, default, min, max,
    default_string, choices, count, unit, description), in the library's order."""
    return _binding.parameters(lib or library())


def variants(lib=None):
    """The library's AO variants: a list of dicts (name, description, parameters: the names of
    the parameters only that variant reads)."""
    return _binding.variants(lib or library())


def _camera_text(camera):
    """A camera file's dict as the file's text, for the library's reader (ssao_job_set_camera_json,
    which checks every rule of the format). numpy values become numbers and lists. JSON has no
    number that is not finite: such a value is refused here, named as the reader names keys."""
    if not isinstance(camera, dict):
        raise SSAOError(f"camera must be a dict (a camera file's keys) or a camera file's "
                        f"path, got {type(camera).__name__}")

    def plain(value, key):
        if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
            value = value.tolist()  # numpy arrays and scalars
        if isinstance(value, (list, tuple)):
            return [plain(v, f"{key}[{k}]") for k, v in enumerate(value)]
        if isinstance(value, numbers.Real) and not isinstance(value, bool):
            try:
                number = float(value)
            except OverflowError:  # an int beyond any float
                number = math.inf
            if not math.isfinite(number):
                raise SSAOError(f"camera file 'camera': key '{key}' must be a finite number, "
                                f"got {value}")
            return value if isinstance(value, int) else number
        return value

    try:
        return json.dumps({str(k): plain(v, k) for k, v in camera.items()})
    except (TypeError, ValueError) as error:
        raise SSAOError(f"camera: {error}") from None


def _apply_camera(job, camera, stacklevel):
    """Sets the job's camera from a camera file's dict, warning about the keys the format does
    not know."""
    for key in job.set_camera_json(_camera_text(camera)):
        warnings.warn(f"camera: unknown key '{key}' ignored", stacklevel=stacklevel + 1)


def read_camera(path):
    """The dict of a camera file (JSON). SSAOError, naming the file, when it cannot be read, is
    not JSON (NaN and Infinity are not JSON either: the CLI refuses them too) or is not an
    object."""
    def refuse(constant):
        raise ValueError(f"{constant} is not JSON")
    try:
        with open(path, encoding="utf-8") as f:
            camera = json.load(f, parse_constant=refuse)
    except OSError as error:
        raise SSAOError(f"camera file '{os.fspath(path)}': {error.strerror or error}") from None
    except ValueError as error:  # JSONDecodeError, UnicodeDecodeError, refuse()
        raise SSAOError(f"camera file '{os.fspath(path)}': malformed JSON: {error}") from None
    if not isinstance(camera, dict):
        raise SSAOError(f"camera file '{os.fspath(path)}': expected a JSON object, got "
                        f"{type(camera).__name__}")
    return camera


def camera_parameters(camera):
    """The library parameters (name -> value) of a camera file's dict, checked by the library's
    reader of the format as `ssao --camera` checks the file: SSAOError for a missing key the
    projection needs, a value of the wrong type or not finite; a key the format does not know
    is warned about and ignored. "ao_distance" is not among them (ambient_occlusion() uses it
    as the default radius)."""
    with Job(library()) as job:
        _apply_camera(job, camera, stacklevel=2)
        return {p["name"]: job.get(p["name"]) for p in parameters()
                if p["group"] == "camera" and job.is_set(p["name"])}


def _set_all(job, settings, what):
    for name, value in settings.items():
        try:
            job.set(name, value)
        except SSAOError as error:
            raise SSAOError(f"{what}{error}") from None


def _check_image(name, array, shape, channels=None):
    problem = image_layout_error(array)
    if problem:
        raise SSAOError(f"{name} {problem}")
    got = array.shape[2] if array.ndim == 3 else 1
    if channels is not None and got not in channels:
        raise SSAOError(f"{name} must have {' or '.join(map(str, channels))} channels "
                        f"(shape (height, width, channels)), got shape {array.shape}")
    if shape is not None and array.shape[:2] != shape:
        raise SSAOError(f"{name} has shape {array.shape[:2]}, the depth {shape}: "
                        "every input must have the depth's height and width")


def ambient_occlusion(depth, *, normals=None, camera, depth_layers=(), facing_layers=(),
                      beauty=None, ambient=None, edge_colours=None, output_window=None,
                      progress=None, require_geometry=True, run_stats=None, **parameters):
    """The AO of a depth pass: float32 (height, width), 1 = unoccluded, row 0 on top.

    depth          float32 (H, W): planar depth (Blender's Depth pass) or radial
                   (depth_kind="radial"); NaN, infinite, <= 0 or >= background_depth is
                   background (AO 1), as in the library's contract.
    normals        float32 (H, W, 3), optional: the normal pass (normal_space="world", the
                   default, needs the camera's "matrix_world"); None rebuilds them from depth.
    camera         the dict of a camera file (ssao --camera), or its path (read_camera), or
                   None to give the camera by its library parameters (lens, sensor_width, ...)
                   among `parameters`.
    depth_layers   float32 (H, W) arrays: the 2nd, 3rd, ... surface hits ("depth2", ...).
    facing_layers  float32 (H, W) arrays: 1 where that hit is a back face ("facing2", ...).
    beauty         float32 (h, w) or (h, w, 1..4), optional: then (ao, composite) is returned,
                   composite = beauty darkened by the AO; `ambient` (same shape) is the part
                   of the beauty AO darkens.
    edge_colours   float32, optional, the beauty's height and width, 1..4 channels: the
                   colours edge_coverage="beauty" reads in place of the beauty's (a beauty
                   that is not the picture, e.g. a white image whose composite is a factor).
    output_window  (x, y, width, height), optional: overscan. The inputs extend beyond the
                   frame, which is this window of them; the outputs have the window's size and
                   the camera describes the frame.
    progress       callable(fraction), optional; returning False cancels (SSAOError).
    require_geometry  False: a depth without any geometry pixel gives AO 1 (and the composite
                   its beauty) instead of SSAOError: a sky-only frame of an animation.
    run_stats      a dict, optional: filled with what the run saw over the frame
                   (ssao_job_last_run): "geometry_pixels" and "mean_ao", their mean final AO.
    parameters     the library's parameters by name (ssao.parameters()), e.g. radius=0.8,
                   variant="horizon", threads=4. Without radius: the camera's "ao_distance",
                   else the library's automatic radius (as the CLI chooses).

    Raises SSAOError (bad input, a library error with its message, a depth without any
    geometry pixel) and never returns a partial image.
    """
    return _ambient_occlusion(
        None, depth, normals=normals, camera=camera, depth_layers=depth_layers,
        facing_layers=facing_layers, beauty=beauty, ambient=ambient,
        edge_colours=edge_colours, output_window=output_window, progress=progress,
        require_geometry=require_geometry, run_stats=run_stats, **parameters)


def _ambient_occlusion(job, depth, *, normals=None, camera, depth_layers=(), facing_layers=(),
                       beauty=None, ambient=None, edge_colours=None, output_window=None,
                       progress=None, require_geometry=True, run_stats=None, **parameters):
    """ambient_occlusion() in `job` (a Sequence's: its images are detached after the run), or
    in a job of its own (None)."""
    import numpy as np
    depth_layers, facing_layers = list(depth_layers), list(facing_layers)  # iterated twice
    _check_image("depth", depth, None, channels=(1,))
    shape = depth.shape[:2]
    frame = shape
    if output_window is not None:
        x, y, width, height = _window(output_window, shape)
        frame = (height, width)
    if normals is not None:
        _check_image("normals", normals, shape, channels=(3, 4))
    for kind, layers in (("depth_layers", depth_layers), ("facing_layers", facing_layers)):
        for k, layer in enumerate(layers):
            _check_image(f"{kind}[{k}]", layer, shape, channels=(1,))
    if beauty is not None:
        _check_image("beauty", beauty, frame, channels=(1, 2, 3, 4))
    if ambient is not None:
        if beauty is None:
            raise SSAOError("ambient needs beauty (it is the part of the beauty AO darkens)")
        _check_image("ambient", ambient, frame)
        if ambient.shape != beauty.shape:
            raise SSAOError(f"ambient has shape {ambient.shape}, beauty {beauty.shape}")
    if edge_colours is not None:
        _check_image("edge_colours", edge_colours, frame, channels=(1, 2, 3, 4))

    if isinstance(camera, (str, os.PathLike)):
        camera = read_camera(camera)
    ao = np.empty(frame, np.float32)
    composite = np.empty(beauty.shape, np.float32) if beauty is not None else None
    own_job = Job(library()) if job is None else None
    job = job or own_job
    try:
        if camera is not None:
            _apply_camera(job, camera, stacklevel=3)
        _set_all(job, parameters, "")  # after the camera: an argument overrides the file
        job.set_image("depth", depth)
        if normals is not None:
            job.set_image("normal", normals)
        for k, layer in enumerate(depth_layers):
            job.set_image(f"depth{k + 2}", layer)
        for k, layer in enumerate(facing_layers):
            job.set_image(f"facing{k + 2}", layer)
        if output_window is not None:
            job.set_output_window(x, y)
        else:  # cleared: a Sequence's job keeps the window of the frame before
            job.set_output_window(0, 0, enable=False)
        job.set_image("ao", ao)
        if edge_colours is not None:
            job.set_image("edge_colours", edge_colours)
        if beauty is not None:
            job.set_image("beauty", beauty)
            if ambient is not None:
                job.set_image("ambient", ambient)
            job.set_image("composite", composite)
        job.check_inputs()  # world-space normals without the camera's matrix
        try:  # without radius: the camera's "ao_distance", else the automatic radius
            job.choose_radius()
        except SSAOError:
            if require_geometry:
                raise SSAOError(_NO_GEOMETRY) from None
            # No geometry: AO 1 whatever the radius; the run still writes the outputs.
        job.run(progress)
        geometry_pixels, mean_ao = job.last_run()
        if run_stats is not None:
            run_stats.update(geometry_pixels=geometry_pixels, mean_ao=mean_ao)
        if geometry_pixels == 0 and require_geometry:
            raise SSAOError(_NO_GEOMETRY)
    finally:
        if own_job is not None:
            own_job.close()
        else:
            job.detach_images()  # the caller's arrays are not the job's beyond the call
    return (ao, composite) if beauty is not None else ao


class Sequence:
    """The frames of a shot computed in one library job, so that the temporal filter
    (`temporal_frames`, default 3) averages each frame with the frames numbered just before it
    that this sequence computed, each carried to its pixels through depth and both cameras
    (docs/variants.md, "Temporal filter"): the sampling pattern then does not crawl over the
    surfaces as the camera moves. Each frame's camera needs its matrix_world (without one the
    camera counts as still). Give the frames in increasing order: a frame at or before one
    computed averages only the frames before it. Parameters keep their values from one frame to
    the next until given again (a library job's rule), so a radius chosen automatically on the
    first frame stays. Use as a context manager or call close()."""

    # The library numbers a sequence's frames from 0; a shot's may be negative (Blender's).
    _FRAME_ORIGIN = 2 ** 30

    def __init__(self, lib=None):
        self._job = Job(lib or library())

    def close(self):
        self._job.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def ambient_occlusion(self, depth, *, frame, **arguments):
        """ssao.ambient_occlusion(depth, **arguments) as frame number `frame` of the shot (an
        int, |frame| < 2**30). Raises as ambient_occlusion does; a frame that failed takes no
        part in the frames after it."""
        if not isinstance(frame, numbers.Integral) or isinstance(frame, bool) or \
                abs(int(frame)) >= self._FRAME_ORIGIN:
            raise SSAOError(f"frame must be an int of magnitude below 2**30, got {frame!r}")
        self._job.set("frame", int(frame) + self._FRAME_ORIGIN)
        return _ambient_occlusion(self._job, depth, **arguments)


def _window(output_window, shape):
    """(x, y, width, height) of an output window inside a depth image of `shape`: integers (no
    float is rounded), checked before the outputs are allocated."""
    try:
        values = tuple(output_window)
    except TypeError:
        values = ()
    if len(values) != 4 or not all(isinstance(v, numbers.Integral) and not isinstance(v, bool)
                                   for v in values):
        raise SSAOError(f"output_window must be (x, y, width, height) in whole pixels, got "
                        f"{output_window!r}")
    x, y, width, height = (int(v) for v in values)
    if min(values) < 0 or x + width > shape[1] or y + height > shape[0]:
        raise SSAOError(f"output window {width}x{height} at ({x}, {y}) does not fit in the "
                        f"{shape[1]}x{shape[0]} depth image")
    return x, y, width, height
