"""Load on the sim node: command flood, a subscriber that stops reading,
parameter spam, service spam. Loopback only (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST), every loop
bounded in time and count.

    source scripts/env.sh && export ROS_DOMAIN_ID=87
    nice python soak/load.py [--seconds 4] [--rate 10000] [--out result.json]

The node runs at its defaults (real_time_factor 1, 1 kHz physics, 100 Hz states, 2 blocks). Each
phase runs for ``--seconds`` of wall time, then the load stops and the script waits for recovery.
Per phase it records every /diagnostics message of the node (real-time factor, level, late steps,
rejected commands); then:

* kept or reported: every diagnostics message during the load has real_time_factor >= 0.9 (the
  node's own WARN threshold) or level WARN with "falling behind" in its message;
* alive: diagnostics kept coming (>= 1 per 2 s of load: the 1 Hz publisher sits in the stepping
  loop, so a frozen loop shows as a gap) and sim time advanced during the load;
* counted: in the command flood the node's own counts of block1/thrust (received/ and lost/ in
  /diagnostics) add up to the messages sent: what DDS dropped from the full command queue is
  reported, not silently gone;
* recovered: after the load a diagnostics window with real_time_factor >= 0.95 and level OK,
  a fresh thrusters command is accepted (its echo on applied/thrusters arrives), ~/step answers,
  and the parameters the spam touched hold their last accepted value.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

REPO = Path(__file__).resolve().parents[1]
if str(REPO / "ros_pkg") not in sys.path:
    sys.path.insert(0, str(REPO / "ros_pkg"))

RTF_KEEP = 0.9      # the node's WARN threshold (docs/ros_interface.md, /diagnostics)
RTF_RECOVERED = 0.95
MAX_IN_FLIGHT = 50  # outstanding async requests during the spam phases


@dataclass
class Phase:
    name: str
    sent: int = 0
    accepted: int = 0   # command flood: echoes seen on applied/block1/thrust
    node_counts: dict[str, int] = field(default_factory=dict)  # command flood: the node's received/accepted/
    # rejected/lost of block1/thrust during the flood, from /diagnostics
    seconds: float = 0.0
    rate_hz: float = 0.0
    answered: int = 0
    diags: list[tuple[float, int, str, float]] = field(default_factory=list)  # (rtf, level, message, sim_time)
    min_rtf: float = float("inf")
    warned: bool = False
    unreported_drops: list[str] = field(default_factory=list)
    sim_advanced_s: float = 0.0
    recovered: bool = False
    recovery_rtf: float = 0.0
    accepted_after: bool = False
    step_answered_after: bool = False
    rejected_during: int = 0
    failures: list[str] = field(default_factory=list)


def _level(st: Any) -> int:
    lv = st.level
    return lv[0] if isinstance(lv, (bytes, bytearray)) else int(lv)


def _diag(msg: Any) -> dict[str, str] | None:
    for st in msg.status:
        if st.name.endswith(": physics"):
            vals = {kv.key: kv.value for kv in st.values}
            vals["_level"] = str(_level(st))
            vals["_message"] = st.message
            return vals
    return None


class Load:
    def __init__(self, client: Any, log: Callable[[str], None] = print) -> None:
        self.c = client
        self.log = log
        self.diags: list[dict[str, str]] = []
        from diagnostic_msgs.msg import DiagnosticArray
        from libcollide_msgs.msg import ThrusterCommand
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        self.echoes: list[Any] = []
        from geometry_msgs.msg import WrenchStamped
        self.thrust_echoes = 0

        def count_echo(m: Any) -> None:
            self.thrust_echoes += 1
        client.node.create_subscription(WrenchStamped, f"{client.ns}/applied/block1/thrust", count_echo,
                                        QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
        client.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 100)
        client.node.create_subscription(ThrusterCommand, f"{client.ns}/applied/thrusters", self.echoes.append, 10)

    def _on_diag(self, msg: Any) -> None:
        d = _diag(msg)
        if d is not None:
            self.diags.append(d)

    # ---------------------------------------------------------------- phase framing
    def run_phase(self, name: str, seconds: float, body: Callable[[Phase, float], None]) -> Phase:
        ph = Phase(name)
        self._phase_seconds = seconds
        self.c.spin(0.5)
        first = len(self.diags)
        t0 = time.monotonic()
        body(ph, t0 + seconds)
        ph.seconds = ph.seconds or (time.monotonic() - t0)  # a body may set it when the load ends
        ph.rate_hz = ph.sent / ph.seconds if ph.seconds > 0 else 0.0
        self.c.spin(1.2)  # the diagnostics window that contains the end of the load
        during = self.diags[first:]
        for d in during:
            rtf, lv = float(d["real_time_factor"]), int(d["_level"])
            ph.diags.append((rtf, lv, d["_message"], float(d["sim_time"])))
            ph.min_rtf = min(ph.min_rtf, rtf)
            if lv >= 1:
                ph.warned = True
            if rtf < RTF_KEEP and not (lv >= 1 and "falling behind" in d["_message"]):
                ph.unreported_drops.append(f"rtf {rtf} level {lv} '{d['_message']}'")
        if during:
            ph.sim_advanced_s = float(during[-1]["sim_time"]) - float(during[0]["sim_time"])
            ph.rejected_during = int(during[-1]["rejected_commands"]) - int(during[0]["rejected_commands"])
        self._recover(ph)
        self._verdict(ph, len(during))
        took = f"; node took {ph.node_counts}" if ph.node_counts else ""
        self.log(f"load: {name:<18} sent {ph.sent:7d} (answered/accepted {ph.answered or ph.accepted}{took}) "
                 f"in {ph.seconds:5.1f} s ({ph.rate_hz:8.0f}/s)  "
                 f"min RTF {ph.min_rtf:.3f} {'WARN' if ph.warned else 'ok  '}  recovered RTF "
                 f"{ph.recovery_rtf:.3f}  accepted after: {ph.accepted_after}")
        return ph

    def _recover(self, ph: Phase, timeout: float = 30.0) -> None:
        from libcollide_msgs.msg import ThrusterCommand
        from libcollide_msgs.srv import Step
        start = len(self.diags)
        end = time.monotonic() + timeout
        while time.monotonic() < end and not ph.recovered:
            self.c.spin(0.2)
            for d in self.diags[start:]:
                if float(d["real_time_factor"]) >= RTF_RECOVERED and int(d["_level"]) == 0:
                    ph.recovered, ph.recovery_rtf = True, float(d["real_time_factor"])
        n = len(self.echoes)
        self.c.publish("thrusters", ThrusterCommand(body="block2", firing=[False, False, False, False]))
        ph.accepted_after = self.c.wait_for(lambda: len(self.echoes) > n, 15.0)
        r = self.c.call(Step, "step", Step.Request(steps=1), timeout=15.0)
        ph.step_answered_after = r is not None and not r.success and "paused" in r.message

    def _verdict(self, ph: Phase, n_diags: int) -> None:
        if ph.unreported_drops:
            ph.failures.append(f"{ph.name}: real-time factor dropped without a WARN: {ph.unreported_drops}")
        if n_diags < max(1, int(ph.seconds / 2)):
            ph.failures.append(f"{ph.name}: only {n_diags} diagnostics in {ph.seconds:.1f} s of load")
        if ph.sim_advanced_s <= 0:
            ph.failures.append(f"{ph.name}: sim time did not advance during the load")
        if not ph.recovered:
            ph.failures.append(f"{ph.name}: real-time factor not back to >= {RTF_RECOVERED} after the load")
        if not ph.accepted_after:
            ph.failures.append(f"{ph.name}: a command after the load was not accepted (no echo)")
        if not ph.step_answered_after:
            ph.failures.append(f"{ph.name}: ~/step did not answer after the load")

    # ---------------------------------------------------------------- the loads
    def flood(self, ph: Phase, until: float, rate: float) -> None:
        """``rate`` WrenchStamped per second on block1/thrust (paced per millisecond)."""
        from geometry_msgs.msg import WrenchStamped
        if not self.c.wait_subscribed("block1/thrust", WrenchStamped):
            ph.failures.append("flood: node not subscribed to block1/thrust")
            return
        msg = WrenchStamped()
        msg.wrench.force.x = 0.01  # tiny, accepted, echoed: each one costs the node a full callback
        pub = self.c._pubs[("block1/thrust", WrenchStamped)]
        # One message first, taken by the node before the flood: the node counts gaps in this
        # publisher's sequence numbers from the first message it took (lost/<topic>).
        pub.publish(msg)
        if not self.c.wait_for(lambda: self.thrust_echoes > 0, 15.0):
            ph.failures.append("flood: the first command was not echoed")
            return
        before = self._settled_thrust_counts(lambda d: d.get("received/block1/thrust") == "1")
        e0 = self.thrust_echoes
        t0 = time.monotonic()
        until = t0 + self._phase_seconds  # the flood itself lasts the phase, after this preparation
        while True:
            now = time.monotonic()
            if now >= until:
                break
            due = int((now - t0) * rate)
            while ph.sent < due:
                pub.publish(msg)
                ph.sent += 1
            self.c.ex.spin_once(timeout_sec=0.0)
            time.sleep(0.0005)
        ph.seconds = time.monotonic() - t0
        self.c.spin(1.0)
        ph.accepted = self.thrust_echoes - e0
        after = self._settled_thrust_counts()
        if before is None or after is None:
            ph.failures.append("flood: no settled block1/thrust counts in /diagnostics")
        else:
            ph.node_counts = {k: after[k] - before[k] for k in after}

    def _settled_thrust_counts(self, ok: Callable[[dict[str, str]], bool] = lambda d: True,
                               timeout: float = 15.0) -> dict[str, int] | None:
        """The node's counts of block1/thrust once two consecutive diagnostics agree (and ``ok``)."""
        keys = [f"{w}/block1/thrust" for w in ("received", "accepted", "rejected", "lost")]
        end = time.monotonic() + timeout
        n = len(self.diags)
        prev = None
        while time.monotonic() < end:
            self.c.spin(0.1)
            for d in self.diags[n:]:
                cur = {k.split("/")[0]: int(d.get(k, -1)) for k in keys}
                if cur == prev and ok(d):
                    return cur
                prev = cur
            n = len(self.diags)
        return None

    def slow_subscriber(self, ph: Phase, until: float) -> None:
        """A child process subscribes (reliable) to everything the node publishes, reads for a
        moment, then is stopped with SIGSTOP (its sockets stay open, nothing is read) until the
        end of the phase; SIGCONT and SIGINT afterwards."""
        env = dict(os.environ)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO / "ros_pkg"), env.get("PYTHONPATH", "")) if p)
        from collide_ros.testing import _die_with_parent
        child = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--as-subscriber", self.c.ns],
                                 env=env, stdout=subprocess.PIPE, preexec_fn=_die_with_parent)
        try:
            line = child.stdout.readline() if child.stdout else b""  # "reading" once it has data
            if b"reading" not in line:
                ph.failures.append(f"slow subscriber did not start: {line!r}")
                return
            child.send_signal(signal.SIGSTOP)
            ph.sent = 1
            while time.monotonic() < until:
                self.c.spin(0.1)
        finally:
            child.send_signal(signal.SIGCONT)
            child.kill()  # a subscriber that vanishes without saying goodbye, too
            child.wait(15)

    def _spam(self, ph: Phase, until: float, make: Callable[[int], tuple[Any, Any]]) -> None:
        """Async requests from ``make(i)`` -> (client, request), at most MAX_IN_FLIGHT outstanding."""
        pending: list[Any] = []
        i = 0
        while time.monotonic() < until:
            pending = [f for f in pending if not f.done()]
            while len(pending) < MAX_IN_FLIGHT:
                cli, req = make(i)
                pending.append(cli.call_async(req))
                ph.sent += 1
                i += 1
            self.c.ex.spin_once(timeout_sec=0.001)
        ph.seconds = time.monotonic() - (until - self._phase_seconds)
        end = time.monotonic() + 3.0  # answers still in flight; requests beyond the queue are gone
        while pending and time.monotonic() < end:
            pending = [f for f in pending if not f.done()]
            self.c.ex.spin_once(timeout_sec=0.01)
        ph.answered = ph.sent - len(pending)

    def param_spam(self, ph: Phase, until: float) -> None:
        """set_parameters: alternating accepted values (cmd_vel_linear_gain 4.0 / 5.0, ending on
        5.0), out-of-range (gravity 1000), wrongly typed (blocks "two") and on-set-rejected
        (world_frame "/w") sets, and get_parameters."""
        from rcl_interfaces.msg import Parameter as P
        from rcl_interfaces.srv import GetParameters, SetParameters
        from collide_ros.testing import _param_value
        setc = self.c.node.create_client(SetParameters, f"{self.c.sim}/set_parameters")
        getc = self.c.node.create_client(GetParameters, f"{self.c.sim}/get_parameters")
        setc.wait_for_service(timeout_sec=10.0)
        getc.wait_for_service(timeout_sec=10.0)
        bad = [("gravity", 1000.0), ("blocks", "two"), ("world_frame", "/w"), ("elasticity", float("nan"))]

        def make(i: int) -> tuple[Any, Any]:
            if i % 4 == 3:
                return getc, GetParameters.Request(names=["gravity", "cmd_vel_linear_gain"])
            if i % 2 == 0:
                name, value = "cmd_vel_linear_gain", 4.0 if i % 8 == 0 else 5.0
            else:
                name, value = bad[(i // 2) % len(bad)]
            return setc, SetParameters.Request(parameters=[P(name=name, value=_param_value(value))])
        self._spam(ph, until, make)
        r = self.c.set_params({"cmd_vel_linear_gain": 5.0})  # the last word, in order
        if not (r and r[0].successful):
            ph.failures.append("param spam: final set refused")

    def service_spam(self, ph: Phase, until: float) -> None:
        """~/step while running (refused), ~/kill of an unknown body, ~/spawn with a bad shape,
        ~/pause false (a no-op while running)."""
        from libcollide_msgs.srv import Kill, Spawn, Step
        from std_srvs.srv import SetBool
        clients = [(self.c.node.create_client(Step, f"{self.c.sim}/step"), Step.Request(steps=1000)),
                   (self.c.node.create_client(Kill, f"{self.c.sim}/kill"), Kill.Request(name="ghost")),
                   (self.c.node.create_client(Spawn, f"{self.c.sim}/spawn"),
                    Spawn.Request(name="line", vertices=[0.0, 0.0, 1.0, 0.0, 2.0, 0.0], mass=1.0)),
                   (self.c.node.create_client(SetBool, f"{self.c.sim}/pause"), SetBool.Request(data=False))]
        for cli, _ in clients:
            cli.wait_for_service(timeout_sec=10.0)
        self._spam(ph, until, lambda i: clients[i % len(clients)])


def run_load(seconds: float = 4.0, rate: float = 10000.0, log: Callable[[str], None] = print,
             node_args: tuple[str, ...] = ()) -> list[Phase]:
    import rclpy
    from collide_ros.testing import NodeProcess, SimClient
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    proc = NodeProcess(*node_args)
    client = SimClient(context=ctx, watch=())
    phases: list[Phase] = []
    try:
        load = Load(client, log)
        if not client.wait_for(lambda: len(load.diags) >= 3, 60.0):
            raise RuntimeError(f"load: no diagnostics from the node; log:\n{proc.output()}")
        phases.append(load.run_phase("command flood", seconds, lambda ph, u: load.flood(ph, u, rate)))
        phases.append(load.run_phase("stopped subscriber", seconds, load.slow_subscriber))
        phases.append(load.run_phase("parameter spam", seconds, load.param_spam))
        phases.append(load.run_phase("service spam", seconds, load.service_spam))
        got = client.get_params(["cmd_vel_linear_gain", "gravity", "blocks", "world_frame", "elasticity"])
        want = {"cmd_vel_linear_gain": 5.0, "gravity": 0.0, "blocks": 2, "world_frame": "world", "elasticity": 1.0}
        if got != want:
            phases[2].failures.append(f"parameters after the spam: {got}, expected {want}")
        if not proc.alive():
            phases[-1].failures.append(f"node exited with {proc.proc.returncode}")
    finally:
        client.close()
        rclpy.shutdown(context=ctx)
        code = proc.stop()
    if code != 0:
        phases[-1].failures.append(f"node exit code {code}")
    return phases


def _as_subscriber(ns: str) -> int:
    """Child for the stopped-subscriber phase: reliable subscriptions to every node topic."""
    import rclpy
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from collide_ros.testing import SimClient
    rclpy.init()
    c = SimClient(ns=ns)
    deep = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    from collide_ros.recorder import msg_class
    for t in ("bodies/poses", "bodies/states", "contacts", "energy"):
        c.node.create_subscription(msg_class({"bodies/poses": "geometry_msgs/msg/PoseArray",
                                              "bodies/states": "libcollide_msgs/msg/BodyStates",
                                              "contacts": "libcollide_msgs/msg/Contacts",
                                              "energy": "libcollide_msgs/msg/Energy"}[t]),
                                   f"{c.ns}/{t}", lambda m: None, deep)
    if c.wait_for(lambda: c.count["bodies/states"] > 5 and c.count["tf"] > 5, 30.0):
        print("reading", flush=True)
    try:
        while True:
            c.spin(0.1)
    except KeyboardInterrupt:
        pass
    finally:
        c.close()
        rclpy.try_shutdown()
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--as-subscriber"]:
        return _as_subscriber(argv[1] if len(argv) > 1 else "")
    p = argparse.ArgumentParser(prog="soak/load.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seconds", type=float, default=4.0, help="wall seconds of each load phase")
    p.add_argument("--rate", type=float, default=10000.0, help="command flood rate (messages/s)")
    p.add_argument("--out", type=Path, default=None, help="write the phases as JSON here")
    a = p.parse_args(argv)
    if "ROS_DOMAIN_ID" not in os.environ:
        print("load: export ROS_DOMAIN_ID first (hand runs: 85-94)", file=sys.stderr)
        return 2
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    phases = run_load(a.seconds, a.rate)
    fails = [f for ph in phases for f in ph.failures]
    if a.out:
        a.out.write_text(json.dumps([asdict(ph) for ph in phases], indent=1, default=str))
    for f in fails:
        print(f"load: FAIL {f}")
    print(f"load: {'PASS' if not fails else 'FAIL'}")
    return 0 if not fails else 1


if __name__ == "__main__":
    sys.exit(main())
