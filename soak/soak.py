"""Bounded soak of the sim node at maximum speed while recording.

    source scripts/env.sh && export ROS_DOMAIN_ID=85
    nice python soak/soak.py --duration 3600 --out /tmp/soak1h      # the documented one-hour run
    nice python soak/soak.py --duration 90                          # what tests/python/test_soak.py runs

The node (``python -m collide_ros.node``, unmodified) runs at real_time_factor 0 with 4 blocks,
starting paused. The project's recorder (``python -m collide_ros.recorder``) records the state,
/tf, /clock and command-echo topics. Once the node's writers have matched the recorder's readers on
every one of them (``subscribers/<topic>`` in /diagnostics), the node's message counts are read
from /diagnostics (``published/<topic>``, docs/ros_interface.md) and the sim resumes; a driver
then sends, at random, thrust (WrenchStamped), thruster, cmd_vel, spring and parameter commands,
and calls ~/reset periodically. At the end the sim is paused, the recorder drains, the counts are
read again once they have settled, and the recorder stops. Checked:

* no NaN: every bodies/states message in the bag is finite;
* no tunnelling: every dynamic body's centre in every recorded message is inside the walls' inner
  box [-6, 6]^2, and even within [-5.501, 5.501]^2 (a 1 m x 3 m block's centre cannot come closer
  than its inradius 0.5 m to a wall without overlapping it; 1 mm of numerical slack);
* not stuck: sim time advances in every check window, and bodies move under thrust (the sum of
  |v| over the bodies is non-zero in every window after commands were sent);
* memory flat: the node's RSS (VmRSS) after the warm-up (first ``--warmup`` fraction of the run,
  default 25 %) grows by at most ``--rss-bound-mb`` (default 8 MiB);
* nothing lost: for each recorded topic, messages in the bag == messages the node published
  between the two snapshots; for each command topic, commands sent == commands the node took
  (``received/<topic>``) == accepted (never rejected: all values are in range) == echoes published.
  A physics step that fails also in parts (docs/ros_interface.md) is a rejection, so it fails this
  check; the steps C undid and the node took in halves instead (``split_steps``) are reported.
Exit 0 when every check passed; the result is printed and written to OUT/result.json.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO / "ros_pkg") not in sys.path:
    sys.path.insert(0, str(REPO / "ros_pkg"))
WALL = 6.0            # inner box of the default scene's walls (m)
# A 1 m x 3 m block's centre is at least its inradius 0.5 m from any wall it does not overlap; the
# engine holds contacts at a 1e-7 m gap and locates impacts to 1e-10 s, so a centre more than
# 1 mm beyond 5.5 m means the block sank into a wall (WALL or more: it went through).
INRADIUS = 0.5
PENETRATION_TOL = 1e-3
BLOCKS = 4
NODE_ARGS = ("-p", "real_time_factor:=0.0", "-p", f"blocks:={BLOCKS}", "-p", "start_paused:=true",
             "-p", "command_timeout:=0.5", "-p", "marker_rate:=0.0")


@dataclass
class SoakResult:
    duration_s: float = 0.0
    sim_time_s: float = 0.0
    steps_per_wall_s: float = 0.0
    commands_sent: dict[str, int] = field(default_factory=dict)
    resets: int = 0
    param_sets: int = 0
    published: dict[str, int] = field(default_factory=dict)  # recorded topic -> published (node's count)
    recorded: dict[str, int] = field(default_factory=dict)
    received: dict[str, int] = field(default_factory=dict)   # command topic -> taken by the node
    accepted: dict[str, int] = field(default_factory=dict)   # command topic -> accepted by the node
    states_checked: int = 0
    max_abs_centre: float = 0.0
    non_finite: int = 0
    outside: int = 0
    penetrating: int = 0
    stuck_windows: list[str] = field(default_factory=list)
    rss_mib: list[float] = field(default_factory=list)
    rss_growth_mib: float = 0.0
    rss_bound_mib: float = 8.0
    rejected_commands: int = -1
    rejection_lines: list[str] = field(default_factory=list)  # the node's first distinct 'rejected:' warnings
    split_steps: int = 0  # steps C undid that the node took in halves instead (reported, not a failure)
    failures: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.failures


def _rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)
    env["PYTHONUNBUFFERED"] = "1"
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO / "ros_pkg"), env.get("PYTHONPATH", "")) if p)
    if "ROS_DOMAIN_ID" not in env:
        raise SystemExit("soak: export ROS_DOMAIN_ID first (hand runs: 85-94)")
    return env


#: the node's state the recorder always records: latched at its start, on its ~/save_snapshot call(s), per reset
SNAPSHOT_TOPIC = "/sim/snapshot"


def recorded_topics() -> list[str]:
    return (["/bodies/poses", "/bodies/states", "/energy", "/contacts", "/tf", "/clock",
             "/applied/thrusters", "/applied/spring", "/applied/cmd_vel"]
            + [f"/applied/block{i}/thrust" for i in range(1, BLOCKS + 1)])


def check_bag(bag: Path, res: SoakResult) -> None:
    """Count every message per topic, and check every bodies/states message (finite, inside)."""
    import numpy as np
    from rclpy.serialization import deserialize_message
    from rosbags.rosbag2 import Reader
    from libcollide_msgs.msg import BodyStates

    counts: dict[str, int] = {}
    with Reader(bag) as reader:
        for conn, _ts, raw in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            if conn.topic != "/bodies/states":
                continue
            msg = deserialize_message(bytes(raw), BodyStates)
            xy = np.array([[p.position.x, p.position.y] for p in msg.poses], dtype=float).reshape(-1, 2)
            tw = np.array([[t.linear.x, t.linear.y, t.angular.z] for t in msg.twists], dtype=float)
            res.states_checked += 1
            if not (np.isfinite(xy).all() and np.isfinite(tw).all()):
                res.non_finite += 1
                continue
            m = float(np.abs(xy).max()) if xy.size else 0.0
            res.max_abs_centre = max(res.max_abs_centre, m)
            if m >= WALL:
                res.outside += 1
            elif m > WALL - INRADIUS + PENETRATION_TOL:
                res.penetrating += 1
    res.recorded = counts


class Driver:
    """Random commands within every accepted range, sent from one client node."""

    def __init__(self, client: Any, rng: random.Random) -> None:
        self.c, self.rng = client, rng
        self.sent: dict[str, int] = {}
        self.springs: set[str] = set()  # springs this driver made since the last reset

    def reset(self) -> None:
        self.springs.clear()

    def _count(self, key: str) -> None:
        self.sent[key] = self.sent.get(key, 0) + 1

    def one(self, may_release: bool = True) -> None:
        """One random command; ``may_release`` false near a reset (a release that the node handles
        after the reset would name a spring that is gone, and be rejected)."""
        from geometry_msgs.msg import Point, Twist, Vector3, WrenchStamped
        from libcollide_msgs.msg import SpringCommand, ThrusterCommand
        r = self.rng
        kind = r.choice(("thrust", "thrust", "thrusters", "cmd_vel", "spring"))
        body = f"block{r.randint(1, BLOCKS)}"
        if kind == "thrust":
            m = WrenchStamped()
            m.header.frame_id = r.choice(("", body, "world"))
            m.wrench.force.x, m.wrench.force.y = r.uniform(-20, 20), r.uniform(-20, 20)
            m.wrench.torque.z = r.uniform(-5, 5)
            self.c.publish(f"{body}/thrust", m)
            self._count(f"/applied/{body}/thrust")
        elif kind == "thrusters":
            body = f"block{r.randint(1, 2)}"  # the scene's blocks with (4 default) thrusters
            self.c.publish("thrusters", ThrusterCommand(body=body, firing=[r.random() < 0.5 for _ in range(4)]))
            self._count("/applied/thrusters")
        elif kind == "cmd_vel":
            self.c.publish("cmd_vel", Twist(linear=Vector3(x=r.uniform(-4, 4), y=r.uniform(-4, 4)),
                                            angular=Vector3(z=r.uniform(-3, 3))))
            self._count("/applied/cmd_vel")
        else:
            name = r.choice(("mouse", "s2"))
            release = may_release and name in self.springs and r.random() < 0.2
            cmd = SpringCommand(name=name, body=body,
                                body_point=Point(x=r.uniform(-0.4, 0.4), y=r.uniform(-1.4, 1.4)),
                                target=Point(x=r.uniform(-5, 5), y=r.uniform(-5, 5)),
                                stiffness=r.uniform(0.5, 20.0), damping=r.uniform(0, 2), rest_length=r.uniform(0, 2),
                                release=release)
            if release:
                self.springs.discard(name)
            else:
                self.springs.add(name)
            self.c.publish("spring", cmd)
            self._count("/applied/spring")

    def params(self) -> dict[str, Any]:
        r = self.rng
        return r.choice(({"gravity": r.uniform(-20, 20)}, {"elasticity": r.uniform(0.3, 1.0)},
                         {"damping": r.uniform(0, 1.0)}, {"green_mass": r.uniform(0.2, 5.0)},
                         {"command_timeout": r.uniform(0.1, 2.0)},
                         {"cmd_vel_linear_gain": r.uniform(1, 20)}, {"cmd_vel_max_accel": r.uniform(5, 50)}))


def _wait_recorder_subscribed(client: Any, topics: list[str], timeout: float) -> list[str]:
    """Topics on which the graph shows no subscription of node 'recorder' after ``timeout`` s."""
    end = time.monotonic() + timeout
    missing = list(topics)
    while time.monotonic() < end and missing:
        missing = [t for t in topics
                   if not any(i.node_name == "soak_recorder"
                              for i in client.node.get_subscriptions_info_by_topic(t))]
        client.spin(0.2)
    return missing


def _wait_matched(client: Any, topics: list[str], timeout: float) -> list[str]:
    """Topics whose writer in the node has not matched every subscription the graph shows after
    ``timeout`` s (the node's ``subscribers/<topic>``). The graph lists a subscription before the
    writer has matched it, and what is published before the match does not reach the recorder."""
    end = time.monotonic() + timeout
    missing = list(topics)
    while time.monotonic() < end and missing:
        vals = client.diagnostics(timeout=max(0.1, end - time.monotonic())) or {}
        missing = [t for t in topics
                   if int(vals.get(f"subscribers/{t.lstrip('/')}", "0"))
                   < len(client.node.get_subscriptions_info_by_topic(t))]
    return missing


def _counts(client: Any, when: str) -> dict[str, int]:
    counts = client.settled_counts(timeout=30.0)
    if counts is None:
        raise RuntimeError(f"soak: the node's /diagnostics counts did not settle {when}")
    return counts


def run_soak(duration: float, out: Path, seed: int = 1, state_rate: float = 10.0, command_hz: float = 40.0,
             reset_every: float = 15.0, param_every: float = 2.0, rss_bound_mib: float = 8.0,
             warmup: float = 0.25, log: Any = print) -> SoakResult:
    """Run the soak for ``duration`` wall seconds; the caller owns nothing (rclpy context inside)."""
    import rclpy
    from std_srvs.srv import Empty, SetBool

    from collide_ros.cdr import join_time
    from collide_ros.testing import SimClient, _die_with_parent

    out.mkdir(parents=True, exist_ok=True)
    env = _env()
    res = SoakResult(rss_bound_mib=rss_bound_mib)
    node_log = open(out / "node.log", "wb")
    rec_log = open(out / "recorder.log", "wb")
    bag = out / "bag"
    node = subprocess.Popen([sys.executable, "-m", "collide_ros.node", "--ros-args", *NODE_ARGS, "-p", f"state_rate:={state_rate}",
                             "-p", f"tf_rate:={state_rate}", "-p", f"clock_rate:={state_rate}"],
                            stdout=node_log, stderr=subprocess.STDOUT, env=env, preexec_fn=_die_with_parent)
    rec: subprocess.Popen[bytes] | None = None
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    client = SimClient(context=ctx, watch=("bodies/states", "diagnostics"))
    rng = random.Random(seed)
    drv = Driver(client, rng)
    try:
        if not client.wait_for(lambda: client.call(SetBool, "pause", SetBool.Request(data=True), 30.0)
                               is not None, 60.0):
            raise RuntimeError("soak: node did not come up")
        if bag.exists():
            raise RuntimeError(f"soak: {bag} exists already")
        rec = subprocess.Popen([sys.executable, "-m", "collide_ros.recorder", "--out", str(bag),
                                "--node-name", "soak_recorder", "--params-of", "sim",
                                "--topics", *recorded_topics()],
                               stdout=rec_log, stderr=subprocess.STDOUT, env=env, preexec_fn=_die_with_parent)
        missing = _wait_recorder_subscribed(client, recorded_topics(), 60.0)
        if missing:
            raise RuntimeError(f"soak: recorder did not subscribe to {missing}")
        for t in recorded_topics():  # let this process's publishers for the commands be matched too
            if t.startswith("/applied/"):
                topic = t[len("/applied/"):]
                typ = {"thrusters": "ThrusterCommand", "spring": "SpringCommand", "cmd_vel": "Twist"}.get(topic)
                from geometry_msgs.msg import Twist, WrenchStamped
                from libcollide_msgs.msg import SpringCommand, ThrusterCommand
                cls = {"ThrusterCommand": ThrusterCommand, "SpringCommand": SpringCommand,
                       "Twist": Twist}.get(typ or "", WrenchStamped)
                if not client.wait_subscribed(topic, cls, 30.0):
                    raise RuntimeError(f"soak: node not subscribed to {topic}")
        unmatched = _wait_matched(client, recorded_topics(), 60.0)
        if unmatched:
            raise RuntimeError(f"soak: the node's writers did not match the recorder on {unmatched}")
        before = _counts(client, "before the run")
        if client.call(SetBool, "pause", SetBool.Request(data=False)) is None:
            raise RuntimeError("soak: ~/pause failed")
        t_start = time.monotonic()
        t_end = t_start + duration
        next_cmd, next_param, next_reset = t_start, t_start + param_every, t_start + reset_every
        next_check = t_start + 5.0
        win_t0, win_moving = None, False
        warm = t_start + warmup * duration
        rss_after_warm: list[float] = []
        sim_t0 = None
        while time.monotonic() < t_end:
            now = time.monotonic()
            if now >= next_cmd:
                # No release within 2 s of a reset: the executor may take the reset before spring
                # messages still queued. 2 s of spring commands (~16 at 40 Hz, 1 in 5 a spring)
                # overflow the node's depth-10 queue, so a release that late would first show as lost.
                drv.one(may_release=now < next_reset - 2.0)
                next_cmd += 1.0 / command_hz
            if now >= next_param:
                p = drv.params()
                r = client.set_params(p)
                if not (r and r[0].successful):
                    res.failures.append(f"parameter {p} refused: {r and r[0].reason}")
                res.param_sets += 1
                next_param = now + param_every
            if now >= next_reset:
                if client.call(Empty, "reset") is None:
                    res.failures.append("~/reset did not answer")
                res.resets += 1
                drv.reset()
                next_reset = now + reset_every
            client.spin(0.005)
            st = client.last.get("bodies/states")
            if st is not None:
                t = join_time(st.header.stamp)
                sim_t0 = t if sim_t0 is None else sim_t0
                if any(abs(tw.linear.x) + abs(tw.linear.y) > 0 for tw in st.twists):
                    win_moving = True
            if now >= next_check:
                rss = _rss_mib(node.pid)
                res.rss_mib.append(round(rss, 2))
                if now >= warm:
                    rss_after_warm.append(rss)
                t_now = None if st is None else join_time(st.header.stamp)
                if t_now is None or (win_t0 is not None and t_now <= win_t0):
                    res.stuck_windows.append(f"sim time did not advance by wall {now - t_start:.0f} s")
                if not win_moving:
                    res.stuck_windows.append(f"no body moved in the window ending at wall {now - t_start:.0f} s")
                if node.poll() is not None:
                    raise RuntimeError(f"soak: node exited with {node.returncode}")
                log(f"soak: {now - t_start:6.0f} s  sim {t_now or 0:9.2f} s  RSS {rss:6.1f} MiB  "
                    f"sent {sum(drv.sent.values())}  resets {res.resets}")
                win_t0, win_moving = t_now, False
                next_check = now + 5.0
        if client.call(SetBool, "pause", SetBool.Request(data=True)) is None:
            raise RuntimeError("soak: ~/pause failed at the end")
        res.duration_s = time.monotonic() - t_start
        client.spin(3.0)  # the recorder drains what is in flight
        after = _counts(client, "after the run")
        last = client.fresh("bodies/states", timeout=0.1) or client.last.get("bodies/states")
        if last is not None and sim_t0 is not None:
            res.sim_time_s = join_time(last.header.stamp) - sim_t0
        rec.send_signal(signal.SIGINT)
        rec.wait(60)
        def delta(key: str) -> int:
            return after.get(key, 0) - before.get(key, 0)
        res.published = {t: delta(f"published/{t.lstrip('/')}") for t in recorded_topics()}
        cmd_topics = [t[len("/applied/"):] for t in recorded_topics() if t.startswith("/applied/")]
        res.split_steps = delta("split_steps")
        res.received = {t: delta(f"received/{t}") for t in cmd_topics}
        res.accepted = {t: delta(f"accepted/{t}") for t in cmd_topics}
        res.commands_sent = dict(drv.sent)
        check_bag(bag, res)
        res.rss_growth_mib = (max(rss_after_warm) - rss_after_warm[0]) if len(rss_after_warm) > 1 else 0.0
    finally:
        client.close()
        rclpy.shutdown(context=ctx)
        if rec is not None and rec.poll() is None:
            rec.send_signal(signal.SIGINT)
            try:
                rec.wait(30)
            except subprocess.TimeoutExpired:
                rec.kill()
        if node.poll() is None:
            node.send_signal(signal.SIGINT)
            try:
                node.wait(30)
            except subprocess.TimeoutExpired:
                node.kill()
        node_log.close()
        rec_log.close()
    # ---- verdict ----
    out_text = (out / "node.log").read_text(errors="replace")
    res.rejected_commands = out_text.count("rejected:")
    # the reasons go into the result: CI shows the assertion's text, not the node log in a temp dir
    for line in out_text.splitlines():
        if "rejected:" in line and len(res.rejection_lines) < 12:
            reason = line[line.index("rejected:"):]
            if reason not in res.rejection_lines:
                res.rejection_lines.append(reason)
    if res.rejected_commands:
        res.failures.append(f"node rejected commands ({res.rejected_commands} warnings; see node.log): "
                            + " | ".join(res.rejection_lines))
    if res.non_finite:
        res.failures.append(f"{res.non_finite} bodies/states messages with NaN/inf")
    if res.outside:
        res.failures.append(f"{res.outside} bodies/states messages with a centre outside the walls")
    if res.penetrating:
        res.failures.append(f"{res.penetrating} bodies/states messages with a centre closer than "
                            f"{INRADIUS - PENETRATION_TOL} m to a wall")
    if res.states_checked == 0:
        res.failures.append("no bodies/states in the bag")
    res.failures += res.stuck_windows
    if res.rss_growth_mib > rss_bound_mib:
        res.failures.append(f"node RSS grew {res.rss_growth_mib:.1f} MiB after warm-up (bound {rss_bound_mib})")
    for t in recorded_topics():
        p, r = res.published.get(t, 0), res.recorded.get(t, 0)
        if p != r:
            res.failures.append(f"{t}: published {p}, recorded {r}")
        if t.startswith("/applied/"):
            c = t[len("/applied/"):]
            sent = res.commands_sent.get(t, 0)
            if not sent == res.received.get(c) == res.accepted.get(c) == p:
                res.failures.append(f"{c}: sent {sent}, taken {res.received.get(c)}, "
                                    f"accepted {res.accepted.get(c)}, echoed {p}")
    if res.sim_time_s > 0 and res.duration_s > 0:
        res.steps_per_wall_s = res.sim_time_s / 0.001 / res.duration_s
    (out / "result.json").write_text(json.dumps({**asdict(res), "ok": res.ok}, indent=1))
    return res


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="soak/soak.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--duration", type=float, default=90.0, help="wall seconds (default 90)")
    p.add_argument("--out", type=Path, default=None, help="directory for bag, logs, result.json (default: temp)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--state-rate", type=float, default=10.0, help="state/tf/clock rate, Hz of sim time")
    p.add_argument("--reset-every", type=float, default=15.0, help="wall seconds between ~/reset calls")
    p.add_argument("--rss-bound-mb", type=float, default=8.0)
    p.add_argument("--warmup", type=float, default=0.25, help="fraction of the run before RSS is judged")
    a = p.parse_args(argv)
    out = a.out or Path(tempfile.mkdtemp(prefix="soak_"))
    res = run_soak(a.duration, out, seed=a.seed, state_rate=a.state_rate, reset_every=a.reset_every,
                   rss_bound_mib=a.rss_bound_mb, warmup=a.warmup)
    summary = {k: v for k, v in asdict(res).items() if k != "rss_mib"}
    print(json.dumps(summary, indent=1))
    print(f"soak: {'PASS' if res.ok else 'FAIL'}  ({out})")
    return 0 if res.ok else 1


if __name__ == "__main__":
    sys.exit(main())
