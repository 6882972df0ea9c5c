/* test_hard_settle (docs/hard_cases.md): (2) settling and (8) a block wedged between two walls, 60 s at
 * dt = 1/60 s, g = 9.8 m/s^2, every other setting the engine's default.
 * (2) the seed scene's 20 blocks (layout of test_hard_seed, sc_rng seed 1) with e = 0.8 and mu = 0.5
 *     (bench settling()): the blocks lose energy at every impact and must come to
 *     rest. Asserted: (monitor) LC_OK, clock, finite, in the box, no overlap > 1e-9 m; the energy
 *     (computed here) never rises above its start by more than n m g contact_distance = 2e-3 J (the
 *     most the drift correction may lift 20 bodies; e <= 1 and no driving force); at 60 s the kinetic
 *     energy is below 1e-6 J (a block of 1 kg at 1.4 mm/s: bouncing at e = 0.8 from even 1 m stops
 *     after ~3 s - the flight times form a geometric series 0.9 s * 0.8^k - and sliding stops within
 *     v / (mu g) = 0.6 s at mu = 0.5; a frictionless variant is not a settling case - a block sliding
 *     between the side walls slows by 0.8 per hit, but the time between hits grows as 1 / 0.8^k, so it
 *     never comes to rest in finite time - and is left out); over the last
 *     10 s no block moves more than 1e-5 m (stays put, no creep or jitter).
 * (8) bench wedged(): a 1 m x 0.5 m 1 kg block turned by 30 degrees whose two corners exactly touch two
 *     static walls (gap w cos a + h sin a), 3 m above a static floor, e = 0. With friction 0.6 the
 *     rigid problem is indeterminate (any squeeze holds it, no squeeze lets it slide), so the test
 *     asserts what holds for either answer: it never passes through a wall or the floor (every
 *     vertex stays between the walls' faces to 1e-9 m), energy never rises above its start by more
 *     than m g contact_distance, and at 60 s it is at rest (|v|, |omega| <= 1e-6). Frictionless, the
 *     contact normals are horizontal, so until it lands it is in free fall with x, angle unchanged:
 *     y(t) = 3 - g t^2 / 2 to 1e-9 m (closed-form flight; the first 0.5 s, before the lowest corner
 *     can reach the floor at t = sqrt(2 (3 - 0.4665) / g) = 0.719 s).
 * (2b) a hopping block: one block of (2) standing on its 0.5 m end, rocking from corner to corner at
 *     ~1 cm/s while drifting sideways (its state at 10 s, to 17 digits, in a run of (2) on an engine
 *     variant since withdrawn, where it hopped for 26 s), e 0.8, mu 0.5, alone on the floor. Friction
 *     that pushed a slipping corner along its slip gave it ~1.5e-4 J per rock, and alone it never
 *     stopped. Asserted: no impact in the last 5 of 10 s, at rest at 10 s (|v|, |omega| <= 1e-6), and
 *     the energy never above its start by more than m g |v0| dt = 2.2e-3 J, the work of a
 *     weight-sized force on a corner parting at the
 *     block's speed for one step: a touch resting when an interval begins keeps its force while it
 *     parts within that interval (event_touches.c lc_event_resting, docs/physics.md). */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

static void settling(double mu, const char *label)
{
    const double g = 9.8, e = 0.8;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_world_def got;
    lc_body_id b[20];
    int i, k;
    hc_mon m;
    const double box[4] = {0.0, 0.0, 10.0, 10.0};
    double pos[20][3], max_move = 0, ke_end, gain_tol;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    lc_world_get_def(w, &got);
    hc_settling_layout(w, 1u, e, mu, b);
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = 200000; /* settling has a few thousand impacts (printed) */
    for (k = 1; k <= HC_STEPS; k++) {
        if (!hc_step(&m)) break;
        if (k == HC_STEPS - 600)
            for (i = 0; i < 20; i++) memcpy(pos[i], sc_row(w, b[i]), 3 * sizeof(double));
        if (k > HC_STEPS - 600)
            for (i = 0; i < 20; i++) {
                const double *s = sc_row(w, b[i]);
                double mv = hypot(s[0] - pos[i][0], s[1] - pos[i][1]) + 0.5 * fabs(s[2] - pos[i][2]);
                if (mv > max_move) max_move = mv;
            }
    }
    hc_finish(&m, HC_STEPS);
    ke_end = sc_kinetic(w);
    gain_tol = 20 * 1.0 * g * got.contact_distance;
    printf("%s: KE at 60 s %.3e J, largest motion over the last 10 s %.3e m, energy %.6g -> %.6g J, max gain %.3e J\n",
           label, ke_end, max_move, m.e0, m.e_now, m.max_gain);
    CHECK(m.max_gain <= gain_tol, "%s: energy rose by %.3e J (tolerance %.3e)", label, m.max_gain, gain_tol);
    CHECK(ke_end <= 1e-6, "%s: kinetic energy %.3e J at 60 s: not at rest", label, ke_end);
    CHECK(max_move <= 1e-5, "%s: a block moved %.3e m over the last 10 s", label, max_move);
    hc_mon_free(&m);
    lc_world_destroy(w);
}

