"""libcollide repro: a resting stack of 10 seed blocks sinks, jitters and costs far too much (bench/ stacks).

10 blocks 1 m wide x 0.5 m tall, 1 kg, mu 0.6, e 0 (or e 1 with --elastic), stacked exactly touching
on a static floor, g = 9.8, dt 1/60, 1 s simulated (or until 30 s of CPU). Expected (issue 4):
the top block stays at y = 4.75 m within 0.01 mm, no sideways drift, steps cost well under 1 ms.
At commit b2b0f9b bench/run measured, for e = 0, 287 ms of CPU per step (run stopped by its CPU
budget after 0.23 s simulated); the 02:44 UTC build of the working tree: 40 ms per step, the top block
94 mm lower and 20 mm sideways after 6.3 s, jitter (std of its height over the last 5 s) 28 mm; e = 1:
about 5 s of CPU per step. At commit 64744d8 (Release): step 9 alone takes 22 s of CPU (4849
collisions, 271 544 serial passes, 147 060 contact solves in that step) and a later step runs for
more than 100 s. The script prints every step slower than 0.5 s and stops after 30 s of CPU.

    source scripts/env.sh && python bench/repro/stack10_sink_jitter.py [--elastic]
"""
import sys
import time

import numpy as np

import collide

e = 1.0 if "--elastic" in sys.argv else 0.0
w = collide.World(gravity=(0.0, -9.8), damping=0.0)
blocks = [w.add_box(1.0, 0.5, position=(0.0, 0.25 + 0.5 * i), mass=1.0, elasticity=e, friction=0.6)
          for i in range(10)]
w.add_box(20.0, 1.0, position=(0.0, -0.5), static=True, elasticity=e, friction=0.6)
top = blocks[-1]
heights, cpu = [], 0.0
for k in range(60):
    t0 = time.process_time()
    w.step(1 / 60)
    dt = time.process_time() - t0
    cpu += dt
    heights.append(top.position[1])
    if dt > 0.5:
        c = w.counters(last=True)
        print(f"step {k + 1}: {dt:.2f} s CPU, collisions {c['collisions']}, serial passes {c['serial_iterations']}, "
              f"contact solves {c['contact_solves']}, top y {heights[-1]:.6f}", flush=True)
    if cpu > 30:
        break
h = np.array(heights)
print(f"e = {e:g}: {k + 1} steps, {1e3 * cpu / (k + 1):.1f} ms CPU per step; top block: sink "
      f"{1e3 * (4.75 - h[-1]):.3f} mm, dx {1e3 * top.position[0]:+.3f} mm, height std {1e3 * h.std():.3f} mm")
