"""The node's parameters: one table of name, default, range and description, the descriptors
built from it, and the cross-field checks that rclpy's descriptor checks cannot do."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor


@dataclass(frozen=True)
class Spec:
    name: str
    default: Any
    description: str
    lo: float | int | None = None
    hi: float | int | None = None
    read_only: bool = False


SPECS: tuple[Spec, ...] = (
    Spec("scene_file", "", "Scene file (YAML/JSON, docs/scene_format.md); empty = the embedded default scene",
         read_only=True),
    Spec("gravity", 0.0, "Gravity magnitude g (m/s^2), applied as (0, -g); negative pulls upwards", -100.0, 100.0),
    Spec("elasticity", 1.0, "Elasticity (coefficient of restitution) of every body, applied at once", 0.0, 1.0),
    Spec("damping", 0.0, "Linear damping k (N*s/m): force -k*v, torque -k*r*omega (r from the scene). At most 10: "
         "C integrates it with RK4, which is stable while k * time_step / mass < 2.78 (beyond it a moving "
         "block's steps are undone); 10 * 0.01 / 0.1 = 1 at the range ends (docs/ros_interface.md)", 0.0, 10.0),
    Spec("green_mass", 1.0, "Mass (kg) of body 'block1' (the green block), applied at once. At least 0.1 kg: a "
         "1 g block1 under 1e4 N into a wall has steps undone at time_step 0.001 s, a 0.1 kg one takes 1e5 N "
         "for 20 s (docs/ros_interface.md)", 0.1, 1000.0),
    Spec("blocks", 2, "Number of blocks in the default scene; applies on ~/reset", 1, 6),
    Spec("time_step", 0.001, "Physics time step (s). At most 0.01 s: at 0.1 s a 0.1 kg block1 under 1e5 N into "
         "a wall has its steps undone, at 0.01 s it takes them (docs/ros_interface.md)", 1e-5, 0.01),
    Spec("real_time_factor", 1.0, "Simulated seconds per wall second; 0 = as fast as possible", 0.0, 100.0),
    Spec("state_rate", 100.0, "Rate (Hz of sim time) of bodies/poses, bodies/states, contacts, energy", 1.0, 10000.0),
    Spec("state_qos_depth", 100, "History depth (KEEP_LAST, reliable) of the publishers of bodies/poses, "
         "bodies/states, contacts and energy: how many messages a subscriber may fall behind before it loses "
         "the oldest; read-only (set at start)", 1, 10000, read_only=True),
    Spec("tf_rate", 50.0, "Rate (Hz of sim time) of /tf; 0 = off", 0.0, 10000.0),
    Spec("marker_rate", 20.0, "Rate (Hz of sim time) of markers; 0 = off", 0.0, 1000.0),
    Spec("clock_rate", 1000.0, "Rate (Hz of sim time) of /clock, at most every step", 1.0, 100000.0),
    Spec("command_timeout", 1.0, "Seconds (sim time) after the last thrust/thrusters/cmd_vel command before "
         "that command is dropped; 0 = hold the last command", 0.0, 60.0),
    Spec("world_frame", "world", "Frame id of every header and parent of /tf; not prefixed by frame_prefix, so "
         "sims side by side share one TF tree rooted in it"),
    Spec("frame_prefix", "", "Prefix of the body frames: /tf children and the body frame of <body>/thrust are "
         "<frame_prefix><body>; world_frame is not prefixed. Default: the node's namespace without its leading "
         "'/' plus '/' ('robot1/' under /robot1), empty in the root namespace"),
    Spec("publish_clock", True, "Publish /clock (this sim's time). One clock per ROS domain: with several sims "
         "side by side, set it false on all but one; read-only (set at start)", read_only=True),
    Spec("cmd_vel_stamped", False, "cmd_vel carries TwistStamped (true) or Twist (false)"),
    Spec("cmd_vel_body", "block1", "Body driven by cmd_vel"),
    Spec("cmd_vel_linear_gain", 5.0, "cmd_vel servo: force = m*gain*(v_cmd - v) (1/s)", 0.0, 1000.0),
    Spec("cmd_vel_angular_gain", 5.0, "cmd_vel servo: torque = I*gain*(w_cmd - w) (1/s)", 0.0, 1000.0),
    Spec("cmd_vel_max_accel", 20.0, "cmd_vel servo: |force| <= m*max_accel (m/s^2) and <= max_thrust, plus "
         "gravity compensation",
         0.0, 10000.0),
    Spec("cmd_vel_max_angular_accel", 40.0, "cmd_vel servo: |torque| <= I*max_angular_accel (rad/s^2) and "
         "<= max_thrust",
         0.0, 100000.0),
    Spec("max_thrust", 1000.0, "Largest accepted thrust force (N) / torque (N*m), larger commands are rejected; also the most the "
         "cmd_vel servo applies. "
         "At most 1e4: into a wall, the lightest block1 (0.1 kg) at time_step 0.01 s takes 1e5 N and N*m held "
         "for 20 s and goes through the wall at 1e6 (docs/ros_interface.md)", 0.0, 1e4),
    Spec("max_body_topics", 64, "Bodies (in row order) that get a <body>/thrust subscription", 0, 100000,
         read_only=True),
    Spec("start_paused", False, "Start paused (use ~/step or ~/pause)", read_only=True),
    Spec("publish_thread", False, "Write and send each step's messages on a thread of their own while the loop "
         "takes the next step (C's step releases the GIL): the period is bounded by the larger of physics and "
         "publishing instead of their sum, given a spare core; without one the threads take turns and hand "
         "the GIL back and forth, which is slower than false (publishing on the stepping thread)",
         read_only=True),
    Spec("allow_kill_static", False, "~/kill may remove static bodies (the walls of the box); false keeps them"),
)

BY_NAME = {s.name: s for s in SPECS}

_FRAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-./]*$")
_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def frame_prefix_for(namespace: str) -> str:
    """The default frame_prefix of a node in ``namespace``: '/robot1' -> 'robot1/', '/' -> ''."""
    ns = namespace.strip("/")
    return f"{ns}/" if ns else ""


def descriptor(spec: Spec) -> ParameterDescriptor:
    d = ParameterDescriptor(description=spec.description, read_only=spec.read_only)
    if spec.lo is not None and isinstance(spec.default, float):
        d.floating_point_range = [FloatingPointRange(from_value=float(spec.lo), to_value=float(spec.hi),
                                                     step=0.0)]
    elif spec.lo is not None and isinstance(spec.default, int) and not isinstance(spec.default, bool):
        d.integer_range = [IntegerRange(from_value=int(spec.lo), to_value=int(spec.hi), step=1)]
    return d


def valid_frame(frame: str) -> str | None:
    """None when ``frame`` is a usable frame id, else why not."""
    if not frame:
        return "frame id must not be empty"
    if frame.startswith("/"):
        return f"frame id '{frame}' must not start with '/'"
    if not _FRAME_RE.match(frame):
        return f"frame id '{frame}' has characters other than letters, digits, '_', '-', '.', '/'"
    return None


def valid_body_name(name: str) -> str | None:
    """Body names become topic name tokens (<body>/thrust)."""
    if not _NAME_RE.match(name):
        return (f"body name '{name}' must start with a letter and hold only letters, digits and '_' "
                "(it becomes the topic <body>/thrust)")
    return None


def check(values: dict[str, Any], body_names: set[str]) -> str | None:
    """Cross-field checks of the would-be parameter set; returns the reason to reject or None."""
    for k, v in values.items():
        if isinstance(v, float) and not math.isfinite(v):
            return f"{k} must be finite, got {v}"
    if "world_frame" in values:
        why = valid_frame(values["world_frame"])
        if why:
            return f"world_frame: {why}"
    if values.get("frame_prefix"):
        why = valid_frame(values["frame_prefix"])
        if why:
            return f"frame_prefix: {why}"
    if "cmd_vel_body" in values and values["cmd_vel_body"] not in body_names:
        return f"cmd_vel_body: no dynamic body named '{values['cmd_vel_body']}' (have: {', '.join(sorted(body_names))})"
    return None
