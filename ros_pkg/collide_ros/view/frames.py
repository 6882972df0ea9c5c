"""The state frame the view sends to the page: one binary WebSocket message per frame.

At 1 000 bodies a JSON frame of poses and velocities is ~120 kB of text to format in the view and
to parse on the page, 30 times a second; as doubles it is 48 kB copied out of numpy arrays, read by
the page as Float64Array views without parsing. Layout (little endian)::

    uint32           n: length of the JSON head
    n bytes          the head, UTF-8 JSON: every field of the state but the arrays, and
                     "bodies" (k, the number of shapes) and "points" (m, contact points)
    0-7 zero bytes   to the next multiple of 8 (a Float64Array starts 8-aligned)
    float64 [k][3]   poses x, y, yaw, in the order of the latest shapes message
    float64 [k][3]   velocities vx, vy, omega; NaN for a body without a state (walls, a body not named yet)
    float64 [m][2]   contact points x, y
"""
from __future__ import annotations

import json
import struct
from typing import Any

import numpy as np

ARRAYS = (("poses", 3), ("velocities", 3), ("contacts", 2))


def encode_state(state: dict[str, Any]) -> bytes:
    """``state``: a state message (scene.state_message plus the bridge's fields), its arrays numpy."""
    poses = np.asarray(state["poses"], dtype="<f8").reshape(-1, 3)
    vel = np.asarray(state["velocities"], dtype="<f8").reshape(-1, 3)
    pts = np.asarray(state["contacts"], dtype="<f8").reshape(-1, 2)
    if len(vel) != len(poses):
        raise ValueError("state frame: poses and velocities differ in length")
    head = {k: v for k, v in state.items() if k not in dict(ARRAYS)}
    head["bodies"], head["points"] = len(poses), len(pts)
    text = json.dumps(head, allow_nan=False, default=float, separators=(",", ":")).encode("utf-8")
    pad = (-(4 + len(text))) % 8
    return b"".join((struct.pack("<I", len(text)), text, b"\0" * pad, poses.tobytes(), vel.tobytes(), pts.tobytes()))


def decode_state(data: bytes) -> dict[str, Any]:
    """encode_state's inverse (for tests and benches): the head's fields and the arrays."""
    (n,) = struct.unpack_from("<I", data, 0)
    out: dict[str, Any] = json.loads(data[4:4 + n].decode("utf-8"))
    off = 4 + n + (-(4 + n)) % 8
    for key, width in ARRAYS:
        rows = out["points"] if key == "contacts" else out["bodies"]
        out[key] = np.frombuffer(data, dtype="<f8", count=rows * width, offset=off).reshape(rows, width)
        off += 8 * rows * width
    if off != len(data):
        raise ValueError(f"state frame of {len(data)} bytes; its head says {off}")
    return out
