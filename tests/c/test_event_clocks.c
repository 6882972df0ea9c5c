/* test_event_clocks: the event regime's lazy clocks (event_regime.c) on seed blocks in free flight at
 * the benchmark's crowding (bench/scenes.py many(n): n blocks of 1 m x 0.5 m, 1 kg, e = 1, on a grid of
 * 2 m cells in walls sized for n / 0.8 cells, random angles, velocities in [-3, 3]^2 m/s, spins in
 * [-2, 2] rad/s), 60 steps of 1/60 s:
 *   - an impact advances only the bodies it involves and the ones near it: closed-form advances per
 *     block per step stay below half of (impacts per step + 1), what advancing every body to every
 *     impact's time and to the step's end costs (about 1.5 against 9.2 for 500 blocks at g = 0);
 *   - and the cost per block does not grow with the world: a block far from every impact goes to the
 *     step's end in one advance, and an impact costs a bounded number (its two bodies to its time and
 *     on to the end, the bodies near them brought to its time, and the time-of-impact searches of the
 *     crossings it makes, bisections of two bodies: about 35 here), so advances per block per step stay
 *     below 1 + 64 x impacts per block per step, at 500 and at 2 000 blocks (a clock shared by the
 *     world, whose trial intervals every body goes through, takes 4.3 at 5 000 blocks and 11 at
 *     20 000 against 1.8 at 100);
 *   - energy is conserved to 1e-12 of its value (e = 1, no friction, closed-form free flight: only
 *     round-off changes it, ~1e-16 per impact; with gravity the potential energy counts);
 *   - the same run twice gives the same lc_world_state_hash after every step;
 *   - every block stays inside the walls;
 *   - independent events do not change each other's bits: 200 blocks in their walled box, alone or
 *     with 200 more in another box 1 km away (created after them: the same rows), end 600 steps in
 *     the same bits, whatever the other box's impacts and the order they fall in between (each body
 *     is advanced from its own last event, each crossing's time kept from the step's start). */
#include <math.h>
#include <stdio.h>

#include "test_hard_common.h"

#define STEPS 60

/* n blocks on a grid of 2 m cells in walls sized for n / 0.8 cells, the box's corner at (x0, 0). */
static void add_blocks(lc_world *w, int n, double x0, uint64_t seed)
{
    lc_body_id walls[4];
    sc_rng rng;
    int i, cells = (int)ceil(sqrt(n / 0.8));
    hc_walls(w, x0, 0.0, x0 + 2.0 * cells, 2.0 * cells, 1.0, 0.0, walls);
    rng.s = seed;
    for (i = 0; i < n; i++)
        hc_box(w, 1.0, 0.5, x0 + 1.0 + 2.0 * (i % cells), 1.0 + 2.0 * (i / cells), sc_uniform(&rng, 0.0, SC_PI),
               sc_uniform(&rng, -3, 3), sc_uniform(&rng, -3, 3), sc_uniform(&rng, -2, 2), 1.0, 1.0, 0.0);
}

static void independent(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *alone, *both;
    lc_state_view a, b;
    lc_counters last, total_a, total_b;
    int i, k, n = 200, rows = 200 + 4, same = 1, first = -1;
    d.gravity.y = 0.0;
    d.damping = 0.0;
    alone = sc_world(&d);
    both = sc_world(&d);
    if (alone == NULL || both == NULL) return;
    add_blocks(alone, n, 0.0, 5u);
    add_blocks(both, n, 0.0, 5u);
    add_blocks(both, n, 1000.0, 9u);
    for (k = 0; k < 600 && same; k++) {
        sc_step_n(alone, 1.0 / 60.0, 1);
        sc_step_n(both, 1.0 / 60.0, 1);
        if (lc_world_get_state(alone, &a) != LC_OK || lc_world_get_state(both, &b) != LC_OK) break;
        for (i = 0; i < rows * 6; i++)
            if (a.state[i] != b.state[i]) same = 0;
        if (!same) first = k;
    }
    lc_world_get_counters(alone, &last, &total_a);
    lc_world_get_counters(both, &last, &total_b);
    printf("independent boxes: %llu impacts alone, %llu with the other box; same bits: %d (first step apart %d)\n",
           (unsigned long long)total_a.collisions, (unsigned long long)total_b.collisions, same, first);
    CHECK(total_b.collisions > total_a.collisions && total_a.collisions > 1000,
          "independent boxes: both boxes have impacts (%llu alone, %llu together)",
          (unsigned long long)total_a.collisions, (unsigned long long)total_b.collisions);
    CHECK(same, "independent boxes: 200 blocks end 600 steps in the same bits alone and beside another box "
          "(first step apart: %d)", first);
    lc_world_destroy(alone);
    lc_world_destroy(both);
}

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
    double size = 2.0 * ceil(sqrt(n / 0.8)), adv, drift, max_advances, per_impact;
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
    per_impact = 1.0 + 64.0 * (double)total.collisions / STEPS / n;
    drift = fabs(e1.total - e0.total) / e0.total;
    printf("%d blocks, g = %g: %.3g impacts and %.3g closed-form advances per block per step, energy drift %.3g\n",
           n, g, (double)total.collisions / STEPS, adv, drift);
    CHECK(total.collisions > 100, "%d blocks, g = %g: the scene has impacts (%llu)", n, g,
          (unsigned long long)total.collisions);
    CHECK(adv < max_advances, "%d blocks, g = %g: %.3g closed-form advances per block per step (< %.3g)", n, g, adv,
          max_advances);
    CHECK(adv < per_impact, "%d blocks, g = %g: %.3g closed-form advances per block per step (< 1 + 64 x impacts "
          "per block per step = %.3g)", n, g, adv, per_impact);
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
    run(2000, 0.0);
    independent();
    return CHECK_SUMMARY("test_event_clocks");
}
