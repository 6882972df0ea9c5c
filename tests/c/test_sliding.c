/* test_sliding: frictionless sliding contact carried across corners (g = 9.81, e = 0.5, friction 0).
 * Every contact normal in these scenes is vertical, so no horizontal force or impulse may ever act:
 * the horizontal velocity is constant (tolerance 1e-9 m/s: round-off only; a bogus impulse at a
 * corner changes it by O(1) m/s), the bodies stay flat (|omega| <= 1e-6 rad/s: the supported body is
 * in static equilibrium, only the drift correction may nudge it) and at their resting height (centre
 * y within [y0 - 1e-9, y0 + contact_distance]), and nothing overlaps by more than 1e-9 m.
 *  (1) a 1 m block slides at 1 m/s (and 3 m/s) across the seam between two static floor slabs
 *      whose tops are level: flush (touching), 1e-7 m apart and 1 mm apart (the corner passes
 *      over the 1 mm gap while the block is held by its other corner: it does not dip);
 *  (2) a 4 m x 0.2 m plank on two static 1 m supports slides at 1 m/s for 1.2 s: its end passes
 *      a support's corner (the support's corner leaves the plank's face, the plank's corner lands
 *      on the support's face) while its centre stays between the supports;
 *  (3) a block on the floor sliding flat into a wall (see into_wall);
 *  (4) a 1 kg block resting on the floor pushed along it by a 100 N thruster through its centre for
 *      0.25 s: every step succeeds and vx = F t / m to 1e-9 m/s (a constant force without friction:
 *      RK4 is exact), vy stays 0. The thruster's work (1.4 J in the first step, more than the block's
 *      kinetic energy plus 1 J) is work of an applied force, which the per-interval energy check of
 *      the contact forces must not take for a blow-up. */
#include "check.h"
#include "scenes.h"

static void watch(lc_world *w, lc_body_id a, const lc_body_id *others, int n, double y0, double vx, double T,
                  const char *label)
{
    lc_world_def got;
    double dvx = 0, maxw = 0, ylo = 0, yhi = 0, worst = 0;
    int k, i, steps = (int)(T / 0.01 + 0.5);
    lc_world_get_def(w, &got);
    for (k = 0; k < steps; k++) {
        const double *r;
        if (sc_step_n(w, 0.01, 1) != 1) break;
        r = sc_row(w, a);
        if (fabs(r[3] - vx) > dvx) dvx = fabs(r[3] - vx);
        if (fabs(r[5]) > maxw) maxw = fabs(r[5]);
        if (r[1] - y0 < ylo) ylo = r[1] - y0;
        if (r[1] - y0 > yhi) yhi = r[1] - y0;
        for (i = 0; i < n; i++) {
            double sp = sc_separation(w, a, others[i]);
            if (-sp > worst) worst = -sp;
        }
    }
    printf("%s: max |dvx| %.3e m/s, max |omega| %.3e rad/s, y - y0 in [%.3e, %.3e] m, worst overlap %.3e m, "
           "final x %.6f\n", label, dvx, maxw, ylo, yhi, worst, sc_row(w, a)[0]);
    CHECK(dvx <= 1e-9, "%s: horizontal velocity changed by %.3e m/s", label, dvx);
    CHECK(maxw <= 1e-6, "%s: the sliding body turned, |omega| up to %.3e rad/s", label, maxw);
    CHECK(ylo >= -1e-9 && yhi <= got.contact_distance, "%s: height left [y0 - 1e-9, y0 + %.0e]: [%.3e, %.3e]",
          label, got.contact_distance, ylo, yhi);
    CHECK(worst <= 1e-9, "%s: overlap of %.3e m", label, worst);
}

static void seam(double gap, double vx)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_body_id slab[2], blk;
    double y0;
    char label[96];
    if (!w) return;
    snprintf(label, sizeof label, "block across a seam %g m wide at %g m/s", gap, vx);
    slab[0] = sc_static_box(w, 3.0, 1.0, -1.5, -0.5, 0.5);       /* top face y = 0, x in [-3, 0] */
    slab[1] = sc_static_box(w, 3.0, 1.0, 1.5 + gap, -0.5, 0.5); /* top face y = 0, x in [gap, 3 + gap] */
    y0 = 0.5 + d.contact_gap;
    blk = sc_box(w, 1.0, 1.0, -1.0, y0, 0.0, vx, 0.0, 0.0, 1.0, 0.5);
    watch(w, blk, slab, 2, y0, vx, 1.6 / vx, label); /* ends near x = 0.6: fully on the second slab */
    lc_world_destroy(w);
}

