/* test_event_tolerances: the event regime at looser time-of-impact tolerances, on the benchmark's seed
 * scene with gravity (bench/scenes.py seed(20, 9.8, s), s = 1..8, the exact layouts in seed_layouts.h:
 * 20 blocks of 1 m x 0.5 m, 1 kg, in a walled 10 m box, e = 1, no friction, no damping), stepped at
 * dt = 1/60 s for STEPS steps with toi_time_tolerance 1e-6 s and toi_distance_tolerance 1e-8 m
 * (bench/main.py's variant "libcollide tol 1e-6"), 1e-8 s and 1e-8 m, and 1e-8 s with the default
 * 1e-10 m, every other setting the engine's default.
 *
 * A looser time tolerance lets a search stop up to that much before the vertex reaches contact_gap
 * (on the open side of its bracket, time_of_impact.c): |vn| tol, 1.8e-5 m at 18 m/s and 1e-6 s, is
 * beyond contact_distance (1e-5 m), where the impact would collect no touch; and an impact found by
 * the pair's first touch resolves only the vertices then within contact_distance, while another
 * corner of the spun block turns in within the same interval. Both must still end in an impact at
 * every touch. Asserted at every step (test_hard_common.h's monitor):
 *  - lc_world_step returns LC_OK (a missed crossing ends as a body deep inside a wall, which the
 *    step refuses with LC_ERR_NUMERIC; an impulse beside an edge as an energy gain it refuses);
 *  - no pair overlaps by more than 1e-9 m (HC_OVERLAP_TOL): impacts are taken on the open side of
 *    contact_gap (1e-7 m) whatever the tolerance, and the end-of-step projection puts any point found
 *    inside back to the gap, so a step ends with no overlap but round-off;
 *  - no block centre leaves the box, every value finite, the clock at k dt;
 *  - energy: |E - E0| <= 1e-9 E0. Free flight is in closed form (round-off only), and an e = 1
 *    impulse conserves kinetic energy exactly whatever its normal, point and instant, so the time of
 *    impact's tolerance moves where impacts happen, not the energy; what can change it is a resting
 *    band event (an approach under resting_speed = 1e-4 m/s held, not bounced: <= 5e-9 J, 5e-12 of
 *    E0 ~ 1e3 J, potential energy from y = 0) or a lift by the end-of-step projection (m g
 *    contact_gap ~ 1e-6 J, 1e-9 E0), while a crossing missed and pushed out by the projection costs
 *    m g times its depth (a 0.18 m lift: 1.8 J, 1.5e-3 E0). Round-off over 1 600 steps and ~3e3
 *    impacts per run is ~1e-14 of E0 (measured gains up to 1e-11 J).
 * STEPS reaches past step 175, where seed 2 at 1e-6 s lands a block flat on the floor at 18 m/s,
 * and past step 1 527, where seed 6 at 1e-8 s / 1e-10 m turns a corner of a block into another just
 * after an impact at its other corner. */
#include <math.h>
#include <stdio.h>

#include "test_hard_common.h"
#include "seed_layouts.h"

#define STEPS 1600

static void run(int seed, double time_tol, double distance_tol)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    hc_mon m;
    char label[96];
    const double box[4] = {0.0, 0.0, 10.0, 10.0};
    int i, k;
    d.gravity.x = 0.0;
    d.gravity.y = -9.8;
    d.damping = 0.0;
    d.toi_time_tolerance = time_tol;
    d.toi_distance_tolerance = distance_tol;
    w = sc_world(&d);
    if (w == NULL) return;
    snprintf(label, sizeof label, "seed(20, 9.8, %d), toi tolerances %g s, %g m", seed, time_tol, distance_tol);
    for (i = 0; i < SEED_BLOCKS; i++) {
        const double *b = seed_layouts[seed - 1][i];
        hc_box(w, 1.0, 0.5, b[0], b[1], b[2], b[3], b[4], b[5], 1.0, 1.0, 0.0);
    }
    /* bench/scenes.py walls(): inner faces on [0, 10]^2, corners filled, in this order */
    hc_static(w, 12.0, 1.0, 5.0, -0.5, 1.0, 0.0);
    hc_static(w, 1.0, 12.0, 10.5, 5.0, 1.0, 0.0);
    hc_static(w, 12.0, 1.0, 5.0, 10.5, 1.0, 0.0);
    hc_static(w, 1.0, 12.0, -0.5, 5.0, 1.0, 0.0);
    if (!hc_mon_init(&m, w, label, HC_DT, box)) {
        lc_world_destroy(w);
        return;
    }
    for (k = 1; k <= STEPS; k++)
        if (!hc_step(&m)) break;
    hc_finish(&m, STEPS);
    CHECK(m.max_gain <= 1e-9 * m.e0 && m.max_loss <= 1e-9 * m.e0,
          "%s: energy gained %.3e J and lost %.3e J of E0 = %.6g J (allowed 1e-9 E0 each way)", label, m.max_gain,
          m.max_loss, m.e0);
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    const double tols[3][2] = {{1e-6, 1e-8}, {1e-8, 1e-8}, {1e-8, 1e-10}};   /* time (s), distance (m) */
    int s, t;
    for (t = 0; t < 3; t++)
        for (s = 1; s <= SEED_LAYOUTS; s++) run(s, tols[t][0], tols[t][1]);
    return CHECK_SUMMARY("test_event_tolerances");
}
