"""The node's ``contacts`` message, written as CDR bytes by ``cdr.ContactsCdr``, carries exactly
what a Python object path carries (one ``Contact`` per kept row, serialized by rclpy; the function
below is that reference).

One in-process node (no executor, no subscribers) runs the node bench's pile: 200 boxes dropped
with friction (bench/node_bench.py, pile_scene). Its publishes are recorded with the rows
``_take_contacts`` handed over: an empty message first (``~/reset`` publishes before any step),
then impacts and resting contacts, messages held at the cap of 1000 while the pile forms, and,
after a body with unread impacts is killed, names of an id the node no longer knows. Every message
must decode field by field to the object path's message and match its bytes. The rows themselves
(``_take_contacts``, joined as opaque records) are checked against np.concatenate on their own.
"""
from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
import rclpy
import yaml
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Vector3
from libcollide_msgs.msg import Contact, Contacts
from libcollide_msgs.srv import Kill
from rclpy.serialization import deserialize_message, serialize_message

import collide
from collide_ros import cdr
from collide_ros.node import MAX_CONTACTS_PER_MESSAGE, SimNode, _concat_rows

from bench_module import load_node_bench

STEPS = 2000      # the pile holds 1000 contacts per message from ~1.5 s on
KILL_AT = 1700    # step after which a body with unread impacts is killed
FIELDS = ("body_a", "body_b", "point", "normal", "gap", "normal_velocity", "impulse", "tangent_impulse",
          "force", "kind")


def _pile_scene(n: int) -> dict[str, Any]:
    return load_node_bench().pile_scene(n)


def object_path(rows: np.ndarray, name_of_id: dict[int, str], stamp: Time, frame: str) -> Contacts:
    """The contacts message as the node built it up to commit 04f7bee (node.py, _publish_state)."""
    cm = Contacts()
    cm.header.stamp = stamp
    cm.header.frame_id = frame
    if len(rows):
        out = []
        for row in rows:
            out.append(Contact(
                body_a=name_of_id.get(int(row["body_a"]), str(int(row["body_a"]))),
                body_b=name_of_id.get(int(row["body_b"]), str(int(row["body_b"]))),
                point=Point(x=float(row["point"][0]), y=float(row["point"][1]), z=0.0),
                normal=Vector3(x=float(row["normal"][0]), y=float(row["normal"][1]), z=0.0),
                gap=float(row["gap"]), normal_velocity=float(row["normal_velocity"]),
                impulse=float(row["impulse"]), tangent_impulse=float(row["tangent_impulse"]),
                force=float(row["force"]), kind=int(row["kind"])))
        cm.contacts = out
    return cm


@dataclass
class Published:
    raw: bytes                  # what the node handed to the publisher
    stamp: Time                 # the node's sim time then
    rows: np.ndarray            # what _take_contacts returned for it
    names: dict[int, str]       # the node's id -> name map then
    frame: str


def _record(node: SimNode, log: list[Published]) -> None:
    """Instance wrappers: the rows of each _take_contacts, and the bytes of each contacts publish."""
    take, publish = node._take_contacts, node._pub_contacts.pub.publish
    taken: list[np.ndarray] = []

    def take_kept() -> np.ndarray:
        rows = take()
        taken.append(rows.copy())
        return rows

    def publish_kept(msg: Any) -> None:
        assert isinstance(msg, bytes), "the contacts message should be published as CDR bytes"
        sec, ns = cdr.split_time(node.sim_time)
        log.append(Published(msg, Time(sec=sec, nanosec=ns), taken.pop(), dict(node._name_of_id),
                             str(node._p["world_frame"])))
        publish(msg)
    node._take_contacts = take_kept  # type: ignore[method-assign]
    node._pub_contacts.pub.publish = publish_kept


