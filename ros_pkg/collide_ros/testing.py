"""Helpers to drive a ``sim`` node in another process: start/stop it, watch its topics, call its
services and parameters, all with timeouts. Used by tests/python/test_node*.py and bench/node_bench.py.

The caller owns rclpy.init()/shutdown() and the ROS_DOMAIN_ID (the child inherits the environment).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseArray
from libcollide_msgs.msg import BodyStates, Contacts, Energy
from rcl_interfaces.msg import Log, Parameter as ParameterMsg, ParameterValue, ParameterType
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from .cdr import join_time
from .diag_name import physics_status

REPO = Path(__file__).resolve().parents[2]


def _die_with_parent() -> None:
    """In the child before exec: SIGTERM it when the parent dies (Linux), so a crashed test or
    bench never leaves a node running."""
    try:
        import ctypes
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except OSError:
        pass


class NodeProcess:
    """``python -m collide_ros.node --ros-args <args>`` in a child process; log in a temp file."""

    def __init__(self, *ros_args: str, env: dict[str, str] | None = None) -> None:
        self.log = tempfile.NamedTemporaryFile(prefix="sim_node_", suffix=".log", delete=False)
        e = dict(os.environ if env is None else env)
        e.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        e["PYTHONUNBUFFERED"] = "1"
        e["RCUTILS_COLORIZED_OUTPUT"] = "0"
        self.proc = subprocess.Popen([sys.executable, "-m", "collide_ros.node", "--ros-args", *ros_args],
                                     stdout=self.log, stderr=subprocess.STDOUT, env=e,
                                     preexec_fn=_die_with_parent)

    def alive(self) -> bool:
        return self.proc.poll() is None

    def output(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text(errors="replace")

    def stop(self, timeout: float = 10.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout)
        return int(self.proc.returncode)


COUNT_PREFIXES = ("published/", "received/", "accepted/", "rejected/", "lost/")


def diag_values(msg: Any, name: str = "/sim") -> dict[str, str] | None:
    """The values of the ``<name>: physics`` status of a DiagnosticArray (None if it has none);
    ``name`` is the node's fully qualified name (``/sim``, ``/robot1/sim``)."""
    for st in msg.status:
        if st.name == physics_status(name):
            return {kv.key: kv.value for kv in st.values}
    return None


def diag_counts(values: dict[str, str]) -> dict[str, int]:
    """The message counts among diagnostics values (docs/ros_interface.md, /diagnostics), with
    rejected_commands (every rejection, also of a failed physics step), dropped_contacts, dropped_impacts
    and split_steps."""
    return {k: int(v) for k, v in values.items()
            if k.startswith(COUNT_PREFIXES)
            or k in ("rejected_commands", "dropped_contacts", "dropped_impacts", "split_steps")}


def _param_value(v: Any) -> ParameterValue:
    pv = ParameterValue()
    if isinstance(v, bool):
        pv.type, pv.bool_value = ParameterType.PARAMETER_BOOL, v
    elif isinstance(v, int):
        pv.type, pv.integer_value = ParameterType.PARAMETER_INTEGER, v
    elif isinstance(v, float):
        pv.type, pv.double_value = ParameterType.PARAMETER_DOUBLE, v
    elif isinstance(v, str):
        pv.type, pv.string_value = ParameterType.PARAMETER_STRING, v
    else:
        raise TypeError(f"unsupported parameter value {v!r}")
    return pv


def _from_value(pv: ParameterValue) -> Any:
    return {ParameterType.PARAMETER_BOOL: pv.bool_value, ParameterType.PARAMETER_INTEGER: pv.integer_value,
            ParameterType.PARAMETER_DOUBLE: pv.double_value,
            ParameterType.PARAMETER_STRING: pv.string_value}.get(pv.type)


