"""Pre-serialized CDR (XCDR1, little endian) for the node's bulk messages, written with numpy.

rclpy's ``Publisher.publish(bytes)`` sends bytes as an already serialized message, so the node
never builds one Python object per body: a *template* holds every byte that only changes when the
body set changes (names, frame ids, lengths, padding), and each publish writes the stamps and the
pose/twist doubles into it with one numpy fancy assignment.

CDR rules used (the ones rmw_fastrtps applies to ROS 2 messages): a 4-byte encapsulation header
``00 01 00 00`` (CDR, little endian); every primitive aligned to its own size, measured from the
first byte after that header; strings as ``uint32`` length including the NUL, the bytes, the NUL;
sequences as ``uint32`` count then the elements. ``tests/python/test_node_cdr.py`` checks every
writer byte for byte against ``rclpy.serialization.serialize_message`` of the same message object.
"""
from __future__ import annotations

import struct
from collections.abc import Sequence
from typing import Any

import numpy as np

ENCAPSULATION = b"\x00\x01\x00\x00"
_HDR = len(ENCAPSULATION)


class CdrWriter:
    """Appends CDR primitives to a bytearray and tells where each one went (absolute offsets)."""

    __slots__ = ("buf",)

    def __init__(self, start: int = 0) -> None:
        # ``start`` = data offset (after the encapsulation header) at which this fragment will sit,
        # so that a fragment written on its own aligns as it will in the final message.
        self.buf = bytearray(ENCAPSULATION) if start == 0 else bytearray(_HDR + start)

    def pos(self) -> int:
        return len(self.buf)

    def align(self, n: int) -> None:
        pad = (-(len(self.buf) - _HDR)) % n
        if pad:
            self.buf += b"\x00" * pad

    def u8(self, v: int) -> None:
        self.buf.append(v & 0xFF)

    def boolean(self, v: bool) -> None:
        self.buf.append(1 if v else 0)

    def i32(self, v: int) -> int:
        self.align(4)
        p = len(self.buf)
        self.buf += struct.pack("<i", v)
        return p

    def u32(self, v: int) -> int:
        self.align(4)
        p = len(self.buf)
        self.buf += struct.pack("<I", v)
        return p

    def f32s(self, vals: Sequence[float]) -> int:
        self.align(4)
        p = len(self.buf)
        self.buf += struct.pack(f"<{len(vals)}f", *vals)
        return p

    def f64s(self, vals: Sequence[float] | np.ndarray) -> int:
        self.align(8)
        p = len(self.buf)
        self.buf += np.asarray(vals, dtype="<f8").tobytes()
        return p

    def string(self, s: str) -> None:
        b = s.encode("utf-8")
        self.u32(len(b) + 1)
        self.buf += b
        self.buf.append(0)

    def stamp(self, sec: int, nanosec: int) -> int:
        """builtin_interfaces/Time; returns the offset of ``sec``."""
        p = self.i32(sec)
        self.u32(nanosec)
        return p

    def header(self, sec: int, nanosec: int, frame_id: str) -> int:
        p = self.stamp(sec, nanosec)
        self.string(frame_id)
        return p

    def u8_seq(self, data: bytes) -> None:
        self.u32(len(data))
        self.buf += data


def split_time(t: float) -> tuple[int, int]:
    """Seconds (float, >= 0) -> (sec, nanosec) as builtin_interfaces/Time."""
    ns = int(round(t * 1e9))
    if ns < 0:
        ns = 0
    return ns // 1_000_000_000, ns % 1_000_000_000


def join_time(t: Any) -> float:
    """builtin_interfaces/Time (anything with .sec and .nanosec) -> seconds (float); split_time's inverse."""
    return t.sec + 1e-9 * t.nanosec


def poses_from_state(state: np.ndarray) -> np.ndarray:
    """(n, >=3) rows x, y, angle -> (n, 7) geometry_msgs/Pose doubles (z = 0, quaternion from yaw)."""
    n = state.shape[0]
    out = np.zeros((n, 7))
    out[:, 0] = state[:, 0]
    out[:, 1] = state[:, 1]
    half = 0.5 * state[:, 2]
    out[:, 5] = np.sin(half)
    out[:, 6] = np.cos(half)
    return out


def twists_from_state(state: np.ndarray) -> np.ndarray:
    """(n, 6) state rows -> (n, 6) geometry_msgs/Twist doubles (vx, vy, 0, 0, 0, omega)."""
    n = state.shape[0]
    out = np.zeros((n, 6))
    out[:, 0] = state[:, 3]
    out[:, 1] = state[:, 4]
    out[:, 5] = state[:, 5]
    return out


