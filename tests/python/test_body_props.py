"""A body's given inertia and centre of mass through the binding and scene files, and every body
property read back from C (no Python-side copies): mass, inertia, material, external force and torque,
thruster levels and mask, stage timing."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import collide
from collide import CollideError, SceneError, World, load_scene
from collide._ffi import lib

BOX = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]


def test_defaults_keep_the_polygon_values() -> None:
    w = World(gravity=(0, 0))
    b = w.add_box(1.0, 3.0, mass=2.0)
    assert b.inertia == pytest.approx(2.0 * 10.0 / 12.0, rel=1e-15)
    assert b.center_of_mass == pytest.approx((0.0, 0.0), abs=1e-15)
    assert b.center_of_mass == b.center_offset
    assert b.mass == 2.0 and b.material == (1.0, 0.0)
    assert b.external == ((0.0, 0.0), 0.0)


def test_given_inertia_is_kept_and_spins_up_at_tau_over_i() -> None:
    w = World(gravity=(0, 0))
    b = w.add_box(1.0, 3.0, mass=2.0, inertia=0.7)
    assert b.inertia == 0.7 and w.inertias[b.index] == 0.7
    b.set_external(torque=0.3)
    w.step(0.01, 100)
    assert b.angular_velocity == pytest.approx(0.3 / 0.7, rel=1e-13)
    assert b.angle == pytest.approx(0.5 * 0.3 / 0.7, rel=1e-13)
    b.inertia = 1.4
    assert b.inertia == 1.4
    b.mass = 4.0
    assert b.inertia == pytest.approx(2.8, rel=1e-15)  # set_mass keeps the inertia per unit mass
    b.inertia = 0.0  # back to the polygon's
    assert b.inertia == pytest.approx(4.0 * 10.0 / 12.0, rel=1e-15)


def test_given_center_of_mass_is_the_state_and_the_pivot_of_free_rotation() -> None:
    w = World(gravity=(0, 0))
    com = (0.3, -0.2)
    b = w.add_body(BOX, position=(1.0, 2.0), mass=1.5, center_of_mass=com, angular_velocity=0.8)
    assert b.center_of_mass == com
    assert b.position == pytest.approx((1.3, 1.8), abs=1e-15)
    np.testing.assert_allclose(b.local_vertices(), np.array(BOX) - com, atol=1e-15)
    assert b.inertia == pytest.approx(1.5 * (1 / 6 + 0.09 + 0.04), rel=1e-14)  # parallel axes
    w.step(0.01, 200)
    assert b.position == pytest.approx((1.3, 1.8), abs=1e-14)
    c, s = math.cos(1.6), math.sin(1.6)
    rel = np.array(BOX) - com
    expect = np.array([1.3, 1.8]) + rel @ np.array([[c, s], [-s, c]])
    np.testing.assert_allclose(b.world_vertices(), expect, atol=1e-13)


def test_a_spring_through_the_offset_center_of_mass_hangs_it_below_the_pivot() -> None:
    w = World(gravity=(0, -9.81), damping=2.0, damping_rotation_ratio=0.5)
    b = w.add_box(1.0, 1.0, center_of_mass=(0.3, 0.0), inertia=0.05)
    w.add_spring(b, (0.0, 0.0), None, (0.0, 0.0), stiffness=1e4, damping=50.0)
    w.step(0.001, 15000)
    assert b.position == pytest.approx((0.0, -0.3 - 9.81 / 1e4), abs=1e-6)
    assert math.remainder(b.angle + math.pi / 2, 2 * math.pi) == pytest.approx(0.0, abs=1e-6)


def test_readers_follow_c_not_a_python_copy() -> None:
    w = World(gravity=(0, 0))
    a = w.add_box(1.0, 1.0, name="a", elasticity=0.5, friction=0.2)
    w.add_walls(-5, -5, 5, 5, elasticity=0.9)
    assert a.material == (0.5, 0.2)
    a.set_material(friction=0.7)
    assert (a.elasticity, a.friction) == (0.5, 0.7)
    w.set_elasticity(0.3)  # every body, through C only
    assert a.elasticity == 0.3 and w.body("wall_top").elasticity == 0.3
    # a change made behind the binding's back, straight through the C API, is what Python reads
    assert lib.lc_body_set_material(w._w, a.id, 0.1, 0.2) == lib.LC_OK
    assert lib.lc_body_set_mass(w._w, a.id, 3.0) == lib.LC_OK
    assert lib.lc_body_set_external(w._w, a.id, (1.0, 2.0), 0.5) == lib.LC_OK
    assert (a.material, a.mass, a.external) == ((0.1, 0.2), 3.0, ((1.0, 2.0), 0.5))
    th = a.add_default_thrusters()
    assert [t.level for t in th] == [0.0] * 4 and a.thruster_mask == 0
    assert lib.lc_body_set_thruster_level(w._w, a.id, 1, 0.25) == lib.LC_OK
    assert th[1].level == 0.25 and a.thruster_mask == 0b10
    a.set_thruster_mask(0b1001)
    assert a.thruster_mask == 0b1001 and [t.level for t in a.thrusters] == [1.0, 0.0, 0.0, 1.0]
    assert not w.stage_timing
    w.set_stage_timing(True)
    assert w.stage_timing
    assert not hasattr(w._rec[a.id], "elasticity")  # nothing cached beside the name


@pytest.mark.parametrize("kwargs,status,words", [
    (dict(inertia=float("nan")), "LC_ERR_NOT_FINITE", "inertia"),
    (dict(inertia=-1.0), "LC_ERR_OUT_OF_RANGE", "inertia"),
    (dict(inertia=0.6), "LC_ERR_OUT_OF_RANGE", "mass * r^2"),   # 1 kg, r^2 = 1/2
    (dict(center_of_mass=(0.6, 0.0)), "LC_ERR_OUT_OF_RANGE", "outside the polygon"),
    (dict(center_of_mass=(float("inf"), 0.0)), "LC_ERR_NOT_FINITE", "center_of_mass"),
])
def test_bad_inertia_or_center_is_refused_by_c(kwargs, status: str, words: str) -> None:
    w = World()
    w.add_box(1.0, 1.0, name="a")
    h = w.state_hash()
    with pytest.raises(CollideError) as err:
        w.add_box(1.0, 1.0, name="b", **kwargs)
    assert err.value.status == getattr(lib, status) and words in err.value.message
    assert w.state_hash() == h and len(w) == 1 and "b" not in w


def test_setters_and_readers_refuse_like_c() -> None:
    w = World()
    a = w.add_box(1.0, 1.0, name="a")
    wall = w.add_walls(-5, -5, 5, 5)[0]
    with pytest.raises(CollideError, match="static"):
        wall.inertia = 1.0
    with pytest.raises(CollideError, match="inertia"):
        a.inertia = -1.0
    with pytest.raises(TypeError):
        a.inertia = "heavy"
    with pytest.raises(TypeError):
        w.add_box(1.0, 1.0, center_of_mass="middle")
    w.remove_body(a)
    for read in (lambda: a.mass, lambda: a.inertia, lambda: a.material, lambda: a.external,
                 lambda: a.thruster_mask):
        with pytest.raises(CollideError) as err:
            read()
        assert err.value.status == lib.LC_ERR_UNKNOWN_BODY
    assert "gone" in repr(collide.Thruster(wall, 0))


SCENE = """\
version: 1
world: {gravity: [0, 0]}
bodies:
  - name: a
    shape: box
    width: 1
    height: 1
    mass: 2
    inertia: 0.25
    center_of_mass: [0.1, -0.2]
  - {name: b, shape: polygon, vertices: [[0, 0], [2, 0], [0, 1]], position: [3, 0]}
