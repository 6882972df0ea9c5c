"""libcollide repro: the first steps of a cold pyramid (base 100: 5050 boxes).

Box2D's large_pyramid layout (unit boxes, 1 kg, mu 0.6, e 0, g 10, dt 1/60) on a ground box, exactly
touching. Each step prints its CPU time and the counters that explain it (contact solves, products of
the response matrix, the largest residual in m/s^2, TOI searches, collisions, projections).
A cold pile starts from the weights it carries (static_load.c): step 1 takes ~0.9 s, nearly all of it the
projection that lifts the faces created at gap 0 to the contact gap, and the steps after ~0.04 s
(docs/physics.md, "A cold pile starts from the weights it carries"). Started from zero forces
instead, MPRGP (sparse_lcp.c) stops at its product budget 2 m/s^2 off and the drift sets off 512
time-of-impact searches (22 s of CPU for step 1, step 2 unfinished after 14 minutes).
The script stops after --cpu seconds of CPU (default 120) or --steps steps (default 3), whichever
comes first; a step in progress is not interrupted.

    source scripts/env.sh && python bench/repro/pyramid100_cold_start.py [--base 100] [--steps 3] [--cpu 120]
"""
import argparse
import sys
import time
from pathlib import Path

import collide

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import scenes  # noqa: E402  (bench/scenes.py)

ap = argparse.ArgumentParser()
ap.add_argument("--base", type=int, default=100)
ap.add_argument("--steps", type=int, default=3)
ap.add_argument("--cpu", type=float, default=120.0)
a = ap.parse_args()
w = collide.World(gravity=(0.0, -10.0), damping=0.0)
for b in scenes.pyramid(a.base).boxes:   # bench/run's layout, the ground last
    w.add_box(b.w, b.h, position=(b.x, b.y), mass=b.mass, static=b.static, elasticity=0.0, friction=0.6)
total = 0.0
for k in range(a.steps):
    t0 = time.process_time()
    w.step(1 / 60)
    dt = time.process_time() - t0
    total += dt
    c = w.counters(last=True)
    print(f"step {k + 1}: {dt:.2f} s CPU; contact solves {c['contact_solves']}, products {c['contact_solve_iterations']}, "
          f"residual {c['max_lcp_residual']:.3g} m/s^2, TOI searches {c['toi_searches']}, collisions {c['collisions']}, "
          f"projections {c['position_projections']}", flush=True)
    if total > a.cpu:
        print(f"stopping after {total:.0f} s of CPU")
        break
