"""libcollide repro: how much complementarity-solver work a step does per body, on the hardest scenes.

A step is undone with LC_ERR_NUMERIC once its solves have visited more than LC_MAX_SOLVER_WORK_PER_BODY
(1e9, libcollide/src/tunables.h) matrix entries per body of the world (lc_counters.solver_work: m^2 per
pivot or sweep of a dense solve of m rows, 12 m per product of a sparse one). This prints, per scene, the step
with the most solver work per body, its CPU time, and the cap's margin over it: the cap must sit well
above every legitimate scene, and far below what a pathological step does (four coincident 5e-12 m
decagons at 1e6 m/s, fuzz/corpus/step-regressions/slow-solver-work-coincident-tiny-decagons: 1.7e10
per body at the 500 000-evaluation cap, 110 s).

    source scripts/env.sh && python bench/repro/solver_work_per_body.py [--quick]

The heaviest scene is the box dropped onto a 78-box frictional pyramid (bench/repro/drop_into_pyramid.py):
its first 45 steps, whose impact steps take up to ~10 s each (~2.5 min). The bench scenes run 600 steps
of 1/60 s each, or 60 with --quick. Exit status 1 if any step was undone.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import collide

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import drop_into_pyramid  # noqa: E402  (bench/repro/drop_into_pyramid.py, beside this script)
import engines  # noqa: E402  (bench/engines/)
import scenes  # noqa: E402  (bench/scenes.py)

CAP_PER_BODY = 1e9  # LC_MAX_SOLVER_WORK_PER_BODY in libcollide/src/tunables.h


def world_of(sc: scenes.Scene) -> collide.World:
    """The scene as bench/run builds it for libcollide (bench/engines/libcollide.py)."""
    return engines.make("libcollide", sc).world


def measure(name: str, w: collide.World, dt: float, steps: int) -> tuple[float, float, int]:
    """Most solver work per body in one step, that step's CPU seconds, and the steps undone."""
    most, cpu, undone = 0.0, 0.0, 0
    for _ in range(steps):
        t0 = time.process_time()
        try:
            w.step(dt)
        except collide.CollideError:
            undone += 1
        t = time.process_time() - t0
        per_body = w.counters(last=True)["solver_work"] / len(w)
        if per_body > most:
            most, cpu = per_body, t
    margin = CAP_PER_BODY / most if most > 0 else float("inf")
    print(f"{name:28s} {steps:5d} steps  most per body {most:9.3g} ({cpu:6.2f} s CPU)  cap / most {margin:9.3g}"
          f"  undone {undone}", flush=True)
    return most, cpu, undone


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps of each scene")
    a = ap.parse_args()
    n = 60 if a.quick else 600
    cases = [("seed 20, g 9.8", scenes.seed(20, 9.8, 1)), ("settling", scenes.settling()),
             ("stack 20", scenes.stack(20)), ("mass ratio 1000 stack", scenes.mass_ratio_stack()),
             ("wedged", scenes.wedged()), ("smash", scenes.smash()), ("cradle", scenes.cradle(0.0)),
             ("pyramid base 20", scenes.pyramid(20))]
    worst = 0.0
    undone = 0
    for name, sc in cases:
        most, _, u = measure(name, world_of(sc), 1 / 60, n)
        worst, undone = max(worst, most), undone + u
    most, _, u = measure("drop into pyramid base 12", drop_into_pyramid.world(12), 1 / 60, 45)
    worst, undone = max(worst, most), undone + u
    print(f"most per body over all scenes {worst:.3g}: the cap (1e9) is {CAP_PER_BODY / worst:.3g}x that; "
          f"steps undone {undone}")
    return 1 if undone else 0


if __name__ == "__main__":
    sys.exit(main())
