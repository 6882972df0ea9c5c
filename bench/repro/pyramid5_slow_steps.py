"""libcollide repro: a small resting pyramid makes single steps take seconds (found by bench/).

A Box2D-style pyramid of base 5 (15 unit boxes, 1 kg, mu 0.6, e 0, g 10) resting on a ground box,
exactly touching (ground added last, as bench/ does). Nothing should happen (it is at rest: the top
box stays at 4.5 m) and a step should cost about a millisecond. At commit b2b0f9b (Release build) the
first ~40 steps take ~3.5 ms each; then the resting pyramid starts producing impact events
(collisions, serial passes, inelastic fallbacks) and steps take 0.1-0.8 s of CPU, and step 62 alone
takes 47 s (960 collisions, 145 915 serial passes, 959 inelastic fallbacks, 58 048 contact solves in
that one step). bench/run reports the pyramids as a hang (base 20 = 210 boxes never finishes a
step within 40 s). Fixed at commit 64744d8: 120 steps at 3.5 ms each (kept as a regression check).
The script stops after 60 s of CPU.

    source scripts/env.sh && python bench/repro/pyramid5_slow_steps.py
"""
import time

import collide

BASE = 5
w = collide.World(gravity=(0.0, -10.0), damping=0.0)
top = None
for i in range(BASE):
    for j in range(i, BASE):
        x = (i + 1.0) * 0.5 + (j - i) * 1.0 - 0.5 * BASE
        top = w.add_box(1.0, 1.0, position=(x, 0.5 + i), mass=1.0, elasticity=0.0, friction=0.6)
w.add_box(2.0 * BASE + 20.0, 1.0, position=(0.0, -0.5), static=True, elasticity=0.0, friction=0.6)  # ground last, as in bench/
total = 0.0
for k in range(120):
    t0 = time.process_time()
    w.step(1 / 60)
    dt = time.process_time() - t0
    total += dt
    c = w.counters(last=True)
    if dt > 0.05:
        print(f"step {k + 1}: {dt:.3f} s CPU, collisions {c['collisions']}, serial passes {c['serial_iterations']}, "
              f"inelastic fallbacks {c['inelastic_fallbacks']}, contact solves {c['contact_solves']}, "
              f"top y {top.position[1]:.7f}", flush=True)
    if total > 60:
        print("stopping after 60 s of CPU")
        break
print(f"{k + 1} steps, {total:.2f} s CPU, {1e3 * total / (k + 1):.1f} ms per step on average")