def _kill_a_body_with_unread_impacts(node: SimNode) -> int:
    """Kill a dynamic body that the last step's impacts name, after a step with no publish: those
    impacts are unread in the world's event stream (the next contacts message carries them); returns
    its id."""
    c = node.world.contacts
    hits = c[c["kind"] == collide.COLLISION]
    dynamic = {int(node._ids[r]) for r in node._dyn_rows}
    victim = next(int(i) for i in np.concatenate([hits["body_a"], hits["body_b"]])
                  if int(i) in dynamic and node._name_of_id[int(i)] != "block1")
    resp = node._srv_kill(Kill.Request(name=node._name_of_id[victim]), Kill.Response())
    assert resp.success, resp.message
    return victim


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[list[Published], int]]:
    scene = tmp_path_factory.mktemp("pile") / "pile.yaml"
    scene.write_text(yaml.safe_dump(_pile_scene(200)))
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    node = SimNode(context=ctx, cli_args=["--ros-args", "-r", "__ns:=/contacts_cdr", "-p", f"scene_file:={scene}"])
    log: list[Published] = []
    try:
        _record(node, log)
        node.reset()  # publishes the state of the fresh world, before any step: no contacts
        killed = -1
        every = round(1.0 / (node.get_parameter("state_rate").value * node.get_parameter("time_step").value))
        for k in range(STEPS):
            assert node.step_once(), node.last_rejection
            c = node.world.contacts
            if (k + 1 >= KILL_AT and killed < 0 and (k + 1) % every
                    and np.any(c["kind"] == collide.COLLISION) and node.world.pending_events):
                killed = _kill_a_body_with_unread_impacts(node)
        yield log, killed
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)


def _first_difference(got: Contacts, ref: Contacts) -> str:
    if (got.header.stamp, got.header.frame_id) != (ref.header.stamp, ref.header.frame_id):
        return f"header {got.header} != {ref.header}"
    if len(got.contacts) != len(ref.contacts):
        return f"{len(got.contacts)} contacts != {len(ref.contacts)}"
    for i, (a, b) in enumerate(zip(got.contacts, ref.contacts)):
        for f in FIELDS:
            if getattr(a, f) != getattr(b, f):
                return f"contact {i}: {f} {getattr(a, f)} != {getattr(b, f)}"
    return ""


def test_the_run_covers_every_case(run: tuple[list[Published], int]) -> None:
    log, killed = run
    sizes = [len(p.rows) for p in log]
    kinds = [set(int(k) for k in p.rows["kind"]) for p in log]
    assert sizes[0] == 0
    assert any(kind == {collide.COLLISION, collide.RESTING} for kind in kinds)
    assert sizes.count(MAX_CONTACTS_PER_MESSAGE) >= 10 and max(sizes) == MAX_CONTACTS_PER_MESSAGE
    assert killed >= 0 and any(killed in p.rows["body_a"] or killed in p.rows["body_b"] for p in log
                               if killed not in p.names)


def test_cdr_contacts_equal_the_object_path(run: tuple[list[Published], int]) -> None:
    log, killed = run
    for i, p in enumerate(log):
        got = deserialize_message(p.raw, Contacts)
        ref = object_path(p.rows, p.names, p.stamp, p.frame)
        assert got == ref, f"message {i}: {_first_difference(got, ref)}"
        # byte for byte, apart from padding (rclpy leaves it uninitialised, ours is zero)
        want = np.frombuffer(serialize_message(ref), np.uint8)
        have = np.frombuffer(p.raw, np.uint8)
        assert len(have) == len(want) and not np.any(have[have != want]), f"message {i}"
    names = [c.body_a for p in log for c in deserialize_message(p.raw, Contacts).contacts
             if killed not in p.names and killed in p.rows["body_a"]]
    assert str(killed) in names  # the object path's name for an id the node no longer knows


def test_concat_rows_equals_numpy_concatenate() -> None:
    # _take_contacts joins the unread impacts and the resting contacts as opaque records (C's padded
    # lc_contact layout kept); field for field the same rows as np.concatenate, also across dtypes
    rng = np.random.default_rng(3)
    parts = []
    for n in (4, 0, 7, 1):
        rows = np.zeros(n, dtype=collide.CONTACT_DTYPE)
        for f in collide.CONTACT_DTYPE.names:
            rows[f] = rng.integers(0, 1000, rows[f].shape) if f in ("body_a", "body_b", "kind") \
                else rng.normal(size=rows[f].shape)
        parts.append(rows)
    packed = np.concatenate(parts[:2])  # numpy's own result has a packed dtype
    for case in (parts, [packed, *parts[2:]]):
        got, want = _concat_rows(case), np.concatenate(case)
        assert len(got) == len(want) == sum(len(p) for p in case)
        for f in collide.CONTACT_DTYPE.names:
            assert np.array_equal(got[f], want[f]), f
    assert _concat_rows(parts).dtype == collide.CONTACT_DTYPE
