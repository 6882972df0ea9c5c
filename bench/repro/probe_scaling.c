/* probe_scaling.c - the benchmark's scaling scene straight through the C API: n seed blocks (1 m x
 * 0.5 m, 1 kg, e = 1) on a grid of 2 m cells in a walled box sized as bench/scenes.py's many(n) (cells =
 * ceil(sqrt(n / 0.8)) a side), random angles, velocities in [-3, 3]^2 m/s and spins in [-2, 2] rad/s
 * (tests/c/scenes.h's generator, not the benchmark's), g = 0, dt = 1/60.
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include -Itests/c bench/repro/probe_scaling.c \
 *      build/libcollide.a -lm -o /tmp/probe_scaling && /tmp/probe_scaling [n 2000] [steps 60] [broadphase 0]
 * broadphase: an lc_broadphase (0 auto, 1 brute force, 2 sort-and-sweep, 3 grid). Prints the CPU time
 * per step, impacts and closed-form advances per step, the whole-world pair searches by kind, and the
 * state hash (for changes meant to keep every bit: the same hash before and after, and for every
 * broadphase). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "test_hard_common.h"

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 2000, steps = argc > 2 ? atoi(argv[2]) : 60, i, cells;
    int broadphase = argc > 3 ? atoi(argv[3]) : 0;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4];
    lc_counters last, total;
    sc_rng rng;
    double size, t0, cpu;
    if (n < 1 || n > 100000 || steps < 1 || broadphase < 0 || broadphase > 3) {
        fprintf(stderr, "usage: probe_scaling [n 1..100000] [steps >= 1] [broadphase 0..3]\n");
        return 2;
    }
    cells = (int)ceil(sqrt(n / 0.8));
    size = 2.0 * cells;
    d.gravity.y = 0.0;
    d.damping = 0.0;
    d.broadphase = (lc_broadphase)broadphase;
    w = sc_world(&d);
    hc_walls(w, 0.0, 0.0, size, size, 1.0, 0.0, walls);
    rng.s = 11;
    for (i = 0; i < n; i++)
        hc_box(w, 1.0, 0.5, 1.0 + 2.0 * (i % cells), 1.0 + 2.0 * (i / cells), sc_uniform(&rng, 0.0, SC_PI),
               sc_uniform(&rng, -3, 3), sc_uniform(&rng, -3, 3), sc_uniform(&rng, -2, 2), 1.0, 1.0, 0.0);
    t0 = cpu_seconds();
    if (sc_step_n(w, 1.0 / 60.0, steps) != steps) return 1;
    cpu = cpu_seconds() - t0;
    lc_world_get_counters(w, &last, &total);
    printf("%d blocks, %d steps: %.3f ms per step, %.1f impacts and %.0f closed-form advances per step, "
           "searches brute/sweep/grid %llu/%llu/%llu, hash %016llx\n",
           n, steps, 1e3 * cpu / steps, (double)total.collisions / steps, (double)total.analytic_advances / steps,
           (unsigned long long)total.brute_force_steps, (unsigned long long)total.sort_and_sweep_steps,
           (unsigned long long)total.grid_steps, (unsigned long long)lc_world_state_hash(w));
    lc_world_destroy(w);
    return 0;
}
