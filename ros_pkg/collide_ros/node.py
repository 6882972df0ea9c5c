"""The simulator node ``sim``: libcollide driven and observed over ROS 2 (docs/ros_interface.md).

    python -m collide_ros.node --ros-args [-r __ns:=/arena2] [-p blocks:=4] [-p scene_file:=f.yaml]

Physics runs in C. This module is a thin shell: a sleep-until loop steps the world at
``time_step`` / ``real_time_factor`` of wall time and publishes at rates counted in sim-time steps;
an executor thread handles commands, services and parameters as they arrive, under one lock. Bulk messages
(poses, states, contacts, /tf, markers, /clock) are written as CDR bytes with numpy (cdr.py, markers.py).
Bad input is rejected with a throttled warning naming the reason; nothing a peer sends stops the loop.
"""
from __future__ import annotations

import math
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseArray, Twist, TwistStamped, Vector3, WrenchStamped
from libcollide_msgs.msg import BodyStates, Contacts, Energy, SpringCommand, ThrusterCommand
from libcollide_msgs.srv import Kill, Spawn, Step
from rcl_interfaces.msg import SetParametersResult
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import ExternalShutdownException, ShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos_overriding_options import QoSOverridingOptions
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, SetBool
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

import collide
from collide import CollideError

from collide_ros import cdr, markers, params, qos
from collide_ros.diag_name import physics_status

WARN_PERIOD = 1.0  # s (wall) between two warnings with the same key
MAX_STEPS_PER_CALL = 1_000_000  # ~/step upper bound per request
APPLIED = "applied/"  # prefix of the command echo topics
# Contacts per contacts message (impacts since the last one first, then resting contacts); more
# are dropped and counted (dropped_contacts). A reliable writer's history keeps every slot's
# largest message (Fast DDS reallocates a slot's buffer upwards, never down), so the node's memory
# grows towards state_qos_depth x the largest contacts message: 1000 contacts (~74 kB) x 100 =
# ~7 MB. Uncapped, the soak saw 100 000 impacts (7.4 MB) in one message and the RSS grew by 94 MiB
# in an hour (docs/hardening.md, "Soak").
MAX_CONTACTS_PER_MESSAGE = 1000
MAX_CMD_SPEED = 1000.0  # m/s or rad/s: larger cmd_vel components are rejected
CATCH_UP_LIMIT = 0.1  # s (wall): a loop further behind than this drops the backlog (counted as late)
# A step C undoes (LC_ERR_NUMERIC: e.g. a crossing missed within a trial interval and caught by the
# energy balance) is deterministic: retried as it was, it fails again and the sim would stand still
# until a reset. Halving the step changes the trial intervals, so it is retried as two halves, each
# of which may halve again, down to time_step / 2**SPLIT_DEPTH; only then is it a failure.
SPLIT_DEPTH = 6
# ... unless the undone step was already costly (C's work caps: 5e5 force evaluations, 5e4 serial
# passes, 1e9 solver work per body): 2 + 2 + ... more attempts at that cost would stall the loop (and
# the executor, which waits for the world lock) for many times as long. The soak's command mix on
# four blocks took at most 3 660 evaluations, 1 100 serial passes and 1.2e5 solver work per body in
# a step (soak/step_search.py, 2.5e8 steps; docs/hardening.md "The node when C undoes a step").
SPLIT_MAX_WORK = {"force_evaluations": 20_000, "serial_iterations": 5_000}
SPLIT_MAX_SOLVER_WORK_PER_BODY = 1e7


@dataclass
class _Thrust:
    fx: float
    fy: float
    torque: float
    world: bool     # force given in the world frame (frame_id == world_frame) instead of the body frame
    stamp: float    # sim time of arrival


@dataclass
class _CmdVel:
    vx: float
    vy: float
    wz: float
    stamp: float


@dataclass
class _SpringEntry:
    spring: Any     # collide.Spring
    body: str
    point: tuple[float, float]  # body frame, about the centre of mass


class _CountedPublisher:
    """An rclpy publisher that counts its publish() calls, for the ``published/<topic>`` values of
    /diagnostics: one int increment per message, whatever the message holds."""

    __slots__ = ("pub", "count")

    def __init__(self, pub: Any) -> None:
        self.pub = pub
        self.count = 0

    def publish(self, msg: Any) -> None:
        self.pub.publish(msg)
        self.count += 1


class _CommandCounts:
    """Per command topic: messages the node took (received = accepted + rejected) and the ones DDS
    dropped before the node took them (lost: gaps in the publisher's sequence numbers)."""

    __slots__ = ("received", "accepted", "rejected", "lost", "topic", "writer", "last_seq")

    def __init__(self) -> None:
        self.received = self.accepted = self.rejected = self.lost = 0
        self.topic = ""            # resolved topic name (for the graph query on a gap)
        self.writer: tuple[int, ...] | None = None  # gid of the only publisher when last_seq was seen
        self.last_seq = -1         # its publication sequence number of the last message taken

    def restart(self, topic: str) -> None:
        """A new subscription: sequence numbers start over."""
        self.topic, self.writer, self.last_seq = topic, None, -1


def _hex_color(value: Any, fallback: markers.Color) -> markers.Color:
    if isinstance(value, str) and value.startswith("#") and len(value) == 7:
        try:
            return (int(value[1:3], 16) / 255.0, int(value[3:5], 16) / 255.0, int(value[5:7], 16) / 255.0, 1.0)
        except ValueError:
            return fallback
    return fallback


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _finite(*vals: float) -> bool:
    return all(math.isfinite(v) for v in vals)


