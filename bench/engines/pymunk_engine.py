"""Chipmunk2D 7 (Munk2D) through pymunk, float64. Settings: iterations (default 10), collision_slop
(default here 0.005 m: pymunk's 0.1 assumes pixels), collision_bias (pymunk default). Sleep is off
(pymunk's default sleep_time_threshold = inf). Chipmunk mixes e and mu by product, so each shape gets
sqrt(e) and sqrt(mu): every contact of a one-material scene then has exactly e and mu."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .base import Engine


class Pymunk(Engine):
    name = "pymunk"

    def __init__(self, scene: Any, settings: dict[str, Any]) -> None:
        super().__init__(scene, settings)
        import pymunk
        import pymunk.batch as pb
        self._pb = pb
        sp = pymunk.Space()
        sp.gravity = (0.0, -scene.gravity)
        sp.iterations = int(settings.get("iterations", 10))
        sp.collision_slop = float(settings.get("collision_slop", 0.005))
        if "collision_bias" in settings:
            sp.collision_bias = float(settings["collision_bias"])
        sp.sleep_time_threshold = math.inf
        e, mu = math.sqrt(scene.e), math.sqrt(scene.mu)
        ids = []
        for b in scene.boxes:
            if b.static:
                body = pymunk.Body(body_type=pymunk.Body.STATIC)
            else:
                body = pymunk.Body(b.mass, b.inertia)
            body.position = (b.x, b.y)
            body.angle = b.angle
            shape = pymunk.Poly.create_box(body, (b.w, b.h), radius=0.0)
            shape.elasticity, shape.friction = e, mu
            if not b.static:
                body.velocity = (b.vx, b.vy)
                body.angular_velocity = b.omega
                ids.append(body.id)
            sp.add(body, shape)
        self.space = sp
        self._ids = np.array(ids, dtype=np.uint64)
        self._buf = pb.Buffer()
        self._fields = (pb.BodyFields.BODY_ID | pb.BodyFields.POSITION | pb.BodyFields.ANGLE
                        | pb.BodyFields.VELOCITY | pb.BodyFields.ANGULAR_VELOCITY)
        self._order: np.ndarray | None = None

    def step(self, dt: float) -> None:
        self.space.step(dt)

    def states(self) -> np.ndarray:
        self._buf.clear()
        self._pb.get_space_bodies(self.space, self._fields, self._buf)
        got_ids = np.frombuffer(self._buf.int_buf(), dtype=np.uintp).astype(np.uint64)
        data = np.frombuffer(self._buf.float_buf(), dtype=np.float64).reshape(len(got_ids), 6)
        if self._order is None or len(self._order) != len(self._ids):
            pos = {int(i): k for k, i in enumerate(got_ids)}
            self._order = np.array([pos[int(i)] for i in self._ids], dtype=np.intp)
        return np.array(data[self._order], dtype=np.float64)
