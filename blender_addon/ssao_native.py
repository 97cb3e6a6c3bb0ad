# SPDX-License-Identifier: MIT
"""ctypes binding to libssao's C API (core/include/ssao/ssao.h).

No bpy import: usable from plain Python (tests, scripts) and from Blender alike. Images are
numpy float32 arrays of shape (height, width) or (height, width, channels), row 0 on top; any
strides are passed through, so views into larger arrays are read in place.
"""
import ctypes
import os
import sys

ABI_MAJOR = 0

_LIB_NAMES = {"linux": "libssao.so", "darwin": "libssao.dylib", "win32": "ssao.dll"}


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


def _candidate_paths(path):
    if path:
        yield path
    if os.environ.get("SSAO_LIBRARY"):
        yield os.environ["SSAO_LIBRARY"]
    here = os.path.dirname(os.path.abspath(__file__))
    name = _LIB_NAMES.get(sys.platform, "libssao.so")
    yield os.path.join(here, "lib", name)
    yield os.path.join(here, "..", "build", "lib", name)


def load_library(path=None):
    """Loads libssao (explicit path, $SSAO_LIBRARY, the add-on's lib/, or build/lib/)."""
    errors = []
    for candidate in _candidate_paths(path):
        if not os.path.exists(candidate):
            errors.append(f"{candidate}: not found")
            continue
        lib = ctypes.CDLL(candidate)
        _declare(lib)
        version = lib.ssao_version()
        if version // 10000 != ABI_MAJOR:
            raise SSAOError(f"{candidate} is libssao {version}, this binding needs {ABI_MAJOR}.x")
        return lib
    raise SSAOError("libssao not found: " + "; ".join(errors))


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
    sig("ssao_job_set_image", c_int, job, cstr, ctypes.c_void_p, c_int, c_int, c_int,
        ctypes.c_ssize_t, ctypes.c_ssize_t)
    if hasattr(lib, "ssao_job_set_output_window"):  # since 0.1 after 7bf6fcd (overscan)
        sig("ssao_job_set_output_window", c_int, job, c_int, c_int, c_int)
    sig("ssao_job_set_progress", c_int, job, _PROGRESS_FN, ctypes.c_void_p)
    sig("ssao_job_run", c_int, job)
    if hasattr(lib, "ssao_job_last_run"):  # since 0.1 after issue 23
        sig("ssao_job_last_run", c_int, job, ctypes.POINTER(ctypes.c_size_t),
            ctypes.POINTER(c_double))


def parameters(lib):
    """Returns the library's parameter table as a list of dicts (name, type, default, ...)."""
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


class Job:
    """One AO job. Use as a context manager or call close()."""

    def __init__(self, lib=None):
        self._lib = lib or load_library()
        handle = ctypes.c_void_p()
        self._lib.ssao_job_create(ctypes.byref(handle))
        self._job = handle
        self._images = {}  # keeps attached arrays alive until run() returns
        self._types = {p["name"]: p["type"] for p in parameters(self._lib)}

    def close(self):
        if self._job:
            self._lib.ssao_job_destroy(self._job)
            self._job = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def set(self, name, value):
        """Sets a parameter; the type comes from the library's table."""
        kind = self._types.get(name)
        key = name.encode()
        if kind == PARAM_INT:
            self._lib.ssao_job_set_int(self._job, key, int(value))
        elif kind == PARAM_FLOAT:
            self._lib.ssao_job_set_float(self._job, key, float(value))
        elif kind == PARAM_STRING:
            self._lib.ssao_job_set_string(self._job, key, str(value).encode())
        elif kind == PARAM_FLOATS:
            values = [float(v) for v in value]
            array = (ctypes.c_double * len(values))(*values)
            self._lib.ssao_job_set_floats(self._job, key, array, len(values))
        else:
            # Let the library produce its "unknown parameter" message.
            self._lib.ssao_job_set_float(self._job, key, float("nan"))

    def set_image(self, name, array):
        """Attaches a float32 numpy array (H, W) or (H, W, C); None detaches."""
        if array is None:
            self._lib.ssao_job_set_image(self._job, name.encode(), None, 0, 0, 1, 0, 0)
            self._images.pop(name, None)
            return
        import numpy as np
        if array.dtype != np.float32:
            raise SSAOError(f"image '{name}' must be float32, got {array.dtype}")
        if array.ndim == 2:
            height, width = array.shape
            channels, pixel_stride = 1, array.strides[1]
        elif array.ndim == 3:
            height, width, channels = array.shape
            pixel_stride = array.strides[1]
            if array.strides[2] != 4:
                raise SSAOError(f"image '{name}': channels must be adjacent floats")
        else:
            raise SSAOError(f"image '{name}' must have 2 or 3 dimensions")
        self._lib.ssao_job_set_image(self._job, name.encode(), array.ctypes.data, width, height,
                                     channels, pixel_stride, array.strides[0])
        self._images[name] = array

    def set_output_window(self, x, y, enable=True):
        """Overscan: the outputs are the window at (x, y) of the depth image (ssao.h)."""
        self._lib.ssao_job_set_output_window(self._job, int(enable), int(x), int(y))

    def run(self, progress=None):
        """Runs the job. progress(fraction) may return False to cancel."""
        callback = None
        if progress is not None:
            callback = _PROGRESS_FN(lambda user, f: 0 if progress(f) is False else 1)
            self._lib.ssao_job_set_progress(self._job, callback, None)
        try:
            self._lib.ssao_job_run(self._job)
        finally:
            if callback is not None:
                self._lib.ssao_job_set_progress(self._job, _PROGRESS_FN(), None)

    def last_run(self):
        """(geometry_pixels, mean_ao) of the last successful run over the frame: the pixels the
        library's background rule took as geometry and their mean AO (ssao_job_last_run)."""
        geometry, mean = ctypes.c_size_t(), ctypes.c_double()
        self._lib.ssao_job_last_run(self._job, ctypes.byref(geometry), ctypes.byref(mean))
        return geometry.value, mean.value
