"""The view's ROS side: the node ``view`` that watches a sim node and talks to it for the page.

All names are relative, so ``--ros-args -r __ns:=/robot1`` watches the sim of /robot1. Callbacks
run on the executor thread (``spin_in_thread``); the WebSocket server calls the methods marked
*thread-safe* from its asyncio thread. Everything shared is under ``self.lock``.
"""
from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from libcollide_msgs.msg import BodyStates, Contacts, Energy, SpringCommand, ThrusterCommand
from libcollide_msgs.srv import Step
from rcl_interfaces.msg import Parameter as ParameterMsg, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.executors import ExternalShutdownException, ShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Empty, SetBool
from visualization_msgs.msg import MarkerArray

from collide_ros import qos
from collide_ros.diag_name import physics_status, sim_node_name
from collide_ros.params import frame_prefix_for
from collide_ros.teleop import N_THRUSTERS, firing_for
from collide_ros.view import cdr_in
from collide_ros.view.protocol import PARAMS
from collide_ros.view.scene import MAX_CONTACTS, SceneState

THRUSTER_PERIOD = 0.1   # s: held thrusters are republished (the node drops a command after command_timeout)
SERVICE_WAIT = 5.0      # s: how long a request waits for the node's service to appear
ANSWER_WAIT = 15.0      # s: ... and for the node's answer
WATCH_PERIOD = 0.5      # s: is the sim node there? parameters refreshed every other tick
LATEST = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=5, reliability=ReliabilityPolicy.BEST_EFFORT,
                    durability=DurabilityPolicy.VOLATILE)
# reliable, transient local: a late view gets the node's latest markers; depth 10 keeps a reset's message
# (DELETEALL + the new scene) while the executor is busy
LATCHED = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)

Reply = Callable[[bool, str], None]
#: the node's frame names (strings), read with the parameters: /tf and the Foxglove stream name frames so
FRAME_PARAMS = ("world_frame", "frame_prefix")


def _param_value(name: str, value: float | int) -> ParameterValue:
    if PARAMS[name] is int:
        return ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=int(value))
    return ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=float(value))


