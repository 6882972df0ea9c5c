"""Every numeric node parameter at both ends of its range, with the bodies driven at a wall: no body
centre leaves the walls' inner box, every step goes through (time advances by time_step each step, no
command is dropped), and the node stays up. The ranges are what the engine takes (docs/ros_interface.md,
"What the ranges guarantee"; measured by bench/repro/drive_into_wall.py).

The drive: block1/thrust at max_thrust towards the right wall in the world frame with a torque of
max_thrust, every block's right thruster (index 1, pushing +x), and cmd_vel at the largest speed the node
takes (1000 m/s forward, no turn: its angular servo holds the heading against the thrust's torque) on
cmd_vel_body; sent again every 0.1 s of sim time, so it holds at every command_timeout. In process the
bodies start thrown at the wall (THROW), so that the heaviest block1 and the finest time step get there
within the run too. In process, one parameter at its end, the others at their defaults; then two node
processes at corners of several ends, driven over ROS, watched on /clock and bodies/states.
"""
from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
import rclpy
from geometry_msgs.msg import Twist, Vector3, Wrench, WrenchStamped
from libcollide_msgs.msg import ThrusterCommand
from rclpy.parameter import Parameter

import collide
from collide_ros import params
from collide_ros.cdr import join_time
from collide_ros.node import MAX_CMD_SPEED, SimNode
from collide_ros.testing import running_sim

RIGHT = 1                  # the default thrusters' index that pushes +x (collide_ros.teleop)
WALLS = collide.default_scene().walls  # inner faces of the default scene's walls: x, y in [-6, 6]
RESEND = 0.1               # s (sim) between two sends of the drive
THROW = 100.0              # m/s towards the right wall at the start: every block is at most 8.5 m from it
SIM_SECONDS = 1.0          # per case, at most MAX_STEPS steps
MAX_STEPS = 15_000         # at time_step 1e-5: 0.15 s, past the 0.085 s a thrown block needs
NUMERIC = [s for s in params.SPECS if s.lo is not None]
ENDS = [(s.name, v) for s in NUMERIC for v in (s.lo, s.hi)]


def _inside(centres: np.ndarray) -> bool:
    x, y = centres[:, 0], centres[:, 1]
    return bool(np.all((x >= WALLS["xmin"]) & (x <= WALLS["xmax"]) & (y >= WALLS["ymin"]) & (y <= WALLS["ymax"])))


def _thrust(force: float) -> WrenchStamped:
    msg = WrenchStamped(wrench=Wrench(force=Vector3(x=force), torque=Vector3(z=force)))
    msg.header.frame_id = "world"
    return msg


def _right_thrusters(node: SimNode, name: str) -> ThrusterCommand:
    return ThrusterCommand(body=name, firing=[i == RIGHT for i in range(len(node._bodies[name].thrusters))])


def _drive(node: SimNode) -> None:
    """The drive, through the node's own command handlers (what its subscriptions call)."""
    if "block1" in node._thrust_subs:  # max_body_topics 0: block1 has no thrust topic
        node._on_thrust("block1", _thrust(float(node._p["max_thrust"])))
    for name in node._dyn_names:
        node._on_thrusters(_right_thrusters(node, name))
    node._on_cmd_vel(Twist(linear=Vector3(x=MAX_CMD_SPEED)))


@pytest.fixture()
def make_node() -> Iterator[Any]:
    made: list[tuple[Any, SimNode]] = []

    def make(values: dict[str, Any]) -> SimNode:
        ctx = rclpy.Context()
        rclpy.init(context=ctx)
        node = SimNode(context=ctx, cli_args=["--ros-args", "-r", "__ns:=/range_ends"],
                       parameter_overrides=[Parameter(k, value=v) for k, v in values.items()])
        made.append((ctx, node))
        assert all(node._p[k] == v for k, v in values.items())
        return node
    yield make
    for ctx, node in made:
        node.destroy_node()
        rclpy.shutdown(context=ctx)


def _drive_at_the_wall(node: SimNode) -> None:
    """SIM_SECONDS (at most MAX_STEPS steps) of the drive, checked after every step."""
    dt = float(node._p["time_step"])
    steps = min(MAX_STEPS, int(round(SIM_SECONDS / dt)))
    every = max(1, int(round(RESEND / dt)))
    wall = node.world.body("wall_right").id
    touched = False
    for name in node._dyn_names:
        node._bodies[name].set_velocity((THROW, 0.0), 0.0)
    for k in range(steps):
        if k % every == 0:
            _drive(node)
        assert node.step_once(), f"step {k}: {node.last_rejection}"
        assert _inside(node.world.state[node._dyn_rows, :2]), f"step {k}: a body left the box"
        c = node.world.contacts
        touched = touched or bool(np.any((c["body_a"] == wall) | (c["body_b"] == wall)))
    assert touched, "no body reached the right wall: the drive did not press anything against it"
    assert node.rejected == 0, node.last_rejection
    # steps additions of dt: round-off a few ulp of t per step, far below 1e-9 s over 15 000 steps
    assert node.sim_time == pytest.approx(steps * dt, rel=0, abs=1e-9)


@pytest.mark.parametrize("name,value", ENDS, ids=[f"{n}={v:g}" for n, v in ENDS])
def test_a_range_end_with_bodies_driven_at_the_wall(make_node: Any, name: str, value: Any) -> None:
    _drive_at_the_wall(make_node({name: value}))


