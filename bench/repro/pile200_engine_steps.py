"""libcollide alone on the node bench's pile scene: where the node's step time goes.

`bench/node_bench.py --bodies pile200` runs the sim node on 200 boxes (0.3-0.8 m, mu 0.5, e 0.3)
dropped into a walled box (`node_bench.pile_scene`). This script builds the same scene with the
Python binding (no ROS, no publishing) and times `World.step` (one `lc_world_step`) at the node's
default time step (1 ms) from the drop on. Per --bin seconds of sim time it prints the median and mean
wall time of a step, the kinetic energy of the boxes at the bin's end (is the pile still tumbling?),
the collisions per step over the bin and the median speed of the boxes at its end (does it rest?),
the islands and contact-regime islands of the last step, and the share of the step time each
pipeline stage took (`World.set_stage_timing(True)`: detection, integration, time-of-impact search,
impulses, projection, contact regime; docs/contact_regime.md). The last line gives the medians over
the whole run. Stops at --until seconds of sim time or after --wall seconds of wall time.

    source scripts/env.sh && python bench/repro/pile200_engine_steps.py [--until 5] [--bin 0.5] [--dt 0.001]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import collide

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from node_bench import pile_scene  # noqa: E402  (bench/node_bench.py)

STAGES = ("detection", "integration", "toi_search", "impulses", "projection", "contact_regime")


def kinetic_energy(world: collide.World, dyn: np.ndarray, m: np.ndarray, inertia: np.ndarray) -> float:
    """Translational + rotational kinetic energy (J) of the dynamic rows."""
    st = np.asarray(world.state)[dyn]
    return float(0.5 * (m * (st[:, 3] ** 2 + st[:, 4] ** 2)).sum() + 0.5 * (inertia * st[:, 5] ** 2).sum())


def stage_times(world: collide.World) -> np.ndarray:
    """Cumulative wall time (s) of the whole step and of each of STAGES."""
    c = world.counters(last=False)
    return np.array([c["time_step"]] + [c[f"time_{s}"] for s in STAGES])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=200, help="boxes in the pile")
    ap.add_argument("--until", type=float, default=5.0, help="sim seconds from the drop")
    ap.add_argument("--bin", type=float, default=0.5, help="sim seconds per printed line")
    ap.add_argument("--dt", type=float, default=0.001, help="time step (s); the node's default is 0.001")
    ap.add_argument("--wall", type=float, default=600.0, help="stop after this many wall seconds")
    a = ap.parse_args()
    world = collide.load_scene(pile_scene(a.bodies)).build()
    world.set_stage_timing(True)
    dyn = ~np.asarray(world.static_mask)
    m, inertia = np.asarray(world.masses)[dyn], np.asarray(world.inertias)[dyn]
    per_bin = max(1, int(round(a.bin / a.dt)))
    steps = int(round(a.until / a.dt))
    print(f"{int(dyn.sum())} dynamic bodies, dt {a.dt} s, libcollide {collide.version()}")
    print("| sim t (s) | step median (ms) | step mean (ms) | KE end (J) | collisions per step | median speed (mm/s) "
          "| islands / contact | " + " / ".join(STAGES) + " (% of step) |")
    print("|---|---|---|---|---|---|---|---|")
    all_times: list[float] = []
    t_start = time.perf_counter()
    s0 = stage_times(world)
    hits0 = world.counters(last=False)["collisions"]
    for k in range(steps):
        t0 = time.perf_counter()
        world.step(a.dt)
        all_times.append(time.perf_counter() - t0)
        if (k + 1) % per_bin == 0 or k + 1 == steps:
            seg = all_times[-per_bin:]
            s1 = stage_times(world)
            share = 100.0 * (s1[1:] - s0[1:]) / max(s1[0] - s0[0], 1e-12)
            s0 = s1
            c = world.counters(last=True)
            hits1 = world.counters(last=False)["collisions"]
            st = np.asarray(world.state)[dyn]
            speed = 1e3 * float(np.median(np.hypot(st[:, 3], st[:, 4])))
            print(f"| {world.time:.2f} | {1e3 * statistics.median(seg):.3f} | {1e3 * statistics.fmean(seg):.3f} "
                  f"| {kinetic_energy(world, dyn, m, inertia):.3g} | {(hits1 - hits0) / len(seg):.2f} | {speed:.3g} "
                  f"| {c['islands']} / {c['contact_islands']} | "
                  + " / ".join(f"{x:.0f}" for x in share) + " |", flush=True)
            hits0 = hits1
        if time.perf_counter() - t_start > a.wall:
            print(f"stopped after {a.wall:g} s of wall time")
            break
    print(f"\n{len(all_times)} steps to t = {world.time:.3f} s: "
          f"step median {1e3 * statistics.median(all_times):.3f} ms, mean {1e3 * statistics.fmean(all_times):.3f} ms "
          f"(real time at dt {a.dt} s needs < {1e3 * a.dt:g} ms for the step and the node's publishing together)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
