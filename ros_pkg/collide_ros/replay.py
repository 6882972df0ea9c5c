"""Replay a recorded bag from the sim's state at its start and check the states bit for bit.

    python -m collide_ros.replay BAG [--json]

The node publishes its state on ``~/snapshot`` (libcollide_msgs/WorldSnapshot: the world's snapshot,
the sim time, the parameters, the step count, the commands in force) when it starts, after each reset
and when the recorder starts recording (it calls ``~/save_snapshot``), and the recorder always records
it. The node also republishes every command it accepts on ``applied/<topic>``, stamped with the sim
time of the first step it acts on (docs/contracts.md), and the recorder records those echoes.

The replay builds a sim node in this process (paused, never spinning, its topics in a private
namespace, no /clock or /tf), loads the bag's latest snapshot into it and steps it from there: before
each step it hands the node the echoed commands stamped with that step's start, through the node's
own subscription callbacks; after each step it compares the node's ``bodies/states`` message with
the recorded one of the same stamp, CDR byte for byte. Only the recorded span is stepped, the bag is
read as a stream (two readers, a bounded look-ahead for the commands), and SIGINT or SIGTERM ends
the replay after the current step with a verdict saying how far it got.

Verdict and exit status: 0 every recorded state from the snapshot on reproduced bit for bit; 1 a
mismatch (the first one's sim time and size are printed) or a step that failed; 2 the bag cannot be
replayed (no snapshot, no states, a snapshot with springs made over ROS or spawned bodies); 3 stopped by a signal
before the end, with no mismatch up to there.
Limits: the states before the bag's latest snapshot (e.g. before a reset during the recording) are
not checked; parameter changes, spawns and kills during the recording are not replayed.
"""
from __future__ import annotations

import argparse
import heapq
import json
import os
import signal
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .recorder import PARAMS_KEY, SNAPSHOT_TYPE

APPLIED = "applied/"
#: parameters the replay node does not take from the snapshot (it sets them itself)
SKIP_PARAMS = frozenset({"use_sim_time", "start_paused", "publish_clock", "tf_rate"})
#: commands read ahead of the one applied next: the recorder receives the echo topics on separate
#: subscriptions, so same-step commands of different topics can arrive in either order
LOOKAHEAD = 256
#: command line that starts a sim node (tools that run one: the demo)
NODE_CMD = [sys.executable, "-m", "collide_ros.node"]


@dataclass
class Snapshot:
    stamp: int               # ns of sim time
    state: dict[str, Any]    # node_state JSON: params, steps, time_offset, commands in force
    world: bytes


@dataclass
class Command:
    stamp: int        # ns of sim time: the first step it acts on starts here
    topic: str        # command topic relative to the node's namespace, e.g. "thrusters"
    msgtype: str      # type of the echo (TwistStamped for cmd_vel)
    raw: bytes        # CDR of the echo


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _split_ns(topic: str, rel: str) -> str | None:
    """Namespace of absolute `topic` if it ends with relative name `rel` ('' for root)."""
    if topic == "/" + rel:
        return ""
    if topic.endswith("/" + rel):
        return topic[: -len(rel) - 1]
    return None


def bag_params(bag: str | Path) -> dict[str, Any]:
    """The node parameters the recorder stored in the bag's metadata (custom_data, --params-of)."""
    import yaml

    meta = yaml.safe_load((Path(bag) / "metadata.yaml").read_text())
    custom = (meta.get("rosbag2_bagfile_information", {}).get("custom_data") or {})
    return json.loads(custom[PARAMS_KEY]) if PARAMS_KEY in custom else {}


def start_snapshot(bag: str | Path, store: Any) -> Snapshot | None:
    """The bag's snapshot of the latest sim time (the state the replay starts from), or None."""
    from rosbags.rosbag2 import Reader

    best: Snapshot | None = None
    with Reader(Path(bag)) as r:
        conns = [c for c in r.connections if c.msgtype == SNAPSHOT_TYPE]
        if not conns:
            return None
        for conn, _ts, raw in r.messages(connections=conns):
            msg = store.deserialize_cdr(raw, conn.msgtype)
            stamp = _ns(msg.stamp)
            if best is None or stamp >= best.stamp:
                best = Snapshot(stamp, json.loads(msg.node_state), bytes(msg.world))
    return best


def iter_states(bag: str | Path, store: Any) -> Iterator[tuple[int, bytes]]:
    """(stamp, CDR) of every recorded bodies/states message, in bag order."""
    from rosbags.rosbag2 import Reader

    with Reader(Path(bag)) as r:
        conns = [c for c in r.connections if _split_ns(c.topic, "bodies/states") is not None]
        if not conns:
            return  # Reader.messages(connections=[]) would yield every message of the bag
        for conn, _ts, raw in r.messages(connections=conns):
            yield _ns(store.deserialize_cdr(raw, conn.msgtype).header.stamp), bytes(raw)