class ViewBridge(Node):
    """Subscribes to a sim node's topics, publishes the page's springs and thrusters, calls its
    parameter and control services."""

    def __init__(self, sim: str = "sim", bodies: tuple[str, str] = ("block1", "block2"),
                 stiffness: float = 0.0, **kwargs: Any) -> None:
        super().__init__("view", **kwargs)
        self.lock = threading.Lock()
        self.scene = SceneState()
        self.bodies = bodies            # driven by S,D,F,E and J,K,L,I / arrows (teleop.KEYMAP slots)
        self.stiffness = stiffness      # 0: the node's default spring stiffness
        self.node_alive = False
        self.params: dict[str, Any] = {}
        self.health: dict[str, Any] | None = None
        # the node's defaults; frames_known once its parameters are read
        self.frames = {"world_frame": "world", "frame_prefix": frame_prefix_for(self.get_namespace())}
        self.frames_known = False
        self._held: dict[int, frozenset[str]] = {}   # client -> thruster keys held
        self._active: set[int] = set()               # block slots firing now
        self._springs: dict[int, str] = {}            # client -> spring name in use
        # the sim names its /diagnostics status by its fully qualified name (/sim, /robot1/sim): the one
        # in this view's namespace, so a view beside several sims shows its own sim's health
        self._diag_name = physics_status(sim_node_name(self.get_namespace(), sim))
        # the bulk topics arrive as CDR bytes, read by cdr_in (rclpy's message objects cost ~0.1 s
        # per message at 1 000 bodies); the readers keep what did not change since the last message
        self._states_in = cdr_in.StatesReader()
        self._markers_in = cdr_in.MarkersReader()
        self.create_subscription(BodyStates, "bodies/states", self._on_states, LATEST, raw=True)
        self.create_subscription(MarkerArray, "markers", self._on_markers, LATCHED, raw=True)
        self.create_subscription(Contacts, "contacts", self._on_contacts, LATEST, raw=True)
        self.create_subscription(Energy, "energy", self._on_energy, LATEST)
        self.create_subscription(DiagnosticArray, "/diagnostics", self._on_diag, 10)
        self._pub_spring = self.create_publisher(SpringCommand, "spring", qos.COMMAND)
        self._pub_thrusters = self.create_publisher(ThrusterCommand, "thrusters", qos.COMMAND)
        self._cli = {
            "set": self.create_client(SetParameters, f"{sim}/set_parameters"),
            "get": self.create_client(GetParameters, f"{sim}/get_parameters"),
            "pause": self.create_client(SetBool, f"{sim}/pause"),
            "step": self.create_client(Step, f"{sim}/step"),
            "reset": self.create_client(Empty, f"{sim}/reset"),
        }
        self._states_topic = self.resolve_topic_name("bodies/states")
        self._polling = False
        self._ticks = 0
        self.create_timer(THRUSTER_PERIOD, self._republish_thrusters)
        self.create_timer(WATCH_PERIOD, self._watch)

    # ---------------------------------------------------------------- topics in
    def _unreadable(self, topic: str, exc: Exception) -> None:
        self.get_logger().warning(f"view: {topic}: message skipped: {exc}", throttle_duration_sec=5.0)

    def _on_states(self, raw: bytes) -> None:
        try:
            m = self._states_in.read(raw)
        except ValueError as exc:
            self._unreadable("bodies/states", exc)
            return
        with self.lock:
            self.scene.on_states(m.stamp, m.names, m.poses, m.twists)
            self.node_alive = True

    def _on_markers(self, raw: bytes) -> None:
        try:
            m = self._markers_in.read(raw)
        except ValueError as exc:
            self._unreadable("markers", exc)
            return
        with self.lock:
            self.scene.on_markers(m)

    def _on_contacts(self, raw: bytes) -> None:
        try:
            _stamp, pts = cdr_in.contact_points(raw, MAX_CONTACTS)
        except ValueError as exc:
            self._unreadable("contacts", exc)
            return
        with self.lock:
            self.scene.on_contacts(pts)

    def _on_energy(self, m: Energy) -> None:
        with self.lock:
            self.scene.on_energy({"translational": m.translational, "rotational": m.rotational,
                                  "potential": m.gravitational + m.spring, "gravitational": m.gravitational,
                                  "spring": m.spring, "total": m.total})

    def _on_diag(self, m: DiagnosticArray) -> None:
        for st in m.status:
            if st.name == self._diag_name:
                vals = {kv.key: kv.value for kv in st.values}
                with self.lock:
                    self.health = {"level": int.from_bytes(st.level, "little") if isinstance(st.level, bytes)
                                   else int(st.level), "message": st.message,
                                   "paused": vals.get("paused") == "true",
                                   "rtf": vals.get("real_time_factor")}

    # ---------------------------------------------------------------- liveness, parameters
    def _watch(self) -> None:
        alive = self.count_publishers(self._states_topic) > 0
        with self.lock:
            if self.node_alive and not alive:
                self.scene.gone()
                self.health = None
                self.params = {}
                self.frames_known = False
            self.node_alive = alive
        self._ticks += 1
        if alive and not self._polling and (self._ticks % 2 == 0 or not self.params):
            self.refresh_params()

    def refresh_params(self) -> None:
        """Ask the node for the settable parameters (thread-safe)."""
        cli = self._cli["get"]
        if not cli.service_is_ready():
            return
        self._polling = True
        names = [*PARAMS, *FRAME_PARAMS]
        fut = cli.call_async(GetParameters.Request(names=names))

        def done(f: Any) -> None:
            self._polling = False
            resp = f.result()
            if resp is None:
                return
            vals: dict[str, Any] = {}
            frames: dict[str, str] = {}
            for n, v in zip(names, resp.values):
                if v.type == ParameterType.PARAMETER_DOUBLE:
                    vals[n] = v.double_value
                elif v.type == ParameterType.PARAMETER_INTEGER:
                    vals[n] = v.integer_value
                elif v.type == ParameterType.PARAMETER_STRING and n in FRAME_PARAMS:
                    frames[n] = v.string_value
            with self.lock:
                self.params = vals
                self.frames.update(frames)
                self.frames_known = self.frames_known or len(frames) == len(FRAME_PARAMS)
        fut.add_done_callback(done)

    # ---------------------------------------------------------------- commands (thread-safe)
    def dynamic_bodies(self) -> frozenset[str]:
        with self.lock:
            return self.scene.dynamic_bodies()

    def spring(self, client: int, body: str, point: tuple[float, float], target: tuple[float, float]) -> None:
        m = SpringCommand()
        m.header.stamp = self.get_clock().now().to_msg()
        m.name = f"view{client}"
        m.body = body
        m.body_point.x, m.body_point.y = point
        m.target.x, m.target.y = target
        m.stiffness = float(self.stiffness)
        with self.lock:
            self._springs[client] = m.name
        self._pub_spring.publish(m)

    def release(self, client: int) -> None:
        with self.lock:
            name = self._springs.pop(client, None)
        if name is not None:
            m = SpringCommand()
            m.header.stamp = self.get_clock().now().to_msg()
            m.name = name
            m.release = True
            self._pub_spring.publish(m)

    def keys(self, client: int, held: frozenset[str]) -> None:
        with self.lock:
            if held:
                self._held[client] = held
            else:
                self._held.pop(client, None)
            self._send_thrusters(changed_only=False)

    def forget(self, client: int) -> None:
        """A page went away: its spring and keys are released."""
        self.release(client)
        self.keys(client, frozenset())

    def _republish_thrusters(self) -> None:
        with self.lock:
            if self._active:
                self._send_thrusters(changed_only=False)

    def _send_thrusters(self, changed_only: bool) -> None:
        """Under self.lock: publish the firing lists of the held keys; all-off for blocks released."""
        union: set[str] = set()
        for h in self._held.values():
            union |= h
        fire = firing_for(union)
        stamp = self.get_clock().now().to_msg()
        for slot in sorted(set(fire) | self._active):
            if slot >= len(self.bodies):
                continue
            m = ThrusterCommand()
            m.header.stamp = stamp
            m.body = self.bodies[slot]
            m.firing = fire.get(slot, [False] * N_THRUSTERS)
            self._pub_thrusters.publish(m)
        self._active = set(fire)

    def call(self, kind: str, args: dict[str, Any], reply: Reply) -> None:
        """Set a parameter or call pause/step/reset and wait for the answer (call it on a worker
        thread): ``reply(ok, message)`` is called once, also when the service is not there within
        SERVICE_WAIT or the answer not within ANSWER_WAIT."""
        key = {"param": "set"}.get(kind, kind)
        cli = self._cli[key]
        # blocks up to SERVICE_WAIT: call it off the event loop (a node that just came up may not be
        # matched yet)
        if not cli.wait_for_service(timeout_sec=SERVICE_WAIT):
            reply(False, f"the sim node's service {cli.srv_name} is not available (is the node running "
                         "in this namespace and ROS_DOMAIN_ID?)")
            return
        if kind == "param":
            req: Any = SetParameters.Request(parameters=[ParameterMsg(
                name=args["name"], value=_param_value(args["name"], args["value"]))])
        elif kind == "pause":
            req = SetBool.Request(data=bool(args["paused"]))
        elif kind == "step":
            req = Step.Request(steps=int(args["steps"]))
        else:
            req = Empty.Request()
        fut = cli.call_async(req)
        answered = threading.Event()
        fut.add_done_callback(lambda _f: answered.set())
        if not answered.wait(ANSWER_WAIT):
            cli.remove_pending_request(fut)
            reply(False, f"{cli.srv_name}: no answer within {ANSWER_WAIT:g} s")
            return
        resp = fut.result()
        if resp is None:
            reply(False, f"{cli.srv_name}: no answer")
        elif kind == "param":
            r = resp.results[0]
            if r.successful:
                self.refresh_params()
            reply(bool(r.successful), r.reason or f"{args['name']} = {args['value']:g}")
        elif kind == "reset":
            # the view starts over when the node's markers message of the reset (DELETEALL first) arrives
            reply(True, "reset")
        else:
            reply(bool(resp.success), resp.message)

    # ---------------------------------------------------------------- snapshots (thread-safe)
    def snapshot(self) -> tuple[int, dict[str, Any]]:
        """(seq, state message): seq changes whenever something worth sending arrived."""
        with self.lock:
            state = self.scene.state_message()
            state["node"] = self.node_alive
            state["health"] = self.health
            state["params"] = dict(self.params)
            return self.scene.seq, state

    def shapes(self) -> dict[str, Any]:
        with self.lock:
            return self.scene.shapes_message()

    def frame_names(self) -> tuple[str, str] | None:
        """(world_frame, frame_prefix) of the sim node; None until its parameters have been read."""
        with self.lock:
            return (self.frames["world_frame"], self.frames["frame_prefix"]) if self.frames_known else None


def spin_in_thread(node: Node) -> tuple[threading.Thread, SingleThreadedExecutor]:
    """Run the node's callbacks on a daemon thread until its context shuts down."""
    ex = SingleThreadedExecutor(context=node.context)
    ex.add_node(node)

    def run() -> None:
        while node.context.ok():
            try:
                ex.spin_once(timeout_sec=0.1)
            except (ExternalShutdownException, ShutdownException):
                return
            except Exception as exc:  # a callback failed: log it, keep serving
                node.get_logger().warning(f"view: {type(exc).__name__}: {exc}")
    t = threading.Thread(target=run, name="view-executor", daemon=True)
    t.start()
    return t, ex
