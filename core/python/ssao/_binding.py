# SPDX-License-Identifier: MIT
"""The ctypes binding to libssao's C API (core/include/ssao/ssao.h): the one binding, used by the
`ssao` module's ambient_occlusion() and by the Blender add-on (which bundles this package).

ctypes rather than a compiled extension: one file serves every Python a user runs it from
(Debian's python3, and Blender 3.4's, 4.3's and 5.2's own), with no build per Python version.
No bpy import. Images are numpy float32 arrays of shape (height, width) or (height, width,
channels), row 0 on top; their strides are passed through, so views into larger arrays (and
flipped ones) are read in place.
"""
import ctypes
import numbers
import os
import sys

ABI_MAJOR = 0

_LIB_NAMES = {"linux": "libssao.so", "darwin": "libssao.dylib", "win32": "ssao.dll"}
_SONAME = "libssao.so.%d" % ABI_MAJOR  # what a package without the -dev symlink installs


class SSAOError(RuntimeError):
    """A libssao call failed; the message is the library's."""


class _ParamDesc(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("type", ctypes.c_int),
        ("default_value", ctypes.c_double),
        ("min_value", ctypes.c_double),
        ("max_value", ctypes.c_double),
        ("default_string", ctypes.c_char_p),
        ("choices", ctypes.c_char_p),
        ("count", ctypes.c_size_t),
        ("unit", ctypes.c_char_p),
        ("description", ctypes.c_char_p),
    ]


class _VariantDesc(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_char_p),
        ("description", ctypes.c_char_p),
        ("parameters", ctypes.c_char_p),
    ]


PARAM_INT, PARAM_FLOAT, PARAM_STRING, PARAM_FLOATS = 0, 1, 2, 3
_PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double)


def _candidate_paths():
    """Where libssao may be when no path is named, in order: a lib/ folder beside this package
    (how the Blender add-on bundles it), where `cmake --install` put it (_installed.py, written
    at install time), the source tree's build/lib/ (this file is core/python/ssao/ there); and
    last the system's loader by SONAME (a standard folder or LD_LIBRARY_PATH)."""
    here = os.path.dirname(os.path.abspath(__file__))
    name = _LIB_NAMES.get(sys.platform, "libssao.so")
    yield os.path.normpath(os.path.join(here, "..", "lib", name))  # bundled: the Blender add-on
    try:
        from . import _installed
        yield os.path.normpath(os.path.join(here, _installed.LIBRARY))
    except ImportError:  # not installed: the source tree (also through blender_addon/ssao, a link)
        source = os.path.dirname(os.path.realpath(__file__))
        yield os.path.normpath(os.path.join(source, "..", "..", "..", "build", "lib", name))
    yield _SONAME


_default_library = None


def library():
    """The library of load_library(), loaded on first use and kept."""
    global _default_library
    if _default_library is None:
        _default_library = load_library()
    return _default_library


def load_library(path=None):
    """Loads libssao: `path`, else $SSAO_LIBRARY, else the first of _candidate_paths() that
    loads. A library named by `path` or $SSAO_LIBRARY is that one or an SSAOError, never another
    found elsewhere (a typo must not compare a library with itself). SSAOError, listing where it
    looked, when none loads, or when the library's major version is not this binding's."""
    named = path or os.environ.get("SSAO_LIBRARY")
    if named:
        lib = _open(named)
        if isinstance(lib, str):
            what = "" if path else " ($SSAO_LIBRARY)"
            raise SSAOError(f"cannot load libssao {named}{what}: {lib}")
        return lib
    errors = []
    for candidate in _candidate_paths():
        lib = _open(candidate)
        if not isinstance(lib, str):
            return lib
        errors.append(f"{candidate}: {lib}")
    raise SSAOError("libssao not found: " + "; ".join(errors) +
                    " (set SSAO_LIBRARY to the library's path)")


def _open(candidate):
    """The library at `candidate` (a path, or a SONAME for the system's loader), declared and
    version-checked; or, when it cannot be loaded, why (a str)."""
    if os.sep in candidate and not os.path.exists(candidate):
        return "not found"
    try:
        lib = ctypes.CDLL(candidate)
    except OSError as error:
        return str(error)
    if not hasattr(lib, "ssao_version"):
        return "not libssao (no ssao_version)"
    _declare(lib)
    version = lib.ssao_version()
    if version // 10000 != ABI_MAJOR:
        raise SSAOError(f"{candidate} is libssao {version}, this binding needs {ABI_MAJOR}.x")
    return lib


