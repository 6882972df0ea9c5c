"""Box2D 2.3 through pybox2d (float32). Settings: velocity_iterations (default 8), position_iterations
(default 3). Sleep off (doSleep=False and allowSleep=False per body); continuous physics on (its
default); the 1 m/s restitution velocity threshold is compiled in (b2_velocityThreshold). Restitution
mixes by max, friction by sqrt(a*b)."""
from __future__ import annotations

from typing import Any

import numpy as np

from .base import Engine


class Box2D2(Engine):
    name = "box2d2"
    precision = "float32"

    def __init__(self, scene: Any, settings: dict[str, Any]) -> None:
        super().__init__(scene, settings)
        import Box2D as B
        self.world = w = B.b2World(gravity=(0.0, -scene.gravity), doSleep=False)
        w.continuousPhysics = bool(settings.get("continuous", True))
        self.vi = int(settings.get("velocity_iterations", 8))
        self.pi = int(settings.get("position_iterations", 3))
        self.bodies = []
        for b in scene.boxes:
            shape = B.b2PolygonShape(box=(b.w / 2, b.h / 2))
            if b.static:
                w.CreateStaticBody(position=(b.x, b.y), angle=b.angle,
                                   fixtures=B.b2FixtureDef(shape=shape, friction=scene.mu, restitution=scene.e))
                continue
            body = w.CreateDynamicBody(position=(b.x, b.y), angle=b.angle, linearVelocity=(b.vx, b.vy),
                                       angularVelocity=b.omega, allowSleep=False,
                                       fixtures=B.b2FixtureDef(shape=shape, density=b.mass / (b.w * b.h),
                                                               friction=scene.mu, restitution=scene.e))
            self.bodies.append(body)

    def step(self, dt: float) -> None:
        self.world.Step(dt, self.vi, self.pi)

    def advance(self, dt: float, steps: int) -> float:
        import time
        f, vi, pi = self.world.Step, self.vi, self.pi
        t0 = time.thread_time()
        for _ in range(steps):
            f(dt, vi, pi)
        return time.thread_time() - t0

    def states(self) -> np.ndarray:
        # pybox2d has no batch getter; this read happens outside the timed step loop.
        out = np.empty((len(self.bodies), 6))
        for k, b in enumerate(self.bodies):
            c, v = b.worldCenter, b.linearVelocity
            out[k] = (c[0], c[1], b.angle, v[0], v[1], b.angularVelocity)
        return out
