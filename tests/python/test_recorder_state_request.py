"""The recorder's request for the node's state at the start of a recording (recorder.StateRequest), without
a ROS graph: a stand-in recorder and node play the graph and the ~/save_snapshot service, which never
answers. The state counts as saved only from a snapshot that followed a call and shows the node's writers
had matched every subscription the graph lists; the latched snapshot from before the call and a snapshot
taken before the writers matched do not count, and the recorder calls again; so it does when a request is
lost (no snapshot follows it)."""
from __future__ import annotations

import json
from types import SimpleNamespace
from typing import Any

from libcollide_msgs.msg import WorldSnapshot
from rclpy.serialization import serialize_message

from collide_ros.recorder import SAVE_SERVICE, StateRequest

STATES, ECHO = "/bodies/states", "/applied/thrusters"


class FakeNode:
    """The graph: subscriptions per topic (this recorder's included); a save service that never answers."""

    def __init__(self) -> None:
        self.graph_subs = {STATES: 2, ECHO: 1}
        self.calls = 0
        self.client_name = ""
        self.warnings: list[str] = []

    def create_client(self, _srv: Any, name: str) -> Any:
        self.client_name = name

        def call_async(_req: Any) -> None:
            self.calls += 1  # the answer is lost: nothing comes back
        return SimpleNamespace(service_is_ready=lambda: True, call_async=call_async)

    def create_timer(self, _period: float, _cb: Any) -> Any:
        return object()

    def destroy_timer(self, _timer: Any) -> None:
        pass

    def get_subscriptions_info_by_topic(self, topic: str) -> list[Any]:
        return [object()] * self.graph_subs.get(topic, 0)

    def get_logger(self) -> Any:
        return SimpleNamespace(warning=self.warnings.append)


def snapshot(matched: dict[str, int]) -> bytes:
    return bytes(serialize_message(WorldSnapshot(node_state=json.dumps({"matched_readers": matched}))))


def make() -> tuple[StateRequest, FakeNode, dict[str, bool]]:
    node = FakeNode()
    ours = {STATES: True, ECHO: True}  # this recorder's readers matched (Recorder.matched)
    rec = SimpleNamespace(node=node, closed=False, wants=lambda t: True, matched=lambda t: ours[t])
    return StateRequest(rec, "/sim/snapshot"), node, ours  # type: ignore[arg-type]


def test_saved_only_from_a_snapshot_after_a_call_with_every_writer_matched() -> None:
    req, node, _ = make()
    assert node.client_name == f"/sim/{SAVE_SERVICE}"
    req.poll()
    assert node.calls == 0  # nothing is known of the node before its latched snapshot
    assert not req.on_message(snapshot({STATES: 2, ECHO: 1}))  # the latched one: from before any call
    assert req.needed == [ECHO, STATES]
    req.poll()
    req.poll()  # one call out at a time
    assert node.calls == 1 and not req.done
    # the echo writer had not matched the recorder's reader yet: not the start, call again
    assert not req.on_message(snapshot({STATES: 2, ECHO: 0}))
    assert req.unmatched == [ECHO] and not req.done
    req.poll()
    assert node.calls == 2
    assert req.on_message(snapshot({STATES: 2, ECHO: 1})) and req.done  # no answer needed
    req.poll()
    assert node.calls == 2 and not req.on_message(snapshot({STATES: 2, ECHO: 1}))  # saved once


def test_no_call_before_the_recorders_readers_have_matched() -> None:
    req, node, ours = make()
    ours[ECHO] = False
    req.on_message(snapshot({STATES: 2, ECHO: 1}))
    req.poll()
    assert node.calls == 0
    ours[ECHO] = True
    req.poll()
    assert node.calls == 1


def test_a_subscription_the_writer_has_not_matched_holds_the_start() -> None:
    # another subscriber the node has not matched yet counts too: the graph shows it, the writer not
    req, node, _ = make()
    req.on_message(snapshot({STATES: 1, ECHO: 1}))
    req.poll()
    assert not req.on_message(snapshot({STATES: 1, ECHO: 1})) and req.unmatched == [STATES]
    node.graph_subs[STATES] = 1  # the other subscriber left
    req.poll()
    assert req.on_message(snapshot({STATES: 1, ECHO: 1}))


def test_a_lost_request_is_sent_again() -> None:
    req, node, _ = make()
    req.on_message(snapshot({STATES: 2, ECHO: 1}))
    req.poll()
    assert node.calls == 1
    for _ in range(StateRequest.RESEND_POLLS - 1):
        req.poll()
    assert node.calls == 1  # waiting for the snapshot the call asked for
    req.poll()
    assert node.calls == 2  # none came: the request was lost, ask again
    assert req.on_message(snapshot({STATES: 2, ECHO: 1})) and req.done