static void wedged(double mu, const char *label)
{
    const double g = 9.8, a = SC_PI / 6.0, y0 = 3.0;
    const double gap = 1.0 * cos(a) + 0.5 * sin(a);
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_world_def got;
    lc_body_id blk;
    hc_mon m;
    const double box[4] = {-gap / 2, 0.0, gap / 2, 10.0};
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, max_fall_err = 0, max_turn = 0, vmax, wmax, gain_tol;
    /* The corners start exactly on the walls (gap 0) and the engine holds contacts at contact_gap: the
     * end-of-step projection can only open both gaps by turning the block, whose width across the
     * slot, W(theta) = w cos theta + h sin theta, shrinks at |W'| = |h cos a - w sin a| = 0.067 m/rad:
     * a turn of 2 contact_gap / |W'| = 3.0e-6 rad, the model's offset (like a stack's n x contact_gap
     * rise), not a numerical error. */
    double turn_tol;
    int k;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    lc_world_get_def(w, &got);
    turn_tol = 1.01 * 2.0 * got.contact_gap / fabs(0.5 * cos(a) - 1.0 * sin(a)) + 1e-9;
    blk = hc_box(w, 1.0, 0.5, 0.0, y0, a, 0, 0, 0, 1.0, 0.0, mu);
    hc_static(w, 1.0, 10.0, -gap / 2 - 0.5, 5.0, 0.0, mu);
    hc_static(w, 1.0, 10.0, gap / 2 + 0.5, 5.0, 0.0, mu);
    hc_static(w, 10.0, 1.0, 0.0, -0.5, 0.0, mu);
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = 100000;
    for (k = 1; k <= HC_STEPS; k++) {
        lc_vec2 p[LC_MAX_POLYGON_VERTICES];
        int n, i;
        double t;
        if (!hc_step(&m)) break;
        n = sc_world_vertices(w, blk, p);
        for (i = 0; i < n; i++) {
            if (p[i].x < xmin) xmin = p[i].x;
            if (p[i].x > xmax) xmax = p[i].x;
            if (p[i].y < ymin) ymin = p[i].y;
        }
        t = lc_world_get_time(w);
        if (mu == 0.0 && t <= 0.5) {
            const double *s = sc_row(w, blk);
            double err = fabs(s[1] - (y0 - 0.5 * g * t * t)) + fabs(s[0]);
            if (err > max_fall_err) max_fall_err = err;
            if (fabs(s[2] - a) > max_turn) max_turn = fabs(s[2] - a);
        }
    }
    hc_finish(&m, HC_STEPS);
    hc_max_speeds(w, &vmax, &wmax);
    gain_tol = 1.0 * g * got.contact_distance;
    printf("%s: vertices x in [%.12f, %.12f] (walls at -/+%.12f), lowest %.3e m, final y %.6f angle %.6f, "
           "max |v| %.3e, |omega| %.3e, free-fall error %.3e, turn %.3e rad, max energy gain %.3e J\n",
           label, xmin, xmax, gap / 2, ymin, sc_row(w, blk)[1], sc_row(w, blk)[2], vmax, wmax, max_fall_err,
           max_turn, m.max_gain);
    CHECK(xmin >= -gap / 2 - 1e-9 && xmax <= gap / 2 + 1e-9, "%s: a vertex left the slot: x in [%.12f, %.12f]",
          label, xmin, xmax);
    CHECK(ymin >= -1e-9, "%s: a vertex went %.3e m into the floor", label, -ymin);
    CHECK(m.max_gain <= gain_tol, "%s: energy rose by %.3e J", label, m.max_gain);
    CHECK(vmax <= 1e-6 && wmax <= 1e-6, "%s: not at rest at 60 s: |v| %.3e, |omega| %.3e", label, vmax, wmax);
    if (mu == 0.0) {
        CHECK(max_fall_err <= 1e-9, "%s: not in free fall while wedged: error %.3e", label, max_fall_err);
        CHECK(max_turn <= turn_tol, "%s: turned by %.3e rad while wedged (contact-gap offset %.3e)", label, max_turn,
              turn_tol);
    }
    hc_mon_free(&m);
    lc_world_destroy(w);
}

static void hopping(void)
{
    const double g = 9.8, mu = 0.5, e = 0.8, dt = HC_DT;
    const double v0[3] = {0.0050645411367954349, 0.012807217399986076, 0.034056703829182994};
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters c;
    hc_mon m;
    const double box[4] = {-5.0, 0.0, 5.0, 10.0};
    const char *label = "hopping block, e = 0.8, mu = 0.5";
    double vmax, wmax, gain_tol;
    unsigned long long late = 0;
    int k;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    hc_box(w, 1.0, 0.5, 0.0, 0.5000039247682968, 1.5707997254196675, v0[0], v0[1], v0[2], 1.0, e, mu);
    hc_static(w, 10.0, 1.0, 0.0, -0.5, e, mu);
    if (!hc_mon_init(&m, w, label, dt, box)) { lc_world_destroy(w); return; }
    for (k = 1; k <= 600; k++) {
        if (!hc_step(&m)) break;
        lc_world_get_counters(w, &c, NULL);
        if (k > 300) late += c.collisions;
    }
    hc_finish(&m, 600);
    hc_max_speeds(w, &vmax, &wmax);
    gain_tol = 1.0 * g * sqrt(v0[0] * v0[0] + v0[1] * v0[1]) * dt;
    printf("%s: impacts in the last 5 s %llu, max |v| %.3e, |omega| %.3e at 10 s, max energy gain %.3e J "
           "(bound %.3e)\n", label, late, vmax, wmax, m.max_gain, gain_tol);
    CHECK(late == 0, "%s: still hopping: %llu impacts in the last 5 s", label, late);
    CHECK(vmax <= 1e-6 && wmax <= 1e-6, "%s: not at rest at 10 s: |v| %.3e, |omega| %.3e", label, vmax, wmax);
    CHECK(m.max_gain <= gain_tol, "%s: energy rose by %.3e J", label, m.max_gain);
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    hopping();
    settling(0.5, "settling 20 blocks, e = 0.8, mu = 0.5");
    wedged(0.6, "wedged 30 deg, mu = 0.6");
    wedged(0.0, "wedged 30 deg, frictionless");
    return CHECK_SUMMARY("test_hard_settle");
}
