# SPDX-License-Identifier: MIT
"""What every area of the bindings shares: finding and loading liblidet_py.so, the status names and LidetError,
the C struct layouts and numpy records built on them, the ndpointer argument types, the one-time typing of a
group of entry points, the scan context and the capacities of the build, and the checks of points and per-point
arrays."""
from __future__ import annotations

import ctypes as C
import functools
import os
import pathlib
import weakref

import numpy as np

_ROOT = pathlib.Path(__file__).resolve().parents[3]
_loaded = None  #: the CDLL, once loaded
_status_names: dict | None = None


def _ptr(dtype):
    """ndpointer of a C-contiguous array of dtype."""
    return np.ctypeslib.ndpointer(dtype, flags="C_CONTIGUOUS")


f32p, i16p, i32p, i64p = _ptr(np.float32), _ptr(np.int16), _ptr(np.int32), _ptr(np.int64)
u8p, u16p, u32p, u64p = _ptr(np.uint8), _ptr(np.uint16), _ptr(np.uint32), _ptr(np.uint64)
V = C.c_void_p  #: a C object (scan context), or a struct passed by pointer (numpy record's address)


def opt(ptype):
    """ndpointer that also accepts None (NULL)."""
    class _Opt(ptype):  # type: ignore[misc, valid-type]
        @classmethod
        def from_param(cls, obj):
            return None if obj is None else ptype.from_param(obj)
    return _Opt


def _find_library() -> pathlib.Path:
    cands = []
    if os.environ.get("LIDET_LIB"):
        cands.append(pathlib.Path(os.environ["LIDET_LIB"]))
    if os.environ.get("LIDET_BUILD_DIR"):
        cands.append(pathlib.Path(os.environ["LIDET_BUILD_DIR"]) / "ports" / "python" / "liblidet_py.so")
    cands.append(_ROOT / "build" / "ports" / "python" / "liblidet_py.so")
    for c in cands:
        if c.exists():
            return c
    raise FileNotFoundError("liblidet_py.so not found (tried: " + ", ".join(map(str, cands)) +
                            "); build it with `make build` or set LIDET_LIB")


def lib():
    """The loaded shared library (loaded once), with the entry points of this module typed; each area of the
    bindings types its own with `entry_points`."""
    global _loaded
    if _loaded is None:
        L = C.CDLL(str(_find_library()))
        L.lidet_py_status_str.restype = C.c_char_p
        L.lidet_py_status_str.argtypes = [C.c_int]
        L.lidet_py_capacity.argtypes = [u32p]
        L.lidet_py_ctx_new.restype = V
        L.lidet_py_ctx_new.argtypes = []
        L.lidet_py_ctx_free.restype = None
        L.lidet_py_ctx_free.argtypes = [V]
        L.lidet_py_ctx_pixel_model.argtypes = [V, C.c_int, C.c_float]
        L.lidet_py_field.argtypes = [C.c_uint32, C.POINTER(C.c_char_p), C.POINTER(C.c_uint32),
                                     C.POINTER(C.c_char_p), C.POINTER(C.c_uint32), C.POINTER(C.c_uint32),
                                     C.POINTER(C.c_char)]
        _loaded = L
    return _loaded


def entry_points(setup):
    """Decorator of a function setup(L) that types a group of entry points: the decorated name becomes a function
    that returns lib() with them typed, setup running on its first call only (again after a setup that raised)."""
    done = False

    @functools.wraps(setup)
    def typed():
        nonlocal done
        L = lib()
        if not done:
            setup(L)
            done = True
        return L
    return typed


def status_names() -> dict:
    """{code: name} of every lidet_status_t, read from the C library's lidet_status_str ("NAME: text"), so the
    names are never copied by hand (codes -64..64; "unknown lidet status" marks the unused ones)."""
    global _status_names
    if _status_names is None:
        out = {}
        for code in range(-64, 65):
            txt = lib().lidet_py_status_str(code).decode()
            if txt.startswith("LIDET_") and ":" in txt:
                out[code] = txt.split(":", 1)[0]
        _status_names = out
    return dict(_status_names)


class LidetError(RuntimeError):
    """A negative lidet status."""

    def __init__(self, status: int, what: str):
        self.status = status
        self.name = status_names().get(status, f"status {status}")
        super().__init__(f"{what}: {lib().lidet_py_status_str(status).decode()}")


# ---- C structs as numpy records ------------------------------------------------------------------------------

_layouts: dict | None = None
_KIND = {("f", 4): "<f4", ("u", 1): "u1", ("u", 2): "<u2", ("u", 4): "<u4", ("i", 1): "i1", ("i", 2): "<i2",
         ("i", 4): "<i4"}


def struct_layouts() -> dict:
    """C struct name -> numpy structured dtype with the C field names, offsets and total size (from the
    C side's offsetof table, so it follows the header: nothing is kept in step by hand)."""
    global _layouts
    if _layouts is None:
        fields: dict = {}
        i = 0
        while True:
            t, f = C.c_char_p(), C.c_char_p()
            tsize, off, size, kind = C.c_uint32(), C.c_uint32(), C.c_uint32(), C.c_char()
            if lib().lidet_py_field(i, C.byref(t), C.byref(tsize), C.byref(f), C.byref(off), C.byref(size),
                                    C.byref(kind)) != 0:
                break
            ent = fields.setdefault(t.value.decode(), {"names": [], "formats": [], "offsets": [],
                                                      "itemsize": int(tsize.value)})
            ent["names"].append(f.value.decode())
            ent["formats"].append(_KIND[(kind.value.decode(), int(size.value))])
            ent["offsets"].append(int(off.value))
            i += 1
        _layouts = {k: np.dtype(v) for k, v in fields.items()}
    return _layouts


