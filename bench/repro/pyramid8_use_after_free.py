"""libcollide repro: heap use-after-free in lc_world_step (found by bench/, pyramid scene).

A Box2D-style pyramid of base 8 (36 unit boxes, 1 kg, mu 0.6, e 0, g 10) resting on a ground box.
Stepping it at dt 1/60 aborts the process within two steps on the plain Release build
("malloc(): unsorted double linked list corrupted"); bases up to 7 run. Seen at the 02:44 UTC
working-tree build and still at commit 64744d8. AddressSanitizer (a private -DLIBCOLLIDE_SANITIZE=ON
build of a clean export of 64744d8) reports:

  heap-use-after-free, WRITE of size 1776 in lc_integrate (integrator.c:64)
    <- gap_at (time_of_impact.c:12) <- lc_time_of_impact (time_of_impact.c:47) <- lc_world_step (step.c:372)
  freed by realloc in lc_buf_get (world.c:18) <- solve_block_friction (impulse.c:61, w->b_vec3)
    <- solve_block (impulse.c:133) <- lc_resolve_impacts (impulse.c:204) <- lc_world_step (step.c:395)
  previously allocated by lc_buf_get <- lc_world_step (step.c:303: scratch = lc_buf_get(&w->b_vec3, ...))

i.e. lc_world_step keeps `scratch` (w->b_vec3) across the step, and the friction block solve of an
impact grows the same w->b_vec3 scratch buffer (realloc moves it), leaving `scratch` dangling.

    source scripts/env.sh && python bench/repro/pyramid8_use_after_free.py           # aborts
    LD_PRELOAD=$(gcc -print-file-name=libasan.so) ASAN_OPTIONS=detect_leaks=0 \\
      LD_LIBRARY_PATH=<a LIBCOLLIDE_SANITIZE build>:$LD_LIBRARY_PATH python bench/repro/pyramid8_use_after_free.py
"""
import collide

BASE = 8
w = collide.World(gravity=(0.0, -10.0), damping=0.0)
w.add_box(2.0 * BASE + 20.0, 1.0, position=(0.0, -0.5), static=True, elasticity=0.0, friction=0.6)
for i in range(BASE):
    for j in range(i, BASE):
        x = (i + 1.0) * 0.5 + (j - i) * 1.0 - 0.5 * BASE
        w.add_box(1.0, 1.0, position=(x, 0.5 + i), mass=1.0, elasticity=0.0, friction=0.6)
for k in range(5):
    w.step(1 / 60)
    print(f"step {k + 1} done, t = {w.time:.4f} s", flush=True)
print("no crash")
