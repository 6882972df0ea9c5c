"""Zero-copy, read-only numpy views of C memory, and the structured dtypes of lc_contact and
lc_impact_event."""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import DTypeLike

from ._ffi import ffi, lib

COLLISION = int(lib.LC_CONTACT_COLLISION)
RESTING = int(lib.LC_CONTACT_RESTING)
IMPACT_EVENT = int(lib.LC_IMPACT_EVENT)      # an impact the event regime resolved at its own time
IMPACT_CONTACT = int(lib.LC_IMPACT_CONTACT)  # an impact the contact regime resolved at a (sub-)step's start


def _struct_dtype(ctype: str, fields: dict[str, Any]) -> np.dtype:
    """Structured dtype with the exact offsets and size of the C struct ctype."""
    c_fields = [name for name, _ in ffi.typeof(ctype).fields]
    if c_fields != list(fields):
        raise ImportError(f"{ctype} fields changed: {c_fields}; update collide._views")
    return np.dtype({
        "names": list(fields),
        "formats": list(fields.values()),
        "offsets": [ffi.offsetof(ctype, n) for n in fields],
        "itemsize": ffi.sizeof(ctype),
    })


CONTACT_DTYPE = _struct_dtype("lc_contact", {
    "body_a": np.uint32, "body_b": np.uint32, "point": (np.float64, (2,)), "normal": (np.float64, (2,)),
    "gap": np.float64, "normal_velocity": np.float64, "impulse": np.float64,
    "tangent_impulse": np.float64, "force": np.float64, "time": np.float64,
    "kind": np.dtype(f"i{ffi.sizeof('lc_contact_kind')}"),
})

EVENT_DTYPE = _struct_dtype("lc_impact_event", {
    "time": np.float64, "body_a": np.uint32, "body_b": np.uint32, "point": (np.float64, (2,)),
    "normal": (np.float64, (2,)), "gap": np.float64, "normal_impulse": np.float64,
    "tangent_impulse": np.float64, "approach_speed": np.float64, "kind": np.dtype(f"i{ffi.sizeof('lc_impact_kind')}"),
})


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
