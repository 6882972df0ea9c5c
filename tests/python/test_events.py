"""The impact event stream through the binding (World.read_events, lc_world_get_events): every collision
of every step exactly once between reads, exact drop counts past event_capacity, bad arguments refused,
the same events on two runs. The reference is the step's own collisions (World.contacts), polled after
every step: the two are the same numbers, so equality is exact."""
from __future__ import annotations

import numpy as np
import pytest

import collide
from collide import CollideError, World

BOX = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]


def bouncing_boxes(**settings: object) -> World:
    """Walls and six boxes at e = 0.7 thrown in different directions under gravity, the floor of a
    pile: impacts in the event regime while they fly, in the contact regime once they settle."""
    w = World(**settings)
    w.add_walls(-6.0, -6.0, 6.0, 6.0, elasticity=0.7)
    for i in range(6):
        w.add_box(1.0, 1.0 + 0.3 * i, position=(-5.0 + 2.0 * i, 1.0 - 0.5 * i), angle=0.1 * i,
                  velocity=(4.0 - 1.3 * i, 3.0 - i), angular_velocity=1.0 - 0.4 * i, elasticity=0.7,
                  friction=0.4)
    return w


def polled_collisions(w: World) -> np.ndarray:
    """The last step's collisions as EVENT_DTYPE rows (kind left 0: the contacts do not tell)."""
    c = w.contacts
    hits = c[c["kind"] == collide.COLLISION]
    out = np.zeros(len(hits), dtype=collide.EVENT_DTYPE)
    for name in ("time", "body_a", "body_b", "point", "normal", "gap", "tangent_impulse"):
        out[name] = hits[name]
    out["normal_impulse"] = hits["impulse"]
    out["approach_speed"] = -hits["normal_velocity"]
    return out


FIELDS = ("time", "body_a", "body_b", "point", "normal", "gap", "normal_impulse", "tangent_impulse", "approach_speed")


def assert_same(a: np.ndarray, b: np.ndarray) -> None:
    assert len(a) == len(b)
    for name in FIELDS:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def test_1khz_steps_read_at_100hz_lose_no_impact() -> None:
    w = bouncing_boxes()
    polled, read = [], []
    for k in range(3000):
        w.step(0.001)
        polled.append(polled_collisions(w))
        if (k + 1) % 10 == 0:
            events, dropped = w.read_events()
            assert dropped == 0
            read.append(events)
    events, dropped = w.read_events()
    read.append(events)
    polled_all, read_all = np.concatenate(polled), np.concatenate(read)
    assert len(polled_all) > 30
    assert_same(polled_all, read_all)
    kinds = set(read_all["kind"].tolist())
    assert kinds <= {collide.IMPACT_EVENT, collide.IMPACT_CONTACT}
    assert collide.IMPACT_EVENT in kinds
    assert w.pending_events == 0


def test_overflow_keeps_the_newest_and_counts_the_rest() -> None:
    cap = 5
    w = bouncing_boxes(event_capacity=cap)
    polled = []
    for _ in range(300):
        w.step(0.01)
        polled.append(polled_collisions(w))
    everything = np.concatenate(polled)
    assert len(everything) > cap
    assert w.pending_events == cap
    events, dropped = w.read_events()
    assert dropped == len(everything) - cap
    assert_same(events, everything[-cap:])
    assert w.read_events()[1] == 0  # the drops were reported once


def test_partial_reads_leave_the_rest_in_order() -> None:
    w = bouncing_boxes()
    w.step(0.01, 200)
    n = w.pending_events
    assert n > 4
    first, _ = w.read_events(3)
    rest, _ = w.read_events()
    assert len(first) == 3 and len(rest) == n - 3
    assert np.all(np.diff(np.concatenate([first, rest])["time"]) >= 0)


def test_bad_arguments_are_refused_and_change_nothing() -> None:
    w = bouncing_boxes()
    w.step(0.01, 100)
    n, h = w.pending_events, w.state_hash()
    with pytest.raises(ValueError):
        w.read_events(-1)
    with pytest.raises(TypeError):
        w.read_events(2.5)  # type: ignore[arg-type]
    with pytest.raises(CollideError, match="event_capacity"):
        w.configure(event_capacity=-1)
    with pytest.raises(CollideError, match="event_capacity"):
        World(event_capacity=10**7)
    assert w.pending_events == n and w.state_hash() == h
    assert w.settings["event_capacity"] == 4096


def test_two_runs_report_the_same_events_and_reading_changes_nothing() -> None:
    a, b = bouncing_boxes(), bouncing_boxes()
    ea = []
    for k in range(400):
        a.step(0.01)
        b.step(0.01)
        if k % 7 == 0:
            ea.append(a.read_events()[0])
        assert a.state_hash() == b.state_hash()
    ea.append(a.read_events()[0])
    eb, _ = b.read_events()
    ea_all = np.concatenate(ea)
    assert len(ea_all) > 30
    assert_same(ea_all, eb)
    np.testing.assert_array_equal(ea_all["kind"], eb["kind"])
