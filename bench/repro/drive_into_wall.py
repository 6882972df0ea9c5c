"""What the engine takes when a body is driven into a wall: the measurement behind the node's ranges of
max_thrust, green_mass, time_step and damping (docs/ros_interface.md, "What the ranges guarantee").

    source scripts/env.sh && python bench/repro/drive_into_wall.py        # about a minute

The engine alone (Python binding, no node, so no split steps): the default scene with two blocks,
block1 of mass m pushed towards the right wall (block2, 1 kg, in between) by a world-frame force F and a
torque of F N*m, held for 1 s of sim time (at least 20 steps) at time step dt. Per case: "ok", "undone k"
(k steps C refused and undid: the body is too fast or spins too fast for dt), or "ESCAPED" (a body centre
left the walls' inner box, [-6, 6]^2, without an error). Then damping k alone on a moving block of mass
m: C integrates the damping force with RK4, stable for k * dt / m up to 2.785; beyond it every step gains
energy and is undone.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "ros_pkg"))

import collide  # noqa: E402
from collide import CollideError  # noqa: E402

FORCES = (1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9)
MASSES = (0.001, 0.1, 1.0, 1000.0)
STEPS = (1e-3, 1e-2, 1e-1)
INNER = 6.0  # m: the default scene's walls' inner faces at x, y = +-6


def drive(force: float, mass: float, dt: float, seconds: float = 1.0) -> str:
    w = collide.default_scene(blocks=2, green_mass=mass).build()
    body = w.body("block1")
    dynamic = ~np.array(w.static_mask, dtype=bool)
    undone = 0
    for _ in range(max(20, int(round(seconds / dt)))):
        body.set_external((force, 0.0), force)
        try:
            w.step(dt)
        except CollideError:
            undone += 1
        centres = w.state[dynamic, :2]
        if not np.all(np.abs(centres) <= INNER):
            return "ESCAPED"
    return f"undone {undone}" if undone else "ok"


def damping_verdict(ratio: float, mass: float, dt: float) -> str:
    w = collide.default_scene(blocks=1, green_mass=mass).build()
    w.set_damping(ratio * mass / dt)
    w.body("block1").set_velocity((10.0, 3.0), 5.0)
    undone = 0
    for _ in range(100):
        try:
            w.step(dt)
        except CollideError:
            undone += 1
    return f"undone {undone}" if undone else "ok"


def main() -> int:
    for dt in STEPS:
        print(f"\ntime step {dt:g} s: F (N, and torque F N*m) on block1 of mass m, 1 s into the right wall\n")
        print("| F \\ m | " + " | ".join(f"{m:g} kg" for m in MASSES) + " |")
        print("|---" * (len(MASSES) + 1) + "|")
        for f in FORCES:
            print(f"| {f:.0e} | " + " | ".join(drive(f, m, dt) for m in MASSES) + " |", flush=True)
    print("\ndamping k = ratio * m / dt on a moving block of mass m (100 steps)\n")
    cases = ((0.001, 1e-3), (0.1, 1e-2), (1.0, 1e-2))
    print("| k*dt/m | " + " | ".join(f"m {m:g}, dt {dt:g}" for m, dt in cases) + " |")
    print("|---" * (len(cases) + 1) + "|")
    for ratio in (1.0, 2.0, 2.7, 2.9, 5.0):
        print(f"| {ratio:g} | " + " | ".join(damping_verdict(ratio, m, dt) for m, dt in cases) + " |", flush=True)
    print("\n(RK4 is stable on the real axis for k*dt/m up to 2.785)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
