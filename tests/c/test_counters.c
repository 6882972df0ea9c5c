/* test_counters: "model only what a scene needs", proven by the work counters (exact integers).
 * Cases (2) and (4)-(7) check the event regime's own machinery (resting contact forces, quiet advances,
 * solver products, serial impacts) and set regime = LC_REGIME_EVENT: in the default AUTO those scenes'
 * resting bodies go to the contact regime (regime.h), whose counters test_contact_regime.c checks.
 * (1) g = 0, two bodies drifting apart, nothing touches: 0 contact solves, 0 TOI searches, 0
 *     collisions, 0 resting contacts, 0 impulse solves; with no force of any kind, no force
 *     evaluations either (free flight is advanced in closed form: analytic_advances > 0).
 * (2) the same bodies with gravity on a floor: contact solves do happen (the counters are live).
 * (3) broadphase AUTO (the *_steps counters count detections, >= 1 per step): 3 bodies -> brute
 *     force in every detection, never sort-and-sweep; 200 bodies -> sort-and-sweep every step,
 *     producing far fewer candidate pairs than the 19900 of brute force; around the default
 *     threshold (32): 31 bodies brute force, 32 sort-and-sweep; around LC_GRID_MIN_ROWS, sort-and-sweep
 *     one body below and the grid from it (grid_steps); forced modes are obeyed.
 * (4) stage timing: off by default (every time_* counter exactly 0); on, a scene with impacts and
 *     resting contact spends time in every stage, the six disjoint stages sum to no more than the
 *     whole step (they do not overlap; the remainder is bookkeeping between them), and the contact
 *     force solves fit inside the integration and time-of-impact stages that run them; off again,
 *     no more time is added; 2 is refused with a message. The physics is the same bit for bit. In
 *     AUTO the same pile settles in the contact regime, whose time is its own disjoint stage.
 * (5) a resting stack is advanced with two force evaluations per interval (see quiet_rest).
 * (6) a frictional pile in motion (a heavy box dropped into a base-4 pyramid, mu 0.6): every step
 *     succeeds and its force solves stay within 120 products of A per force evaluation. There the
 *     alternation of normal and friction rows does not converge; solving each of its rounds to the
 *     final tolerance cost 353 products per evaluation on this scene, inexact rounds that stop when
 *     the change grows 138, and with the tolerance of a group in motion 94 (contact_forces.c), so
 *     the bound fails if that tolerance is lost (the counters are the same on every run).
 *     With lcp_exact_max = 2 (every group solved as a large one, by MPRGP): within 100 products
 *     per evaluation (50 on this scene; the resting tolerance applied in motion too costs 198).
 * (7) a box dropped at 3 m/s onto a resting stack of four (e = 0, mu 0.6), with lcp_exact_max = 2 so
 *     that the impact's ~10 touches form a large group: no point bounces, so the impact takes no
 *     serial pass (impulse.c, the simultaneous inelastic solve at once), and the dropped box ends
 *     the step at rest on the stack (|v| < 1e-3 m/s: the inelastic answer, which the serial passes
 *     only approach). With lcp_exact_max at its default the same impact is resolved serially
 *     (serial passes > 0) to the same rest; with e = 1 on every body the large group bounces and
 *     keeps its serial passes. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "scenes.h"
#include "tunables.h"

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
    CHECK(tot.solver_work == 0, "no solver work without a solve (%llu)", (unsigned long long)tot.solver_work);
    CHECK(tot.force_evaluations == 0, "no force of any kind -> no force evaluations (%llu)",
          (unsigned long long)tot.force_evaluations);
    CHECK(tot.analytic_advances > 0, "%s", "free flight advanced in closed form");
    lc_world_destroy(w);
}

static void resting_is_counted(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters tot;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return;
    lc_world_add_walls(w, -5.0, 0.0, 5.0, 10.0, 1.0, 0.5, NULL);
    sc_box(w, 1.0, 1.0, 0.0, 0.5 + 1e-7, 0.0, 0, 0, 0, 1.0, 0.5);
    sc_step_n(w, 0.01, 100);
    lc_world_get_counters(w, NULL, &tot);
    CHECK(tot.contact_solves > 0, "a block resting on the floor needs contact solves (%llu)",
          (unsigned long long)tot.contact_solves);
    CHECK(tot.resting_contacts > 0, "%s", "resting contacts counted");
    /* a dense solve of m rows visits m^2 entries at least twice (set-up and answer) */
    CHECK(tot.solver_work >= 2 * tot.contact_solves, "solver work counted (%llu for %llu solves)",
          (unsigned long long)tot.solver_work, (unsigned long long)tot.contact_solves);
    CHECK(tot.force_evaluations + tot.analytic_advances > 0, "%s", "the body was advanced");
    lc_world_destroy(w);
}

