"""Teleop across processes against the real sim node: keys -> ThrusterCommand -> the body moves;
and a teleop_twist_keyboard-style Twist stream on cmd_vel drives block1."""
from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable, Iterator

import pytest
import rclpy
from geometry_msgs.msg import Twist
from libcollide_msgs.msg import BodyStates
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_srvs.srv import Empty

from collide_ros.cdr import join_time
from collide_ros.demo import Proc

GIVE_UP = 60.0  # s: only guards against a hung test; never a pass/fail criterion


class Watch:
    """Test-side node in its own context: last body states, the reset service, publishers."""

    def __init__(self, proc: Proc) -> None:
        self.proc = proc
        self.ctx = rclpy.Context()
        rclpy.init(context=self.ctx)
        self.node = rclpy.create_node("teleop_test", context=self.ctx)
        self.ex = SingleThreadedExecutor(context=self.ctx)
        self.ex.add_node(self.node)
        self.last: dict[str, tuple[float, float, float, float, float, float]] = {}
        self.stamp = -1.0
        self.node.create_subscription(BodyStates, "bodies/states", self._on, 10)
        self.reset_cli = self.node.create_client(Empty, "sim/reset")

    def _on(self, m: BodyStates) -> None:
        self.stamp = join_time(m.header.stamp)
        for n, p, t in zip(m.names, m.poses, m.twists):
            yaw = 2.0 * math.atan2(p.orientation.z, p.orientation.w)
            self.last[n] = (p.position.x, p.position.y, yaw, t.linear.x, t.linear.y, t.angular.z)

    def spin_until(self, cond: Callable[[], bool], what: str) -> None:
        end = time.monotonic() + GIVE_UP
        while not cond():
            assert self.proc.proc.poll() is None, \
                f"the node exited while waiting for {what}: " + "\n".join(self.proc.lines[-15:])
            assert time.monotonic() < end, f"gave up waiting for {what}"
            self.ex.spin_once(timeout_sec=0.02)

    def spin_sim(self, seconds: float) -> None:
        """Spin until the node's sim time advanced by `seconds`."""
        t0 = self.stamp
        self.spin_until(lambda: self.stamp >= t0 + seconds, f"{seconds} s of sim time")

    def reset(self) -> None:
        self.spin_until(self.reset_cli.service_is_ready, "sim/reset")
        fut = self.reset_cli.call_async(Empty.Request())
        self.spin_until(fut.done, "reset reply")
        self.spin_sim(0.05)

    def close(self) -> None:
        self.ex.shutdown()
        self.node.destroy_node()
        rclpy.shutdown(context=self.ctx)


@pytest.fixture(scope="module")
def sim(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Watch]:
    log = tmp_path_factory.mktemp("teleop") / "node.log"
    node = Proc([sys.executable, "-m", "collide_ros.node", "--ros-args", "-p", "command_timeout:=0.5"],
                Path(log))
    w = Watch(node)
    try:
        w.spin_until(lambda: "block1" in w.last and "block2" in w.last, "the node's first states")
        yield w
    finally:
        w.close()
        node.stop()


def test_keys_drive_blocks(sim: Watch) -> None:
    sim.reset()
    b1, b2 = sim.last["block1"], sim.last["block2"]
    # the default scene starts at rest: every velocity is exactly 0
    assert b1[3:] == (0.0, 0.0, 0.0) and b2[3:] == (0.0, 0.0, 0.0)
    out = subprocess.run([sys.executable, "-m", "collide_ros.teleop", "--keys", "f" * 8 + "[up]" * 8,
                          "--interval", "0.05"], capture_output=True, text=True, timeout=GIVE_UP)
    assert out.returncode == 0, out.stderr
    assert "S,J,Left" in out.stdout  # prints its key map
    sent = int(out.stdout.strip().split("sent ")[-1].split()[0])
    assert sent >= 4  # held keys are republished at 20 Hz, plus one release per block
    sim.spin_sim(0.3)
    a1, a2 = sim.last["block1"], sim.last["block2"]
    # F = block1's right thruster: block1 gains +x velocity and moves right. A pure thrust of
    # 1.5 N on 1 kg over >= 0.35 s gives ~0.5 m/s; 0.05 m/s is far above zero and far below that.
    assert a1[3] > 0.05 and a1[0] > b1[0]
    # Up arrow = block2's up thruster: block2 moves up
    assert a2[4] > 0.05 and a2[1] > b2[1]
    # released (all-off sent, watchdog 0.5 s): no force acts any more, so with no damping or
    # gravity and nothing hit the velocities stay constant (bitwise up to RK4 round-off, 1e-12)
    v1 = sim.last["block1"][3:]
    sim.spin_sim(0.3)
    v2 = sim.last["block1"][3:]
    assert all(abs(p - q) < 1e-12 for p, q in zip(v1, v2))


def test_twist_on_cmd_vel_drives_block1(sim: Watch) -> None:
    sim.reset()
    pub = sim.node.create_publisher(Twist, "cmd_vel",
                                    QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    sim.spin_until(lambda: pub.get_subscription_count() > 0, "the node's cmd_vel subscription")
    # like teleop_twist_keyboard with 'i' held: one Twist per autorepeated key press (~30 Hz)
    msg = Twist()
    msg.linear.x = 0.5
    t_start = sim.stamp
    while sim.stamp < t_start + 1.5:
        pub.publish(msg)
        end = time.monotonic() + 1 / 30
        while time.monotonic() < end:
            sim.ex.spin_once(timeout_sec=0.005)
    x, y, yaw, vx, vy, wz = sim.last["block1"]
    # servo v' = gain*(v_cmd - v) with gain 5/s: after >= 1.4 s the error is < 0.5*e^-7 = 5e-4
    # (plus one 10 ms state period of lag); 0.01 m/s leaves room for wall-clock jitter
    assert abs(vx - 0.5) < 0.01 and abs(vy) < 1e-6 and abs(wz) < 1e-6
    assert x > sim.last["block2"][0] - 5.0 + 0.3  # moved right from x = -2.5
    # key released: after command_timeout (0.5 s sim) the servo lets go; the block coasts at its
    # last velocity (no force), so vx stays where the servo left it
    sim.spin_sim(0.8)
    va = sim.last["block1"][3]
    sim.spin_sim(0.3)
    assert abs(sim.last["block1"][3] - va) < 1e-12 and abs(va - 0.5) < 0.01
