"""What a laser scanner costs the node: 360 rays at 10 Hz in a world of 1 000 bodies.

    source scripts/env.sh && python bench/scan_bench.py [--bodies 1000] [--range 10] [--scans 200]

The world: 999 boxes (0.2-0.6 m, random angles) on a jittered grid, 2 m apart, inside walls (60 m x
60 m for 1 000 bodies), no gravity, and ``bot`` in the middle carrying the scene format's default
scanner (360 rays, one a degree, --range m long). Measured with the thread's CPU clock, median over
--scans scans:

- ``scan``: collide_ros.sim.scanners.scan_ranges, what the node runs per scan (the rays' ends in numpy,
  one lc_world_ray_cast_batch call, the ranges), and its share of one core at 10 Hz;
- ``batch call``: the C call alone (World.ray_cast_batch);
- ``360 single casts``: the same rays as 360 World.ray_cast calls, for comparison;
- ``step``: one physics step of this world at 1 kHz (time_step 0.001 s), for scale.
Prints a markdown table.
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))

import collide  # noqa: E402
from collide_ros.sim.scanners import ScannerSpec, scan_ranges, scanner_pose  # noqa: E402

RATE = 10.0  # Hz


def build(bodies: int, seed: int = 1) -> collide.World:
    """``bodies`` bodies in all: boxes on a jittered grid 2 m apart, ``bot`` at the centre, and walls."""
    rng = np.random.default_rng(seed)
    side = math.ceil(math.sqrt(bodies))
    half = side  # 2 m per cell
    w = collide.World(gravity=(0.0, 0.0))
    w.add_walls(-half, -half, half, half)
    w.add_box(0.3, 0.3, position=(0.0, 0.0), name="bot")
    placed = 1 + 4
    for i in range(side):
        for j in range(side):
            if placed >= bodies:
                return w
            x, y = -half + 1.0 + 2.0 * i, -half + 1.0 + 2.0 * j
            if abs(x) < 1.5 and abs(y) < 1.5:
                continue  # the bot's cell
            x, y = x + rng.uniform(-0.4, 0.4), y + rng.uniform(-0.4, 0.4)
            w.add_box(*rng.uniform(0.2, 0.6, 2), position=(x, y), angle=float(rng.uniform(-3, 3)))
            placed += 1
    return w


def median_cpu(fn: Callable[[], object], n: int) -> float:
    times = []
    for _ in range(n):
        t0 = time.thread_time()
        fn()
        times.append(time.thread_time() - t0)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=1000)
    ap.add_argument("--range", type=float, default=10.0)
    ap.add_argument("--scans", type=int, default=200)
    args = ap.parse_args(argv)
    w = build(args.bodies)
    spec = ScannerSpec.from_scene(collide.load_scene({
        "bodies": [{"name": "bot", "shape": "box", "width": 0.3, "height": 0.3}],
        "scanners": [{"name": "lidar", "body": "bot", "range_max": args.range, "rate": RATE}]}).scanners[0])
    bot = w.body("bot")
    pose = (0.0, 0.0, 0.0)
    angles = spec.ray_angles()
    ox, oy, h = scanner_pose(spec, pose)
    ends = np.column_stack([ox + spec.range_max * np.cos(h + angles), oy + spec.range_max * np.sin(h + angles)])
    ranges = scan_ranges(w, spec, bot.id, pose, angles)
    scan = median_cpu(lambda: scan_ranges(w, spec, bot.id, pose, angles), args.scans)
    batch = median_cpu(lambda: w.ray_cast_batch((ox, oy), ends, skip=bot), args.scans)
    single = median_cpu(lambda: [w.ray_cast((ox, oy), tuple(e), skip=bot) for e in ends], max(args.scans // 10, 5))
    step = median_cpu(lambda: w.step(0.001), 50)
    print(f"{len(w)} bodies, {spec.rays} rays of {spec.range_max:g} m, {int(np.isfinite(ranges).sum())} hits; "
          f"CPU (thread time), median of {args.scans} scans\n")
    print("| what | ms | at 10 Hz, % of one core |")
    print("|---|---|---|")
    for name, t in (("scan (node's scan_ranges)", scan), ("batch call (C)", batch),
                    ("360 single casts", single)):
        print(f"| {name} | {1e3 * t:.3f} | {100 * RATE * t:.2f} |")
    print(f"| one physics step (for scale) | {1e3 * step:.3f} | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
