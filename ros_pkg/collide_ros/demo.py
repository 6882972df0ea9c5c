"""The main job: node + recorder + a scripted driver over ROS topics, then a GIF and a summary.

    python -m collide_ros.demo [--out out] [--duration 10] [--no-gif] [--replay]

1. starts the sim node on the embedded default scene (2 blocks, no gravity, e = 1, no
   damping) in a subprocess, in its own ROS_DOMAIN_ID (a free one is locked unless you
   exported one) with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST;
2. starts the recorder (subprocess) writing out/demo_bag (rosbag2, MCAP, metadata v9);
3. drives the node from this process over ROS topics with a scripted thrust + spring
   sequence timed in sim time (~10 s): ThrusterCommand on `thrusters` (myPhysicsLab's F, I, E, S
   keys), a world-frame push on `block1/thrust`, a mouse spring dragged on `spring`, a
   torque on `block2/thrust`, Twists on `cmd_vel` (block2, as teleop_twist_keyboard sends
   them), then a free coast with no forces;
4. stops both, renders out/demo.gif from the bag and prints a summary: collisions,
   energy drift over the force-free coast, real-time factor, where the bag and GIF are.
With --replay it also replays the bag from the node's state at its start and checks the states bit for bit.
While the node runs, the live view (python -m collide_ros.view) serves the sim on
http://127.0.0.1:8080/ (or a free port when 8080 is taken); its URL is printed (--no-view: not started).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import ros_domain
from .cdr import join_time
from .teleop import LEFT, RIGHT, UP

ROOT = Path(__file__).resolve().parents[2]

# what the recorder records: everything the node publishes, the commands and their echoes
NODE_TOPICS = ["bodies/poses", "bodies/states", "contacts", "energy", "/clock", "/tf", "markers",
               "/diagnostics"]
COMMAND_TOPICS = ["thrusters", "spring", "block1/thrust", "block2/thrust", "cmd_vel"]
ECHO_TOPICS = ["applied/" + t for t in COMMAND_TOPICS]
#: the demo's node parameters (everything else at the node's defaults)
NODE_PARAMS = {"clock_rate": 100.0, "state_rate": 100.0, "cmd_vel_body": "block2"}


# ------------------------------------------------------------------ the script

@dataclass
class Cue:
    """What the driver wants at one sim-time instant (s since the script started)."""

    firing: dict[str, list[bool]] = field(default_factory=dict)
    spring: tuple[float, float] | None = None      # target of the mouse spring on block1
    torque: float = 0.0                             # on block2 (N*m), via block2/thrust
    push: float = 0.0                               # +x world-frame force on block1 (N), block1/thrust
    twist: tuple[float, float] | None = None        # cmd_vel (linear.x m/s, angular.z rad/s) for block2


SPRING_BODY = "block1"
SPRING_POINT = (0.5, 1.5)    # body frame, about the centre of mass: the top-right corner
SPRING_K = 3.0               # N/m, myPhysicsLab's mouse spring
COAST_FROM = 7.0             # s: no force acts from here on (energy must stay constant)


def cue(s: float, anchor: tuple[float, float] = (-2.0, 1.5)) -> Cue:
    """The scripted sequence as a pure function of script time s (sim seconds); `anchor` is
    where the spring's body point was when the drag started (the mouse grabs it there)."""
    b1 = [False] * 4
    b2 = [False] * 4
    if 0.0 <= s < 1.5:
        b1[RIGHT] = True          # F: block1's right thruster (off-centre: it also turns it)
    if 0.0 <= s < 1.2:
        c_push = 1.5              # plus a world-frame push: block1 heads for block2 and hits it
    else:
        c_push = 0.0
    if 0.5 <= s < 1.5:
        b2[UP] = True             # I: block2 moves up, so the hit is off-centre
    if 6.0 <= s < 7.0:
        b1[UP] = b1[LEFT] = True  # E + S (cmd_vel's watchdog, 1 s, lets go of block2 at ~7 s)
    c = Cue(firing={"block1": b1, "block2": b2}, push=c_push)
    if 3.0 <= s < 6.0:
        u = math.sin(math.pi * (s - 3.0) / 3.0)   # drag the mouse out and back
        c.spring = (anchor[0] - 3.0 * u, anchor[1] + 2.0 * u)
    if 4.0 <= s < 5.0:
        c.torque = 0.3
    if 5.0 <= s < 6.0:
        c.twist = (-1.0, 1.5)     # teleop_twist_keyboard style: block2 backs up turning left

    return c


