"""The live view's Foxglove WebSocket server (python -m collide_ros.view --foxglove): a client of the
Foxglove WebSocket protocol (over the pinned ``websockets``) against a running sim node and view,
decoding what it receives with the schemas the server advertises.

foxglove-sdk 0.30.3 accepts the subprotocol ``foxglove.sdk.v1`` only: the protocol of
``foxglove.websocket.v1`` under a new name (serverInfo, advertise, subscribe, binary message data:
opcode 1, subscription id u32, log time u64, payload). The client offers both names, as Foxglove and
Lichtblick do, and the handshake must pick the SDK's.

The protobuf messages are decoded by tests/python/protobuf_wire.py (the wire format, and field names
from the advertised FileDescriptorSet): the venv has no protobuf package. The encoder
(collide_ros/view/foxglove_wire.py) is checked byte for byte against foxglove-sdk's own encode().
"""
from __future__ import annotations

import base64
import json
import math
import struct
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import rclpy
from foxglove import messages as fm
from libcollide_msgs.srv import Kill, Spawn
from websockets.sync.client import ClientConnection, connect
from websockets.typing import Subprotocol

from collide_ros.testing import NodeProcess, SimClient
from collide_ros.view import foxglove_wire as wire
from collide_ros.view.scene import yaw_of
from collide_ros.view.server import parse_args
from protobuf_wire import Schema
from view_process import ViewProcess

GIVE_UP = 60.0      # s: guards against a hung test only; never a pass/fail criterion
SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
OP_MESSAGE_DATA = 0x01
WORLD, PREFIX = "map", "lab/"  # the node's world_frame and frame_prefix in these tests
# the poses go node -> bodies/states (doubles) -> view (yaw from the quaternion) -> protobuf doubles:
# x and y are copied; yaw -> quaternion -> yaw round trips to a few ulp
POS_TOL, YAW_TOL = 1e-12, 1e-12


# ---------------------------------------------------------------- the encoder against the SDK's
def _sdk_pose(x: float, y: float, yaw: float) -> fm.Pose:
    return fm.Pose(position=fm.Vector3(x=x, y=y, z=0.0),
                   orientation=fm.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)))


def _sdk_color(c: tuple[float, float, float, float]) -> fm.Color:
    return fm.Color(r=c[0], g=c[1], b=c[2], a=c[3])


def test_wire_bytes_equal_the_sdks() -> None:
    """SceneUpdate and FrameTransforms bytes as foxglove-sdk encodes the same messages; poses with a
    coordinate exactly 0 (proto3 leaves it out) and without."""
    verts = [[-0.25, -0.5], [0.25, -0.5], [0.25, 0.5], [-0.25, 0.5]]
    tri = [[0.0, 0.0], [1.0, 0.0], [0.3, 0.7]]
    t = 12.345678901
    poses = [(0.1 * i - 3.0, 0.2 + i, 0.3 * i + 0.1) for i in range(4)] + [(0.0, 1.0, 0.0), (2.0, 0.0, math.pi)]
    shapes = [verts if i % 2 else tri for i in range(len(poses))]
    colors = [(0.2, 0.75, 0.2, 1.0), (0.5, 0.5, 0.5, 1.0)]
    stamp, frame = wire.timestamp(t), wire.string_field(2, "world")
    parts = [wire.body_parts(f"body/b{i}", s, colors[i % 2]) for i, s in enumerate(shapes)]
    contacts, springs = [(1.0, 2.0), (0.0, -1.0)], [(0.0, 1.0, 2.0, 3.0)]
    mine = wire.scene_update(stamp, frame, parts, poses,
                             [wire.points_entity(stamp, frame, "contacts", contacts),
                              wire.lines_entity(stamp, frame, "springs", springs)], deleted=["body/gone"])

    sec, ns = divmod(round(t * 1e9), 10**9)
    ts = fm.Timestamp(sec, ns)
    ents = []
    for i, ((x, y, a), s) in enumerate(zip(poses, shapes)):
        pts = [fm.Point3(x=v[0], y=v[1], z=0.0) for v in s]
        fan = [p for k in range(1, len(pts) - 1) for p in (pts[0], pts[k], pts[k + 1])]
        ents.append(fm.SceneEntity(
            timestamp=ts, frame_id="world", id=f"body/b{i}",
            lines=[fm.LinePrimitive(type=fm.LinePrimitiveLineType.LineLoop, pose=_sdk_pose(x, y, a), thickness=2.0,
                                    scale_invariant=True, points=pts, color=_sdk_color(wire.OUTLINE))],
            triangles=[fm.TriangleListPrimitive(pose=_sdk_pose(x, y, a), points=fan, color=_sdk_color(colors[i % 2]))]))
    size = fm.Vector3(x=wire.CONTACT_SIZE, y=wire.CONTACT_SIZE, z=wire.CONTACT_SIZE)
    ents.append(fm.SceneEntity(timestamp=ts, frame_id="world", id="contacts", spheres=[
        fm.SpherePrimitive(pose=_sdk_pose(px, py, 0.0), size=size, color=_sdk_color(wire.CONTACT))
        for px, py in contacts]))
    ends = [fm.Point3(x=0.0, y=1.0, z=0.0), fm.Point3(x=2.0, y=3.0, z=0.0)]
    ents.append(fm.SceneEntity(timestamp=ts, frame_id="world", id="springs", lines=[
        fm.LinePrimitive(type=fm.LinePrimitiveLineType.LineList, pose=_sdk_pose(0.0, 0.0, 0.0), thickness=2.0,
                         scale_invariant=True, points=ends, color=_sdk_color(wire.SPRING))]))
    sdk = fm.SceneUpdate(deletions=[fm.SceneEntityDeletion(timestamp=ts, id="body/gone")], entities=ents)
    assert mine == sdk.encode()

    children = [f"lab/b{i}" for i in range(len(poses))]
    mine_tf = wire.frame_transforms(stamp, frame, [wire.string_field(3, c) for c in children], poses)
    sdk_tf = fm.FrameTransforms(transforms=[
        fm.FrameTransform(timestamp=ts, parent_frame_id="world", child_frame_id=c,
                          translation=fm.Vector3(x=x, y=y, z=0.0),
                          rotation=fm.Quaternion(x=0.0, y=0.0, z=math.sin(a / 2), w=math.cos(a / 2)))
        for c, (x, y, a) in zip(children, poses)])
    assert mine_tf == sdk_tf.encode()


