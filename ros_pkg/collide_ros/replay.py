"""Replay a recorded bag's commands into a fresh sim node and check the poses bit for bit.

    python -m collide_ros.replay BAG [--node-cmd CMD] [--json]

Design (docs/contracts.md, "Command echo for bit-exact replay"): the node republishes every
command it accepts on `applied/<command topic>` with header.stamp = the sim time of the
first step the command acts on, and the recorder stores those echoes. To reproduce the run,
this tool starts a fresh node with `start_paused:=true` and the parameters the recorder
stored in the bag (custom_data "collide_ros.params"), then for each echoed command in order:
advance the node with `~/step` to step round(stamp / time_step), publish the command on its
topic, and wait for the fresh node's own echo with the same stamp (so the command is in the
node before the next step is requested). After the last command it steps to the last
recorded state and compares every recorded `bodies/states` message with the replayed one of
the same stamp: names, poses and twists must be equal bit for bit (float64 bit patterns).
The command watchdog runs on sim time, so it reproduces by itself.
Limits: the recording must start before the first command (the fresh node replays from
t = 0), and parameter changes, resets, spawns and kills during the recording are not replayed.
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .cdr import join_time
from .recorder import PARAMS_KEY

APPLIED = "applied/"
#: parameters never passed to the fresh node
SKIP_PARAMS = frozenset({"use_sim_time", "start_paused"})


@dataclass
class Command:
    stamp: int        # ns of sim time: the first step it acts on starts here
    topic: str        # command topic relative to the node's namespace, e.g. "thrusters"
    msgtype: str      # type of the echo (TwistStamped for cmd_vel)
    raw: bytes        # CDR of the echo


@dataclass
class States:
    stamp: int
    names: list[str]
    values: np.ndarray  # (n, 13): px py pz qx qy qz qw vx vy vz wx wy wz


def _split_ns(topic: str, rel: str) -> str | None:
    """Namespace of absolute `topic` if it ends with relative name `rel` ('' for root)."""
    if topic == "/" + rel:
        return ""
    if topic.endswith("/" + rel):
        return topic[: -len(rel) - 1]
    return None


def states_from_msg(msg: Any) -> States:
    vals = np.array([[p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y,
                      p.orientation.z, p.orientation.w, t.linear.x, t.linear.y, t.linear.z,
                      t.angular.x, t.angular.y, t.angular.z]
                     for p, t in zip(msg.poses, msg.twists)], dtype=np.float64).reshape(-1, 13)
    st = msg.header.stamp
    return States(stamp=int(st.sec) * 1_000_000_000 + int(st.nanosec), names=list(msg.names),
                  values=vals)


def bag_params(bag: str | Path) -> dict[str, Any]:
    """The node parameters the recorder stored in the bag's metadata (custom_data)."""
    import yaml

    meta = yaml.safe_load((Path(bag) / "metadata.yaml").read_text())
    custom = (meta.get("rosbag2_bagfile_information", {}).get("custom_data") or {})
    return json.loads(custom[PARAMS_KEY]) if PARAMS_KEY in custom else {}


def read_recording(bag: str | Path) -> tuple[list[Command], list[States], dict[str, Any], str]:
    """(commands in apply order, recorded states, node parameters, namespace) of a bag."""
    from rosbags.rosbag2 import Reader

    from .recorder import make_typestore

    store = make_typestore()
    cmds: list[tuple[int, int, Command]] = []
    states: list[States] = []
    ns = None
    with Reader(Path(bag)) as r:
        params = bag_params(bag)
        seq = 0
        for conn, _ts, raw in r.messages():
            t = conn.topic
            k = t.find("/" + APPLIED)
            if k >= 0:
                ns_c, rel = t[:k], t[k + 1 + len(APPLIED):]
                msg = store.deserialize_cdr(raw, conn.msgtype)
                st = msg.header.stamp
                stamp = int(st.sec) * 1_000_000_000 + int(st.nanosec)
                cmds.append((stamp, seq, Command(stamp, rel, conn.msgtype, bytes(raw))))
                seq += 1
                ns = ns_c if ns is None else ns
            elif _split_ns(t, "bodies/states") is not None:
                states.append(states_from_msg(store.deserialize_cdr(raw, conn.msgtype)))
                ns = _split_ns(t, "bodies/states") if ns is None else ns
    cmds.sort(key=lambda c: (c[0], c[1]))  # stable: same-stamp commands keep arrival order
    states.sort(key=lambda s: s.stamp)
    return [c for _, _, c in cmds], states, params, ns or ""


