"""Benchmark of the sim node: CPU share, rates, real time and command -> pose latency for 6 and 1000
bodies and for 200 boxes tumbling with friction.

    source scripts/env.sh && nice python bench/node_bench.py [--seconds 5] [--windows 3] [--trials 25]
                                                             [--drop-seconds 3] [--bodies 6 1000 pile200 pile200@0.005]
                                                             [--param publish_thread:=true ...]

For each case a node runs in its own process at the node's default parameters (given explicitly on its
command line): 1 kHz physics (time_step 0.001 s), 100 Hz poses/states, 50 Hz /tf, 20 Hz markers,
real-time factor 1. The bench (another process) measures, per window,
- CPU share of the node process (utime + stime from /proc over the window),
- how often bodies/poses arrives (raw CDR subscription, so the bench itself is not the bottleneck),
  and sim seconds per wall second from the poses' stamps,
- the node's own /diagnostics (1 Hz wall): real-time factor, step time (the physics step: C's
  lc_world_step and collecting its impacts), publish time per step of the stepping loop (reading the
  round from the world, handing it over) and of the publish thread (writing and sending it, beside the
  next step), steps/s, contacts, taken from every message whose second lay inside the window,
and prints the medians over windows (over all those messages for /diagnostics). The node holds real
time when the median real-time factor is >= 0.99 (of the requested 1). Then the command -> pose
latency: after ~/reset, one WrenchStamped is published on block1/thrust (block1 at rest); latency =
wall time from publish to the first bodies/poses message in which block1 has moved (median and 90th
percentile over --trials).

Cases (--bodies; default 6 1000 pile200 pile200@0.005; a case may end in @ and the node's time_step in
seconds, default 0.001):
- 6: the default scene with blocks:=6; --windows windows of --seconds wall seconds.
- 1000 (any n > 6): a generated scene (walls around [-40, 40]^2, 0.5 m boxes on a 2 m grid, random
  speeds up to 0.5 m/s, e = 1, no gravity) with block1 at rest in a free corner; windows as for 6.
- pile200 (pileN: N boxes): 200 boxes tumbling with friction, `pile_scene`: width and height each
  uniform in 0.3-0.8 m, mass proportional to area (2 kg/m^2: 0.18-1.28 kg), mu 0.5, e 0.3, gravity
  9.81 m/s^2 down, dropped with random speeds (each axis within +-1 m/s) and spins (within +-2 rad/s)
  from a loose grid (1.2 m cells, 17 columns, 12 rows) into a walled room 20.4 m wide, 16.4 m high
  (walls and floor are static boxes of the same material: the scene format's `walls` have no
  friction); block1, the latency probe, rests in a bay of its own behind a full-height divider. The
  boxes land from 0.35 s on, the pile forms and tumbles until ~2.5 s after the drop and rests by ~3 s
  (kinetic energy per 0.5 s: `python bench/repro/pile200_engine_steps.py`). So that what is measured
  is a pile tumbling, not one at rest, each window is one drop: ~/reset (the scene as generated), then
  measured until the poses' stamps are --drop-seconds (3 s) of sim time past the drop: the fall,
  the pile-up and its tumbling until it comes to rest; --windows drops. Its latency trials start right
  after a reset, while the boxes are still falling (the cheap part of a drop).
- pile200@0.005: the same drops at a 5 ms time step. The contact regime's cost per step grows slowly
  with the step, so a pile's cost per simulated second falls with it (the engine alone:
  `python bench/repro/pile200_engine_steps.py --dt 0.005`); 1 ms is the node's default for the seed's
  exact impacts, not what a pile needs.
Scene files are written into a temp dir and removed. Prints a markdown table and, per case, the
real-time factor from the stamps, how many /diagnostics messages were used, steps/s and contacts,
after naming the libcollide each node loaded. Not run by the tests (timings). Where the pile's time
goes: `bench/repro/pile200_engine_steps.py` (the engine alone) and `bench/repro/pile200_node_publish.py`
(the node's step against each publisher). Uses ROS_DOMAIN_ID from the environment, or picks a free
one in the bench range 75-79.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import struct
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))

DEFAULT_CASES = ("6", "1000", "pile200", "pile200@0.005")


def pick_domain() -> object | None:
    if "ROS_DOMAIN_ID" in os.environ:
        return None
    from collide_ros import ros_domain
    lock = ros_domain.acquire(range(75, 80))
    os.environ["ROS_DOMAIN_ID"] = str(lock.domain_id)
    return lock


def big_scene(n: int, path: Path, seed: int = 1) -> None:
    """n bodies (block1 at rest in the lower-left corner, the rest moving) as a scene file."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n + 8)))
    half = side  # 2 m grid
    bodies = [{"name": "block1", "shape": "box", "width": 0.5, "height": 0.5,
               "position": [-half + 1.0, -half + 1.0], "mass": 1.0, "elasticity": 1.0}]
    k = 1
    for i in range(side):
        for j in range(side):
            if k >= n:
                break
            x, y = -half + 1.0 + 2.0 * i, -half + 1.0 + 2.0 * j
            if i < 3 and j < 3:
                continue  # keep block1's corner free
            v = rng.uniform(-0.5, 0.5, size=2)
            bodies.append({"name": f"b{k}", "shape": "box", "width": 0.5, "height": 0.5, "position": [x, y],
                           "velocity": [float(v[0]), float(v[1])], "mass": 1.0, "elasticity": 1.0})
            k += 1
    scene = {"version": 1, "description": f"node bench: {n} boxes",
             "world": {"gravity": [0.0, 0.0]},
             "walls": {"xmin": -half, "ymin": -half, "xmax": half, "ymax": half, "thickness": 1.0,
                       "elasticity": 1.0},
             "bodies": bodies}
    path.write_text(yaml.safe_dump(scene))


