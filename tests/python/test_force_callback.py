"""World.set_force_callback (collide/force.h through the binding): a constant force against the external
force (same bits), a spring law against the harmonic closed form at RK4's predicted error, mutual
gravitation with its potential (energy and momentum), and failures (NaN, exceptions, a wrong shape)
that undo the step and leave the world as it was."""
from __future__ import annotations

import gc
import math

import numpy as np
import pytest

from collide import CollideError, ForceQuery, World
from collide._ffi import lib


def thrown_box(damping: float = 0.3) -> tuple[World, str]:
    """A 1 x 0.5 box of 2 kg thrown (2 m/s, spin 1 rad/s) above a floor of elasticity 0.2."""
    w = World(damping=damping)
    w.add_box(20.0, 1.0, position=(0.0, -0.5), static=True, elasticity=0.2, name="floor")
    w.add_box(1.0, 0.5, position=(-2.0, 1.5), angle=0.3, velocity=(2.0, 0.5), angular_velocity=1.0, mass=2.0,
              elasticity=0.2, name="box")
    return w, "box"


def constant(force: tuple[float, float, float]):
    def law(q: ForceQuery) -> np.ndarray:
        out = np.zeros((len(q.state), 3))
        out[q.rows] = force
        return out
    return law


def test_constant_callback_force_is_the_external_force_bit_for_bit() -> None:
    # the callback's force is added right after the external force (forces.c): F + 0 and 0 + F are the
    # same bits, so with both bodies integrated alike (damping on) the worlds agree through impacts and
    # resting on the floor
    a, box_a = thrown_box()
    b, _ = thrown_box()
    a.body(box_a).set_external((3.0, -1.5), 0.25)
    b.set_force_callback(constant((3.0, -1.5, 0.25)))
    for _ in range(240):
        a.step(1.0 / 60.0)
        b.step(1.0 / 60.0)
        assert a.state_hash() == b.state_hash()
    assert a.counters(last=False)["collisions"] > 0


def test_the_query_holds_every_body_and_lists_dynamic_rows() -> None:
    w, _ = thrown_box()
    seen: list[ForceQuery] = []

    def law(q: ForceQuery) -> np.ndarray:
        seen.append(q)
        return np.zeros((len(q.state), 3))

    w.set_force_callback(law)
    w.step(1.0 / 60.0)
    assert seen
    q = seen[0]
    assert q.state.shape == (2, 6) and list(q.ids) == list(w.ids)
    assert list(q.static) == [True, False] and q.mass[1] == 2.0 and q.mass[0] == 0.0
    assert all(list(x.rows) == [1] for x in seen)
    # copies: a kept query still shows the state it was made at, which the step has since left
    np.testing.assert_array_equal(seen[0].state[1, :2], (-2.0, 1.5))
    assert w.state[1, 0] != -2.0


def harmonic_error(n: int) -> float:
    """Phase-space error (velocity over omega) after one period of x'' = -omega^2 x in n RK4 steps,
    relative to the amplitude 1 m: a 2 kg box on a spring k = 8 N/m to the origin (omega = 2 rad/s)."""
    m, omega = 2.0, 2.0
    k = m * omega ** 2
    w = World(gravity=(0.0, 0.0))
    w.add_box(1.0, 1.0, position=(1.0, 0.0), mass=m, name="b")

    def spring(q: ForceQuery) -> np.ndarray:
        out = np.zeros((len(q.state), 3))
        out[:, :2] = -k * q.state[:, :2]
        return out

    w.set_force_callback(spring)
    period = 2.0 * math.pi / omega
    w.step(period / n, n)
    x, y, _, vx, vy, _ = w.state[0]
    return math.sqrt((x - 1.0) ** 2 + y ** 2 + (vx / omega) ** 2 + (vy / omega) ** 2)


