"""The view reads the node's bulk topics from their CDR bytes (collide_ros/view/cdr_in.py): the same
values as rclpy's own deserialization, for the node's writers (cdr.py, markers.py) and for rclpy's
serializer; the markers' shortcut (same bytes but stamps and poses) gives what a full read gives;
truncated or foreign bytes are refused with ValueError."""
from __future__ import annotations

import numpy as np
import pytest
from libcollide_msgs.msg import BodyStates, Contact, Contacts
from rclpy.serialization import deserialize_message, serialize_message
from visualization_msgs.msg import Marker, MarkerArray

from collide_ros import cdr, markers
from collide_ros.view import cdr_in
from collide_ros.view.scene import yaw_of

RNG = np.random.default_rng(7)


def states_bytes(names: list[str], state: np.ndarray, stamp: tuple[int, int] = (3, 250)) -> bytes:
    return cdr.BodyStatesCdr(names, "world").encode(*stamp, cdr.poses_from_state(state), cdr.twists_from_state(state))


def random_state(n: int) -> np.ndarray:
    st = RNG.uniform(-5.0, 5.0, (n, 6))
    st[:, 2] = RNG.uniform(-np.pi, np.pi, n)
    return st


# rad: the reader's yaw is numpy's arctan2 over the whole array, yaw_of's math.atan2 one at a time; numpy's
# vectorized arctan2 (SVML on a CPU with AVX-512) and libm's agree to an ulp or two, not bit for bit
YAW_ULPS = 4 * float(np.spacing(np.pi))


def check_poses(got: np.ndarray, want: list[list[float]]) -> None:
    """x, y bit for bit; yaw to YAW_ULPS."""
    w = np.array(want, dtype=np.float64).reshape(-1, 3)
    assert got.shape == w.shape
    assert got[:, :2].tolist() == w[:, :2].tolist()
    assert np.all(np.abs(got[:, 2] - w[:, 2]) <= YAW_ULPS), np.max(np.abs(got[:, 2] - w[:, 2]))


def test_states_match_rclpy() -> None:
    names = ["block1", "b2", "crate_ü"]
    st = random_state(3)
    raw = states_bytes(names, st)
    ref = deserialize_message(raw, BodyStates)
    got = cdr_in.StatesReader().read(raw)
    assert got.names == tuple(ref.names) == tuple(names)
    assert got.stamp == ref.header.stamp.sec + 1e-9 * ref.header.stamp.nanosec
    # x, y are the doubles of the message, bit for bit; yaw goes through the same formula as yaw_of
    check_poses(got.poses, [[p.position.x, p.position.y, yaw_of(p.orientation)] for p in ref.poses])
    assert got.twists.tolist() == [[t.linear.x, t.linear.y, t.angular.z] for t in ref.twists]
    # rclpy's serializer writes the same layout
    again = cdr_in.StatesReader().read(serialize_message(ref))
    assert again.names == got.names and np.array_equal(again.poses, got.poses)


def test_states_names_read_again_when_they_change() -> None:
    r = cdr_in.StatesReader()
    st = random_state(3)
    assert r.read(states_bytes(["a", "b", "c"], st)).names == ("a", "b", "c")
    assert r.read(states_bytes(["a", "b", "c"], st)).names == ("a", "b", "c")   # the cached names
    assert r.read(states_bytes(["a", "x", "c"], st)).names == ("a", "x", "c")   # same lengths, new bytes
    got = r.read(states_bytes(["a", "b", "c", "dd"], random_state(4)))
    assert got.names == ("a", "b", "c", "dd") and got.poses.shape == (4, 3)
    assert r.read(states_bytes([], np.zeros((0, 6)))).names == ()


def body_markers(n: int, lead: bool) -> tuple[markers.MarkerArrayCdr, list[int], list[np.ndarray]]:
    outlines = [np.array([[-0.25, -0.25], [0.25, -0.25], [0.25, 0.25], [-0.25, 0.25]]) * (1 + i % 3) for i in range(n)]
    ids = [10 + 3 * i for i in range(n)]
    colors = [markers.body_color(f"b{i}", i, i < 4) for i in range(n)]
    return (markers.MarkerArrayCdr("world", ids, outlines, colors, lead=[markers.DELETE_ALL] if lead else []),
            ids, outlines)


