/* test_contact_regime: islands and the regime rule (regime.h), proven by the counters, and what the
 * contact regime must do at rest. g = 9.81 m/s^2 unless said, dt = 1/60 s, 1 m x 0.5 m 1 kg blocks,
 * a static floor 20 m x 1 m with its top at y = 0.
 *  (1) the rule, per step: a block in flight is one island in the event regime; a block resting on
 *      the floor with e = 0.5 is one island in the contact regime; with e = 1 (both bodies) it stays
 *      in the event regime (e = 1 chains need the event regime's sequential impacts); a block on the
 *      floor moving farther than its own shortest edge in a step is taken in sub-steps that each move
 *      it less (40 m/s: two), and stays in the event regime beyond 16 (600 m/s);
 *      regime = EVENT and regime = CONTACT force every island into that regime;
 *  (2) islands: two blocks resting 5 m apart are two islands, two blocks resting side by side and
 *      touching are one;
 *  (3) a block dropped onto the floor at e = 0.5 from 1 m is in the event regime while it bounces
 *      (its first impact at the exact time: its speed then is sqrt(2 g h) to 1e-9 relative, which
 *      the contact regime's step would not give) and in the contact regime once it rests;
 *  (4) at rest: a 10-block stack (e = 0, mu 0.6) is one island whose solve, warm-started from the
 *      last step's forces, ends after at most two Gauss-Seidel sweeps (the last step's answer met
 *      contact_tolerance, so it changes by about that much; from zero forces a 10-stack takes tens
 *      of sweeps); the floor's
 *      reported contact forces carry the stack's weight, 10 x 9.81 N, to 1e-9 relative (the solve's
 *      residual is <= contact_tolerance, 1e-10 m/s, on impulses of ~1.6 N s); the stack does not
 *      move (|v| <= 1e-9 m/s);
 *  (5) solves cut short keep the guarantees: two blocks tumbling onto each other and the floor with
 *      contact_iterations = 1 never end a step with an overlap over 1e-9 m (the projection's
 *      allowance) or a gain over 1e-9 of the energy in play (the energy guard); a 10-stack's 20
 *      points are solved by Gauss-Seidel, none exactly (the pivoting is kept for precise retries);
 *  (6) free flight in the forced contact regime is still the exact parabola (the trapezoidal update
 *      is exact under constant forces): 1e-12 m over 1 s;
 *  (7) a sub-step of a few bodies (fewer than LC_CONTACT_MOREAU_JEAN_POINTS points) moves positions by
 *      x += h v, and its flow stops approaches slower than resting_speed (1e-4 m/s): the top block of a
 *      resting 3-stack (mu 0.5) set moving down at 5e-5 m/s stops in one step with no impact solve
 *      (impulse_solves 0; the trapezoidal update needs one for any approach above contact_tolerance),
 *      no collision reported, every block at rest (|v| <= 1e-9 m/s: the solve's tolerance is
 *      1e-10) and no energy gained. At 0.5 m/s the approach is a collision: with e = 0 the impact
 *      stage runs, reports it at -0.5 m/s at each point of the face, and the block stops, every block
 *      at rest, nothing moved (1e-9 m) and exactly its kinetic energy, 0.125 J, lost (1e-9 J); with
 *      e = 0.5 the block leaves at e 0.5 - g h (Poisson's restitution off the resting stack, then
 *      gravity over the step), to 1e-9 m/s, and the blocks below stay. A block arriving on the stack
 *      within the first half of a step (3 m/s, 2 cm above it) is an impact at its full speed: the
 *      collision is reported at -3 m/s and the block leaves at 1.5 - g h, to 1e-9 m/s (a bounce a
 *      centimetre early; the flow alone would have clipped the arrival to the 1.2 m/s that closes
 *      the gap by the step's end);
 *  (8) a pile sub-step (at least 16 bodies and 64 points) has no impact stage: a block (e 0.5) arriving
 *      at 3 m/s 2 cm above a resting base-6 pyramid is reported at -3 m/s with no impulse solve and
 *      leaves the top box at 1.5 m/s (Newton's law in the flow's target, to PILE_BOUNCE_TOL), losing
 *      energy. */
#include "check.h"
#include "scenes.h"

#define G 9.81
#define DT (1.0 / 60.0)
/* m/s: a pile sub-step's solve stops at contact_iterations sweeps, not at contact_tolerance (its largest
 * last change here ~1e-3 m/s, deep in the pile); the bounce, against a top box the pile holds, was 5e-10 off */
