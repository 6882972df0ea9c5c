"""The node's message counts in /diagnostics and its state_qos_depth parameter.

One node process (2 blocks, lower rates than the defaults so that a short run has every topic
but little traffic) serves the module. A client with deep (1000) reliable subscriptions to every
topic the node publishes counts what it receives between two settled /diagnostics snapshots of the
paused node (docs/ros_interface.md): the node's ``published/<topic>`` deltas must equal what the
client received, and the ``received/ accepted/ rejected/ lost/<command topic>`` deltas must equal
the commands the client sent, split by whether they were legal.
"""
from __future__ import annotations

from typing import Any, Iterator

import pytest
import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Point, PoseArray, Twist, TwistStamped, Vector3, WrenchStamped
from libcollide_msgs.msg import BodyStates, Contacts, Energy, SpringCommand, ThrusterCommand
from libcollide_msgs.srv import Step
from rcl_interfaces.msg import ParameterType
from rcl_interfaces.srv import DescribeParameters
from rclpy.exceptions import InvalidParameterValueException
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from std_srvs.srv import SetBool
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from collide_ros.node import SimNode
from collide_ros.testing import SimClient, diag_values, running_sim

DEPTH = 37  # state_qos_depth of the module's node: not the default (100), to see it applied
# topic as the node names it (its diagnostics key is published/<topic without '/'>) -> type
PUBLISHED: dict[str, Any] = {
    "bodies/poses": PoseArray, "bodies/states": BodyStates, "contacts": Contacts, "energy": Energy,
    "/clock": Clock, "/tf": TFMessage, "markers": MarkerArray, "applied/thrusters": ThrusterCommand,
    "applied/spring": SpringCommand, "applied/cmd_vel": TwistStamped,
    "applied/block1/thrust": WrenchStamped, "applied/block2/thrust": WrenchStamped,
}
COMMAND_TOPICS = ("thrusters", "spring", "cmd_vel", "block1/thrust", "block2/thrust")


@pytest.fixture(scope="module")
def sim() -> Iterator[SimClient]:
    args = ("-p", "blocks:=2", "-p", f"state_qos_depth:={DEPTH}", "-p", "state_rate:=50.0",
            "-p", "tf_rate:=25.0", "-p", "marker_rate:=10.0", "-p", "clock_rate:=100.0")
    with running_sim(*args) as (client, _):
        yield client


class Counter:
    """Deep reliable subscriptions of ``client`` to every topic of PUBLISHED and /diagnostics."""

    def __init__(self, client: SimClient) -> None:
        self.n = {t: 0 for t in PUBLISHED}
        self.diags: list[dict[str, str]] = []
        deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        self.subs = [client.node.create_subscription(typ, topic, self._counter(topic), deep)
                     for topic, typ in PUBLISHED.items()]
        self.subs.append(client.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, deep))
        self.client = client

    def _counter(self, topic: str) -> Any:
        def cb(msg: Any) -> None:
            self.n[topic] += 1
        return cb

    def _on_diag(self, msg: DiagnosticArray) -> None:
        vals = diag_values(msg)
        if vals is not None:
            self.diags.append(vals)

    def close(self) -> None:
        for s in self.subs:
            self.client.node.destroy_subscription(s)


def _send_commands(sim: SimClient) -> dict[str, tuple[int, int]]:
    """Legal and illegal commands on every command topic; returns topic -> (accepted, rejected)."""
    nan = float("nan")
    legal = WrenchStamped()
    legal.wrench.force.x = 0.5
    bad = WrenchStamped()
    bad.wrench.force.x = nan
    plan: list[tuple[str, Any, bool]] = [
        ("thrusters", ThrusterCommand(body="block1", firing=[True]), True),
        ("thrusters", ThrusterCommand(body="block2", firing=[False, True]), True),
        ("thrusters", ThrusterCommand(body="ghost", firing=[True]), False),
        ("thrusters", ThrusterCommand(body="block1", firing=[True] * 9), False),
        ("block1/thrust", legal, True), ("block1/thrust", bad, False),
        ("block2/thrust", legal, True), ("block2/thrust", legal, True),
        ("cmd_vel", Twist(linear=Vector3(x=0.2)), True), ("cmd_vel", Twist(linear=Vector3(x=nan)), False),
        ("spring", SpringCommand(name="m", body="block2", target=Point(x=2.5, y=2.0), stiffness=1.0), True),
        ("spring", SpringCommand(name="m", release=True), True),
        ("spring", SpringCommand(name="never", release=True), False),
    ]
    types = {"thrusters": ThrusterCommand, "spring": SpringCommand, "cmd_vel": Twist}
    for topic in COMMAND_TOPICS:
        assert sim.wait_subscribed(topic, types.get(topic, WrenchStamped))
    out = {t: (0, 0) for t in COMMAND_TOPICS}
    for topic, msg, ok in plan:
        sim.publish(topic, msg)
        a, r = out[topic]
        out[topic] = (a + 1, r) if ok else (a, r + 1)
        sim.spin(0.05)  # in order, and never more than the command queue's depth 10 in flight
    return out


