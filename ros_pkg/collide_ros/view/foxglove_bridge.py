"""The view's scene for Foxglove and Lichtblick: a Foxglove WebSocket server (foxglove-sdk) beside
the page (``python -m collide_ros.view --foxglove``).

Channels, under the view's namespace (``/robot1/scene`` for a view started with ``-r __ns:=/robot1``):

- ``/scene`` (foxglove.SceneUpdate, protobuf): one entity per body, ``body/<name>`` for the dynamic
  bodies and ``static/<id>`` for the walls (``shape/<id>`` for a body the view has not named yet:
  more than UNNAMED_WAIT after its shapes came), each a filled polygon (the node's marker colour, block1
  green) with a dark outline, at its pose in the world frame; ``contacts`` (red spheres at the contact
  points) and ``springs`` (orange lines). Every message carries the whole scene; entities that went
  (a body killed, a reset with fewer bodies) are deleted by id.
- ``/tf`` (foxglove.FrameTransforms, protobuf): world_frame -> ``<frame_prefix><body>`` for every
  dynamic body, as the node's /tf names them (the node's world_frame and frame_prefix parameters).
- ``/energy`` (JSON): sim time ``t``, translational, rotational, potential (gravitational + spring),
  gravitational, spring, total, and ``start`` (the total at the start or the last reset).

Timestamps are sim time. Messages go out at the view's display rate (``--rate``) while a client
subscribes and something changed (at least once a second otherwise), built from the same snapshot as
the page's frames. A client that cannot keep up loses the oldest messages (the SDK's per-client
backlog), never slows the view down.
"""
from __future__ import annotations

import threading
import time
from typing import Any

import foxglove
from foxglove.messages import FrameTransforms, SceneUpdate

from collide_ros.view import foxglove_wire as wire
from collide_ros.view.bridge import ViewBridge

HEARTBEAT = 1.0  # s: a message at least this often, even when nothing changed
UNNAMED_WAIT = 1.0  # s: how long the scene waits for the view to name the bodies of new shapes
ENERGY_KEYS = ("translational", "rotational", "potential", "gravitational", "spring", "total", "start")
ENERGY_SCHEMA: dict[str, Any] = {
    "type": "object", "title": "libcollide energy (J)",
    "properties": {"t": {"type": "number", "description": "sim time (s)"},
                   **{k: {"type": "number"} for k in ENERGY_KEYS},
                   "start": {"type": ["number", "null"], "description": "total at the start or the last reset"}},
}


def topics(namespace: str) -> dict[str, str]:
    """The channel topics of a view in ``namespace`` ('/', '/robot1')."""
    ns = namespace.rstrip("/")
    return {"scene": f"{ns}/scene", "tf": f"{ns}/tf", "energy": f"{ns}/energy"}