def params_file(params: dict[str, Any], path: Path) -> Path:
    import yaml

    keep = {k: v for k, v in params.items() if k not in SKIP_PARAMS and not k.startswith("qos_overrides")}
    keep["start_paused"] = True
    path.write_text(yaml.safe_dump({"/**": {"ros__parameters": keep}}))
    return path


def compare(recorded: list[States], replayed: dict[int, States]) -> dict[str, Any]:
    """Bitwise comparison of every recorded state with the replayed state of the same stamp."""
    compared = identical = missing = 0
    max_diff = 0.0
    first_bad: int | None = None
    for s in recorded:
        r = replayed.get(s.stamp)
        if r is None:
            missing += 1
            continue
        compared += 1
        same = (r.names == s.names and r.values.shape == s.values.shape
                and np.array_equal(r.values.view(np.uint64), s.values.view(np.uint64)))
        if same:
            identical += 1
        else:
            if r.values.shape == s.values.shape:
                max_diff = max(max_diff, float(np.max(np.abs(r.values - s.values))))
            else:
                max_diff = float("inf")
            if first_bad is None:
                first_bad = s.stamp
    return {"recorded": len(recorded), "compared": compared, "identical": identical,
            "missing": missing, "max_abs_diff": max_diff,
            "first_mismatch_s": None if first_bad is None else first_bad * 1e-9,
            "ok": compared > 0 and identical == compared and missing == 0}