class Driver:
    """The separate process's ROS side: publishes the cues, watches /clock."""

    def __init__(self) -> None:
        import rclpy
        from geometry_msgs.msg import WrenchStamped
        from libcollide_msgs.msg import SpringCommand, ThrusterCommand
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock

        self.rclpy = rclpy
        self.node = rclpy.create_node("demo_driver")
        q = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.pub_thr = self.node.create_publisher(ThrusterCommand, "thrusters", q)
        self.pub_spring = self.node.create_publisher(SpringCommand, "spring", q)
        self.pub_wrench = self.node.create_publisher(WrenchStamped, "block2/thrust", q)
        self.pub_push = self.node.create_publisher(WrenchStamped, "block1/thrust", q)
        from geometry_msgs.msg import Twist
        self.pub_twist = self.node.create_publisher(Twist, "cmd_vel", q)
        self.Twist = Twist
        self.T, self.S, self.W = ThrusterCommand, SpringCommand, WrenchStamped
        self.sim_time = -1.0
        self.node.create_subscription(Clock, "/clock", self._on_clock,
                                      QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
        from libcollide_msgs.msg import BodyStates
        self.poses: dict[str, tuple[float, float, float]] = {}
        self.node.create_subscription(BodyStates, "bodies/states", self._on_states,
                                      QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
        self.prev = Cue()
        self.sent = 0

    def _on_clock(self, m: Any) -> None:
        self.sim_time = join_time(m.clock)

    def _on_states(self, m: Any) -> None:
        for n, p in zip(m.names, m.poses):
            self.poses[n] = (p.position.x, p.position.y,
                             2.0 * math.atan2(p.orientation.z, p.orientation.w))

    def body_point(self, body: str, point: tuple[float, float]) -> tuple[float, float]:
        """World position of a body-frame point (about the centre of mass), from the last state."""
        x, y, a = self.poses.get(body, (0.0, 0.0, 0.0))
        c, s = math.cos(a), math.sin(a)
        return (x + c * point[0] - s * point[1], y + s * point[0] + c * point[1])

    def spin(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while True:
            self.rclpy.spin_once(self.node, timeout_sec=max(0.0, min(0.01, end - time.monotonic())))
            if time.monotonic() >= end:
                return

    def matched(self, n: int) -> bool:
        pubs = (self.pub_thr, self.pub_spring, self.pub_wrench, self.pub_push, self.pub_twist)
        return all(p.get_subscription_count() >= n for p in pubs) and self.sim_time >= 0

    def _stamp(self, h: Any) -> None:
        h.stamp = self.node.get_clock().now().to_msg()

    def send(self, c: Cue) -> None:
        for body, fire in c.firing.items():
            # while firing: every tick (feeds the node's watchdog); once all-off on release
            if any(fire) or any(self.prev.firing.get(body, [False])):
                m = self.T(body=body, firing=fire)
                self._stamp(m.header)
                self.pub_thr.publish(m)
                self.sent += 1
        if c.spring is not None:
            m = self.S(name="mouse", body=SPRING_BODY, stiffness=SPRING_K)
            m.body_point.x, m.body_point.y = SPRING_POINT
            m.target.x, m.target.y = c.spring
            self._stamp(m.header)
            self.pub_spring.publish(m)
            self.sent += 1
        elif self.prev.spring is not None:
            m = self.S(name="mouse", release=True)
            self._stamp(m.header)
            self.pub_spring.publish(m)
            self.sent += 1
        if c.torque != 0.0 or self.prev.torque != 0.0:
            m = self.W()
            m.wrench.torque.z = c.torque
            self._stamp(m.header)
            self.pub_wrench.publish(m)
            self.sent += 1
        if c.push != 0.0 or self.prev.push != 0.0:
            m = self.W()
            m.header.frame_id = "world"  # the node's world_frame: force in world axes
            m.wrench.force.x = c.push
            self._stamp(m.header)
            self.pub_push.publish(m)
            self.sent += 1
        if c.twist is not None:  # one Twist per tick while "the key is held"; nothing after
            tw = self.Twist()
            tw.linear.x, tw.angular.z = c.twist
            self.pub_twist.publish(tw)
            self.sent += 1
        self.prev = c

    def close(self) -> None:
        self.node.destroy_node()


# ------------------------------------------------------------------ processes

class Proc:
    """A child process whose output goes to a log file (and is scanned for lines)."""

    def __init__(self, cmd: list[str], log: Path) -> None:
        self.log_path = log
        self.lines: list[str] = []
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, bufsize=1, env=dict(os.environ))
        self._t = threading.Thread(target=self._pump, daemon=True)
        self._t.start()

    def _pump(self) -> None:
        assert self.proc.stdout is not None
        with self.log_path.open("w") as f:
            for line in self.proc.stdout:
                f.write(line)
                f.flush()
                self.lines.append(line.rstrip("\n"))

    def stop(self, timeout: float = 20.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._t.join(timeout=5)
        return int(self.proc.returncode)


def start_view(out: Path, port: int = 8080, wait: float = 30.0) -> tuple[Proc | None, str | None]:
    """The live view next to the demo's node: (process, URL), or (None, None) if it did not come up
    (the demo goes on without it). A taken ``port`` falls back to a free one."""
    for p in (port, 0):
        view = Proc([sys.executable, "-m", "collide_ros.view", "--port", str(p)], out / "demo_view.log")
        end = time.monotonic() + wait
        while time.monotonic() < end and view.proc.poll() is None:
            for ln in list(view.lines):
                if ln.startswith("view: open "):
                    return view, ln.split()[-1]
            time.sleep(0.05)
        view.stop()
    return None, None


def node_cmd() -> list[str]:
    from .replay import NODE_CMD
    return list(NODE_CMD)


# ------------------------------------------------------------------ summary from the bag

def summarize(msgs: dict[str, list[tuple[int, Any]]], t0: float, coast_from: float,
              params: dict[str, Any] | None = None) -> dict[str, Any]:
    from .render import _topic

    def stamp(m: Any) -> float:
        return join_time(m.header.stamp)

    states = _topic(msgs, "bodies/states")
    energy = _topic(msgs, "energy")
    contacts = _topic(msgs, "contacts")
    diags = _topic(msgs, "/diagnostics") or msgs.get("/diagnostics", [])
    out: dict[str, Any] = {}
    params = params or {}
    # real-time factor: sim time over wall time between the first and last recorded state
    if len(states) >= 2:
        (w0, m0), (w1, m1) = states[0], states[-1]
        out["sim_seconds"] = stamp(m1) - stamp(m0)
        out["wall_seconds"] = (w1 - w0) * 1e-9
        out["real_time_factor"] = out["sim_seconds"] / max(out["wall_seconds"], 1e-9)
    # energy over the coast (no thrust, no spring; e = 1, no damping: must stay constant). The
    # coast starts when the node applied the last command (its echo's stamp), else a margin after
    # the script's COAST_FROM
    echoed = [stamp(m) for name, lst in msgs.items() if "/applied/" in name for _, m in lst]
    # a cmd_vel command holds its servo force until the watchdog (command_timeout) drops it
    timeout = float(params.get("command_timeout", 1.0))
    echoed += [stamp(m) + timeout for name, lst in msgs.items() if name.endswith("/applied/cmd_vel")
               for _, m in lst]
    start = max(echoed) if echoed else t0 + coast_from + 0.25
    coast = [(stamp(m), m.total) for _, m in energy if stamp(m) > start]
    if coast:
        e0 = coast[0][1]
        vals = [e for _, e in coast]
        out["coast_energy_J"] = e0
        out["coast_seconds"] = coast[-1][0] - coast[0][0]
        out["energy_drift_rel"] = (max(vals) - min(vals)) / abs(e0) if e0 else 0.0
    # collisions: the node's cumulative counter if its diagnostics carry one, else the distinct
    # collision contacts seen in the published snapshots
    coll_diag = None
    for _, d in diags:
        for st in d.status:
            for kv in st.values:
                if kv.key in ("collisions", "collisions_total"):
                    coll_diag = int(float(kv.value))
    seen = 0
    impact_contacts = 0
    for _, cm in contacts:
        n = sum(1 for c in cm.contacts if c.kind == 0)
        impact_contacts += n
        seen += 1 if n else 0
    out["impact_contacts"] = impact_contacts
    out["collisions"] = coll_diag
    from .render import impacts
    # impacts visible in the recorded states as velocity kinks (one per state interval, so a
    # block-block impact that kinks both bodies counts once)
    out["impacts_in_states"] = len({k for k, _ in impacts([m for _, m in states])})
    out["collision_snapshots"] = seen
    out["max_contacts"] = max((len(cm.contacts) for _, cm in contacts), default=0)
    rtfs = [float(kv.value) for _, d in diags for st in d.status for kv in st.values
            if kv.key == "real_time_factor"]
    if rtfs:
        out["diag_real_time_factor_median"] = sorted(rtfs)[len(rtfs) // 2]
    return out


# ------------------------------------------------------------------ main

def run(out: Path, duration: float, gif: bool, do_replay: bool, view: bool = True) -> int:
    import rclpy

    from .render import read_bag, render_bag

    out.mkdir(parents=True, exist_ok=True)
    bag = out / "demo_bag"
    if bag.exists():
        if not (bag / "metadata.yaml").exists() and any(bag.iterdir()):
            print(f"demo: {bag} exists and is not a bag; not touching it", file=sys.stderr)
            return 2
        shutil.rmtree(bag)
    gif_path = out / "demo.gif"
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.pop("ROS_LOCALHOST_ONLY", None)
    lock = ros_domain.lock_unless_set()
    print(f"demo: ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']}, discovery LOCALHOST; logs in {out}/",
          flush=True)

    args = ["--ros-args"] + [x for k, v in NODE_PARAMS.items() for x in ("-p", f"{k}:={v}")]
    node = Proc(node_cmd() + args, out / "demo_node.log")
    rclpy.init(args=[])
    drv = Driver()
    rec: Proc | None = None
    viewer: Proc | None = None
    wall0 = time.monotonic()
    try:
        # node up: its command subscriptions match our publishers and /clock ticks
        end = time.monotonic() + 60
        while not drv.matched(1):
            if time.monotonic() > end or node.proc.poll() is not None:
                raise RuntimeError(f"node did not come up; see {node.log_path}")
            drv.spin(0.05)
        print(f"demo: node up (sim time {drv.sim_time:.2f} s)", flush=True)
        if view:
            viewer, url = start_view(out)
            if url:
                print(f"demo: live view: open {url} in a browser while the demo runs "
                      "(mouse: spring; keys S,D,F,E / J,K,L,I: thrusters)", flush=True)
            else:
                print(f"demo: the live view did not start; see {out / 'demo_view.log'}", flush=True)
        topics = NODE_TOPICS + COMMAND_TOPICS + ECHO_TOPICS
        rec = Proc([sys.executable, "-m", "collide_ros.recorder", "--out", str(bag), "--params-of",
                    "sim", "--topics", *topics], out / "demo_recorder.log")
        end = time.monotonic() + 60
        while True:
            # every listed topic that has a publisher (ours included; no one publishes cmd_vel)
            wanted = {("/" + t).replace("//", "/") for t in topics if drv.node.count_publishers(t) > 0}
            got = {ln.split()[-1] for ln in rec.lines if ln.startswith("recorder: subscribed")}
            # and recording: every subscription matched and the node's state saved at the start, so the
            # replay starts before the first command and every echo of one reaches the bag
            recording = any(ln.startswith("recorder: recording") for ln in rec.lines)
            if wanted <= got and recording and drv.matched(2):
                break
            if time.monotonic() > end or rec.proc.poll() is not None:
                raise RuntimeError(f"recorder did not subscribe to {sorted(wanted - got)}; "
                                   f"see {rec.log_path}")
            drv.spin(0.05)
        drv.spin(0.3)
        t0 = drv.sim_time
        print(f"demo: recording; driving for {duration:.1f} s of sim time from t = {t0:.2f} s",
              flush=True)
        period = 0.05
        next_tick = time.monotonic()
        anchor: tuple[float, float] | None = None
        while drv.sim_time < t0 + duration:
            if node.proc.poll() is not None:
                raise RuntimeError(f"node exited; see {node.log_path}")
            s = drv.sim_time - t0
            if anchor is None and s >= 3.0:
                anchor = drv.body_point(SPRING_BODY, SPRING_POINT)
            drv.send(cue(s, anchor or (0.0, 0.0)))
            next_tick += period
            drv.spin(max(0.0, next_tick - time.monotonic()))
        # the node applies and echoes the last commands at its next steps, a loaded machine's steps
        # late: the recording goes on long enough for each command's echo to reach the bag
        drv.spin(2.0)
    finally:
        rc_rec = rec.stop() if rec is not None else -1
        if viewer is not None:
            viewer.stop()
        drv.close()
        rclpy.try_shutdown()
        node.stop()
        if lock is not None:
            lock.release()
    wall = time.monotonic() - wall0
    if rc_rec != 0:
        print(f"demo: recorder failed ({rc_rec}); see {out / 'demo_recorder.log'}", file=sys.stderr)
        return 1
    counts_txt = "\n".join(ln for ln in rec.lines if ln.startswith("  "))
    msgs = read_bag(bag)
    from .replay import bag_params
    summ = summarize(msgs, t0, COAST_FROM, bag_params(bag))
    if gif:
        ref = ("coast", summ["coast_energy_J"]) if "coast_energy_J" in summ else None
        r = render_bag(bag, gif_path, msgs=msgs, energy_ref=ref)
        summ["gif_frames"] = r["frames"]
    summ.update(bag=str(bag), gif=str(gif_path) if gif else None, commands_sent=drv.sent,
                wall_seconds_total=wall)
    if do_replay:
        from .replay import replay
        rclpy.init(args=[])
        lock = ros_domain.lock_unless_set()
        try:
            summ["replay"] = replay(bag)
        finally:
            rclpy.try_shutdown()
            if lock is not None:
                lock.release()
    (out / "demo_summary.json").write_text(json.dumps(summ, indent=2, default=str))
    print_summary(summ, counts_txt)
    return 0 if not do_replay or summ["replay"]["ok"] else 1


def print_summary(s: dict[str, Any], counts: str) -> None:
    print("\n=== libcollide demo summary ===")
    if s.get("collisions") is not None:
        print(f"collisions:          {s['collisions']} (node's cumulative counter)")
    else:
        print(f"collisions:          {s.get('impact_contacts', 0)} impact contact points reported on "
              f"`contacts` in {s.get('collision_snapshots', 0)} messages; "
              f"{s.get('impacts_in_states', 0)} impacts seen as velocity jumps in the states")
    if "energy_drift_rel" in s:
        print(f"energy drift:        {s['energy_drift_rel']:.3e} relative (max-min)/E over the "
              f"{s['coast_seconds']:.2f} s force-free coast, E = {s['coast_energy_J']:.6f} J "
              "(e = 1, no damping, no gravity)")
    if "real_time_factor" in s:
        print(f"real-time factor:    {s['real_time_factor']:.3f} ({s['sim_seconds']:.2f} s sim in "
              f"{s['wall_seconds']:.2f} s wall, target 1.0)")
    print(f"commands sent:       {s['commands_sent']} (thrusters, spring, block1/thrust, block2/thrust, "
          "cmd_vel)")
    print(f"bag:                 {s['bag']}  (rosbag2, MCAP, metadata v9)")
    if counts:
        print(counts)
    if s.get("gif"):
        print(f"GIF:                 {s['gif']}  ({s.get('gif_frames', 0)} frames)")
    if "replay" in s:
        r = s["replay"]
        print(f"replay:              {r['identical']}/{r['compared']} recorded states bit-identical "
              f"replayed from the snapshot ({'OK' if r['ok'] else 'MISMATCH'})")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m collide_ros.demo", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default=str(ROOT / "out"), help="output directory (default: <repo>/out)")
    p.add_argument("--duration", type=float, default=10.0, help="scripted sim seconds")
    p.add_argument("--no-gif", action="store_true")
    p.add_argument("--replay", action="store_true", help="also replay the bag and check bit-exactness")
    p.add_argument("--no-view", action="store_true", help="do not start the live view next to the node")
    a = p.parse_args(argv)
    return run(Path(a.out), a.duration, not a.no_gif, a.replay, not a.no_view)


if __name__ == "__main__":
    sys.exit(main())