#define PILE_BOUNCE_TOL 1e-6

static lc_world *world_with_floor(lc_regime regime, double floor_e)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    d.regime = regime;
    w = sc_world(&d);
    if (w) lc_body_set_material(w, sc_static_box(w, 20.0, 1.0, 0.0, -0.5, floor_e), floor_e, 0.5);
    return w;
}

static lc_body_id block(lc_world *w, double x, double y, double vx, double e)
{
    lc_body_id b = sc_box(w, 1.0, 0.5, x, y, 0.0, vx, 0.0, 0.0, 1.0, e);
    lc_body_set_material(w, b, e, 0.5);
    return b;
}

/* Steps n times; returns the last step's counters. */
static lc_counters run(lc_world *w, int n)
{
    lc_counters c;
    memset(&c, 0, sizeof c);
    if (sc_step_n(w, DT, n) == n) lc_world_get_counters(w, &c, NULL);
    return c;
}

/* One step; e0 and e1 get the energy before and after, *hits the collisions it reported and *off the
 * largest difference of their normal velocities from v (m/s). Returns the step's counters. */
static lc_counters one_step(lc_world *w, double v, lc_energy *e0, lc_energy *e1, int *hits, double *off)
{
    const lc_contact *cs;
    lc_counters c;
    int i, nc = 0;
    lc_world_get_energy(w, e0);
    c = run(w, 1);
    lc_world_get_energy(w, e1);
    lc_world_get_contacts(w, &cs, &nc);
    *hits = 0;
    *off = 0.0;
    for (i = 0; i < nc; ++i)
        if (cs[i].kind == LC_CONTACT_COLLISION) {
            (*hits)++;
            *off = fmax(*off, fabs(cs[i].normal_velocity - v));
        }
    return c;
}

/* The counters of the last of `steps` steps of one block (elasticity e, its floor's too, at height y,
 * sliding at vx) on the floor in `regime`. 0 if the world could not be made. */
static int one_block(lc_regime regime, double e, double y, double vx, int steps, lc_counters *c)
{
    lc_world *w = world_with_floor(regime, e);
    if (!w) return 0;
    block(w, 0.0, y, vx, e);
    *c = run(w, steps);
    lc_world_destroy(w);
    return 1;
}

static void rule(void)
{
    lc_counters c;
    double rest_y = 0.25 + 1e-7;
    /* in flight */
    if (!one_block(LC_REGIME_AUTO, 0.5, 3.0, 0.0, 1, &c)) return;
    CHECK(c.islands == 1 && c.contact_islands == 0, "a block in flight: %llu islands, %llu in the contact regime",
          (unsigned long long)c.islands, (unsigned long long)c.contact_islands);
    /* resting, e = 0.5 */
    if (!one_block(LC_REGIME_AUTO, 0.5, rest_y, 0.0, 3, &c)) return;
    CHECK(c.islands == 1 && c.contact_islands == 1, "a resting block at e = 0.5: %llu islands, %llu contact",
          (unsigned long long)c.islands, (unsigned long long)c.contact_islands);
    /* resting, e = 1 */
    if (!one_block(LC_REGIME_AUTO, 1.0, rest_y, 0.0, 3, &c)) return;
    CHECK(c.islands == 1 && c.contact_islands == 0, "a resting block at e = 1 stays event (%llu contact islands)",
          (unsigned long long)c.contact_islands);
    /* faster than its shortest edge (0.5 m) per step: 40 m/s x 1/60 s = 0.67 m, two sub-steps */
    if (!one_block(LC_REGIME_AUTO, 0.5, rest_y, 40.0, 1, &c)) return;
    CHECK(c.contact_islands == 2 && c.islands == 1, "a block sliding at 40 m/s is taken in two contact sub-steps "
          "(%llu contact island steps)", (unsigned long long)c.contact_islands);
    /* more than LC_CONTACT_MAX_SUBSTEPS (16) shortest edges per step: 600 m/s x 1/60 s = 20 edges */
    if (!one_block(LC_REGIME_AUTO, 0.5, rest_y, 600.0, 1, &c)) return;
    CHECK(c.contact_islands == 0, "a block sliding at 600 m/s stays event (%llu contact islands)",
          (unsigned long long)c.contact_islands);
    /* forced regimes */
    if (!one_block(LC_REGIME_EVENT, 0.5, rest_y, 0.0, 3, &c)) return;
    CHECK(c.contact_islands == 0 && c.contact_solves > 0, "regime EVENT: %llu contact islands, %llu force solves",
          (unsigned long long)c.contact_islands, (unsigned long long)c.contact_solves);
    if (!one_block(LC_REGIME_CONTACT, 0.5, 3.0, 0.0, 1, &c)) return;
    CHECK(c.contact_islands == 1, "regime CONTACT: a block in flight in the contact regime (%llu)",
          (unsigned long long)c.contact_islands);
}

