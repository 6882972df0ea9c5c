"""The node's bulk topics read from their CDR bytes (the view subscribes with ``raw=True``).

rclpy turns a message into one Python object per pose, twist, marker and point: for a 1 000-body
sim that is ~0.1 s per ``bodies/states`` and ~0.5 s per ``markers`` message, while the node sends
100 and 20 of them a second. Read here instead: the poses and twists as one numpy view each, the
names and the body outlines only when their bytes change, the contacts' points only.

CDR as cdr.py writes it and rmw_fastrtps sends it: a 4-byte encapsulation header (``00 01``: CDR,
little endian), primitives aligned to their size from the first byte after it, strings as ``uint32``
length (with the NUL) + bytes + NUL, sequences as ``uint32`` count + elements. A message that does not
parse raises ``ValueError`` with the reason.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field

import numpy as np

_HDR = 4
_U32 = struct.Struct("<I")
_I32x3 = struct.Struct("<3i")
_POSE = struct.Struct("<10d")   # pose (7) and scale (3) of a Marker
_RGBA = struct.Struct("<4f")

DELETEALL = 3
ADD = 0


class Reader:
    """A cursor over one message; ``pos`` counts from the first byte after the encapsulation header."""

    __slots__ = ("buf", "pos", "end")

    def __init__(self, buf: bytes, pos: int = 0) -> None:
        if len(buf) < _HDR or buf[0] != 0 or buf[1] != 1:
            raise ValueError("not a little-endian CDR message (encapsulation 00 01)")
        self.buf = buf
        self.pos = pos
        self.end = len(buf) - _HDR

    def _need(self, n: int) -> int:
        p = self.pos
        if n < 0 or p + n > self.end:
            raise ValueError(f"message ends at byte {self.end}, {n} more needed at {p}")
        self.pos = p + n
        return _HDR + p

    def align(self, n: int) -> None:
        self.pos += (-self.pos) % n

    def u32(self) -> int:
        self.align(4)
        return int(_U32.unpack_from(self.buf, self._need(4))[0])

    def i32x3(self) -> tuple[int, int, int]:
        self.align(4)
        a, b, c = _I32x3.unpack_from(self.buf, self._need(12))
        return a, b, c

    def f64s(self, k: int) -> np.ndarray:
        if k == 0:
            return np.zeros(0)  # an empty sequence has no padding before its (absent) elements
        self.align(8)
        return np.frombuffer(self.buf, dtype="<f8", count=k, offset=self._need(8 * k))

    def f32s(self, k: int) -> np.ndarray:
        if k == 0:
            return np.zeros(0, dtype=np.float32)
        self.align(4)
        return np.frombuffer(self.buf, dtype="<f4", count=k, offset=self._need(4 * k))

    def skip(self, n: int) -> None:
        self._need(n)

    def string(self) -> str:
        n = self.u32()
        at = self._need(n)
        return self.buf[at:at + max(0, n - 1)].decode("utf-8", errors="replace")

    def skip_string(self) -> None:
        self._need(self.u32())

    def stamp(self) -> float:
        self.align(4)
        sec, nsec = struct.unpack_from("<iI", self.buf, self._need(8))
        return sec + 1e-9 * nsec

    def count(self, element_size: int) -> int:
        """A sequence's length, checked against the bytes left (``element_size``: at least that many each)."""
        n = self.u32()
        if n * element_size > self.end - self.pos:
            raise ValueError(f"sequence of {n} elements longer than the message")
        return n