def _declare(lib):
    def check(status, func, args):
        if status != 0:
            message = lib.ssao_last_error().decode("utf-8", "replace")
            raise SSAOError(f"{func.__name__}: {message}")
        return status

    def sig(name, restype, *argtypes, checked=True):
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, list(argtypes)
        if checked:
            fn.errcheck = check

    job, cstr, c_int, c_double = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_double
    sig("ssao_version", c_int, checked=False)
    sig("ssao_last_error", cstr, checked=False)
    sig("ssao_param_count", ctypes.c_size_t, checked=False)
    sig("ssao_param_info", c_int, ctypes.c_size_t, ctypes.POINTER(_ParamDesc))
    if hasattr(lib, "ssao_variant_count"):  # since 0.1 after 45f8526
        sig("ssao_variant_count", ctypes.c_size_t, checked=False)
        sig("ssao_variant_info", c_int, ctypes.c_size_t, ctypes.POINTER(_VariantDesc))
    if hasattr(lib, "ssao_param_group"):  # since 0.1 after issue 23
        sig("ssao_param_group", c_int, ctypes.c_size_t, ctypes.POINTER(ctypes.c_char_p))
    sig("ssao_job_create", c_int, ctypes.POINTER(ctypes.c_void_p))
    sig("ssao_job_destroy", None, job, checked=False)
    sig("ssao_job_set_int", c_int, job, cstr, c_int)
    sig("ssao_job_set_float", c_int, job, cstr, c_double)
    sig("ssao_job_set_string", c_int, job, cstr, cstr)
    sig("ssao_job_set_floats", c_int, job, cstr, ctypes.POINTER(c_double), ctypes.c_size_t)
    sig("ssao_job_get_int", c_int, job, cstr, ctypes.POINTER(c_int))
    sig("ssao_job_get_float", c_int, job, cstr, ctypes.POINTER(c_double))
    sig("ssao_job_get_string", c_int, job, cstr, ctypes.c_char_p, ctypes.c_size_t)
    sig("ssao_job_get_floats", c_int, job, cstr, ctypes.POINTER(c_double), ctypes.c_size_t)
    sig("ssao_job_set_image", c_int, job, cstr, ctypes.c_void_p, c_int, c_int, c_int,
        ctypes.c_ssize_t, ctypes.c_ssize_t)
    if hasattr(lib, "ssao_job_set_output_window"):  # since 0.1 after 7bf6fcd (overscan)
        sig("ssao_job_set_output_window", c_int, job, c_int, c_int, c_int)
    sig("ssao_job_set_progress", c_int, job, _PROGRESS_FN, ctypes.c_void_p)
    sig("ssao_job_auto_radius", c_int, job, ctypes.POINTER(c_double))
    sig("ssao_job_run", c_int, job)
    if hasattr(lib, "ssao_job_last_run"):  # since 0.1 after issue 23
        sig("ssao_job_last_run", c_int, job, ctypes.POINTER(ctypes.c_size_t),
            ctypes.POINTER(c_double))
    if hasattr(lib, "ssao_job_set_camera_json"):  # since 0.1 after issue 35
        # Their messages carry their own context (the camera file, the key): raised as they are.
        sig("ssao_job_set_camera_json", c_int, job, cstr, ctypes.c_size_t, cstr, checked=False)
        sig("ssao_job_camera_unknown_keys", c_int, job, ctypes.c_char_p, ctypes.c_size_t)
        sig("ssao_job_is_set", c_int, job, cstr, ctypes.POINTER(c_int))
        sig("ssao_job_choose_radius", c_int, job, c_int, ctypes.POINTER(c_double),
            ctypes.POINTER(c_int), checked=False)
        sig("ssao_job_check_inputs", c_int, job, checked=False)


OUTPUT_IMAGES = ("ao", "composite")


