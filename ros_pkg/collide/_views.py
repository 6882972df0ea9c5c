"""Zero-copy, read-only numpy views of C memory, and the structured dtype of lc_contact."""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import DTypeLike

from ._ffi import ffi, lib

COLLISION = int(lib.LC_CONTACT_COLLISION)
RESTING = int(lib.LC_CONTACT_RESTING)


def _contact_dtype() -> np.dtype:
    """Structured dtype with the exact offsets and size of C's lc_contact."""
    kind_size = ffi.sizeof("lc_contact_kind")
    fields = {
        "body_a": np.uint32, "body_b": np.uint32, "point": (np.float64, (2,)), "normal": (np.float64, (2,)),
        "gap": np.float64, "normal_velocity": np.float64, "impulse": np.float64,
        "tangent_impulse": np.float64, "force": np.float64, "time": np.float64,
        "kind": np.dtype(f"i{kind_size}"),
    }
    c_fields = [name for name, _ in ffi.typeof("lc_contact").fields]
    if c_fields != list(fields):
        raise ImportError(f"lc_contact fields changed: {c_fields}; update collide.world")
    return np.dtype({
        "names": list(fields),
        "formats": list(fields.values()),
        "offsets": [ffi.offsetof("lc_contact", n) for n in fields],
        "itemsize": ffi.sizeof("lc_contact"),
    })


CONTACT_DTYPE = _contact_dtype()


class _Keeper:
    """Holds the owner of C memory so a numpy view built on it keeps that owner alive."""

    __slots__ = ("__array_interface__", "owner")

    def __init__(self, owner: Any, address: int, shape: tuple[int, ...], dtype: np.dtype) -> None:
        self.owner = owner
        descr = dtype.descr if dtype.names else [("", dtype.str)]
        self.__array_interface__ = {"shape": shape, "typestr": dtype.str, "descr": descr,
                                    "data": (address, True), "version": 3}


def _view(owner: Any, ptr: Any, shape: tuple[int, ...], dtype: DTypeLike) -> np.ndarray:
    """Read-only zero-copy ndarray over C memory at ptr."""
    dtype = np.dtype(dtype)
    if ptr == ffi.NULL or 0 in shape:
        out = np.zeros(shape, dtype=dtype)
        out.flags.writeable = False
        return out
    arr = np.asarray(_Keeper(owner, int(ffi.cast("uintptr_t", ptr)), shape, dtype))
    if dtype.names and arr.dtype != dtype:  # descr round-trip may drop padding info; re-view
        arr = arr.view(dtype)
    return arr


# ---- enums: names derived from the C enum constants (LC_INTEGRATOR_RK4 -> "rk4") ----------------