def _pause(sim: SimClient, on: bool) -> None:
    r = sim.call(SetBool, "pause", SetBool.Request(data=on))
    assert r is not None and r.success


def _ours(sim: SimClient) -> dict[str, int]:
    """This client's subscriptions on every topic of PUBLISHED, as the ROS graph lists them."""
    return {t: sum(i.node_name == sim.node.get_name()
                   for i in sim.node.get_subscriptions_info_by_topic(t if t.startswith("/") else f"/{t}"))
            for t in PUBLISHED}


def _matched(sim: SimClient, ours: dict[str, int]) -> bool:
    """The graph lists ``ours`` of this client's subscriptions per topic, and the node's
    subscribers/<topic> (readers its writer has matched) equals all the graph lists."""
    vals = sim.diagnostics()
    assert vals is not None
    for t in PUBLISHED:
        infos = sim.node.get_subscriptions_info_by_topic(t if t.startswith("/") else f"/{t}")
        if sum(i.node_name == sim.node.get_name() for i in infos) != ours[t]:
            return False
        if int(vals[f"subscribers/{t.lstrip('/')}"]) != len(infos):
            return False
    return True


def test_counts_match_what_a_subscriber_received(sim: SimClient) -> None:
    base = _ours(sim)
    counter = Counter(sim)
    try:
        # every one of our readers matched by the node's writer before the first snapshot: its
        # subscribers/<topic> counts each of them (the graph lists a reader before it is matched)
        assert sim.wait_for(lambda: _matched(sim, {t: n + 1 for t, n in base.items()}), 20.0)
        _pause(sim, True)
        before = sim.settled_counts()
        assert before is not None
        sim.spin(0.5)  # what was published before the snapshot reaches our readers
        got_before = dict(counter.n)
        _pause(sim, False)
        sent = _send_commands(sim)
        sim.spin(1.0)  # ~1 s of sim time at real-time factor 1: ~50 states, ~100 clocks, ~10 markers
        _pause(sim, True)
        after = sim.settled_counts()
        assert after is not None
        sim.spin(0.5)
        got = {t: counter.n[t] - got_before[t] for t in PUBLISHED}
        published = {t: after[f"published/{t.lstrip('/')}"] - before[f"published/{t.lstrip('/')}"]
                     for t in PUBLISHED}
        assert published == got
        assert all(got[t] > 0 for t in PUBLISHED), got  # every topic had traffic in the window
        for topic, (accepted, rejected) in sent.items():
            node = {w: after[f"{w}/{topic}"] - before[f"{w}/{topic}"]
                    for w in ("received", "accepted", "rejected", "lost")}
            assert node == {"received": accepted + rejected, "accepted": accepted, "rejected": rejected,
                            "lost": 0}, topic
            assert got[f"applied/{topic}"] == accepted, topic  # accepted = echoed
        assert after["rejected_commands"] - before["rejected_commands"] == sum(r for _, r in sent.values())
        # published/diagnostics numbers the diagnostics messages: consecutive ones differ by one
        seq = [int(d["published/diagnostics"]) for d in counter.diags]
        assert len(seq) >= 3 and seq == list(range(seq[0], seq[0] + len(seq)))
    finally:
        counter.close()
        _pause(sim, False)
    # and unmatched again once our readers are gone
    assert sim.wait_for(lambda: _matched(sim, base), 20.0)


