"""Bag round trip: record the real node (plus a counted test publisher) with collide_ros.recorder
in its own process, then read the rosbag2 directory back with rosbags and with the independent
mcap / mcap_ros2 readers."""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import pytest
import rclpy
import yaml
from libcollide_msgs.msg import ThrusterCommand
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy

from collide_ros.demo import Proc
from collide_ros.recorder import installed_type_hash, make_typestore

GIVE_UP = 60.0  # s: guards against a hang only
N_SENT = 300
TOPICS = ["bodies/states", "bodies/poses", "energy", "contacts", "/clock", "/tf", "markers", "thrusters"]


def _stamp_ns(m: Any) -> int:
    return int(m.header.stamp.sec) * 1_000_000_000 + int(m.header.stamp.nanosec)


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("rec")
    bag = tmp / "bag"
    node = Proc([sys.executable, "-m", "collide_ros.node", "--ros-args", "-p", "state_rate:=100.0",
                 "-p", "clock_rate:=100.0"], tmp / "node.log")
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    n = rclpy.create_node("rec_test_pub", context=ctx)
    ex = SingleThreadedExecutor(context=ctx)
    ex.add_node(n)
    pub = n.create_publisher(ThrusterCommand, "thrusters",
                             QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    rec = None
    try:
        end = time.monotonic() + GIVE_UP
        while pub.get_subscription_count() < 1 or n.count_publishers("bodies/states") < 1:
            assert node.proc.poll() is None and time.monotonic() < end, "node did not come up"
            ex.spin_once(timeout_sec=0.05)
        rec = Proc([sys.executable, "-m", "collide_ros.recorder", "--out", str(bag), "--params-of", "sim",
                    "--topics", *TOPICS], tmp / "recorder.log")
        want = {("/" + t).replace("//", "/") for t in TOPICS}
        while True:
            got = {ln.split()[-1] for ln in rec.lines if ln.startswith("recorder: subscribed")}
            if want <= got and pub.get_subscription_count() >= 2:
                break
            assert rec.proc.poll() is None and time.monotonic() < end, f"recorder: {rec.lines}"
            ex.spin_once(timeout_sec=0.05)
        # exactly N_SENT commands, numbered in header.stamp.sec; all-off, valid for the node
        for i in range(N_SENT):
            m = ThrusterCommand(body="block1", firing=[False] * 4)
            m.header.stamp.sec = i
            pub.publish(m)
            ex.spin_once(timeout_sec=0.004)
        t_end = time.monotonic() + 0.5
        while time.monotonic() < t_end:
            ex.spin_once(timeout_sec=0.02)
        assert rec.stop() == 0, "\n".join(rec.lines)
    finally:
        if rec is not None:
            rec.stop()
        ex.shutdown()
        n.destroy_node()
        rclpy.shutdown(context=ctx)
        node.stop()
    printed = {}
    for ln in rec.lines:
        parts = ln.split()
        if ln.startswith("  /") and len(parts) == 2:
            printed[parts[0]] = int(parts[1])
    return {"bag": bag, "printed": printed}


def _read(bag: Path) -> tuple[dict[str, list[tuple[int, Any]]], dict[str, str]]:
    from rosbags.rosbag2 import Reader

    store = make_typestore()
    out: dict[str, list[tuple[int, Any]]] = {}
    types: dict[str, str] = {}
    with Reader(bag) as r:
        for c in r.connections:
            types[c.topic] = c.msgtype
        for conn, ts, raw in r.messages():
            out.setdefault(conn.topic, []).append((ts, store.deserialize_cdr(raw, conn.msgtype)))
    return out, types


def test_metadata_v9_mcap(recording: dict[str, Any]) -> None:
    bag = recording["bag"]
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["version"] == 9 and meta["storage_identifier"] == "mcap"
    files = meta["relative_file_paths"]
    assert len(files) == 1 and files[0].endswith(".mcap") and (bag / files[0]).is_file()
    for t in meta["topics_with_message_count"]:
        tm = t["topic_metadata"]
        assert tm["serialization_format"] == "cdr"
        assert tm["type_description_hash"].startswith("RIHS01_")
        if tm["type"].startswith(("libcollide_msgs/", "tf2_msgs/")):
            # the hash rosidl generated for the installed package (what a ROS install checks)
            assert tm["type_description_hash"] == installed_type_hash(tm["type"])
        assert isinstance(tm["offered_qos_profiles"], list) and tm["offered_qos_profiles"]
    assert "collide_ros.params" in (meta.get("custom_data") or {})


def test_metadata_ros_distro_jazzy(recording: dict[str, Any]) -> None:
    """The bag says which ROS 2 release it is for (rosbags would write "rosbags"): in metadata.yaml,
    as rosbags reads it, and in the MCAP file's rosbag2 metadata record (what `ros2 bag info` of
    the bare .mcap file reads)."""
    from mcap.reader import make_reader
    from rosbags.rosbag2 import Reader

    bag = recording["bag"]
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["ros_distro"] == "jazzy"
    with Reader(bag) as r:
        assert r.ros_distro == "jazzy"
    (mcap_file,) = list(bag.glob("*.mcap"))
    with mcap_file.open("rb") as f:
        records = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
    embedded = yaml.safe_load(records["rosbag2"]["serialized_metadata"])
    assert embedded["ros_distro"] == "jazzy"
    assert embedded["message_count"] == meta["message_count"]  # the rest as rosbags wrote it


def test_counts_timestamps_decode(recording: dict[str, Any]) -> None:
    msgs, types = _read(recording["bag"])
    assert set(recording["printed"]) == set(msgs)
    for topic, lst in msgs.items():
        # what the recorder printed is what the bag holds
        assert recording["printed"][topic] == len(lst), topic
        ts = [t for t, _ in lst]
        assert ts == sorted(ts), f"{topic}: receive timestamps not monotonic"
    # the counted publisher: every one of the N_SENT commands, in order
    cmds = msgs["/thrusters"]
    assert [m.header.stamp.sec for _, m in cmds] == list(range(N_SENT))
    assert all(m.body == "block1" and list(m.firing) == [False] * 4 for _, m in cmds)
    # the node's periodic topics: sim-time stamps 10 ms apart (100 Hz of sim time at dt 1 ms) with
    # no gap from the first to the last recorded one, so nothing published in between was lost
    for topic in ("/bodies/states", "/bodies/poses", "/energy", "/contacts", "/clock"):
        lst = msgs[topic]
        stamps = [(m.clock.sec * 1_000_000_000 + m.clock.nanosec) if topic == "/clock" else _stamp_ns(m)
                  for _, m in lst]
        assert len(stamps) > 100, topic
        steps = {round((b - a) / 1e6) for a, b in zip(stamps, stamps[1:])}
        assert steps == {10}, f"{topic}: stamp spacing {sorted(steps)} ms"
    st = msgs["/bodies/states"][-1][1]
    assert list(st.names) == ["block1", "block2"] and len(st.poses) == 2 and len(st.twists) == 2
    assert types["/tf"] == "tf2_msgs/msg/TFMessage"
    assert msgs["/tf"][-1][1].transforms[0].child_frame_id.endswith("block1")


def test_mcap_independent_reader(recording: dict[str, Any]) -> None:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    bag = recording["bag"]
    (mcap_file,) = list(bag.glob("*.mcap"))
    counts: dict[str, int] = {}
    with mcap_file.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, _msg, decoded in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            assert channel.message_encoding == "cdr" and schema.encoding == "ros2msg"
            if channel.topic == "/energy":
                assert schema.name == "libcollide_msgs/msg/Energy"
                assert decoded.total >= 0.0  # kinetic + potential with no gravity: never negative
    assert counts == recording["printed"]