def test_spring_law_matches_the_harmonic_closed_form_at_rk4_accuracy() -> None:
    # RK4 on the oscillator (test_force_callback.c, harmonic_oscillator): over one period of n steps the
    # phase lags 2 pi (omega h)^4 / 120 and the amplitude shrinks n (omega h)^6 / 144; at n = 64 that is
    # 4.9e-6 of the amplitude, and the measured error is within 2 % of it (next terms: (omega h)^2 ~ 1 %)
    n = 64
    wh = 2.0 * math.pi / n
    predicted = math.hypot(2.0 * math.pi * wh ** 4 / 120.0, n * wh ** 6 / 144.0)
    e64, e128 = harmonic_error(64), harmonic_error(128)
    assert e64 == pytest.approx(predicted, rel=0.02)
    assert e64 / e128 == pytest.approx(16.0, rel=0.05)   # fourth order: the force is evaluated at every stage


def gravitation(G: float):
    def force(q: ForceQuery) -> np.ndarray:
        p, m = q.state[:, :2], np.where(q.static, 0.0, q.mass)
        d = p[None, :, :] - p[:, None, :]                  # d[i, j] = p_j - p_i
        r2 = (d ** 2).sum(axis=2)
        np.fill_diagonal(r2, 1.0)
        f = G * (m[:, None] * m[None, :]) / (r2 * np.sqrt(r2))
        np.fill_diagonal(f, 0.0)
        out = np.zeros((len(p), 3))
        out[:, :2] = (f[:, :, None] * d).sum(axis=1)
        return out

    def potential(q: ForceQuery) -> float:
        p, m = q.state[:, :2], np.where(q.static, 0.0, q.mass)
        i, j = np.triu_indices(len(p), 1)
        return float(-(G * m[i] * m[j] / np.hypot(*(p[j] - p[i]).T)).sum())

    return force, potential


def test_mutual_gravitation_conserves_energy_and_momentum() -> None:
    # relative orbit a = 2 m, e = 0.3 of 3 kg and 1 kg under G = 1 (period 4.44 s), 800 steps per period,
    # over one period. Energy: RK4's drift is below a period x (omega_p h)^4 x |U| with omega_p = 1.37 rad/s
    # the turn rate at pericentre (test_force_callback.c, mutual_gravitation): 7e-9 J, asserted 1e-8 J.
    # Momentum: the forces are equal and opposite at every stage, so it stays 0 up to round-off (a few
    # ulps of 2.2 kg m/s per step): 1e-11 kg m/s.
    G, m1, m2, ecc, a = 1.0, 3.0, 1.0, 0.3, 2.0
    M, rp = m1 + m2, a * (1.0 - ecc)
    period, vp = 2.0 * math.pi * math.sqrt(a ** 3 / (G * M)), math.sqrt(G * M * (1.0 + ecc) / rp)
    w = World(gravity=(0.0, 0.0))
    w.add_box(0.2, 0.2, position=(-rp * m2 / M, 0.0), velocity=(0.0, -vp * m2 / M), mass=m1)
    w.add_box(0.2, 0.2, position=(rp * m1 / M, 0.0), velocity=(0.0, vp * m1 / M), mass=m2)
    force, potential = gravitation(G)
    w.set_force_callback(force, potential)
    e0 = w.energy
    assert e0.callback == pytest.approx(-G * m1 * m2 / rp, rel=1e-15)
    assert e0.total == pytest.approx(e0.translational + e0.callback, rel=1e-15)
    swing = [e0.callback]
    for _ in range(16):
        w.step(period / 800, 50)
        e = w.energy
        swing.append(e.callback)
        assert abs(e.total - e0.total) < 1e-8
        assert math.hypot(*e.linear_momentum) < 1e-11
    assert max(swing) - min(swing) > 0.5   # the potential's part matters: without it total swings that much


@pytest.mark.parametrize("bad", ["nan", "raise", "shape"])
def test_a_failing_force_function_undoes_the_step(bad: str) -> None:
    w, _ = thrown_box()
    w.step(1.0 / 60.0, 10)
    calls = [0]

    def law(q: ForceQuery) -> np.ndarray:
        calls[0] += 1
        out = np.zeros((len(q.state), 3))
        if calls[0] == 3:
            if bad == "nan":
                out[q.rows[0], 1] = math.nan
            elif bad == "raise":
                raise ZeroDivisionError("the law divided by zero")
            else:
                return np.zeros(3)
        return out

    w.set_force_callback(law)
    h, t = w.state_hash(), w.time
    with pytest.raises(CollideError) as info:
        w.step(1.0 / 60.0)
    err = info.value
    assert err.status == lib.LC_ERR_CALLBACK
    assert "the step was undone" in str(err)
    assert {"nan": "non-finite force", "raise": "ZeroDivisionError: the law divided by zero",
            "shape": "returned shape (3,), expected (2, 3)"}[bad] in str(err)
    if bad == "raise":
        assert isinstance(err.__cause__, ZeroDivisionError)
    assert calls[0] == 3                       # not called again once it failed
    assert w.state_hash() == h and w.time == t and len(w.contacts) == 0
    w.step(1.0 / 60.0)                         # the law behaves again: the world steps on
    assert w.time > t


