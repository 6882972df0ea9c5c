"""The node's command topics: ``<body>/thrust`` (one per dynamic body, up to max_body_topics),
``thrusters``, ``spring`` and ``cmd_vel``. Each message is checked and either rejected with its reason or
taken and republished on ``applied/<topic>`` (docs/contracts.md: what bit-exact replay records).
What the taken commands do to each step is forces.py's."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Twist, TwistStamped, WrenchStamped
from libcollide_msgs.msg import SpringCommand, ThrusterCommand
from rclpy.qos_overriding_options import QoSOverridingOptions

from collide import CollideError

from collide_ros import cdr, params, qos
from collide_ros.sim.guards import CountedPublisher, finite

APPLIED = "applied/"  # prefix of the command echo topics
MAX_CMD_SPEED = 1000.0  # m/s or rad/s: larger cmd_vel components are rejected


@dataclass
class Thrust:
    fx: float
    fy: float
    torque: float
    world: bool     # force given in the world frame (frame_id == world_frame) instead of the body frame
    stamp: float    # sim time of arrival


@dataclass
class CmdVel:
    vx: float
    vy: float
    wz: float
    stamp: float


@dataclass
class SpringEntry:
    spring: Any     # collide.Spring
    body: str
    point: tuple[float, float]  # body frame, about the centre of mass


class Commands:
    """Owns the commands in force: ``_thrust`` (body -> Thrust), ``_thrusters`` (body -> sim time of the
    last non-zero mask), ``_cmd_vel``, ``_springs`` (name -> SpringEntry made over ROS), and the command
    endpoints: ``_thrust_subs``, ``_echo_pubs`` (topic -> applied/<topic> publisher), the cmd_vel
    subscription."""

    def _init_commands(self) -> None:
        self._thrust: dict[str, Thrust] = {}
        self._thrusters: dict[str, float] = {}   # body -> sim time of the last non-zero mask
        self._cmd_vel: CmdVel | None = None
        self._springs: dict[str, SpringEntry] = {}
        self._thrust_subs: dict[str, Any] = {}
        self._echo_pubs: dict[str, CountedPublisher] = {
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

    def _make_cmd_vel_sub(self) -> None:
        stamped = bool(self._p["cmd_vel_stamped"])
        if self._cmd_vel_sub is not None and self._cmd_vel_sub_stamped == stamped:
            return
        if self._cmd_vel_sub is not None:
            self.destroy_subscription(self._cmd_vel_sub)
        self._cmd_vel_sub = self._subscribe(TwistStamped if stamped else Twist, "cmd_vel", "cmd_vel",
                                            self._on_cmd_vel, qos_overriding_options=self._overrides)
        self._cmd_vel_sub_stamped = stamped

    def _make_thrust_topics(self) -> None:
        """<body>/thrust subscriptions (and their echoes) for the first max_body_topics dynamic bodies."""
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

    def _forget_gone_bodies(self) -> None:
        """Commands and springs of bodies that are gone."""
        for name in [n for n in self._thrust if n not in self._row_of]:
            del self._thrust[name]
        for name in [n for n in self._thrusters if n not in self._row_of]:
            del self._thrusters[name]
        self._ext_bodies &= set(self._names)
        for sname in [s for s, e in self._springs.items() if e.body not in self._row_of]:
            del self._springs[sname]

    def _drop_commands(self) -> None:
        """Every command and every spring made over ROS (the scene's own forces stay)."""
        self._thrust.clear()
        self._cmd_vel = None
        for name in list(self._thrusters):
            self._bodies[name].set_thruster_mask(0)
        self._thrusters.clear()
        for entry in self._springs.values():
            entry.spring.remove()
        self._springs.clear()

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
        if not finite(f.x, f.y, t.z):
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
            self._thrust[name] = Thrust(f.x, f.y, t.z, in_world, self.sim_time)
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
        if not finite(vx, vy, wz):
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
        self._cmd_vel = CmdVel(vx, vy, wz, self.sim_time)
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
        if not finite(*nums):
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
        self._springs[sname] = SpringEntry(new, body, point)
        self._echo("spring", msg)