def test_decoder_reads_what_the_sdk_writes() -> None:
    """protobuf_wire (the tests' decoder) against a message the SDK encoded: the decoder is not checked
    by the encoder it checks."""
    schema = Schema.parse(fm.SceneUpdate.get_schema().data)
    msg = fm.SceneUpdate(deletions=[fm.SceneEntityDeletion(id="x", type=fm.SceneEntityDeletionType.All)], entities=[
        fm.SceneEntity(frame_id="w", id="e", timestamp=fm.Timestamp(3, 5),
                       cubes=[fm.CubePrimitive(pose=_sdk_pose(1.5, -2.0, 0.5), size=fm.Vector3(x=1.0, y=2.0, z=3.0))])])
    got = schema.decode("foxglove.SceneUpdate", msg.encode())
    assert got["deletions"] == [{"id": "x", "type": 1}]
    (e,) = got["entities"]
    assert e["frame_id"] == "w" and e["id"] == "e" and e["timestamp"] == {"seconds": 3, "nanos": 5}
    cube = e["cubes"][0]
    assert cube["pose"]["position"] == {"x": 1.5, "y": -2.0}
    assert cube["pose"]["orientation"] == {"z": math.sin(0.25), "w": math.cos(0.25)}
    assert cube["size"] == {"x": 1.0, "y": 2.0, "z": 3.0}


def test_cli_defaults_port_8765_on_loopback() -> None:
    a, _ = parse_args(["--foxglove"])
    assert a.foxglove and a.foxglove_port == 8765 and a.host == "127.0.0.1"
    assert not parse_args([])[0].foxglove


