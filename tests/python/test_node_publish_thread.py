"""The stepping loop's publish thread (sim/publish_thread.py) sends what inline publishing sends.

PublishThread on its own: rounds run one at a time in submission order, ``submit`` waits for the
previous round, a round that raises is reported and the next one still runs.

Two in-process nodes on one scene (60 moving, spinning bodies, static bodies in the middle of the row
order; every topic due after every step): one publishes inline, the other steps with ``threaded=True``
(its rounds written and sent by the publish thread from a copy of the state while the test already
takes the next step), with a ``~/reset`` (a direct publish of markers and state) in the middle. The
world is deterministic, so each topic's sequence of messages must be the same bytes in the same order
on both nodes. And the node process with ``publish_thread`` true and false."""
from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import rclpy
import yaml

from collide_ros.node import SimNode
from collide_ros.sim.publish_thread import PublishThread
from collide_ros.testing import running_sim

from test_node_pose_frame import DT, scene

STEPS = 40
RESET_AFTER = 25
TOPICS = ("poses", "states", "tf", "markers", "energy", "contacts", "clock")


def test_rounds_run_in_order_one_at_a_time() -> None:
    errors: list[Exception] = []
    t = PublishThread(errors.append)
    done: list[int] = []
    running = threading.Lock()
    overlaps = 0

    def job(k: int) -> Callable[[], None]:
        def run() -> None:
            nonlocal overlaps
            if not running.acquire(blocking=False):
                overlaps += 1
                return
            time.sleep(0.002)
            done.append(k)
            running.release()
            if k == 3:
                raise RuntimeError("round 3")
        return run
    for k in range(10):
        t.submit(job(k))
    t.wait_idle()
    assert done == list(range(10)) and overlaps == 0
    assert [str(e) for e in errors] == ["round 3"]
    assert t.take_busy_time() >= 10 * 0.002 and t.take_busy_time() == 0.0
    t.stop()
    assert not t._thread.is_alive()


def _node(ctx: Any, path: Path, ns: str) -> SimNode:
    rate = f"{1.0 / DT!r}"
    return SimNode(context=ctx, cli_args=[
        "--ros-args", "-r", f"__ns:=/{ns}", "-p", f"scene_file:={path}", "-p", f"time_step:={DT!r}",
        "-p", f"state_rate:={rate}", "-p", f"tf_rate:={rate}", "-p", f"marker_rate:={rate}",
        "-p", f"clock_rate:={rate}", "-p", "frame_prefix:=robot/"])


def _record(node: SimNode) -> list[tuple[str, bytes]]:
    log: list[tuple[str, bytes]] = []
    pubs = {"poses": node._pub_poses, "states": node._pub_states, "tf": node._pub_tf, "markers": node._pub_markers,
            "energy": node._pub_energy, "contacts": node._pub_contacts, "clock": node._pub_clock}
    for topic, pub in pubs.items():
        def keep(msg: Any, topic: str = topic, publish: Callable[[Any], None] = pub.pub.publish) -> None:
            assert isinstance(msg, bytes), topic
            log.append((topic, msg))
            publish(msg)
        pub.pub.publish = keep
    return log


def _run(node: SimNode, threaded: bool) -> None:
    for k in range(STEPS):
        assert node.step_once(threaded=threaded), node.last_rejection
        if k + 1 == RESET_AFTER:
            node.reset()


@pytest.mark.parametrize("repeat", range(2))
def test_threaded_rounds_equal_inline_rounds(tmp_path: Path, repeat: int) -> None:
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene(static_in_middle=True)))
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    inline, threaded = _node(ctx, path, "inline"), _node(ctx, path, "threaded")
    try:
        want, got = _record(inline), _record(threaded)
        _run(inline, threaded=False)
        threaded._start_publish_thread()
        assert threaded._publish_thread is not None
        _run(threaded, threaded=True)
        threaded._stop_publish_thread()
        assert threaded._publish_thread is None
    finally:
        inline.destroy_node()
        threaded.destroy_node()
        rclpy.shutdown(context=ctx)
    for topic in TOPICS:
        a = [m for t, m in want if t == topic]
        b = [m for t, m in got if t == topic]
        assert len(a) == len(b) > STEPS - 1, topic
        bad = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
        assert not bad, f"{topic}: messages {bad[:5]} differ"
    # the order across topics too: the reset's markers (DELETEALL) and state follow the pending round
    assert [t for t, _ in want] == [t for t, _ in got]


@pytest.mark.parametrize("on", ["true", "false"])
def test_node_process_either_way(on: str) -> None:
    """The node process with the publish thread and without: states arrive with advancing stamps, the
    diagnostics report the thread's time only with it, and the node exits cleanly (running_sim)."""
    with running_sim("-p", "blocks:=3", "-p", f"publish_thread:={on}") as (client, _):
        first = client.sim_time()
        assert first is not None
        assert client.wait_for(lambda: (client.sim_time(1.0) or 0.0) > first + 0.2, 30.0)
        values = client.diagnostics(timeout=15.0)
        assert values is not None
        assert (float(values["publish_thread_time_mean_ms"]) > 0.0) == (on == "true")
        assert float(values["publish_time_mean_ms"]) > 0.0
