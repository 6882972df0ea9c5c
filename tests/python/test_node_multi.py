"""Two sims side by side in one ROS domain (``-r __ns:=/robot1``, ``/robot2``), as a multi-robot
user runs them: only /robot1 owns /clock (``publish_clock:=false`` on /robot2), their body frames
in the one /tf tree differ by the frame prefix the namespace gives, and their /diagnostics statuses
are named by each node's fully qualified name (docs/ros_interface.md, "Several sims in one domain")."""
from __future__ import annotations

import time
from typing import Any, Iterator

import pytest
import rclpy
from geometry_msgs.msg import WrenchStamped
from rosgraph_msgs.msg import Clock
from std_srvs.srv import SetBool

from collide_ros.cdr import join_time
from collide_ros.testing import NodeProcess, SimClient, sims_side_by_side


@pytest.fixture(scope="module")
def robots() -> Iterator[tuple[SimClient, SimClient]]:
    # clock_rate 100 Hz: a Python subscriber keeps up, so every /clock message is seen in order
    with sims_side_by_side(("-r", "__ns:=/robot1", "-p", "blocks:=1", "-p", "clock_rate:=100.0"),
                           ("-r", "__ns:=/robot2", "-p", "blocks:=2", "-p", "clock_rate:=100.0",
                            "-p", "publish_clock:=false")) as (c1, c2):
        yield c1, c2


def test_one_clock_that_never_jumps_back(robots: tuple[SimClient, SimClient]) -> None:
    r1, r2 = robots
    assert r2.get_params(["publish_clock"]) == {"publish_clock": False}
    assert r1.get_params(["publish_clock"]) == {"publish_clock": True}
    res = r2.set_params({"publish_clock": True})
    assert res is not None and not res[0].successful and "read-only" in res[0].reason
    # the graph: a single /clock writer, robot1's sim (wait until both nodes' endpoints are known)
    node = r1.node
    assert r1.wait_for(lambda: len(node.get_publishers_info_by_topic("/robot2/bodies/states")) == 1, 20.0)
    r1.spin(1.0)
    writers = node.get_publishers_info_by_topic("/clock")
    assert [(w.node_namespace, w.node_name) for w in writers] == [("/robot1", "sim")]
    assert "published/clock" not in (r2.diagnostics() or {"published/clock": "?"})
    # /clock over robot2 paused for 2 s, then both running for 2 s: with two writers, robot2's
    # time (which stood still meanwhile) would interleave with robot1's and go back every time
    stamps: list[float] = []
    sub = node.create_subscription(Clock, "/clock", lambda m: stamps.append(join_time(m.clock)), 100)
    try:
        assert r1.wait_for(lambda: len(stamps) > 10, 20.0)
        # at least 2 s of wall time and 2 s of sim time (200 messages at 100 Hz) with robot2 paused ...
        start = len(stamps)
        assert r2.call(SetBool, "pause", SetBool.Request(data=True)).success
        r1.spin(2.0)
        assert r1.wait_for(lambda: len(stamps) >= start + 200, 30.0), len(stamps) - start
        paused_until = len(stamps)
        # ... then 2 s of sim time with both running
        assert r2.call(SetBool, "pause", SetBool.Request(data=False)).success
        assert r2.fresh("bodies/states", timeout=10.0) is not None  # robot2 runs again
        assert r1.wait_for(lambda: len(stamps) >= paused_until + 200, 30.0), len(stamps) - paused_until
    finally:
        node.destroy_subscription(sub)
    back = [(a, b) for a, b in zip(stamps, stamps[1:]) if b < a]
    assert not back, f"{len(back)} backward jumps of /clock, e.g. {back[:3]}"


def _tf_frames(client: SimClient, want: int, timeout: float = 20.0) -> dict[str, str]:
    """child -> parent frame of every transform seen on /tf until ``want`` children are known."""
    seen: dict[str, str] = {}
    start = client.count["tf"]

    def enough() -> bool:
        for msg in client.since("tf", start):
            for t in msg.transforms:
                seen[t.child_frame_id] = t.header.frame_id
        return len(seen) >= want
    client.wait_for(enough, timeout)
    client.spin(0.3)
    enough()
    return seen


