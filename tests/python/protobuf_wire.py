"""A minimal protobuf decoder for the tests: the wire format, and messages named by the schema a Foxglove
server advertises (a serialized google.protobuf.FileDescriptorSet), with no protobuf package.

Only what the Foxglove schemas use: varints (int, bool, enum), fixed64 (double), fixed32 (float,
fixed32) and length-delimited fields (string, bytes, messages, packed repeated scalars). A message
decodes to a dict of field name -> value; repeated fields are lists; absent fields are absent
(proto3 leaves default values out).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field
from typing import Any

# google/protobuf/descriptor.proto field numbers (stable since proto2)
_FDS_FILE = 1                                            # FileDescriptorSet.file
_FILE_PACKAGE, _FILE_MESSAGE = 2, 4                      # FileDescriptorProto
_MSG_NAME, _MSG_FIELD, _MSG_NESTED, _MSG_ENUM = 1, 2, 3, 4   # DescriptorProto
_F_NAME, _F_NUMBER, _F_LABEL, _F_TYPE, _F_TYPE_NAME = 1, 3, 4, 5, 6  # FieldDescriptorProto
LABEL_REPEATED = 3
# FieldDescriptorProto.Type
T_DOUBLE, T_FLOAT, T_INT64, T_UINT64, T_INT32, T_FIXED64, T_FIXED32, T_BOOL = 1, 2, 3, 4, 5, 6, 7, 8
T_STRING, T_MESSAGE, T_BYTES, T_UINT32, T_ENUM = 9, 11, 12, 13, 14


def varint(buf: bytes, i: int) -> tuple[int, int]:
    """(value, next index) of the varint at buf[i]."""
    shift = value = 0
    while True:
        b = buf[i]
        i += 1
        value |= (b & 0x7F) << shift
        if b < 0x80:
            return value, i
        shift += 7
        if shift > 63:
            raise ValueError("varint longer than 10 bytes")


def fields(buf: bytes) -> list[tuple[int, int, Any]]:
    """(field number, wire type, raw value) of every field of one message, in order: an int for
    varints, 8 or 4 bytes for fixed64/fixed32, bytes for length-delimited."""
    out: list[tuple[int, int, Any]] = []
    i = 0
    while i < len(buf):
        key, i = varint(buf, i)
        num, wt = key >> 3, key & 7
        if wt == 0:
            v, i = varint(buf, i)
        elif wt == 1:
            v, i = buf[i:i + 8], i + 8
        elif wt == 5:
            v, i = buf[i:i + 4], i + 4
        elif wt == 2:
            n, i = varint(buf, i)
            v, i = buf[i:i + n], i + n
        else:
            raise ValueError(f"wire type {wt} (groups) not supported")
        if i > len(buf):
            raise ValueError("truncated message")
        out.append((num, wt, v))
    return out


@dataclass
class Field:
    name: str
    number: int
    type: int
    repeated: bool
    type_name: str  # ".pkg.Message" for messages and enums


@dataclass
class Schema:
    """Messages by full name (without the leading dot): field number -> Field."""
    messages: dict[str, dict[int, Field]] = field(default_factory=dict)

    @classmethod
    def parse(cls, fds: bytes) -> "Schema":
        s = cls()
        for num, _, fbytes in fields(fds):
            if num != _FDS_FILE:
                continue
            fd = fields(fbytes)
            package = next((v.decode() for n, _, v in fd if n == _FILE_PACKAGE), "")
            for n, _, mbytes in fd:
                if n == _FILE_MESSAGE:
                    s._message(package, mbytes)
        return s

    def _message(self, scope: str, mbytes: bytes) -> None:
        parts = fields(mbytes)
        name = next(v.decode() for n, _, v in parts if n == _MSG_NAME)
        full = f"{scope}.{name}" if scope else name
        table: dict[int, Field] = {}
        for n, _, v in parts:
            if n == _MSG_FIELD:
                f = {k: val for k, _, val in fields(v)}
                table[f[_F_NUMBER]] = Field(f[_F_NAME].decode(), f[_F_NUMBER], f[_F_TYPE],
                                            f.get(_F_LABEL) == LABEL_REPEATED,
                                            f.get(_F_TYPE_NAME, b"").decode())
            elif n == _MSG_NESTED:
                self._message(full, v)
        self.messages[full] = table

    def decode(self, name: str, buf: bytes) -> dict[str, Any]:
        """The message ``name`` (e.g. "foxglove.SceneUpdate") in buf, as a dict."""
        table = self.messages[name.lstrip(".")]
        out: dict[str, Any] = {}
        for num, wt, raw in fields(buf):
            f = table.get(num)
            if f is None:
                continue  # unknown field: skipped, as protobuf does
            if f.repeated and wt == 2 and f.type not in (T_STRING, T_BYTES, T_MESSAGE):
                vals = _packed(f.type, raw)
            else:
                vals = [self._scalar(f, wt, raw)]
            if f.repeated:
                out.setdefault(f.name, []).extend(vals)
            else:
                out[f.name] = vals[-1]
        return out

    def _scalar(self, f: Field, wt: int, raw: Any) -> Any:
        t = f.type
        if t == T_DOUBLE:
            return struct.unpack("<d", raw)[0]
        if t == T_FLOAT:
            return struct.unpack("<f", raw)[0]
        if t == T_FIXED64:
            return struct.unpack("<Q", raw)[0]
        if t == T_FIXED32:
            return struct.unpack("<I", raw)[0]
        if t == T_BOOL:
            return bool(raw)
        if t in (T_INT64, T_INT32):
            return raw - (1 << 64) if raw >= 1 << 63 else raw
        if t in (T_UINT64, T_UINT32, T_ENUM):
            return raw
        if t == T_STRING:
            return raw.decode()
        if t == T_BYTES:
            return bytes(raw)
        if t == T_MESSAGE:
            return self.decode(f.type_name, raw)
        raise ValueError(f"field {f.name}: type {t} not supported (wire type {wt})")


def _packed(t: int, raw: bytes) -> list[Any]:
    if t == T_DOUBLE:
        return list(struct.unpack(f"<{len(raw) // 8}d", raw))
    if t == T_FLOAT:
        return list(struct.unpack(f"<{len(raw) // 4}f", raw))
    if t == T_FIXED32:
        return list(struct.unpack(f"<{len(raw) // 4}I", raw))
    if t == T_FIXED64:
        return list(struct.unpack(f"<{len(raw) // 8}Q", raw))
    out, i = [], 0
    while i < len(raw):
        v, i = varint(raw, i)
        out.append(bool(v) if t == T_BOOL else v)
    return out
