"""visualization_msgs/MarkerArray for RViz / Foxglove, written as CDR bytes (see cdr.py).

Markers (all in ``world_frame``):
- ns ``bodies``: one LINE_STRIP per body (id = body id), the closed outline in the body frame about
  the centre of mass, placed by ``pose`` = the body's pose; only the stamps and poses change between
  publishes, so they are numpy writes into a template.
- ns ``springs``: one LINE_LIST per spring (id = index), from the body point to the target.
- ns ``contacts``: id 0 POINTS at the contact points, id 1 LINE_LIST along the normals (0.3 m),
  replaced every publish and DELETEd when there are none.
A reset (and the start, and a kill) publishes one message that begins with a DELETEALL marker (action 3)
and goes on with the new scene: with the publisher's depth-1 history, a DELETEALL sent on its own could
be replaced by the next message before a subscriber took it.

Field order is visualization_msgs/msg/Marker of ROS 2 Jazzy (texture, uv_coordinates, mesh_file
included); tests/python/test_node_cdr.py compares these bytes with rclpy's serializer.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from collide_ros.cdr import CdrWriter, _Template, ENCAPSULATION

LINE_STRIP = 4
LINE_LIST = 5
POINTS = 8
ADD = 0
DELETE = 2
DELETEALL = 3

Color = tuple[float, float, float, float]

GREEN: Color = (0.2, 0.75, 0.2, 1.0)
WALL: Color = (0.5, 0.5, 0.5, 1.0)
SPRING: Color = (0.9, 0.6, 0.1, 1.0)
CONTACT: Color = (0.9, 0.1, 0.1, 1.0)
PALETTE: tuple[Color, ...] = (
    (0.85, 0.25, 0.2, 1.0), (0.2, 0.4, 0.9, 1.0), (0.9, 0.7, 0.1, 1.0),
    (0.6, 0.3, 0.8, 1.0), (0.1, 0.7, 0.7, 1.0),
)


def body_color(name: str, index: int, is_static: bool) -> Color:
    if is_static:
        return WALL
    if name == "block1":
        return GREEN
    return PALETTE[index % len(PALETTE)]


@dataclass
class MarkerSpec:
    """Everything of one Marker that the node sets; the rest stays at its default."""
    ns: str
    id: int
    type: int
    action: int = ADD
    pose: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    scale: tuple[float, float, float] = (0.0, 0.0, 0.0)
    color: Color = (0.0, 0.0, 0.0, 0.0)
    points: np.ndarray | None = None  # (k, 3)


def write_marker(w: CdrWriter, m: MarkerSpec, sec: int, nanosec: int, frame_id: str) -> tuple[int, int]:
    """Serializes one Marker; returns (stamp offset, pose offset)."""
    s = w.header(sec, nanosec, frame_id)
    w.string(m.ns)
    w.i32(m.id)
    w.i32(m.type)
    w.i32(m.action)
    p = w.f64s(m.pose)
    w.f64s(m.scale)
    w.f32s(m.color)
    w.i32(0)       # lifetime.sec
    w.u32(0)       # lifetime.nanosec
    w.boolean(False)  # frame_locked
    pts = m.points
    if pts is None or len(pts) == 0:
        w.u32(0)
    else:
        w.u32(len(pts))
        w.f64s(np.asarray(pts, dtype=np.float64).ravel())
    w.u32(0)       # colors[]
    w.string("")   # texture_resource
    w.header(0, 0, "")  # texture.header
    w.string("")   # texture.format
    w.u32(0)       # texture.data[]
    w.u32(0)       # uv_coordinates[]
    w.string("")   # text
    w.string("")   # mesh_resource
    w.string("")   # mesh_file.filename
    w.u32(0)       # mesh_file.data[]
    w.boolean(False)  # mesh_use_embedded_materials
    return s, p


class MarkerArrayCdr:
    """Body outlines as a template; springs and contacts appended per publish."""

    def __init__(self, frame_id: str, ids: Sequence[int], outlines: Sequence[np.ndarray],
                 colors: Sequence[Color], line_width: float = 0.05, lead: Sequence[MarkerSpec] = ()) -> None:
        """lead: markers before the bodies (a DELETEALL), stamped as they are."""
        self.frame_id = frame_id
        self.n = len(lead) + len(ids)
        w = CdrWriter()
        w.u32(0)  # marker count, rewritten per publish
        stamps: list[int] = []
        poses: list[int] = []
        for spec in lead:
            stamps.append(write_marker(w, spec, 0, 0, frame_id)[0])
        for bid, outline, color in zip(ids, outlines, colors):
            loop = np.vstack([outline, outline[:1]])
            pts = np.zeros((len(loop), 3))
            pts[:, :2] = loop
            spec = MarkerSpec("bodies", int(bid), LINE_STRIP, ADD, scale=(line_width, 0.0, 0.0),
                              color=color, points=pts)
            s, p = write_marker(w, spec, 0, 0, frame_id)
            stamps.append(s)
            poses.append(p)
        self._end = len(w.buf) - len(ENCAPSULATION)
        self._t = _Template(w, stamps, {"pose": np.array(poses, dtype=np.int64)})

    def encode(self, sec: int, nanosec: int, poses: np.ndarray, extras: Sequence[MarkerSpec]) -> bytes:
        """poses (n, 7) for the bodies in constructor order; extras serialized after them."""
        t = self._t
        t._u32[0] = np.uint32(self.n + len(extras))
        if self.n:
            t.set_stamp(sec, nanosec)
            if len(poses):
                t.set_doubles("pose", poses)
        if not extras:
            return t.tobytes()
        # The extras only need the template's end modulo 8 (CDR alignment), not a copy of its bytes;
        # template and extras are copied once, into the message.
        lead = self._end % 8
        w = CdrWriter(start=lead)
        for m in extras:
            write_marker(w, m, sec, nanosec, self.frame_id)
        return b"".join((t.buf.data, memoryview(w.buf)[len(ENCAPSULATION) + lead:]))


DELETE_ALL = MarkerSpec("", 0, 0, DELETEALL)


def delete_all(frame_id: str, sec: int, nanosec: int) -> bytes:
    """A MarkerArray of the DELETEALL marker alone."""
    w = CdrWriter()
    w.u32(1)
    write_marker(w, DELETE_ALL, sec, nanosec, frame_id)
    return bytes(w.buf)


def spring_markers(endpoints: Sequence[tuple[np.ndarray, np.ndarray]]) -> list[MarkerSpec]:
    out = []
    for i, (a, b) in enumerate(endpoints):
        pts = np.array([[a[0], a[1], 0.0], [b[0], b[1], 0.0]])
        out.append(MarkerSpec("springs", i, LINE_LIST, ADD, scale=(0.03, 0.0, 0.0), color=SPRING, points=pts))
    return out


def contact_markers(points: np.ndarray, normals: np.ndarray, normal_length: float = 0.3) -> list[MarkerSpec]:
    """points, normals (m, 2). With no contacts both contact markers are deleted."""
    if len(points) == 0:
        return [MarkerSpec("contacts", 0, POINTS, DELETE), MarkerSpec("contacts", 1, LINE_LIST, DELETE)]
    m = len(points)
    p3 = np.zeros((m, 3))
    p3[:, :2] = points
    seg = np.zeros((2 * m, 3))
    seg[0::2, :2] = points
    seg[1::2, :2] = points + normal_length * normals
    return [MarkerSpec("contacts", 0, POINTS, ADD, scale=(0.12, 0.12, 0.0), color=CONTACT, points=p3),
            MarkerSpec("contacts", 1, LINE_LIST, ADD, scale=(0.02, 0.0, 0.0), color=CONTACT, points=seg)]
