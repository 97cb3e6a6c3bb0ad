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

__all__ = ["ambient_occlusion", "read_camera", "camera_parameters", "parameters", "variants",
           "version", "library", "load_library", "Job", "SSAOError", "image_layout_error",
           "PARAM_INT", "PARAM_FLOAT", "PARAM_STRING", "PARAM_FLOATS"]
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


# A camera file's keys (docs/conventions.md, "Camera file") that are not the library parameter
# of the same name, and the shapes of its matrices. Every other key of the format is a camera
# parameter of the library under its own name, which checks its range.
_CAMERA_RENAMED = {"type": "camera_type", "matrix_world": "camera_to_world"}
_CAMERA_MATRICES = {"matrix_world": (4, 4), "projection_matrix": (4, 4), "intrinsics": (4,)}
_CAMERA_ONLY = ("ao_distance",)  # the AO radius the shot was made for: not a camera parameter
# Numbers the camera file requires positive or not negative (camera_json.cpp's checks; the
# library's own ranges allow clip_end 0, "no clip test", which a file cannot say).
_CAMERA_POSITIVE = ("lens", "sensor_width", "sensor_height", "ortho_scale", "clip_end",
                    "pixel_aspect_x", "pixel_aspect_y", "ao_distance")
_CAMERA_NOT_NEGATIVE = ("clip_start",)


def _camera_keys():
    """{camera file key: library parameter} for every camera parameter of the library."""
    names = [p["name"] for p in parameters() if p["group"] == "camera"]
    key_of = {param: key for key, param in _CAMERA_RENAMED.items()}
    return {key_of.get(name, name): name for name in names}


def _required_camera_keys(camera):
    """The keys the camera's projection depends on, which a camera file must have (the CLI's
    rule): a default would give a plausible but wrong image."""
    projection = camera.get("projection", "lens")
    if projection == "intrinsics":
        return ["type", "intrinsics"]
    if projection == "matrix":
        return ["projection_matrix"]
    lens_keys = ["type", "sensor_fit", "shift_x", "shift_y"]
    if camera.get("type") == "ORTHO":
        return lens_keys + ["ortho_scale"]
    side = "sensor_height" if camera.get("sensor_fit") == "VERTICAL" else "sensor_width"
    return lens_keys + ["lens", side]


def _camera_number(key, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SSAOError(f"camera key '{key}' must be a number, got {type(value).__name__}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise SSAOError(f"camera key '{key}' must be a finite number, got {value}")
    return number


def _camera_matrix(key, value):
    import numpy as np
    shape = _CAMERA_MATRICES[key]
    rows = "an array of 4 numbers" if shape == (4,) else "a 4x4 matrix (4 rows of 4 numbers)"
    try:
        matrix = np.array(value, dtype=object)
    except ValueError:  # ragged nesting
        matrix = None
    if matrix is None or matrix.shape != shape:
        raise SSAOError(f"camera key '{key}' must be {rows}")
    # Numbers only, as in the file (np.array(..., float) would take "1" and True).
    matrix = np.array([_camera_number(key, v) for v in matrix.ravel()]).reshape(shape)
    if key == "matrix_world" and list(matrix[3]) != [0.0, 0.0, 0.0, 1.0]:
        raise SSAOError("camera key 'matrix_world' must be an affine transform: its last row "
                        "must be [0, 0, 0, 1]")
    return [float(v) for v in matrix.ravel()]


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
    """The library parameters (name -> value) of a camera file's dict, checked as `ssao --camera`
    checks the file: SSAOError for a missing key the projection needs, a value of the wrong
    type or not finite; a key the format does not know is warned about and ignored.
    "ao_distance" is not among them (ambient_occlusion() uses it as the default radius)."""
    if not isinstance(camera, dict):
        raise SSAOError(f"camera must be a dict (a camera file's keys) or a camera file's "
                        f"path, got {type(camera).__name__}")
    known = _camera_keys()
    for key in camera:
        if key not in known and key not in _CAMERA_ONLY:
            warnings.warn(f"camera: unknown key '{key}' ignored", stacklevel=3)
    for key in _required_camera_keys(camera):
        if key not in camera:
            raise SSAOError(f"camera: missing key '{key}', which its projection needs "
                            "(scripts/blender/export_cameras.py writes every key)")
    params = {}
    for key, value in camera.items():
        if key in _CAMERA_POSITIVE and not _camera_number(key, value) > 0.0:
            raise SSAOError(f"camera key '{key}' must be positive, got {value}")
        if key in _CAMERA_NOT_NEGATIVE and _camera_number(key, value) < 0.0:
            raise SSAOError(f"camera key '{key}' must not be negative, got {value}")
        if key in _CAMERA_ONLY:
            continue
        if key in _CAMERA_MATRICES:
            params[known[key]] = _camera_matrix(key, value)
        elif key in known:
            params[known[key]] = value  # Job.set checks the type, the library the value
    return params


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
                      beauty=None, ambient=None, output_window=None, progress=None,
                      **parameters):
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
    output_window  (x, y, width, height), optional: overscan. The inputs extend beyond the
                   frame, which is this window of them; the outputs have the window's size and
                   the camera describes the frame.
    progress       callable(fraction), optional; returning False cancels (SSAOError).
    parameters     the library's parameters by name (ssao.parameters()), e.g. radius=0.8,
                   variant="horizon", threads=4. Without radius: the camera's "ao_distance",
                   else the library's automatic radius (as the CLI chooses).

    Raises SSAOError (bad input, a library error with its message, a depth without any
    geometry pixel) and never returns a partial image.
    """
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

    if isinstance(camera, (str, os.PathLike)):
        camera = read_camera(camera)
    settings = camera_parameters(camera) if camera is not None else {}
    ao = np.empty(frame, np.float32)
    composite = np.empty(beauty.shape, np.float32) if beauty is not None else None
    with Job(library()) as job:
        _set_all(job, settings, "camera: ")
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
        job.set_image("ao", ao)
        if beauty is not None:
            job.set_image("beauty", beauty)
            if ambient is not None:
                job.set_image("ambient", ambient)
            job.set_image("composite", composite)
        _require_matrix_world(job, normals, camera, parameters)
        if "radius" not in parameters:
            job.set("radius", _default_radius(job, camera))
        job.run(progress)
        if job.last_run()[0] == 0:
            raise SSAOError(_NO_GEOMETRY)
    return (ao, composite) if beauty is not None else ao


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


def _require_matrix_world(job, normals, camera, parameters):
    """World-space normals without the camera's matrix would be turned by the identity: a
    silently wrong AO, so refused (as the CLI refuses it), whether the matrix would come from
    the camera ("matrix_world") or the parameters ("camera_to_world")."""
    has_matrix = (camera is not None and "matrix_world" in camera) or \
        "camera_to_world" in parameters
    if normals is None or has_matrix or job.get("normal_space") != "world":
        return
    raise SSAOError("missing the camera's matrix ('matrix_world' of the camera, or the "
                    "parameter camera_to_world), which world-space normals need; add it, or "
                    "pass normal_space='camera' for view-space normals, or normals=None to "
                    "rebuild them from depth")


def _default_radius(job, camera):
    """The CLI's rule without --radius: the camera's ao_distance, else the library's automatic
    radius (10% of the view's width at the median depth)."""
    if camera is not None and "ao_distance" in camera:
        return float(camera["ao_distance"])
    try:
        return job.auto_radius()
    except SSAOError:
        raise SSAOError(_NO_GEOMETRY) from None
