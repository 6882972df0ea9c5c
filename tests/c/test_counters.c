/* test_counters: "model only what a scene needs", proven by the work counters (exact integers).
 * (1) g = 0, two bodies drifting apart, nothing touches: 0 contact solves, 0 TOI searches, 0
 *     collisions, 0 resting contacts, 0 impulse solves; with no force of any kind, no force
 *     evaluations either (free flight is advanced in closed form: analytic_advances > 0).
 * (2) the same bodies with gravity on a floor: contact solves do happen (the counters are live).
 * (3) broadphase AUTO (the *_steps counters count detections, >= 1 per step): 3 bodies -> brute
 *     force in every detection, never sort-and-sweep; 200 bodies -> sort-and-sweep every step,
 *     producing far fewer candidate pairs than the 19900 of brute force; around the default
 *     threshold (32): 31 bodies brute force, 32 sort-and-sweep; forced modes are obeyed. */
#include "check.h"
#include "scenes.h"

static void nothing_touches(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_counters last, tot;
    if (!w) return;
    sc_box(w, 1.0, 1.0, -2.0, 0.0, 0.1, -0.5, 0.2, 0.3, 1.0, 1.0);
    sc_box(w, 1.0, 2.0, 2.0, 0.0, -0.2, 0.5, -0.1, -0.4, 2.0, 1.0);
    sc_step_n(w, 0.01, 100);
    lc_world_get_counters(w, &last, &tot);
    printf("nothing touches: steps %llu, force evaluations %llu, analytic advances %llu, broadphase pairs %llu, "
           "toi searches %llu, contact solves %llu\n", (unsigned long long)tot.steps,
           (unsigned long long)tot.force_evaluations, (unsigned long long)tot.analytic_advances,
           (unsigned long long)tot.broadphase_pairs, (unsigned long long)tot.toi_searches,
           (unsigned long long)tot.contact_solves);
    CHECK(tot.steps == 100 && last.steps == 1, "steps counted: total %llu last %llu", (unsigned long long)tot.steps,
          (unsigned long long)last.steps);
    CHECK(tot.contact_solves == 0, "no contact solve when nothing touches (%llu)", (unsigned long long)tot.contact_solves);
    CHECK(tot.toi_searches == 0, "no TOI search when nothing collides (%llu)", (unsigned long long)tot.toi_searches);
    CHECK(tot.collisions == 0 && tot.impulses == 0 && tot.impulse_solves == 0, "%s", "no collisions or impulses");
    CHECK(tot.resting_contacts == 0, "%s", "no resting contacts");
    CHECK(tot.force_evaluations == 0, "no force of any kind -> no force evaluations (%llu)",
          (unsigned long long)tot.force_evaluations);
    CHECK(tot.analytic_advances > 0, "%s", "free flight advanced in closed form");
    lc_world_destroy(w);
}

static void resting_is_counted(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_counters tot;
    if (!w) return;
    lc_world_add_walls(w, -5.0, 0.0, 5.0, 10.0, 1.0, 0.5, NULL);
    sc_box(w, 1.0, 1.0, 0.0, 0.5 + 1e-7, 0.0, 0, 0, 0, 1.0, 0.5);
    sc_step_n(w, 0.01, 100);
    lc_world_get_counters(w, NULL, &tot);
    CHECK(tot.contact_solves > 0, "a block resting on the floor needs contact solves (%llu)",
          (unsigned long long)tot.contact_solves);
    CHECK(tot.resting_contacts > 0, "%s", "resting contacts counted");
    CHECK(tot.force_evaluations + tot.analytic_advances > 0, "%s", "the body was advanced");
    lc_world_destroy(w);
}

/* n bodies of 0.2 m on a grid with 1 m pitch (columns of 10), slow random drift, g = 0. */
static void broadphase(int n, lc_broadphase mode, int expect_sweep)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_counters tot, last;
    sc_rng rng = {12345u};
    int i;
    d.broadphase = mode;
    w = sc_world(&d);
    if (!w) return;
    for (i = 0; i < n; i++)
        sc_box(w, 0.2, 0.2, (double)(i / 10), (double)(i % 10), 0.0, sc_uniform(&rng, -0.1, 0.1),
               sc_uniform(&rng, -0.1, 0.1), 0.0, 1.0, 1.0);
    sc_step_n(w, 0.01, 10);
    lc_world_get_counters(w, &last, &tot);
    printf("broadphase %d bodies mode %d: brute force steps %llu, sort-and-sweep steps %llu, pairs last step %llu\n",
           n, (int)mode, (unsigned long long)tot.brute_force_steps, (unsigned long long)tot.sort_and_sweep_steps,
           (unsigned long long)last.broadphase_pairs);
    if (expect_sweep) {
        CHECK(tot.sort_and_sweep_steps >= 10 && tot.brute_force_steps == 0,
              "%d bodies (mode %d): sort-and-sweep expected, got brute %llu sweep %llu", n, (int)mode,
              (unsigned long long)tot.brute_force_steps, (unsigned long long)tot.sort_and_sweep_steps);
    } else {
        CHECK(tot.brute_force_steps >= 10 && tot.sort_and_sweep_steps == 0,
              "%d bodies (mode %d): brute force expected, got brute %llu sweep %llu", n, (int)mode,
              (unsigned long long)tot.brute_force_steps, (unsigned long long)tot.sort_and_sweep_steps);
    }
    if (n == 200) {
        /* bodies 0.8 m apart: even pairs overlapping along one axis only (same column: 20 x 45 = 900)
         * are far fewer than all 19900 pairs */
        CHECK(last.broadphase_pairs <= 900, "sort-and-sweep should prune: %llu candidate pairs of 19900",
              (unsigned long long)last.broadphase_pairs);
    }
    CHECK(tot.toi_searches == 0 && tot.contact_solves == 0, "%d separated bodies: no TOI search or contact solve", n);
    lc_world_destroy(w);
}