PILE_SPACING = 1.2  # m: grid cell of the pile scene; a 0.8 m box at any angle (diagonal 1.13 m) fits
PILE_BAY = 2.0      # m: width of block1's bay, left of the pile, behind a full-height static divider
PILE_MU, PILE_E, PILE_G, PILE_DENSITY = 0.5, 0.3, 9.81, 2.0  # friction, elasticity, m/s^2, kg/m^2


def _static_box(name: str, x0: float, y0: float, x1: float, y1: float) -> dict[str, Any]:
    """A static box over [x0, x1] x [y0, y1] with the pile's material (the scene's `walls` have no friction)."""
    return {"name": name, "shape": "box", "width": x1 - x0, "height": y1 - y0,
            "position": [(x0 + x1) / 2, (y0 + y1) / 2], "static": True, "elasticity": PILE_E, "friction": PILE_MU}


def pile_scene(n: int = 200, seed: int = 1) -> dict[str, Any]:
    """n boxes dropped into a walled box, as a scene dict (docs/scene_format.md).

    Boxes: width and height uniform in [0.3, 0.8] m, mass = PILE_DENSITY x area, angle uniform in
    [0, pi), velocity uniform in [-1, 1]^2 m/s and spin in [-2, 2] rad/s (default_rng(seed), in that
    order), one per PILE_SPACING cell of a grid of cols = ceil(1.2 sqrt n) columns, bottom row 0.6 m
    above the floor; mu 0.5, e 0.3, gravity 9.81 m/s^2 down. The walls (static boxes, 1 m thick, same
    material) enclose the grid with 2 m above its top row. block1 (0.5 m, 1 kg, the latency probe) rests
    on the floor of a PILE_BAY wide bay left of the pile, behind a full-height static divider, so no box
    reaches it. Dynamic rows: block1, then p1 ... pn."""
    rng = np.random.default_rng(seed)
    w, h = rng.uniform(0.3, 0.8, n), rng.uniform(0.3, 0.8, n)
    angle = rng.uniform(0.0, np.pi, n)
    vel = rng.uniform(-1.0, 1.0, (n, 2))
    spin = rng.uniform(-2.0, 2.0, n)
    cols = int(np.ceil(1.2 * np.sqrt(n)))
    rows = int(np.ceil(n / cols))
    x0 = PILE_BAY + 0.2                       # the divider is 0.2 m thick
    xmax, ymax = x0 + cols * PILE_SPACING, rows * PILE_SPACING + 2.0
    k = np.arange(n)
    cx, cy = x0 + (k % cols + 0.5) * PILE_SPACING, (k // cols + 0.5) * PILE_SPACING
    mat = {"elasticity": PILE_E, "friction": PILE_MU}
    bodies: list[dict[str, Any]] = [
        {"name": "block1", "shape": "box", "width": 0.5, "height": 0.5, "position": [PILE_BAY / 2, 0.25 + 1e-7],
         "mass": 1.0, **mat}]
    bodies += [{"name": f"p{i + 1}", "shape": "box", "width": float(w[i]), "height": float(h[i]),
                "position": [float(cx[i]), float(cy[i])], "angle": float(angle[i]),
                "velocity": [float(vel[i, 0]), float(vel[i, 1])], "angular_velocity": float(spin[i]),
                "mass": float(PILE_DENSITY * w[i] * h[i]), **mat} for i in range(n)]
    t = 1.0  # wall thickness
    bodies += [_static_box("floor", -t, -t, xmax + t, 0.0), _static_box("ceiling", -t, ymax, xmax + t, ymax + t),
               _static_box("wall_l", -t, 0.0, 0.0, ymax), _static_box("wall_r", xmax, 0.0, xmax + t, ymax),
               _static_box("divider", PILE_BAY, 0.0, x0, ymax)]
    return {"version": 1,
            "description": f"node bench: {n} boxes 0.3-0.8 m dropped into a walled box (mu {PILE_MU}, e {PILE_E})",
            "world": {"gravity": [0.0, -PILE_G]}, "bodies": bodies}


def loaded_libcollide(pid: int) -> str:
    """Path of the libcollide shared library a process has mapped ("?" if none is)."""
    for line in Path(f"/proc/{pid}/maps").read_text().splitlines():
        if "libcollide.so" in line:
            return line.split()[-1]
    return "?"


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def pose_x0(raw: bytes) -> float:
    """x of the first pose in a raw CDR PoseArray."""
    (flen,) = struct.unpack_from("<I", raw, 4 + 8)
    off = 4 + 8 + 4 + flen
    off = 4 + ((off - 4 + 3) // 4) * 4
    (count,) = struct.unpack_from("<I", raw, off)
    off += 4
    off = 4 + ((off - 4 + 7) // 8) * 8
    return struct.unpack_from("<d", raw, off)[0] if count else float("nan")


def pose_stamp(raw: bytes) -> float:
    """header.stamp (s) of a raw CDR PoseArray."""
    sec, nsec = struct.unpack_from("<iI", raw, 4)
    return sec + 1e-9 * nsec


@dataclass(frozen=True)
class Case:
    """One bench case: `label` as given on the command line, `bodies` the moving boxes, `pile` whether it
    is the frictional pile (pile_scene, measured from drops) rather than a steady scene."""
    label: str
    bodies: int
    pile: bool
    time_step: float = 0.001  # s, the node's time_step parameter


def parse_case(text: str) -> Case:
    """'6' (default scene, 1-6 blocks), '1000' (any n > 6: big_scene) or 'pile200' (pile_scene of 200),
    each optionally followed by '@' and the node's time_step in seconds ('pile200@0.005'; default 0.001)."""
    body, at, dt_text = text.partition("@")
    try:
        dt = float(dt_text) if at else 0.001
    except ValueError:
        dt = float("nan")
    if not (0.0 < dt <= 0.1):
        raise argparse.ArgumentTypeError(f"'{text}': time step after '@' must be a number in (0, 0.1] s")
    if body.startswith("pile") and body[4:].isdigit() and int(body[4:]) > 0:
        return Case(text, int(body[4:]), True, dt)
    if body.isdigit() and int(body) > 0:
        return Case(text, int(body), False, dt)
    raise argparse.ArgumentTypeError(f"'{text}': expected a body count (6, 1000, ...) or pileN (pile200), "
                                     "optionally @time_step")


def node_args(case: Case, tmp: Path, params: tuple[str, ...] = ()) -> list[str]:
    """The node's command line for a case (``params``: more NAME:=VALUE); scene files are written into tmp."""
    args = ["-p", f"time_step:={case.time_step!r}", "-p", "state_rate:=100.0", "-p", "tf_rate:=50.0",
            "-p", "marker_rate:=20.0", "-p", "real_time_factor:=1.0"]
    for p in params:
        args += ["-p", p]
    if case.pile:
        path = tmp / f"bench_pile{case.bodies}.yaml"
        path.write_text(yaml.safe_dump(pile_scene(case.bodies)))
    elif case.bodies > 6:
        path = tmp / f"bench_{case.bodies}.yaml"
        big_scene(case.bodies, path)
    else:
        return args + ["-p", f"blocks:={case.bodies}"]
    return args + ["-p", f"scene_file:={path}"]


@dataclass
class Window:
    """One measuring window: the node's CPU share, poses received per wall second, sim seconds per
    wall second from the poses' stamps, and the values of the /diagnostics that fell inside it."""
    cpu_percent: float
    poses_hz: float
    stamp_rtf: float
    diags: list[dict[str, str]]


class Bench:
    """A running node and the bench's client: raw bodies/poses (arrival time, bytes) and /diagnostics."""

    def __init__(self, client: Any, pid: int) -> None:
        from geometry_msgs.msg import PoseArray
        self.client, self.pid = client, pid
        self.raw: list[tuple[float, bytes]] = []
        client.node.create_subscription(PoseArray, "bodies/poses",
                                        lambda m: self.raw.append((time.perf_counter(), m)), 10, raw=True)

    def diags_between(self, t0: float, t1: float) -> list[dict[str, str]]:
        """/diagnostics values of the messages whose 1 s averaging window lay inside [t0, t1] (monotonic)."""
        from collide_ros.testing import diag_values
        out = [diag_values(m) for t, m in self.client.history["diagnostics"] if t0 + 1.0 <= t <= t1]
        return [v for v in out if v is not None]

    def steady_window(self, seconds: float) -> Window:
        """CPU, rates and diagnostics over `seconds` of wall time."""
        self.raw.clear()
        c0, t0, m0 = cpu_seconds(self.pid), time.perf_counter(), time.monotonic()
        self.client.spin(seconds)
        c1, t1, m1 = cpu_seconds(self.pid), time.perf_counter(), time.monotonic()
        stamps = [pose_stamp(r) for _, r in self.raw]
        sim = stamps[-1] - stamps[0] if len(stamps) > 1 else float("nan")
        span = self.raw[-1][0] - self.raw[0][0] if len(self.raw) > 1 else float("nan")
        return Window(100.0 * (c1 - c0) / (t1 - t0), len(self.raw) / (t1 - t0), sim / span,
                      self.diags_between(m0, m1))

    def drop_window(self, sim_seconds: float, timeout: float) -> Window:
        """~/reset (a fresh drop), then CPU, rates and diagnostics until the poses' stamps are
        `sim_seconds` past the first message after the reset (or `timeout` wall seconds have passed)."""
        from std_srvs.srv import Empty
        self.client.call(Empty, "reset")
        self.raw.clear()
        if not self.client.wait_for(lambda: len(self.raw) > 0, 10.0):
            raise RuntimeError("no bodies/poses after ~/reset")
        c0, m0 = cpu_seconds(self.pid), time.monotonic()
        t0, s0 = self.raw[0][0], pose_stamp(self.raw[0][1])
        self.client.wait_for(lambda: pose_stamp(self.raw[-1][1]) >= s0 + sim_seconds - 1e-9, timeout)
        c1, t1, m1 = cpu_seconds(self.pid), time.perf_counter(), time.monotonic()
        t_last, s_last = self.raw[-1][0], pose_stamp(self.raw[-1][1])
        return Window(100.0 * (c1 - c0) / (t1 - t0), (len(self.raw) - 1) / (t_last - t0),
                      (s_last - s0) / (t_last - t0), self.diags_between(m0, m1))

    def latency(self, trials: int) -> list[float]:
        """Command -> pose latency (ms): after ~/reset, one WrenchStamped on block1/thrust; wall time to
        the first bodies/poses message in which block1 has moved. Lost trials are left out."""
        from geometry_msgs.msg import WrenchStamped
        from std_srvs.srv import Empty
        c = self.client
        rng = np.random.default_rng(3)
        assert c.wait_subscribed("block1/thrust", WrenchStamped)
        cmd = WrenchStamped()
        cmd.wrench.force.x = 10.0
        lat: list[float] = []
        for _ in range(trials):
            c.call(Empty, "reset")
            self.raw.clear()
            if not c.wait_for(lambda: len(self.raw) >= 3, 10.0):
                continue  # trial lost (node busy); the count of trials is reported
            x0 = pose_x0(self.raw[-1][1])
            c.spin(float(rng.uniform(0.0, 0.01)))  # a random phase against the 100 Hz publishing
            self.raw.clear()
            t_pub = time.perf_counter()
            c.publish("block1/thrust", cmd)
            seen: list[float] = []

            def moved() -> bool:
                for t, raw in self.raw:
                    if pose_x0(raw) != x0:
                        seen.append(t)
                        return True
                return False
            if c.wait_for(moved, 10.0) and seen:
                lat.append(1e3 * (seen[0] - t_pub))
        return lat


DIAG_KEYS = ("real_time_factor", "step_time_mean_ms", "publish_time_mean_ms", "publish_thread_time_mean_ms",
             "steps_per_second", "contacts")


def summarize(case: Case, windows: list[Window], lat: list[float]) -> dict[str, float]:
    """Medians over windows (CPU, poses rate, stamp RTF) and over every diagnostics message in them."""
    out: dict[str, float] = {"bodies": float(case.bodies)}
    out["cpu_percent"] = statistics.median(w.cpu_percent for w in windows)
    out["poses_hz"] = statistics.median(w.poses_hz for w in windows)
    out["stamp_rtf"] = statistics.median(w.stamp_rtf for w in windows)
    diags = [d for w in windows for d in w.diags]
    out["diagnostics"] = float(len(diags))
    for key in DIAG_KEYS:
        vals = [float(d[key]) for d in diags if key in d]
        out[key] = statistics.median(vals) if vals else float("nan")
    out["trials"] = float(len(lat))
    out["latency_p50_ms"] = statistics.median(lat) if lat else float("nan")
    out["latency_p90_ms"] = float(np.percentile(lat, 90)) if lat else float("nan")
    return out


def run_case(case: Case, seconds: float, windows: int, trials: int, drop_seconds: float,
             params: tuple[str, ...] = ()) -> dict[str, float]:
    import rclpy

    from collide_ros.testing import NodeProcess, SimClient

    tmp = Path(tempfile.mkdtemp())
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    proc = NodeProcess(*node_args(case, tmp, params))
    client = SimClient(context=ctx, watch=("diagnostics",))
    bench = Bench(client, proc.proc.pid)
    try:
        if not client.wait_for(lambda: len(bench.raw) > 0, 120.0):
            raise RuntimeError(f"node did not publish:\n{proc.output()}")
        client.spin(1.0)
        print(f"{case.label}: node pid {proc.proc.pid} runs {loaded_libcollide(proc.proc.pid)}", flush=True)
        if case.pile:
            ws = [bench.drop_window(drop_seconds, timeout=120.0 * drop_seconds) for _ in range(windows)]
        else:
            ws = [bench.steady_window(seconds) for _ in range(windows)]
        return summarize(case, ws, bench.latency(trials))
    finally:
        client.close()
        proc.stop()
        rclpy.shutdown(context=ctx)
        shutil.rmtree(tmp, ignore_errors=True)


def print_table(cases: list[Case], rows: list[dict[str, float]], drop_seconds: float,
                params: tuple[str, ...] = ()) -> None:
    print(f"\nsim node, time_step as given per case (default 1 ms), 100 Hz poses/states, 50 Hz tf, 20 Hz markers, RTF 1; "
          f"{os.cpu_count()} cores; ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']}; load average {os.getloadavg()[0]:.2f}; "
          "medians" + (f"; node parameters {' '.join(params)}" if params else "") + "\n")
    print("| bodies | node CPU (% of a core) | poses received (Hz) | real-time factor | real time (>= 0.99) "
          "| step (ms) | publishing per step: loop / publish thread (ms) | command -> pose p50 / p90 (ms) | trials |")
    print("|---|---|---|---|---|---|---|---|---|")
    for case, r in zip(cases, rows):
        name = f"{case.bodies} (pile, first {drop_seconds:g} s of each drop)" if case.pile else str(case.bodies)
        name += f", dt {case.time_step * 1e3:g} ms"
        rtf = r["real_time_factor"]
        holds = "n/a (no diagnostics)" if np.isnan(rtf) else "yes" if rtf >= 0.99 else "no"
        print(f"| {name} | {r['cpu_percent']:.1f} | {r['poses_hz']:.1f} | {r['real_time_factor']:.3f} | {holds} "
              f"| {r['step_time_mean_ms']:.4f} | {r['publish_time_mean_ms']:.4f} / {r['publish_thread_time_mean_ms']:.4f} "
              f"| {r['latency_p50_ms']:.1f} / {r['latency_p90_ms']:.1f} | {int(r['trials'])} |")
    print("\nreal-time factor, step and publishing: medians of the node's /diagnostics (1 Hz) in the windows; "
          "also from the poses' stamps (sim s / wall s), diagnostics used, steps/s, contacts:")
    for case, r in zip(cases, rows):
        print(f"- {case.label}: stamps {r['stamp_rtf']:.3f}; {int(r['diagnostics'])} diagnostics; "
              f"{r['steps_per_second']:.0f} steps/s; {r['contacts']:.0f} contacts")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="length of one CPU window (s) of a steady case")
    ap.add_argument("--windows", type=int, default=3, help="CPU windows (pile: drops) per case (median)")
    ap.add_argument("--drop-seconds", type=float, default=3.0,
                    help="sim seconds measured from each drop of a pile case")
    ap.add_argument("--trials", type=int, default=25, help="latency trials per case")
    ap.add_argument("--bodies", type=parse_case, nargs="+", default=[parse_case(c) for c in DEFAULT_CASES],
                    metavar="CASE", help="body counts (6, 1000, ...) and piles (pile200); default: "
                    + " ".join(DEFAULT_CASES))
    ap.add_argument("--param", action="append", default=[], metavar="NAME:=VALUE",
                    help="another node parameter for every case (e.g. publish_thread:=true); repeatable")
    a = ap.parse_args()
    lock = pick_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    rows = [run_case(c, a.seconds, a.windows, a.trials, a.drop_seconds, tuple(a.param)) for c in a.bodies]
    print_table(a.bodies, rows, a.drop_seconds, tuple(a.param))
    if lock is not None:
        lock.release()  # type: ignore[attr-defined]
    return 0


if __name__ == "__main__":
    sys.exit(main())
