"""What rest costs with sleep (lc_world_def.allow_sleep): a resting frictional pyramid asleep against
the same pyramid awake, and a box dropped on the sleeping pyramid.

    source scripts/env.sh && python bench/sleep.py [--base 50] [--repeats 3]

1. Awake: bench/scenes.py's pyramid(base) (base 50: 1 275 unit boxes, mu 0.6, e 0, g 10) with sleep off;
   after 60 steps from the cold start, the CPU per step of the next 120 (thread time).
2. Asleep: the same with allow_sleep = 1: stepped until every box sleeps (at most 600 steps), then the
   CPU per step of the next 120. The ratio asleep / awake is the cost of rest (to be <= 5 %).
3. Dropped on it: with allow_sleep = 1, a 5 kg unit box 10 m above the top falls onto the pyramid
   asleep by then; reported: the step it wakes the pyramid, the deepest overlap of any two boxes at
   any step end from there (bench/metrics.py, exact separating-axis depth), whether every body sleeps
   again within the run, and the CPU per step of the steps from the wake to the end.
Medians over --repeats runs (each in this process, one after the other). Prints a markdown table.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))
sys.path.insert(0, str(ROOT / "bench"))

import metrics  # noqa: E402
import scenes  # noqa: E402
from engines.libcollide import LibCollide  # noqa: E402

DT = 1.0 / 60.0


def cpu_per_step(engine: LibCollide, steps: int) -> float:
    """Thread CPU seconds per step over `steps` steps."""
    return engine.advance(DT, steps) / steps


def asleep(engine: LibCollide) -> int:
    return int(engine.world.counters(last=True)["bodies_asleep"])


def awake_cost(scene: Any) -> float:
    eng = LibCollide(scene, {})
    eng.advance(DT, 60)
    return cpu_per_step(eng, 120)


def asleep_cost(scene: Any) -> tuple[float, int]:
    eng = LibCollide(scene, {"allow_sleep": 1})
    n = len(scene.dynamic)
    for k in range(600):
        eng.step(DT)
        if asleep(eng) == n:
            return cpu_per_step(eng, 120), k + 1
    raise RuntimeError(f"the pyramid did not fall asleep in 600 steps ({asleep(eng)} of {n} asleep)")


def drop(scene: Any, steps: int) -> dict[str, Any]:
    base = scene.meta["base"]
    box = scenes.Box(1.0, 1.0, 0.3, base + 10.5, mass=5.0)
    sc = replace(scene, name=f"{scene.name}_drop", boxes=scene.boxes + (box,))
    eng = LibCollide(sc, {"allow_sleep": 1})
    n = len(sc.dynamic)
    woken, slept_again, states, cpu = -1, -1, [], 0.0
    for k in range(steps):
        t0 = time.thread_time()
        eng.step(DT)
        dt = time.thread_time() - t0
        c = eng.world.counters(last=True)
        if woken < 0 and c["islands_woken"] > 0:
            woken = k + 1
        if woken >= 0:
            cpu += dt
            states.append(eng.states())
            if slept_again < 0 and c["bodies_asleep"] == n:
                slept_again = k + 1
    if eng.status:
        raise RuntimeError(f"step failed with status {eng.status}")
    ov = metrics.max_overlap(sc, np.array(states)) if states else {"max_overlap": float("nan")}
    return {"woken": woken, "slept_again": slept_again, "overlap": ov["max_overlap"],
            "cpu": cpu / max(1, steps - woken + 1) if woken >= 0 else float("nan")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--drop-steps", type=int, default=900)
    args = ap.parse_args()
    scene = scenes.pyramid(args.base)
    scene = replace(scene, meta={**scene.meta, "base": args.base})
    awake, sleeping, fell = [], [], []
    for _ in range(args.repeats):
        awake.append(awake_cost(scene))
        cost, k = asleep_cost(scene)
        sleeping.append(cost)
        fell.append(k)
    d = drop(scene, args.drop_steps)
    a, s = statistics.median(awake), statistics.median(sleeping)
    n = len(scene.dynamic)
    print(f"| pyramid base {args.base} ({n} boxes) | µs per step |")
    print("|---|---|")
    print(f"| awake (sleep off), resting | {a * 1e6:.1f} |")
    print(f"| asleep (all {n} bodies, from step {statistics.median(fell):.0f}) | {s * 1e6:.2f} "
          f"({100.0 * s / a:.2f} % of awake) |")
    print(f"| 5 kg box dropped from 10 m above the sleeping pyramid: from the wake (step {d['woken']}) on | "
          f"{d['cpu'] * 1e6:.1f} |")
    print()
    print(f"Drop: deepest overlap from the wake on {d['overlap'] * 1e3:.3g} mm; every body asleep again at step "
          f"{d['slept_again'] if d['slept_again'] >= 0 else 'never (within the run)'} of {args.drop_steps}. "
          f"Medians over {args.repeats} repeats (drop: one run); dt 1/60 s; thread CPU time.")


if __name__ == "__main__":
    main()