static void plank(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_body_id sup[2], p;
    double y0;
    if (!w) return;
    sup[0] = sc_static_box(w, 1.0, 1.0, -1.2, 0.0, 0.5); /* tops at y = 0.5, x in [-1.7, -0.7] */
    sup[1] = sc_static_box(w, 1.0, 1.0, 1.2, 0.0, 0.5);  /* and [0.7, 1.7] */
    y0 = 0.5 + d.contact_gap + 0.1;
    p = sc_box(w, 4.0, 0.2, 0.0, y0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.5);
    watch(w, p, sup, 2, y0, 1.0, 1.2, "plank sliding over a support's corner");
    lc_world_destroy(w);
}

/* (3) a block resting on the floor slides into the right wall at 2 m/s: its face hits the wall
 * flat (two corners at once) while its bottom rests on the floor; it must come back at -e * 2 m/s
 * (1e-9: the wall impulses are symmetric, the floor contacts see no approach), flat and on the
 * floor. Both impact modes, e = 1 and 0.5 (wall and block). */
static void into_wall(double e, lc_impact_mode mode)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4], blk;
    double y0, maxw = 0, ylo = 0, yhi = 0;
    const double *r;
    int k;
    char label[96];
    d.impact_mode = mode;
    w = sc_world(&d);
    if (!w) return;
    snprintf(label, sizeof label, "sliding into the wall, e = %g, %s", e, mode ? "simultaneous" : "serial");
    CHECK(lc_world_add_walls(w, -5, 0, 5, 10, 1.0, e, walls) == LC_OK, "%s", "walls");
    y0 = 0.5 + d.contact_gap;
    blk = sc_box(w, 1.0, 1.0, 3.0, y0, 0.0, 2.0, 0.0, 0.0, 1.0, e);
    for (k = 0; k < 200; k++) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        r = sc_row(w, blk);
        if (fabs(r[5]) > maxw) maxw = fabs(r[5]);
        if (r[1] - y0 < ylo) ylo = r[1] - y0;
        if (r[1] - y0 > yhi) yhi = r[1] - y0;
    }
    r = sc_row(w, blk);
    printf("%s: vx %.12f, max |omega| %.3e, y - y0 in [%.3e, %.3e]\n", label, r[3], maxw, ylo, yhi);
    CHECK_NEAR(r[3], -2.0 * e, 1e-9, label);
    CHECK(maxw <= 1e-6, "%s: turned, |omega| up to %.3e", label, maxw);
    CHECK(ylo >= -1e-9 && yhi <= d.contact_distance, "%s: left the floor: y - y0 in [%.3e, %.3e]", label, ylo, yhi);
    lc_world_destroy(w);
}

static void thrust_on_floor(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_thruster_def td;
    lc_body_id b;
    int idx, k, failed = 0;
    double t = 0.0;
    if (!w) return;
    lc_world_add_walls(w, -50.0, 0.0, 50.0, 10.0, 1.0, 0.5, NULL);
    b = sc_box(w, 1.0, 0.5, 0.0, 0.25 + d.contact_gap, 0.0, 0, 0, 0, 1.0, 0.5);
    td.point.x = 0.0; td.point.y = 0.0;
    td.direction.x = 1.0; td.direction.y = 0.0;
    td.magnitude = 100.0;
    CHECK(lc_body_add_thruster(w, b, &td, &idx) == LC_OK && lc_body_set_thruster_level(w, b, idx, 1.0) == LC_OK,
          "%s", "thruster added and fired");
    for (k = 0; k < 15 && !failed; k++) {
        lc_status s = lc_world_step(w, 1.0 / 60);
        failed = s != LC_OK;
        CHECK(s == LC_OK, "thrust on the floor: step %d failed: %s", k, lc_world_last_error(w));
        t += 1.0 / 60;
    }
    CHECK_NEAR(sc_row(w, b)[3], 100.0 * t, 1e-9, "thrust on the floor: vx = F t / m");
    CHECK_NEAR(sc_row(w, b)[4], 0.0, 1e-9, "thrust on the floor: vy");
    lc_world_destroy(w);
}

int main(void)
{
    seam(0.0, 1.0);
    seam(1e-7, 1.0);
    seam(1e-3, 1.0);
    seam(0.0, 3.0);
    plank();
    into_wall(1.0, LC_IMPACT_SERIAL);
    into_wall(0.5, LC_IMPACT_SERIAL);
    into_wall(1.0, LC_IMPACT_SIMULTANEOUS);
    into_wall(0.5, LC_IMPACT_SIMULTANEOUS);
    thrust_on_floor();
    return CHECK_SUMMARY("test_sliding");
}