/* (5) A resting stack needs two force evaluations per interval, not RK4's four: a 4-box stack on a
 * floor takes every step after the first as one quiet advance (2 evaluations), and stays put to 1 %
 * of the contact gap (the end-of-step projection holds every gap at contact_gap). A box at rest that
 * a stiff spring tears off the floor is quiet at the start (v = 0) but its acceleration changes by
 * far more than the tolerance over the interval: the attempt is refused, and the step is RK4's bit
 * for bit (the same world with resting_speed 0, which never attempts it: a touch at v = 0 rests
 * either way). */
static lc_world *spring_lift(double resting_speed, lc_body_id *box)
{
    lc_world_def d = lc_default_world_def();
    lc_spring_def sp = lc_default_spring_def();
    lc_spring_id sid;
    lc_world *w;
    d.gravity.y = -10.0;
    d.resting_speed = resting_speed;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return NULL;
    sc_static_box(w, 10.0, 1.0, 0.0, -0.5, 0.0);
    *box = sc_box(w, 1.0, 1.0, 0.0, 0.5 + d.contact_gap, 0.0, 0, 0, 0, 1.0, 0.0);
    sp.body_a = *box;
    sp.point_a.y = 0.5;
    sp.body_b = LC_WORLD_ANCHOR;
    sp.point_b.y = 3.0;
    sp.stiffness = 1000.0;
    CHECK(lc_world_add_spring(w, &sp, &sid) == LC_OK, "add spring: %s", lc_world_last_error(w));
    return w;
}

static void quiet_rest(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w, *a, *b;
    lc_body_id top = 0, ba, bb;
    lc_counters last, tot, last_b;
    double y0, dy;
    int k, quiet_steps = 0;
    d.gravity.y = -10.0;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return;
    sc_static_box(w, 10.0, 1.0, 0.0, -0.5, 0.0);
    for (k = 0; k < 4; ++k) top = sc_box(w, 1.0, 1.0, 0.0, 0.5 + (k + 1) * d.contact_gap + k, 0.0, 0, 0, 0, 1.0, 0.0);
    sc_step_n(w, 1.0 / 60.0, 1);
    y0 = sc_row(w, top)[1];
    for (k = 1; k < 60; ++k) {
        sc_step_n(w, 1.0 / 60.0, 1);
        lc_world_get_counters(w, &last, NULL);
        if (last.quiet_advances == 1 && last.force_evaluations == 2) quiet_steps++;
    }
    lc_world_get_counters(w, NULL, &tot);
    dy = sc_row(w, top)[1] - y0;
    printf("resting stack: %d of 59 steps quiet (2 force evaluations), %llu quiet advances, top moved %.3g m\n",
           quiet_steps, (unsigned long long)tot.quiet_advances, dy);
    CHECK(quiet_steps == 59, "every step of a resting stack is one quiet advance of 2 evaluations (%d of 59)",
          quiet_steps);
    CHECK(fabs(dy) < 0.01 * d.contact_gap, "the quiet stack stays put (top moved %.3g m)", dy);
    lc_world_destroy(w);

    a = spring_lift(d.resting_speed, &ba);
    b = spring_lift(0.0, &bb);
    if (!a || !b) return;
    sc_step_n(a, 1.0 / 60.0, 1);
    sc_step_n(b, 1.0 / 60.0, 1);
    lc_world_get_counters(a, &last, NULL);
    lc_world_get_counters(b, &last_b, NULL);
    printf("spring lift: quiet advances %llu, force evaluations %llu (RK4 alone %llu), y %.17g vs %.17g\n",
           (unsigned long long)last.quiet_advances, (unsigned long long)last.force_evaluations,
           (unsigned long long)last_b.force_evaluations, sc_row(a, ba)[1], sc_row(b, bb)[1]);
    CHECK(last.force_evaluations == last_b.force_evaluations + 1,
          "the quiet attempt was made and refused: one evaluation more than RK4 alone (%llu vs %llu)",
          (unsigned long long)last.force_evaluations, (unsigned long long)last_b.force_evaluations);
    CHECK(last.quiet_advances == 0, "a box torn off the floor is not advanced as quiet (%llu)",
          (unsigned long long)last.quiet_advances);
    CHECK(sc_row(a, ba)[1] > 0.5 + 1e-3, "the spring lifted the box (y %.6g)", sc_row(a, ba)[1]);
    CHECK(memcmp(sc_row(a, ba), sc_row(b, bb), 6 * sizeof(double)) == 0,
          "a refused quiet attempt leaves RK4's step bit for bit (y %.17g vs %.17g)", sc_row(a, ba)[1],
          sc_row(b, bb)[1]);
    lc_world_destroy(a);
    lc_world_destroy(b);
}

