"""Bad-input catalogue: the gaps left by test_api_errors.c, test_binding.py,
test_scene.py, test_runner.py and test_node*.py. Every case asserts the error (type and text) and
that the state is unchanged: for the library the state hash, names and spring count; for the
runner that nothing was written; for the node that the other bodies did not move, sim time kept
advancing, and the parameters kept their values. The table is in docs/hardening.md.

Exact equality throughout: a refused input must change no bit (validation is logic, not arithmetic).
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
import pytest
from geometry_msgs.msg import Point, Twist, TwistStamped, Vector3, WrenchStamped
from libcollide_msgs.msg import SpringCommand, ThrusterCommand
from libcollide_msgs.srv import Kill, Spawn, Step
from std_msgs.msg import String
from std_srvs.srv import Empty, SetBool

import collide
from collide import CollideError, World
from collide_ros import params as node_params
from collide_ros.testing import SimClient, running_sim

ROOT = Path(__file__).resolve().parents[2]
NAN, INF = float("nan"), float("inf")


# ================================================================ Python API (the gaps)

def two_boxes() -> World:
    w = World(gravity=(0.0, 0.0))
    w.add_walls(-6, -6, 6, 6)
    w.add_box(1.0, 1.0, name="a")
    w.add_box(1.0, 1.0, position=(2.0, 0.0), name="b")
    w.add_spring("a", stiffness=2.0, name="s")
    w.step(0.01)
    return w


def fingerprint(w: World) -> tuple[Any, ...]:
    return (w.state_hash(), tuple(w.names), w.spring_count, w.time, tuple(np.asarray(w.masses).tolist()))


API_CASES: list[tuple[str, Callable[[World], Any], type, str]] = [
    ("set_state wrong shape", lambda w: w.set_state(np.zeros((3, 6))), ValueError, "shape"),
    ("set_state NaN", lambda w: w.set_state(np.full((len(w), 6), NAN)), CollideError, "not finite"),
    ("mass negative", lambda w: setattr(w.body("a"), "mass", -1.0), CollideError, "mass = -1"),
    ("mass zero", lambda w: setattr(w.body("a"), "mass", 0.0), CollideError, "mass = 0"),
    ("mass inf", lambda w: setattr(w.body("a"), "mass", INF), CollideError, "mass is not finite"),
    ("velocity inf", lambda w: w.body("a").set_velocity((INF, 0.0), 0.0), CollideError, "velocity.x"),
    ("pose huge", lambda w: w.body("a").set_pose((1e300, 0.0), 0.0), CollideError, "outside [-1e+09"),
    ("box huge", lambda w: w.add_box(1e300, 1e300, position=(0, -4), name="h"), CollideError, "rectangle"),
    ("self-intersecting polygon", lambda w: w.add_body([(0, 0), (1, 1), (1, 0), (0, 1)], position=(0, -4),
                                                       name="bow"), CollideError, "degenerate"),
    ("empty polygon", lambda w: w.add_body([], name="e"), CollideError, "vertex_count 0"),
    ("coincident vertices", lambda w: w.add_body([(0, 0), (0, 0), (1, 0), (0, 1)], position=(0, -4), name="d"),
     CollideError, "coincide"),
    ("spring to unknown body", lambda w: w.add_spring("ghost"), KeyError, "no body named 'ghost'"),
    ("remove unknown body", lambda w: w.remove_body("ghost"), KeyError, "no body named 'ghost'"),
    ("duplicate spring name", lambda w: w.add_spring("b", name="s"), ValueError, "'s'"),
    ("step negative", lambda w: w.step(-0.1), CollideError, "dt = -0.1"),
    ("step huge", lambda w: w.step(1e300), CollideError, "dt = 1e+300"),
    ("gravity NaN", lambda w: w.set_gravity((NAN, 0.0)), CollideError, "gravity.x"),
    ("damping negative", lambda w: w.set_damping(-1.0, 0.1), CollideError, "damping = -1"),
    ("elasticity > 1", lambda w: w.set_elasticity(2.0), CollideError, "elasticity = 2"),
    ("material negative", lambda w: w.body("a").set_material(-1.0, 0.0), CollideError, "elasticity = -1"),
    ("thruster NaN", lambda w: w.body("a").add_thruster((0, 0), (1, 0), NAN), CollideError, "magnitude"),
    ("external force NaN", lambda w: w.body("a").set_external((NAN, 0.0), 0.0), CollideError, "force.x"),
    ("spring params negative", lambda w: w.spring("s").set_params(-1.0, 0.0, 0.0), CollideError, "stiffness = -1"),
    ("spring target inf", lambda w: setattr(w.spring("s"), "target", (INF, 0.0)), CollideError, "not finite"),
    ("configure wrong type", lambda w: w.configure(contact_gap="x"), TypeError, "real number"),
    ("box NaN elasticity", lambda w: w.add_box(1, 1, position=(0, -4), elasticity=NAN, name="en"), CollideError,
     "elasticity is not finite"),
    ("walls inverted", lambda w: World().add_walls(6, 6, -6, -6), CollideError, "xmax > xmin"),
    ("walls zero thickness", lambda w: World().add_walls(-6, -6, 6, 6, thickness=0.0), CollideError, "thickness"),
]


@pytest.mark.parametrize("desc,call,exc,words", API_CASES, ids=[c[0] for c in API_CASES])
def test_python_api_bad_input(desc: str, call: Callable[[World], Any], exc: type, words: str) -> None:
    w = two_boxes()
    before = fingerprint(w)
    with pytest.raises(exc) as err:
        call(w)
    assert words in str(err.value), str(err.value)
    assert fingerprint(w) == before
    w.step(0.01)  # and the world still steps
    assert w.time > before[3]


def test_python_api_overlap_is_allowed_and_resolved_by_the_library() -> None:
    """The library accepts a body placed into another (its contract: the caller places bodies; the
    node refuses overlaps with a separating-axis test). The state stays finite while stepping."""
    w = two_boxes()
    w.add_box(1.0, 1.0, position=(0.2, 0.0), name="ov")
    for _ in range(100):
        w.step(0.001)
    assert np.isfinite(np.asarray(w.state)).all()


# ================================================================ the runner (python -m collide.run)

def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "ros_pkg"), env.get("PYTHONPATH", "")) if p)
    return subprocess.run([sys.executable, "-m", "collide.run", *args], env=env, capture_output=True, text=True,
                          timeout=120)


GOOD_YAML = (ROOT / "scenes" / "default.yaml").read_text()

RUNNER_CASES = [
    ("truncated YAML", "cut.yaml", GOOD_YAML[: len(GOOD_YAML) // 2] + "\n  - {name: x, shape: box, width: 1,\n",
     "invalid YAML"),
    ("truncated JSON", "cut.json", '{"bodies": [{"name": "a", "shape": "box", "width": 1', "invalid JSON"),
    ("empty file", "empty.yaml", "", "empty"),
    ("binary garbage", "junk.yaml", "\x00\x01\x02\xff\xfe", "cannot read|invalid YAML|expected a mapping"),
    ("JSON NaN", "nan.json", '{"bodies": [], "world": {"gravity": [NaN, 0]}}', "finite"),
    ("huge magnitude", "huge.yaml", "bodies:\n  - {name: a, shape: box, width: 1, height: 1, position: [1e300, 0]}\n",
     "position"),
    ("zero mass", "zero.yaml", "bodies:\n  - {name: a, shape: box, width: 1, height: 1, mass: 0}\n", "mass"),
    ("non-convex polygon", "nc.yaml", "bodies:\n  - {name: p, shape: polygon, vertices: "
     "[[0, 0], [2, 0], [1, 0.3], [2, 2], [0, 2]]}\n", "bodies[0]"),
    ("self-intersecting polygon", "bow.yaml", "bodies:\n  - {name: p, shape: polygon, vertices: "
     "[[0, 0], [1, 1], [1, 0], [0, 1]]}\n", "bodies[0]"),
    ("duplicate body name", "dup.yaml", "bodies:\n  - {name: a, shape: box, width: 1, height: 1}\n"
     "  - {name: a, shape: box, width: 1, height: 1, position: [3, 0]}\n", "duplicate body name 'a'"),
]


@pytest.mark.parametrize("desc,fname,text,words", RUNNER_CASES, ids=[c[0] for c in RUNNER_CASES])
def test_runner_bad_scene_file_exit_2(tmp_path: Path, desc: str, fname: str, text: str, words: str) -> None:
    scene = tmp_path / fname
    scene.write_bytes(text.encode("latin-1") if desc == "binary garbage" else text.encode())
    out = tmp_path / "out"
    res = run_cli(str(scene), "--until", "0.1", "--out", str(out))
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    assert any(w in res.stderr for w in words.split("|")), res.stderr
    assert str(scene.name) in res.stderr  # the message names the file
    assert "Traceback" not in res.stderr
    assert not out.exists()  # nothing written for a rejected scene


# ================================================================ the node

START = {"block1": (-2.5, 0.0), "block2": (2.5, 0.0)}


@pytest.fixture(scope="module")
def sim() -> Iterator[SimClient]:
    with running_sim("-p", "blocks:=2", "-p", "state_rate:=100.0") as (client, _):
        yield client


def at_rest(sim: SimClient, names: tuple[str, ...] = ("block1", "block2")) -> bool:
    # a states message with these bodies: one published before a kill or spawn was answered can still
    # be on its way with the old body set
    got: list[Any] = []

    def has_names() -> bool:
        msg = sim.fresh("bodies/states", timeout=2.0)
        if msg is None or tuple(msg.names) != names:
            return False
        got.append(msg)
        return True

    if not sim.wait_for(has_names, 15.0):
        return False
    msg = got[-1]
    for i, n in enumerate(msg.names):
        p, t = msg.poses[i].position, msg.twists[i]
        if (p.x, p.y) != START.get(n, (p.x, p.y)) or (t.linear.x, t.linear.y, t.angular.z) != (0.0, 0.0, 0.0):
            return False
    return True


@pytest.fixture(autouse=False)
def fresh(sim: SimClient) -> None:
    assert sim.call(SetBool, "pause", SetBool.Request(data=False)) is not None
    assert sim.call(Empty, "reset") is not None
    assert sim.wait_for(lambda: at_rest(sim), 20.0)


def sim_time(sim: SimClient) -> float:
    t = sim.sim_time()
    assert t is not None
    return t


def unchanged(sim: SimClient, t0: float) -> None:
    """Sim time advanced beyond t0 (+0.1 s), and the blocks are still exactly at rest where they started."""
    assert sim.wait_for(lambda: (sim.sim_time(1.0) or 0.0) > t0 + 0.1, 30.0)
    assert at_rest(sim)


WRONG_TYPES = [  # (topic, a message of the wrong type)
    ("thrusters", String(data="fire")),
    ("block1/thrust", Twist(linear=Vector3(x=5.0))),
    ("spring", ThrusterCommand(body="block1", firing=[True])),
    ("cmd_vel", TwistStamped(twist=Twist(linear=Vector3(x=1.0)))),  # the node expects plain Twist
]


@pytest.mark.usefixtures("fresh")
def test_wrong_message_type_on_command_topics(sim: SimClient) -> None:
    t0 = sim_time(sim)
    for topic, msg in WRONG_TYPES:
        sim.publish(topic, msg)
    for _ in range(20):
        for topic, msg in WRONG_TYPES:
            sim.publish(topic, msg)
        sim.spin(0.01)
    unchanged(sim, t0)
    for topic, _ in WRONG_TYPES:
        sim.forget(topic)
    # the right type on the same topics still works afterwards
    assert sim.wait_subscribed("block1/thrust", WrenchStamped)
    m = WrenchStamped()
    m.wrench.force.x = 1.0
    sim.publish("block1/thrust", m)
    assert sim.wait_for(lambda: (sim.body_state("block1") or (0, 0, 0, 0))[3] > 0.0, 10.0)
    sim.forget("block1/thrust")
    sim.forget("cmd_vel")


@pytest.mark.usefixtures("fresh")
def test_more_bad_commands_are_rejected_and_change_nothing(sim: SimClient) -> None:
    t0 = sim_time(sim)
    assert sim.wait_subscribed("block1/thrust", WrenchStamped)
    m = WrenchStamped()
    m.header.frame_id = "map"
    m.wrench.force.x = 1.0
    sim.publish("block1/thrust", m)
    neg = WrenchStamped()
    neg.wrench.torque.z = -INF
    sim.publish("block2/thrust", neg)
    sim.publish("cmd_vel", Twist(linear=Vector3(x=1e6)))
    sim.publish("cmd_vel", Twist(angular=Vector3(z=-INF)))
    sim.publish("spring", SpringCommand(name="never", release=True))
    sim.publish("spring", SpringCommand(name="w", body="wall_left", target=Point(x=0.0, y=0.0)))
    sim.publish("spring", SpringCommand(name="h", body="block1", body_point=Point(x=NAN)))
    sim.publish("thrusters", ThrusterCommand(body="", firing=[]))
    expected = ["frame_id 'map' is neither", "block2/thrust: force (0.0, 0.0) N / torque -inf",
                "exceeds 1000 m/s", "cmd_vel: (0.0, 0.0, -inf) is not finite",
                "release of 'never', which does not exist", "body 'wall_left' is static",
                "spring 'h': non-finite", "thrusters: no body named ''"]
    for text in expected:
        assert sim.wait_rosout(text) is not None, f"no warning with {text!r}"
    unchanged(sim, t0)


@pytest.mark.usefixtures("fresh")
def test_duplicate_and_bad_spawns(sim: SimClient) -> None:
    t0 = sim_time(sim)
    ok = Spawn.Request(name="crate", width=1.0, height=1.0, mass=1.0, elasticity=1.0)
    ok.pose.position.y = -4.0
    r = sim.call(Spawn, "spawn", ok)
    assert r.success and r.name == "crate", r.message
    again = Spawn.Request(name="crate", width=1.0, height=1.0, mass=1.0, elasticity=1.0)
    again.pose.position.y = 4.0
    cases: list[tuple[Spawn.Request, str]] = [(again, "crate")]
    taken = Spawn.Request(name="block1", width=1.0, height=1.0, mass=1.0)
    taken.pose.position.y = 4.0
    cases.append((taken, "block1"))
    wall = Spawn.Request(name="wall_top", width=1.0, height=1.0, mass=1.0)
    wall.pose.position.y = 4.0
    cases.append((wall, "wall_top"))
    nanpose = Spawn.Request(name="np", width=1.0, height=1.0, mass=1.0)
    nanpose.pose.position.x = NAN
    cases.append((nanpose, ""))
    inftwist = Spawn.Request(name="it", width=1.0, height=1.0, mass=1.0)
    inftwist.pose.position.y = 4.0
    inftwist.twist.linear.x = INF
    cases.append((inftwist, ""))
    huge = Spawn.Request(name="hg", width=1e300, height=1.0, mass=1.0)
    huge.pose.position.y = 4.0
    cases.append((huge, ""))
    zero_mass_neg = Spawn.Request(name="zm", width=1.0, height=1.0, mass=-1e-300)
    zero_mass_neg.pose.position.y = 4.0
    cases.append((zero_mass_neg, "mass"))
    bow = Spawn.Request(name="bow", vertices=[0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 1.0], mass=1.0)
    bow.pose.position.y = 4.0
    cases.append((bow, ""))
    nonconvex = Spawn.Request(name="nc", vertices=[0.0, 0.0, 2.0, 0.0, 1.0, 0.3, 2.0, 2.0, 0.0, 2.0], mass=1.0)
    nonconvex.pose.position.y = 2.5
    cases.append((nonconvex, ""))
    inside_wall = Spawn.Request(name="iw", width=1.0, height=1.0, mass=1.0)
    inside_wall.pose.position.x = 6.2
    cases.append((inside_wall, "overlaps body 'wall_right'"))
    on_crate = Spawn.Request(name="oc", width=1.0, height=1.0, mass=1.0)
    on_crate.pose.position.x, on_crate.pose.position.y = 0.3, -4.2
    cases.append((on_crate, "overlaps body 'crate'"))
    for req, words in cases:
        res = sim.call(Spawn, "spawn", req)
        assert res is not None and not res.success, req.name
        assert res.message and words in res.message, (req.name, res.message)
    assert list(sim.fresh("bodies/states").names) == ["block1", "block2", "crate"]
    st = sim.body_state("crate")
    assert st is not None and (st[0], st[3], st[4]) == (0.0, 0.0, 0.0)  # the first crate untouched
    r = sim.call(Kill, "kill", Kill.Request(name="ghost"))
    assert r is not None and not r.success and "ghost" in r.message
    assert sim.call(Kill, "kill", Kill.Request(name="crate")).success
    unchanged(sim, t0)


@pytest.mark.usefixtures("fresh")
def test_step_refusals(sim: SimClient) -> None:
    t0 = sim_time(sim)
    r = sim.call(Step, "step", Step.Request(steps=10))
    assert r is not None and not r.success and "only while paused" in r.message
    assert sim.call(SetBool, "pause", SetBool.Request(data=True)).success
    r = sim.call(Step, "step", Step.Request(steps=2_000_000))
    assert r is not None and not r.success and "exceeds 1000000" in r.message
    assert sim.call(SetBool, "pause", SetBool.Request(data=False)).success
    unchanged(sim, t0)


def _bad_values(spec: node_params.Spec) -> list[tuple[Any, str]]:
    """(value, why) pairs every parameter must refuse."""
    d = spec.default
    if spec.read_only:
        return [(d, "read-only")]
    if isinstance(d, bool):
        return [(1, "int for bool"), ("true", "str for bool")]
    if isinstance(d, int):
        out: list[tuple[Any, str]] = [(float(d), "double for int"), ("3", "str for int")]
        return out + [(int(spec.lo) - 1, "below range"), (int(spec.hi) + 1, "above range")]
    if isinstance(d, float):
        out = [(NAN, "NaN"), (INF, "inf"), (-INF, "-inf"), (int(d), "int for double"), ("1.0", "str for double")]
        return out + [(float(spec.lo) - 1.0, "below range"), (float(spec.hi) * 2 + 1.0, "above range")]
    out = [(1.5, "double for string"), (True, "bool for string")]
    if spec.name == "world_frame":
        out += [("", "empty frame"), ("/world", "leading slash"), ("my frame", "space in frame")]
    if spec.name == "frame_prefix":
        out += [("/robot1/", "leading slash"), ("my robot/", "space in frame")]
    if spec.name == "cmd_vel_body":
        out += [("", "empty body"), ("ghost", "unknown body"), ("wall_left", "static body")]
    return out


PARAM_CASES = [(s.name, v, why) for s in node_params.SPECS for v, why in _bad_values(s)]


def test_every_parameter_refuses_bad_values(sim: SimClient) -> None:
    names = [s.name for s in node_params.SPECS]
    before = sim.get_params(names)
    assert before is not None
    t0 = sim_time(sim)
    refused: dict[str, str] = {}
    for name, value, why in PARAM_CASES:
        res = sim.set_params({name: value})
        assert res is not None and not res[0].successful, f"{name} accepted {value!r} ({why})"
        assert res[0].reason, f"{name} {why}: no reason"
        refused[f"{name} {why}"] = res[0].reason
    after = sim.get_params(names)
    assert after == before  # NaN never got in, so == is exact here
    assert sim.wait_for(lambda: (sim.sim_time(1.0) or 0.0) > t0 + 0.1, 30.0)
    # rclpy's range check refuses NaN/inf itself (NaN compares false with both bounds)
    assert "out of range" in refused["gravity NaN"] and "nan" in refused["gravity NaN"]
    assert "Wrong parameter type" in refused["blocks double for int"]
    assert "read-only" in refused["scene_file read-only"]
    # the on-set callback's reasons, for what a range cannot express
    assert refused["world_frame space in frame"] == ("world_frame: frame id 'my frame' has characters other "
                                                     "than letters, digits, '_', '-', '.', '/'")
    assert "no dynamic body named 'wall_left'" in refused["cmd_vel_body static body"]
    assert refused["frame_prefix leading slash"] == "frame_prefix: frame id '/robot1/' must not start with '/'"
    assert "read-only" in refused["publish_clock read-only"]
    assert len(PARAM_CASES) > 100
