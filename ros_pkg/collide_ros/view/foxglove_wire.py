"""The view's scene as Foxglove protobuf messages (foxglove.SceneUpdate, foxglove.FrameTransforms),
written as bytes.

foxglove-sdk's message classes cost ~30 us per body to build (1 000 bodies: ~30 ms a frame, a core at
30 Hz); the parts of a body that do not change between frames (its id, outline, colours) are encoded
here once per shape set, and a frame only encodes the poses and joins bytes. The encoding is the
canonical proto3 one that the SDK writes (fields in number order, scalars equal to their default left
out, sub-messages always written): tests/python/test_view_foxglove.py checks these bytes against
the SDK's own ``encode()``. Field numbers: foxglove's schemas (the FileDescriptorSet of
``foxglove.messages.SceneUpdate.get_schema()``), which the server advertises with these messages.
"""
from __future__ import annotations

import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass

from collide_ros.cdr import split_time

Rgba = tuple[float, float, float, float]

# wire types
_VARINT, _FIXED64, _LEN = 0, 1, 2
# foxglove.LinePrimitive.Type
LINE_STRIP, LINE_LOOP, LINE_LIST = 0, 1, 2
OUTLINE: Rgba = (0.2, 0.2, 0.2, 1.0)
CONTACT: Rgba = (0.87, 0.13, 0.13, 1.0)
SPRING: Rgba = (0.9, 0.6, 0.1, 1.0)
CONTACT_SIZE = 0.12   # m: diameter of a contact point's sphere
Z_FLAT = 0.0          # the scene lies in the plane z = 0


def _key(num: int, wt: int) -> bytes:
    return _varint((num << 3) | wt)


_SMALL = tuple(bytes((i,)) for i in range(128))


def _varint(v: int) -> bytes:
    if 0 <= v < 128:
        return _SMALL[v]
    if v < 0:
        v += 1 << 64  # int64 as protobuf writes it: ten bytes
    out = bytearray()
    while v >= 0x80:
        out.append((v & 0x7F) | 0x80)
        v >>= 7
    out.append(v)
    return bytes(out)


def _len(num: int, payload: bytes) -> bytes:
    return _key(num, _LEN) + _varint(len(payload)) + payload


def _double(num: int, v: float) -> bytes:
    return b"" if v == 0.0 else _key(num, _FIXED64) + struct.pack("<d", v)


def _string(num: int, s: str) -> bytes:
    return _len(num, s.encode()) if s else b""


def _uint(num: int, v: int) -> bytes:
    return _key(num, _VARINT) + _varint(v) if v else b""


def _xyz(x: float, y: float, z: float = 0.0) -> bytes:
    """foxglove.Vector3 / Point3 (same field numbers)."""
    return _double(1, x) + _double(2, y) + _double(3, z)


def _color(c: Rgba) -> bytes:
    return _double(1, c[0]) + _double(2, c[1]) + _double(3, c[2]) + _double(4, c[3])


def timestamp(t: float) -> bytes:
    """google.protobuf.Timestamp of t seconds (sim time), rounded to 1 ns as the node's stamps are."""
    sec, ns = split_time(t)
    return _uint(1, sec) + _uint(2, ns)


# Pose{position{x, y}, orientation{z, w}} with all four nonzero: 40 bytes (keys and lengths fixed)
_POSE = struct.Struct("<BBBdBdBBBdBd")


# translation{x, y} and rotation{z, w} of a FrameTransform (fields 4, 5), all four nonzero
_TRANSFORM = struct.Struct("<BBBdBdBBBdBd")


def pose(x: float, y: float, yaw: float) -> bytes:
    """foxglove.Pose of a body in the plane: position (x, y, 0), rotation yaw about z."""
    qz, qw = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    if x != 0.0 and y != 0.0 and qz != 0.0 and qw != 0.0:  # the usual case, in one pack
        return _POSE.pack(0x0A, 18, 0x09, x, 0x11, y, 0x12, 18, 0x19, qz, 0x21, qw)
    return _len(1, _xyz(x, y, Z_FLAT)) + _len(2, _double(3, qz) + _double(4, qw))


def hex_rgba(color: str) -> Rgba:
    """'#rrggbb' -> (r, g, b, 1) in 0..1."""
    return (int(color[1:3], 16) / 255.0, int(color[3:5], 16) / 255.0, int(color[5:7], 16) / 255.0, 1.0)


_POSE_LEN = _POSE.size


@dataclass(frozen=True)
class BodyParts:
    """The constant parts of one body's SceneEntity: its id, and around the pose of each primitive."""
    id: bytes          # field 3 of SceneEntity
    line_head: bytes   # LinePrimitive fields before its pose (type)
    line_tail: bytes   # LinePrimitive fields after its pose (thickness, scale_invariant, points, color)
    fill_tail: bytes   # TriangleListPrimitive fields after its pose (points, color)
    # with a 40-byte pose (_POSE): the entity after its timestamp and frame is
    # id + fast_a + pose + fast_b + pose + fill_tail, fast_len bytes in all
    fast_a: bytes
    fast_b: bytes
    fast_len: int


