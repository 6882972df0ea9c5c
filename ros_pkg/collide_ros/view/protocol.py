"""The view's WebSocket protocol: what the page may send, checked before anything reaches ROS.

Every message from the page is one JSON object with a ``type``. ``parse`` turns the text into a
``Command`` or raises ``Refused`` with the reason the page shows; nothing a page sends can stop the
view. ``RateLimit`` refuses floods. The server's messages to the page are documented in
docs/live_view.md.

    {"type": "spring", "body": "block1", "point": [bx, by], "target": [x, y]}   # body frame / world
    {"type": "release"}                                                         # drop the spring
    {"type": "keys", "held": ["s", "e"]}                 # the thruster keys held now (teleop.KEYMAP)
    {"type": "param", "name": "gravity", "value": 9.81}  # set one of PARAMS on the node
    {"type": "pause", "paused": true} | {"type": "step", "steps": 10} | {"type": "reset"}
    {"type": "ack", "frame": 17}                         # the page has handled state frame 17

A request may carry ``"id"`` (an integer), echoed in the reply or the refusal.
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from typing import Any

from collide_ros.teleop import KEYMAP

MAX_TEXT = 4096           # characters per message
MAX_COORD = 1e6           # m: |coordinate| of a spring point or target
MAX_PARAM = 1e9           # |value| of a parameter (the node checks its own range after this)
MAX_STEPS = 100_000       # per step request
MAX_KEYS = len(KEYMAP)

#: parameters the page may set, with their ROS type (the node checks ranges and refuses with a reason)
PARAMS: dict[str, type] = {
    "gravity": float, "elasticity": float, "damping": float, "green_mass": float,
    "real_time_factor": float, "time_step": float, "blocks": int,
}


class Refused(ValueError):
    """A message from the page that is not taken; ``str()`` is the reason shown to the page."""

    def __init__(self, reason: str, req_id: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.req_id = req_id


@dataclass(frozen=True)
class Command:
    type: str
    id: int | None = None
    args: dict[str, Any] = field(default_factory=dict)


def _reject_constant(name: str) -> float:
    raise Refused(f"{name} is not a number JSON allows")


def _number(value: Any, what: str, limit: float, req_id: int | None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise Refused(f"{what} must be a number, got {type(value).__name__}", req_id)
    v = float(value)  # an int too large for a float raises OverflowError
    if not math.isfinite(v):
        raise Refused(f"{what} must be finite, got {value}", req_id)
    if abs(v) > limit:
        raise Refused(f"{what} = {value:g} is out of range (|{what}| <= {limit:g})", req_id)
    return v


def _point(value: Any, what: str, req_id: int | None) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2:
        raise Refused(f"{what} must be a list [x, y]", req_id)
    return (_number(value[0], f"{what}[0]", MAX_COORD, req_id),
            _number(value[1], f"{what}[1]", MAX_COORD, req_id))


def parse(text: str | bytes, bodies: set[str] | frozenset[str]) -> Command:
    """Check one message from the page. ``bodies``: the dynamic bodies a spring may grab."""
    if isinstance(text, bytes):
        raise Refused("binary messages are not accepted; send JSON text")
    if len(text) > MAX_TEXT:
        raise Refused(f"message of {len(text)} characters; at most {MAX_TEXT}")
    try:
        msg = json.loads(text, parse_constant=_reject_constant)
    except Refused:
        raise
    except (ValueError, RecursionError) as exc:
        raise Refused(f"malformed JSON: {exc}") from None
    if not isinstance(msg, dict):
        raise Refused("a message must be a JSON object")
    req_id = msg.get("id")
    if req_id is not None and (isinstance(req_id, bool) or not isinstance(req_id, int) or abs(req_id) > 2**53):
        raise Refused("id must be an integer")
    kind = msg.get("type")
    try:
        if kind == "spring":
            body = msg.get("body")
            if not isinstance(body, str):
                raise Refused("spring: body must be a string", req_id)
            if body not in bodies:
                have = ", ".join(sorted(bodies)) or "none"
                raise Refused(f"spring: unknown body '{body[:64]}' (dynamic bodies: {have})", req_id)
            return Command("spring", req_id, {"body": body, "point": _point(msg.get("point"), "point", req_id),
                                              "target": _point(msg.get("target"), "target", req_id)})
        if kind == "release":
            return Command("release", req_id)
        if kind == "keys":
            held = msg.get("held")
            if not isinstance(held, list) or len(held) > MAX_KEYS:
                raise Refused(f"keys: held must be a list of at most {MAX_KEYS} keys", req_id)
            bad = [k for k in held if not isinstance(k, str) or k not in KEYMAP]
            if bad:
                raise Refused(f"keys: not a thruster key: {str(bad[0])[:32]!r} (keys: {', '.join(KEYMAP)})", req_id)
            return Command("keys", req_id, {"held": frozenset(held)})
        if kind == "param":
            name = msg.get("name")
            if name not in PARAMS:
                raise Refused(f"param: '{str(name)[:64]}' cannot be set from the view "
                              f"(settable: {', '.join(PARAMS)})", req_id)
            value = _number(msg.get("value"), name, MAX_PARAM, req_id)
            if PARAMS[name] is int:
                if value != int(value):
                    raise Refused(f"{name} must be an integer, got {value:g}", req_id)
                return Command("param", req_id, {"name": name, "value": int(value)})
            return Command("param", req_id, {"name": name, "value": value})
        if kind == "pause":
            paused = msg.get("paused")
            if not isinstance(paused, bool):
                raise Refused("pause: paused must be true or false", req_id)
            return Command("pause", req_id, {"paused": paused})
        if kind == "step":
            steps = msg.get("steps", 1)
            if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
                raise Refused(f"step: steps must be an integer in 1..{MAX_STEPS}", req_id)
            return Command("step", req_id, {"steps": steps})
        if kind == "reset":
            return Command("reset", req_id)
        if kind == "ack":
            frame = msg.get("frame")
            if isinstance(frame, bool) or not isinstance(frame, int) or not 0 <= frame <= 2**53:
                raise Refused("ack: frame must be an integer >= 0", req_id)
            return Command("ack", req_id, {"frame": frame})
    except OverflowError:
        raise Refused("number too large", req_id) from None
    raise Refused(f"unknown message type {str(kind)[:32]!r}", req_id)


class RateLimit:
    """Token bucket: ``rate`` messages per second on average, bursts of ``burst``."""

    def __init__(self, rate: float = 200.0, burst: float = 400.0, clock: Any = time.monotonic) -> None:
        self.rate, self.burst, self.clock = rate, burst, clock
        self.tokens = burst
        self.last = clock()
        self.refused = 0

    def take(self) -> bool:
        now = self.clock()
        self.tokens = min(self.burst, self.tokens + (now - self.last) * self.rate)
        self.last = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        self.refused += 1
        return False
