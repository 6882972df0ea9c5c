/* test_event_clocks: the event regime's lazy clocks (event_regime.c) on seed blocks in free flight at
 * the benchmark's crowding (bench/scenes.py many(n): n blocks of 1 m x 0.5 m, 1 kg, e = 1, on a grid of
 * 2 m cells in walls sized for n / 0.8 cells, random angles, velocities in [-3, 3]^2 m/s, spins in
 * [-2, 2] rad/s), 60 steps of 1/60 s:
 *   - an impact advances only the bodies it involves and the ones near it: closed-form advances per
 *     block per step stay below half of (impacts per step + 1), what advancing every body to every
 *     impact's time and to the step's end costs (about 2.7 against 9.2 for 500 blocks at g = 0);
 *   - energy is conserved to 1e-12 of its value (e = 1, no friction, closed-form free flight: only
 *     round-off changes it, ~1e-16 per impact; with gravity the potential energy counts);
 *   - the same run twice gives the same lc_world_state_hash after every step;
 *   - every block stays inside the walls. */
#include <math.h>
#include <stdio.h>

#include "test_hard_common.h"

#define STEPS 60

static lc_world *blocks(int n, double g, uint64_t seed)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4];
    sc_rng rng;
    int i, cells = (int)ceil(sqrt(n / 0.8));
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    d.damping = 0.0;
    w = sc_world(&d);
    if (w == NULL) return NULL;
    hc_walls(w, 0.0, 0.0, 2.0 * cells, 2.0 * cells, 1.0, 0.0, walls);
    rng.s = seed;
    for (i = 0; i < n; i++)
        hc_box(w, 1.0, 0.5, 1.0 + 2.0 * (i % cells), 1.0 + 2.0 * (i / cells), sc_uniform(&rng, 0.0, SC_PI),
               sc_uniform(&rng, -3, 3), sc_uniform(&rng, -3, 3), sc_uniform(&rng, -2, 2), 1.0, 1.0, 0.0);
    return w;
}

static void run(int n, double g)
{
    lc_world *w = blocks(n, g, 77u), *twin = blocks(n, g, 77u);
    lc_counters last, total;
    lc_energy e0, e1;
    lc_state_view sv;
    double size = 2.0 * ceil(sqrt(n / 0.8)), adv, drift, max_advances;
    int i, same = 1, inside = 1;
    if (w == NULL || twin == NULL) return;
    e0 = sc_energy(w);
    for (i = 0; i < STEPS; i++) {
        sc_step_n(w, 1.0 / 60.0, 1);
        sc_step_n(twin, 1.0 / 60.0, 1);
        if (lc_world_state_hash(w) != lc_world_state_hash(twin)) same = 0;
    }
    e1 = sc_energy(w);
    CHECK(lc_world_get_counters(w, &last, &total) == LC_OK, "%s", "counters");
    adv = (double)total.analytic_advances / STEPS / n;
    max_advances = 0.5 * ((double)total.collisions / STEPS + 1.0);
    drift = fabs(e1.total - e0.total) / e0.total;
    printf("%d blocks, g = %g: %.3g impacts and %.3g closed-form advances per block per step, energy drift %.3g\n",
           n, g, (double)total.collisions / STEPS, adv, drift);
    CHECK(total.collisions > 100, "%d blocks, g = %g: the scene has impacts (%llu)", n, g,
          (unsigned long long)total.collisions);
    CHECK(adv < max_advances, "%d blocks, g = %g: %.3g closed-form advances per block per step (< %.3g)", n, g, adv,
          max_advances);
    CHECK(drift <= 1e-12, "%d blocks, g = %g: energy drift %.3g (<= 1e-12)", n, g, drift);
    CHECK(same, "%d blocks, g = %g: two runs give the same state hash after every step", n, g);
    CHECK(lc_world_get_state(w, &sv) == LC_OK, "%s", "state");
    for (i = 0; i < sv.count; i++)
        if (!sv.is_static[i]) {
            const double *s = &sv.state[i * 6];
            if (!(s[0] > 0.0 && s[0] < size && s[1] > 0.0 && s[1] < size)) inside = 0;
        }
    CHECK(inside, "%d blocks, g = %g: every block inside the walls", n, g);
    lc_world_destroy(w);
    lc_world_destroy(twin);
}

int main(void)
{
    run(500, 0.0);
    run(500, 9.8);
    return CHECK_SUMMARY("test_event_clocks");
}
