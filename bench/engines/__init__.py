"""One small adapter per engine, all with the interface of base.Engine."""
from __future__ import annotations

from .base import Engine

ENGINES = ("libcollide", "pymunk", "box2d3", "box2d2")


def make(name: str, scene, settings: dict | None = None) -> Engine:
    """Build `scene` in engine `name` with extra `settings` (engine-specific, see each module)."""
    settings = dict(settings or {})
    if name == "libcollide":
        from .libcollide import LibCollide as cls
    elif name == "pymunk":
        from .pymunk_engine import Pymunk as cls
    elif name == "box2d3":
        from .box2d3 import Box2D3 as cls
    elif name == "box2d2":
        from .box2d2 import Box2D2 as cls
    else:
        raise ValueError(f"unknown engine {name!r}; known: {', '.join(ENGINES)}")
    return cls(scene, settings)
