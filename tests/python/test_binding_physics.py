"""Physics through the Python binding, against closed forms. Tolerances follow the engine's documented
accuracy: RK4 is exact (to rounding) for the polynomial motion of constant forces; impacts are
handled at the time of impact with restitution from the true normal velocity (contact_gap 1e-7 m)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import collide
from collide import World

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def test_free_fall_parabola_matches_analytic() -> None:
    g = 9.81
    w = World(gravity=(0.0, -g))
    b = w.add_box(1.0, 0.5, position=(1.0, 2.0), velocity=(2.0, 5.0), angular_velocity=0.7, name="ball")
    s = w.state  # one view, read after every step without re-fetching
    for _ in range(100):
        w.step(0.01)
    t = w.time
    assert t == pytest.approx(1.0, abs=1e-12)
    x, y, a, vx, vy, om = s[b.index]
    # Constant acceleration: position is quadratic in t, so RK4 (and any closed-form advance) is
    # exact; what remains is rounding over 100 steps, far below 1e-9 m.
    assert x == pytest.approx(1.0 + 2.0 * t, abs=1e-9)
    assert y == pytest.approx(2.0 + 5.0 * t - 0.5 * g * t * t, abs=1e-9)
    assert a == pytest.approx(0.7 * t, abs=1e-9)
    assert (vx, vy, om) == pytest.approx((2.0, 5.0 - g * t, 0.7), abs=1e-9)
    assert w.counters(last=False)["collisions"] == 0


def test_thruster_force_through_python_matches_analytic() -> None:
    w = World(gravity=(0.0, 0.0))
    b = w.add_box(1.0, 1.0, mass=2.0, name="b")
    th = b.add_thruster((0.0, 0.0), (1.0, 0.0), 4.0)  # at the centre of mass: no torque
    th.level = 0.5  # 2 N on 2 kg: a = 1 m/s^2
    w.step(0.05, steps=20)
    t = w.time
    # constant force: exact under RK4 up to rounding
    assert b.position == pytest.approx((0.5 * t * t, 0.0), abs=1e-9)
    assert b.velocity == pytest.approx((t, 0.0), abs=1e-9)
    assert b.angular_velocity == pytest.approx(0.0, abs=1e-12)


def test_spring_oscillates_with_the_analytic_period() -> None:
    k, m, amp = 4.0, 1.0, 0.5
    w = World(gravity=(0.0, 0.0))
    b = w.add_box(1.0, 1.0, mass=m, position=(amp, 0.0), name="b")
    w.add_spring(b, (0.0, 0.0), None, (0.0, 0.0), stiffness=k)
    omega = math.sqrt(k / m)  # period 2*pi*sqrt(m/k) = pi s
    w.step(0.001, steps=1000)
    # RK4 global error ~ (omega*h)^4 * omega*t / 120 ~ 1e-13 here; 1e-6 m leaves room for any
    # order-4 scheme detail while still catching a wrong period (a 1 % error moves x by ~1e-2 m).
    assert b.position[0] == pytest.approx(amp * math.cos(omega * w.time), abs=1e-6)
    assert b.velocity[0] == pytest.approx(-amp * omega * math.sin(omega * w.time), abs=1e-6)
    e = w.energy
    assert e.total == pytest.approx(0.5 * k * amp * amp, rel=1e-6)


@pytest.mark.parametrize("m_b,v_b", [(3.0, -0.5), (1.0, 0.0)])
def test_head_on_impact_conserves_momentum_and_energy_at_e1(m_b: float, v_b: float) -> None:
    w = World(gravity=(0.0, 0.0))
    a = w.add_box(1.0, 1.0, position=(-2.0, 0.0), velocity=(1.0, 0.0), mass=1.0, name="a")
    b = w.add_box(1.0, 1.0, position=(2.0, 0.0), velocity=(v_b, 0.0), mass=m_b, name="b")
    p0, e0 = w.energy.linear_momentum, w.energy.total
    w.step(0.01, steps=400)  # faces 3 m apart: they meet at t = 2 s (3:1) or 3 s (1:1), before 4 s
    assert w.counters(last=False)["collisions"] >= 1
    # impulses are equal and opposite: momentum is conserved to rounding
    assert w.energy.linear_momentum == pytest.approx(p0, abs=1e-9)
    # e = 1 with the restitution taken from the true pre-impact normal velocity: energy to 1e-9
    # relative in principle; 1e-6 allows for the 1e-7 m contact gap of the impact position.
    assert w.energy.total == pytest.approx(e0, rel=1e-6)
    # 1D elastic collision (faces stay parallel, collinear top and bottom edges must not interfere)
    va = ((1.0 - m_b) * 1.0 + 2.0 * m_b * v_b) / (1.0 + m_b)
    vb = (2.0 * 1.0 + (m_b - 1.0) * v_b) / (1.0 + m_b)
    assert a.velocity == pytest.approx((va, 0.0), abs=1e-6)
    assert b.velocity == pytest.approx((vb, 0.0), abs=1e-6)
    assert abs(a.angular_velocity) < 1e-6 and abs(b.angular_velocity) < 1e-6


def test_energy_is_conserved_in_the_six_block_box_at_e1() -> None:
    w = collide.load_scene(SCENES / "six_blocks.json").build()
    e0 = w.energy.total
    w.step(0.01, steps=300)
    collisions = w.counters(last=False)["collisions"]
    assert collisions >= 3, "the scene must exercise impacts"
    # e = 1, no damping, no gravity: only integration/TOI rounding changes the energy. The engine
    # targets 1e-9 relative over 10 s; 1e-6 over 3 s is the acceptance bound.
    assert abs(w.energy.total - e0) / e0 < 1e-6
    assert np.isfinite(w.state).all()
    # nothing left the box [-6, 6]^2 (centres stay inside it)
    assert (np.abs(w.state[4:, :2]) < 6.0).all()
