/* test_sparse_lcp.c - MPRGP on the never-formed sparse response (libcollide/src/sparse_lcp.c), the
 * solver of large contact groups, against the exact pivoting solver (lcp.c) on the same problems.
 *
 * Problems come from real touches: a wall of unit boxes (a brick pattern, every face touching, on a
 * static floor), so A = J M^-1 J' has the redundant rows of real piles (four corner points per box
 * on two boxes: A is singular). Right-hand sides are random, in m/s^2 of the order of gravity.
 * Checked:
 *  - the complementarity conditions hold to the tolerance asked for: x within its bounds, y = A x + b
 *    >= -tol where x sits at its lower bound, <= tol at its upper bound, |y| <= tol in between;
 *  - y agrees with the exact solver's y (on a convex QP, A x is the same at every minimiser, while x
 *    is not unique for singular A) to 1e3 tol: the relative-accuracy factor of a stopping test on
 *    the projected gradient, which bounds y's error by cond-weighted multiples of tol;
 *  - boxed rows (friction: -c <= x <= c) satisfy the same conditions at both bounds;
 *  - rows whose bounds coincide (friction without normal force) keep x at that bound;
 *  - no memory is kept beyond the world (LeakSanitizer in the sanitizer build). */
#include "check.h"
#include "lcp.h"
#include "scenes.h"
#include "world.h"
#include "white_box.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ROWS 4          /* layers of the wall */
#define PER_ROW 5       /* boxes in the bottom layer */

static lc_world *brick_wall(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    int i, j;
    d.gravity.y = -9.8;
    w = sc_world(&d);
    if (!w) return NULL;
    sc_static_box(w, 40.0, 1.0, 0.0, -0.5, 0.0);
    for (i = 0; i < ROWS; ++i)
        for (j = 0; j < PER_ROW - i; ++j)
            sc_box(w, 1.0, 1.0, 0.5 * i + j - 0.5 * PER_ROW, 0.5 + i, 0.0, 0, 0, 0, 1.0 + 0.5 * j, 0.0);
    return w;
}

/* Complementarity of x with y = A x + b within bounds, to tol; returns the worst violation. */
static double violation(int m, const double *A, const double *b, const double *lo, const double *hi, const double *x,
                        double *y)
{
    double worst = 0.0;
    int i, j;
    for (i = 0; i < m; ++i) {
        double v;
        y[i] = b[i];
        for (j = 0; j < m; ++j) y[i] += A[i * m + j] * x[j];
        if (x[i] < lo[i] || x[i] > hi[i]) return INFINITY;
        if (lo[i] == hi[i]) v = 0.0;
        else if (x[i] <= lo[i]) v = y[i] < 0.0 ? -y[i] : 0.0;
        else if (x[i] >= hi[i]) v = y[i] > 0.0 ? y[i] : 0.0;
        else v = fabs(y[i]);
        if (v > worst) worst = v;
    }
    return worst;
}

static void dense_response(const lc_world *w, const lc_touch *t, int m, int tangent, double *A)
{
    int i, j;
    for (i = 0; i < m; ++i)
        for (j = 0; j < m; ++j) {
            lc_vec2 di = tangent ? lc_tangent_of(t[i].n) : t[i].n, dj = tangent ? lc_tangent_of(t[j].n) : t[j].n;
            A[i * m + j] = lc_response_dir(w, &t[i], di, &t[j], dj);
        }
}