def record(type_name: str, values: dict | None = None) -> np.ndarray:
    """A zeroed C struct (numpy record, shape (1,)) with `values` set by field name."""
    dt = struct_layouts()[type_name]
    rec = np.zeros(1, dt)
    for k, v in (values or {}).items():
        if k not in dt.names:
            raise TypeError(f"{type_name} has no field {k!r}")
        rec[k] = _checked(type_name, k, v, dt[k])
    return rec


def _checked(type_name: str, field: str, v, dtype: np.dtype):
    """A value for a C field, refused with a clear message instead of a silent cast: integer fields take
    integers (or integral floats) in range, float fields finite numbers (a NaN or a string would otherwise
    become garbage or undefined behaviour on the C side)."""
    where = f"{type_name}.{field}"
    if isinstance(v, (bool, np.bool_)):
        v = int(v)
    if isinstance(v, (str, bytes)) or not np.isscalar(v) or not isinstance(v, (int, float, np.number)):
        raise TypeError(f"{where}: expected a number, got {v!r}")
    if dtype.kind == "f":
        if not np.isfinite(v):
            raise ValueError(f"{where}: {v!r} is not finite")
        return v
    if not np.isfinite(v) or float(v) != int(v):
        raise ValueError(f"{where}: expected an integer, got {v!r}")
    info = np.iinfo(dtype)
    if not info.min <= int(v) <= info.max:
        raise ValueError(f"{where}: {v!r} outside [{info.min}, {info.max}]")
    return int(v)


def to_dict(rec: np.ndarray) -> dict:
    """A record of `record` as {field: int or float}."""
    return {k: (float(rec[k][0]) if rec.dtype[k].kind == "f" else int(rec[k][0])) for k in rec.dtype.names}


def addr(rec: np.ndarray) -> int:
    """The address of a record, for an entry point that takes the struct by pointer."""
    return rec.ctypes.data


# ---- the scan context and the build's capacities -----------------------------------------------------------

#: pixel models of lidet_py_ctx_pixel_model (what a more compact pixel would hand the stages)
PIXEL_MODELS = {"float": 0, "s16": 1, "recompute": 2, "real_elev": 3, "real_azimuth": 4}


class ScanContext:
    """One scan's C states (lidet_py_ctx_t): the projection, ground and clustering of that scan only.
    Freed when the last object referring to it goes away.

    pixel_model (measurement only, docs/journal/memory.md, "What a compact pixel would cost"): after each projection
    the image is rewritten as a
    pixel stored another way would decode: "float" (the library), "s16" (x, y, z, range rounded to
    multiples of q_m), "recompute" (x, y, z from the range, the beam's elevation and the column
    centre), "real_elev" / "real_azimuth" (one of the two angles kept exact)."""

    def __init__(self, pixel_model: str = "float", q_m: float = 0.004):
        self.ptr = lib().lidet_py_ctx_new()
        if not self.ptr:
            raise MemoryError("lidet_py_ctx_new")
        weakref.finalize(self, lib().lidet_py_ctx_free, self.ptr)
        if pixel_model != "float":
            st = lib().lidet_py_ctx_pixel_model(self.ptr, PIXEL_MODELS[pixel_model], q_m)
            if st < 0:
                raise LidetError(st, "lidet_py_ctx_pixel_model")


def capacity() -> dict:
    """Compile-time capacities of the built library (lidet_opt.h)."""
    out = np.zeros(6, np.uint32)
    lib().lidet_py_capacity(out)
    keys = ["max_rows", "max_cols", "max_points", "max_clusters", "proposal_points", "max_detections"]
    return dict(zip(keys, map(int, out)))


# ---- input checks --------------------------------------------------------------------------------------------

#: most floats per point record the bindings accept (x, y, z, remission and a few extra channels)
MAX_STRIDE = 16


def as_points(points) -> tuple[np.ndarray, int]:
    """(N, 3..MAX_STRIDE) numeric points -> (C-contiguous float32 copy or view, stride)."""
    arr = np.asarray(points)
    if arr.dtype.kind not in "fiu":
        raise TypeError(f"points must be numeric, got dtype {arr.dtype}")
    if arr.ndim != 2 or not 3 <= arr.shape[1] <= MAX_STRIDE:
        hint = " (transposed? points are rows)" if arr.ndim == 2 and 3 <= arr.shape[0] <= MAX_STRIDE else ""
        raise ValueError(f"points must be (N, 3..{MAX_STRIDE}): x, y, z first; got shape {arr.shape}{hint}")
    return np.ascontiguousarray(arr, dtype=np.float32), arr.shape[1]


def as_per_point(values, n: int, what: str, dtype, lo: int, hi: int) -> np.ndarray:
    """(n,) integer values in [lo, hi]: booleans, integers, or floats that are whole numbers; anything else
    (strings, NaN, 3.7, 65539 for a uint16) is a ValueError, never a silent cast."""
    a = np.asarray(values)
    if a.shape != (n,):
        raise ValueError(f"{what} must have one entry per point ({n}), got shape {a.shape}")
    if a.dtype.kind == "b":
        a = a.astype(np.int64)
    elif a.dtype.kind == "f":
        if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
            raise ValueError(f"{what}: non-integer or non-finite values")
    elif a.dtype.kind not in "iu":
        raise TypeError(f"{what} must be integers or booleans, got dtype {a.dtype}")
    if n and (a.min() < lo or a.max() > hi):
        raise ValueError(f"{what}: values outside [{lo}, {hi}] (min {a.min()}, max {a.max()})")
    return np.ascontiguousarray(a, dtype=dtype)