static void islands(void)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, 0.5);
    lc_counters c;
    double rest_y = 0.25 + 1e-7;
    if (!w) return;
    block(w, -3.0, rest_y, 0.0, 0.5);
    block(w, 2.0, rest_y, 0.0, 0.5);
    c = run(w, 2);
    CHECK(c.islands == 2 && c.contact_islands == 2, "two blocks 5 m apart: %llu islands (2), %llu contact",
          (unsigned long long)c.islands, (unsigned long long)c.contact_islands);
    lc_world_destroy(w);
    w = world_with_floor(LC_REGIME_AUTO, 0.5);
    if (!w) return;
    block(w, -0.5, rest_y, 0.0, 0.5);
    block(w, 0.5 + 1e-7, rest_y, 0.0, 0.5);
    c = run(w, 2);
    CHECK(c.islands == 1, "two blocks side by side, touching: %llu islands (1)", (unsigned long long)c.islands);
    lc_world_destroy(w);
}

static void drop_then_rest(void)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, 0.5);
    lc_body_id b;
    int k, first_contact_step = -1, impact_step = -1;
    double v_impact = 0.0, h = 1.0;
    if (!w) return;
    b = block(w, 0.0, 0.25 + 1e-7 + h, 0.0, 0.5);
    for (k = 0; k < 300; ++k) {
        lc_counters c;
        const lc_contact *cs;
        int nc, i;
        if (sc_step_n(w, DT, 1) != 1) break;
        lc_world_get_counters(w, &c, NULL);
        lc_world_get_contacts(w, &cs, &nc);
        for (i = 0; i < nc && impact_step < 0; ++i)
            if (cs[i].kind == LC_CONTACT_COLLISION) {
                impact_step = k;
                v_impact = -cs[i].normal_velocity;
            }
        if (first_contact_step < 0 && c.contact_islands > 0) first_contact_step = k;
    }
    printf("drop: first impact in step %d at %.12f m/s (exact %.12f), contact regime from step %d, end |v| %.3g\n",
           impact_step, v_impact, sqrt(2.0 * G * h), first_contact_step, hypot(sc_row(w, b)[3], sc_row(w, b)[4]));
    CHECK(impact_step >= 0 && first_contact_step > impact_step,
          "the drop's impact is an event (step %d) before the contact regime takes the resting block (step %d)",
          impact_step, first_contact_step);
    CHECK_REL(v_impact, sqrt(2.0 * G * h), 1e-9, "impact speed of the located first impact");
    CHECK(hypot(sc_row(w, b)[3], sc_row(w, b)[4]) <= 1e-9, "the block rests at the end (|v| %.3g m/s)",
          hypot(sc_row(w, b)[3], sc_row(w, b)[4]));
    lc_world_destroy(w);
}

