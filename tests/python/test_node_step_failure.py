"""What the node does when C undoes a step (LC_ERR_NUMERIC), in-process (no executor).

C's verdict is deterministic: the same state, forces and dt fail again, so a node that only retried
would stand still until a reset (what a short soak in CI most likely ran into). The node takes such a
step as halves instead (collide_ros.node.SPLIT_DEPTH levels), and only when a part of
time_step / 2**SPLIT_DEPTH fails does it drop the commands and springs made over ROS. The failure
is injected by wrapping the world's step where the node's bookkeeping is checked (time, parts,
counts, commands, the warning); two tests use a real one, a block at ~1e5 m/s and 1e5 rad/s.
(With the soak's legal values it is rare: none in 2.5e8 steps of its command mix, soak/step_search.py;
docs/hardening.md "The node when C undoes a step".)
"""
from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import rclpy
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import Point, Vector3, Wrench, WrenchStamped
from rclpy.parameter import Parameter

from collide import CollideError
from collide_ros import node as node_mod
from collide_ros.node import SimNode
from collide_ros.testing import diag_values
from libcollide_msgs.msg import SpringCommand

DT = 0.001
NUMERIC = 10  # LC_ERR_NUMERIC


class FailingSteps:
    """Stands in for World.step: a step longer than ``longest`` raises what C raises for an undone
    step (state untouched); shorter ones run the real step. Records every dt asked for."""

    def __init__(self, real: Any, longest: float) -> None:
        self.real, self.longest, self.calls = real, longest, []  # type: ignore[var-annotated]

    def __call__(self, dt: float, steps: int = 1) -> None:
        self.calls.append(dt)
        if dt > self.longest:
            raise CollideError(NUMERIC, "injected: contact forces gained energy; the step was undone")
        self.real(dt, steps)


@pytest.fixture()
def sim(request: pytest.FixtureRequest) -> Iterator[SimNode]:
    """An in-process node; ``indirect`` parametrisation overrides its parameters."""
    over = {"blocks": 2, "gravity": 9.8, "time_step": DT, "command_timeout": 0.0, **getattr(request, "param", {})}
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    node = SimNode(context=ctx, cli_args=["--ros-args", "-r", "__ns:=/step_failure_probe"],
                   parameter_overrides=[Parameter(k, value=v) for k, v in over.items()])
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)


def _thrust_and_spring(sim: SimNode) -> None:
    sim._on_thrust("block1", WrenchStamped(wrench=Wrench(force=Vector3(x=2.0))))
    sim._on_spring(SpringCommand(name="mouse", body="block2", body_point=Point(x=0.1, y=0.2),
                                 target=Point(x=1.0, y=2.0), stiffness=5.0))
    assert sim.rejected == 0 and "block1" in sim._thrust and "mouse" in sim._springs


def test_an_undone_step_is_taken_in_halves(sim: SimNode) -> None:
    _thrust_and_spring(sim)
    for _ in range(3):
        assert sim.step_once()
    t0, steps0 = sim.sim_time, sim.steps
    fake = FailingSteps(sim.world.step, longest=DT / 8)
    sim.world.step = fake  # type: ignore[method-assign]
    assert sim.step_once()
    # the full step and the halves of 1/2 and 1/4 fail; the 1/8 parts go through: 8 of them,
    # each taken after its parent failed (depth-first), in time order
    assert fake.calls.count(DT / 8) == 8 and fake.calls[0] == DT
    assert [c for c in fake.calls if c <= DT / 8] == [DT / 8] * 8
    # a step's worth of time (eight additions of dt/8: exact to a few ulp of t), one step counted
    assert sim.sim_time == pytest.approx(t0 + DT, rel=0, abs=1e-15)
    assert sim.steps == steps0 + 1 and sim.split_steps == 1
    # nothing was rejected or dropped: the commands and the spring act on the next steps too
    assert sim.rejected == 0 and "block1" in sim._thrust and "mouse" in sim._springs
    assert sim._warned.get("split") is not None
    sim.world.step = fake.real  # type: ignore[method-assign]
    assert sim.step_once() and sim.split_steps == 1


