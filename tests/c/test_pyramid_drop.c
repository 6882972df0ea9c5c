/* test_pyramid_drop: the contact bench's drop12 scene (bench/scenes.py drop_on_pyramid): a base-12
 * pyramid of unit boxes (1 kg, mu 0.6, e 0) on a static ground box 44 m x 1 m (top face y = 0), g = 10
 * m/s^2, no damping, and a 5 kg unit box from 2 m above the top at 8 m/s down, turning at 1 rad/s.
 * The hit topples part of the pyramid; the rest of it comes nearly to rest in a 78-body island while
 * the boxes that fell tumble on: its nearly resting steps are where the contact regime's precise and
 * split retries run (contact_regime.c). Bodies are added in the bench's order (pyramid rows, ground,
 * box), so this is the bench's trajectory, step for step, over its first 160 steps at dt = 1/60 s.
 * Asserted at every step end: LC_OK; no overlap deeper than 2.5e-7 m (HC_PILE_OVERLAP_TOL: the pile is
 * one island of 78 bodies, whose sub-steps are pile sub-steps projected to 1e-7 m); the total
 * energy never rises by more than 1e-9 of itself (nothing drives the scene: the contacts dissipate,
 * the projection's lift and the energy guard's rounding stay below that, contact_regime.md). Over the
 * run: what a step kept unresolved (lc_counters contact_unresolved) is within the same 1e-9. */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

#define BASE 12
#define STEPS 160
#define GAIN_TOL 1e-9

int main(void)
{
    const double box[4] = {-30.0, -1.0, 30.0, 40.0};
    lc_world *w;
    lc_counters tot;
    lc_energy en;
    double e_prev, worst = -INFINITY, t_worst = 0.0;
    hc_mon m;
    int k;
    w = sc_drop_on_pyramid(BASE);
    if (!w) return CHECK_SUMMARY("test_pyramid_drop");
    if (!hc_mon_init(&m, w, "drop on a base-12 pyramid", 1.0 / 60.0, box)) return CHECK_SUMMARY("test_pyramid_drop");
    m.overlap_tol = HC_PILE_OVERLAP_TOL;
    CHECK(lc_world_get_energy(w, &en) == LC_OK, "%s", "energy");
    e_prev = en.total;
    for (k = 0; k < STEPS && hc_step(&m); ++k) {
        double gain;
        CHECK(lc_world_get_energy(w, &en) == LC_OK, "%s", "energy");
        gain = (en.total - e_prev) / fabs(e_prev);
        if (gain > worst) {
            worst = gain;
            t_worst = lc_world_get_time(w);
        }
        e_prev = en.total;
    }
    CHECK(worst <= GAIN_TOL, "the largest step gain is %.3g of the energy (t = %.4f s), above %g", worst, t_worst,
          GAIN_TOL);
    CHECK(lc_world_get_counters(w, NULL, &tot) == LC_OK, "%s", "counters");
    CHECK(tot.max_unresolved_energy <= GAIN_TOL * fabs(e_prev) && tot.max_unresolved_overlap <= 1e-9,
          "%llu steps kept unresolved, the largest keeping %.3g J (%.3g of the energy) and %.3g m of overlap",
          (unsigned long long)tot.contact_unresolved, tot.max_unresolved_energy, tot.max_unresolved_energy / fabs(e_prev),
          tot.max_unresolved_overlap);
    printf("test_pyramid_drop: %d steps, largest step gain %.3g of the energy (t = %.4f s), precise retries %llu\n",
           m.steps_ok, worst, t_worst, (unsigned long long)tot.contact_precise_retries);
    hc_finish(&m, STEPS);
    hc_mon_free(&m);
    lc_world_destroy(w);
    return CHECK_SUMMARY("test_pyramid_drop");
}
