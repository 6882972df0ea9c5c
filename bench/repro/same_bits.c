/* same_bits.c - state hashes of the benchmark's scenes after a fixed run, for engine changes meant to
 * change speed only: built against two libraries, both must print the same lines (bit-identical
 * states). A change that moves any result by one rounding shows here at once (the seed scenes are
 * chaotic), and then needs the full test suite and benchmark instead.
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include -Itests/c bench/repro/same_bits.c \
 *      build/libcollide.a -lm -o /tmp/same_bits && /tmp/same_bits
 * Prints "<scene> <steps> <hash> <force evaluations> <collisions>" per scene. */
#include <stdio.h>

#include "test_hard_common.h"

typedef struct scene { const char *name; int steps; } scene;

/* n seed blocks (1 m x 0.5 m, 1 kg, e = 1) on a grid of 2 m cells, cols a row, in walls around it,
 * random angles, velocities in [-3, 3]^2 m/s and spins in [-2, 2] rad/s from generator seed. */
static lc_world *blocks_in_box(const lc_world_def *d, int n, int cols, uint64_t seed)
{
    lc_world *w = sc_world(d);
    lc_body_id walls[4];
    sc_rng rng;
    int i;
    hc_walls(w, 0.0, 0.0, 2.0 * cols, 2.0 * cols, 1.0, 0.0, walls);
    rng.s = seed;
    for (i = 0; i < n; i++)
        hc_box(w, 1.0, 0.5, 1.0 + 2.0 * (i % cols), 1.0 + 2.0 * (i / cols), sc_uniform(&rng, 0.0, SC_PI),
               sc_uniform(&rng, -3, 3), sc_uniform(&rng, -3, 3), sc_uniform(&rng, -2, 2), 1.0, 1.0, 0.0);
    return w;
}

static lc_world *build(int which)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id ids[20];
    int i;
    switch (which) {
    case 0: /* pyramid base 20 (Box2D's layout, mu 0.6, g = 10) */
    case 1: /* pyramid base 50 */
        d.gravity.y = -10.0;
        w = sc_world(&d);
        sc_static_box(w, 200.0, 1.0, 0.0, -0.5, 0.0);
        sc_pyramid(w, which == 0 ? 20 : 50, 0.6, NULL);
        return w;
    case 2: /* the seed scene, 20 blocks, e = 1, g = 0 */
    case 3: /* the same at g = 9.8 */
        d.gravity.y = which == 2 ? 0.0 : -9.8;
        d.damping = 0.0;
        return blocks_in_box(&d, 20, 5, 7);
    case 4: /* the settling scene, layout 1 (e 0.8, mu 0.5) */
        d.gravity.y = -9.8;
        w = sc_world(&d);
        hc_settling_layout(w, 1, 0.8, 0.5, ids);
        return w;
    case 5: /* the scaling scene's 400 blocks (sort-and-sweep), e = 1, g = 0 */
        d.gravity.y = 0.0;
        d.damping = 0.0;
        return blocks_in_box(&d, 400, 23, 11);
    default: /* a stack of 10 */
        d.gravity.y = -9.8;
        w = sc_world(&d);
        hc_static(w, 20.0, 1.0, 0.0, -0.5, 0.0, 0.5);
        for (i = 0; i < 10; i++) hc_box(w, 1.0, 0.5, 0.0, 0.25 + 0.5 * i, 0.0, 0, 0, 0, 1.0, 0.0, 0.5);
        return w;
    }
}

int main(void)
{
    static const scene scenes[] = {{"pyramid20", 300}, {"pyramid50", 60}, {"seed_g0", 600},
                                   {"seed_g9.8", 600}, {"settling", 1200}, {"many400", 200}, {"stack10", 600}};
    int k;
    for (k = 0; k < (int)(sizeof scenes / sizeof scenes[0]); k++) {
        lc_world *w = build(k);
        lc_counters last, c;
        int n = sc_step_n(w, 1.0 / 60.0, scenes[k].steps);
        lc_world_get_counters(w, &last, &c);
        printf("%-10s %5d %016llx %8llu %6llu\n", scenes[k].name, n, (unsigned long long)lc_world_state_hash(w),
               (unsigned long long)c.force_evaluations, (unsigned long long)c.collisions);
        lc_world_destroy(w);
    }
    return 0;
}