# ---------------------------------------------------------------- a Foxglove client against the view
@dataclass
class FoxgloveClient:
    """One connection: the server's info, its channels by topic, and the decoded messages per topic."""
    ws: ClientConnection
    info: dict[str, Any] = field(default_factory=dict)
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)
    schemas: dict[str, Schema] = field(default_factory=dict)
    subs: dict[int, str] = field(default_factory=dict)   # subscription id -> topic
    log_times: list[int] = field(default_factory=list)

    def advertised(self, topics: tuple[str, ...]) -> None:
        end = time.monotonic() + GIVE_UP
        while not all(t in self.channels for t in topics):
            assert time.monotonic() < end, f"not advertised: {topics}; got {list(self.channels)}"
            self.handle(self.ws.recv(timeout=GIVE_UP))

    def subscribe(self, topics: tuple[str, ...]) -> None:
        subs = []
        for i, t in enumerate(topics, start=len(self.subs) + 1):
            self.subs[i] = t
            subs.append({"id": i, "channelId": self.channels[t]["id"]})
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def handle(self, frame: str | bytes) -> tuple[str, Any] | None:
        """A JSON control message is recorded; a message data frame is decoded: (topic, message)."""
        if isinstance(frame, str):
            m = json.loads(frame)
            if m["op"] == "serverInfo":
                self.info = m
            elif m["op"] == "advertise":
                for ch in m["channels"]:
                    self.channels[ch["topic"]] = ch
            return None
        assert frame[0] == OP_MESSAGE_DATA, f"unexpected binary opcode {frame[0]}"
        sub_id, log_time = struct.unpack_from("<IQ", frame, 1)
        self.log_times.append(log_time)
        topic = self.subs[sub_id]
        ch, payload = self.channels[topic], frame[13:]
        if ch["encoding"] == "json":
            return topic, json.loads(payload)
        assert ch["encoding"] == "protobuf" and ch["schemaEncoding"] == "protobuf", ch
        schema = self.schemas.get(topic)
        if schema is None:
            schema = self.schemas[topic] = Schema.parse(base64.b64decode(ch["schema"]))
        return topic, schema.decode(ch["schemaName"], payload)

    def until(self, cond: Any, what: str) -> Any:
        """Decode messages until cond(topic, message) returns something true (returned)."""
        end = time.monotonic() + GIVE_UP
        while True:
            remaining = end - time.monotonic()
            assert remaining > 0, f"gave up waiting for {what}"
            got = self.handle(self.ws.recv(timeout=remaining))
            if got is not None:
                r = cond(*got)
                if r:
                    return r


@dataclass
class Stack:
    client: SimClient
    node: NodeProcess
    view: ViewProcess


@pytest.fixture(scope="module")
def stack() -> Iterator[Stack]:
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    node = NodeProcess("-p", f"world_frame:={WORLD}", "-p", f"frame_prefix:={PREFIX}")
    st = Stack(SimClient(context=ctx), node, None)  # type: ignore[arg-type]
    try:
        assert st.client.wait_for(lambda: st.client.count["bodies/states"] > 0, timeout=GIVE_UP), \
            f"the node published no bodies/states:\n{st.node.output()}"
        # port 0: a free port, so that test runs side by side do not collide on 8765 (its default is
        # checked above)
        st.view = ViewProcess(0, "--foxglove", "--foxglove-port", "0")
        assert st.view.foxglove_port, f"the view printed no Foxglove port:\n{st.view.output()}"
        yield st
        assert st.view.stop() == 0, f"the view did not exit cleanly:\n{st.view.output()}"
    finally:
        if st.view is not None:
            st.view.stop()
        st.client.close()
        code = st.node.stop()
        rclpy.shutdown(context=ctx)
    assert code == 0, f"the node exited with {code}:\n{st.node.output()}"


@contextmanager
def _connect(stack: Stack) -> Iterator[FoxgloveClient]:
    with connect(f"ws://127.0.0.1:{stack.view.foxglove_port}", subprotocols=[Subprotocol(p) for p in SUBPROTOCOLS],
                 max_size=None, open_timeout=GIVE_UP) as ws:
        assert ws.subprotocol == "foxglove.sdk.v1"
        yield FoxgloveClient(ws)


def _body(scene: dict[str, Any], name: str) -> dict[str, Any] | None:
    return next((e for e in scene.get("entities", []) if e["id"] == f"body/{name}"), None)


def _pose(p: dict[str, Any]) -> tuple[float, float, float]:
    """(x, y, yaw) of a decoded foxglove.Pose (absent fields are 0, as proto3 leaves them out)."""
    pos, q = p.get("position", {}), p.get("orientation", {})
    return pos.get("x", 0.0), pos.get("y", 0.0), 2.0 * math.atan2(q.get("z", 0.0), q.get("w", 0.0))


def test_listens_on_loopback_only(stack: Stack) -> None:
    listening = Path("/proc/net/tcp").read_text().splitlines()[1:]
    local = {ln.split()[1] for ln in listening if ln.split()[3] == "0A"}  # state LISTEN
    assert f"0100007F:{stack.view.foxglove_port:04X}" in local  # 127.0.0.1, not 0.0.0.0