def _polygons_overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Separating-axis test of two convex polygons (k, 2); touching counts as not overlapping."""
    for poly in (a, b):
        edges = np.roll(poly, -1, axis=0) - poly
        normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1)
        pa = a @ normals.T
        pb = b @ normals.T
        if np.any((pa.max(axis=0) <= pb.min(axis=0) + 1e-12) | (pb.max(axis=0) <= pa.min(axis=0) + 1e-12)):
            return False  # a separating axis exists
    return True


def _concat_rows(parts: list[np.ndarray]) -> np.ndarray:
    """np.concatenate of structured rows, copied as opaque records when all have one dtype: numpy
    copies a structured dtype with padding (lc_contact's) field by field into a packed dtype, several
    times slower; this keeps the dtype."""
    dtype = parts[0].dtype
    if any(p.dtype != dtype for p in parts):
        return np.concatenate(parts)
    record = np.dtype((np.void, dtype.itemsize))
    return np.concatenate([p.view(record) for p in parts]).view(dtype)


class SimNode(Node):
    """The ``sim`` node. Construct after rclpy.init(); call run() to simulate until shutdown."""

    #: every accepted command is republished on applied/<topic> (docs/contracts.md, bit-exact replay)
    ECHOES_COMMANDS = True

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("sim", **kwargs)
        self._lock = threading.RLock()  # world and command state: stepping thread vs executor thread
        self._lock_waiters = 0  # executor threads waiting for self._lock (see _executor_lock)
        self._waiters_lock = threading.Lock()
        self._warned: dict[str, float] = {}
        self.rejected = 0
        self.last_rejection = ""
        self._published: dict[str, _CountedPublisher] = {}  # diagnostics key (topic without '/') -> publisher
        self._commands: dict[str, _CommandCounts] = {}      # command topic (relative) -> counts
        # ---- parameters ----
        # scene_file first: a scene file supplies the defaults of gravity, damping, elasticity and
        # green_mass (its own settings), which -p on the command line still overrides.
        sf = params.BY_NAME["scene_file"]
        scene_file = str(self.declare_parameter(sf.name, sf.default, params.descriptor(sf)).value)
        self._scene_defaults: dict[str, float] = {}
        if scene_file:
            scene = collide.load_scene(scene_file)
            self._scene_defaults = self._file_values(scene, scene.build())
        for spec in params.SPECS:
            if spec.name == sf.name:
                continue
            default = spec.default
            if spec.name == "frame_prefix":
                default = params.frame_prefix_for(self.get_namespace())
            if spec.name in self._scene_defaults:
                default = min(max(self._scene_defaults[spec.name], spec.lo), spec.hi)
            self._declare(spec, default)
        self._p: dict[str, Any] = {s.name: self.get_parameter(s.name).value for s in params.SPECS}
        for name in ("world_frame", "frame_prefix"):  # the on-set callback checks them from here on
            why = params.check({name: self._p[name]}, set())
            if why:
                raise InvalidParameterValueException(name, self._p[name], why)
        self._refuse_sim_time()
        # ---- world ----
        self._time_offset = 0.0
        self._paused = bool(self._p["start_paused"])
        self.world: collide.World
        self._build_world()  # raises on a bad scene file: the node cannot start without a world
        # ---- publishers ----
        state_qos = qos.state(int(self._p["state_qos_depth"]))
        self._pub_poses = self._publisher(PoseArray, "bodies/poses", state_qos)
        self._pub_states = self._publisher(BodyStates, "bodies/states", state_qos)
        self._pub_contacts = self._publisher(Contacts, "contacts", state_qos)
        self._pub_energy = self._publisher(Energy, "energy", state_qos)
        # one /clock per domain: a sim beside the clock owner leaves it out (publish_clock, read-only)
        self._pub_clock = self._publisher(Clock, "/clock", qos.CLOCK) if self._p["publish_clock"] else None
        self._pub_tf = self._publisher(TFMessage, "/tf", qos.TF)
        self._pub_markers = self._publisher(MarkerArray, "markers", qos.MARKERS)
        self._pub_diag = self._publisher(DiagnosticArray, "/diagnostics", qos.DIAGNOSTICS)
        # ---- commands ----
        self._thrust: dict[str, _Thrust] = {}
        self._thrusters: dict[str, float] = {}   # body -> sim time of the last non-zero mask
        self._cmd_vel: _CmdVel | None = None
        self._springs: dict[str, _SpringEntry] = {}
        self._ext_bodies: set[str] = set()
        self._pending: list[np.ndarray] = []
        self._pending_count = 0
        self.dropped_contacts = 0  # beyond MAX_CONTACTS_PER_MESSAGE, since the start
        self._thrust_subs: dict[str, Any] = {}
        self._echo_pubs: dict[str, _CountedPublisher] = {
            "thrusters": self._publisher(ThrusterCommand, APPLIED + "thrusters", qos.COMMAND),
            "spring": self._publisher(SpringCommand, APPLIED + "spring", qos.COMMAND),
            "cmd_vel": self._publisher(TwistStamped, APPLIED + "cmd_vel", qos.COMMAND),
        }
        self._overrides = QoSOverridingOptions.with_default_policies()
        self._subscribe(ThrusterCommand, "thrusters", "thrusters", self._on_thrusters,
                        qos_overriding_options=self._overrides)
        self._subscribe(SpringCommand, "spring", "spring", self._on_spring, qos_overriding_options=self._overrides)
        self._cmd_vel_sub: Any = None
        self._cmd_vel_sub_stamped: bool | None = None
        self._make_cmd_vel_sub()
        # ---- services ----
        self.create_service(Empty, "~/reset", self._guard_srv("reset", self._srv_reset))
        self.create_service(SetBool, "~/pause", self._guard_srv("pause", self._srv_pause))
        self.create_service(Step, "~/step", self._guard_srv("step", self._srv_step))
        self.create_service(Spawn, "~/spawn", self._guard_srv("spawn", self._srv_spawn))
        self.create_service(Kill, "~/kill", self._guard_srv("kill", self._srv_kill))
        # ---- parameter callbacks ----
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)
        # ---- bookkeeping ----
        self.steps = 0          # since the last (re)build; drives the publish periods
        self.total_steps = 0
        self._step_time_sum = 0.0
        self._step_time_max = 0.0
        self._pub_time_sum = 0.0
        self._window_steps = 0
        self.late_steps = 0
        self.split_steps = 0    # steps C undid that went through in parts (_step_in_parts)
        self._split_tried = False  # whether the last step C undid was tried in parts
        self.failing_since: float | None = None  # sim time of the first of the failed steps in a row
        self._schedule_dirty = True
        self._diag_wall = time.perf_counter()
        self._diag_sim = self.sim_time
        self._diag_cpu = time.process_time()
        self.last_rtf = 0.0
        self.last_cpu = 0.0
        self._periods()
        self._on_topology(deleteall=True)
        self.get_logger().info(
            f"sim ready: {len(self.world.names)} bodies ({', '.join(self._dyn_names[:8])}"
            f"{' ...' if len(self._dyn_names) > 8 else ''}), dt {self._p['time_step']} s, "
            f"RTF {self._p['real_time_factor']}, {'paused' if self._paused else 'running'}, "
            f"frame prefix '{self._p['frame_prefix']}', "
            + ("publishing /clock" if self._pub_clock is not None else "not publishing /clock (publish_clock false)"))

    def _refuse_sim_time(self) -> None:
        """The sim is the clock: use_sim_time would make its node clock follow its own /clock (or, with
        publish_clock false, another sim's), standing still while it is paused. Launch files often set
        use_sim_time for every node, so it is not a start failure: the value is reset to false with an
        error in the log, and the on-set callback refuses true later (_on_set_parameters)."""
        if self.get_parameter("use_sim_time").value is True:
            self.set_parameters([Parameter("use_sim_time", Parameter.Type.BOOL, False)])
            self.get_logger().error(
                "use_sim_time:=true ignored: this node is the sim and publishes the sim time itself; it keeps "
                "wall time (set use_sim_time only on the nodes that consume /clock)")

    def _publisher(self, msg_type: Any, topic: str, profile: Any) -> _CountedPublisher:
        """A counted publisher; its count is ``published/<topic without a leading '/'>`` in /diagnostics."""
        pub = _CountedPublisher(self.create_publisher(msg_type, topic, profile))
        self._published[topic.lstrip("/")] = pub
        return pub

    def _unpublish(self, topic: str, pub: _CountedPublisher) -> None:
        self._published.pop(topic.lstrip("/"), None)
        self.destroy_publisher(pub.pub)

    def _subscribe(self, msg_type: Any, topic: str, kind: str, fn: Callable[[Any], None], **kwargs: Any) -> Any:
        """A command subscription whose messages are counted (``received/<topic>`` ...) and guarded."""
        counts = self._commands.setdefault(topic, _CommandCounts())
        sub = self.create_subscription(msg_type, topic, self._guard(kind, counts, fn), qos.COMMAND, **kwargs)
        counts.restart(sub.topic_name)
        return sub

    def _declare(self, spec: params.Spec, default: Any) -> None:
        """Declare one parameter; an integer given on the command line for a double (-p gravity:=5)
        is taken as that double instead of aborting the start."""
        try:
            self.declare_parameter(spec.name, default, params.descriptor(spec))
        except InvalidParameterTypeException:
            over = getattr(self, "_parameter_overrides", {}).get(spec.name)
            if not (isinstance(default, float) and over is not None and over.type_ == Parameter.Type.INTEGER):
                raise
            self._parameter_overrides[spec.name] = Parameter(spec.name, Parameter.Type.DOUBLE, float(over.value))
            self.declare_parameter(spec.name, default, params.descriptor(spec))

    # ================================================================== world and topology
    @property
    def sim_time(self) -> float:
        return self._time_offset + self.world.time

    def _scene(self) -> collide.Scene:
        if self._p["scene_file"]:
            return collide.load_scene(self._p["scene_file"])
        return collide.default_scene(blocks=int(self._p["blocks"]), green_mass=float(self._p["green_mass"]),
                                     gravity=float(self._p["gravity"]), elasticity=float(self._p["elasticity"]),
                                     damping=float(self._p["damping"]))

    def _build_world(self) -> None:
        scene = self._scene()
        world = scene.build()
        self._colors = {b["name"]: b.get("color") for b in scene.bodies}
        if self._p["scene_file"]:
            # A scene file brings its own settings; a parameter applies only where it differs from the file.
            for key, setter in (("gravity", self._apply_gravity), ("damping", self._apply_damping),
                                ("elasticity", self._apply_elasticity), ("green_mass", self._apply_green_mass)):
                if self._p[key] != self._scene_defaults[key]:
                    setter(world, self._p[key])
        self.world = world

    @staticmethod
    def _file_values(scene: collide.Scene, world: collide.World) -> dict[str, float]:
        s = world.settings
        vals = {"gravity": -float(s["gravity"][1]), "damping": float(s["damping"])}
        dyn = [b for b in scene.bodies if not b.get("static")]
        vals["elasticity"] = float(dyn[0]["elasticity"]) if dyn else 1.0
        green = [b for b in scene.bodies if b["name"] == "block1"]
        vals["green_mass"] = float(green[0]["mass"]) if green else 1.0
        return vals

    @staticmethod
    def _apply_gravity(world: collide.World, g: float) -> None:
        world.set_gravity((0.0, -g))

    @staticmethod
    def _apply_damping(world: collide.World, k: float) -> None:
        world.set_damping(k)

    @staticmethod
    def _apply_elasticity(world: collide.World, e: float) -> None:
        world.set_elasticity(e)

    def _apply_green_mass(self, world: collide.World, m: float) -> None:
        if "block1" in world:
            world.body("block1").mass = m
        else:
            self._warn("green_mass", "green_mass: this world has no body 'block1'; nothing to apply")

    def _on_topology(self, deleteall: bool = False) -> None:
        """Recompute everything that depends on the body set (after build, spawn, kill, frame change)."""
        w = self.world
        self._names = w.names
        self._ids = np.array(w.ids, dtype=np.int64)
        static = np.array(w.static_mask, dtype=bool)
        self._dyn_rows = np.flatnonzero(~static)
        self._dyn_names = [self._names[i] for i in self._dyn_rows]
        self._row_of = {n: i for i, n in enumerate(self._names)}
        self._name_of_id = {int(i): n for i, n in zip(self._ids, self._names)}
        self._bodies = {n: w.body(n) for n in self._names}
        self._masses = np.array(w.masses)
        self._inertias = np.array(w.inertias)
        frame = self._p["world_frame"]
        self._cdr_poses = cdr.PoseArrayCdr(len(self._dyn_rows), frame)
        self._cdr_states = cdr.BodyStatesCdr(self._dyn_names, frame)
        prefix = self._p["frame_prefix"]
        self._cdr_tf = cdr.TFMessageCdr(frame, [prefix + n for n in self._dyn_names])
        self._cdr_contacts = cdr.ContactsCdr(frame, self._name_of_id)
        outlines, colors = [], []
        for i, n in enumerate(self._names):
            outlines.append(self._bodies[n].local_vertices())
            colors.append(_hex_color(self._colors.get(n), markers.body_color(n, i, bool(static[i]))))
        ids = [int(i) for i in self._ids]
        self._cdr_markers = markers.MarkerArrayCdr(frame, ids, outlines, colors)
        # per-body thrust subscriptions for the first max_body_topics dynamic bodies
        want = set(self._dyn_names[: int(self._p["max_body_topics"])])
        for name in list(self._thrust_subs):
            if name not in want:
                # the counts go with the topic: a later body of the same name starts from zero
                self.destroy_subscription(self._thrust_subs.pop(name))
                self._commands.pop(f"{name}/thrust", None)
                self._unpublish(f"{APPLIED}{name}/thrust", self._echo_pubs.pop(f"{name}/thrust"))
        for name in self._dyn_names:
            if name in want and name not in self._thrust_subs and params.valid_body_name(name) is None:
                self._echo_pubs[f"{name}/thrust"] = self._publisher(
                    WrenchStamped, f"{APPLIED}{name}/thrust", qos.COMMAND)
                self._thrust_subs[name] = self._subscribe(WrenchStamped, f"{name}/thrust", "thrust",
                                                          self._thrust_callback(name))
        # forget commands and springs of bodies that are gone
        for name in [n for n in self._thrust if n not in self._row_of]:
            del self._thrust[name]
        for name in [n for n in self._thrusters if n not in self._row_of]:
            del self._thrusters[name]
        self._ext_bodies &= set(self._names)
        for sname in [s for s, e in self._springs.items() if e.body not in self._row_of]:
            del self._springs[sname]
        # DELETEALL heads the new scene's message: sent on its own, the depth-1 history could replace it
        # with the scene before a subscriber (RViz, the live view) took it
        self._publish_markers(markers.MarkerArrayCdr(frame, ids, outlines, colors, lead=[markers.DELETE_ALL])
                              if deleteall else None)

    def _periods(self) -> None:
        dt = float(self._p["time_step"])

        def every(rate: float) -> int:
            return 0 if rate <= 0 else max(1, int(round(1.0 / (rate * dt))))
        self._every_state = every(self._p["state_rate"])
        self._every_tf = every(self._p["tf_rate"])
        self._every_marker = every(self._p["marker_rate"])
        self._every_clock = every(self._p["clock_rate"])

    # ================================================================== warnings and guards
    def _warn(self, key: str, msg: str) -> None:
        now = time.monotonic()
        if now - self._warned.get(key, -1e9) >= WARN_PERIOD:
            self._warned[key] = now
            self.get_logger().warning(msg)

    def _reject(self, key: str, msg: str) -> None:
        """A command was refused: count it, remember why, warn (throttled per key)."""
        self.rejected += 1
        self.last_rejection = msg
        self._warn(key, f"rejected: {msg}")

    @contextmanager
    def _executor_lock(self) -> Iterator[None]:
        """self._lock for a callback. Python's lock is not fair: a stepping loop that releases and
        retakes it at once can keep a waiting thread out for seconds (at real_time_factor 0 the
        command queues overflowed). So a callback says it is waiting, and the loop then yields."""
        with self._waiters_lock:
            self._lock_waiters += 1
        try:
            self._lock.acquire()
        finally:
            with self._waiters_lock:
                self._lock_waiters -= 1
        try:
            yield
        finally:
            self._lock.release()

    def _guard(self, kind: str, counts: _CommandCounts, fn: Callable[[Any], None]) -> Callable[[Any, Any], None]:
        """The subscription callback: count the message, run ``fn`` under the lock; an exception
        is a rejection. Accepted = not rejected (every handler either rejects or echoes)."""
        def wrapped(msg: Any, info: Any) -> None:
            try:
                self._note_sequence(counts, info.get("publication_sequence_number"))
            except Exception as exc:  # the graph query; the command itself is still handled
                self._warn(f"{kind}:sequence", f"{kind}: cannot check the sequence number: {exc}")
            with self._executor_lock():
                counts.received += 1
                before = self.rejected
                try:
                    fn(msg)
                except Exception as exc:  # nothing a peer sends may stop the simulation
                    self._reject(f"{kind}:exception", f"{kind} command failed: {type(exc).__name__}: {exc}")
                if self.rejected != before:
                    counts.rejected += 1
                else:
                    counts.accepted += 1
        return wrapped

    def _note_sequence(self, counts: _CommandCounts, seq: Any) -> None:
        """Count the messages DDS dropped before the node took them (a full depth-10 queue, or the
        publisher's own history overwritten before delivery): a gap in the publisher's sequence
        numbers. The rmw does not say which publisher sent a message, so a gap is only counted when
        the topic has a single publisher, the same one as for the previous message (a graph query,
        only on a gap: a new publisher starts its own numbering)."""
        if not isinstance(seq, int) or seq <= 0:
            return  # an rmw without publication sequence numbers
        if seq == counts.last_seq + 1:
            counts.last_seq = seq
            return
        infos = self.get_publishers_info_by_topic(counts.topic)
        writer = tuple(infos[0].endpoint_gid) if len(infos) == 1 else None
        if writer is not None and writer == counts.writer and seq > counts.last_seq + 1:
            counts.lost += seq - counts.last_seq - 1
        counts.writer, counts.last_seq = writer, seq

    def _guard_srv(self, kind: str, fn: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
        def wrapped(req: Any, resp: Any) -> Any:
            try:
                with self._executor_lock():
                    return fn(req, resp)
            except Exception as exc:
                msg = f"{kind} failed: {type(exc).__name__}: {exc}"
                self._warn(f"srv:{kind}", msg)
                if hasattr(resp, "success"):
                    resp.success = False
                    resp.message = msg
                return resp
        return wrapped

    # ================================================================== command callbacks
    def _echo(self, topic: str, msg: Any) -> None:
        """Republish an accepted command on applied/<topic>, stamped with the sim time at which the
        next step starts (callbacks run between steps), i.e. the first step it acts on."""
        sec, ns = cdr.split_time(self.sim_time)
        msg.header.stamp = Time(sec=sec, nanosec=ns)
        self._echo_pubs[topic].publish(msg)

    def _thrust_callback(self, name: str) -> Callable[[WrenchStamped], None]:
        def cb(msg: WrenchStamped) -> None:
            self._on_thrust(name, msg)
        return cb

    def _on_thrust(self, name: str, msg: WrenchStamped) -> None:
        f, t = msg.wrench.force, msg.wrench.torque
        if not _finite(f.x, f.y, t.z):
            self._reject(f"thrust:{name}:nan", f"{name}/thrust: force ({f.x}, {f.y}) N / torque {t.z} N*m "
                         "is not finite")
            return
        lim = float(self._p["max_thrust"])
        if math.hypot(f.x, f.y) > lim or abs(t.z) > lim:
            self._reject(f"thrust:{name}:big", f"{name}/thrust: |force| {math.hypot(f.x, f.y):.6g} N or "
                         f"|torque| {abs(t.z):.6g} N*m exceeds max_thrust {lim:g}")
            return
        frame = msg.header.frame_id
        if frame in ("", name, self._p["frame_prefix"] + name):
            in_world = False
        elif frame == self._p["world_frame"]:
            in_world = True
        else:
            body_frames = " / ".join(f"'{f}'" for f in dict.fromkeys(("", name, self._p["frame_prefix"] + name)))
            self._reject(f"thrust:{name}:frame", f"{name}/thrust: frame_id '{frame}' is neither {body_frames} "
                         f"(body frame) nor '{self._p['world_frame']}' (world frame)")
            return
        if name not in self._row_of:
            self._reject(f"thrust:{name}:gone", f"{name}/thrust: no body named '{name}'")
            return
        if f.x == 0.0 and f.y == 0.0 and t.z == 0.0:
            self._thrust.pop(name, None)
        else:
            self._thrust[name] = _Thrust(f.x, f.y, t.z, in_world, self.sim_time)
        self._echo(f"{name}/thrust", msg)

    def _on_thrusters(self, msg: ThrusterCommand) -> None:
        name = msg.body
        if name not in self._row_of:
            self._reject(f"thrusters:unknown:{name}", f"thrusters: no body named '{name}' "
                         f"(dynamic bodies: {', '.join(self._dyn_names[:12])})")
            return
        body = self._bodies[name]
        count = len(body.thrusters) if not body.static else 0
        firing = list(msg.firing)
        if len(firing) > count:
            self._reject(f"thrusters:count:{name}", f"thrusters: body '{name}' has {count} thrusters, "
                         f"got {len(firing)} firing flags")
            return
        mask = 0
        for i, on in enumerate(firing):
            if on:
                mask |= 1 << i
        body.set_thruster_mask(mask)
        if mask:
            self._thrusters[name] = self.sim_time
        else:
            self._thrusters.pop(name, None)
        self._echo("thrusters", msg)

    def _on_cmd_vel(self, msg: Any) -> None:
        tw = msg.twist if isinstance(msg, TwistStamped) else msg
        vx, vy, wz = tw.linear.x, tw.linear.y, tw.angular.z
        if not _finite(vx, vy, wz):
            self._reject("cmd_vel:nan", f"cmd_vel: ({vx}, {vy}, {wz}) is not finite")
            return
        if max(abs(vx), abs(vy), abs(wz)) > MAX_CMD_SPEED:
            self._reject("cmd_vel:big", f"cmd_vel: ({vx:.6g}, {vy:.6g}, {wz:.6g}) exceeds {MAX_CMD_SPEED:g} "
                         "m/s or rad/s")
            return
        body = self._p["cmd_vel_body"]
        if body not in self._row_of or self._bodies[body].static:
            self._reject("cmd_vel:body", f"cmd_vel: cmd_vel_body '{body}' is not a dynamic body of this world")
            return
        self._cmd_vel = _CmdVel(vx, vy, wz, self.sim_time)
        self._echo("cmd_vel", msg if isinstance(msg, TwistStamped) else TwistStamped(twist=msg))

    def _on_spring(self, msg: SpringCommand) -> None:
        sname = msg.name or "mouse"
        if msg.release:
            entry = self._springs.pop(sname, None)
            if entry is None:
                self._reject(f"spring:release:{sname}", f"spring: release of '{sname}', which does not exist")
                return
            entry.spring.remove()
            self._echo("spring", msg)
            return
        body = msg.body
        if body not in self._row_of:
            self._reject(f"spring:body:{body}", f"spring '{sname}': no body named '{body}'")
            return
        if self._bodies[body].static:
            self._reject(f"spring:static:{body}", f"spring '{sname}': body '{body}' is static")
            return
        bp, tg = msg.body_point, msg.target
        nums = (bp.x, bp.y, tg.x, tg.y, msg.stiffness, msg.damping, msg.rest_length)
        if not _finite(*nums):
            self._reject(f"spring:nan:{sname}", f"spring '{sname}': non-finite value in body_point "
                         f"({bp.x}, {bp.y}), target ({tg.x}, {tg.y}), stiffness {msg.stiffness}, "
                         f"damping {msg.damping} or rest_length {msg.rest_length}")
            return
        if msg.stiffness < 0 or msg.damping < 0 or msg.rest_length < 0:
            self._reject(f"spring:neg:{sname}", f"spring '{sname}': stiffness {msg.stiffness}, damping "
                         f"{msg.damping} and rest_length {msg.rest_length} must be >= 0")
            return
        entry = self._springs.get(sname)
        point = (bp.x, bp.y)
        try:
            if entry is not None and entry.body == body and entry.point == point:
                d = entry.spring.definition
                k = msg.stiffness if msg.stiffness > 0 else d["stiffness"]
                if (k, msg.damping, msg.rest_length) != (d["stiffness"], d["damping"], d["rest_length"]):
                    entry.spring.set_params(k, msg.damping, msg.rest_length)
                entry.spring.target = (tg.x, tg.y)
                self._echo("spring", msg)
                return
            k = msg.stiffness if msg.stiffness > 0 else (entry.spring.definition["stiffness"] if entry else 3.0)
            off = self._bodies[body].center_offset
            new = self.world.add_spring(body, (bp.x + off[0], bp.y + off[1]), None, (tg.x, tg.y), k,
                                        msg.damping, msg.rest_length)
        except (CollideError, ValueError, TypeError, KeyError) as exc:
            self._reject(f"spring:c:{sname}", f"spring '{sname}': {exc}")
            return
        if entry is not None:
            entry.spring.remove()
        self._springs[sname] = _SpringEntry(new, body, point)
        self._echo("spring", msg)

    def _make_cmd_vel_sub(self) -> None:
        stamped = bool(self._p["cmd_vel_stamped"])
        if self._cmd_vel_sub is not None and self._cmd_vel_sub_stamped == stamped:
            return
        if self._cmd_vel_sub is not None:
            self.destroy_subscription(self._cmd_vel_sub)
        self._cmd_vel_sub = self._subscribe(TwistStamped if stamped else Twist, "cmd_vel", "cmd_vel",
                                            self._on_cmd_vel, qos_overriding_options=self._overrides)
        self._cmd_vel_sub_stamped = stamped

    # ================================================================== services
    def _srv_reset(self, req: Empty.Request, resp: Empty.Response) -> Empty.Response:
        self.reset()
        return resp

    def reset(self) -> None:
        self._springs.clear()  # the springs go with the old world
        self.failing_since = None
        self._thrust.clear()
        self._thrusters.clear()
        self._cmd_vel = None
        self._ext_bodies.clear()
        self._pending, self._pending_count = [], 0
        offset = self.sim_time  # the clock keeps running forward across a reset
        self._build_world()
        self._time_offset = offset
        self.steps = 0
        self._schedule_dirty = True
        self._on_topology(deleteall=True)
        self._publish_state()
        self.get_logger().info(f"reset: {len(self._dyn_names)} dynamic bodies at sim time {self.sim_time:.3f} s")

    def _srv_pause(self, req: SetBool.Request, resp: SetBool.Response) -> SetBool.Response:
        self._paused = bool(req.data)
        self._schedule_dirty = True
        resp.success = True
        resp.message = "paused" if self._paused else "running"
        return resp

    def _srv_step(self, req: Step.Request, resp: Step.Response) -> Step.Response:
        if not self._paused:
            resp.success = False
            resp.message = "~/step works only while paused; call ~/pause with data: true first"
        elif req.steps > MAX_STEPS_PER_CALL:
            resp.success = False
            resp.message = f"steps {req.steps} exceeds {MAX_STEPS_PER_CALL} per call"
        else:
            done = 0
            for _ in range(req.steps):
                if not self.step_once():
                    break
                done += 1
            resp.success = done == req.steps
            resp.message = f"stepped {done} x {self._p['time_step']} s" + (
                "" if resp.success else f"; stopped: {self.last_rejection}")
        sec, ns = cdr.split_time(self.sim_time)
        resp.sim_time = Time(sec=sec, nanosec=ns)
        return resp

    def _srv_spawn(self, req: Spawn.Request, resp: Spawn.Response) -> Spawn.Response:
        resp.success = False
        name = req.name
        if not name:
            k = 1
            while f"body{k}" in self._row_of:
                k += 1
            name = f"body{k}"
        why = params.valid_body_name(name)
        if why:
            resp.message = why
            return resp
        if name in self._row_of:
            resp.message = f"a body named '{name}' already exists"
            return resp
        if len(req.vertices) > 0:
            if len(req.vertices) % 2:
                resp.message = f"vertices must hold x,y pairs; got {len(req.vertices)} numbers"
                return resp
            verts = np.asarray(req.vertices, dtype=np.float64).reshape(-1, 2)
        else:
            w, h = float(req.width), float(req.height)
            if w == 0.0 and h == 0.0:
                w = h = 1.0
            if not (_finite(w, h) and w > 0 and h > 0):
                resp.message = f"box width {w} and height {h} must be finite and > 0"
                return resp
            verts = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
        p, q, tw = req.pose.position, req.pose.orientation, req.twist
        nums = (p.x, p.y, q.x, q.y, q.z, q.w, tw.linear.x, tw.linear.y, tw.angular.z, req.mass, req.elasticity)
        if not _finite(*nums):
            resp.message = "pose, twist, mass and elasticity must be finite"
            return resp
        angle = _yaw(q)
        mass = float(req.mass) if req.mass != 0.0 else 1.0
        if np.all(np.isfinite(verts)) and len(verts) >= 3:
            c, s = math.cos(angle), math.sin(angle)
            placed = verts @ np.array([[c, s], [-s, c]]) + np.array([p.x, p.y])
            lo, hi = placed.min(axis=0), placed.max(axis=0)
            outside = self._outside_static_extent(lo, hi)
            if outside:
                resp.message = f"spawn '{name}' at ({p.x:g}, {p.y:g}) {outside}"
                self._warn(f"spawn:outside:{name}", f"rejected: {resp.message}")
                return resp
            for other, body in self._bodies.items():
                ov = body.world_vertices()
                if np.any(ov.max(axis=0) <= lo) or np.any(ov.min(axis=0) >= hi):
                    continue
                if _polygons_overlap(placed, ov):
                    resp.message = f"spawn '{name}' at ({p.x:g}, {p.y:g}) overlaps body '{other}'"
                    self._warn(f"spawn:overlap:{name}", f"rejected: {resp.message}")
                    return resp
        try:
            self.world.add_body(verts, position=(p.x, p.y), angle=angle, velocity=(tw.linear.x, tw.linear.y),
                                angular_velocity=tw.angular.z, mass=mass, elasticity=float(req.elasticity),
                                name=name)
        except (CollideError, ValueError, TypeError) as exc:
            resp.message = f"spawn '{name}': {exc}"
            self._warn(f"spawn:c:{name}", f"rejected: {resp.message}")
            return resp
        self._on_topology()
        resp.success = True
        resp.name = name
        resp.message = f"spawned '{name}'"
        return resp

    def _outside_static_extent(self, lo: np.ndarray, hi: np.ndarray) -> str | None:
        """Why a body with bounds [lo, hi] lies (partly) outside the box the static bodies enclose, or None.

        The static bodies (walls, floor, fixed obstacles) bound the world; a body placed beyond them would
        fall or fly away for ever. A world without static bodies has no such bound."""
        extent = [self._bodies[n].world_vertices() for n in self._names if self._bodies[n].static]
        if not extent:
            return None
        pts = np.vstack(extent)
        smin, smax = pts.min(axis=0), pts.max(axis=0)
        if np.all(lo >= smin) and np.all(hi <= smax):
            return None
        return (f"lies outside the box the static bodies enclose (x in [{smin[0]:g}, {smax[0]:g}], "
                f"y in [{smin[1]:g}, {smax[1]:g}])")

    def _srv_kill(self, req: Kill.Request, resp: Kill.Response) -> Kill.Response:
        if req.name not in self._row_of:
            resp.success = False
            resp.message = f"no body named '{req.name}'"
            return resp
        if self._bodies[req.name].static and not self._p["allow_kill_static"]:
            resp.success = False
            resp.message = (f"'{req.name}' is static (a wall of the box or a fixed body) and stays; "
                            "set parameter allow_kill_static to true to remove it")
            self._warn(f"kill:static:{req.name}", f"rejected: {resp.message}")
            return resp
        self.world.remove_body(req.name)
        self._springs = {s: e for s, e in self._springs.items() if e.body != req.name}
        if self._cmd_vel is not None and self._p["cmd_vel_body"] == req.name:
            self._cmd_vel = None
        self._on_topology(deleteall=True)  # its marker must go from RViz too
        resp.success = True
        resp.message = f"killed '{req.name}'"
        return resp

    # ================================================================== parameters
    def _on_set_parameters(self, plist: list[Parameter]) -> SetParametersResult:
        if any(p.name == "use_sim_time" and p.value is True for p in plist):
            why = ("use_sim_time: the sim publishes the sim time itself and keeps wall time; set use_sim_time "
                   "on the nodes that consume /clock")
            self._warn("param:use_sim_time", f"parameter rejected: {why}")
            return SetParametersResult(successful=False, reason=why)
        cand = {p.name: p.value for p in plist if p.name in params.BY_NAME}
        why = params.check(cand, set(self._dyn_names))
        if why:
            self._warn(f"param:{why[:40]}", f"parameter rejected: {why}")
            return SetParametersResult(successful=False, reason=why)
        return SetParametersResult(successful=True)

    def _post_set_parameters(self, plist: list[Parameter]) -> None:
        with self._executor_lock():
            self._post_set_locked(plist)

    def _post_set_locked(self, plist: list[Parameter]) -> None:
        for prm in plist:
            if prm.name not in params.BY_NAME:
                continue
            self._p[prm.name] = prm.value
            try:
                self._apply_param(prm.name, prm.value)
            except Exception as exc:  # the value passed the checks; report what C said anyway
                self._warn(f"param-apply:{prm.name}", f"parameter {prm.name}={prm.value}: {exc}")

    def _apply_param(self, name: str, value: Any) -> None:
        if name == "gravity":
            self._apply_gravity(self.world, float(value))
        elif name == "damping":
            self._apply_damping(self.world, float(value))
        elif name == "elasticity":
            self._apply_elasticity(self.world, float(value))
        elif name == "green_mass":
            self._apply_green_mass(self.world, float(value))
            self._masses = np.array(self.world.masses)
            self._inertias = np.array(self.world.inertias)
        elif name in ("time_step", "state_rate", "tf_rate", "marker_rate", "clock_rate"):
            self._periods()
            self._schedule_dirty = True
        elif name == "real_time_factor":
            self._schedule_dirty = True
        elif name in ("world_frame", "frame_prefix"):
            self._on_topology()
        elif name == "cmd_vel_stamped":
            self._make_cmd_vel_sub()
        elif name == "cmd_vel_body":
            self._cmd_vel = None

    # ================================================================== stepping
    def _apply_forces(self) -> None:
        """External force/torque of every commanded body for the coming step; expired commands dropped."""
        now = self.sim_time
        timeout = float(self._p["command_timeout"])
        if timeout > 0:
            for name in [n for n, c in self._thrust.items() if now - c.stamp > timeout]:
                del self._thrust[name]
            for name in [n for n, t in self._thrusters.items() if now - t > timeout]:
                del self._thrusters[name]
                if name in self._bodies:
                    self._bodies[name].set_thruster_mask(0)
            if self._cmd_vel is not None and now - self._cmd_vel.stamp > timeout:
                self._cmd_vel = None
        if not self._thrust and self._cmd_vel is None and not self._ext_bodies:
            return
        st = self.world.state
        total: dict[str, list[float]] = {}
        for name, c in self._thrust.items():
            fx, fy = c.fx, c.fy
            if not c.world:
                a = st[self._row_of[name], 2]
                ca, sa = math.cos(a), math.sin(a)
                fx, fy = ca * c.fx - sa * c.fy, sa * c.fx + ca * c.fy
            total[name] = [fx, fy, c.torque]
        cv = self._cmd_vel
        name = self._p["cmd_vel_body"]
        if cv is not None and name in self._row_of:
            r = self._row_of[name]
            x = st[r]
            m, inertia = self._masses[r], self._inertias[r]
            ca, sa = math.cos(x[2]), math.sin(x[2])
            vdx, vdy = ca * cv.vx - sa * cv.vy, sa * cv.vx + ca * cv.vy  # body-frame command -> world
            k = float(self._p["cmd_vel_linear_gain"])
            fx, fy = m * k * (vdx - x[3]), m * k * (vdy - x[4])
            fmax = m * float(self._p["cmd_vel_max_accel"])
            fn = math.hypot(fx, fy)
            if fn > fmax:
                fx, fy = fx * fmax / fn, fy * fmax / fn
            fy += m * float(self._p["gravity"])  # hold the body up against gravity while driven
            tau = inertia * float(self._p["cmd_vel_angular_gain"]) * (cv.wz - x[5])
            tmax = inertia * float(self._p["cmd_vel_max_angular_accel"])
            tau = max(-tmax, min(tmax, tau))
            acc = total.setdefault(name, [0.0, 0.0, 0.0])
            acc[0] += fx
            acc[1] += fy
            acc[2] += tau
        for name in self._ext_bodies - total.keys():
            if name in self._bodies:
                self._bodies[name].set_external((0.0, 0.0), 0.0)
        for name, (fx, fy, tau) in total.items():
            self._bodies[name].set_external((fx, fy), tau)
        self._ext_bodies = set(total)

    def _step_in_parts(self, dt: float) -> None:
        """world.step(dt) and its impacts kept; a step C undoes is taken as halves instead (recursively,
        SPLIT_DEPTH levels), unless its work counters say it was costly (SPLIT_MAX_WORK). Raises C's
        error if a part of dt / 2**SPLIT_DEPTH or a costly part fails; the parts before it stay taken
        (their time too: the sim clock then leaves the time_step grid)."""
        self._split_tried = False
        try:
            self.world.step(dt)
            self._collect_collisions()
            return
        except CollideError as exc:
            why = str(exc)
            if not self._worth_splitting():
                raise
        self._split_tried = True
        t = self.sim_time
        parts = self._halves(dt, 1)
        self.split_steps += 1
        self._warn("split", f"physics step at t={t:.6f} s was undone by C ({why}); "
                   f"taken as {parts} parts instead")

    def _worth_splitting(self) -> bool:
        """Whether the step C just undid was cheap enough to be tried again in parts (its counters)."""
        c = self.world.counters(last=True)
        return (all(c[k] <= v for k, v in SPLIT_MAX_WORK.items())
                and c["solver_work"] <= SPLIT_MAX_SOLVER_WORK_PER_BODY * max(len(self.world), 1))

    def _halves(self, dt: float, depth: int) -> int:
        """Two steps of dt / 2, each halved again if C undoes it; returns the number of parts taken."""
        n = 0
        for _ in range(2):
            try:
                self.world.step(dt / 2)
                self._collect_collisions()  # each part's impacts: the world keeps only the last part's
                n += 1
            except CollideError:
                if depth >= SPLIT_DEPTH or not self._worth_splitting():
                    raise
                n += self._halves(dt / 2, depth + 1)
        return n

    def step_once(self) -> bool:
        """One physics step and whatever publishing is due; False if the step failed (and was undone)."""
        self._apply_forces()
        t0 = time.perf_counter()
        try:
            self._step_in_parts(float(self._p["time_step"]))
        except CollideError as exc:
            # C undid the step. Drop every command and every spring made over ROS, so that what a
            # peer sent cannot keep the world from stepping (the scene's own forces stay).
            how = (f"also in parts of time_step / {2 ** SPLIT_DEPTH}" if self._split_tried
                   else "not split (a costly step: C's work counters past the node's split limits)")
            self._reject("step", f"physics step at t={self.sim_time:.6f} s failed, {how} ({exc}); all thrust, "
                         f"thruster and cmd_vel commands and springs ({', '.join(self._springs) or 'none'}) "
                         "dropped")
            self._thrust.clear()
            self._cmd_vel = None
            for name in list(self._thrusters):
                self._bodies[name].set_thruster_mask(0)
            self._thrusters.clear()
            for entry in self._springs.values():
                entry.spring.remove()
            self._springs.clear()
            self._apply_forces()
            if self.failing_since is None:
                self.failing_since = self.sim_time
            return False
        self.failing_since = None
        t1 = time.perf_counter()
        self.steps += 1
        self.total_steps += 1
        self._window_steps += 1
        dt_step = t1 - t0
        self._step_time_sum += dt_step
        self._step_time_max = max(self._step_time_max, dt_step)
        s = self.steps
        if self._pub_clock is not None and self._every_clock and s % self._every_clock == 0:
            sec, ns = cdr.split_time(self.sim_time)
            self._pub_clock.publish(cdr.clock_cdr(sec, ns))
        if s % self._every_state == 0:
            self._publish_state()
        if self._every_tf and s % self._every_tf == 0:
            self._publish_tf()
        if self._every_marker and s % self._every_marker == 0:
            self._publish_markers()
        self._pub_time_sum += time.perf_counter() - t1
        return True

    # ================================================================== publishing
    def _stamp(self) -> tuple[int, int]:
        return cdr.split_time(self.sim_time)

    def _publish_state(self) -> None:
        sec, ns = self._stamp()
        st = self.world.state[self._dyn_rows]
        poses = cdr.poses_from_state(st)
        self._pub_poses.publish(self._cdr_poses.encode(sec, ns, poses))
        self._pub_states.publish(self._cdr_states.encode(sec, ns, poses, cdr.twists_from_state(st)))
        stamp = Time(sec=sec, nanosec=ns)
        frame = self._p["world_frame"]
        e = self.world.energy
        em = Energy()
        em.header.stamp = stamp
        em.header.frame_id = frame
        em.translational, em.rotational = float(e.translational), float(e.rotational)
        em.gravitational, em.spring, em.total = float(e.gravitational), float(e.spring), float(e.total)
        em.linear_momentum = Vector3(x=float(e.linear_momentum[0]), y=float(e.linear_momentum[1]), z=0.0)
        em.angular_momentum = float(e.angular_momentum)
        self._pub_energy.publish(em)
        self._pub_contacts.publish(self._cdr_contacts.encode(sec, ns, self._take_contacts()))

    def _collect_collisions(self) -> None:
        """Keep the impacts of every step until the next contacts publish (they last one step)."""
        c = self.world.contacts
        if len(c):
            hits = c[c["kind"] == collide.COLLISION]
            room = MAX_CONTACTS_PER_MESSAGE - self._pending_count
            if len(hits) > room:
                self.dropped_contacts += len(hits) - room
                hits = hits[:room]
            if len(hits):
                self._pending.append(hits.copy())
                self._pending_count += len(hits)

    def _take_contacts(self) -> np.ndarray:
        """Impacts since the last publish, then the resting contacts of the current step (at most
        MAX_CONTACTS_PER_MESSAGE in all)."""
        c = self.world.contacts
        resting = c[c["kind"] != collide.COLLISION]
        room = MAX_CONTACTS_PER_MESSAGE - self._pending_count
        if len(resting) > room:
            self.dropped_contacts += len(resting) - room
            resting = resting[:room]
        parts = [*self._pending, resting]
        self._pending = []
        self._pending_count = 0
        return _concat_rows(parts) if len(parts) > 1 else resting.copy()

    def _publish_tf(self) -> None:
        sec, ns = self._stamp()
        st = self.world.state[self._dyn_rows]
        self._pub_tf.publish(self._cdr_tf.encode(sec, ns, cdr.poses_from_state(st)))

    def _publish_markers(self, template: markers.MarkerArrayCdr | None = None) -> None:
        """The bodies, springs and contacts; ``template``: another body template (one with DELETEALL)."""
        sec, ns = self._stamp()
        poses = cdr.poses_from_state(self.world.state)
        ends = [(np.asarray(a), np.asarray(b)) for a, b in (e.spring.endpoints() for e in self._springs.values())]
        extras = markers.spring_markers(ends)
        c = self.world.contacts
        extras += markers.contact_markers(np.array(c["point"]).reshape(-1, 2), np.array(c["normal"]).reshape(-1, 2))
        self._pub_markers.publish((template or self._cdr_markers).encode(sec, ns, poses, extras))

    def _publish_diagnostics(self) -> None:
        wall, cpu, sim = time.perf_counter(), time.process_time(), self.sim_time
        dw = max(wall - self._diag_wall, 1e-9)
        self.last_rtf = (sim - self._diag_sim) / dw
        self.last_cpu = (cpu - self._diag_cpu) / dw
        n = max(self._window_steps, 1)
        target = float(self._p["real_time_factor"])
        st = DiagnosticStatus()
        st.name = physics_status(self.get_fully_qualified_name())
        st.hardware_id = "libcollide " + collide.version()
        slow = target > 0 and not self._paused and self.last_rtf < 0.9 * target
        st.level = DiagnosticStatus.WARN if slow else DiagnosticStatus.OK
        st.message = ("paused" if self._paused else
                      f"real-time factor {self.last_rtf:.3f} (target {target:g})" + (" - falling behind" if slow else ""))
        if self.failing_since is not None:
            # the world state itself cannot be stepped (commands and springs are gone already):
            # only a reset, a parameter change or a new command can get it going again
            st.level = DiagnosticStatus.ERROR
            st.message = f"physics steps failing since t={self.failing_since:.6f} s: {self.last_rejection}"
        vals = {
            "real_time_factor": f"{self.last_rtf:.4f}", "target_real_time_factor": f"{target:g}",
            "step_time_mean_ms": f"{1e3 * self._step_time_sum / n:.4f}",
            "step_time_max_ms": f"{1e3 * self._step_time_max:.4f}",
            "publish_time_mean_ms": f"{1e3 * self._pub_time_sum / n:.4f}",
            "steps_per_second": f"{self._window_steps / dw:.1f}", "late_steps": str(self.late_steps),
            "cpu_percent": f"{100 * self.last_cpu:.1f}", "bodies": str(len(self._names)),
            "dynamic_bodies": str(len(self._dyn_names)), "contacts": str(len(self.world.contacts)),
            "sim_time": f"{sim:.6f}", "paused": str(self._paused).lower(),
            "rejected_commands": str(self.rejected), "last_rejection": self.last_rejection,
            "dropped_contacts": str(self.dropped_contacts), "split_steps": str(self.split_steps),
        }
        vals.update(self._count_values())
        st.values = [KeyValue(key=k, value=v) for k, v in vals.items()]
        msg = DiagnosticArray()
        sec, ns = self._stamp()
        msg.header.stamp = Time(sec=sec, nanosec=ns)
        msg.status = [st]
        self._pub_diag.publish(msg)
        self._diag_wall, self._diag_cpu, self._diag_sim = wall, cpu, sim
        self._step_time_sum = self._step_time_max = self._pub_time_sum = 0.0
        self._window_steps = 0

    def _count_values(self) -> dict[str, str]:
        """published/<topic> and subscribers/<topic> for every publisher (published/diagnostics: the
        ones before this message), then received/, accepted/, rejected/, lost/<topic> for every command topic (docs/ros_interface.md)."""
        vals = {f"published/{k}": str(p.count) for k, p in sorted(self._published.items())}
        # the writer's matched readers, not the graph's subscriptions: a subscription the graph
        # already shows may not be matched yet, and gets nothing published before it is
        vals.update({f"subscribers/{k}": str(p.pub.get_subscription_count())
                     for k, p in sorted(self._published.items())})
        for topic, c in sorted(self._commands.items()):
            vals[f"received/{topic}"] = str(c.received)
            vals[f"accepted/{topic}"] = str(c.accepted)
            vals[f"rejected/{topic}"] = str(c.rejected)
            vals[f"lost/{topic}"] = str(c.lost)
        return vals

    # ================================================================== main loop
    def _spin(self, ex: SingleThreadedExecutor) -> None:
        """Executor thread: commands, services and parameters are handled as they arrive (under the
        lock). It sleeps inside rcl_wait (GIL released) while nothing arrives, so the size of the
        wait set (per-body topics) costs nothing per physics step."""
        while self.context.ok():
            try:
                ex.spin_once(timeout_sec=0.1)
            except (ExternalShutdownException, ShutdownException):
                return
            except Exception as exc:  # a callback outside our guards (e.g. rclpy's parameter services)
                self._warn("executor", f"executor: {type(exc).__name__}: {exc}")

    def run(self, executor: SingleThreadedExecutor | None = None) -> None:
        """Simulate until the context shuts down (Ctrl-C, SIGTERM, rclpy.shutdown()).

        The calling thread steps the world on a sleep-until schedule (step k is due at
        ref + k * time_step / real_time_factor, wall time); a second thread runs the executor."""
        ex = executor or SingleThreadedExecutor(context=self.context)
        ex.add_node(self)
        spinner = threading.Thread(target=self._spin, args=(ex,), name="sim-executor", daemon=True)
        spinner.start()
        ref_wall = time.perf_counter()
        ref_steps = 0
        next_diag = ref_wall + 1.0
        try:
            while self.context.ok():
                now = time.perf_counter()
                if now >= next_diag:
                    with self._lock:
                        self._publish_diagnostics()
                    next_diag = now + 1.0
                if self._schedule_dirty:
                    self._schedule_dirty = False
                    ref_wall, ref_steps = now, 0
                if self._paused:
                    time.sleep(0.01)
                    ref_wall, ref_steps = time.perf_counter(), 0
                    continue
                rtf = float(self._p["real_time_factor"])
                if rtf > 0:
                    due = ref_wall + ref_steps * float(self._p["time_step"]) / rtf
                    if now < due:
                        time.sleep(min(due - now, 0.05))
                        continue
                    if now - due > CATCH_UP_LIMIT:
                        self.late_steps += 1  # too far behind: drop the backlog, keep the pace from here
                        ref_wall, ref_steps = now, 0
                with self._lock:
                    if self._paused or self._schedule_dirty:
                        continue
                    self.step_once()
                ref_steps += 1
                if self._lock_waiters:
                    # A callback waits for the lock (_executor_lock). Without sleeping this loop would
                    # take it back at once (flat out at real_time_factor 0, or catching up), so sleep
                    # long enough for the waiting thread to get it. Only then: time.sleep(0) costs
                    # ~80 us here (an actual timer sleep), more than a step of a small scene.
                    time.sleep(0)
        except KeyboardInterrupt:
            pass
        except Exception:
            # Ctrl-C or SIGTERM between the loop's context check and a publish: rclpy raises on the
            # shut-down context (seen once in CI: "publisher's context is invalid", exit status 1).
            # That is the end of the run, not an error; anything else while the context lives is.
            if self.context.ok():
                raise
        finally:
            spinner.join(timeout=2.0)
            ex.remove_node(self)


def main(argv: list[str] | None = None) -> int:
    rclpy.init(args=argv if argv is not None else sys.argv)
    node = None
    try:
        node = SimNode()
        node.run()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except collide.SceneError as exc:
        print(f"sim: cannot load scene: {exc}", file=sys.stderr)
        return 2
    except (InvalidParameterTypeException, InvalidParameterValueException) as exc:
        print(f"sim: bad parameter on the command line: {exc}", file=sys.stderr)
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