class FoxgloveStream:
    """Serves the view's scene over the Foxglove WebSocket protocol on host:port (port 0: a free one)."""

    def __init__(self, bridge: ViewBridge, host: str = "127.0.0.1", port: int = 8765, rate: float = 30.0) -> None:
        self.bridge = bridge
        self.period = 1.0 / rate
        self.topics = topics(bridge.get_namespace())
        self.ctx = foxglove.Context()  # its own: channels reach this server only
        self._scene = foxglove.Channel(self.topics["scene"], schema=SceneUpdate.get_schema(),
                                       message_encoding="protobuf", context=self.ctx)
        self._tf = foxglove.Channel(self.topics["tf"], schema=FrameTransforms.get_schema(),
                                    message_encoding="protobuf", context=self.ctx)
        self._energy = foxglove.Channel(self.topics["energy"], schema=ENERGY_SCHEMA, context=self.ctx)
        # raises (e.g. the port is taken) before anything runs
        self.server = foxglove.start_server(name="libcollide view", host=host, port=port, context=self.ctx)
        self.port = int(self.server.port)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="view-foxglove", daemon=True)
        # the scene's constant parts, rebuilt when the bodies change
        self._version = -1
        self._parts: list[wire.BodyParts] = []
        self._ids: list[str] = []
        self._dynamic: list[int] = []        # indices of the dynamic bodies among the shapes
        self._names: list[str] = []          # ... and their names
        self._children: list[bytes] = []     # ... and their frames, encoded
        self._frames: tuple[str, str] | None = None
        self._named = False                  # the dynamic bodies among the shapes are known
        self._shapes_at = 0.0                # when the shapes last changed (monotonic s)
        self._sent_ids: set[str] = set()     # entity ids of the last scene sent
        self.sent = 0                        # scene messages logged

    def start(self) -> "FoxgloveStream":
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)
        self.server.stop()

    def _run(self) -> None:
        seq, last = -1, 0.0
        while not self._stop.is_set():
            t0 = time.monotonic()
            try:
                if self._scene.has_sinks() or self._tf.has_sinks() or self._energy.has_sinks():
                    new_seq, state = self.bridge.snapshot()
                    if state["t"] is not None and (new_seq != seq or t0 - last >= HEARTBEAT):
                        seq, last = new_seq, t0
                        self.publish(state)
            except Exception as exc:  # a bad frame is logged and skipped; the stream goes on
                self.bridge.get_logger().warning(f"view: Foxglove stream: {type(exc).__name__}: {exc}")
            self._stop.wait(max(0.0, self.period - (time.monotonic() - t0)))

    def _refresh(self, version: int) -> bool:
        """Rebuild the bodies' constant parts when the shapes or the frame names change; False while
        the node's frame names are not known."""
        frames = self.bridge.frame_names()
        if frames is None:
            return False
        if version == self._version and frames == self._frames:
            return True
        shapes = self.bridge.shapes()
        if shapes["version"] != self._version:
            self._shapes_at = time.monotonic()
        self._version, self._frames = shapes["version"], frames
        self._parts, self._ids, self._dynamic, self._names = [], [], [], []
        self._named = all(b["name"] or b["static"] for b in shapes["bodies"])
        for i, b in enumerate(shapes["bodies"]):
            # a shape the view has not named yet (matched with bodies/states) is shape/<marker id>
            eid = (f"body/{b['name']}" if b["name"] else f"static/{b['id']}" if b["static"]
                   else f"shape/{b['id']}")
            self._ids.append(eid)
            self._parts.append(wire.body_parts(eid, b["verts"], wire.hex_rgba(b["color"])))
            if b["name"]:
                self._dynamic.append(i)
                self._names.append(b["name"])
        self._children = [wire.string_field(3, frames[1] + n) for n in self._names]
        return True

    def publish(self, state: dict[str, Any]) -> None:
        """Log one frame of the view's state (a ``snapshot()`` state message) on the channels."""
        if not self._refresh(state["version"]):
            return  # the frames' names first (the node's parameters)
        if len(state["poses"]) != len(self._parts):
            return  # the shapes changed since the snapshot: the next frame has both
        if not self._named and state["dynamic"] and time.monotonic() - self._shapes_at < UNNAMED_WAIT:
            return  # right after the shapes change: names first, so that no entity id flickers
        assert self._frames is not None
        world = self._frames[0]
        stamp = wire.timestamp(state["t"])
        frame = wire.string_field(2, world)
        poses = state["poses"].tolist()
        if self._scene.has_sinks():
            ids = set(self._ids) | {"contacts", "springs"}
            extras = [wire.points_entity(stamp, frame, "contacts", state["contacts"].tolist()),
                      wire.lines_entity(stamp, frame, "springs", state["springs"])]
            gone = sorted(self._sent_ids - ids)
            self._scene.log(wire.scene_update(stamp, frame, self._parts, poses, extras, gone))
            self._sent_ids = ids
            self.sent += 1
        if self._tf.has_sinks() and self._dynamic:
            self._tf.log(wire.frame_transforms(stamp, frame, self._children, [poses[i] for i in self._dynamic]))
        e = state["energy"]
        if self._energy.has_sinks() and e is not None:
            self._energy.log({"t": state["t"], **{k: e.get(k) for k in ENERGY_KEYS}})
