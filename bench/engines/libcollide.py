"""libcollide through its cffi binding. Settings: any lc_world_def field (e.g. toi_time_tolerance,
toi_distance_tolerance, impact_mode, integrator), and ``stage_timing`` (bool: fill the counters' time_*
fields, for the per-stage time shares; off in timed runs); damping is 0. Steps call the C function
directly."""
from __future__ import annotations

from typing import Any

import numpy as np

from .base import Engine


class LibCollide(Engine):
    name = "libcollide"

    def __init__(self, scene: Any, settings: dict[str, Any]) -> None:
        super().__init__(scene, settings)
        import collide
        from collide._ffi import lib
        self._lib = lib
        settings = dict(settings)
        timing = bool(settings.pop("stage_timing", False))
        self.world = collide.World(gravity=(0.0, -scene.gravity), damping=0.0, **settings)
        self.world.set_stage_timing(timing)
        rows = []
        for k, b in enumerate(scene.boxes):
            body = self.world.add_box(b.w, b.h, position=(b.x, b.y), angle=b.angle, velocity=(b.vx, b.vy),
                                      angular_velocity=b.omega, mass=b.mass, elasticity=scene.e,
                                      friction=scene.mu, static=b.static)
            if not b.static:
                rows.append(body.index)
        self._rows = np.array(rows, dtype=np.intp)
        self._w = self.world._w
        self.status = 0

    def step(self, dt: float) -> None:
        self._lib.lc_world_step(self._w, dt)

    def advance(self, dt: float, steps: int) -> float:
        import time
        f, w = self._lib.lc_world_step, self._w
        t0 = time.thread_time()
        for _ in range(steps):
            st = f(w, dt)
            if st:
                self.status = st
                break
        return time.thread_time() - t0

    def states(self) -> np.ndarray:
        return np.array(self.world.state[self._rows], dtype=np.float64)

    def stages(self) -> dict[str, Any]:
        return self.world.counters(last=False)
