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
from collections.abc import Mapping, Sequence
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


def poses_from_state(state: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """(n, >=3) rows x, y, angle -> (n, 7) geometry_msgs/Pose doubles (z = 0, quaternion from yaw),
    written into ``out`` (n, 7) when given (its columns 2-4 must be zero: they are not written)."""
    n = state.shape[0]
    if out is None:
        out = np.zeros((n, 7))
    out[:, 0] = state[:, 0]
    out[:, 1] = state[:, 1]
    # sin and cos of a contiguous array, copied into the strided columns after: numpy's vectorized
    # loops for contiguous input are the ones every caller gets, so the bits do not depend on ``out``
    half = 0.5 * state[:, 2]
    out[:, 5] = np.sin(half)
    out[:, 6] = np.cos(half)
    return out


def twists_from_state(state: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """(n, 6) state rows -> (n, 6) geometry_msgs/Twist doubles (vx, vy, 0, 0, 0, omega), written into
    ``out`` (n, 6) when given (its columns 2-4 must be zero)."""
    n = state.shape[0]
    if out is None:
        out = np.zeros((n, 6))
    out[:, 0] = state[:, 3]
    out[:, 1] = state[:, 4]
    out[:, 5] = state[:, 5]
    return out


# A scatter through strided views costs one numpy call per run of equally spaced blocks; past this
# many blocks per run on average a fancy index (one call, ~4x slower per element) is the cheaper one.
_MIN_BLOCKS_PER_RUN = 16


def _runs(starts: np.ndarray, limit: int) -> list[tuple[int, int, int]] | None:
    """(first block, blocks, step) of each maximal run of equally spaced ``starts`` (increasing), or
    None when there are more than ``limit`` runs."""
    n = len(starts)
    d = np.diff(starts)
    change = np.flatnonzero(np.diff(d)) + 1  # j: d[j] != d[j - 1]
    out: list[tuple[int, int, int]] = []
    i = 0
    while i < n:
        if len(out) >= limit:
            return None
        if i == n - 1:
            out.append((i, 1, 1))
            break
        k = int(np.searchsorted(change, i, side="right"))
        end = int(change[k]) if k < len(change) else len(d)  # d[i:end] are all equal
        out.append((i, end - i + 1, int(d[i])))
        i = end + 1
    return out


class _Blocks:
    """Blocks of ``k`` consecutive elements of ``flat`` that start at ``starts`` (element indices,
    increasing): ``write(values)`` puts row i of values (n, k), or one row (k,) for all, into block i.

    Templates repeat one layout per body, so the starts fall into a few runs of equal spacing (a run
    per name length); each run is then one strided view of ``flat`` and a write is one copy per run.
    Starts without such runs (names of many lengths in turn) take one fancy index instead."""

    def __init__(self, flat: np.ndarray, starts: np.ndarray, k: int) -> None:
        starts = np.asarray(starts, dtype=np.int64)
        self.n = len(starts)
        self._views: list[tuple[int, int, np.ndarray]] | None = None
        self._flat, self._idx = flat, None
        runs = _runs(starts, max(1, self.n // _MIN_BLOCKS_PER_RUN)) if self.n else []
        if runs is None:
            self._idx = starts[:, None] + np.arange(k)
            return
        size = flat.itemsize
        self._views = [(i, i + count, np.lib.stride_tricks.as_strided(
            flat[int(starts[i]):], shape=(count, k), strides=(step * size, size)))
            for i, count, step in runs]

    def write(self, values: np.ndarray) -> None:
        if self._views is None:
            self._flat[self._idx] = values
            return
        if values.ndim == 1:
            for _, _, view in self._views:
                view[...] = values
            return
        for a, b, view in self._views:
            view[...] = values[a:b]


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
        self._stamps = _Blocks(self._u32, st // 4, 2)
        self._dbl = {k: (np.asarray(v, dtype=np.int64) - _HDR) // 8 for k, v in double_offsets.items()}
        self._blocks: dict[tuple[str, int], _Blocks] = {}

    def set_stamp(self, sec: int, nanosec: int) -> None:
        # sec is int32, but as it is never negative here the same bits fit a uint32 view.
        self._stamps.write(np.array([sec, nanosec], dtype=np.uint32))

    def set_doubles(self, key: str, values: np.ndarray) -> None:
        """values (n, k): row i goes to the i-th block registered under ``key``."""
        k = values.shape[1]
        blocks = self._blocks.get((key, k))
        if blocks is None:
            blocks = self._blocks[(key, k)] = _Blocks(self._f64, self._dbl[key], k)
        blocks.write(values)

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


class EnergyCdr:
    """libcollide_msgs/Energy: header, translational, rotational, gravitational, spring, total,
    linear_momentum (x, y, 0), angular_momentum (all float64)."""

    def __init__(self, frame_id: str) -> None:
        w = CdrWriter()
        s = w.header(0, 0, frame_id)
        p = w.f64s(np.zeros(9))
        self._t = _Template(w, [s], {"energy": np.array([p])})
        self._values = np.zeros(9)

    def encode(self, sec: int, nanosec: int, energy: Any) -> bytes:
        """``energy``: a collide.Energy (or anything with its fields)."""
        v = self._values
        v[0:5] = (energy.translational, energy.rotational, energy.gravitational, energy.spring, energy.total)
        v[5:7] = energy.linear_momentum[0], energy.linear_momentum[1]
        v[8] = energy.angular_momentum
        self._t.set_stamp(sec, nanosec)
        self._t.set_block("energy", v)
        return self._t.tobytes()


# ---------------------------------------------------------------- libcollide_msgs/Contacts
# A Contact element: string body_a, string body_b, then 11 float64 (point x y z, normal x y z, gap,
# normal_velocity, impulse, tangent_impulse, force) and uint8 kind. Its strings make the elements
# differ in size, so there is no fixed template: the offsets come from a cumulative sum instead.
# Each element ends one byte past an 8-aligned offset (the kind after the doubles), so every element
# after the first starts at 4 mod 8 after 3 bytes of padding; only the first one's start depends on
# the header (the frame id's length).
_CONTACT_DOUBLES = 11
_CONTACT_TAIL = 8 * _CONTACT_DOUBLES + 1   # the doubles and the kind byte
_CONTACT_GAP = 3                           # padding from one element's kind to the next element


def _string_block(s: str) -> bytes:
    """A CDR string that starts 4-aligned, padded with zeros to a multiple of 4 bytes."""
    b = s.encode("utf-8")
    raw = struct.pack("<I", len(b) + 1) + b + b"\x00"
    return raw + b"\x00" * ((-len(raw)) % 4)


def _ragged_index(starts: np.ndarray, lens: np.ndarray) -> np.ndarray:
    """Concatenation of arange(starts[j], starts[j] + lens[j]) over j, without a Python loop."""
    total = int(lens.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    first = np.cumsum(lens) - lens  # where segment j begins in the output
    return np.repeat(starts - first, lens) + np.arange(total, dtype=np.int64)


class _NameTable:
    """Body id -> its name as a padded CDR string block, looked up for whole id arrays at once.

    An id the table does not know (a body killed after its impact was kept) is named by its number,
    as str(id)."""

    def __init__(self, names: Mapping[int, str]) -> None:
        self._names = dict(names)
        self._build()

    def _build(self) -> None:
        ids = np.array(sorted(self._names), dtype=np.int64)
        blocks = [_string_block(self._names[int(i)]) for i in ids]
        self.ids = ids
        self.words = np.frombuffer(b"".join(blocks), dtype="<u4") if blocks else np.zeros(0, dtype="<u4")
        lens = np.array([len(b) for b in blocks], dtype=np.int64)
        self.lens = lens  # bytes, multiples of 4
        self.word_starts = (np.cumsum(lens) - lens) // 4

    def rows(self, ids: np.ndarray) -> np.ndarray:
        """Row in the table of each id (unknown ids are added first)."""
        ids = ids.astype(np.int64)
        pos = np.searchsorted(self.ids, ids)
        known = self.ids[np.minimum(pos, len(self.ids) - 1)] == ids if len(self.ids) else np.zeros(len(ids), bool)
        if not known.all():
            for i in np.unique(ids[~known]):
                self._names[int(i)] = str(int(i))
            self._build()
            return self.rows(ids)
        return pos


class ContactsCdr:
    """libcollide_msgs/Contacts from rows of collide.CONTACT_DTYPE (lc_contact), written by numpy.

    The same message as one ``Contact`` per row with body_a/body_b = the bodies' names (their id as
    text if unknown), point/normal (x, y, 0), the five doubles copied bit for bit and kind = the
    row's kind; the ``time`` of lc_contact is not part of the message."""

    def __init__(self, frame_id: str, names: Mapping[int, str]) -> None:
        w = CdrWriter()
        self._sec = w.header(0, 0, frame_id) - _HDR
        self._count = w.u32(0) - _HDR
        self._head = np.frombuffer(bytes(w.buf), dtype=np.uint8)
        self._first = len(w.buf) - _HDR  # data offset of the first element (4-aligned)
        self._names = _NameTable(names)

    def _layout(self, la: np.ndarray, lb: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """Data offsets of each element and of its doubles, and the message's data size."""
        names = la + lb
        pad = (-(4 + names)) % 8           # to 8-align the doubles of an element starting at 4 mod 8
        pad[0] = (-(self._first + names[0])) % 8
        size = names + pad + _CONTACT_TAIL + _CONTACT_GAP
        starts = self._first + np.cumsum(size) - size
        doubles = starts + names + pad
        return starts, doubles, int(doubles[-1]) + _CONTACT_TAIL

    @staticmethod
    def _doubles(c: np.ndarray) -> np.ndarray:
        """(n, 11) float64 of each Contact after its strings."""
        out = np.zeros((len(c), _CONTACT_DOUBLES))
        out[:, 0:2] = c["point"]
        out[:, 3:5] = c["normal"]
        out[:, 6] = c["gap"]
        out[:, 7] = c["normal_velocity"]
        out[:, 8] = c["impulse"]
        out[:, 9] = c["tangent_impulse"]
        out[:, 10] = c["force"]
        return out

    def _write_names(self, u32: np.ndarray, starts: np.ndarray, ra: np.ndarray, rb: np.ndarray) -> None:
        """Each element's two string blocks, which lie back to back from its start (4-byte words)."""
        t = self._names
        src_starts = np.column_stack([t.word_starts[ra], t.word_starts[rb]]).ravel()
        src_lens = np.column_stack([t.lens[ra], t.lens[rb]]).ravel() // 4
        dst = _ragged_index(starts // 4, (t.lens[ra] + t.lens[rb]) // 4)
        u32[dst] = t.words[_ragged_index(src_starts, src_lens)]

    def encode(self, sec: int, nanosec: int, contacts: np.ndarray) -> bytes:
        """The serialized message (encapsulation header included) for ``contacts`` in their order."""
        n = len(contacts)
        size, starts, doubles = self._first, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        if n:
            # one lookup for both columns: a lookup that adds an unknown id renumbers the rows
            ra, rb = np.split(self._names.rows(np.concatenate([contacts["body_a"], contacts["body_b"]])), 2)
            starts, doubles, size = self._layout(self._names.lens[ra], self._names.lens[rb])
        # The raw buffer starts 4 bytes early so that data offset 0 (after the header) is 8-aligned.
        raw = np.zeros(8 + size + 8, dtype=np.uint8)
        buf = raw[4:8 + size]
        buf[:len(self._head)] = self._head
        u32 = raw[8:8 + size // 4 * 4].view("<u4")
        u32[self._sec // 4] = np.uint32(sec)
        u32[self._sec // 4 + 1] = np.uint32(nanosec)
        u32[self._count // 4] = np.uint32(n)
        if n:
            self._write_names(u32, starts, ra, rb)
            f64 = raw[8:8 + size // 8 * 8].view("<f8")
            f64[(doubles // 8)[:, None] + np.arange(_CONTACT_DOUBLES)] = self._doubles(contacts)
            buf[_HDR + doubles + 8 * _CONTACT_DOUBLES] = contacts["kind"].astype(np.uint8)
        return buf.tobytes()
