"""The node's state as a snapshot, in process (no ROS graph traffic is needed): a node restored from
another's snapshot, commands in force included, steps on bit for bit; a snapshot with springs made
over ROS or spawned bodies is refused with its reason and leaves the node as it was."""
from __future__ import annotations

import json
import os
from itertools import count

import numpy as np
import pytest
from geometry_msgs.msg import Point, Pose, Twist, WrenchStamped
from libcollide_msgs.msg import SpringCommand, ThrusterCommand
from libcollide_msgs.srv import Spawn
from rclpy.parameter import Parameter

from collide_ros.node import SimNode

_ns = count()
pytestmark = pytest.mark.usefixtures("ros")  # rclpy for every test (conftest.py)


def make_node() -> SimNode:
    return SimNode(namespace=f"/snap_{os.getpid()}_{next(_ns)}",
                   parameter_overrides=[Parameter("start_paused", value=True)])


def restored_from(a: SimNode) -> SimNode:
    msg = a.snapshot_message()
    b = make_node()
    b.restore_snapshot(bytes(msg.world), json.loads(msg.node_state))
    return b


def test_restored_node_steps_on_bit_for_bit() -> None:
    a = make_node()
    for _ in range(300):
        assert a.step_once()
    # commands in force at the snapshot: a body-frame thrust, thrusters, cmd_vel on block1
    w = WrenchStamped()
    w.wrench.force.x, w.wrench.force.y, w.wrench.torque.z = 3.0, 1.0, 0.5
    a._on_thrust("block2", w)
    a._on_thrusters(ThrusterCommand(body="block1", firing=[True, False, True]))
    tw = Twist()
    tw.linear.x, tw.angular.z = 0.7, -0.3
    a._on_cmd_vel(tw)
    assert a._thrust and a._thrusters and a._cmd_vel is not None and a.rejected == 0
    b = restored_from(a)
    try:
        assert b.sim_time == a.sim_time and b.steps == a.steps
        for _ in range(500):
            assert a.step_once() and b.step_once()
        # float64 bit patterns of every body's state, and the clock
        assert np.array_equal(a.world.state.view(np.uint64), b.world.state.view(np.uint64))
        assert b.sim_time == a.sim_time and a._thrust.keys() == b._thrust.keys()
    finally:
        a.destroy_node()
        b.destroy_node()


def restore_is_refused(a: SimNode, match: str) -> list[str]:
    """Restores a's snapshot into a fresh node, which must refuse it (ValueError matching `match`) and
    keep its world as it was; returns that node's body names. Destroys both nodes."""
    b = make_node()
    before = b.world.save()
    try:
        with pytest.raises(ValueError, match=match):
            msg = a.snapshot_message()
            b.restore_snapshot(bytes(msg.world), json.loads(msg.node_state))
        assert b.world.save() == before
        return list(b.world.names)
    finally:
        a.destroy_node()
        b.destroy_node()


def test_snapshot_with_a_ros_spring_is_refused() -> None:
    a = make_node()
    a._on_spring(SpringCommand(name="mouse", body="block1", body_point=Point(), target=Point(x=1.0, y=2.0)))
    assert a._springs
    restore_is_refused(a, "springs made over ROS")


def test_snapshot_with_a_spawned_body_is_refused() -> None:
    a = make_node()
    req = Spawn.Request(name="extra", width=0.5, height=0.5, pose=Pose(position=Point(x=0.0, y=4.0)))
    assert a._srv_spawn(req, Spawn.Response()).success
    assert "extra" not in restore_is_refused(a, "spawned")