def test_commands_dropped_while_the_executor_is_busy_are_counted_lost(sim: SimClient) -> None:
    """While one ~/step call keeps the node's executor busy, DDS keeps only the newest 10 (the
    command queue's depth) of a burst on one topic; the node counts the others as lost/<topic>
    from the gap in the publisher's sequence numbers (docs/ros_interface.md, "Message counts in /diagnostics")."""
    assert sim.wait_subscribed("thrusters", ThrusterCommand)
    echoes: list[ThrusterCommand] = []
    sub = sim.node.create_subscription(ThrusterCommand, "applied/thrusters", echoes.append, 100)
    try:
        # our reader seeing the node's writer is not enough: the echo reaches us only once the
        # node's writer has matched our reader, which DDS may do later (a CI run lost the echo)
        assert sim.wait_node_matched("applied/thrusters")
        sim.publish("thrusters", ThrusterCommand(body="block1", firing=[False]))  # the node's first from us
        assert sim.wait_for(lambda: len(echoes) >= 1, 10.0)
        _pause(sim, True)
        before = sim.settled_counts()
        assert before is not None
        step = sim.node.create_client(Step, f"{sim.sim}/step")
        assert step.wait_for_service(timeout_sec=10.0)
        n_clock = sim.count["clock"]
        # 300 000 steps keep the executor in this one callback for seconds (4 s on the 2-core
        # development VM); /clock advancing while paused shows the call is being served
        fut = step.call_async(Step.Request(steps=300_000))
        assert sim.wait_for(lambda: sim.count["clock"] > n_clock + 2, 30.0)
        burst = 30
        for _ in range(burst):
            sim.publish("thrusters", ThrusterCommand(body="block1", firing=[False]))
        still_stepping = sim.count["clock"]
        sim.ex.spin_until_future_complete(fut, timeout_sec=300.0)
        assert fut.done() and fut.result().success
        after = sim.settled_counts()
        assert after is not None
        node = {w: after[f"{w}/thrusters"] - before[f"{w}/thrusters"] for w in ("received", "lost")}
        assert sim.count["clock"] > still_stepping + 2  # the burst went out while the step ran
        # every message of the burst was either taken or counted lost; at most a queue's worth taken
        assert node["received"] + node["lost"] == burst, node
        assert node["received"] <= 10 and node["lost"] >= burst - 10, node
        assert after["accepted/thrusters"] - before["accepted/thrusters"] == node["received"]
    finally:
        sim.node.destroy_subscription(sub)
        _pause(sim, False)


def test_state_qos_depth_is_read_only_with_its_range(sim: SimClient) -> None:
    assert sim.get_params(["state_qos_depth"]) == {"state_qos_depth": DEPTH}
    res = sim.set_params({"state_qos_depth": 50})
    assert res is not None and not res[0].successful
    assert "read-only" in res[0].reason and "state_qos_depth" in res[0].reason
    assert sim.get_params(["state_qos_depth"]) == {"state_qos_depth": DEPTH}
    d = sim.call(DescribeParameters, "describe_parameters", DescribeParameters.Request(names=["state_qos_depth"]))
    assert d is not None
    desc = d.descriptors[0]
    assert desc.type == ParameterType.PARAMETER_INTEGER and desc.read_only and desc.description
    assert (desc.integer_range[0].from_value, desc.integer_range[0].to_value) == (1, 10000)


def _in_process_node(depth: int) -> tuple[Any, SimNode | None, Exception | None]:
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    try:
        # its own namespace: constructing it publishes markers, which must not reach the module's client
        node = SimNode(context=ctx, cli_args=["--ros-args", "-r", "__ns:=/qos_probe"],
                       parameter_overrides=[Parameter("state_qos_depth", value=depth)])
        return ctx, node, None
    except InvalidParameterValueException as exc:
        return ctx, None, exc


def test_state_qos_depth_sets_the_state_publishers_history() -> None:
    # The publishers' history depth is not visible from another process with Fast DDS (the graph's
    # get_publishers_info_by_topic reports depth 0: history is not part of DDS discovery), so this
    # checks the profile the node's publishers were created with, in-process.
    ctx, node, exc = _in_process_node(DEPTH)
    try:
        assert exc is None and node is not None
        for pub in (node._pub_poses, node._pub_states, node._pub_contacts, node._pub_energy):
            assert pub.pub.qos_profile.depth == DEPTH
            assert pub.pub.qos_profile.reliability == ReliabilityPolicy.RELIABLE
        assert node._pub_tf.pub.qos_profile.depth == 100  # /tf keeps tf2's depth
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.shutdown(context=ctx)


@pytest.mark.parametrize("depth", [0, 10001])
def test_state_qos_depth_out_of_range_stops_the_start(depth: int) -> None:
    # what `-p state_qos_depth:=0` on the command line does: node.main reports the exception and exits 2
    ctx, node, exc = _in_process_node(depth)
    try:
        assert node is None and exc is not None
        assert "state_qos_depth" in str(exc) and "out of range" in str(exc).lower(), str(exc)
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.shutdown(context=ctx)
