"""Box2D v3 through pyb2d3 (float32). Settings: substeps (default 4), restitution_threshold (default
here 0: Box2D's 1 m/s kills slow e = 1 bounces; "thr1" variants keep 1), contact_hertz,
continuous (default on, Box2D's default). Sleep is disabled world-wide. Box2D mixes restitution by
max and friction by sqrt(a*b): both give e and mu exactly in a one-material scene."""
from __future__ import annotations

from typing import Any

import numpy as np

from .base import Engine


class Box2D3(Engine):
    name = "box2d3"
    precision = "float32"

    def __init__(self, scene: Any, settings: dict[str, Any]) -> None:
        super().__init__(scene, settings)
        import pyb2d3 as b2
        kw: dict[str, Any] = {"gravity": (0.0, -scene.gravity),
                              "restitution_threshold": float(settings.get("restitution_threshold", 0.0))}
        if "contact_hertz" in settings:
            kw["contact_hertz"] = float(settings["contact_hertz"])
        self.world = w = b2.World(**kw)
        w.sleeping_enabled = False
        w.continuous_enabled = bool(settings.get("continuous", True))
        self.substeps = int(settings.get("substeps", 4))
        self.batch = b2.Bodies()
        for b in scene.boxes:
            mat = b2.surface_material(restitution=scene.e, friction=scene.mu)
            if b.static:
                body = w.create_static_body(position=(b.x, b.y), rotation=b.angle)
                body.create_polygon_shape(b2.shape_def(material=mat), b2.box(b.w / 2, b.h / 2))
                continue
            body = w.create_dynamic_body(position=(b.x, b.y), rotation=b.angle, linear_velocity=(b.vx, b.vy),
                                         angular_velocity=b.omega, enable_sleep=False)
            body.create_polygon_shape(b2.shape_def(density=b.mass / (b.w * b.h), material=mat),
                                      b2.box(b.w / 2, b.h / 2))
            self.batch.append(body)

    def step(self, dt: float) -> None:
        self.world.step(dt, self.substeps)

    def advance(self, dt: float, steps: int) -> float:
        import time
        f, n = self.world.step, self.substeps
        t0 = time.thread_time()
        for _ in range(steps):
            f(dt, n)
        return time.thread_time() - t0

    def states(self) -> np.ndarray:
        p = self.batch.get_positions().astype(np.float64)
        r = self.batch.get_rotations().astype(np.float64)
        v = self.batch.get_linear_velocities().astype(np.float64)
        w = self.batch.get_angular_velocities().astype(np.float64)
        return np.column_stack([p, np.arctan2(r[:, 1], r[:, 0]), v, w])
