"""Search the soak's command mix for physics steps that C undoes, faster than the soak itself.

    source scripts/env.sh && export ROS_DOMAIN_ID=86
    python soak/step_search.py --mode engine --seeds 1000-1009 --steps 10000000   # ~100 s a seed
    python soak/step_search.py --mode node --seeds 1-4 --steps 6000000             # ~200 s a seed

The soak (soak/soak.py) runs the node at ~25 000-50 000 steps/s with ROS in the loop. This drives
the same random commands without it, deterministically per seed, on the soak's timing (at
CI's 52 000 steps/s: a command every 1 300 steps, a parameter every 104 000, a reset every
780 000; no spring release within 52 000 steps of a reset):

* ``--mode node``: soak.soak.Driver into an in-process SimNode's own command handlers and
  ``step_once`` (no executor), so the node's force servo, watchdog and step split are the real ones;
  counts the steps C undid (``split_steps``) and the steps that failed even in parts.
* ``--mode engine``: soak.soak.Driver into EngineClient, the engine alone through the Python
  API with the node's handling of each command and the node's forces (body-frame
  thrust, thrusters, the cmd_vel servo on block1, springs, watchdog, parameters) recomputed every
  ``--chunk`` steps instead of every step (~4x faster); counts the steps C undid and whether their
  two halves go through.

Prints a line per seed and the totals, and the largest work counters of one step
(docs/hardening.md, "The node when C undoes a step"). Exit status 1 when a step was undone.
"""
from __future__ import annotations

import argparse
import math
import os
import random
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
for p in (REPO, REPO / "ros_pkg"):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))

from soak.soak import BLOCKS, Driver  # noqa: E402

DT = 0.001
CMD_EVERY, PARAM_EVERY, RESET_EVERY, RELEASE_MARGIN = 1300, 104_000, 780_000, 52_000
WORK_KEYS = ("force_evaluations", "serial_iterations", "solver_work")


@dataclass
class SeedResult:
    seed: int
    steps: int = 0
    undone: int = 0                 # steps C undid (node: taken in parts; engine: whole step refused)
    failed: int = 0                 # node: failed also in parts; engine: the two halves failed too
    max_work: dict[str, float] = field(default_factory=dict)
    events: list[str] = field(default_factory=list)


def _keep_max(res: SeedResult, counters: dict[str, Any]) -> None:
    for k in WORK_KEYS:
        res.max_work[k] = max(res.max_work.get(k, 0), counters[k])


def run_node(seed: int, steps: int) -> SeedResult:
    import rclpy
    from rclpy.parameter import Parameter

    from collide_ros.node import SimNode

    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # the node's publishers stay on this machine
    os.environ.pop("ROS_LOCALHOST_ONLY", None)
    if "ROS_DOMAIN_ID" not in os.environ:
        raise SystemExit("step_search: export ROS_DOMAIN_ID first (hand runs: 85-94)")
    res = SeedResult(seed)
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    node = SimNode(context=ctx, cli_args=["--ros-args", "-r", f"__ns:=/step_search_{seed}"],
                   parameter_overrides=[Parameter("real_time_factor", value=0.0), Parameter("blocks", value=BLOCKS),
                                        Parameter("command_timeout", value=0.5), Parameter("marker_rate", value=0.0),
                                        Parameter("state_rate", value=5.0), Parameter("tf_rate", value=5.0),
                                        Parameter("clock_rate", value=5.0)])

    class Handlers:
        def publish(self, topic: str, msg: Any) -> None:
            if topic.endswith("/thrust"):
                node._on_thrust(topic.split("/")[0], msg)
            else:
                {"thrusters": node._on_thrusters, "cmd_vel": node._on_cmd_vel, "spring": node._on_spring}[topic](msg)

    drv = Driver(Handlers(), random.Random(seed))
    try:
        for s in range(steps):
            if s % CMD_EVERY == 0:
                before = node.rejected
                drv.one(may_release=s % RESET_EVERY < RESET_EVERY - RELEASE_MARGIN)
                if node.rejected != before:
                    res.events.append(f"step {s}: command rejected: {node.last_rejection}")
            if s and s % PARAM_EVERY == 0:
                node.set_parameters([Parameter(k, value=v) for k, v in drv.params().items()])
            if s and s % RESET_EVERY == 0:
                node.reset()
                drv.reset()
            split = node.split_steps
            ok = node.step_once()
            _keep_max(res, node.world.counters(last=True))
            if node.split_steps != split:
                res.undone += 1
                res.events.append(f"step {s}: sim t={node.sim_time:.6f} s undone by C, taken in parts")
            if not ok:
                res.undone += 1
                res.failed += 1
                res.events.append(f"step {s}: {node.last_rejection}")
            res.steps += 1
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)
    return res