def yaw_from_quaternions(q: np.ndarray) -> np.ndarray:
    """(n, 4) x, y, z, w -> (n,) yaw."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _poses_xy_yaw(p7: np.ndarray) -> np.ndarray:
    """(n, 7) geometry_msgs/Pose doubles -> (n, 3) x, y, yaw."""
    out = np.empty((len(p7), 3))
    out[:, :2] = p7[:, :2]
    out[:, 2] = yaw_from_quaternions(p7[:, 3:7])
    return out


@dataclass
class States:
    stamp: float
    names: tuple[str, ...]
    poses: np.ndarray    # (n, 3) x, y, yaw
    twists: np.ndarray   # (n, 3) vx, vy, omega


class StatesReader:
    """libcollide_msgs/BodyStates; the names are parsed again only when their bytes change."""

    def __init__(self) -> None:
        self._names_at = -1
        self._names_bytes = b""
        self._names: tuple[str, ...] = ()

    def read(self, buf: bytes) -> States:
        r = Reader(buf)
        stamp = r.stamp()
        r.skip_string()  # frame_id
        r.align(4)
        start = r.pos
        cached = self._names_bytes
        if start == self._names_at and cached and buf[_HDR + start:_HDR + start + len(cached)] == cached:
            # the same bytes parse to the same names and end at the same place
            names = self._names
            r.pos = start + len(cached)
        else:
            n = r.count(5)
            names = tuple(r.string() for _ in range(n))
            self._names_at, self._names = start, names
            self._names_bytes = bytes(buf[_HDR + start:_HDR + r.pos])
        n = len(names)
        if r.count(56) != n:
            raise ValueError("BodyStates: poses and names differ in length")
        poses = r.f64s(7 * n).reshape(n, 7)
        if r.count(48) != n:
            raise ValueError("BodyStates: twists and names differ in length")
        tw = r.f64s(6 * n).reshape(n, 6)
        return States(stamp, names, _poses_xy_yaw(poses), tw[:, [0, 1, 5]].copy())


def contact_points(buf: bytes, limit: int) -> tuple[float, np.ndarray]:
    """libcollide_msgs/Contacts -> (stamp, (m, 2) points of the first ``limit`` contacts)."""
    r = Reader(buf)
    stamp = r.stamp()
    r.skip_string()
    n = r.count(5 + 5 + 88 + 1)  # two strings of at least a length and a NUL, 11 doubles, kind
    m = min(n, limit)
    out = np.empty((m, 2))
    for i in range(m):
        r.skip_string()   # body_a
        r.skip_string()   # body_b
        d = r.f64s(11)    # point xyz, normal xyz, gap, normal_velocity, impulse, tangent_impulse, force
        out[i, 0], out[i, 1] = d[0], d[1]
        r.skip(1)         # kind
    return stamp, out


def _hex(rgb: tuple[float, ...]) -> str:
    c = [max(0, min(255, int(round(255 * float(v))))) for v in rgb[:3]]
    return f"#{c[0]:02x}{c[1]:02x}{c[2]:02x}"


@dataclass
class Markers:
    """The view's part of one visualization_msgs/MarkerArray, in message order.

    Bodies (ns ``bodies``, ADD) after the last DELETEALL: ids, outlines (body frame, the closed loop's
    repeated point dropped), colours and poses; ``layout`` is the same object as the previous message's
    when the ids, outlines and colours are byte for byte the same (only stamps and poses moved)."""
    delete_alls: int = 0
    stamp: float | None = None                 # of the first bodies marker
    ids: list[int] = field(default_factory=list)
    verts: list[list[list[float]]] = field(default_factory=list)
    colors: list[str] = field(default_factory=list)
    poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    deleted: list[int] = field(default_factory=list)   # bodies markers with another action
    springs: list[list[float]] = field(default_factory=list)  # [x0, y0, x1, y1]
    layout: object = None


class _Layout:
    """Where the bodies' stamps and poses lie in a message, and its other bytes up to the last body."""

    def __init__(self, buf: bytes, end: int, markers: int, moving: list[tuple[int, int]], pose_at: list[int],
                 lead_delete_alls: int, ids: list[int], verts: list[list[list[float]]], colors: list[str],
                 deleted: list[int], springs: list[list[float]], stamp_at: int | None) -> None:
        raw = np.frombuffer(buf, dtype=np.uint8, count=_HDR + end)
        keep = np.ones(_HDR + end, dtype=bool)
        keep[_HDR:_HDR + 4] = False  # the marker count: the springs and contacts after the bodies vary
        for a, n in moving:
            keep[_HDR + a:_HDR + a + n] = False
        self.keep = keep
        self.fixed = raw[keep].copy()
        self.end, self.markers = end, markers
        self.pose_idx = ((np.asarray(pose_at, dtype=np.int64) // 8)[:, None] + np.arange(7)).ravel() if pose_at else None
        self.lead_delete_alls, self.ids, self.verts, self.colors, self.deleted = (
            lead_delete_alls, ids, verts, colors, deleted)
        self.springs = springs  # the springs among the bodies (the node puts them after)
        self.stamp_at = stamp_at

    def matches(self, buf: bytes) -> bool:
        if len(buf) < _HDR + self.end:
            return False
        raw = np.frombuffer(buf, dtype=np.uint8, count=_HDR + self.end)
        return bool(np.array_equal(raw[self.keep], self.fixed))


class MarkersReader:
    """visualization_msgs/MarkerArray (ROS 2 Jazzy's Marker). A message whose bytes up to its last
    body marker equal the previous one's but for stamps and poses (the node's template) costs a byte
    compare and one numpy gather; any other is walked marker by marker."""

    def __init__(self) -> None:
        self._layout: _Layout | None = None

    def read(self, buf: bytes) -> Markers:
        lay = self._layout
        if lay is not None and lay.matches(buf):
            r = Reader(buf)
            total = r.count(4)
            if total >= lay.markers:
                out = Markers(delete_alls=lay.lead_delete_alls, ids=lay.ids, verts=lay.verts, colors=lay.colors,
                              deleted=lay.deleted, layout=lay)
                if lay.pose_idx is not None:
                    # element i of this view is the double at data offset 8 i (poses are 8-aligned)
                    f64 = np.frombuffer(buf, dtype="<f8", count=lay.end // 8, offset=_HDR)
                    out.poses = _poses_xy_yaw(f64[lay.pose_idx].reshape(-1, 7))
                out.springs = list(lay.springs)
                if lay.stamp_at is not None:
                    out.stamp = Reader(buf, lay.stamp_at).stamp()
                r.pos = lay.end
                try:
                    self._extras(r, total - lay.markers, out)
                    return out
                except ValueError:
                    pass  # not the node's layout after all: walked in full
        return self._walk(buf)

    def _walk(self, buf: bytes) -> Markers:
        r = Reader(buf)
        total = r.count(4)
        out = Markers()
        moving: list[tuple[int, int]] = []
        pose_at: list[int] = []
        poses: list[tuple[float, ...]] = []
        last_body, last_body_end, prefix_springs, stamp_at = -1, 0, 0, None
        for k in range(total):
            ns, mid, action, s_at, p_at, pose, rgba, pts = self._marker(r)
            moving.append((s_at, 8))  # every stamp may change (the node stamps them all)
            if action == DELETEALL:
                out.delete_alls += 1
                out.ids, out.verts, out.colors, out.deleted, out.springs = [], [], [], [], []
                poses, pose_at, stamp_at = [], [], None
                continue
            if ns == "bodies":
                if action != ADD:
                    out.deleted.append(mid)
                else:
                    moving.append((p_at, 56))
                    pose_at.append(p_at)
                    loop = pts[:, :2].tolist()
                    if len(loop) > 1 and loop[0] == loop[-1]:
                        loop = loop[:-1]  # the closed loop's repeated first point
                    out.ids.append(mid)
                    out.verts.append(loop)
                    out.colors.append(_hex(rgba))
                    poses.append(pose)
                    if stamp_at is None:
                        stamp_at = s_at
                last_body, last_body_end, prefix_springs = k, r.pos, len(out.springs)
            elif ns == "springs" and action == ADD and len(pts) >= 2:
                out.springs.append([float(pts[0, 0]), float(pts[0, 1]), float(pts[1, 0]), float(pts[1, 1])])
        out.poses = _poses_xy_yaw(np.array(poses, dtype=np.float64).reshape(-1, 7))
        if stamp_at is not None:
            out.stamp = Reader(buf, stamp_at).stamp()
        if last_body >= 0:
            out.layout = self._layout = _Layout(buf, last_body_end, last_body + 1, moving, pose_at,
                                                out.delete_alls, out.ids, out.verts, out.colors, out.deleted,
                                                out.springs[:prefix_springs], stamp_at)
        else:
            self._layout = None
        return out

    def _extras(self, r: Reader, n: int, out: Markers) -> None:
        """The markers after the bodies (springs, contacts) of a message that matched the layout."""
        for _ in range(n):
            ns, _mid, action, _s, _p, _pose, _rgba, pts = self._marker(r)
            if action == DELETEALL or ns == "bodies":
                raise ValueError("markers: bodies or DELETEALL after the bodies")  # walked in full instead
            if ns == "springs" and action == ADD and len(pts) >= 2:
                out.springs.append([float(pts[0, 0]), float(pts[0, 1]), float(pts[1, 0]), float(pts[1, 1])])

    @staticmethod
    def _marker(r: Reader) -> tuple[str, int, int, int, int, tuple[float, ...], tuple[float, ...], np.ndarray]:
        """One Marker: (ns, id, action, stamp offset, pose offset, pose (7), rgba (4), points (k, 3)).
        Straight-line struct reads: this runs once per body when the bodies change."""
        buf, end = r.buf, r.end
        u32 = _U32.unpack_from

        def string_end(p: int) -> int:  # p: 4-aligned data offset of a string's length
            return p + 4 + u32(buf, _HDR + p)[0]

        def seq_end(p: int, size: int) -> int:
            return p + 4 + size * u32(buf, _HDR + p)[0]

        def a4(p: int) -> int:
            return p + (-p) % 4

        def a8(p: int) -> int:
            return p + (-p) % 8
        try:
            p = s_at = a4(r.pos)
            p = a4(string_end(p + 8))                 # stamp, frame_id
            ns_len = u32(buf, _HDR + p)[0]
            ns = buf[_HDR + p + 4:_HDR + p + 3 + ns_len].decode("utf-8", errors="replace")
            p = a4(p + 4 + ns_len)
            mid, _type, action = _I32x3.unpack_from(buf, _HDR + p)
            p_at = a8(p + 12)
            pose = _POSE.unpack_from(buf, _HDR + p_at)  # pose (7), scale (3)
            rgba = _RGBA.unpack_from(buf, _HDR + p_at + 80)
            p = a4(p_at + 80 + 16 + 8 + 1)            # color, lifetime, frame_locked
            k = u32(buf, _HDR + p)[0]
            if 24 * k > end - p:
                raise ValueError(f"marker of {k} points longer than the message")
            p += 4
            if k:  # padding to the doubles only when there are some
                p = a8(p)
            pts = np.frombuffer(buf, dtype="<f8", count=3 * k, offset=_HDR + p).reshape(k, 3)
            p = a4(p + 24 * k)
            p = a4(seq_end(p, 16))                    # colors
            p = a4(string_end(p))                     # texture_resource
            p = a4(string_end(p + 8))                 # texture.header
            p = a4(string_end(p))                     # texture.format
            p = a4(seq_end(p, 1))                     # texture.data
            p = a4(seq_end(p, 8))                     # uv_coordinates
            p = a4(string_end(p))                     # text
            p = a4(string_end(p))                     # mesh_resource
            p = a4(string_end(p))                     # mesh_file.filename
            p = seq_end(p, 1) + 1                     # mesh_file.data, mesh_use_embedded_materials
        except struct.error as exc:
            raise ValueError(f"marker at byte {r.pos}: {exc}") from None
        if p > end:
            raise ValueError(f"message ends at byte {end}, a marker needs {p}")
        r.pos = p
        return ns, mid, action, s_at, p_at, pose[:7], rgba, pts