static void stack_at_rest(void)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, 0.0);
    lc_body_id ids[10], floor_id = 0;
    lc_counters c;
    const lc_contact *cs;
    int i, nc, k, few_sweeps = 0;
    double fsum = 0.0, vmax = 0.0;
    lc_state_view sv;
    if (!w) return;
    lc_world_get_state(w, &sv);
    floor_id = sv.ids[0];
    for (i = 0; i < 10; ++i) {
        ids[i] = sc_box(w, 1.0, 0.5, 0.0, 0.25 + i * 0.5, 0.0, 0, 0, 0, 1.0, 0.0);
        lc_body_set_material(w, ids[i], 0.0, 0.6);
    }
    run(w, 30);
    for (k = 0; k < 30; ++k) {
        c = run(w, 1);
        if (c.contact_islands == 1 && c.contact_sweeps <= 2) few_sweeps++;
        for (i = 0; i < 10; ++i) vmax = fmax(vmax, hypot(sc_row(w, ids[i])[3], sc_row(w, ids[i])[4]));
    }
    lc_world_get_contacts(w, &cs, &nc);
    for (i = 0; i < nc; ++i)
        if (cs[i].kind == LC_CONTACT_RESTING && (cs[i].body_a == floor_id || cs[i].body_b == floor_id))
            fsum += cs[i].force * fabs(cs[i].normal.y);
    printf("stack at rest: %d of 30 steps with at most two sweeps, floor carries %.12f N, max |v| %.3g m/s, "
           "residual %.3g\n", few_sweeps, fsum, vmax, c.max_contact_residual);
    CHECK(few_sweeps == 30, "a warm-started stack at rest takes at most two sweeps per step (%d of 30)", few_sweeps);
    CHECK_REL(fsum, 10.0 * G, 1e-9, "the floor carries the stack's weight");
    CHECK(vmax <= 1e-9, "the stack does not move (max |v| %.3g m/s)", vmax);
    lc_world_destroy(w);
}

static void solves_cut_short(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters tot;
    lc_body_id floor, a, b;
    double worst = 0.0, gain = 0.0, e_prev, scale;
    lc_energy e0;
    int i;
    /* two blocks tumbling onto each other and the floor, solves cut at one sweep */
    d.contact_iterations = 1;
    w = sc_world(&d);
    if (!w) return;
    floor = sc_static_box(w, 20.0, 1.0, 0.0, -0.5, 0.3);
    lc_body_set_material(w, floor, 0.3, 0.5);
    a = sc_box(w, 1.0, 0.5, 0.0, 1.0, 0.4, 1.0, 0.0, 2.0, 1.0, 0.3);
    b = sc_box(w, 1.0, 0.5, 0.3, 2.0, -0.3, -0.5, 0.0, -1.0, 1.0, 0.3);
    e0 = sc_energy(w);
    e_prev = e0.total;
    scale = e0.translational + e0.rotational + fabs(e0.gravitational);
    for (i = 0; i < 120; ++i) {
        double e;
        if (lc_world_step(w, DT) != LC_OK) break;
        e = sc_energy(w).total;
        gain = fmax(gain, e - e_prev);
        e_prev = e;
        worst = fmax(worst, fmax(-sc_separation(w, a, b), fmax(-sc_separation(w, a, floor), -sc_separation(w, b, floor))));
    }
    lc_world_get_counters(w, NULL, &tot);
    CHECK(i == 120, "120 steps taken (%d)", i);
    CHECK(tot.contact_islands > 60, "the blocks come to rest in the contact regime (%llu contact islands)",
          (unsigned long long)tot.contact_islands);
    CHECK(worst <= 1e-9, "no overlap deeper than 1e-9 m at a step's end (%.3g m)", worst);
    CHECK(gain <= 1e-9 * scale, "no step gains more than 1e-9 of the %.3g J in play (%.3g J)", scale, gain);
    lc_world_destroy(w);
    w = world_with_floor(LC_REGIME_AUTO, 0.0);
    if (!w) return;
    for (i = 0; i < 10; ++i) sc_box(w, 1.0, 0.5, 0.0, 0.25 + i * 0.5, 0.0, 0, 0, 0, 1.0, 0.0);
    sc_step_n(w, DT, 2);
    lc_world_get_counters(w, NULL, &tot);
    CHECK(tot.contact_points > 12 && tot.contact_exact_solves == 0 && tot.contact_sweeps > 0,
          "a 10-stack (%llu points) is solved by Gauss-Seidel (%llu exact solves)",
          (unsigned long long)tot.contact_points, (unsigned long long)tot.contact_exact_solves);
    lc_world_destroy(w);
}

static void contact_free_flight(void)
{
    lc_world *w = world_with_floor(LC_REGIME_CONTACT, 0.5);
    lc_body_id b;
    double t = 1.0, x, y;
    if (!w) return;
    b = sc_box(w, 1.0, 0.5, 0.0, 10.0, 0.3, 2.0, 5.0, 1.5, 1.0, 0.5);
    sc_step_n(w, DT, 60);
    x = 2.0 * t;
    y = 10.0 + 5.0 * t - 0.5 * G * t * t;
    CHECK_NEAR(sc_row(w, b)[0], x, 1e-12, "contact regime free flight: x");
    CHECK_NEAR(sc_row(w, b)[1], y, 1e-12, "contact regime free flight: y");
    CHECK_NEAR(sc_row(w, b)[2], 0.3 + 1.5 * t, 1e-12, "contact regime free flight: angle");
    lc_world_destroy(w);
}