class EngineClient:
    """The node's command semantics on a bare World (collide_ros/sim/commands.py and forces.py):
    the client that soak.soak.Driver publishes its random commands to, so both modes draw the
    soak's own mix."""

    GAINS = {"cmd_vel_linear_gain": 5.0, "cmd_vel_max_accel": 20.0, "cmd_vel_angular_gain": 5.0,
             "cmd_vel_max_angular_accel": 40.0}

    def __init__(self) -> None:
        self.p: dict[str, float] = {"gravity": 0.0, "elasticity": 1.0, "damping": 0.0, "green_mass": 1.0,
                                    "command_timeout": 0.5, **self.GAINS}
        self.reset()

    def reset(self) -> None:
        import collide
        w = collide.default_scene(blocks=BLOCKS).build()
        w.set_gravity((0.0, -self.p["gravity"]))
        w.set_damping(self.p["damping"])
        w.set_elasticity(self.p["elasticity"])
        w.body("block1").mass = self.p["green_mass"]
        self.w = w
        self.rows = {n: i for i, n in enumerate(w.names)}
        self.thrust: dict[str, tuple[float, float, float, bool, float]] = {}
        self.thrusters: dict[str, float] = {}
        self.springs: dict[str, Any] = {}
        self.cmd_vel: tuple[float, float, float, float] | None = None

    def publish(self, topic: str, msg: Any) -> None:
        now = self.w.time
        if topic.endswith("/thrust"):
            body, f, t = topic.split("/")[0], msg.wrench.force, msg.wrench.torque
            self.thrust[body] = (f.x, f.y, t.z, msg.header.frame_id == "world", now)
        elif topic == "thrusters":
            self.w.body(msg.body).set_thruster_mask(sum(1 << i for i, on in enumerate(msg.firing) if on))
            self.thrusters[msg.body] = now
        elif topic == "cmd_vel":
            self.cmd_vel = (msg.linear.x, msg.linear.y, msg.angular.z, now)
        else:  # spring: the driver releases only springs it made, and the points never repeat
            old = self.springs.pop(msg.name, None)
            if not msg.release:
                self.springs[msg.name] = self.w.add_spring(
                    msg.body, (msg.body_point.x, msg.body_point.y), None, (msg.target.x, msg.target.y),
                    msg.stiffness, msg.damping, msg.rest_length)
            if old is not None:
                old.remove()

    def set_parameters(self, values: dict[str, float]) -> None:
        for key, value in values.items():
            self.p[key] = value
            if key == "gravity":
                self.w.set_gravity((0.0, -value))
            elif key == "elasticity":
                self.w.set_elasticity(value)
            elif key == "damping":
                self.w.set_damping(value)
            elif key == "green_mass":
                self.w.body("block1").mass = value

    def apply_forces(self) -> None:
        now, p, w = self.w.time, self.p, self.w
        timeout = p["command_timeout"]
        self.thrust = {n: c for n, c in self.thrust.items() if now - c[4] <= timeout}
        for n in [n for n, t in self.thrusters.items() if now - t > timeout]:
            del self.thrusters[n]
            w.body(n).set_thruster_mask(0)
        if self.cmd_vel is not None and now - self.cmd_vel[3] > timeout:
            self.cmd_vel = None
        st = w.state
        total = {f"block{i}": [0.0, 0.0, 0.0] for i in range(1, BLOCKS + 1)}
        for n, (fx, fy, tq, in_world, _) in self.thrust.items():
            if not in_world:
                a = st[self.rows[n], 2]
                fx, fy = math.cos(a) * fx - math.sin(a) * fy, math.sin(a) * fx + math.cos(a) * fy
            total[n] = [total[n][0] + fx, total[n][1] + fy, total[n][2] + tq]
        if self.cmd_vel is not None:
            i = self.rows["block1"]
            x, m, inertia = st[i], w.masses[i], w.inertias[i]
            c, s = math.cos(x[2]), math.sin(x[2])
            vx, vy = c * self.cmd_vel[0] - s * self.cmd_vel[1], s * self.cmd_vel[0] + c * self.cmd_vel[1]
            fx, fy = m * p["cmd_vel_linear_gain"] * (vx - x[3]), m * p["cmd_vel_linear_gain"] * (vy - x[4])
            fn, fmax = math.hypot(fx, fy), m * p["cmd_vel_max_accel"]
            if fn > fmax:
                fx, fy = fx * fmax / fn, fy * fmax / fn
            tmax = inertia * p["cmd_vel_max_angular_accel"]
            tq = max(-tmax, min(tmax, inertia * p["cmd_vel_angular_gain"] * (self.cmd_vel[2] - x[5])))
            t = total["block1"]
            total["block1"] = [t[0] + fx, t[1] + fy + m * p["gravity"], t[2] + tq]
        for n, (fx, fy, tq) in total.items():
            w.body(n).set_external((fx, fy), tq)


