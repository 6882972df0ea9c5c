"""Replay from the recorded state: the README's pair (recorder with its defaults, then replay) reproduces
every recorded state bit for bit; a bag recorded after the node ran 20 s of sim time is replayed from the
snapshot at its start, stepping only the recorded span; SIGTERM ends a replay with its verdict."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable

import pytest
import rclpy
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from rosgraph_msgs.msg import Clock

from collide_ros.cdr import split_time
from collide_ros.demo import Proc
from collide_ros.node import SimNode
from collide_ros.recorder import SNAPSHOT_TYPE, make_typestore, msgdef_and_hash
from collide_ros.replay import _Capture, replay, verdict

STATES_TYPE = "libcollide_msgs/msg/BodyStates"

GIVE_UP = 120.0  # s: guards against a hang only
LONG_RUN = 20.0  # s of sim time the node runs before the recording starts


def _record(tmp: Path, node_args: list[str], sim_seconds: float, wait_sim: float = 0.0) -> Path:
    """Start a node, wait until its /clock reads `wait_sim` s, set it to real time (a recorder keeps up with
    a node at real time, not with one flat out: what it has not taken when stopped is not in the bag),
    start the recorder with its defaults, and once it says it is recording let the sim run `sim_seconds` s
    of sim time; stop both, return the bag. Every wait is on a condition (a clock value, a parameter's
    answer, a line of the recorder), GIVE_UP only ends a hang."""
    bag = tmp / "bag"
    node = Proc([sys.executable, "-m", "collide_ros.node", "--ros-args", *node_args], tmp / "node.log")
    watcher = rclpy.create_node("replay_test_clock")
    seen = {"t": -1.0}
    watcher.create_subscription(Clock, "/clock", lambda m: seen.update(t=m.clock.sec + 1e-9 * m.clock.nanosec),
                                QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT,
                                           durability=DurabilityPolicy.VOLATILE))
    rec: Proc | None = None
    end = time.monotonic() + GIVE_UP

    def wait(cond: Callable[[], bool], what: str) -> None:
        while not cond():
            assert node.proc.poll() is None, f"node exited: {node.lines}"
            assert rec is None or rec.proc.poll() is None, f"recorder exited: {rec.lines}"
            assert time.monotonic() < end, f"gave up waiting for {what}: {rec.lines if rec else node.lines}"
            rclpy.spin_once(watcher, timeout_sec=0.05)
    try:
        wait(lambda: seen["t"] >= wait_sim, f"sim time {wait_sim} s")
        params = AsyncParameterClient(watcher, "sim")
        while True:  # a lost answer is asked again: setting the same value twice changes nothing
            fut = params.set_parameters([Parameter("real_time_factor", value=1.0)])
            rclpy.spin_until_future_complete(watcher, fut, timeout_sec=5.0)
            if fut.done() and fut.result() is not None:
                assert all(r.successful for r in fut.result().results), fut.result()
                break
            assert node.proc.poll() is None and time.monotonic() < end, f"no answer to set_parameters: {node.lines}"
        rec = Proc([sys.executable, "-m", "collide_ros.recorder", "--out", str(bag)], tmp / "recorder.log")
        wait(lambda: any(ln.startswith("recorder: recording") for ln in rec.lines), "the recorder's 'recording'")
        assert any(ln.startswith("recorder: state saved on /sim/snapshot") for ln in rec.lines), rec.lines
        t_rec = seen["t"]
        wait(lambda: seen["t"] >= t_rec + sim_seconds, f"{sim_seconds} s of sim time recorded")
        assert rec.stop(timeout=GIVE_UP) == 0, rec.lines
        counts = _counts(rec.lines)
        # state_rate's default 100 Hz of sim time gives 100 states a recorded second, more from the 'recording'
        # line to the clock message read after it; at least half of them: a loaded recorder may not have
        # taken the last ones when stopped (the replay compares every one it has)
        assert counts["/bodies/states"] >= 50 * sim_seconds and counts["/sim/snapshot"] >= 2, rec.lines
    finally:
        if rec is not None:
            rec.stop(timeout=GIVE_UP)
        watcher.destroy_node()
        node.stop()
    return bag


def _counts(lines: list[str]) -> dict[str, int]:
    """The recorder's closing message counts per topic."""
    out: dict[str, int] = {}
    for ln in lines[next(i for i, ln in enumerate(lines) if ln.startswith("recorder: wrote")) + 1:]:
        topic, n = ln.split()
        out[topic] = int(n)
    return out


@pytest.fixture(scope="module")
def long_bag(tmp_path_factory: pytest.TempPathFactory, ros: None) -> Path:
    # flat out (real_time_factor 0): 20 s of sim time before the recording; recorded at real time
    return _record(tmp_path_factory.mktemp("long"), ["-p", "real_time_factor:=0.0"], 2.0, wait_sim=LONG_RUN)