def iter_commands(bag: str | Path, store: Any) -> Iterator[Command]:
    """The echoed commands in apply order (stamp, then arrival), read ahead by LOOKAHEAD messages."""
    from rosbags.rosbag2 import Reader

    heap: list[tuple[int, int, Command]] = []
    with Reader(Path(bag)) as r:
        conns = [c for c in r.connections if c.topic.find("/" + APPLIED) >= 0]
        if not conns:
            return  # no command echoes recorded; messages(connections=[]) would yield them all
        for seq, (conn, _ts, raw) in enumerate(r.messages(connections=conns)):
            t = conn.topic
            rel = t[t.find("/" + APPLIED) + 1 + len(APPLIED):]
            stamp = _ns(store.deserialize_cdr(raw, conn.msgtype).header.stamp)
            heapq.heappush(heap, (stamp, seq, Command(stamp, rel, conn.msgtype, bytes(raw))))
            if len(heap) > LOOKAHEAD:
                yield heapq.heappop(heap)[2]
    while heap:
        yield heapq.heappop(heap)[2]


def states_values(store: Any, raw: bytes) -> tuple[list[str], np.ndarray]:
    """Names and (n, 13) pose and twist doubles of a bodies/states CDR message."""
    msg = store.deserialize_cdr(raw, "libcollide_msgs/msg/BodyStates")
    vals = np.array([[p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y,
                      p.orientation.z, p.orientation.w, t.linear.x, t.linear.y, t.linear.z,
                      t.angular.x, t.angular.y, t.angular.z]
                     for p, t in zip(msg.poses, msg.twists)], dtype=np.float64).reshape(-1, 13)
    return list(msg.names), vals


class _Capture:
    """Stands in for the replay node's bodies/states publisher: keeps the last message, sends nothing."""

    def __init__(self) -> None:
        self.count = 0
        self.last: bytes | None = None

    def publish(self, msg: Any) -> None:
        self.last = bytes(msg)
        self.count += 1


def _make_node(snap: Snapshot) -> Any:
    from rclpy.parameter import Parameter

    from .node import SimNode

    params = {k: v for k, v in snap.state["params"].items()
              if k not in SKIP_PARAMS and not k.startswith("qos_overrides")}
    overrides = [Parameter(k, value=v) for k, v in params.items()]
    overrides += [Parameter("start_paused", value=True), Parameter("publish_clock", value=False),
                  Parameter("tf_rate", value=0.0)]
    # a namespace of its own: nothing of the replay reaches a live sim's topics or theirs the replay
    node = SimNode(namespace=f"/collide_replay_{os.getpid()}", parameter_overrides=overrides)
    try:
        node.restore_snapshot(snap.world, snap.state)
    except Exception:
        node.destroy_node()
        raise
    return node


def _deliver(node: Any, c: Command, subs: dict[str, Any], cmd_vel_stamped: bool) -> None:
    """Hand an echoed command to the node's own subscription callback (as if it had arrived)."""
    from rclpy.serialization import deserialize_message

    from .recorder import msg_class

    sub = subs.get(c.topic)
    if sub is None:
        want = node.resolve_topic_name(c.topic)
        sub = next((s for s in node.subscriptions if s.topic_name == want), None)
        if sub is None:
            raise ValueError(f"the replay node has no subscription {c.topic}")
        subs[c.topic] = sub
    msg = deserialize_message(c.raw, msg_class(c.msgtype))
    if c.topic == "cmd_vel" and not cmd_vel_stamped:
        msg = msg.twist
    sub.callback(msg, {})


