/* test_hard_pyramid (docs/hard_cases.md): Box2D's "large pyramid" layout with base 20 (210 unit
 * boxes, 1 m x 1 m, 1 kg; row i at y = 0.5 + i, box j of it at x = (i + 1)/2 + (j - i) - base/2, all
 * faces touching) on a static ground box 60 m x 1 m (top face y = 0), g = 10 m/s^2 (Box2D's), e = 0,
 * friction mu = 0.6 on every body and, second case, frictionless (every contact normal is vertical
 * or horizontal and nothing pushes sideways, so friction is never needed: it must stand as well).
 * 60 s (3600 steps) at dt = 1/60 s. Every other setting the engine's default (sort-and-sweep
 * broadphase: 211 bodies > broadphase_threshold 32; contact groups of ~1200 points > lcp_exact_max, so
 * the sparse solver, sparse_lcp.c).
 * Asserted at every step end (besides test_hard_common.h's LC_OK / clock / finite / in box / overlap
 * <= 1e-9 m):
 *  - every box stays put: |x - x0| and |y - y0| <= 1e-4 m, tilt <= 1e-5 rad. The exact answer is 0;
 *    contacts are held at gap contact_gap = 1e-7 m, so the top (row 20) may rise by 20 * 1e-7 = 2e-6 m;
 *    the sparse solver stops when the unresolved relative acceleration is below 2.5e-5 contact_gap /
 *    h^2 = 9e-9 m/s^2 (contact_forces.c), which the velocity stabilisation stops every step where a
 *    contact holds; in a direction nothing holds (frictionless, sideways) it integrates into a creep:
 *    uncorrected over 60 s 9e-9 * 60^2 / 2 = 1.6e-5 m. Measured: 4.9e-5 m (box 209), more than that
 *    estimate, so the residual is not the creep's only source (not yet explained); at a 10x looser
 *    tolerance 4.1e-4 m, which failed this bound.
 *    1e-4 m is 10 contact_distances and 300 x below Box2D v3's top-box motion of 3 cm in 8 s;
 *  - at rest: |v| <= 1e-5 m/s and |omega| <= 1e-5 rad/s (a residual of 9e-9 m/s^2 over one step is
 *    1.5e-10 m/s; over 60 s 5.4e-7 m/s; anything near 1e-5 is jitter);
 *  - energy (computed here) never rises or falls by more than sum m g 1e-4 m (the position bound);
 *  - no impacts: faces start touching and nothing approaches (budget: one per box, run stops beyond);
 *  - at the end the ground's contact forces carry the whole weight, 210 * 10 N, to 1e-6 relative. */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

/* The faces start at gap 0 and the engine lifts each to the held gap contact_gap = 1e-7 m in the first
 * step (a stack of n moves its top by n * 1e-7 m in 1/60 s, ~1e-5 m/s for n = 20): the rest-speed
 * bound applies from the 7th step (t > 0.1 s) on; positions and overlap are checked from step 1. */
#define SETTLE_STEPS 6

#define BASE 20
#define NBOX (BASE * (BASE + 1) / 2)
#define POS_TOL 1e-4
#define TILT_TOL 1e-5
#define REST_V 1e-5
#define PYR_STEPS 3600

static void pyramid(double mu, const char *label)
{
    const double g = 10.0;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id ground, b[NBOX];
    double x0[NBOX], y0[NBOX], max_dx = 0, max_dy = 0, max_tilt = 0, max_v = 0, max_w = 0, t_v = 0, fsum = 0;
    double top_dx = 0, top_dy = 0, etol;
    const double box[4] = {-30.0, -1.0, 30.0, 30.0};
    int i, k, nb = 0, nc, n_ground = 0, worst_box = -1;
    const lc_contact *cs;
    hc_mon m;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    ground = hc_static(w, 2.0 * BASE + 20.0, 1.0, 0.0, -0.5, 0.0, mu);
    nb = sc_pyramid(w, BASE, mu, b);
    for (i = 0; i < nb; i++) {
        x0[i] = sc_row(w, b[i])[0];
        y0[i] = sc_row(w, b[i])[1];
    }
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = NBOX;
    for (k = 1; k <= PYR_STEPS; k++) {
        lc_state_view v;
        if (!hc_step(&m)) break;
        lc_world_get_state(w, &v);
        for (i = 0; i < nb; i++) {
            const double *s = v.state + 6 * lc_world_body_index(w, b[i]);
            double sp = hypot(s[3], s[4]);
            if (fabs(s[0] - x0[i]) > max_dx) { max_dx = fabs(s[0] - x0[i]); worst_box = i; }
            if (fabs(s[1] - y0[i]) > max_dy) { max_dy = fabs(s[1] - y0[i]); worst_box = i; }
            if (hc_tilt(s[2]) > max_tilt) max_tilt = hc_tilt(s[2]);
            if (k > SETTLE_STEPS && sp > max_v) { max_v = sp; t_v = lc_world_get_time(w); }
            if (k > SETTLE_STEPS && fabs(s[5]) > max_w) max_w = fabs(s[5]);
            if (i == nb - 1) {
                if (fabs(s[0] - x0[i]) > top_dx) top_dx = fabs(s[0] - x0[i]);
                if (fabs(s[1] - y0[i]) > top_dy) top_dy = fabs(s[1] - y0[i]);
            }
        }
    }
    hc_finish(&m, PYR_STEPS);
    nc = sc_contacts(w, &cs);
    for (i = 0; i < nc; i++) {
        if (cs[i].kind != LC_CONTACT_RESTING) continue;
        if (cs[i].body_b == ground) { fsum += cs[i].force * cs[i].normal.y; n_ground++; }
        else if (cs[i].body_a == ground) { fsum -= cs[i].force * cs[i].normal.y; n_ground++; }
    }
    etol = NBOX * 1.0 * g * POS_TOL;
    printf("%s: max |dx| %.3e m, max |dy| %.3e m (box %d), top box |dx| %.3e |dy| %.3e m, tilt %.3e rad, "
           "max |v| %.3e m/s (t = %.3f), max |omega| %.3e rad/s, ground force %.9g N for weight %.9g N (%d points)\n",
           label, max_dx, max_dy, worst_box, top_dx, top_dy, max_tilt, max_v, t_v, max_w, fsum, NBOX * g, n_ground);
    CHECK(max_dx <= POS_TOL, "%s: a box moved sideways %.3e m", label, max_dx);
    CHECK(max_dy <= POS_TOL, "%s: a box moved vertically %.3e m", label, max_dy);
    CHECK(max_tilt <= TILT_TOL, "%s: a box tilted %.3e rad", label, max_tilt);
    CHECK(max_v <= REST_V, "%s: a box moved at %.3e m/s (t = %.3f)", label, max_v, t_v);
    CHECK(max_w <= REST_V, "%s: a box turned at %.3e rad/s", label, max_w);
    CHECK(m.max_gain <= etol, "%s: energy rose by %.3e J (tolerance %.3e)", label, m.max_gain, etol);
    CHECK(m.max_loss <= etol, "%s: energy fell by %.3e J (tolerance %.3e)", label, m.max_loss, etol);
    CHECK(n_ground >= 2 * BASE, "%s: the base row rests on >= %d ground points, got %d", label, 2 * BASE, n_ground);
    CHECK_REL(fsum, NBOX * g, 1e-6, "ground contact forces carry the pyramid's weight");
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    pyramid(0.6, "pyramid base 20, mu = 0.6");
    pyramid(0.0, "pyramid base 20, frictionless");
    return CHECK_SUMMARY("test_hard_pyramid");
}