"""


def test_scene_inertia_and_center_of_mass(tmp_path: Path) -> None:
    path = tmp_path / "scene.yaml"
    path.write_text(SCENE)
    scene = load_scene(path)
    w = scene.build()
    a, b = w.body("a"), w.body("b")
    assert a.inertia == 0.25 and a.center_of_mass == (0.1, -0.2)
    assert b.center_of_mass == pytest.approx((2 / 3, 1 / 3), abs=1e-15)
    assert "inertia" not in scene.to_dict()["bodies"][1]  # absent keys stay absent
    again = tmp_path / "again.yaml"
    scene.dump(again)
    assert load_scene(again) == scene


@pytest.mark.parametrize("line,replacement,where,words", [
    ("    inertia: 0.25", "    inertia: 0", "scene.yaml:9: bodies[0].inertia", "must be > 0"),
    ("    inertia: 0.25", "    inertia: heavy", "scene.yaml:9: bodies[0].inertia", "expected a number"),
    ("    inertia: 0.25", "    inertia: 5", "scene.yaml:9: bodies[0].inertia", "exceeds mass * r^2"),
    ("    center_of_mass: [0.1, -0.2]", "    center_of_mass: [0.1]", "scene.yaml:10: bodies[0].center_of_mass",
     "expected a pair"),
    ("    center_of_mass: [0.1, -0.2]", "    center_of_mass: [2, 0]", "scene.yaml:10: bodies[0].center_of_mass",
     "outside the polygon"),
    ("    center_of_mass: [0.1, -0.2]", "    centre_of_mass: [0.1, -0.2]", "scene.yaml:10: bodies[0].centre_of_mass",
     "did you mean 'center_of_mass'"),
])
def test_scene_rejects_bad_inertia_and_center_with_line_and_reason(tmp_path: Path, line: str, replacement: str,
                                                                   where: str, words: str) -> None:
    assert line in SCENE
    path = tmp_path / "scene.yaml"
    path.write_text(SCENE.replace(line, replacement))
    with pytest.raises(SceneError) as err:
        load_scene(path)
    text = str(err.value)
    assert where in text and words in text, text


def test_scenes_without_the_new_keys_give_the_same_bits() -> None:
    """The new keys are optional and absent by default: a scene without them builds the world it
    always did (a given inertia equal to the polygon's gives the same bits too)."""
    scene = collide.default_scene(blocks=2, gravity=9.81, elasticity=0.9)
    w1 = scene.build()
    data = scene.to_dict()
    for body in data["bodies"]:
        assert "inertia" not in body and "center_of_mass" not in body
        body["center_of_mass"] = [0.0, 0.0]  # the box's centroid, given explicitly
    w2 = load_scene(data).build()
    for w in (w1, w2):
        w.body("block1").thrusters[2].level = 1.0
        w.step(0.01, 200)
    assert w1.state_hash() == w2.state_hash()