def test_a_step_that_fails_in_every_part_drops_the_commands_and_keeps_time(sim: SimNode) -> None:
    _thrust_and_spring(sim)
    assert sim.step_once()
    t0, steps0, state0 = sim.sim_time, sim.steps, sim.world.state.copy()
    fake = FailingSteps(sim.world.step, longest=0.0)  # every step fails
    sim.world.step = fake  # type: ignore[method-assign]
    assert not sim.step_once()
    # depth-first down to dt / 2**SPLIT_DEPTH, where the first part fails: 1 + SPLIT_DEPTH attempts
    assert fake.calls == [DT / 2 ** k for k in range(node_mod.SPLIT_DEPTH + 1)]
    assert sim.sim_time == t0 and sim.steps == steps0
    assert (sim.world.state == state0).all()
    assert sim.rejected == 1 and "also in parts of time_step / 64" in sim.last_rejection
    assert "injected" in sim.last_rejection
    assert not sim._thrust and not sim._springs and sim.world.spring_count == 0
    # the state itself fails: the node stands still, and /diagnostics says so at ERROR level
    assert not sim.step_once() and sim.sim_time == t0 and sim.rejected == 2
    status = _diagnostics(sim).status[0]
    assert status.level == DiagnosticStatus.ERROR and f"failing since t={t0:.6f} s" in status.message
    sim.world.step = fake.real  # type: ignore[method-assign]
    assert sim.step_once() and sim.sim_time > t0
    # (WARN, not OK: in-process nothing keeps the real-time factor of 1)
    assert sim.failing_since is None and _diagnostics(sim).status[0].level != DiagnosticStatus.ERROR


def test_a_costly_undone_step_is_not_split(sim: SimNode) -> None:
    # a step undone at C's work caps took seconds; its parts would each cost as much, so the node
    # goes straight to dropping the commands (the verdict comes from the step's counters, here forced)
    _thrust_and_spring(sim)
    assert sim.step_once()
    t0 = sim.sim_time
    fake = FailingSteps(sim.world.step, longest=0.0)
    sim.world.step = fake  # type: ignore[method-assign]
    sim._worth_splitting = lambda: False  # type: ignore[method-assign]
    assert not sim.step_once()
    assert fake.calls == [DT] and sim.sim_time == t0 and sim.split_steps == 0
    assert sim.rejected == 1 and "not split" in sim.last_rejection and not sim._springs


def test_a_normal_step_is_worth_splitting(sim: SimNode) -> None:
    # the real verdict on the default scene's steps: far inside the limits
    for _ in range(50):
        assert sim.step_once()
    c = sim.world.counters(last=True)
    assert c["force_evaluations"] < node_mod.SPLIT_MAX_WORK["force_evaluations"] // 100
    assert sim._worth_splitting()


def _fast_spinner(sim: SimNode) -> None:
    # block1 at ~1e5 m/s and 1e5 rad/s among three blocks under gravity: absurd, but a state the
    # API accepts, in which C undoes its step at t = 1.192 s (the whole-step energy
    # balance: "gained far more energy than its external forces ... can give") and the same step
    # goes through as five parts (1/2, 1/4, ... of the step).
    for _ in range(10):
        assert sim.step_once()
    sim.world.body("block1").set_velocity((1e5, 3e4), 1e5)


@pytest.mark.parametrize("sim", [{"blocks": 4, "gravity": 9.8}], indirect=True)
def test_a_step_c_undoes_goes_through_in_parts(sim: SimNode) -> None:
    _fast_spinner(sim)
    for _ in range(1500):
        assert sim.step_once(), sim.last_rejection
    assert sim.split_steps >= 1, "C undid no step of this scene (engine changed?): find another such state"
    assert sim.rejected == 0 and sim.steps == 1510
    assert sim.sim_time == pytest.approx(1.510, abs=1e-9)


@pytest.mark.parametrize("sim", [{"blocks": 4, "gravity": 9.8}], indirect=True)
def test_without_parts_the_same_step_fails_again_and_again(sim: SimNode) -> None:
    # a node that only retries: the undone step is tried again unchanged, and fails again
    _fast_spinner(sim)
    sim._worth_splitting = lambda: False  # type: ignore[method-assign]
    ok = [sim.step_once() for _ in range(1500)]
    first = ok.index(False)
    assert all(not x for x in ok[first:]), "the state stood still from the first failure on"
    assert sim.sim_time < 1.2


class Capture:
    def __init__(self) -> None:
        self.messages: list[Any] = []

    def publish(self, msg: Any) -> None:
        self.messages.append(msg)


def _diagnostics(sim: SimNode) -> Any:
    """The DiagnosticArray the node would publish now."""
    capture = Capture()
    real, sim._pub_diag = sim._pub_diag, capture  # type: ignore[assignment]
    try:
        sim._publish_diagnostics()
    finally:
        sim._pub_diag = real
    return capture.messages[0]


def test_split_steps_in_diagnostics(sim: SimNode) -> None:
    sim.split_steps = 3
    assert (diag_values(_diagnostics(sim), sim.get_fully_qualified_name()) or {})["split_steps"] == "3"