def test_scene_update_has_the_bodies_at_their_poses(stack: Stack) -> None:
    # the default scene at gravity 0 with no command rests: bodies/poses and the view's scene agree
    names = list(stack.client.fresh("bodies/states", timeout=GIVE_UP).names)
    poses = stack.client.fresh("bodies/poses", timeout=GIVE_UP)
    assert poses is not None and len(poses.poses) == len(names) >= 2
    want = {n: (p.position.x, p.position.y, yaw_of(p.orientation)) for n, p in zip(names, poses.poses)}

    with _connect(stack) as fc:
        topics = ("/scene", "/tf", "/energy")
        fc.advertised(topics)
        assert fc.info.get("name") == "libcollide view", fc.info
        assert fc.channels["/scene"]["schemaName"] == "foxglove.SceneUpdate"
        assert fc.channels["/tf"]["schemaName"] == "foxglove.FrameTransforms"
        assert fc.channels["/energy"]["encoding"] == "json"
        fc.subscribe(topics)

        def full_scene(topic: str, m: dict[str, Any]) -> dict[str, Any] | None:
            return m if topic == "/scene" and all(_body(m, n) for n in names) else None
        scene = fc.until(full_scene, "a SceneUpdate with every dynamic body")
        for n in names:
            e = _body(scene, n)
            assert e is not None and e["frame_id"] == WORLD, e
            fill, outline = e["triangles"][0], e["lines"][0]
            for prim in (fill, outline):
                x, y, a = _pose(prim["pose"])
                wx, wy, wa = want[n]
                assert abs(x - wx) <= POS_TOL and abs(y - wy) <= POS_TOL and abs(a - wa) <= YAW_TOL, (n, prim["pose"], want[n])
            assert outline["type"] == wire.LINE_LOOP and len(outline["points"]) == 4  # the blocks are boxes
            assert len(fill["points"]) == 6  # two triangles
            c = fill["color"]
            green = c["g"] > c["r"] + 0.3 and c["g"] > c["b"] + 0.3
            assert green == (n == "block1"), f"{n} filled with {c}: the green block (only) is green"
        walls = [e for e in scene["entities"] if e["id"].startswith("static/")]
        assert len(walls) == 4  # the default scene's box
        assert {e["id"] for e in scene["entities"]} >= {"contacts", "springs"}

        def transforms(topic: str, m: dict[str, Any]) -> dict[str, Any] | None:
            return m if topic == "/tf" else None
        tf = fc.until(transforms, "FrameTransforms")
        got = {t["child_frame_id"]: t for t in tf["transforms"]}
        assert set(got) == {PREFIX + n for n in names}  # named as the node's /tf names them
        for n in names:
            t = got[PREFIX + n]
            assert t["parent_frame_id"] == WORLD
            tr = t["translation"]
            assert abs(tr.get("x", 0.0) - want[n][0]) <= POS_TOL and abs(tr.get("y", 0.0) - want[n][1]) <= POS_TOL

        def energy(topic: str, m: dict[str, Any]) -> dict[str, Any] | None:
            return m if topic == "/energy" else None
        e = fc.until(energy, "the energy")
        for k in ("translational", "rotational", "potential", "total", "t"):
            assert math.isfinite(e[k]), e
        assert e["total"] == pytest.approx(e["translational"] + e["rotational"] + e["potential"], abs=1e-9)


def test_killed_body_is_deleted(stack: Stack) -> None:
    with _connect(stack) as fc:
        fc.advertised(("/scene",))
        fc.subscribe(("/scene",))
        req = Spawn.Request(name="crate", width=1.0, height=1.0, mass=2.0, elasticity=1.0)
        req.pose.position.x, req.pose.position.y = 0.0, -4.0
        r = stack.client.call(Spawn, "spawn", req)
        assert r is not None and r.success, r
        scene = fc.until(lambda t, m: m if _body(m, "crate") else None, "the spawned crate in a SceneUpdate")
        x, y, _ = _pose(_body(scene, "crate")["triangles"][0]["pose"])
        assert abs(x) <= POS_TOL and abs(y + 4.0) <= POS_TOL
        k = stack.client.call(Kill, "kill", Kill.Request(name="crate"))
        assert k is not None and k.success, k
        fc.until(lambda t, m: any(d.get("id") == "body/crate" for d in m.get("deletions", [])),
                 "a SceneUpdate that deletes body/crate")
        # and the crate is not drawn again
        later = fc.until(lambda t, m: m if _body(m, "block1") else None, "the next SceneUpdate")
        assert _body(later, "crate") is None
