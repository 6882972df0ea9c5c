"""collide: Python binding of libcollide (cffi, API mode), scenes and a headless runner.

    from collide import World, load_scene, default_scene
    w = default_scene(blocks=2).build()
    w.step(0.01)
    w.state        # (n, 6) read-only zero-copy numpy view: x, y, angle, vx, vy, omega

Names are loaded on first use, so `python -m collide.build_ffi` runs without the extension.
"""
from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "CollideError": "_ffi", "status_name": "_ffi",
    "Scene": "scene", "SceneError": "scene", "default_scene": "scene", "load_scene": "scene",
    "World": "world", "Energy": "world", "WALL_NAMES": "world",
    "Body": "body", "Spring": "body", "Thruster": "body",
    "CONTACT_DTYPE": "_views", "COLLISION": "_views", "RESTING": "_views",
    "EVENT_DTYPE": "_views", "IMPACT_EVENT": "_views", "IMPACT_CONTACT": "_views",
    "RayHit": "query", "BodyDistance": "query",
    "ForceQuery": "force",
}
__all__ = sorted(_EXPORTS) + ["version"]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'collide' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__


def version() -> str:
    """Version string of the loaded C library."""
    from ._ffi import ffi, lib
    return ffi.string(lib.lc_version()).decode()