def replay(bag: str | Path, delay_command: int | None = None,
           stop: Callable[[], bool] = lambda: False,
           on_start: Callable[[Snapshot], None] | None = None) -> dict[str, Any]:
    """Replay the bag's recorded span; returns the verdict. rclpy must be initialised.

    `stop` is polled before each step (a signal's flag); `on_start` is called once the node holds
    the snapshot. `delay_command` (for tests): apply that
    command (index in apply order) one step late, to show that the comparison notices it."""
    from .cdr import split_time
    from .recorder import make_typestore

    store = make_typestore()
    snap = start_snapshot(bag, store)
    if snap is None:
        raise ValueError(f"{bag}: no {SNAPSHOT_TYPE} message (the node's ~/snapshot); record with "
                         "collide_ros.recorder from a node that publishes it")
    node = _make_node(snap)
    try:
        if on_start is not None:
            on_start(snap)
        cap = _Capture()
        node._pub_states = cap
        # the state at the snapshot itself: a recorded state of the snapshot's stamp (published by the
        # step the snapshot was taken after) is compared with it, not stepped to
        node._publish_state()
        dt = float(node._p["time_step"])
        stamped = bool(node._p["cmd_vel_stamped"])
        rejected0 = node.rejected

        def now() -> int:
            sec, ns = split_time(node.sim_time)
            return sec * 1_000_000_000 + ns

        out: dict[str, Any] = {"start_s": snap.stamp * 1e-9, "time_step": dt, "recorded": 0, "compared": 0,
                               "identical": 0, "missing": 0, "skipped": 0, "commands": 0, "steps": 0,
                               "first_mismatch_s": None, "first_mismatch_size": None, "max_abs_diff": 0.0,
                               "stopped": False, "failed_step_s": None}
        cmds = iter_commands(bag, store)
        pending = next(cmds, None)
        subs: dict[str, Any] = {}
        index = 0
        cur = now()
        for stamp, raw in iter_states(bag, store):
            out["recorded"] += 1
            if stamp < snap.stamp:
                out["skipped"] += 1  # before the state the replay starts from
                continue
            while cur < stamp and not out["stopped"] and out["failed_step_s"] is None:
                while pending is not None and (pending.stamp < cur if index == delay_command
                                               else pending.stamp <= cur):
                    if pending.stamp >= snap.stamp:  # older ones are in the snapshot's commands in force
                        _deliver(node, pending, subs, stamped)
                        out["commands"] += 1
                        index += 1
                    pending = next(cmds, None)
                if stop():
                    out["stopped"] = True
                    break
                if not node.step_once():
                    out["failed_step_s"] = node.sim_time
                    break
                out["steps"] += 1
                cur = now()
            if out["stopped"] or out["failed_step_s"] is not None:
                break
            mine = cap.last
            if cur != stamp or mine is None:
                out["missing"] += 1
                continue
            out["compared"] += 1
            if mine == raw:
                out["identical"] += 1
                continue
            rn, rv = states_values(store, raw)
            mn, mv = states_values(store, mine)
            diff = float(np.max(np.abs(rv - mv))) if rn == mn and rv.shape == mv.shape else float("inf")
            out["max_abs_diff"] = max(out["max_abs_diff"], diff)
            if out["first_mismatch_s"] is None:
                out["first_mismatch_s"], out["first_mismatch_size"] = stamp * 1e-9, diff
        if out["recorded"] == 0:
            raise ValueError(f"{bag}: no bodies/states messages")
        out["reached_s"] = node.sim_time
        out["rejected"] = node.rejected - rejected0
        out["ok"] = (out["compared"] > 0 and out["identical"] == out["compared"] and out["missing"] == 0
                     and not out["stopped"] and out["failed_step_s"] is None)
        return out
    finally:
        node.destroy_node()


def verdict(res: dict[str, Any]) -> tuple[str, int]:
    """The one-line verdict and the exit status (module docstring)."""
    span = (f"from {res['start_s']:.3f} s to {res['reached_s']:.3f} s of sim time, {res['steps']} steps of "
            f"{res['time_step']} s, {res['commands']} commands; {res['identical']}/{res['compared']} recorded "
            f"states bit-identical ({res['missing']} missing, {res['skipped']} before the snapshot)")
    if res["first_mismatch_s"] is not None:
        return (f"MISMATCH {span}; first at {res['first_mismatch_s']:.9f} s, max |diff| "
                f"{res['first_mismatch_size']:.3g} there, {res['max_abs_diff']:.3g} overall"), 1
    if res["failed_step_s"] is not None:
        return f"FAILED: the step at {res['failed_step_s']:.9f} s failed; {span}", 1
    if res["stopped"]:
        return f"STOPPED by a signal, no mismatch up to there; {span}", 3
    if res["ok"]:
        return f"OK, reproduced bit for bit {span}", 0
    return f"MISMATCH {span}", 1


def main(argv: list[str] | None = None) -> int:
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from collide import CollideError

    argv = list(sys.argv[1:] if argv is None else argv)
    p = argparse.ArgumentParser(prog="python -m collide_ros.replay", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bag")
    p.add_argument("--json", action="store_true", help="print the verdict's numbers as JSON too")
    a = p.parse_args(argv)
    flag = {"stop": False}

    def on_signal(signum: int, frame: Any) -> None:
        flag["stop"] = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    rclpy.init(args=[], signal_handler_options=SignalHandlerOptions.NO)
    try:
        res = replay(a.bag, stop=lambda: flag["stop"], on_start=lambda s: print(
            f"replay: starting from the snapshot at {s.stamp * 1e-9:.3f} s of sim time", flush=True))
    except (ValueError, FileNotFoundError, CollideError) as exc:
        print(f"replay: {exc}", file=sys.stderr)
        return 2
    finally:
        rclpy.try_shutdown()
    text, code = verdict(res)
    if a.json:
        print(json.dumps(res))
    print(f"replay: {text}", flush=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
