"""Benchmark of the sim node: CPU share, rates and command -> pose latency for 6 and 1000 bodies.

    source scripts/env.sh && nice python bench/node_bench.py [--seconds 5] [--trials 25] [--bodies 6 1000]

For each body count a node runs in its own process at 1 kHz physics, 100 Hz poses/states, 50 Hz
/tf, 20 Hz markers, real-time factor 1. The bench (another process) measures
- CPU share of the node process (utime + stime from /proc over windows of --seconds; median),
- how often bodies/poses arrives (raw CDR subscription, so the bench itself is not the bottleneck),
- the node's own /diagnostics: real-time factor, step time, publish time per step,
- command -> pose latency: after ~/reset (everything at rest) one WrenchStamped is published on
  block1/thrust; latency = wall time from publish to the first bodies/poses message in which block1
  has moved (median and 90th percentile over --trials).
6 bodies = the default scene with blocks:=6. 1000 bodies = a generated scene (walls around
[-40, 40]^2, 0.5 m boxes on a 2 m grid, random speeds up to 0.5 m/s, e = 1, no gravity) with
block1 at rest in a free corner. Prints a markdown table. Not run by the tests (timings).
Uses ROS_DOMAIN_ID from the environment, or picks a free one in the bench range 75-79.
"""
from __future__ import annotations

import argparse
import os
import statistics
import struct
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))
sys.path.insert(0, str(ROOT / "tests" / "python"))


def pick_domain() -> object | None:
    if "ROS_DOMAIN_ID" in os.environ:
        return None
    import ros_domain
    lock = ros_domain.acquire(range(75, 80))
    os.environ["ROS_DOMAIN_ID"] = str(lock.domain_id)
    return lock


def big_scene(n: int, path: Path, seed: int = 1) -> None:
    """n bodies (block1 at rest in the lower-left corner, the rest moving) as a scene file."""
    import yaml
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


def run_case(n: int, seconds: float, windows: int, trials: int) -> dict[str, float]:
    import rclpy
    from geometry_msgs.msg import PoseArray, WrenchStamped
    from std_srvs.srv import Empty

    from collide_ros.testing import NodeProcess, SimClient

    args = ["-p", "time_step:=0.001", "-p", "state_rate:=100.0", "-p", "tf_rate:=50.0",
            "-p", "marker_rate:=20.0", "-p", "real_time_factor:=1.0"]
    tmp = None
    if n <= 6:
        args += ["-p", f"blocks:={n}"]
    else:
        tmp = Path(tempfile.mkdtemp()) / f"bench_{n}.yaml"
        big_scene(n, tmp)
        args += ["-p", f"scene_file:={tmp}"]
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    proc = NodeProcess(*args)
    client = SimClient(context=ctx, watch=("diagnostics",))
    raw_msgs: list[tuple[float, bytes]] = []
    client.node.create_subscription(PoseArray, "bodies/poses", lambda m: raw_msgs.append((time.perf_counter(), m)),
                                    10, raw=True)
    out: dict[str, float] = {"bodies": float(n)}
    try:
        if not client.wait_for(lambda: len(raw_msgs) > 0, 120.0):
            raise RuntimeError(f"node did not publish:\n{proc.output()}")
        client.spin(1.0)
        cpu, rates = [], []
        for _ in range(windows):
            raw_msgs.clear()
            c0, t0 = cpu_seconds(proc.proc.pid), time.perf_counter()
            client.spin(seconds)
            c1, t1 = cpu_seconds(proc.proc.pid), time.perf_counter()
            cpu.append(100.0 * (c1 - c0) / (t1 - t0))
            rates.append(len(raw_msgs) / (t1 - t0))
        out["cpu_percent"] = statistics.median(cpu)
        out["poses_hz"] = statistics.median(rates)
        d = client.fresh("diagnostics", timeout=5.0)
        vals = {kv.key: kv.value for kv in d.status[0].values} if d else {}
        for key in ("real_time_factor", "step_time_mean_ms", "publish_time_mean_ms", "steps_per_second"):
            out[key] = float(vals.get(key, "nan"))
        # ---- latency ----
        lat = []
        rng = np.random.default_rng(3)
        assert client.wait_subscribed("block1/thrust", WrenchStamped)
        cmd = WrenchStamped()
        cmd.wrench.force.x = 10.0
        for _ in range(trials):
            client.call(Empty, "reset")
            raw_msgs.clear()
            if not client.wait_for(lambda: len(raw_msgs) >= 3, 10.0):
                continue  # trial lost (node busy); the count of trials is reported
            x0 = pose_x0(raw_msgs[-1][1])
            client.spin(float(rng.uniform(0.0, 0.01)))  # a random phase against the 100 Hz publishing
            raw_msgs.clear()
            t_pub = time.perf_counter()
            client.publish("block1/thrust", cmd)
            seen: list[float] = []

            def moved() -> bool:
                for t, raw in raw_msgs:
                    if pose_x0(raw) != x0:
                        seen.append(t)
                        return True
                return False
            if client.wait_for(moved, 10.0) and seen:
                lat.append(1e3 * (seen[0] - t_pub))
        out["trials"] = float(len(lat))
        out["latency_p50_ms"] = statistics.median(lat) if lat else float("nan")
        out["latency_p90_ms"] = float(np.percentile(lat, 90)) if lat else float("nan")
    finally:
        client.close()
        proc.stop()
        rclpy.shutdown(context=ctx)
        if tmp is not None:
            tmp.unlink(missing_ok=True)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="length of one CPU window (s)")
    ap.add_argument("--windows", type=int, default=3, help="CPU windows per case (median)")
    ap.add_argument("--trials", type=int, default=25, help="latency trials per case")
    ap.add_argument("--bodies", type=int, nargs="+", default=[6, 1000])
    a = ap.parse_args()
    lock = pick_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    rows = [run_case(n, a.seconds, a.windows, a.trials) for n in a.bodies]
    print(f"\nsim node, 1 kHz physics, 100 Hz poses/states, 50 Hz tf, 20 Hz markers, RTF 1; "
          f"{os.cpu_count()} cores; ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']}\n")
    print("| bodies | node CPU (% of a core) | poses received (Hz) | real-time factor | step (ms) "
          "| publishing per step (ms) | command -> pose p50 / p90 (ms) | trials |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {int(r['bodies'])} | {r['cpu_percent']:.1f} | {r['poses_hz']:.1f} | {r['real_time_factor']:.3f} "
              f"| {r['step_time_mean_ms']:.4f} | {r['publish_time_mean_ms']:.4f} "
              f"| {r['latency_p50_ms']:.1f} / {r['latency_p90_ms']:.1f} | {int(r['trials'])} |")
    if lock is not None:
        lock.release()  # type: ignore[attr-defined]
    return 0


if __name__ == "__main__":
    sys.exit(main())