def test_readme_pair_replays_bit_for_bit(tmp_path: Path, ros: None) -> None:
    bag = _record(tmp_path, [], 2.0)
    r = subprocess.run([sys.executable, "-m", "collide_ros.replay", str(bag), "--json"], capture_output=True,
                       text=True, timeout=GIVE_UP)
    assert r.returncode == 0, r.stdout + r.stderr
    res = json.loads(next(ln for ln in r.stdout.splitlines() if ln.startswith("{")))
    # the ~200 states of ~2 s of sim time (_record checks the count); every one from the snapshot on is
    # byte-identical
    assert res["ok"] and res["identical"] == res["compared"] >= 100 and res["missing"] == 0, res
    assert "replay: OK, reproduced bit for bit" in r.stdout


def test_long_run_replays_only_the_recorded_span(long_bag: Path) -> None:
    res = replay(long_bag)
    assert res["ok"], res
    assert res["start_s"] >= LONG_RUN
    # the work is the recorded span: one step per time step from the snapshot to the last state
    span_steps = round((res["reached_s"] - res["start_s"]) / res["time_step"])
    assert res["steps"] == span_steps and res["identical"] == res["compared"] >= 100 and res["missing"] == 0, res


def test_stop_gives_a_verdict(long_bag: Path) -> None:
    polls = {"n": 0}

    def stop() -> bool:
        polls["n"] += 1
        return polls["n"] > 500
    res = replay(long_bag, stop=stop)
    text, code = verdict(res)
    assert res["stopped"] and not res["ok"] and res["steps"] == 500 and code == 3, res
    assert text.startswith("STOPPED") and res["first_mismatch_s"] is None


def test_sigterm_ends_the_replay_with_a_verdict(long_bag: Path, tmp_path: Path) -> None:
    p = Proc([sys.executable, "-m", "collide_ros.replay", str(long_bag), "--json"], tmp_path / "replay.log")
    end = time.monotonic() + GIVE_UP
    while not any(ln.startswith("replay: starting from") for ln in p.lines):
        assert p.proc.poll() is None and time.monotonic() < end, p.lines
        time.sleep(0.02)
    p.proc.send_signal(signal.SIGTERM)
    rc = p.proc.wait(timeout=GIVE_UP)
    p._t.join(timeout=GIVE_UP)  # the output pump's last lines
    res = json.loads(next(ln for ln in p.lines if ln.startswith("{")))
    assert rc == 3 and res["stopped"] and res["first_mismatch_s"] is None, p.lines
    assert any(ln.startswith("replay: STOPPED by a signal") for ln in p.lines)


def _write_bag(bag: Path, ns: str, snapshot: bytes, states: list[tuple[int, bytes]]) -> None:
    """A bag of the snapshot, then the states, as the recorder writes them (receive order)."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    store = make_typestore()
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conns = {}
        for topic, msgtype in ((f"{ns}/snapshot", SNAPSHOT_TYPE), (f"{ns}/bodies/states", STATES_TYPE)):
            msgdef, rihs = msgdef_and_hash(store, msgtype)
            conns[topic] = w.add_connection(topic, msgtype, msgdef=msgdef, rihs01=rihs)
        w.write(conns[f"{ns}/snapshot"], 1, snapshot)
        for i, (_stamp, raw) in enumerate(states):
            w.write(conns[f"{ns}/bodies/states"], 2 + i, raw)


def test_state_stamped_at_the_snapshot_is_compared(tmp_path: Path, ros: None) -> None:
    """A snapshot taken right after a step that published a state has that state's stamp: the replay
    compares the recorded state with the loaded snapshot's and steps on from there."""
    ns = f"/stamp_{os.getpid()}"
    node = SimNode(namespace=ns, parameter_overrides=[Parameter("start_paused", value=True)])
    cap = _Capture()
    node._pub_states = cap
    states: list[tuple[int, bytes]] = []
    snapshot = b""
    try:
        while len(states) < 10:
            assert node.step_once()
            if cap.count > len(states):
                assert cap.last is not None
                sec, nsec = split_time(node.sim_time)
                states.append((sec * 1_000_000_000 + nsec, cap.last))
                if len(states) == 4:  # the snapshot after the step that published the 4th state
                    snapshot = bytes(serialize_message(node.snapshot_message()))
    finally:
        node.destroy_node()
    _write_bag(tmp_path / "bag", ns, snapshot, states)
    res = replay(tmp_path / "bag")
    # 3 states before the snapshot; the 4th at its stamp, compared without a step; 6 stepped to
    assert res["skipped"] == 3 and res["missing"] == 0, res
    assert res["ok"] and res["compared"] == res["identical"] == 7, res
    assert res["steps"] == round((states[-1][0] - states[3][0]) * 1e-9 / res["time_step"]), res