def run_engine(seed: int, steps: int, chunk: int) -> SeedResult:
    from collide import CollideError

    res = SeedResult(seed)
    eng = EngineClient()
    drv = Driver(eng, random.Random(seed))
    for s in range(0, steps, chunk):
        # the events of the chunk's steps, at the chunk's start (chunk divides none of the periods exactly)
        if s % CMD_EVERY < chunk:
            drv.one(may_release=s % RESET_EVERY < RESET_EVERY - RELEASE_MARGIN)
        if s and s % PARAM_EVERY < chunk:
            eng.set_parameters(drv.params())
        if s and s % RESET_EVERY < chunk:
            eng.reset()
            drv.reset()
        eng.apply_forces()
        w = eng.w
        for _ in range(chunk):
            try:
                w.step(DT)
            except CollideError as exc:
                res.undone += 1
                state_t = w.time
                try:
                    w.step(DT / 2)
                    w.step(DT / 2)
                    res.events.append(f"step {res.steps}: t={state_t:.6f} s undone ({exc}); its halves went through")
                except CollideError as exc2:
                    res.failed += 1
                    res.events.append(f"step {res.steps}: t={state_t:.6f} s undone ({exc}); halves too ({exc2})")
            _keep_max(res, w.counters(last=True))
            res.steps += 1
        if res.failed > 100:  # a state that cannot be stepped: the rest of the seed would say the same
            res.events.append(f"step {res.steps}: stopped after {res.failed} failures")
            break
    return res


def _seeds(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="soak/step_search.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mode", choices=("node", "engine"), default="engine")
    ap.add_argument("--seeds", default="1-4", help="a seed or a range, e.g. 1000-1009")
    ap.add_argument("--steps", type=int, default=10_000_000, help="steps per seed")
    ap.add_argument("--chunk", type=int, default=10, help="engine mode: steps between force updates")
    a = ap.parse_args(argv)
    total = SeedResult(-1)
    for seed in _seeds(a.seeds):
        t0 = time.perf_counter()
        res = run_node(seed, a.steps) if a.mode == "node" else run_engine(seed, a.steps, a.chunk)
        for line in res.events[:20]:
            print(f"  seed {seed}: {line}", flush=True)
        work = ", ".join(f"{k} {v:.4g}" for k, v in res.max_work.items())
        print(f"seed {seed}: {res.steps} steps, {res.undone} undone by C, {res.failed} failed also in parts; "
              f"largest in a step: {work} ({time.perf_counter() - t0:.0f} s)", flush=True)
        total.steps += res.steps
        total.undone += res.undone
        total.failed += res.failed
        for k, v in res.max_work.items():
            total.max_work[k] = max(total.max_work.get(k, 0), v)
    work = ", ".join(f"{k} {v:.4g}" for k, v in total.max_work.items())
    print(f"total ({a.mode}): {total.steps} steps, {total.undone} undone by C, {total.failed} failed also in parts; "
          f"largest in a step: {work}")
    return 1 if total.undone else 0


if __name__ == "__main__":
    sys.exit(main())
