"""Python-side argument checks: wrong types fail here with a clear message, before any C call.
Values of the right type (NaN included) go to C, which owns the range rules and their messages."""
from __future__ import annotations

import numbers
from typing import Any

import numpy as np


def real(value: Any, what: str) -> float:
    if type(value) is float:  # the common case, without the ABC checks (scene loads call this per field)
        return value
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what} must be a real number, got {type(value).__name__} {value!r}")
    return float(value)


def integer(value: Any, what: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{what} must be an integer, got {type(value).__name__} {value!r}")
    return int(value)


def flag(value: Any, what: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{what} must be True or False, got {type(value).__name__} {value!r}")
    return bool(value)


def vec2(value: Any, what: str) -> tuple[float, float]:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{what} must be a pair of numbers (x, y), got {type(value).__name__} {value!r}")
    if len(value) != 2:
        raise ValueError(f"{what} must have exactly 2 components (x, y), got {len(value)}")
    return real(value[0], f"{what}[0]"), real(value[1], f"{what}[1]")


def points(value: Any, what: str) -> np.ndarray:
    """A (k, 2) float64 C-contiguous array from a sequence of (x, y) pairs."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{what} must be a sequence of (x, y) pairs, got {type(value).__name__}")
    if len(value) == 0:
        return np.zeros((0, 2))
    try:
        arr = np.asarray(value)
    except ValueError as exc:  # ragged nesting
        raise ValueError(f"{what} must be a sequence of (x, y) pairs: {exc}") from None
    if arr.dtype.kind not in "iuf" or arr.dtype == np.bool_:
        raise TypeError(f"{what} must hold numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{what} must have shape (k, 2), got {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float64)


def name(value: Any, what: str = "name") -> str:
    if not isinstance(value, str):
        raise TypeError(f"{what} must be a string, got {type(value).__name__} {value!r}")
    if not value.strip():
        raise ValueError(f"{what} must not be empty")
    return value
