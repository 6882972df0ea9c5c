/* test_static_load.c - the starting guesses of a cold pile's sparse solves (libcollide/src/static_load.c).
 *
 * Checked:
 *  - a column of three 1 kg boxes on the floor (g = 10): the touches each box rests on carry, along up,
 *    exactly the weight above them (30, 20 and 10 N), split evenly between the two corners: a
 *    statically exact answer, so to round-off (1e-12 N);
 *  - the lever rule: a 1 kg box resting off-centre on a 1 kg box (its centre 0.25 m right of the lower
 *    box's) makes the lower box press its right floor corner harder. Moments about the lower box's
 *    centre: 10 N at 0 and the upper box's 10 N at 0.25 m give 7.5 N on the left corner and 12.5 N on
 *    the right; again statically exact (1e-12 N);
 *  - without gravity there is no up and no guess (the forces stay 0);
 *  - lifts: the column at gap 0 (each face contact_gap short): the multipliers move box k up by
 *    k * contact_gap and do not turn it (1e-20 m / rad: round-off of 1e-7 m sums);
 *  - in use by the event regime: a cold pyramid of 820 boxes (base 40, Box2D's layout, mu 0.6) ends its
 *    first step with the contact solves converged (max_lcp_residual <= 2.5e-5 contact_gap / h^2 = 9e-9
 *    m/s^2, the large groups' tolerance, contact_forces.c) and without a time-of-impact search or
 *    collision in its first three steps. From zero forces (at 48f383c, tolerance 9e-8) the same step
 *    ended 2e-4 m/s^2 off after 16 000 products;
 *  - in use by the contact regime (the default for that pile): its first solve starts at the lever
 *    rule's answer, which is the pyramid's static answer, so it ends within contact_tolerance (1e-10
 *    m/s) in a few sweeps, with no collision, in each of its first three steps. */
#include "check.h"
#include "scenes.h"
#include "world.h"
#include "white_box.h"

#include <math.h>
#include <stdlib.h>

/* Sum of the guess's parts along up over the touches that hold up row `held` (its normal points up into
 * it); left/right: only those whose point lies left/right of x_split (NULL: every one). */
static double carried(const lc_world *w, const lc_touch *t, int n, const double *f, int held, double x_split,
                      int side)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; ++i) {
        double up = t[i].a == held ? t[i].n.y : t[i].b == held ? -t[i].n.y : 0.0;
        if (up <= 0.5) continue;
        if (side < 0 && !(t[i].p.x < x_split)) continue;
        if (side > 0 && !(t[i].p.x > x_split)) continue;
        s += f[i] * up;
    }
    (void)w;
    return s;
}

static lc_world *column(double g)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    int k;
    d.gravity = lc_v(0.0, -g);
    w = sc_world(&d);
    if (!w) return NULL;
    sc_static_box(w, 10.0, 1.0, 0.0, -0.5, 0.0);
    for (k = 0; k < 3; ++k) sc_box(w, 1.0, 1.0, 0.0, 0.5 + k, 0.0, 0, 0, 0, 1.0, 0.0);
    return w;
}

static void column_forces(void)
{
    lc_world *w = column(10.0);
    lc_buf buf = {NULL, 0};
    double *f;
    int n, k;
    if (!w) return;
    n = wb_all_touches(w, &buf);
    f = calloc((size_t)(n > 0 ? n : 1), sizeof *f);
    CHECK(f != NULL && n >= 6, "the column has %d touches (floor and two faces, two corners each)", n);
    if (f && n >= 6) {
        CHECK(lc_static_load_forces(w, (lc_touch *)buf.p, n, f) == 0, "%s", "lc_static_load_forces failed");
        for (k = 1; k <= 3; ++k) {
            double above = 10.0 * (4 - k);   /* row k is the k-th box from the floor (row 0) */
            CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, k, 0.0, 0), above, 1e-12, "load under box k");
            CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, k, 0.0, -1), above / 2, 1e-12, "left corner");
            CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, k, 0.0, 1), above / 2, 1e-12, "right corner");
        }
    }
    free(f);
    lc_buf_free(&buf);
    lc_world_destroy(w);
}

static void lever_rule(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_buf buf = {NULL, 0};
    double *f;
    int n;
    d.gravity = lc_v(0.0, -10.0);
    w = sc_world(&d);
    if (!w) return;
    sc_static_box(w, 10.0, 1.0, 0.0, -0.5, 0.0);
    sc_box(w, 1.0, 1.0, 0.0, 0.5, 0.0, 0, 0, 0, 1.0, 0.0);     /* row 1 */
    sc_box(w, 0.5, 0.5, 0.25, 1.25, 0.0, 0, 0, 0, 1.0, 0.0);   /* row 2: spans x 0 .. 0.5 on row 1's top */
    n = wb_all_touches(w, &buf);
    f = calloc((size_t)(n > 0 ? n : 1), sizeof *f);
    CHECK(f != NULL && n >= 4, "%d touches", n);
    if (f && n >= 4) {
        CHECK(lc_static_load_forces(w, (lc_touch *)buf.p, n, f) == 0, "%s", "lc_static_load_forces failed");
        CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, 2, 0.0, 0), 10.0, 1e-12, "upper box's weight");
        CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, 1, 0.0, -1), 7.5, 1e-12, "lower box, left floor corner");
        CHECK_NEAR(carried(w, (lc_touch *)buf.p, n, f, 1, 0.0, 1), 12.5, 1e-12, "lower box, right floor corner");
    }
    free(f);
    lc_buf_free(&buf);
    lc_world_destroy(w);
}