def _end(name: str, which: int) -> Any:
    spec = params.BY_NAME[name]
    return (spec.lo, spec.hi)[which]


# The ends that bound what the engine is asked to take together: block1's mass against time_step and
# damping (k * time_step / mass) and the largest thrust, with six blocks to be squeezed against the wall.
PHYSICS_CORNERS = [{"green_mass": _end("green_mass", m), "time_step": _end("time_step", t),
                    "damping": _end("damping", d), "max_thrust": _end("max_thrust", 1), "blocks": 6}
                   for m in (0, 1) for t in (0, 1) for d in (0, 1)]


@pytest.mark.parametrize("values", PHYSICS_CORNERS,
                         ids=[",".join(f"{k}={v:g}" for k, v in c.items()) for c in PHYSICS_CORNERS])
def test_corners_of_the_physics_ranges_with_bodies_driven_at_the_wall(make_node: Any, values: dict[str, Any]) -> None:
    _drive_at_the_wall(make_node(values))


# ---------------------------------------------------------------- node processes at corners

CORNERS = {
    # coarse steps, the heaviest block1, strongest damping and servo, six blocks under full gravity
    "coarse": {"time_step": 0.01, "green_mass": 1000.0, "damping": 10.0, "blocks": 6, "gravity": -100.0,
               "elasticity": 0.0, "max_thrust": 1e4, "real_time_factor": 100.0, "command_timeout": 0.0,
               "cmd_vel_linear_gain": 1000.0, "cmd_vel_angular_gain": 1000.0, "cmd_vel_max_accel": 10000.0,
               "cmd_vel_max_angular_accel": 100000.0, "state_qos_depth": 10000},
    # the finest step flat out, the lightest block1 under the largest thrust, everything published every
    # step (elasticity 0 in both: what reaches the wall stays against it, in every contacts message)
    "fine": {"time_step": 1e-5, "green_mass": 0.1, "max_thrust": 1e4, "real_time_factor": 0.0, "elasticity": 0.0,
             "clock_rate": 100000.0, "state_rate": 10000.0, "tf_rate": 10000.0, "marker_rate": 1000.0,
             "state_qos_depth": 1, "max_body_topics": 100000, "command_timeout": 60.0},
}
DRIVE_WALL_SECONDS = 3.0
DRIVE_WALL_LIMIT = 120.0   # s of wall time the drive may take to reach the wall
CLOCK_WAIT = 20.0          # s of wall time for a /clock later than the drive's last to arrive
THRUSTING = ("block1", "block2")  # the default scene's blocks with the four default thrusters


def _wall_touched(sim: Any) -> bool:
    return any("wall_right" in (c.body_a, c.body_b) for _, m in sim.history["contacts"] for c in m.contacts)


@pytest.mark.parametrize("corner", sorted(CORNERS))
def test_a_node_at_range_ends_keeps_its_bodies_in_and_its_clock_running(corner: str) -> None:
    values = CORNERS[corner]
    # doubles with a mantissa dot and an exponent, so that no value is read as an integer
    args = [x for k, v in values.items() for x in ("-p", f"{k}:={v:.6e}" if isinstance(v, float) else f"{k}:={v}")]
    with running_sim(*args) as (sim, proc):
        for topic, typ in (("block1/thrust", WrenchStamped), ("thrusters", ThrusterCommand), ("cmd_vel", Twist)):
            assert sim.wait_subscribed(topic, typ), topic
        clock0 = sim.count["clock"]
        start = time.monotonic()
        # at least DRIVE_WALL_SECONDS, and on until a body touched the right wall: a loaded machine steps
        # the fine corner (1e-5 s, everything published every step) slower than the drive needs to get there
        while True:
            now = time.monotonic()
            if now >= start + DRIVE_WALL_SECONDS and (_wall_touched(sim) or now >= start + DRIVE_WALL_LIMIT):
                break
            sim.publish("block1/thrust", _thrust(float(values["max_thrust"])))
            for name in THRUSTING:
                sim.publish("thrusters", ThrusterCommand(body=name, firing=[i == RIGHT for i in range(4)]))
            sim.publish("cmd_vel", Twist(linear=Vector3(x=MAX_CMD_SPEED)))
            sim.spin(0.1)
        # the sim time at the end of the drive: the latest /clock received so far
        assert sim.count["clock"] - clock0 > 10
        at_end = max(join_time(m.clock) for _, m in sim.history["clock"])
        assert proc.alive(), proc.output()
        states = [m for _, m in sim.history["bodies/states"]]
        assert len(states) > 10
        for m in states:
            centres = np.array([[p.position.x, p.position.y] for p in m.poses])
            assert _inside(centres), f"a body left the box at t={join_time(m.header.stamp):.6f} s"
        # The clock kept running to the end of the drive: a /clock later than the drive's last one follows
        # (the node keeps stepping until the test stops it). Waited for, not looked for in a window of wall
        # time before the end: a loaded test process receives nothing for half a second at times (a full
        # garbage collection over the recorded messages takes 0.3-0.6 s at load 6) while the node steps on.
        # A node that stopped stepping sends no later clock, however long the wait.
        assert sim.wait_for(lambda: join_time(sim.last["clock"].clock) > at_end, CLOCK_WAIT), \
            f"the sim time stood still at {at_end:.6f} s, the end of the drive"
        assert _wall_touched(sim), "no body reached the right wall: the drive did not press anything against it"
        vals = sim.diagnostics()
        assert vals is not None and vals["rejected_commands"] == "0", vals and vals["last_rejection"]