/* n bodies of 0.2 m on a grid with 1 m pitch (columns of 10), slow random drift, g = 0. */
static void broadphase(int n, lc_broadphase mode, lc_broadphase expect)
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
    printf("broadphase %d bodies mode %d: brute force steps %llu, sort-and-sweep steps %llu, grid steps %llu, "
           "pairs last step %llu\n", n, (int)mode, (unsigned long long)tot.brute_force_steps,
           (unsigned long long)tot.sort_and_sweep_steps, (unsigned long long)tot.grid_steps,
           (unsigned long long)last.broadphase_pairs);
    {
        uint64_t used = expect == LC_BROADPHASE_BRUTE_FORCE ? tot.brute_force_steps
                      : expect == LC_BROADPHASE_SORT_AND_SWEEP ? tot.sort_and_sweep_steps : tot.grid_steps;
        CHECK(used >= 10 && tot.brute_force_steps + tot.sort_and_sweep_steps + tot.grid_steps == used,
              "%d bodies (mode %d): only broadphase %d expected, got brute %llu sweep %llu grid %llu", n, (int)mode,
              (int)expect, (unsigned long long)tot.brute_force_steps, (unsigned long long)tot.sort_and_sweep_steps,
              (unsigned long long)tot.grid_steps);
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

/* Seven blocks of 0.5 m dropped onto a floor at e = 0.5 and onto each other: impacts, TOI searches,
 * resting contact and projections all happen within the 200 steps. Returns the state hash. */
static uint64_t timed_pile(int timing, lc_regime regime, lc_counters *tot)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    uint64_t h;
    int i;
    d.regime = regime;
    w = sc_world(&d);
    if (!w) return 0;
    lc_world_add_walls(w, -3.0, 0.0, 3.0, 10.0, 1.0, 0.5, NULL);
    for (i = 0; i < 7; i++)
        sc_box(w, 0.5, 0.5, -1.2 + 0.4 * i, 0.6 + 0.7 * i, 0.1 * i, 0, 0, 0, 1.0, 0.5);
    CHECK(lc_world_set_stage_timing(w, timing) == LC_OK, "%s", "stage timing set");
    sc_step_n(w, 0.01, 200);
    lc_world_get_counters(w, NULL, tot);
    h = lc_world_state_hash(w);
    if (timing) {
        CHECK(lc_world_set_stage_timing(w, 2) == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "not 2") != NULL,
              "stage timing 2 refused with a message (%s)", lc_world_last_error(w));
        lc_world_set_stage_timing(w, 0);
        {
            lc_counters after;
            sc_step_n(w, 0.01, 10);
            lc_world_get_counters(w, NULL, &after);
            CHECK(after.time_step == tot->time_step && after.steps == tot->steps + 10,
                  "%s", "timing off: steps counted, no time added");
        }
    }
    lc_world_destroy(w);
    return h;
}

