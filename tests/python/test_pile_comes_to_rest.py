"""A dropped pile comes to rest: the contact bench's 100-box mixed pile of seed 5 (bench/scenes.py
mixed_boxes: boxes 0.3-0.8 m, mu 0.5, e 0.3, dropped into a walled box, dt 1/60).

This pile is the case for the pile rule (docs/contact_regime.md, stopping rule; tunables.h
LC_CONTACT_PILE_FLOW_FRACTION): moving at centimetres a second, slower than gravity changes a velocity in
a step, its flow solves stopped at contact_iterations sweeps keep an error the size of its motion, its
friction holds too little and it flows on as a slow avalanche (3-37 cm/s rms up to 11 s). Box2D v3's pile
of the same scene rests by 6 s (bench/repro/pile_rest.py).

Asserted over 12 s: no step gains more than 1e-9 of the total energy (nothing drives the scene), and the
pile rests: over the last 2 s every body's velocity is exactly 0 and no coordinate changes by a single
bit (docs/contact_regime.md, "Settling and rest")."""
from __future__ import annotations

import numpy as np

import collide
from bench_module import load_bench

sc = load_bench("scenes")

DT = 1.0 / 60.0
SECONDS = 12
LAST = 2 * 60          # steps: the last 2 s
GAIN_TOL = 1e-9        # the bound on one step's gain in a dissipative scene


def energy(world: collide.World, rows: np.ndarray, m: np.ndarray, inertia: np.ndarray, g: float) -> float:
    """Kinetic plus gravitational energy of the dynamic rows (J)."""
    st = np.asarray(world.state)[rows]
    return float(0.5 * (m * (st[:, 3] ** 2 + st[:, 4] ** 2)).sum() + 0.5 * (inertia * st[:, 5] ** 2).sum()
                 + (m * g * st[:, 1]).sum())


def test_mixed_pile_of_seed_5_comes_to_rest() -> None:
    scene = sc.mixed_boxes(100, seed=5)
    world = collide.World(gravity=(0.0, -scene.gravity), damping=0.0)
    rows = []
    for b in scene.boxes:
        body = world.add_box(b.w, b.h, position=(b.x, b.y), angle=b.angle, velocity=(b.vx, b.vy),
                             angular_velocity=b.omega, mass=b.mass, elasticity=scene.e, friction=scene.mu,
                             static=b.static)
        if not b.static:
            rows.append(body.index)
    idx = np.array(rows, dtype=np.intp)
    m = np.array(world.masses[idx])
    inertia = np.array(world.inertias[idx])
    e_prev = energy(world, idx, m, inertia, scene.gravity)
    worst = -np.inf
    last_states = []
    steps = SECONDS * 60
    for k in range(steps):
        world.step(DT)
        e = energy(world, idx, m, inertia, scene.gravity)
        worst = max(worst, (e - e_prev) / abs(e_prev))
        e_prev = e
        if k >= steps - LAST - 1:
            last_states.append(np.array(world.state[idx], dtype=np.float64))
    assert worst <= GAIN_TOL, f"a step gained {worst:.3g} of the energy"
    moving = int(np.count_nonzero(np.stack(last_states)[:, :, 3:]))
    changed = int(sum(np.count_nonzero(s[:, :3] != last_states[0][:, :3]) for s in last_states))
    assert moving == 0, f"{moving} velocity components were not 0 over the last 2 s"
    assert changed == 0, f"{changed} coordinates changed over the last 2 s"