class Replayer:
    """In-process ROS side: publishers for the commands, echo and state subscriptions, ~/step."""

    def __init__(self, node_name: str = "sim", cmd_vel_stamped: bool = False,
                 time_step: float = 0.001) -> None:
        import rclpy
        from libcollide_msgs.msg import BodyStates
        from libcollide_msgs.srv import Step
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

        self.rclpy = rclpy
        self.node = rclpy.create_node("replay")
        self.qos_cmd = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.qos_in = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
        self.cmd_vel_stamped = cmd_vel_stamped
        self.pubs: dict[str, Any] = {}
        self.echo_subs: dict[str, Any] = {}
        self.echoes: list[tuple[str, int]] = []
        self.states: dict[int, States] = {}
        self.node.create_subscription(BodyStates, "bodies/states", self._on_states, self.qos_in, raw=True)
        self._states_cls = BodyStates
        self.step_cli = self.node.create_client(Step, f"{node_name}/step")
        self._step_cls = Step
        self.steps = 0
        self.sim_time = 0.0
        self.time_step = time_step

    def _on_states(self, raw: bytes) -> None:
        from rclpy.serialization import deserialize_message

        s = states_from_msg(deserialize_message(raw, self._states_cls))
        self.states[s.stamp] = s

    def _msgcls(self, msgtype: str) -> Any:
        from .recorder import msg_class
        return msg_class(msgtype)

    def prepare(self, cmds: list[Command]) -> None:
        """Create one publisher and one echo subscription per command topic."""
        for c in cmds:
            if c.topic in self.pubs:
                continue
            if c.topic == "cmd_vel" and not self.cmd_vel_stamped:
                from geometry_msgs.msg import Twist
                cls = Twist
            else:
                cls = self._msgcls(c.msgtype)
            self.pubs[c.topic] = (self.node.create_publisher(cls, c.topic, self.qos_cmd), cls)

            def on_echo(raw: bytes, topic: str = c.topic, ecls: Any = self._msgcls(c.msgtype)) -> None:
                from rclpy.serialization import deserialize_message
                st = deserialize_message(raw, ecls).header.stamp
                self.echoes.append((topic, int(st.sec) * 1_000_000_000 + int(st.nanosec)))

            self.echo_subs[c.topic] = self.node.create_subscription(
                self._msgcls(c.msgtype), APPLIED + c.topic, on_echo, self.qos_in, raw=True)

    def wait_ready(self, timeout: float) -> bool:
        """Wait until the fresh node's step service, command subscriptions and publishers match."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            ok = self.step_cli.service_is_ready()
            ok = ok and all(p.get_subscription_count() > 0 for p, _ in self.pubs.values())
            ok = ok and all(self.node.count_publishers(s.topic_name) > 0 for s in self.echo_subs.values())
            ok = ok and self.node.count_publishers("bodies/states") > 0
            if ok:
                return True
            self.rclpy.spin_once(self.node, timeout_sec=0.05)
        return False

    def spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.rclpy.spin_once(self.node, timeout_sec=0.01)

    def _call_step(self, k: int, timeout: float) -> Any:
        """One ~/step call; None when no answer came within `timeout` s."""
        req = self._step_cls.Request()
        req.steps = k
        fut = self.step_cli.call_async(req)
        self.rclpy.spin_until_future_complete(self.node, fut, timeout_sec=timeout)
        return fut.result() if fut.done() else None

    def handshake(self, timeout: float, attempt: float = 2.0) -> Any:
        """Call ~/step with 0 steps until an answer comes back; returns it (None on timeout).

        `service_is_ready()` shows only that requests reach the node. The answer travels on a
        second DDS topic whose two ends match on their own schedule, and an answer sent before
        they have matched is dropped (rmw_fastrtps waits 100 ms, then gives up; a loaded CI
        machine lost the first ~/step answer of a replay that way). A zero-step call changes
        nothing, so it can be repeated until one answer proves the way back."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            res = self._call_step(0, min(attempt, max(end - time.monotonic(), 0.01)))
            if res is not None:
                return res
        return None

    def step(self, n: int, chunk: int = 50, timeout: float = 30.0) -> None:
        """Advance the paused node by n steps (in chunks, draining states in between)."""
        while n > 0:
            k = min(n, chunk)
            res = self._call_step(k, timeout)
            if res is None:
                # the answer may be lost rather than late: ask where the node is, via zero-step
                # calls, before deciding whether these k steps happened
                probe = self.handshake(timeout)
                if probe is None:
                    raise RuntimeError(f"~/step {k} failed: timeout, and the node answers no zero-step call")
                t = join_time(probe.sim_time)
                moved = round((t - self.sim_time) / self.time_step)
                if moved == 0:
                    continue  # the request was lost: send it again
                if moved != k:
                    raise RuntimeError(f"~/step {k}: the answer was lost and the node moved {moved} steps")
                res = probe
            elif not res.success:
                raise RuntimeError(f"~/step {k} failed: {res.message}")
            self.sim_time = join_time(res.sim_time)
            self.steps += k
            n -= k
            self.rclpy.spin_once(self.node, timeout_sec=0.0)

    def send(self, c: Command, timeout: float = 10.0, check_stamp: bool = True) -> None:
        """Publish a command and wait for the node's echo with the same stamp."""
        from rclpy.serialization import deserialize_message

        pub, cls = self.pubs[c.topic]
        if c.topic == "cmd_vel" and not self.cmd_vel_stamped:
            pub.publish(deserialize_message(c.raw, self._msgcls(c.msgtype)).twist)
        else:
            pub.publish(c.raw)
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for i, (topic, stamp) in enumerate(self.echoes):
                if topic == c.topic:
                    del self.echoes[i]
                    if check_stamp and stamp != c.stamp:
                        raise RuntimeError(
                            f"{c.topic}: fresh node applied the command at {stamp * 1e-9:.9f} s, "
                            f"recorded {c.stamp * 1e-9:.9f} s")
                    return
            self.rclpy.spin_once(self.node, timeout_sec=0.01)
        raise RuntimeError(f"no echo on {APPLIED}{c.topic} within {timeout} s (does the node echo "
                           "accepted commands? docs/contracts.md)")

    def close(self) -> None:
        self.node.destroy_node()