class _Template:
    """A finished message with the positions of its stamps and of its double blocks."""

    def __init__(self, w: CdrWriter, stamp_offsets: list[int], double_offsets: dict[str, np.ndarray]) -> None:
        size = len(w.buf)
        # The raw buffer starts 4 bytes early so that data offset 0 (after the header) is 8-aligned.
        self._raw = np.zeros(size + 4 + 8, dtype=np.uint8)
        self.buf = self._raw[4:4 + size]
        self.buf[:] = np.frombuffer(bytes(w.buf), dtype=np.uint8)
        body_len = (size - _HDR) // 8 * 8
        self._f64 = self._raw[8:8 + body_len].view("<f8")
        u32_len = (size - _HDR) // 4 * 4
        self._u32 = self._raw[8:8 + u32_len].view("<u4")
        st = np.asarray(stamp_offsets, dtype=np.int64) - _HDR
        self._sec_idx = st // 4
        self._dbl = {k: (np.asarray(v, dtype=np.int64) - _HDR) // 8 for k, v in double_offsets.items()}
        self._idx_cache: dict[tuple[str, int], np.ndarray] = {}

    def set_stamp(self, sec: int, nanosec: int) -> None:
        # sec is int32, but as it is never negative here the same bits fit a uint32 view.
        self._u32[self._sec_idx] = np.uint32(sec)
        self._u32[self._sec_idx + 1] = np.uint32(nanosec)

    def set_doubles(self, key: str, values: np.ndarray) -> None:
        """values (n, k): row i goes to the i-th block registered under ``key``."""
        starts = self._dbl[key]
        k = values.shape[1]
        idx = self._idx_cache.get((key, k))
        if idx is None:
            idx = (starts[:, None] + np.arange(k)).ravel()
            self._idx_cache[(key, k)] = idx
        self._f64[idx] = values.ravel()

    def set_block(self, key: str, values: np.ndarray) -> None:
        """values written contiguously starting at the single offset registered under ``key``."""
        start = int(self._dbl[key][0])
        flat = values.ravel()
        self._f64[start:start + flat.size] = flat

    def tobytes(self) -> bytes:
        return self.buf.tobytes()


class PoseArrayCdr:
    """geometry_msgs/PoseArray for n poses under one frame id."""

    def __init__(self, n: int, frame_id: str) -> None:
        w = CdrWriter()
        s = w.header(0, 0, frame_id)
        w.u32(n)
        p = w.f64s(np.zeros(7 * n)) if n else w.pos()
        self.n = n
        self._t = _Template(w, [s], {"poses": np.array([p])})

    def encode(self, sec: int, nanosec: int, poses: np.ndarray) -> bytes:
        self._t.set_stamp(sec, nanosec)
        if self.n:
            self._t.set_block("poses", poses)
        return self._t.tobytes()


class BodyStatesCdr:
    """libcollide_msgs/BodyStates (header, names[], poses[], twists[])."""

    def __init__(self, names: Sequence[str], frame_id: str) -> None:
        n = len(names)
        w = CdrWriter()
        s = w.header(0, 0, frame_id)
        w.u32(n)
        for name in names:
            w.string(name)
        w.u32(n)
        p = w.f64s(np.zeros(7 * n)) if n else w.pos()
        w.u32(n)
        t = w.f64s(np.zeros(6 * n)) if n else w.pos()
        self.n = n
        self._t = _Template(w, [s], {"poses": np.array([p]), "twists": np.array([t])})

    def encode(self, sec: int, nanosec: int, poses: np.ndarray, twists: np.ndarray) -> bytes:
        self._t.set_stamp(sec, nanosec)
        if self.n:
            self._t.set_block("poses", poses)
            self._t.set_block("twists", twists)
        return self._t.tobytes()


class TFMessageCdr:
    """tf2_msgs/TFMessage: one TransformStamped parent -> child per row."""

    def __init__(self, parent: str, children: Sequence[str]) -> None:
        w = CdrWriter()
        w.u32(len(children))
        stamps: list[int] = []
        blocks: list[int] = []
        for child in children:
            stamps.append(w.header(0, 0, parent))
            w.string(child)
            blocks.append(w.f64s(np.zeros(7)))
        self.n = len(children)
        self._t = _Template(w, stamps, {"tf": np.array(blocks, dtype=np.int64)})

    def encode(self, sec: int, nanosec: int, transforms: np.ndarray) -> bytes:
        """transforms (n, 7): translation x, y, z, rotation x, y, z, w."""
        if self.n:
            self._t.set_stamp(sec, nanosec)
            self._t.set_doubles("tf", transforms)
        return self._t.tobytes()


def clock_cdr(sec: int, nanosec: int) -> bytes:
    """rosgraph_msgs/Clock."""
    return ENCAPSULATION + struct.pack("<iI", sec, nanosec)
