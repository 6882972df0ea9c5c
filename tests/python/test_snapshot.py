"""World snapshots through the binding (World.save, World.load, World.from_snapshot; lc_world_save /
lc_world_load): bit-identical continuation (the state hash at every later step, and the final snapshot
bytes), names kept across a load into the same world, and truncated, corrupt or mistyped snapshots refused
with the world unchanged. No tolerance: equality is the requirement."""
from __future__ import annotations

import pytest

import collide
from collide import CollideError, World


def seed_scene() -> World:
    """The default scene: walls, three blocks at e = 0.7, thrusters firing, a mouse spring, damping."""
    w = collide.default_scene(blocks=3, gravity=9.81, elasticity=0.7, damping=0.05).build()
    w.body("block1").set_thruster_mask(0b101)
    w.add_spring("block2", (0.2, 1.0), None, (0.0, 3.0), stiffness=3.0, name="mouse")
    return w


def pile(allow_sleep: int = 0) -> World:
    """A pyramid of base 7 on a floor (friction 0.5, e 0) and a box dropped on it: the contact regime."""
    w = World(allow_sleep=allow_sleep, sleep_time=0.2)
    w.add_box(40.0, 1.0, position=(0.0, -0.5), static=True, elasticity=0.0, name="floor")
    for row in range(7):
        for j in range(7 - row):
            w.add_box(1.0, 1.0, position=(j - (6 - row) / 2.0, 0.5 + row), elasticity=0.0, friction=0.5)
    w.add_box(1.0, 1.0, position=(0.3, 10.0), angle=0.2, velocity=(0.0, -3.0), elasticity=0.2, friction=0.5,
              name="dropped")
    return w


def hashes(w: World, n: int, dt: float = 0.01) -> list[int]:
    out = []
    for _ in range(n):
        w.step(dt)
        out.append(w.state_hash())
    return out


@pytest.mark.parametrize("build,k,n", [(seed_scene, 120, 150), (pile, 60, 120), (lambda: pile(1), 40, 150)],
                         ids=["seed scene", "pile", "pile with sleep"])
def test_continuation_is_bit_identical(build, k: int, n: int) -> None:
    w = build()
    w.step(0.01, k)
    snap = w.save()
    ref = hashes(w, n)
    end = w.save()
    fresh = World.from_snapshot(snap)
    assert fresh.save() == snap
    assert hashes(fresh, n) == ref
    assert fresh.save() == end
    w.load(snap)  # the world it came from, which went on
    assert hashes(w, n) == ref
    other = World(gravity=(0.0, 0.0))  # an unrelated world
    other.add_box(1.0, 1.0, velocity=(1.0, 0.0))
    other.step(0.01, 5)
    other.load(snap)
    assert hashes(other, n) == ref


def test_names_survive_a_load_into_the_same_world() -> None:
    w = seed_scene()
    snap = w.save()
    names = w.names
    w.add_box(0.5, 0.5, position=(2.0, 2.0), name="late")
    w.step(0.01, 10)
    w.load(snap)
    assert w.names == names and "late" not in w
    assert w.spring("mouse").endpoints() is not None
    assert w.body("block1").thruster_mask == 0b101
    fresh = World.from_snapshot(snap)
    assert fresh.names == [f"body{int(i)}" for i in fresh.ids]


def test_bad_snapshots_are_refused_and_change_nothing() -> None:
    w = pile()
    w.step(0.01, 30)
    snap = w.save()
    target = seed_scene()
    before = target.save()
    for bad, says in ((snap[:-1], "truncated"), (snap[:10], "too short"),
                      (snap[:40] + bytes([snap[40] ^ 1]) + snap[41:], "checksum"), (b"x" * 64, "magic")):
        with pytest.raises(CollideError, match=says) as err:
            target.load(bad)
        assert err.value.status_name == "bad snapshot"
        assert target.save() == before
    with pytest.raises(TypeError):
        target.load("not bytes")  # type: ignore[arg-type]
    with pytest.raises(CollideError):
        World.from_snapshot(snap[:-3])
