"""libcollide repro: energy gain in a resting 1:1000 mass-ratio stack (found by bench/ hard cases).

A 1 kg seed block (1 m x 0.5 m) on a static floor with a 1000 kg seed block resting on it, exactly
touching, mu 0.6, e 0, g 9.8, dt 1/60. Nothing drives the scene, so the total energy
(KE + m g y, computed here from the states) must never rise above its initial value beyond rounding
(~1e-12 relative). At commits 64744d8 and 8120888 the first step already ends with E = 1.00113 E0:
both blocks move down (vy -0.027 and -0.13 m/s) while their positions stay where they were (the
end-of-step position projection seems to undo the fall but keep its kinetic energy); bench/run
measured a rise of +0.116 % within 0.53 s at 64744d8, and at 8120888 a step after the 2nd makes no
progress for 40 s. The script prints the first steps where E exceeds E0 by more than 1e-9 E0.

    source scripts/env.sh && python bench/repro/mass_ratio_energy_gain.py
"""
import time

import numpy as np

import collide

w = collide.World(gravity=(0.0, -9.8), damping=0.0)
w.add_box(1.0, 0.5, position=(0.0, 0.25), mass=1.0, elasticity=0.0, friction=0.6)
w.add_box(1.0, 0.5, position=(0.0, 0.75), mass=1000.0, elasticity=0.0, friction=0.6)
w.add_box(20.0, 1.0, position=(0.0, -0.5), static=True, elasticity=0.0, friction=0.6)
m = np.array([1.0, 1000.0])
inertia = m * (1.0 + 0.25) / 12.0


def energy() -> float:
    s = w.state[:2]
    return float(np.sum(0.5 * m * (s[:, 3] ** 2 + s[:, 4] ** 2) + 0.5 * inertia * s[:, 5] ** 2 + m * 9.8 * s[:, 1]))


e0 = energy()
cpu, shown, worst = 0.0, 0, 0.0
for k in range(60):
    t0 = time.process_time()
    w.step(1 / 60)
    cpu += time.process_time() - t0
    rise = (energy() - e0) / e0
    worst = max(worst, rise)
    if rise > 1e-9 and shown < 5:
        shown += 1
        s = w.state
        print(f"step {k + 1}: E - E0 = {rise:+.3e} E0; light block y {s[0, 1]:.6f} vy {s[0, 4]:+.3e}, "
              f"heavy block y {s[1, 1]:.6f} vy {s[1, 4]:+.3e}", flush=True)
    if cpu > 60:
        break
print(f"{k + 1} steps, {cpu:.2f} s CPU; largest rise {worst:+.3e} E0")