static void stage_timing(void)
{
    lc_counters off, on, aoff, aon;
    uint64_t h_off = timed_pile(0, LC_REGIME_EVENT, &off), h_on = timed_pile(1, LC_REGIME_EVENT, &on);
    uint64_t ha_off = timed_pile(0, LC_REGIME_AUTO, &aoff), ha_on = timed_pile(1, LC_REGIME_AUTO, &aon);
    double stages = on.time_detection + on.time_integration + on.time_toi_search + on.time_impulses + on.time_projection;
    double astages = aon.time_detection + aon.time_integration + aon.time_toi_search + aon.time_impulses +
                     aon.time_projection + aon.time_contact_regime;
    printf("stage timing, 200 steps of a 7-block pile in the event regime: step %.3e s = detection %.3e + integration "
           "%.3e + toi %.3e + impulses %.3e + projection %.3e (+ %.3e between); contact forces %.3e inside; %llu "
           "impacts\n", on.time_step, on.time_detection, on.time_integration, on.time_toi_search, on.time_impulses,
           on.time_projection, on.time_step - stages, on.time_contact_forces, (unsigned long long)on.collisions);
    printf("the same pile, regime AUTO: step %.3e s, of it contact regime %.3e s, event stages %.3e s\n",
           aon.time_step, aon.time_contact_regime, astages - aon.time_contact_regime);
    CHECK(off.time_step == 0.0 && off.time_detection == 0.0 && off.time_integration == 0.0 && off.time_toi_search == 0.0 &&
          off.time_impulses == 0.0 && off.time_projection == 0.0 && off.time_contact_forces == 0.0 &&
          aoff.time_contact_regime == 0.0, "%s", "timing off by default: every time_* counter is 0");
    CHECK(h_on == h_off && ha_on == ha_off, "%s", "timing changes no physics (same state hash)");
    CHECK(on.collisions > 0 && on.toi_searches > 0 && on.contact_solves > 0 && on.position_projections > 0,
          "the scene exercises every stage (impacts %llu, toi %llu, contact solves %llu, projections %llu)",
          (unsigned long long)on.collisions, (unsigned long long)on.toi_searches,
          (unsigned long long)on.contact_solves, (unsigned long long)on.position_projections);
    CHECK(on.time_detection > 0.0 && on.time_integration > 0.0 && on.time_toi_search > 0.0 && on.time_impulses > 0.0 &&
          on.time_projection > 0.0 && on.time_contact_forces > 0.0, "%s", "time measured in every stage");
    CHECK(stages <= on.time_step, "disjoint stages sum to %.6e s, more than the whole steps' %.6e s", stages, on.time_step);
    CHECK(on.time_contact_forces <= on.time_integration + on.time_toi_search + on.time_detection,
          "%s", "contact forces run inside integration (and the TOI searches' and swept checks' integrations)");
    CHECK(aon.contact_islands > 0 && aon.time_contact_regime > 0.0, "the pile settles in the contact regime, timed "
          "(%llu island steps, %.3e s)", (unsigned long long)aon.contact_islands, aon.time_contact_regime);
    CHECK(astages <= aon.time_step, "disjoint stages with the contact regime sum to %.6e s, more than the steps' %.6e s",
          astages, aon.time_step);
}

static void pile_in_motion(int exact_max, double bound)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters tot;
    lc_body_id ground, heavy;
    int k, ok = 1;
    const int base = 4;
    d.gravity.x = 0.0;
    d.gravity.y = -10.0;
    d.lcp_exact_max = exact_max;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return;
    sc_pyramid(w, base, 0.6, NULL);
    ground = sc_static_box(w, 2.0 * base + 20.0, 1.0, 0.0, -0.5, 0.5);
    lc_body_set_material(w, ground, 0.5, 0.6);
    heavy = sc_box(w, 1.0, 1.0, 0.3, base + 2.0, 0.0, 0.0, -8.0, 1.0, 5.0, 0.5);
    lc_body_set_material(w, heavy, 0.5, 0.6);
    for (k = 0; k < 40 && ok; ++k) {
        lc_status s = lc_world_step(w, 1.0 / 60.0);
        ok = s == LC_OK;
        CHECK(ok, "step %d -> %s: %s", k, lc_status_string(s), lc_world_last_error(w));
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("pile in motion (lcp_exact_max %d): collisions %llu, force evaluations %llu, products %llu (%.1f per evaluation), "
           "largest residual %.3g m/s^2\n", exact_max, (unsigned long long)tot.collisions,
           (unsigned long long)tot.force_evaluations, (unsigned long long)tot.contact_solve_iterations,
           (double)tot.contact_solve_iterations / (double)(tot.force_evaluations ? tot.force_evaluations : 1),
           tot.max_lcp_residual);
    CHECK(tot.collisions > 0 && tot.force_evaluations > 0, "%s", "the box hit the pile");
    CHECK((double)tot.contact_solve_iterations <= bound * (double)tot.force_evaluations,
          "force solves within %g products per evaluation (%llu products, %llu evaluations)", bound,
          (unsigned long long)tot.contact_solve_iterations, (unsigned long long)tot.force_evaluations);
    CHECK(isfinite(tot.max_lcp_residual), "%s", "the residual is a number");
    /* every pivot visits a row of m entries per row, every sparse product 12 per row */
    CHECK(tot.solver_work > tot.contact_solve_iterations, "solver work %llu counts the %llu pivots and products",
          (unsigned long long)tot.solver_work, (unsigned long long)tot.contact_solve_iterations);
    lc_world_destroy(w);
}