/* (7): the top block of a resting 3-stack (elasticity e everywhere) hits the block below at speed. */
static void moreau_jean_substep(double e, double speed)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, e);
    lc_body_id ids[3];
    lc_counters c;
    lc_vec2 down = {0.0, 0.0};
    lc_energy e0, e1;
    double y0[3], vmax = 0.0, moved = 0.0, v_off = 0.0;
    int i, hits = 0;
    if (!w) return;
    for (i = 0; i < 3; ++i) ids[i] = block(w, 0.0, 0.25 + 0.5 * i, 0.0, e);
    run(w, 60);
    down.y = -speed;
    CHECK(lc_body_set_velocity(w, ids[2], down, 0.0) == LC_OK, "%s", "set the top block moving");
    for (i = 0; i < 3; ++i) y0[i] = sc_row(w, ids[i])[1];
    c = one_step(w, -speed, &e0, &e1, &hits, &v_off);
    for (i = 0; i < 3; ++i) {
        if (i < 2 || e == 0.0) vmax = fmax(vmax, hypot(sc_row(w, ids[i])[3], sc_row(w, ids[i])[4]));
        if (i < 2 || e == 0.0) moved = fmax(moved, fabs(sc_row(w, ids[i])[1] - y0[i]));
    }
    printf("moreau-jean e %.1f at %g m/s: contact islands %llu, impulse solves %llu, collisions %d (off by %.3g m/s), "
           "top vy %.12f, others |v| %.3g, moved %.3g m, energy %.12f J\n", e, speed, (unsigned long long)c.contact_islands,
           (unsigned long long)c.impulse_solves, hits, v_off, sc_row(w, ids[2])[4], vmax, moved, e1.total - e0.total);
    CHECK(c.contact_islands == 1, "the stack is one contact-regime island (%llu)", (unsigned long long)c.contact_islands);
    if (speed < 1e-4) {
        CHECK(c.impulse_solves == 0, "an approach slower than resting_speed takes no impact solve (%llu)",
              (unsigned long long)c.impulse_solves);
        CHECK(hits == 0, "no collision is reported for it (%d)", hits);
        CHECK(vmax <= 1e-9, "every block rests after the step (max |v| %.3g m/s)", vmax);
        CHECK(e1.total <= e0.total, "no energy gained (%.3g J)", e1.total - e0.total);
    } else if (e == 0.0) {
        CHECK(c.impulse_solves >= 1, "a collision takes the impact stage (%llu)", (unsigned long long)c.impulse_solves);
        CHECK(hits >= 1 && v_off <= 1e-9, "the impact is reported at -0.5 m/s at each point of the face (%d points, "
              "off by %.3g m/s)", hits, v_off);
        CHECK(vmax <= 1e-9, "every block rests after the step (max |v| %.3g m/s)", vmax);
        CHECK(moved <= 1e-9, "no block moved (%.3g m)", moved);
        CHECK(fabs(e1.total - e0.total + 0.125) <= 1e-9, "the step lost the top block's 0.125 J (%.12f J)",
              e0.total - e1.total);
    } else {
        CHECK(c.impulse_solves >= 1, "an approach that bounces takes the impact stage (%llu)",
              (unsigned long long)c.impulse_solves);
        CHECK(hits >= 1 && v_off <= 1e-9, "the impact is reported at -0.5 m/s at each point of the face (%d points, "
              "off by %.3g m/s)", hits, v_off);
        CHECK(fabs(sc_row(w, ids[2])[4] - (0.5 * e - G * DT)) <= 1e-9, "the top block leaves at e 0.5 - g h (%.12f)",
              sc_row(w, ids[2])[4]);
        CHECK(vmax <= 1e-9 && moved <= 1e-9, "the blocks below stay (|v| %.3g m/s, moved %.3g m)", vmax, moved);
    }
    lc_world_destroy(w);
}