class SimClient:
    """A client node that records what one sim (namespace ``ns``) publishes."""

    TOPICS: dict[str, Any] = {"bodies/poses": PoseArray, "bodies/states": BodyStates, "energy": Energy,
                              "contacts": Contacts}

    def __init__(self, ns: str = "", name: str = "sim", context: Any = None,
                 watch: tuple[str, ...] | None = None) -> None:
        """``watch``: the keys to subscribe to (default all: the TOPICS keys, clock, tf, diagnostics,
        markers); a bench that receives 1000-body messages itself should watch only what it needs."""
        self.ns = ns.rstrip("/")
        self.sim = f"{self.ns}/{name}"
        self.node: Node = rclpy.create_node(f"sim_test_client_{os.getpid()}_{abs(hash(ns)) % 10000}",
                                            context=context)
        self.ex = SingleThreadedExecutor(context=self.node.context)
        self.ex.add_node(self.node)
        self.last: dict[str, Any] = {}
        self.count: dict[str, int] = {}
        self.history: dict[str, deque[tuple[float, Any]]] = {}
        self.rosout: list[Log] = []
        latched = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
        subs = {**{k: (f"{self.ns}/{k}", t, 10) for k, t in self.TOPICS.items()},
                "clock": ("/clock", Clock, 10), "tf": ("/tf", TFMessage, 10),
                "diagnostics": ("/diagnostics", DiagnosticArray, 10),
                "markers": (f"{self.ns}/markers", MarkerArray, latched)}
        for key, (topic, typ, q) in subs.items():
            if watch is None or key in watch:
                self._sub(topic, typ, key, q)
        rosout_qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                                durability=DurabilityPolicy.VOLATILE)
        self.node.create_subscription(Log, "/rosout", self.rosout.append, rosout_qos)
        self._pubs: dict[tuple[str, Any], Any] = {}
        self._clients: dict[tuple[str, Any], Any] = {}

    def _sub(self, topic: str, typ: Any, key: str, q: Any = 10) -> None:
        self.count[key] = 0
        self.history[key] = deque(maxlen=2000)

        def cb(msg: Any) -> None:
            self.last[key] = msg
            self.count[key] += 1
            self.history[key].append((time.monotonic(), msg))
        self.node.create_subscription(typ, topic, cb, q)

    # ---- waiting ----
    def spin(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.ex.spin_once(timeout_sec=min(0.05, max(0.0, end - time.monotonic())))

    def wait_for(self, pred: Callable[[], Any], timeout: float = 10.0) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if pred():
                return True
            self.ex.spin_once(timeout_sec=0.02)
        return bool(pred())

    def since(self, key: str, mark: int) -> list[Any]:
        """The messages on ``key`` received after ``self.count[key]`` was ``mark``, oldest first. The
        history holds the newest 2000 only: slicing it by a count taken earlier goes wrong (empty) once
        more than that arrived in all, so the new ones are counted from its end."""
        new = self.count[key] - mark
        if new <= 0:
            return []
        held = list(self.history[key])
        return [m for _, m in held[-new:]]

    def fresh(self, key: str, n: int = 1, timeout: float = 10.0) -> Any:
        """Wait for n new messages on ``key`` and return the last one (None on timeout)."""
        start = self.count[key]
        if not self.wait_for(lambda: self.count[key] >= start + n, timeout):
            return None
        return self.last[key]

    def wait_rosout(self, text: str, timeout: float = 10.0) -> Log | None:
        def find() -> Log | None:
            for m in self.rosout:
                if text in m.msg:
                    return m
            return None
        self.wait_for(lambda: find() is not None, timeout)
        return find()

    def diagnostics(self, timeout: float = 10.0) -> dict[str, str] | None:
        """The values of the node's next /diagnostics status (None on timeout)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            msg = self.fresh("diagnostics", timeout=max(0.0, end - time.monotonic()))
            vals = None if msg is None else diag_values(msg, self.sim)
            if vals is not None:
                return vals
        return None

    def wait_node_matched(self, topic: str, timeout: float = 20.0) -> bool:
        """Wait until the node's writer on ``topic`` has matched every reader the graph lists,
        by its own subscribers/<topic> diagnostic. A reader that sees the writer
        (get_publisher_count) may still miss messages: DDS matches the two ends separately."""
        name = topic if topic.startswith("/") else f"{self.ns}/{topic}"
        key = topic.lstrip("/")

        def matched() -> bool:
            vals = self.diagnostics(timeout=min(5.0, timeout))
            listed = len(self.node.get_subscriptions_info_by_topic(name))
            return vals is not None and listed > 0 and int(vals.get(f"subscribers/{key}", -1)) >= listed
        return self.wait_for(matched, timeout)

    def settled_counts(self, timeout: float = 20.0) -> dict[str, int] | None:
        """The node's message counts once they stopped changing: two consecutive /diagnostics
        messages of a paused node with equal counts, apart from published/diagnostics (the node
        builds diagnostics under the same lock as it publishes and takes commands, so nothing
        was published or taken between them). Pause the node first."""
        end = time.monotonic() + timeout
        prev: dict[str, int] | None = None
        while time.monotonic() < end:
            vals = self.diagnostics(timeout=max(0.0, end - time.monotonic()))
            if vals is None:
                return None
            counts = diag_counts(vals) if vals.get("paused") == "true" else None
            same = (counts is not None and prev is not None
                    and {k: v for k, v in counts.items() if k != "published/diagnostics"}
                    == {k: v for k, v in prev.items() if k != "published/diagnostics"})
            if same:
                return counts
            prev = counts
        return None

    def sim_time(self, timeout: float = 10.0) -> float | None:
        msg = self.fresh("clock", timeout=timeout)
        return None if msg is None else join_time(msg.clock)

    def body_state(self, name: str, timeout: float = 10.0) -> tuple[float, ...] | None:
        """(x, y, yaw, vx, vy, omega) from a fresh bodies/states message."""
        import math
        msg = self.fresh("bodies/states", timeout=timeout)
        if msg is None or name not in msg.names:
            return None
        i = list(msg.names).index(name)
        p, t = msg.poses[i], msg.twists[i]
        yaw = 2.0 * math.atan2(p.orientation.z, p.orientation.w)
        return (p.position.x, p.position.y, yaw, t.linear.x, t.linear.y, t.angular.z)

    # ---- talking ----
    def publish(self, topic: str, msg: Any) -> None:
        key = (topic, type(msg))
        if key not in self._pubs:
            self._pubs[key] = self.node.create_publisher(type(msg), topic if topic.startswith("/")
                                                         else f"{self.ns}/{topic}", 10)
        self._pubs[key].publish(msg)

    def forget(self, topic: str) -> None:
        """Destroy this client's publishers on ``topic`` (a DDS participant holds one type per topic)."""
        for key in [k for k in self._pubs if k[0] == topic]:
            self.node.destroy_publisher(self._pubs.pop(key))

    def wait_subscribed(self, topic: str, typ: Any, timeout: float = 10.0) -> bool:
        key = (topic, typ)
        if key not in self._pubs:
            self._pubs[key] = self.node.create_publisher(typ, topic if topic.startswith("/")
                                                         else f"{self.ns}/{topic}", 10)
        pub = self._pubs[key]
        return self.wait_for(lambda: pub.get_subscription_count() > 0, timeout)

    def call(self, srv_type: Any, name: str, request: Any = None, timeout: float = 15.0) -> Any:
        """Call ``<sim>/<name>`` (or an absolute name); None on timeout."""
        full = name if name.startswith("/") else f"{self.sim}/{name}"
        key = (full, srv_type)
        if key not in self._clients:
            self._clients[key] = self.node.create_client(srv_type, full)
        cli = self._clients[key]
        if not cli.wait_for_service(timeout_sec=timeout):
            return None
        fut = cli.call_async(request if request is not None else srv_type.Request())
        self.ex.spin_until_future_complete(fut, timeout_sec=timeout)
        return fut.result() if fut.done() else None

    def set_params(self, values: dict[str, Any], timeout: float = 15.0) -> list[Any] | None:
        req = SetParameters.Request()
        req.parameters = [ParameterMsg(name=k, value=_param_value(v)) for k, v in values.items()]
        resp = self.call(SetParameters, "set_parameters", req, timeout)
        return None if resp is None else list(resp.results)

    def get_params(self, names: list[str], timeout: float = 15.0) -> dict[str, Any] | None:
        req = GetParameters.Request()
        req.names = names
        resp = self.call(GetParameters, "get_parameters", req, timeout)
        return None if resp is None else {n: _from_value(v) for n, v in zip(names, resp.values)}

    def close(self) -> None:
        self.ex.remove_node(self.node)
        self.node.destroy_node()


@contextmanager
def running_sim(*node_args: str) -> Iterator[tuple[SimClient, NodeProcess]]:
    """A node process with `node_args` and a client in its own rclpy context, once the node publishes
    bodies/states; on exit both are stopped and the node must have exited cleanly (code 0)."""
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    proc = NodeProcess(*node_args)
    client = SimClient(context=ctx)
    try:
        ok = client.wait_for(lambda: client.count["bodies/states"] > 0, timeout=60.0)
        assert ok, f"node published no bodies/states; log:\n{proc.output()}"
        yield client, proc
    finally:
        client.close()
        code = proc.stop()
        rclpy.shutdown(context=ctx)
    assert code == 0, f"node exited with {code}; log:\n{proc.output()}"


@contextmanager
def sims_side_by_side(*node_args: tuple[str, ...]) -> Iterator[list[SimClient]]:
    """One sim node per argument tuple (each with its own ``-r __ns:=/name``), in one rclpy context, a
    SimClient for each namespace; yields the clients once every sim has published its states, and on
    exit stops the nodes and asserts that each exited cleanly (status 0)."""
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    procs = [NodeProcess(*args) for args in node_args]
    spaces = [args[args.index("-r") + 1].split(":=", 1)[1] for args in node_args]
    clients = [SimClient(ns, context=ctx) for ns in spaces]
    try:
        for c, p in zip(clients, procs):
            assert c.wait_for(lambda c=c: c.count["bodies/states"] > 0, 60.0), p.output()
        yield clients
    finally:
        for c in clients:
            c.close()
        codes = [p.stop() for p in procs]
        rclpy.shutdown(context=ctx)
    assert codes == [0] * len(procs), "".join(p.output() for p in procs)