/* Drops a fifth box onto a stack of four; returns the dropped box's speed after the impact's step and
 * that step's serial passes (*serial), or -1 when no step had a collision. */
static double drop_on_stack(int exact_max, double e, unsigned long long *serial)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id top = 0;
    int i, k;
    double speed = -1.0;
    d.lcp_exact_max = exact_max;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return -1.0;
    lc_body_set_material(w, sc_static_box(w, 20.0, 1.0, 0.0, -0.5, e), e, 0.6);
    for (i = 0; i < 5; ++i) {
        double y = i < 4 ? 0.5 + 1e-7 + i * (1.0 + 1e-7) : 5.0;
        top = sc_box(w, 1.0, 1.0, 0.0, y, 0.0, 0.0, i < 4 ? 0.0 : -3.0, 0.0, 1.0, e);
        lc_body_set_material(w, top, e, 0.6);
    }
    *serial = 0;
    for (k = 0; k < 60; ++k) {
        lc_counters last;
        lc_status s = lc_world_step(w, 1.0 / 60.0);
        CHECK(s == LC_OK, "step %d -> %s: %s", k, lc_status_string(s), lc_world_last_error(w));
        if (s != LC_OK) break;
        lc_world_get_counters(w, &last, NULL);
        if (last.collisions > 0) {
            const double *r = sc_row(w, top);
            *serial = (unsigned long long)last.serial_iterations;
            speed = sqrt(r[3] * r[3] + r[4] * r[4]);
            break;
        }
    }
    lc_world_destroy(w);
    return speed;
}

static void large_inelastic_impact(void)
{
    unsigned long long serial_large, serial_small, serial_elastic;
    double v_large = drop_on_stack(2, 0.0, &serial_large);
    double v_small = drop_on_stack(128, 0.0, &serial_small);
    double v_elastic = drop_on_stack(2, 1.0, &serial_elastic);
    printf("drop on a stack: large group e 0: %llu serial passes, |v| %.3g m/s; small groups e 0: %llu, |v| %.3g; "
           "large group e 1: %llu, |v| %.3g\n", serial_large, v_large, serial_small, v_small, serial_elastic, v_elastic);
    CHECK(v_large >= 0.0 && v_small >= 0.0 && v_elastic >= 0.0, "%s", "every drop hit the stack");
    CHECK(serial_large == 0, "a large impact where nothing bounces takes no serial pass (%llu)", serial_large);
    CHECK(serial_small > 0, "small groups are still resolved serially (%llu passes)", serial_small);
    CHECK(serial_elastic > 0, "a large impact that bounces is still resolved serially (%llu passes)", serial_elastic);
    CHECK(v_large < 1e-3 && v_small < 1e-3, "the dropped box rests on the stack after an inelastic impact (%.3g, %.3g m/s)",
          v_large, v_small);
    CHECK(v_elastic > 1.0, "at e = 1 it bounces (%.3g m/s)", v_elastic);
}

int main(void)
{
    nothing_touches();
    resting_is_counted();
    broadphase(3, LC_BROADPHASE_AUTO, LC_BROADPHASE_BRUTE_FORCE);
    broadphase(200, LC_BROADPHASE_AUTO, LC_BROADPHASE_SORT_AND_SWEEP);
    broadphase(31, LC_BROADPHASE_AUTO, LC_BROADPHASE_BRUTE_FORCE);
    broadphase(32, LC_BROADPHASE_AUTO, LC_BROADPHASE_SORT_AND_SWEEP);
    broadphase(LC_GRID_MIN_ROWS - 1, LC_BROADPHASE_AUTO, LC_BROADPHASE_SORT_AND_SWEEP);
    broadphase(LC_GRID_MIN_ROWS, LC_BROADPHASE_AUTO, LC_BROADPHASE_GRID);
    broadphase(3, LC_BROADPHASE_SORT_AND_SWEEP, LC_BROADPHASE_SORT_AND_SWEEP);
    broadphase(200, LC_BROADPHASE_GRID, LC_BROADPHASE_GRID);
    broadphase(40, LC_BROADPHASE_BRUTE_FORCE, LC_BROADPHASE_BRUTE_FORCE);
    broadphase_equivalence();
    stage_timing();
    quiet_rest();
    pile_in_motion(128, 120.0);
    pile_in_motion(2, 100.0);
    large_inelastic_impact();
    return CHECK_SUMMARY("test_counters");
}
