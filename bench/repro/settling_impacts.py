"""libcollide repro: where bench/run's settling scene spends its impacts, second by second.

The settling scene (bench/scenes.py: 20 blocks 1 m x 0.5 m in the walled 10 m box, e 0.8, mu 0.5,
g 9.8) comes to rest in about 6 s. While it settles, blocks on the floor bounce ever smaller, and each
bounce is an impact with its own time-of-impact search. Below restitution_threshold an impact of a
pair with e < 1 does not bounce; run with --threshold 1e-4 (= resting_speed, the engine before the
threshold) to compare.

    source scripts/env.sh && python bench/repro/settling_impacts.py [--threshold 1e-2] [--seconds 10]
"""
import argparse
import sys
import time
from pathlib import Path

import collide

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import scenes  # noqa: E402  (bench/scenes.py)

ap = argparse.ArgumentParser()
ap.add_argument("--threshold", type=float, default=None, help="restitution_threshold, m/s (default: the engine's)")
ap.add_argument("--seconds", type=int, default=10)
a = ap.parse_args()
sc = scenes.settling()
settings = {} if a.threshold is None else {"restitution_threshold": a.threshold}
w = collide.World(gravity=(0.0, -sc.gravity), damping=0.0, **settings)
for b in sc.boxes:
    w.add_box(b.w, b.h, position=(b.x, b.y), angle=b.angle, velocity=(b.vx, b.vy), angular_velocity=b.omega,
              mass=b.mass, static=b.static, elasticity=sc.e, friction=sc.mu)
print(f"restitution_threshold {w.settings['restitution_threshold']:g} m/s")
total = 0
for sec in range(a.seconds):
    t0 = time.process_time()
    impacts = evals = 0
    for _ in range(60):
        w.step(1 / 60)
        c = w.counters(last=True)
        impacts += c["collisions"]
        evals += c["force_evaluations"]
    total += impacts
    e = w.energy
    print(f"second {sec + 1}: {1e3 * (time.process_time() - t0) / 60:.3f} ms CPU per step, impacts {impacts}, "
          f"force evaluations {evals}, kinetic energy {e.translational + e.rotational:.3g} J", flush=True)
print(f"impacts in {a.seconds} s: {total}")