def body_parts(entity_id: str, verts: Sequence[Sequence[float]], color: Rgba) -> BodyParts:
    """A body drawn as its outline (LINE_LOOP, 2 px) over a fill (a triangle fan: the bodies are convex
    polygons), both in the body frame about the centre of mass."""
    pts = [_len(5, _xyz(float(v[0]), float(v[1]))) for v in verts]
    fan: list[bytes] = []
    for k in range(1, len(verts) - 1):
        for v in (verts[0], verts[k], verts[k + 1]):
            fan.append(_len(2, _xyz(float(v[0]), float(v[1]))))
    ident = _string(3, entity_id)
    line_head = _uint(1, LINE_LOOP)
    line_tail = _double(3, 2.0) + _uint(4, 1) + b"".join(pts) + _len(6, _color(OUTLINE))
    fill_tail = b"".join(fan) + _len(3, _color(color))
    pose_key = _varint(_POSE_LEN)
    line_len = len(line_head) + 2 + _POSE_LEN + len(line_tail)
    fill_len = 2 + _POSE_LEN + len(fill_tail)
    fast_a = _key(11, _LEN) + _varint(line_len) + line_head + _key(2, _LEN) + pose_key
    fast_b = line_tail + _key(12, _LEN) + _varint(fill_len) + _key(1, _LEN) + pose_key
    return BodyParts(ident, line_head, line_tail, fill_tail, fast_a, fast_b,
                     len(ident) + len(fast_a) + len(fast_b) + len(fill_tail) + 2 * _POSE_LEN)


def scene_update(stamp: bytes, frame: bytes, bodies: Sequence[BodyParts],
                 poses: Sequence[Sequence[float]], extras: Sequence[bytes] = (),
                 deleted: Sequence[str] = ()) -> bytes:
    """foxglove.SceneUpdate: deletions of the entity ids ``deleted``, then one entity per body at its
    pose (x, y, yaw), then ``extras`` (entities from points_entity / lines_entity).
    stamp: timestamp(t); frame: the world frame's name as string_field(2, name)."""
    ts = _len(1, stamp)
    out = [_len(1, ts + _string(3, d)) for d in deleted]
    head = ts + frame
    entity_key = _key(2, _LEN)
    starts: dict[int, bytes] = {}  # entity length -> its key and length
    for b, p in zip(bodies, poses):
        ps = pose(p[0], p[1], p[2])
        if len(ps) == _POSE_LEN:
            n = len(head) + b.fast_len
            start = starts.get(n)
            if start is None:
                start = starts[n] = entity_key + _varint(n)
            out += (start, head, b.id, b.fast_a, ps, b.fast_b, ps, b.fill_tail)
        else:  # a coordinate exactly 0: proto3 leaves it out, so the lengths differ
            line = _len(11, b.line_head + _len(2, ps) + b.line_tail)  # pose: field 2 of a LinePrimitive,
            fill = _len(12, _len(1, ps) + b.fill_tail)                # field 1 of a TriangleListPrimitive
            out.append(_len(2, head + b.id + line + fill))
    out.extend(_len(2, e) for e in extras)
    return b"".join(out)


def points_entity(stamp: bytes, frame: bytes, entity_id: str, points: Sequence[Sequence[float]]) -> bytes:
    """A SceneEntity (body bytes) of small red spheres at ``points`` (x, y): the contact points."""
    size = _len(2, _xyz(CONTACT_SIZE, CONTACT_SIZE, CONTACT_SIZE)) + _len(3, _color(CONTACT))
    spheres = [_len(9, _len(1, _len(1, _xyz(float(p[0]), float(p[1]))) + _len(2, _double(4, 1.0))) + size)
               for p in points]
    return _len(1, stamp) + frame + _string(3, entity_id) + b"".join(spheres)


def lines_entity(stamp: bytes, frame: bytes, entity_id: str, segments: Sequence[Sequence[float]]) -> bytes:
    """A SceneEntity (body bytes) of one LINE_LIST of ``segments`` [x0, y0, x1, y1]: the springs."""
    body = _len(1, stamp) + frame + _string(3, entity_id)
    if not segments:
        return body
    pts = b"".join(_len(5, _xyz(float(s[0]), float(s[1]))) + _len(5, _xyz(float(s[2]), float(s[3])))
                   for s in segments)
    identity = _len(2, _len(1, b"") + _len(2, _double(4, 1.0)))
    line = _uint(1, LINE_LIST) + identity + _double(3, 2.0) + _uint(4, 1) + pts + _len(6, _color(SPRING))
    return body + _len(11, line)


def frame_transforms(stamp: bytes, parent: bytes, children: Sequence[bytes],
                     poses: Sequence[Sequence[float]]) -> bytes:
    """foxglove.FrameTransforms: parent -> each child frame at its pose (x, y, yaw).
    parent: _string(2, world frame); children: _string(3, body frame) each."""
    head = _len(1, stamp) + parent
    out: list[bytes] = []
    for child, p in zip(children, poses):
        qz, qw = math.sin(0.5 * p[2]), math.cos(0.5 * p[2])
        if p[0] != 0.0 and p[1] != 0.0 and qz != 0.0 and qw != 0.0:
            tr = _TRANSFORM.pack(0x22, 18, 0x09, p[0], 0x11, p[1], 0x2A, 18, 0x19, qz, 0x21, qw)
        else:
            tr = _len(4, _xyz(p[0], p[1])) + _len(5, _double(3, qz) + _double(4, qw))
        body = head + child + tr
        out += (b"\n", _varint(len(body)), body)
    return b"".join(out)


def string_field(num: int, s: str) -> bytes:
    """A string field as these messages write it (frame names, child frames)."""
    return _string(num, s)