def test_tf_frames_differ_by_the_namespace_prefix(robots: tuple[SimClient, SimClient]) -> None:
    r1, r2 = robots
    assert r1.get_params(["frame_prefix", "world_frame"]) == {"frame_prefix": "robot1/", "world_frame": "world"}
    assert r2.get_params(["frame_prefix"]) == {"frame_prefix": "robot2/"}
    # one tree: both sims hang their (prefixed) bodies under the shared, unprefixed world frame
    assert _tf_frames(r1, 3) == {"robot1/block1": "world", "robot2/block1": "world", "robot2/block2": "world"}
    # state headers stay in the world frame
    assert r1.fresh("bodies/poses").header.frame_id == "world"
    assert r2.fresh("bodies/states").header.frame_id == "world"
    # a thrust in the body's TF frame is a body-frame thrust
    before = int((r1.diagnostics() or {}).get("accepted/block1/thrust", -1))
    assert before >= 0 and r1.wait_subscribed("block1/thrust", WrenchStamped)
    m = WrenchStamped()
    m.header.frame_id = "robot1/block1"
    m.wrench.force.x = 0.1
    r1.publish("block1/thrust", m)
    assert r1.wait_for(lambda: int((r1.diagnostics(2.0) or {}).get("accepted/block1/thrust", -1)) > before, 15.0)
    # the prefix is a parameter: set at run time, refused with a leading '/'
    res = r2.set_params({"frame_prefix": "/arena"})
    assert res is not None and not res[0].successful and "frame_prefix" in res[0].reason
    try:
        assert r2.set_params({"frame_prefix": "arena_b/"})[0].successful
        frames = _tf_frames(r2, 5)
        assert {"arena_b/block1", "arena_b/block2"} <= frames.keys()
    finally:
        assert r2.set_params({"frame_prefix": "robot2/"})[0].successful


def test_diagnostics_named_by_the_full_node_name(robots: tuple[SimClient, SimClient]) -> None:
    r1, r2 = robots
    names: set[str] = set()

    def both() -> bool:
        for _, msg in list(r1.history["diagnostics"]):
            names.update(st.name for st in msg.status)
        return {"/robot1/sim: physics", "/robot2/sim: physics"} <= names
    assert r1.wait_for(both, 15.0), names
    assert names == {"/robot1/sim: physics", "/robot2/sim: physics"}
    # each client reads its own sim's status: 1 and 2 dynamic bodies
    v1, v2 = r1.diagnostics(), r2.diagnostics()
    assert v1 is not None and v2 is not None
    assert (v1["dynamic_bodies"], v2["dynamic_bodies"]) == ("1", "2")


def _wait_log(proc: NodeProcess, text: str, timeout: float = 20.0) -> str:
    end = time.monotonic() + timeout
    while time.monotonic() < end and text not in proc.output():
        time.sleep(0.1)
    return proc.output()


@pytest.fixture()
def own_context() -> Iterator[Any]:
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    try:
        yield ctx
    finally:
        rclpy.shutdown(context=ctx)


def test_use_sim_time_on_the_sim_is_ignored_and_diagnostics_go_on_paused(own_context: Any) -> None:
    """use_sim_time:=true on the sim (a launch file setting it for every node) is reset to false
    with an error in the log; setting it later is refused; /diagnostics keeps its 1 Hz wall pace
    while the sim is paused. Own namespace and publish_clock false: the module's robots run meanwhile."""
    proc = NodeProcess("-r", "__ns:=/simtime", "-p", "use_sim_time:=true", "-p", "start_paused:=true",
                       "-p", "publish_clock:=false")
    client = SimClient("/simtime", context=own_context)
    try:
        out = _wait_log(proc, "sim ready")
        assert "use_sim_time:=true ignored" in out, out
        assert client.get_params(["use_sim_time"]) == {"use_sim_time": False}
        res = client.set_params({"use_sim_time": True})
        assert res is not None and not res[0].successful and "publishes the sim time itself" in res[0].reason
        assert client.get_params(["use_sim_time"]) == {"use_sim_time": False}
        # paused: diagnostics at ~1 Hz of wall time, sim time standing at 0
        first = client.diagnostics(timeout=20.0)
        assert first is not None and first["paused"] == "true"
        t0 = time.monotonic()
        seen = [client.diagnostics(timeout=5.0) for _ in range(3)]
        assert all(v is not None and v["paused"] == "true" and float(v["sim_time"]) == 0.0 for v in seen)
        assert time.monotonic() - t0 < 6.0
    finally:
        client.close()
        code = proc.stop()
    assert code == 0, proc.output()


def test_bad_frame_prefix_on_the_command_line_stops_the_start() -> None:
    """A prefix that would make every body frame invalid is refused at start (exit status 2, the
    reason on stderr), as the on-set callback refuses it at run time."""
    proc = NodeProcess("-r", "__ns:=/badprefix", "-p", "frame_prefix:=/robot1/", "-p", "publish_clock:=false")
    try:
        proc.proc.wait(60.0)
    finally:
        code = proc.stop()
    out = proc.output()
    assert code == 2, out
    assert "frame_prefix: frame id '/robot1/' must not start with '/'" in out, out