def image_layout_error(array, writable=False):
    """Why the library cannot use `array` as an image in place (None if it can). It reads
    rows of pixels of adjacent float32 channels: any row step (negative too: a flipped view) and
    any pixel step of at least one pixel, e.g. array[::2, ::2]; not a transposed or Fortran-order
    array, columns reversed, a broadcast (stride 0) or unaligned data."""
    import numpy as np
    if not isinstance(array, np.ndarray):
        return f"must be a numpy array, got {type(array).__name__}"
    if isinstance(array, np.ma.MaskedArray):  # the library would read the masked values
        return "is a masked array: fill it first, e.g. .filled(np.nan) (NaN depth is background)"
    if array.dtype != np.float32:
        return f"must be float32 (native byte order), got {array.dtype}; use .astype(np.float32)"
    if array.ndim not in (2, 3):
        return f"must have 2 dimensions (height, width) or 3 (height, width, channels), " \
               f"got shape {array.shape}"
    height, width = array.shape[:2]
    channels = array.shape[2] if array.ndim == 3 else 1
    if max(height, width) >= 2**31:
        return f"is too large for the library (shape {array.shape}: sides below 2^31)"
    if array.size == 0:
        return None  # no pixel to address: the library takes a 0-pixel image as it is
    pixel = 4 * channels
    fix = "; pass np.ascontiguousarray(array)"
    if array.ndim == 3 and channels > 1 and array.strides[2] != 4:
        return f"its channels are not adjacent floats (strides {array.strides}){fix}"
    if width > 1 and array.strides[1] < pixel:
        return f"its pixels are not in rows of increasing address (strides {array.strides}: " \
               f"transposed, reversed or broadcast){fix}"
    if height > 1 and abs(array.strides[0]) < (array.strides[1] if width > 1 else pixel) * width:
        return f"its rows overlap (strides {array.strides}: transposed or broadcast){fix}"
    if not array.flags.aligned or any(step % 4 for step in array.strides):
        return f"its data is not aligned to 4 bytes{fix}"
    if writable and not array.flags.writeable:
        return "is read-only, and the library writes it"
    return None


def parameters(lib):
    """Returns the library's parameter table as a list of dicts (name, type, default, ...): a
    copy of the table read once per loaded library (it never changes while loaded)."""
    table = lib.__dict__.get("_ssao_parameters")
    if table is None:
        table = lib.__dict__["_ssao_parameters"] = _read_parameters(lib)
    return [dict(p) for p in table]


def _read_parameters(lib):
    out = []
    for i in range(lib.ssao_param_count()):
        d = _ParamDesc()
        lib.ssao_param_info(i, ctypes.byref(d))
        text = lambda b: b.decode() if b is not None else None  # noqa: E731
        group = ctypes.c_char_p()
        if hasattr(lib, "ssao_param_group"):
            lib.ssao_param_group(i, ctypes.byref(group))
        out.append({
            "group": text(group.value),
            "name": text(d.name), "type": d.type, "default": d.default_value,
            "min": d.min_value, "max": d.max_value, "default_string": text(d.default_string),
            "choices": text(d.choices).split("|") if d.choices else None, "count": d.count,
            "unit": text(d.unit), "description": text(d.description),
        })
    return out


def variants(lib):
    """Returns the library's variants as a list of dicts (name, description, parameters: the
    names of the parameters only that variant reads)."""
    out = []
    if not hasattr(lib, "ssao_variant_count"):
        return out
    for i in range(lib.ssao_variant_count()):
        d = _VariantDesc()
        lib.ssao_variant_info(i, ctypes.byref(d))
        out.append({"name": d.name.decode(), "description": d.description.decode(),
                    "parameters": d.parameters.decode().split("|")})
    return out


