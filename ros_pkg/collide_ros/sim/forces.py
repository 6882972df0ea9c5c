"""The commands in force turned into the external force and torque of each body for the coming step:
expired commands dropped (command_timeout), body-frame thrust turned into the world frame, and the
cmd_vel servo (a velocity error times a gain, bounded by an acceleration and by max_thrust, plus
gravity compensation)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ServoGains:
    """The cmd_vel servo's parameters (docs/ros_interface.md, cmd_vel_*), max_thrust and gravity g."""

    linear: float          # 1/s
    angular: float         # 1/s
    max_accel: float       # m/s^2
    max_angular_accel: float  # rad/s^2
    max_thrust: float      # N and N*m: the servo pushes no harder than a thrust command may
    gravity: float         # m/s^2


def servo_wrench(x: np.ndarray, mass: float, inertia: float, cmd: tuple[float, float, float],
                 g: ServoGains) -> tuple[float, float, float]:
    """Force (world frame) and torque that drive a body with state row ``x`` (x, y, angle, vx, vy, w)
    towards the body-frame velocity ``cmd`` = (vx, vy, wz): force = m*gain*(v_cmd - v) with
    |force| <= min(m*max_accel, max_thrust), plus m*g upwards; torque = I*gain*(w_cmd - w) within
    +-min(I*max_angular_accel, max_thrust). Without the max_thrust bound a heavy body's servo would push
    harder than the engine takes: 1000 kg at 1e4 m/s^2 is 1e7 N, which squeezes a 1 kg block through
    a wall (docs/ros_interface.md, "What the ranges guarantee")."""
    ca, sa = math.cos(x[2]), math.sin(x[2])
    vdx, vdy = ca * cmd[0] - sa * cmd[1], sa * cmd[0] + ca * cmd[1]  # body-frame command -> world
    fx, fy = mass * g.linear * (vdx - x[3]), mass * g.linear * (vdy - x[4])
    fmax = min(mass * g.max_accel, g.max_thrust)
    fn = math.hypot(fx, fy)
    if fn > fmax:
        fx, fy = fx * fmax / fn, fy * fmax / fn
    fy += mass * g.gravity  # hold the body up against gravity while driven
    tau = inertia * g.angular * (cmd[2] - x[5])
    tmax = min(inertia * g.max_angular_accel, g.max_thrust)
    tau = max(-tmax, min(tmax, tau))
    return fx, fy, tau


class Forces:
    """Owns ``_ext_bodies``: the bodies given an external force or torque for the last step (cleared
    when no command acts on them any more)."""

    def _init_forces(self) -> None:
        self._ext_bodies: set[str] = set()

    def _expire_commands(self, now: float) -> None:
        """Drop the thrust, thrusters and cmd_vel commands older than command_timeout (0: never)."""
        timeout = float(self._p["command_timeout"])
        if timeout <= 0:
            return
        for name in [n for n, c in self._thrust.items() if now - c.stamp > timeout]:
            del self._thrust[name]
        for name in [n for n, t in self._thrusters.items() if now - t > timeout]:
            del self._thrusters[name]
            if name in self._bodies:
                self._bodies[name].set_thruster_mask(0)
        if self._cmd_vel is not None and now - self._cmd_vel.stamp > timeout:
            self._cmd_vel = None

    def _apply_forces(self) -> None:
        """External force/torque of every commanded body for the coming step; expired commands dropped."""
        self._expire_commands(self.sim_time)
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
            p = self._p
            gains = ServoGains(float(p["cmd_vel_linear_gain"]), float(p["cmd_vel_angular_gain"]),
                               float(p["cmd_vel_max_accel"]), float(p["cmd_vel_max_angular_accel"]),
                               float(p["max_thrust"]), float(p["gravity"]))
            fx, fy, tau = servo_wrench(st[r], self._masses[r], self._inertias[r], (cv.vx, cv.vy, cv.wz), gains)
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