def check_markers(got: cdr_in.Markers, raw: bytes) -> None:
    """got against rclpy's deserialization of the same bytes."""
    ref = deserialize_message(raw, MarkerArray)
    bodies = [m for m in ref.markers if m.ns == "bodies" and m.action == Marker.ADD]
    assert got.ids == [m.id for m in bodies]
    check_poses(got.poses, [[m.pose.position.x, m.pose.position.y, yaw_of(m.pose.orientation)] for m in bodies])
    assert got.verts == [[[p.x, p.y] for p in m.points][:-1] for m in bodies]
    assert got.colors == ["#%02x%02x%02x" % tuple(round(255 * c) for c in (m.color.r, m.color.g, m.color.b))
                          for m in bodies]
    assert got.delete_alls == sum(m.action == Marker.DELETEALL for m in ref.markers)
    assert got.springs == [[m.points[0].x, m.points[0].y, m.points[1].x, m.points[1].y]
                           for m in ref.markers if m.ns == "springs" and m.action == Marker.ADD]
    assert got.stamp == bodies[0].header.stamp.sec + 1e-9 * bodies[0].header.stamp.nanosec


def test_markers_match_rclpy_and_the_shortcut_reads_the_same() -> None:
    n = 40
    plain, ids, _ = body_markers(n, lead=False)
    reset, _, _ = body_markers(n, lead=True)
    reader = cdr_in.MarkersReader()
    layouts = []
    for k, tmpl in enumerate([reset, plain, plain, plain, reset, reset]):
        springs = [(RNG.uniform(-1, 1, 2), RNG.uniform(-1, 1, 2)) for _ in range(k % 3)]
        extras = markers.spring_markers(springs) + markers.contact_markers(RNG.uniform(-1, 1, (k, 2)),
                                                                           RNG.uniform(-1, 1, (k, 2)))
        raw = tmpl.encode(5 + k, 100 * k, cdr.poses_from_state(random_state(n)), extras)
        got = reader.read(raw)
        check_markers(got, raw)
        assert got.ids == ids
        layouts.append(got.layout)
    # the third and fourth messages have the second's layout (the shortcut); a DELETEALL-led message
    # has its own; a repeated one is a shortcut too and still counts its DELETEALL
    assert layouts[2] is layouts[1] and layouts[3] is layouts[1]
    assert layouts[4] is not layouts[1] and layouts[5] is layouts[4]
    # rclpy's serializer of the same message: walked, same values
    ref = deserialize_message(raw, MarkerArray)
    check_markers(cdr_in.MarkersReader().read(serialize_message(ref)), raw)


def test_markers_changed_outline_is_read_in_full() -> None:
    n = 5
    tmpl, _, outlines = body_markers(n, lead=False)
    reader = cdr_in.MarkersReader()
    first = reader.read(tmpl.encode(1, 0, cdr.poses_from_state(random_state(n)), []))
    outlines[2] = outlines[2] * 2.0  # same size in bytes, other vertices
    other = markers.MarkerArrayCdr("world", first.ids, outlines, [markers.GREEN] * n)
    raw = other.encode(1, 0, cdr.poses_from_state(random_state(n)), [])
    got = reader.read(raw)
    assert got.layout is not first.layout
    check_markers(got, raw)


def test_contact_points_match_rclpy() -> None:
    msg = Contacts()
    for i in range(7):
        c = Contact(body_a="b" * (i + 1), body_b="wall", kind=i % 2)
        c.point.x, c.point.y, c.force = 0.5 * i, -1.0 - i, float(i)
        msg.contacts.append(c)
    raw = serialize_message(msg)
    _, pts = cdr_in.contact_points(raw, 100)
    assert pts.tolist() == [[c.point.x, c.point.y] for c in msg.contacts]
    _, pts = cdr_in.contact_points(raw, 4)
    assert len(pts) == 4  # the first `limit` only


@pytest.mark.parametrize("raw", [b"", b"\x00\x01", b"\x00\x00\x00\x00" + bytes(40), b"\x00\x01\x00\x00" + b"\xff" * 40])
def test_foreign_bytes_refused(raw: bytes) -> None:
    with pytest.raises(ValueError):
        cdr_in.StatesReader().read(raw)
    with pytest.raises(ValueError):
        cdr_in.MarkersReader().read(raw)
    with pytest.raises(ValueError):
        cdr_in.contact_points(raw, 10)


def test_truncated_messages_refused() -> None:
    st = states_bytes(["a", "b"], random_state(2))
    tmpl, _, _ = body_markers(3, lead=True)
    mk = tmpl.encode(1, 0, cdr.poses_from_state(random_state(3)), [])
    msg = Contacts(contacts=[Contact(body_a="a", body_b="b")])
    ct = serialize_message(msg)
    for cut in (5, 17, len(st) // 2, len(st) - 1):
        with pytest.raises(ValueError):
            cdr_in.StatesReader().read(st[:cut])
    for cut in (9, 60, len(mk) // 2, len(mk) - 1):
        with pytest.raises(ValueError):
            cdr_in.MarkersReader().read(mk[:cut])
    for cut in (9, 30, len(ct) - 2):
        with pytest.raises(ValueError):
            cdr_in.contact_points(ct[:cut], 10)