def test_keyboard_interrupt_in_the_force_function_propagates() -> None:
    w, _ = thrown_box()

    def law(q: ForceQuery) -> np.ndarray:
        raise KeyboardInterrupt

    w.set_force_callback(law)
    h = w.state_hash()
    with pytest.raises(KeyboardInterrupt):
        w.step(1.0 / 60.0)
    assert w.state_hash() == h


def test_a_failing_potential_fails_the_energy_reading() -> None:
    w, _ = thrown_box()

    def potential(q: ForceQuery) -> float:
        raise RuntimeError("no potential here")

    w.set_force_callback(constant((0.0, 0.0, 0.0)), potential)
    with pytest.raises(CollideError, match="potential function raised RuntimeError: no potential here") as info:
        w.energy
    assert info.value.status == lib.LC_ERR_CALLBACK
    w.set_force_callback(constant((0.0, 0.0, 0.0)), lambda q: math.inf)
    with pytest.raises(CollideError, match="non-finite energy"):
        w.energy
    w.step(1.0 / 60.0)                         # stepping never calls the potential


def test_removing_the_callback_restores_the_old_behaviour() -> None:
    a, _ = thrown_box(damping=0.0)
    b, _ = thrown_box(damping=0.0)
    b.set_force_callback(constant((0.0, 0.0, 0.0)))
    b.set_force_callback(None)
    for _ in range(200):
        a.step(1.0 / 60.0)
        b.step(1.0 / 60.0)
        assert a.state_hash() == b.state_hash()
    assert b.energy.callback == 0.0


def test_the_world_keeps_the_functions_alive() -> None:
    w = World(gravity=(0.0, 0.0))
    w.add_box(1.0, 1.0, mass=2.0)
    w.set_force_callback(constant((4.0, 0.0, 0.0)))   # nothing else holds this closure
    gc.collect()
    w.step(0.5)
    # x = F t^2 / (2 m), exact up to round-off of RK4's sums
    assert w.state[0, 0] == pytest.approx(4.0 * 0.25 / 4.0, rel=1e-15)


def test_bad_arguments_are_refused() -> None:
    w = World()
    with pytest.raises(TypeError, match="force must be callable"):
        w.set_force_callback(42)              # type: ignore[arg-type]
    with pytest.raises(TypeError, match="potential must be callable"):
        w.set_force_callback(constant((0.0, 0.0, 0.0)), "U")  # type: ignore[arg-type]
    with pytest.raises(CollideError, match="potential belongs to a force law") as info:
        w.set_force_callback(None, lambda q: 0.0)
    assert info.value.status == lib.LC_ERR_NULL


def test_snapshots_hold_no_callback() -> None:
    # load keeps the world's own law; a world from a snapshot has none until it is set again, and then
    # steps on bit for bit (two boxes attracting each other over the floor)
    force, potential = gravitation(50.0)
    w, _ = thrown_box(damping=0.0)
    w.add_box(0.5, 0.5, position=(2.0, 0.25), elasticity=0.2)
    w.set_force_callback(force, potential)
    w.step(1.0 / 60.0, 60)
    snap = w.save()
    w.step(1.0 / 60.0, 120)
    copy = World.from_snapshot(snap)
    assert copy.energy.callback == 0.0                 # no law, no potential
    copy.set_force_callback(force, potential)
    copy.step(1.0 / 60.0, 120)
    assert copy.state_hash() == w.state_hash()
    other = World()
    other.set_force_callback(force, potential)
    other.load(snap)
    assert other.energy.callback < 0.0                 # the law stayed
    other.step(1.0 / 60.0, 120)
    assert other.state_hash() == w.state_hash()