/* (7): a block 2 cm above a resting 3-stack falls onto it at 3 m/s (e = 0.5 everywhere). */
static void moreau_jean_arrival(void)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, 0.5);
    lc_body_id ids[4];
    lc_counters c;
    lc_energy e0, e1;
    double v_off = 0.0;
    int i, hits = 0;
    if (!w) return;
    for (i = 0; i < 3; ++i) ids[i] = block(w, 0.0, 0.25 + 0.5 * i, 0.0, 0.5);
    run(w, 60);
    ids[3] = sc_box(w, 1.0, 0.5, 0.0, 1.75 + 0.02, 0.0, 0.0, -3.0, 0.0, 1.0, 0.5);
    lc_body_set_material(w, ids[3], 0.5, 0.5);
    c = one_step(w, -3.0, &e0, &e1, &hits, &v_off);
    printf("moreau-jean arrival: contact islands %llu, collisions %d (off by %.3g m/s), vy %.12f\n",
           (unsigned long long)c.contact_islands, hits, v_off, sc_row(w, ids[3])[4]);
    CHECK(c.contact_islands == 1, "the falling block and the stack are one contact-regime island (%llu)",
          (unsigned long long)c.contact_islands);
    CHECK(hits >= 1 && v_off <= 1e-9, "the arrival is reported at -3 m/s (%d points, off by %.3g m/s)", hits, v_off);
    CHECK(fabs(sc_row(w, ids[3])[4] - (1.5 - G * DT)) <= 1e-9, "the block leaves at e 3 - g h (%.12f)",
          sc_row(w, ids[3])[4]);
    lc_world_destroy(w);
}

/* A pile sub-step (LC_CONTACT_PILE_BODIES): a block (e 0.5) arriving at 3 m/s 2 cm above the top of a
 * resting base-6 pyramid (21 boxes and the floor: over 64 points) is an impact of the flow itself. No
 * impact stage runs (impulse_solves 0), the arrival is reported at -3 m/s, the block leaves the top box
 * at e times its approach (Newton's law in the flow's target: the top box, held by the pile, does not
 * give), and the step loses energy. */
static void pile_substep_bounce(void)
{
    lc_world *w = world_with_floor(LC_REGIME_AUTO, 0.0);
    lc_body_id ids[21], drop;
    lc_counters c;
    lc_energy e0, e1;
    double v_off = 0.0, rel;
    int hits = 0;
    if (!w) return;
    sc_pyramid(w, 6, 0.5, ids);
    lc_body_set_material(w, ids[20], 0.5, 0.5);
    run(w, 60);
    drop = sc_box(w, 1.0, 0.5, 0.0, 6.0 + 0.25 + 0.02, 0.0, 0.0, -3.0, 0.0, 1.0, 0.5);
    lc_body_set_material(w, drop, 0.5, 0.5);
    c = one_step(w, -3.0, &e0, &e1, &hits, &v_off);
    rel = sc_row(w, drop)[4] - sc_row(w, ids[20])[4];
    printf("pile sub-step bounce: contact islands %llu, impulse solves %llu, collisions %d (off by %.3g m/s), "
           "leaves at %.12f m/s, residual %.3g m/s, energy %.6f -> %.6f J\n",
           (unsigned long long)c.contact_islands, (unsigned long long)c.impulse_solves, hits, v_off, rel,
           c.max_contact_residual, e0.total, e1.total);
    CHECK(c.contact_islands == 1, "the block and the pyramid are one contact-regime island (%llu)",
          (unsigned long long)c.contact_islands);
    CHECK(c.impulse_solves == 0, "no impact stage in a pile sub-step (%llu impulse solves)",
          (unsigned long long)c.impulse_solves);
    CHECK(hits >= 1 && v_off <= 1e-9, "the arrival is reported at -3 m/s (%d points, off by %.3g m/s)", hits, v_off);
    CHECK(fabs(rel - 1.5) <= PILE_BOUNCE_TOL, "the block leaves the top box at e 3 = 1.5 m/s (%.12f)", rel);
    CHECK(e1.total < e0.total, "the bounce loses energy (%.9f -> %.9f J)", e0.total, e1.total);
    lc_world_destroy(w);
}

int main(void)
{
    rule();
    islands();
    drop_then_rest();
    stack_at_rest();
    solves_cut_short();
    contact_free_flight();
    moreau_jean_substep(0.0, 5e-5);
    moreau_jean_substep(0.0, 0.5);
    moreau_jean_substep(0.5, 0.5);
    moreau_jean_arrival();
    pile_substep_bounce();
    return CHECK_SUMMARY("test_contact_regime");
}
