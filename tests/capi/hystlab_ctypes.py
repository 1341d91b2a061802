"""hystlab's C API from Python, with ctypes only (no packages): what capi_python drives the C
API with. (It was the Python example; the Python module, docs/PYTHON.md, replaced it there.)

    from hystlab_ctypes import Model
    with Model("table.json") as m:          # an Everett table or simplified-model parameters
        forces = m.evaluate([0.0, 1.0, 2.0, 1.5])

The library is libhystlab.so: found through $HYSTLAB_LIBRARY, or the system's loader path.
"""
import ctypes
import ctypes.util
import os

_STATUS = {0: "ok", 1: "argument", 2: "io", 3: "format", 4: "memory"}


class HystlabError(Exception):
    """A failed call: the status name and the library's message."""


def load_library(path=None):
    path = path or os.environ.get("HYSTLAB_LIBRARY") or ctypes.util.find_library("hystlab") or "libhystlab.so"
    lib = ctypes.CDLL(path)
    model_pp = ctypes.POINTER(ctypes.c_void_p)
    lib.hystlab_version.restype = ctypes.c_char_p
    lib.hystlab_last_error.restype = ctypes.c_char_p
    lib.hystlab_model_load.argtypes = [ctypes.c_char_p, model_pp]
    lib.hystlab_model_from_json.argtypes = [ctypes.c_char_p, model_pp]
    lib.hystlab_model_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.POINTER(ctypes.c_double)]
    lib.hystlab_model_evaluate.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double),
                                           ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
    lib.hystlab_model_reset.argtypes = [ctypes.c_void_p]
    lib.hystlab_model_copy.argtypes = [ctypes.c_void_p, model_pp]
    lib.hystlab_model_free.argtypes = [ctypes.c_void_p]
    lib.hystlab_model_free.restype = None
    lib.hystlab_model_saturations.argtypes = [ctypes.c_void_p]
    lib.hystlab_model_saturations.restype = ctypes.c_uint64
    for f in ("hystlab_model_load", "hystlab_model_from_json", "hystlab_model_step", "hystlab_model_evaluate",
              "hystlab_model_reset", "hystlab_model_copy"):
        getattr(lib, f).restype = ctypes.c_int
    return lib


class Model:
    """One model instance: its memory of the input's history is its own."""

    def __init__(self, source=None, json_text=None, library=None, _handle=None):
        self._lib = library or load_library()
        self._h = ctypes.c_void_p(_handle)
        if _handle is None:
            if json_text is not None:
                self._check(self._lib.hystlab_model_from_json(json_text.encode(), ctypes.byref(self._h)))
            else:
                self._check(self._lib.hystlab_model_load(os.fsencode(source), ctypes.byref(self._h)))

    def _check(self, status):
        if status != 0:
            raise HystlabError("%s: %s" % (_STATUS.get(status, status), self._lib.hystlab_last_error().decode()))

    def step(self, x):
        f = ctypes.c_double()
        self._check(self._lib.hystlab_model_step(self._h, x, ctypes.byref(f)))
        return f.value

    def evaluate(self, xs):
        n = len(xs)
        x = (ctypes.c_double * n)(*xs)
        f = (ctypes.c_double * n)()
        self._check(self._lib.hystlab_model_evaluate(self._h, x, f, n))
        return list(f)

    def reset(self):
        self._check(self._lib.hystlab_model_reset(self._h))

    def copy(self):
        h = ctypes.c_void_p()
        self._check(self._lib.hystlab_model_copy(self._h, ctypes.byref(h)))
        return Model(library=self._lib, _handle=h.value)

    @property
    def saturations(self):
        return self._lib.hystlab_model_saturations(self._h)

    def close(self):
        if self._h:
            self._lib.hystlab_model_free(self._h)
            self._h = ctypes.c_void_p()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()
