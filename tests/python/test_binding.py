"""Binding mechanics: cffi API mode against the public header, zero-copy views, names, objects,
error mapping. Only the public C API is used (through collide's cffi module)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import collide
from collide import CollideError, World
from collide._ffi import ffi, lib
from collide import build_ffi

BOX = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]


def c_state_pointer(w: World) -> int:
    view = ffi.new("lc_state_view *")
    assert lib.lc_world_get_state(w._w, view) == lib.LC_OK
    return int(ffi.cast("uintptr_t", view.state))


def three_boxes() -> World:
    w = World(gravity=(0.0, 0.0))
    for i, name in enumerate(("a", "b", "c")):
        w.add_box(1.0, 1.0, position=(3.0 * i, 0.0), velocity=(0.0, 1.0 + i), name=name)
    return w


# ---- the cdef comes from the header -------------------------------------------------------------

def test_cdef_is_generated_from_the_public_header() -> None:
    cdef = build_ffi.generate_cdef()
    header = (build_ffi.INCLUDE_DIR / "collide" / "collide.h").read_text()
    # every function the header declares is in the cdef and bound in lib
    import re
    names = set(re.findall(r"\b(lc_\w+)\s*\(", header))
    assert len(names) > 40
    for n in names:
        assert n in cdef, n
        assert hasattr(lib, n), n
    # constants read from the compiler, not copied
    assert lib.LC_WORLD_ANCHOR == 0xFFFFFFFF
    assert lib.LC_MAX_POLYGON_VERTICES == 64
    assert build_ffi.is_up_to_date()


def test_build_is_idempotent_and_reports_up_to_date(capsys: pytest.CaptureFixture[str]) -> None:
    before = build_ffi.extension_path().stat().st_mtime_ns
    assert build_ffi.main([]) == 0
    assert "up to date" in capsys.readouterr().out
    assert build_ffi.extension_path().stat().st_mtime_ns == before


def test_contact_dtype_matches_c_layout() -> None:
    dt = collide.CONTACT_DTYPE
    assert dt.itemsize == ffi.sizeof("lc_contact")
    for name, _ in ffi.typeof("lc_contact").fields:
        assert dt.fields[name][1] == ffi.offsetof("lc_contact", name), name
    assert dt["point"].shape == (2,) and dt["normal"].shape == (2,)


# ---- zero-copy views -------------------------------------------------------------------------------

def test_state_is_a_zero_copy_read_only_view_that_follows_steps() -> None:
    w = three_boxes()
    s = w.state
    assert s.shape == (3, 6) and s.dtype == np.float64
    assert s.__array_interface__["data"][0] == c_state_pointer(w)  # the C array itself
    assert np.shares_memory(s, w.state)
    assert not s.flags.writeable
    with pytest.raises(ValueError):
        s[0, 0] = 1.0
    y0 = s[:, 1].copy()
    w.step(0.1)
    # no re-fetch: the same array object now shows the new state (vy = 1, 2, 3 m/s, no gravity;
    # free flight is exact to rounding, 1e-12 m)
    np.testing.assert_allclose(s[:, 1] - y0, [0.1, 0.2, 0.3], rtol=0, atol=1e-12)
    ids = w.ids
    assert ids.dtype == np.uint32 and list(ids) == [b.id for b in w.bodies]


def test_view_keeps_its_world_alive() -> None:
    s = three_boxes().state  # the World object is not referenced anywhere else
    import gc
    gc.collect()
    np.testing.assert_array_equal(s[:, 0], [0.0, 3.0, 6.0])


def test_masses_inertias_static_views() -> None:
    w = World()
    w.add_box(2.0, 1.0, mass=3.0, name="box")
    w.add_walls(-5, -5, 5, 5)
    np.testing.assert_allclose(w.masses, [3, 0, 0, 0, 0])
    # rectangle: I = m (w^2 + h^2) / 12 = 3 * 5 / 12, exact up to the polygon integration's rounding
    assert w.inertias[0] == pytest.approx(1.25, rel=1e-12)
    assert list(w.static_mask) == [False, True, True, True, True]


def test_set_state_round_trip_ignores_static_rows() -> None:
    w = three_boxes()
    w.add_walls(-10, -10, 10, 10)
    new = np.array(w.state)
    new[:, 3] = 7.0
    w.set_state(new)
    assert list(w.state[:3, 3]) == [7.0] * 3  # dynamic rows copied bit for bit
    assert list(w.state[3:, 3]) == [0.0] * 4  # walls never move
    with pytest.raises(ValueError, match="shape"):
        w.set_state(np.zeros((2, 6)))
    with pytest.raises(TypeError):
        w.set_state(np.array([["a"] * 6] * 7))


# ---- names and objects -------------------------------------------------------------------------------

def test_names_follow_rows_when_bodies_are_removed() -> None:
    w = three_boxes()
    w.add_box(1, 1, position=(9.0, 0.0), name="d")
    w.remove_body("b")
    assert w.names == ["a", "c", "d"]
    np.testing.assert_array_equal(w.state[:, 0], [0.0, 6.0, 9.0])  # rows match the names
    assert w.body("c").index == 1 and w.body("c").position == (6.0, 0.0)
    with pytest.raises(KeyError):
        w.body("b")


def test_names_stay_in_row_order_through_adds_walls_removals_and_failed_adds() -> None:
    # names are appended per add (not rebuilt from the ids): after any mix of calls they must still be
    # the names of the ids in row order
    w = three_boxes()
    w.add_walls(-5.0, -5.0, 15.0, 5.0)
    w.remove_body("a")
    w.add_box(1, 1, position=(1.0, 2.0))
    with pytest.raises(CollideError):
        w.add_box(1, 1, position=(1.0, 2.0), mass=-1.0)      # refused by C: no name added
    with pytest.raises(ValueError):
        w.add_box(1, 1, name="c")                             # refused by Python: a duplicate name
    w.add_box(1, 1, position=(4.0, 2.0), name="e")
    by_id = {w.body(n).id: n for n in w.names}
    assert len(by_id) == len(w) == 8
    assert w.names == [by_id[int(i)] for i in w.ids]
    assert w.names[:2] == ["b", "c"] and w.names[-1] == "e" and w.names[2:6] == list(collide.WALL_NAMES)


def test_body_properties_and_setters() -> None:
    w = World(gravity=(0, 0))
    b = w.add_box(2.0, 1.0, position=(1.0, 2.0), angle=0.5, velocity=(3.0, 4.0), angular_velocity=0.25,
                  mass=2.0, elasticity=0.5, friction=0.2, name="b")
    assert (b.name, b.position, b.angle, b.velocity, b.angular_velocity) == ("b", (1.0, 2.0), 0.5, (3.0, 4.0), 0.25)
    assert (b.mass, b.elasticity, b.friction, b.static) == (2.0, 0.5, 0.2, False)
    b.mass = 4.0
    assert b.mass == 4.0
    b.set_pose((-1.0, -2.0), 1.0)
    b.set_velocity((0.0, 0.0), 0.0)
    assert b.position == (-1.0, -2.0) and b.angle == 1.0 and b.velocity == (0.0, 0.0)
    v = b.world_vertices()
    # the box's corners are 1.118 m from its centre whatever the angle (rounding only)
    np.testing.assert_allclose(np.hypot(v[:, 0] + 1.0, v[:, 1] + 2.0), [math.hypot(1.0, 0.5)] * 4, rtol=1e-12)
    np.testing.assert_allclose(np.abs(b.local_vertices()), [[1.0, 0.5]] * 4, rtol=1e-12)
    assert b.center_offset == pytest.approx((0.0, 0.0), abs=1e-12)


def test_polygon_centre_of_mass_is_computed() -> None:
    w = World()
    # right triangle legs 3 (x) and 3 (y): centroid (1, 1) from the frame origin
    t = w.add_body([(0, 0), (3, 0), (0, 3)], position=(10.0, 0.0), name="tri")
    assert t.center_offset == pytest.approx((1.0, 1.0), abs=1e-12)
    assert t.position == pytest.approx((11.0, 1.0), abs=1e-12)


def test_thrusters_and_springs_objects() -> None:
    w = World(gravity=(0, 0))
    a = w.add_box(1, 3, name="a")
    b = w.add_box(1, 3, position=(3, 0), name="b")
    th = a.add_default_thrusters(1.5)
    assert [t.index for t in th] == [0, 1, 2, 3] and len(a.thrusters) == 4
    th[2].level = 0.5
    assert a.thrusters[2].level == 0.5
    a.set_thruster_mask(0b1001)
    assert [t.level for t in a.thrusters] == [1.0, 0.0, 0.0, 1.0]
    extra = a.add_thruster((0, 0), (1, 0), 2.0)
    assert extra.index == 4
    s = w.add_spring(a, (0, 1), b, (0, -1), stiffness=5.0, damping=0.1, rest_length=2.0, name="link")
    m = w.add_spring(a, (0, 0), None, (0, 4), name="mouse")
    assert w.spring_count == 2 and w.spring("link").id == s.id
    (p1, p2) = s.endpoints()
    assert p1 == pytest.approx((0.0, 1.0)) and p2 == pytest.approx((3.0, -1.0))
    assert s.target is None and m.target == (0.0, 4.0)
    m.target = (1.0, 2.0)
    assert m.endpoints()[1] == (1.0, 2.0)
    s.set_params(6.0, 0.0, 1.0)
    assert s.definition["stiffness"] == 6.0 and s.definition["body_b"] == b.id
    m.remove()
    assert w.spring_count == 1
    w.remove_body("b")  # removes the spring attached to it
    assert w.spring_count == 0
    with pytest.raises(CollideError) as err:
        s.endpoints()
    assert err.value.status == lib.LC_ERR_UNKNOWN_SPRING


def test_settings_round_trip_and_configure() -> None:
    w = World(integrator="euler", damping=0.5, gravity=(1.0, -2.0))
    st = w.settings
    assert (st["integrator"], st["damping"], st["gravity"]) == ("euler", 0.5, (1.0, -2.0))
    w.configure(impact_mode="simultaneous", toi_max_iterations=50)
    assert w.settings["impact_mode"] == "simultaneous" and w.settings["toi_max_iterations"] == 50
    w.set_gravity((0, -1))
    w.set_damping(0.25, 0.2)
    assert w.settings["gravity"] == (0.0, -1.0) and w.settings["damping_rotation_ratio"] == 0.2


def test_energy_and_counters_types() -> None:
    w = World(gravity=(0, -10))
    w.add_box(1, 1, position=(0, 2), velocity=(3, 4), mass=2.0)
    e = w.energy
    # 1/2 m v^2 = 25 J; m g h = 2*10*2 = 40 J (zero level 0); no spin, no spring
    assert e.translational == pytest.approx(25.0, rel=1e-14)
    assert e.gravitational == pytest.approx(40.0, rel=1e-14)
    assert e.total == pytest.approx(65.0, rel=1e-14)
    assert e.linear_momentum == pytest.approx((6.0, 8.0), rel=1e-14)
    w.step(0.01)
    last, total = w.counters(), w.counters(last=False)
    assert last["steps"] == 1 and total["steps"] == 1 and set(last) >= {"collisions", "contact_solves"}


def test_stage_timing_fills_the_time_counters() -> None:
    def run(timing: bool) -> tuple[dict[str, Any], int]:
        w = collide.default_scene(blocks=3).build()
        w.set_stage_timing(timing)
        w.step(0.01, steps=100)
        return w.counters(last=False), w.state_hash()
    off, h_off = run(False)
    on, h_on = run(True)
    times = [k for k in on if k.startswith("time_")]
    assert set(times) >= {"time_step", "time_detection", "time_integration", "time_contact_forces"}
    assert all(off[k] == 0.0 for k in times)  # off by default
    assert on["time_step"] > 0.0 and on["time_detection"] > 0.0 and on["time_integration"] > 0.0
    disjoint = ("time_detection", "time_integration", "time_toi_search", "time_impulses", "time_projection")
    assert sum(on[k] for k in disjoint) <= on["time_step"]
    assert h_on == h_off  # measuring changes no physics


def test_state_hash_is_deterministic() -> None:
    def run() -> int:
        w = collide.default_scene(blocks=3).build()
        w.body("block1").set_velocity((2.0, 1.0), 0.5)
        w.step(0.01, steps=50)
        return w.state_hash()
    assert run() == run()


# ---- errors -------------------------------------------------------------------------------------------

def _fingerprint(w: World) -> tuple:
    return (w.state_hash(), w.names, len(w), w.spring_count, w.time)


@pytest.mark.parametrize("call,status,words", [
    (lambda w: w.add_box(1.0, 1.0, mass=float("nan"), name="x"), "LC_ERR_NOT_FINITE", "mass"),
    (lambda w: w.add_box(1.0, 1.0, mass=-1.0, name="x"), "LC_ERR_OUT_OF_RANGE", "mass"),
    (lambda w: w.add_body([(0, 0), (2, 0), (1, 0.3), (2, 2), (0, 2)], name="x"), "LC_ERR_BAD_POLYGON", ""),
    (lambda w: w.add_body([(0, 0), (1, 0)], name="x"), "LC_ERR_BAD_POLYGON", ""),
    (lambda w: w.remove_body(12345), "LC_ERR_UNKNOWN_BODY", ""),
    (lambda w: w.step(0.0), "LC_ERR_OUT_OF_RANGE", ""),
    (lambda w: w.step(float("inf")), "LC_ERR_NOT_FINITE", ""),
    (lambda w: w.configure(contact_gap=-1.0), "LC_ERR_OUT_OF_RANGE", "contact_gap"),
    (lambda w: w.configure(integrator=3), "LC_ERR_BAD_ENUM", ""),
    (lambda w: w.body("a").set_pose((float("nan"), 0.0), 0.0), "LC_ERR_NOT_FINITE", ""),
    (lambda w: w.body("wall_top").add_default_thrusters(), "LC_ERR_STATIC_BODY", ""),
    (lambda w: setattr(w.body("a").thrusters[0], "level", 2.0), "LC_ERR_OUT_OF_RANGE", ""),
    (lambda w: setattr(collide.Thruster(w.body("a"), 9), "level", 1.0), "LC_ERR_UNKNOWN_THRUSTER", ""),
    (lambda w: w.add_spring("a", stiffness=float("nan")), "LC_ERR_NOT_FINITE", ""),
])
def test_c_errors_carry_status_and_message_and_leave_world_unchanged(call, status: str, words: str) -> None:
    w = three_boxes()
    w.add_walls(-10, -10, 10, 10)
    w.body("a").add_default_thrusters()
    w.step(0.01)
    before = _fingerprint(w)
    with pytest.raises(CollideError) as err:
        call(w)
    assert err.value.status == getattr(lib, status)
    assert err.value.status_name == collide.status_name(err.value.status)
    assert err.value.message, "the C message must not be empty"
    assert err.value.message == ffi.string(lib.lc_world_last_error(w._w)).decode()
    assert words in err.value.message
    assert _fingerprint(w) == before


@pytest.mark.parametrize("call,exc", [
    (lambda w: w.add_box("1", 1.0), TypeError),
    (lambda w: w.add_box(1.0, 1.0, position=(1.0,)), ValueError),
    (lambda w: w.add_box(1.0, 1.0, position="xy"), TypeError),
    (lambda w: w.add_box(1.0, 1.0, mass=True), TypeError),
    (lambda w: w.add_box(1.0, 1.0, static="yes"), TypeError),
    (lambda w: w.add_box(1.0, 1.0, name="a"), ValueError),  # duplicate name
    (lambda w: w.add_box(1.0, 1.0, name=""), ValueError),
    (lambda w: w.add_body([(0, 0, 0), (1, 0, 0), (0, 1, 0)]), ValueError),
    (lambda w: w.add_body("triangle"), TypeError),
    (lambda w: w.configure(gravty=(0, 0)), TypeError),
    (lambda w: w.configure(integrator="rk5"), ValueError),
    (lambda w: w.configure(toi_max_iterations=1.5), TypeError),
    (lambda w: w.step("0.1"), TypeError),
    (lambda w: w.body("nobody"), KeyError),
    (lambda w: w.body("a").set_thruster_mask(2**40), ValueError),
    (lambda w: w.add_walls(-1, -1, 1, 1, names=["x", "y"]), ValueError),
])
def test_python_side_type_errors_before_c(call, exc: type) -> None:
    w = three_boxes()
    before = _fingerprint(w)
    with pytest.raises(exc):
        call(w)
    assert _fingerprint(w) == before


def test_world_constructor_error_and_box_helper_error() -> None:
    with pytest.raises(CollideError) as err:
        World(contact_gap=float("nan"))
    assert err.value.status == lib.LC_ERR_NOT_FINITE
    w = World()
    with pytest.raises(CollideError) as err:
        w.add_box(0.0, 1.0)
    assert err.value.status == lib.LC_ERR_OUT_OF_RANGE and "rectangle" in err.value.message
    assert len(w) == 0


def test_polygons_in_bulk_match_per_body_vertices() -> None:
    w = collide.default_scene(blocks=4).build()
    w.add_body([(0, 0), (1, 0), (0.2, 0.8)], position=(1.0, -4.0), angle=0.3, angular_velocity=2.0, name="tri")
    w.body("block1").set_velocity((1.0, 0.5), 1.5)
    w.step(0.01, steps=10)
    verts, start = w.polygons()
    assert start[-1] == len(verts) == 4 * 4 + 4 * 4 + 3
    for i, body in enumerate(w.bodies):
        # same rotation from the same doubles; only the order of operations differs (1e-12 m)
        np.testing.assert_allclose(verts[start[i]:start[i + 1]], body.world_vertices(), rtol=0, atol=1e-12)
    w.remove_body("block2")  # topology change: the cached local table is rebuilt
    verts, start = w.polygons()
    assert len(start) == len(w) + 1 and start[-1] == len(verts) == 4 * 4 + 3 * 4 + 3


def test_contacts_view_is_zero_copy_and_matches_c_fields() -> None:
    w = World(gravity=(0.0, 0.0))
    a = w.add_box(1.0, 1.0, position=(-2.0, 0.0), velocity=(2.0, 0.0), name="a")
    b = w.add_box(1.0, 1.0, position=(0.0, 0.25), name="b")
    for _ in range(200):  # impact at t = 0.5 s
        w.step(0.01)
        if len(w.contacts):
            break
    c = w.contacts
    assert len(c) >= 1 and not c.flags.writeable
    ptr, count = ffi.new("const lc_contact **"), ffi.new("int *")
    assert lib.lc_world_get_contacts(w._w, ptr, count) == lib.LC_OK
    assert count[0] == len(c)
    assert c.__array_interface__["data"][0] == int(ffi.cast("uintptr_t", ptr[0]))
    for i in range(len(c)):  # every field read through numpy equals the C struct's (bit for bit)
        cc = ptr[0][i]
        assert (c[i]["body_a"], c[i]["body_b"], c[i]["kind"]) == (cc.body_a, cc.body_b, cc.kind)
        assert tuple(c[i]["point"]) == (cc.point.x, cc.point.y)
        assert tuple(c[i]["normal"]) == (cc.normal.x, cc.normal.y)
        assert (c[i]["impulse"], c[i]["time"], c[i]["force"]) == (cc.impulse, cc.time, cc.force)
    assert {int(c[0]["body_a"]), int(c[0]["body_b"])} == {a.id, b.id}
    assert c[0]["kind"] == collide.COLLISION and c[0]["impulse"] > 0