static void no_gravity(void)
{
    lc_world *w = column(0.0);
    lc_buf buf = {NULL, 0};
    double *f;
    int n, i, nonzero = 0;
    if (!w) return;
    n = wb_all_touches(w, &buf);
    f = calloc((size_t)(n > 0 ? n : 1), sizeof *f);
    CHECK(f != NULL && n >= 6, "%d touches", n);
    if (f && n >= 6) {
        CHECK(lc_static_load_forces(w, (lc_touch *)buf.p, n, f) == 0, "%s", "lc_static_load_forces failed");
        for (i = 0; i < n; ++i) nonzero += f[i] != 0.0;
        CHECK(nonzero == 0, "%d touches got a guess without gravity", nonzero);
    }
    free(f);
    lc_buf_free(&buf);
    lc_world_destroy(w);
}

static void column_lifts(void)
{
    lc_world *w = column(10.0);
    lc_buf buf = {NULL, 0};
    double *lam, *deficit, *disp;
    lc_touch *t;
    int n, i, k;
    if (!w) return;
    n = wb_all_touches(w, &buf);
    t = (lc_touch *)buf.p;
    lam = calloc((size_t)(n > 0 ? n : 1), sizeof *lam);
    deficit = calloc((size_t)(n > 0 ? n : 1), sizeof *deficit);
    disp = calloc((size_t)w->count * 3, sizeof *disp);
    CHECK(lam && deficit && disp && n >= 6, "%d touches", n);
    if (lam && deficit && disp && n >= 6) {
        for (i = 0; i < n; ++i) deficit[i] = w->def.contact_gap - t[i].gap;
        CHECK(lc_static_load_lifts(w, t, n, deficit, lam) == 0, "%s", "lc_static_load_lifts failed");
        for (i = 0; i < n; ++i)
            if (lam[i] > 0.0) lc_touch_apply(w, &t[i], lc_scale(t[i].n, lam[i]), disp, 3);
        for (k = 1; k <= 3; ++k) {
            CHECK_NEAR(disp[k * 3 + 1], k * w->def.contact_gap, 1e-20, "rise of box k");
            CHECK_NEAR(disp[k * 3 + 0], 0.0, 1e-20, "sideways shift of box k");
            CHECK_NEAR(disp[k * 3 + 2], 0.0, 1e-20, "turn of box k");
        }
    }
    free(lam);
    free(deficit);
    free(disp);
    lc_buf_free(&buf);
    lc_world_destroy(w);
}

static void cold_pyramid(lc_regime regime)
{
    const int base = 40;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_vec2 v[4];
    int k;
    d.gravity = lc_v(0.0, -10.0);
    d.regime = regime;
    w = sc_world(&d);
    if (!w) return;
    lc_make_rectangle(2.0 * base + 20.0, 1.0, v);
    {
        lc_body_def g = lc_default_body_def();
        g.type = LC_BODY_STATIC;
        g.vertices = v;
        g.vertex_count = 4;
        g.position = lc_v(0.0, -0.5);
        g.elasticity = 0.0;
        g.friction = 0.6;
        sc_add(w, &g, "ground");
    }
    sc_pyramid(w, base, 0.6, NULL);
    for (k = 0; k < 3; ++k) {
        lc_counters c;
        lc_status s = lc_world_step(w, 1.0 / 60.0);
        CHECK(s == LC_OK, "step %d: %s", k + 1, lc_world_last_error(w));
        lc_world_get_counters(w, &c, NULL);
        if (regime != LC_REGIME_EVENT) {
            printf("contact regime, step %d: %llu points, %llu sweeps, residual %.3g m/s\n", k + 1,
                   (unsigned long long)c.contact_points, (unsigned long long)c.contact_sweeps, c.max_contact_residual);
            CHECK(c.contact_islands == 1 && c.max_contact_residual <= d.contact_tolerance && c.collisions == 0,
                  "contact regime, step %d: residual %.3g m/s after %llu sweeps, %llu collisions", k + 1,
                  c.max_contact_residual, (unsigned long long)c.contact_sweeps, (unsigned long long)c.collisions);
            continue;
        }
        if (k == 0) {
            CHECK(c.contact_solves > 0, "%s", "the pile's forces were solved");
            CHECK(c.max_lcp_residual <= 2.5e-5 * d.contact_gap * 3600.0,
                  "first step: contact solves %.3g m/s^2 off after %llu products (tolerance 9e-9)",
                  c.max_lcp_residual, (unsigned long long)c.contact_solve_iterations);
        }
        CHECK(c.toi_searches == 0 && c.collisions == 0, "step %d: %llu TOI searches, %llu collisions", k + 1,
              (unsigned long long)c.toi_searches, (unsigned long long)c.collisions);
    }
    lc_world_destroy(w);
}

int main(void)
{
    column_forces();
    lever_rule();
    no_gravity();
    column_lifts();
    cold_pyramid(LC_REGIME_EVENT);
    cold_pyramid(LC_REGIME_AUTO);
    return CHECK_SUMMARY("test_static_load");
}