int main(void)
{
    lc_world *w = brick_wall();
    lc_buf buf = {NULL, 0};
    lc_touch *t;
    double *A, *b, *lo, *hi, *x, *f, *y, *ye;
    int m, trial, i;
    sc_rng rng;
    rng.s = 7;
    if (!w) return CHECK_SUMMARY("test_sparse_lcp");
    m = wb_all_touches(w, &buf);
    t = (lc_touch *)buf.p;
    /* 14 boxes: 5 on the floor (2 corners each), 13 box-on-box faces (2 points each), side faces */
    CHECK(m >= 30, "the wall has %d touches (expected the floor, stacked and side faces)", m);
    A = calloc((size_t)m * (size_t)m, sizeof *A);
    b = calloc((size_t)m, sizeof *b);
    lo = calloc((size_t)m, sizeof *lo);
    hi = calloc((size_t)m, sizeof *hi);
    x = calloc((size_t)m, sizeof *x);
    f = calloc((size_t)m, sizeof *f);
    y = calloc((size_t)m, sizeof *y);
    ye = calloc((size_t)m, sizeof *ye);
    if (!A || !b || !lo || !hi || !x || !f || !y || !ye) {
        CHECK(0, "out of memory");
        return CHECK_SUMMARY("test_sparse_lcp");
    }
    dense_response(w, t, m, 0, A);
    for (trial = 0; trial < 20; ++trial) {
        const double tol = 1e-9;
        double viol, worst_ye = 0.0, v;
        int products;
        lc_lcp_result res;
        lc_lcp_options opt = lc_lcp_default_options();
        opt.exact_max = m;
        for (i = 0; i < m; ++i) {
            /* mostly pressing (weight-like), some rows pulling apart */
            b[i] = sc_uniform(&rng, -20.0, 5.0);
            lo[i] = 0.0;
            hi[i] = INFINITY;
            x[i] = trial % 2 ? sc_uniform(&rng, 0.0, 5.0) : 0.0;   /* warm and cold starts */
        }
        products = lc_sparse_lcp(w, t, m, 0, b, lo, hi, x, tol, 100000, &v);
        CHECK(products > 0, "normal rows, trial %d: lc_sparse_lcp returned %d", trial, products);
        viol = violation(m, A, b, lo, hi, x, y);
        /* the solver's own test is on the same conditions: allow round-off of the y recomputed here */
        CHECK(viol <= 2.0 * tol, "normal rows, trial %d: complementarity violated by %.3e (tol %.1e, %d products)",
              trial, viol, tol, products);
        CHECK(v <= tol, "normal rows, trial %d: reported violation %.3e above tol", trial, v);
        for (i = 0; i < m; ++i) f[i] = 0.0;
        lc_lcp_solve(m, A, b, f, NULL, &opt, NULL, &res);
        CHECK(res.status == 0 && res.exact, "exact solver status %d exact %d", res.status, res.exact);
        violation(m, A, b, lo, hi, f, ye);
        for (i = 0; i < m; ++i) worst_ye = fmax(worst_ye, fabs(y[i] - ye[i]));
        CHECK(worst_ye <= 1e3 * tol, "normal rows, trial %d: y differs from the exact solver's by %.3e",
              trial, worst_ye);
    }
    /* boxed (friction) rows, with some rows fixed at 0 (no normal force) */
    dense_response(w, t, m, 1, A);
    for (trial = 0; trial < 20; ++trial) {
        const double tol = 1e-9;
        double viol, v;
        int products, fixed_moved = 0;
        for (i = 0; i < m; ++i) {
            double c = i % 5 == 0 ? 0.0 : sc_uniform(&rng, 0.0, 8.0);
            b[i] = sc_uniform(&rng, -10.0, 10.0);
            lo[i] = -c;
            hi[i] = c;
            x[i] = trial % 2 ? sc_uniform(&rng, -c, c) : 0.0;
        }
        products = lc_sparse_lcp(w, t, m, 1, b, lo, hi, x, tol, 100000, &v);
        CHECK(products > 0, "tangent rows, trial %d: lc_sparse_lcp returned %d", trial, products);
        viol = violation(m, A, b, lo, hi, x, y);
        CHECK(viol <= 2.0 * tol, "tangent rows, trial %d: complementarity violated by %.3e (tol %.1e, %d products)",
              trial, viol, tol, products);
        for (i = 0; i < m; ++i)
            if (lo[i] == hi[i] && x[i] != lo[i]) fixed_moved++;
        CHECK(fixed_moved == 0, "tangent rows, trial %d: %d rows with equal bounds moved", trial, fixed_moved);
    }
    free(A); free(b); free(lo); free(hi); free(x); free(f); free(y); free(ye);
    lc_buf_free(&buf);
    lc_world_destroy(w);
    return CHECK_SUMMARY("test_sparse_lcp");
}