/* The broadphase only proposes candidate pairs; it must not change the physics. 40 boxes of 0.5 m
 * in a walled box, e = 1, g = 0, random velocities, 1 s (dozens of collisions), once with brute force
 * and once with sort-and-sweep: same number of collision events and the same states to 1e-9
 * (identical candidate pairs reach the same narrow phase; only a different processing order could
 * differ, by round-off ~1e-15 amplified by a few impacts). Sort-and-sweep proposes no more pairs. */
static void broadphase_equivalence(void)
{
    lc_world *w[2];
    lc_counters tot[2];
    lc_state_view v[2];
    int m, i, k;
    double maxdiff = 0;
    for (m = 0; m < 2; m++) {
        lc_world_def d = sc_def_zero_g();
        sc_rng rng = {777u};
        d.broadphase = m ? LC_BROADPHASE_SORT_AND_SWEEP : LC_BROADPHASE_BRUTE_FORCE;
        w[m] = sc_world(&d);
        if (!w[m]) return;
        lc_world_add_walls(w[m], -5.0, -4.0, 5.0, 4.0, 1.0, 1.0, NULL);
        for (i = 0; i < 40; i++)
            sc_box(w[m], 0.5, 0.5, -4.2 + 1.2 * (i % 8), -3.0 + 1.4 * (i / 8), sc_uniform(&rng, -0.5, 0.5),
                   sc_uniform(&rng, -2.0, 2.0), sc_uniform(&rng, -2.0, 2.0), sc_uniform(&rng, -1.0, 1.0), 1.0, 1.0);
        sc_step_n(w[m], 0.01, 100);
        lc_world_get_counters(w[m], NULL, &tot[m]);
        lc_world_get_state(w[m], &v[m]);
    }
    printf("broadphase equivalence: collisions brute %llu / sweep %llu, candidate pairs brute %llu / sweep %llu\n",
           (unsigned long long)tot[0].collisions, (unsigned long long)tot[1].collisions,
           (unsigned long long)tot[0].broadphase_pairs, (unsigned long long)tot[1].broadphase_pairs);
    CHECK(tot[0].collisions >= 10, "the scene has collisions (%llu)", (unsigned long long)tot[0].collisions);
    CHECK(tot[0].collisions == tot[1].collisions, "same collision events: brute %llu sweep %llu",
          (unsigned long long)tot[0].collisions, (unsigned long long)tot[1].collisions);
    CHECK(tot[1].broadphase_pairs <= tot[0].broadphase_pairs, "sort-and-sweep proposes more pairs (%llu > %llu)",
          (unsigned long long)tot[1].broadphase_pairs, (unsigned long long)tot[0].broadphase_pairs);
    CHECK(tot[0].brute_force_steps > 0 && tot[0].sort_and_sweep_steps == 0 && tot[1].sort_and_sweep_steps > 0 &&
              tot[1].brute_force_steps == 0, "%s", "forced modes used");
    if (v[0].count == v[1].count) {
        for (k = 0; k < 6 * v[0].count; k++)
            if (fabs(v[0].state[k] - v[1].state[k]) > maxdiff) maxdiff = fabs(v[0].state[k] - v[1].state[k]);
    } else {
        maxdiff = INFINITY;
    }
    CHECK_NEAR(maxdiff, 0.0, 1e-9, "largest state difference brute force vs sort-and-sweep");
    lc_world_destroy(w[0]);
    lc_world_destroy(w[1]);
}

int main(void)
{
    nothing_touches();
    resting_is_counted();
    broadphase(3, LC_BROADPHASE_AUTO, 0);
    broadphase(200, LC_BROADPHASE_AUTO, 1);
    broadphase(31, LC_BROADPHASE_AUTO, 0);
    broadphase(32, LC_BROADPHASE_AUTO, 1);
    broadphase(3, LC_BROADPHASE_SORT_AND_SWEEP, 1);
    broadphase(40, LC_BROADPHASE_BRUTE_FORCE, 0);
    broadphase_equivalence();
    return CHECK_SUMMARY("test_counters");
}