#: command line that starts a sim node (it echoes accepted commands: SimNode.ECHOES_COMMANDS)
NODE_CMD = [sys.executable, "-m", "collide_ros.node"]


def replay(bag: str | Path, node_cmd: list[str] | None = None, env: dict[str, str] | None = None,
           log: Any = None, delay_command: int | None = None) -> dict[str, Any]:
    """Run the whole replay; returns the comparison summary. rclpy must be initialised.

    `delay_command` (for tests): apply that command (index in apply order) one step late, to
    show that the comparison notices a one-step difference."""
    cmds, recorded, params, _ns = read_recording(bag)
    if not recorded:
        raise ValueError(f"{bag}: no bodies/states messages")
    if not params:
        raise ValueError(f"{bag}: no node parameters in custom_data[{PARAMS_KEY!r}] "
                         "(record with --params-of sim)")
    dt = float(params.get("time_step", 0.001))
    node_cmd = node_cmd or NODE_CMD
    env = dict(os.environ if env is None else env)
    with tempfile.TemporaryDirectory() as tmp:
        pf = params_file(params, Path(tmp) / "params.yaml")
        proc = subprocess.Popen(node_cmd + ["--ros-args", "--params-file", str(pf)], env=env,
                                stdout=log or subprocess.DEVNULL, stderr=subprocess.STDOUT)
        rep = Replayer(cmd_vel_stamped=bool(params.get("cmd_vel_stamped", False)), time_step=dt)
        try:
            rep.prepare(cmds)
            if not rep.wait_ready(60.0):
                raise RuntimeError("fresh node did not come up (step service / topics)")
            first = rep.handshake(60.0)
            if first is None:
                raise RuntimeError("fresh node's ~/step never answered a zero-step call")
            rep.sim_time = join_time(first.sim_time)
            for i, c in enumerate(cmds):
                k = round(c.stamp * 1e-9 / dt) + (1 if i == delay_command else 0)
                if k < rep.steps:
                    raise RuntimeError(f"command at step {k} but the node is already at {rep.steps}")
                rep.step(k - rep.steps)
                rep.send(c, check_stamp=i != delay_command)
            last = round(recorded[-1].stamp * 1e-9 / dt)
            if last > rep.steps:
                rep.step(last - rep.steps)
            # collect the states still in flight
            end = time.monotonic() + 10.0
            while time.monotonic() < end and recorded[-1].stamp not in rep.states:
                rep.spin_for(0.05)
            rep.spin_for(0.2)
            out = compare(recorded, rep.states)
            out.update(commands=len(cmds), steps=rep.steps, time_step=dt,
                       replayed_states=len(rep.states))
            return out
        finally:
            rep.close()
            proc.send_signal(signal.SIGINT)  # the node's clean shutdown path
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def main(argv: list[str] | None = None) -> int:
    import rclpy

    argv = list(sys.argv[1:] if argv is None else argv)
    p = argparse.ArgumentParser(prog="python -m collide_ros.replay", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bag")
    p.add_argument("--node-cmd", default=None, help="command that starts the node (default: "
                   "python -m collide_ros.node)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    a = p.parse_args(argv)
    rclpy.init(args=[])
    try:
        res = replay(a.bag, shlex.split(a.node_cmd) if a.node_cmd else None)
    except (RuntimeError, ValueError, FileNotFoundError) as exc:
        print(f"replay: {exc}", file=sys.stderr)
        return 2
    finally:
        rclpy.try_shutdown()
    if a.json:
        print(json.dumps(res))
    else:
        print(f"replay: {res['commands']} commands over {res['steps']} steps of {res['time_step']} s; "
              f"{res['identical']}/{res['compared']} recorded states bit-identical "
              f"({res['missing']} missing, max |diff| {res['max_abs_diff']:.3g})")
        print("replay: OK, poses reproduced bit for bit" if res["ok"] else "replay: MISMATCH")
    return 0 if res["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
