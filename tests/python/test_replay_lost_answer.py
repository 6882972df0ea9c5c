"""The replayer's ~/step client when an answer is lost on the way back (a DDS matching race seen
on CI): it must neither step twice nor skip steps. A scripted stand-in node plays the service;
no ROS graph is needed, the logic under test is which requests the client sends."""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from collide_ros.cdr import split_time
from collide_ros.replay import Replayer

DT = 0.001


class ScriptedNode:
    """Serves ~/step like the sim node; drop_answer / drop_request: call indices whose answer / request is lost."""

    def __init__(self, drop_answer: set[int], drop_request: set[int]) -> None:
        self.steps = 0
        self.calls: list[int] = []
        self.served: list[int] = []  # the chunks the node carried out
        self.drop_answer, self.drop_request = drop_answer, drop_request

    def __call__(self, k: int, timeout: float) -> Any:
        i = len(self.calls)
        self.calls.append(k)
        if i in self.drop_request:
            return None
        self.steps += k
        self.served.append(k)
        if i in self.drop_answer:
            return None
        sec, nanosec = split_time(self.steps * DT)
        return SimpleNamespace(success=True, message="", sim_time=SimpleNamespace(sec=sec, nanosec=nanosec))


def _replayer(node: ScriptedNode) -> Replayer:
    rep = Replayer.__new__(Replayer)  # no rclpy node: only the step logic is exercised
    rep.steps, rep.sim_time, rep.time_step = 0, 0.0, DT
    rep.rclpy = SimpleNamespace(spin_once=lambda *a, **k: None)
    rep.node = None
    rep._call_step = node  # type: ignore[method-assign]
    return rep


@pytest.mark.parametrize("drop_answer,drop_request", [
    (set(), set()),
    ({1}, set()),        # second chunk's answer lost: the node did step, do not resend
    (set(), {1}),        # second chunk's request lost: resend it
    ({0, 2}, {4}),       # an answer lost, the probe's answer lost too, then a request lost
])
def test_step_count_is_exact_when_answers_are_lost(drop_answer: set[int], drop_request: set[int]) -> None:
    node = ScriptedNode(drop_answer, drop_request)
    rep = _replayer(node)
    rep.step(260, chunk=50, timeout=0.01)
    assert node.steps == 260 == rep.steps
    assert rep.sim_time == pytest.approx(260 * DT, abs=1e-12)
    assert [k for k in node.served if k] == [50, 50, 50, 50, 50, 10]  # each chunk carried out once


def test_node_that_never_answers_is_an_error() -> None:
    node = ScriptedNode(set(), set())
    node.drop_request = range(10**9)  # type: ignore[assignment]
    rep = _replayer(node)
    with pytest.raises(RuntimeError, match="answers no zero-step call"):
        rep.step(10, timeout=0.05)
