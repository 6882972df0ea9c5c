"""The node's ``contacts`` topic against the world's own impacts: every impact between two publishes
arrives, in order, bit for bit, and what the messages leave out is counted in /diagnostics.

Each case runs a node process on a scene file with no commands, so its world steps exactly as the same
scene built in this process does (the node adds no force without a command). The replay polls the
contacts view after every step (the collisions of that step: an account independent of the event
stream the node reads) and builds the messages the node must publish by its documented rule
(docs/ros_interface.md, ``contacts``): every ``publish_every`` steps, the oldest unread impacts up to
the cap of 1000 (the rest wait), then the latest step's resting contacts as room allows (the rest
dropped and counted); unread impacts past the scene's ``event_capacity`` drop the oldest (counted).
A client with a deep reliable subscription receives the messages; they must equal the replay's field
by field, the message count must equal the node's ``published/contacts``, and ``dropped_contacts``
and ``dropped_impacts`` must equal the replay's counts.

- ``test_1khz_steps_100hz_publishes``: the real stepping loop at 1 kHz (time_step 0.001 s, real-time
  factor 1) publishing at 100 Hz, twelve boxes bouncing in a box; most impacts happen in steps after
  which nothing is published.
- ``test_impacts_past_the_cap_wait``: 600 boxes dropped side by side onto a floor, stepped by ~/step:
  1200 impacts in one step, 1000 in one message and the other 200 first in the next; 1200 resting
  contacts from then on, sent as room allows and the rest dropped.
- ``test_stream_overflow_is_counted``: the same with ``event_capacity: 500``: of the 1200 the oldest
  700 go, counted in ``dropped_impacts``; with ``event_capacity: 0`` all 1200.
"""
from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rclpy
import yaml
from libcollide_msgs.msg import Contacts
from libcollide_msgs.srv import Step
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_srvs.srv import SetBool

import collide
from collide_ros import cdr
from collide_ros.testing import NodeProcess, SimClient

DT = 0.001
PUBLISH_EVERY = 10       # state_rate 100 Hz at time_step 0.001 s
CAP = 1000               # contacts per message (collide_ros.sim.publishing.MAX_CONTACTS_PER_MESSAGE)


