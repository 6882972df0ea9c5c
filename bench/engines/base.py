"""Common adapter interface: build a neutral scene, step(dt), read states as numpy arrays."""
from __future__ import annotations

import time
from typing import Any

import numpy as np


class Engine:
    """Subclasses build `scene` in __init__ and implement step() and states()."""

    name = "engine"
    precision = "float64"

    def __init__(self, scene: Any, settings: dict[str, Any]) -> None:
        self.scene = scene
        self.settings = settings

    def step(self, dt: float) -> None:
        raise NotImplementedError

    def advance(self, dt: float, steps: int) -> float:
        """Take `steps` steps of dt; returns the CPU time (s) of this thread spent in them."""
        step = self.step
        t0 = time.thread_time()
        for _ in range(steps):
            step(dt)
        return time.thread_time() - t0

    def states(self) -> np.ndarray:
        """(n_dynamic, 6) float64: x, y, angle, vx, vy, omega of each dynamic box's centre, scene order."""
        raise NotImplementedError

    def stages(self) -> dict[str, Any]:
        """Pipeline work counters, where the engine exposes them ({} otherwise)."""
        return {}

    def close(self) -> None:
        pass