def _int_value(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise SSAOError(f"parameter '{name}' must be an int, got {type(value).__name__}")
    if not -2**31 <= value < 2**31:
        raise SSAOError(f"parameter '{name}' is out of range: {value}")
    return int(value)


def _float_value(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SSAOError(f"parameter '{name}' must be a number, got {type(value).__name__}")
    try:
        return float(value)  # NaN and infinity reach the library, which says what it accepts
    except OverflowError:
        raise SSAOError(f"parameter '{name}' is out of range: {value}") from None


def _float_values(name, value):
    """A parameter of several floats: a sequence or array of numbers (a 4x4 matrix may be
    nested or 2-D), in row-major order; not a set or mapping, whose order means nothing."""
    import numpy as np
    if isinstance(value, (str, bytes, set, frozenset, dict)) or np.ndim(value) == 0:
        raise SSAOError(f"parameter '{name}' must be a sequence of numbers, got "
                        f"{type(value).__name__}")
    try:
        array = np.asarray(value)
    except ValueError:  # ragged nesting
        raise SSAOError(f"parameter '{name}' must be a sequence of numbers") from None
    if array.dtype.kind not in "iuf":
        flat = array.ravel() if array.dtype == object else ()
        if not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in flat) \
                or not len(flat):
            raise SSAOError(f"parameter '{name}' must be a sequence of numbers, got "
                            f"{array.dtype} values")
    return [_float_value(name, v) for v in array.ravel().tolist()]


class Job:
    """One AO job. Use as a context manager or call close()."""

    def __init__(self, lib=None):
        self._lib = lib or library()
        handle = ctypes.c_void_p()
        self._lib.ssao_job_create(ctypes.byref(handle))
        self._job = handle
        self._images = {}  # keeps attached arrays alive until run() returns
        table = parameters(self._lib)
        self._types = {p["name"]: p["type"] for p in table}
        self._counts = {p["name"]: p["count"] for p in table}

    def close(self):
        if self._job:
            self._lib.ssao_job_destroy(self._job)
            self._job = None

    def __del__(self):  # a job never closed is freed with its object
        if getattr(self, "_job", None):
            self.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def set(self, name, value):
        """Sets a parameter; the type comes from the library's table. SSAOError for a value of
        another type (a str for a number, a float for an int, ...): never converted."""
        kind = self._types.get(name)
        key = name.encode()
        if kind == PARAM_INT:
            self._lib.ssao_job_set_int(self._job, key, _int_value(name, value))
        elif kind == PARAM_FLOAT:
            self._lib.ssao_job_set_float(self._job, key, _float_value(name, value))
        elif kind == PARAM_STRING:
            if not isinstance(value, str):
                raise SSAOError(f"parameter '{name}' must be a str, got {type(value).__name__}")
            self._lib.ssao_job_set_string(self._job, key, value.encode())
        elif kind == PARAM_FLOATS:
            values = _float_values(name, value)
            array = (ctypes.c_double * len(values))(*values)
            self._lib.ssao_job_set_floats(self._job, key, array, len(values))
        else:
            # Let the library produce its "unknown parameter" message.
            self._lib.ssao_job_set_float(self._job, key, float("nan"))

    def get(self, name):
        """A parameter's value (int, float, str or a list of floats), by the library's table."""
        kind, key = self._types.get(name), name.encode()
        if kind == PARAM_INT:
            value = ctypes.c_int()
            self._lib.ssao_job_get_int(self._job, key, ctypes.byref(value))
            return value.value
        if kind == PARAM_STRING:
            text = ctypes.create_string_buffer(256)
            self._lib.ssao_job_get_string(self._job, key, text, len(text))
            return text.value.decode()
        if kind == PARAM_FLOATS:
            count = self._counts[name]
            values = (ctypes.c_double * count)()
            self._lib.ssao_job_get_floats(self._job, key, values, count)
            return list(values)
        value = ctypes.c_double()  # floats; an unknown name gets the library's message
        self._lib.ssao_job_get_float(self._job, key, ctypes.byref(value))
        return value.value

    def auto_radius(self):
        """The library's automatic radius for the attached depth and camera (ssao_job_auto_radius);
        SSAOError when the depth has no geometry pixel."""
        radius = ctypes.c_double()
        self._lib.ssao_job_auto_radius(self._job, ctypes.byref(radius))
        return radius.value

    def _raise_unless_ok(self, status):
        if status != 0:
            raise SSAOError(self._lib.ssao_last_error().decode("utf-8", "replace"))

    def set_camera_json(self, text, source="camera"):
        """Sets the camera from a camera file's text (ssao_job_set_camera_json: the format's one
        reader, which the CLI calls too); SSAOError naming `source` and the key, the job then
        unchanged. Returns the keys the format does not know (ignored)."""
        if not isinstance(text, str):
            raise SSAOError(f"camera file text must be a str, got {type(text).__name__}")
        data = text.encode()
        self._raise_unless_ok(self._lib.ssao_job_set_camera_json(self._job, data, len(data),
                                                                 str(source).encode()))
        keys = ctypes.create_string_buffer(4096)
        self._lib.ssao_job_camera_unknown_keys(self._job, keys, len(keys))
        return [key for key in keys.value.decode().split(",") if key]

    def is_set(self, name):
        """True if a set() or a camera file gave the parameter its value (ssao_job_is_set)."""
        value = ctypes.c_int()
        self._lib.ssao_job_is_set(self._job, name.encode(), ctypes.byref(value))
        return bool(value.value)

    def choose_radius(self, allow_automatic=True):
        """The radius rule without a radius set (ssao_job_choose_radius): a radius set stays;
        else the camera file's "ao_distance"; else the automatic radius. Returns (radius,
        source), source one of "set", "camera_file", "automatic"."""
        radius, source = ctypes.c_double(), ctypes.c_int()
        self._raise_unless_ok(self._lib.ssao_job_choose_radius(
            self._job, int(bool(allow_automatic)), ctypes.byref(radius), ctypes.byref(source)))
        return radius.value, ("set", "camera_file", "automatic")[source.value]

    def check_inputs(self):
        """SSAOError for what a run would get wrong without a word: world-space normals without
        the camera's matrix (ssao_job_check_inputs)."""
        self._raise_unless_ok(self._lib.ssao_job_check_inputs(self._job))

    def set_image(self, name, array):
        """Attaches a float32 numpy array (H, W) or (H, W, C), read (or, for the outputs "ao" and
        "composite", written) in place; None detaches. SSAOError for an array the library cannot
        address in place: see image_layout_error()."""
        if array is None:
            self._lib.ssao_job_set_image(self._job, name.encode(), None, 0, 0, 1, 0, 0)
            self._images.pop(name, None)
            return
        problem = image_layout_error(array, writable=name in OUTPUT_IMAGES)
        if problem:
            raise SSAOError(f"image '{name}': {problem}")
        height, width = array.shape[:2]
        channels = array.shape[2] if array.ndim == 3 else 1
        pixel_stride = array.strides[1] if width > 1 else 4 * channels
        row_stride = array.strides[0] if height > 1 else pixel_stride * width
        self._lib.ssao_job_set_image(self._job, name.encode(), array.ctypes.data, width, height,
                                     channels, pixel_stride, row_stride)
        self._images[name] = array

    def detach_images(self):
        """Detaches every image attached with set_image (the job keeps its parameters)."""
        for name in list(self._images):
            self.set_image(name, None)

    def set_output_window(self, x, y, enable=True):
        """Overscan: the outputs are the window at (x, y) of the depth image (ssao.h)."""
        self._lib.ssao_job_set_output_window(self._job, int(bool(enable)),
                                             _int_value("output window x", x),
                                             _int_value("output window y", y))

    def run(self, progress=None):
        """Runs the job. progress(fraction) is called on this thread; a false value other than
        None (False, 0) cancels the run (SSAOError "cancelled"). An exception it raises cancels
        the run too and is raised from here, as it was (ctypes would only print it)."""
        callback, raised = None, []
        if progress is not None:
            def call(user, fraction):
                try:
                    result = progress(fraction)
                except BaseException as error:  # KeyboardInterrupt included
                    raised.append(error)
                    return 0
                return 0 if result is not None and not result else 1
            callback = _PROGRESS_FN(call)
            self._lib.ssao_job_set_progress(self._job, callback, None)
        try:
            self._lib.ssao_job_run(self._job)
        except SSAOError:
            if raised:
                raise raised[0] from None
            raise
        finally:
            if callback is not None:
                self._lib.ssao_job_set_progress(self._job, _PROGRESS_FN(), None)

    def last_run(self):
        """(geometry_pixels, mean_ao) of the last successful run over the frame: the pixels the
        library's background rule took as geometry and their mean AO (ssao_job_last_run)."""
        geometry, mean = ctypes.c_size_t(), ctypes.c_double()
        self._lib.ssao_job_last_run(self._job, ctypes.byref(geometry), ctypes.byref(mean))
        return geometry.value, mean.value