def bouncing_scene() -> dict[str, Any]:
    """Twelve boxes with assorted velocities in a 4 m x 4 m box, no damping, elasticity 0.9."""
    rng = np.random.default_rng(11)
    bodies = []
    for i in range(12):
        x, y = -1.5 + (i % 4), -1.0 + (i // 4)
        vx, vy = rng.uniform(-3, 3, 2)
        bodies.append({"name": f"b{i}", "shape": "box", "width": 0.3, "height": 0.2, "position": [x, y],
                       "velocity": [float(vx), float(vy)], "angular_velocity": float(rng.uniform(-2, 2)),
                       "elasticity": 0.9})
    return {"world": {"gravity": [0, -9.81]}, "walls": {"xmin": -2, "ymin": -2, "xmax": 2, "ymax": 2,
                                                         "elasticity": 0.9},
            "bodies": bodies, "run": {"dt": DT}}


def row_scene(n: int, event_capacity: int | None = None) -> dict[str, Any]:
    """``n`` boxes 1 cm above a static floor, side by side, inelastic: they land in one step (t = 45.2 ms,
    two corners each) and stay, resting on two contacts each."""
    bodies: list[dict[str, Any]] = [{"name": "floor", "shape": "box", "width": 0.2 * n + 1, "height": 1.0,
                                     "position": [0.1 * n, -0.5], "static": True, "elasticity": 0.0}]
    bodies += [{"name": f"r{i}", "shape": "box", "width": 0.1, "height": 0.1, "position": [0.2 * i + 0.5, 0.06],
                "elasticity": 0.0} for i in range(n)]
    world: dict[str, Any] = {"gravity": [0, -9.81]}
    if event_capacity is not None:
        world["event_capacity"] = event_capacity
    return {"world": world, "bodies": bodies, "run": {"dt": DT}}


@dataclass
class Expected:
    """The node's contacts messages by its documented rule, from a replay that polls every step."""

    messages: list[tuple[float, np.ndarray]] = field(default_factory=list)  # (sim time, rows)
    dropped_contacts: int = 0
    dropped_impacts: int = 0
    impacts: int = 0                 # impacts the world reported
    impacts_between: int = 0         # of those, in steps after which nothing is published
    carried: int = 0                 # publishes that left impacts for the next message


def replay(scene: dict[str, Any], steps: int) -> Expected:
    world = collide.load_scene(scene).build()
    capacity = int(world.settings["event_capacity"])
    unread: deque[np.ndarray] = deque()
    out = Expected()
    for s in range(1, steps + 1):
        world.step(DT)
        c = world.contacts
        hits = c[c["kind"] == collide.COLLISION]
        out.impacts += len(hits)
        unread.extend(hits.copy())
        while len(unread) > capacity:
            unread.popleft()
            out.dropped_impacts += 1
        if s % PUBLISH_EVERY:
            out.impacts_between += len(hits)
            continue
        taken = [unread.popleft() for _ in range(min(CAP, len(unread)))]
        out.carried += bool(unread)
        resting = c[c["kind"] == collide.RESTING]
        room = CAP - len(taken)
        out.dropped_contacts += max(0, len(resting) - room)
        rows = np.array(taken + list(resting[:room]), dtype=collide.CONTACT_DTYPE)
        out.messages.append((world.time, rows))
    return out


def names_of(scene: dict[str, Any]) -> dict[int, str]:
    world = collide.load_scene(scene).build()
    return {int(i): n for i, n in zip(world.ids, world.names)}


def assert_message_equals(msg: Contacts, when: float, rows: np.ndarray, names: dict[int, str], k: int) -> None:
    sec, ns = cdr.split_time(when)
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (sec, ns), f"message {k}: stamp"
    assert len(msg.contacts) == len(rows), f"message {k}: {len(msg.contacts)} contacts, replay {len(rows)}"
    for i, (c, r) in enumerate(zip(msg.contacts, rows)):
        got = (c.body_a, c.body_b, c.point.x, c.point.y, c.normal.x, c.normal.y, c.gap, c.normal_velocity,
               c.impulse, c.tangent_impulse, c.force, c.kind)
        want = (names[int(r["body_a"])], names[int(r["body_b"])], *map(float, r["point"]),
                *map(float, r["normal"]), float(r["gap"]), float(r["normal_velocity"]), float(r["impulse"]),
                float(r["tangent_impulse"]), float(r["force"]), int(r["kind"]))
        assert got == want, f"message {k}, contact {i}: {got} != {want}"  # bit for bit: the same steps


@dataclass
class Run:
    client: SimClient
    proc: NodeProcess
    received: list[Contacts]


@contextmanager
def paused_node(scene: dict[str, Any], path: Path, ns: str) -> Iterator[Run]:
    """A paused node on ``scene`` and a client whose deep reliable subscription to its contacts the
    node's writer has matched (so it gets every message from the first step on)."""
    path.write_text(yaml.safe_dump(scene))
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    proc = NodeProcess("-r", f"__ns:={ns}", "-p", f"scene_file:={path}", "-p", f"time_step:={DT}",
                       "-p", "state_rate:=100.0", "-p", "start_paused:=true", "-p", "publish_clock:=false",
                       # the writer keeps 10 s of messages for a client starved of CPU (reliable KEEP_LAST)
                       "-p", "state_qos_depth:=1000")
    client = SimClient(ns, context=ctx, watch=("diagnostics",))
    received: list[Contacts] = []
    deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    client.node.create_subscription(Contacts, f"{ns}/contacts", received.append, deep)
    try:
        assert client.wait_node_matched("contacts", timeout=60.0), proc.output()
        yield Run(client, proc, received)
    finally:
        client.close()
        code = proc.stop()
        rclpy.shutdown(context=ctx)
    assert code == 0, proc.output()


def pause(client: SimClient, on: bool) -> None:
    r = client.call(SetBool, "pause", SetBool.Request(data=on))
    assert r is not None and r.success


def settled(run: Run) -> dict[str, int]:
    """The paused node's counts once settled, after every contacts message it published arrived."""
    counts = run.client.settled_counts(timeout=30.0)
    assert counts is not None, run.proc.output()
    assert run.client.wait_for(lambda: len(run.received) >= counts["published/contacts"], 30.0)
    assert len(run.received) == counts["published/contacts"]
    return counts


def check(run: Run, scene: dict[str, Any], counts: dict[str, int]) -> Expected:
    exp = replay(scene, PUBLISH_EVERY * len(run.received))
    names = names_of(scene)
    for k, (msg, (when, rows)) in enumerate(zip(run.received, exp.messages)):
        assert_message_equals(msg, when, rows, names, k)
    assert counts["dropped_contacts"] == exp.dropped_contacts
    assert counts["dropped_impacts"] == exp.dropped_impacts
    return exp


def test_1khz_steps_100hz_publishes(tmp_path: Path) -> None:
    scene = bouncing_scene()
    with paused_node(scene, tmp_path / "bounce.yaml", "/impacts_rt") as run:
        pause(run.client, False)
        assert run.client.wait_for(lambda: len(run.received) >= 150, 120.0), run.proc.output()
        pause(run.client, True)
        counts = settled(run)
    exp = check(run, scene, counts)
    received = sum(int(np.sum([c.kind == collide.COLLISION for c in m.contacts])) for m in run.received)
    assert received == exp.impacts  # every impact the world reported, none past the cap or the stream
    assert exp.dropped_impacts == 0 and exp.carried == 0
    # the case the event stream exists for: most impacts fall in steps without a publish, where the
    # contacts view of the publishing step no longer shows them
    assert exp.impacts >= 50 and exp.impacts_between > exp.impacts / 2


def _step(run: Run, steps: int) -> None:
    r = run.client.call(Step, "step", Step.Request(steps=steps), timeout=60.0)
    assert r is not None and r.success, None if r is None else r.message


def test_impacts_past_the_cap_wait(tmp_path: Path) -> None:
    scene = row_scene(600)
    with paused_node(scene, tmp_path / "row.yaml", "/impacts_cap") as run:
        _step(run, 100)
        counts = settled(run)
    exp = check(run, scene, counts)
    sizes = [len(m.contacts) for m in run.received]
    assert exp.impacts == 1200 and exp.carried == 1 and exp.dropped_impacts == 0
    assert sizes.count(CAP) == len(sizes) - 4  # none before the landing, full from then on
    assert exp.dropped_contacts == 1200 + 400 + 4 * 200  # no room, room for 800, then 1000 of 1200 (x4)


@pytest.mark.parametrize("capacity", [500, 0])  # 0: the stream keeps none, every impact is dropped
def test_stream_overflow_is_counted(tmp_path: Path, capacity: int) -> None:
    scene = row_scene(600, event_capacity=capacity)
    with paused_node(scene, tmp_path / "row.yaml", "/impacts_overflow") as run:
        _step(run, 100)
        counts = settled(run)
    exp = check(run, scene, counts)
    assert exp.impacts == 1200 and exp.dropped_impacts == 1200 - capacity
    received = sum(int(np.sum([c.kind == collide.COLLISION for c in m.contacts])) for m in run.received)
    assert received + exp.dropped_impacts == exp.impacts

