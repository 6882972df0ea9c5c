/* test_lcp.c - the complementarity solvers (libcollide/src/lcp.c).
 *
 * Problems: a = A f + b, 0 <= f _|_ a >= 0 with A = J M^-1 J^T (contact matrices) or random SPD,
 * the boxed variant with friction rows, and bad input. Units in the physical cases: kg, m, s, N.
 * Tolerances are stated where used; "rounding level" means a few hundred ulps of the data scale.
 */
#include "check.h"
#include "lcp.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define G 9.81

/* ---------------------------------------------------------------------------------------------
 * helpers
 * ------------------------------------------------------------------------------------------- */
typedef struct {
    uint64_t s;
} lcg_t;

/* 64-bit LCG (Knuth's MMIX constants); top 53 bits -> [0, 1). */
static double lcg_uniform(lcg_t *g)
{
    g->s = g->s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(g->s >> 11) * (1.0 / 9007199254740992.0);
}

static double lcg_range(lcg_t *g, double lo, double hi) { return lo + (hi - lo) * lcg_uniform(g); }

/* A = J diag(w) J^T, J m x d row-major. */
static void jwjt(int m, int d, const double *J, const double *w, double *A)
{
    int i, j, k;
    for (i = 0; i < m; ++i)
        for (j = 0; j < m; ++j) {
            double s = 0.0;
            for (k = 0; k < d; ++k) s += J[i * d + k] * w[k] * J[j * d + k];
            A[i * m + j] = s;
        }
}

/* Make A exactly symmetric (average of the two rounded products). */
static void symmetrize(int n, double *A)
{
    int i, j;
    for (i = 0; i < n; ++i)
        for (j = i + 1; j < n; ++j) {
            double v = 0.5 * (A[i * n + j] + A[j * n + i]);
            A[i * n + j] = v;
            A[j * n + i] = v;
        }
}

static void matvec_plus(int n, const double *A, const double *x, const double *b, double *y)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        double s = b ? b[i] : 0.0;
        for (j = 0; j < n; ++j) s += A[i * n + j] * x[j];
        y[i] = s;
    }
}

/* Independent check of an LCP answer: returns max_i |min(f_i, a_i)| / (max|b|) with a recomputed
 * here, and the most negative f. */
static double indep_residual(int n, const double *A, const double *b, const double *f, double *fmin_out)
{
    double *a = (double *)malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    double r = 0.0, bmax = 0.0, fmin = 0.0;
    int i;
    matvec_plus(n, A, f, b, a);
    for (i = 0; i < n; ++i) {
        double m = f[i] < a[i] ? f[i] : a[i];
        if (fabs(m) > r || m != m) r = fabs(m);
        if (fabs(b[i]) > bmax) bmax = fabs(b[i]);
        if (f[i] < fmin) fmin = f[i];
    }
    free(a);
    *fmin_out = fmin;
    return bmax > 0.0 ? r / bmax : r;
}

static double max_abs_diff(int n, const double *x, const double *y)
{
    double m = 0.0;
    int i;
    for (i = 0; i < n; ++i)
        if (fabs(x[i] - y[i]) > m) m = fabs(x[i] - y[i]);
    return m;
}

static lc_lcp_options opts(int exact_max, int max_it, double tol)
{
    lc_lcp_options o = lc_lcp_default_options();
    o.exact_max = exact_max;
    o.max_iterations = max_it;
    o.tolerance = tol;
    return o;
}

/* Jacobian row of a contact at world point p with normal nrm (pointing from body L to body U),
 * bodies given by column offsets (3 per body: x, y, angle; -1 = static) and centres. */
static void contact_row(double *row, int d, int colU, const double cU[2], int colL, const double cL[2],
                        const double p[2], const double nrm[2])
{
    int k;
    for (k = 0; k < d; ++k) row[k] = 0.0;
    if (colU >= 0) {
        row[colU + 0] = nrm[0];
        row[colU + 1] = nrm[1];
        row[colU + 2] = (p[0] - cU[0]) * nrm[1] - (p[1] - cU[1]) * nrm[0];
    }
    if (colL >= 0) {
        row[colL + 0] = -nrm[0];
        row[colL + 1] = -nrm[1];
        row[colL + 2] = -((p[0] - cL[0]) * nrm[1] - (p[1] - cL[1]) * nrm[0]);
    }
}

/* ---------------------------------------------------------------------------------------------
 * 1. small problems with closed-form answers
 * ------------------------------------------------------------------------------------------- */
static void test_small(lc_lcp_workspace *ws)
{
    lc_lcp_options o = lc_lcp_default_options();
    lc_lcp_result r;
    double f[4], a[4];
    /* Exact method answers agree with the closed forms to rounding: 1e-14 relative on O(1) data. */
    const double tol = 1e-14;

    { /* n = 1, b < 0: f = -b/A = 2, a = 0 */
        double A[1] = {2.0}, b[1] = {-4.0};
        lc_lcp_solve(1, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "n=1 b<0: status %d exact %d", r.status, r.exact);
        CHECK_NEAR(f[0], 2.0, tol, "n=1 b<0 force");
        CHECK_NEAR(a[0], 0.0, tol, "n=1 b<0 accel");
    }
    { /* n = 1, b > 0: f = 0, a = b */
        double A[1] = {2.0}, b[1] = {3.0};
        lc_lcp_solve(1, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "n=1 b>0: status %d exact %d", r.status, r.exact);
        CHECK_NEAR(f[0], 0.0, 0.0, "n=1 b>0 force");
        CHECK_NEAR(a[0], 3.0, 0.0, "n=1 b>0 accel");
    }
    { /* n = 1, b = 0: f = 0, a = 0 (degenerate) */
        double A[1] = {2.0}, b[1] = {0.0};
        lc_lcp_solve(1, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0, "n=1 b=0 status %d", r.status);
        CHECK_NEAR(f[0], 0.0, 0.0, "n=1 b=0 force");
    }
    { /* n = 2, one active: f = (1, 0), a = (0, 4) */
        double A[4] = {2.0, 1.0, 1.0, 2.0}, b[2] = {-2.0, 3.0};
        lc_lcp_solve(2, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "n=2: status %d exact %d", r.status, r.exact);
        CHECK_NEAR(f[0], 1.0, tol, "n=2 f0");
        CHECK_NEAR(f[1], 0.0, tol, "n=2 f1");
        CHECK_NEAR(a[0], 0.0, tol, "n=2 a0");
        CHECK_NEAR(a[1], 4.0, tol, "n=2 a1");
    }
    { /* n = 2, both b < 0 but only one active (the guess {b<0} is wrong and must be corrected):
       * f = (1, 0) gives a = (0, 1 - 0.5) = (0, 0.5) */
        double A[4] = {2.0, 1.0, 1.0, 2.0}, b[2] = {-2.0, -0.5};
        lc_lcp_solve(2, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "n=2 wrong guess: status %d exact %d", r.status, r.exact);
        CHECK_NEAR(f[0], 1.0, tol, "n=2 wrong guess f0");
        CHECK_NEAR(f[1], 0.0, tol, "n=2 wrong guess f1");
        CHECK_NEAR(a[1], 0.5, tol, "n=2 wrong guess a1");
    }
    { /* diagonal: f_i = max(0, -b_i / A_ii) */
        double A[16] = {1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 3, 0, 0, 0, 0, 4};
        double b[4] = {-1.0, 2.0, -6.0, 0.0};
        double fe[4] = {1.0, 0.0, 2.0, 0.0}, ae[4] = {0.0, 2.0, 0.0, 0.0};
        int i;
        lc_lcp_solve(4, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "diagonal: status %d exact %d", r.status, r.exact);
        for (i = 0; i < 4; ++i) {
            CHECK_NEAR(f[i], fe[i], tol, "diagonal f");
            CHECK_NEAR(a[i], ae[i], tol, "diagonal a");
        }
    }
    { /* box (m = 2 kg, 1 m x 0.5 m) resting on its two bottom corners on a static floor:
       * J rows (0, 1, -w/2), (0, 1, w/2); b = J M^-1 F_gravity = (-g, -g); f = m g / 2 each. */
        double m = 2.0, w = 1.0, h = 0.5, I = m * (w * w + h * h) / 12.0;
        double J[6] = {0.0, 1.0, -w / 2, 0.0, 1.0, w / 2}, Wd[3] = {1 / m, 1 / m, 1 / I};
        double A[4], b[2] = {-G, -G};
        jwjt(2, 3, J, Wd, A);
        lc_lcp_solve(2, A, b, f, a, &o, ws, &r);
        CHECK(r.status == 0 && r.exact == 1, "box on two corners: status %d exact %d", r.status, r.exact);
        /* forces of ~10 N from data of size ~10: 1e-13 N is rounding level */
        CHECK_NEAR(f[0], m * G / 2, 1e-13, "box corner 1 force [N]");
        CHECK_NEAR(f[1], m * G / 2, 1e-13, "box corner 2 force [N]");
        CHECK(r.residual < 1e-14, "box residual %g", r.residual);
        CHECK(r.iterations <= 2, "box: the {b<0} guess is right, expected <= 2 pivots, got %d", r.iterations);
    }
    { /* the same box solved by the iterative method gives the same forces (tolerance: the residual
       * target 1e-12 * g times ||A^-1|| ~ 1 / (2/m) -> ~1e-11 N) */
        double m = 2.0, w = 1.0, h = 0.5, I = m * (w * w + h * h) / 12.0;
        double J[6] = {0.0, 1.0, -w / 2, 0.0, 1.0, w / 2}, Wd[3] = {1 / m, 1 / m, 1 / I};
        double A[4], b[2] = {-G, -G};
        lc_lcp_options oi = opts(-1, 10000, 1e-12);
        jwjt(2, 3, J, Wd, A);
        lc_lcp_solve(2, A, b, f, a, &oi, ws, &r);
        CHECK(r.status == 0 && r.exact == 0, "box PGS: status %d exact %d", r.status, r.exact);
        CHECK_NEAR(f[0], m * G / 2, 1e-10, "box PGS corner 1 force [N]");
        CHECK_NEAR(f[1], m * G / 2, 1e-10, "box PGS corner 2 force [N]");
    }
    { /* exact_max boundary: n == exact_max -> exact, n == exact_max + 1 -> iterative; a temporary
       * workspace (ws = NULL) gives bit-identical forces to the reused one */
        double A[4] = {2.0, 1.0, 1.0, 2.0}, b[2] = {-2.0, -0.5}, f2[2];
        lc_lcp_options ob = opts(2, 1000, 1e-12);
        lc_lcp_solve(2, A, b, f, a, &ob, ws, &r);
        CHECK(r.exact == 1 && r.pivots > 0 && r.sweeps == 0, "exact_max=2, n=2: exact %d", r.exact);
        lc_lcp_solve(2, A, b, f2, NULL, &ob, NULL, &r);
        CHECK(memcmp(f, f2, sizeof f2) == 0, "%s", "temporary workspace gives identical forces");
        ob.exact_max = 1;
        lc_lcp_solve(2, A, b, f, a, &ob, ws, &r);
        CHECK(r.exact == 0 && r.pivots == 0 && r.sweeps > 0 && r.status == 0, "exact_max=1, n=2: exact %d sweeps %d",
              r.exact, r.sweeps);
        CHECK_NEAR(f[0], 1.0, 1e-11, "exact_max=1 PGS f0 (residual 1e-12, ||A^-1|| ~ 1)");
    }
}

/* ---------------------------------------------------------------------------------------------
 * 2. random SPD, n = 1..60
 * ------------------------------------------------------------------------------------------- */
static void random_spd(lcg_t *g, int n, double *A, double *b)
{
    double *B = (double *)malloc((size_t)n * (size_t)n * sizeof(double));
    int i, j, k;
    for (i = 0; i < n * n; ++i) B[i] = lcg_range(g, -1.0, 1.0);
    /* A = B B^T / n + 0.05 I: eigenvalues in [0.05, ~4.05], condition <= ~100 */
    for (i = 0; i < n; ++i)
        for (j = 0; j <= i; ++j) {
            double s = 0.0;
            for (k = 0; k < n; ++k) s += B[i * n + k] * B[j * n + k];
            s /= n;
            if (i == j) s += 0.05;
            A[i * n + j] = s;
            A[j * n + i] = s;
        }
    for (i = 0; i < n; ++i) b[i] = lcg_range(g, -1.0, 1.0);
    free(B);
}

static void test_random_spd(lc_lcp_workspace *ws)
{
    lcg_t g = {12345u};
    lc_lcp_options o = lc_lcp_default_options();
    int n, worst_n = 0, max_piv = 0, all_exact = 1, all_ok = 1;
    double worst = 0.0;
    double *A = (double *)malloc(60 * 60 * sizeof(double)), *b = (double *)malloc(60 * sizeof(double));
    double *f = (double *)malloc(60 * sizeof(double)), *f2 = (double *)malloc(60 * sizeof(double));
    double *a = (double *)malloc(60 * sizeof(double));
    for (n = 1; n <= 60; ++n) {
        lc_lcp_result r;
        double fmin, ri;
        random_spd(&g, n, A, b);
        lc_lcp_solve(n, A, b, f, a, &o, ws, &r);
        ri = indep_residual(n, A, b, f, &fmin);
        /* cond(A) <= ~100 and |b| <= 1: the exact method is accurate to ~1e-14; 1e-10 as required */
        if (!CHECK(ri < 1e-10 && fmin >= 0.0, "n=%d residual %g fmin %g", n, ri, fmin)) all_ok = 0;
        if (!CHECK(r.status == 0 && r.exact == 1 && r.fallback == 0, "n=%d status %d exact %d fallback %d", n,
                   r.status, r.exact, r.fallback))
            all_exact = 0;
        /* the reported residual is the same measure */
        CHECK(fabs(r.residual - ri) <= 1e-15 + 1e-12 * ri, "n=%d reported residual %g vs %g", n, r.residual, ri);
        if (ri > worst) {
            worst = ri;
            worst_n = n;
        }
        if (r.pivots > max_piv) max_piv = r.pivots;
        /* deterministic: the same call again gives bit-identical forces */
        lc_lcp_solve(n, A, b, f2, NULL, &o, ws, &r);
        CHECK(memcmp(f, f2, (size_t)n * sizeof(double)) == 0, "n=%d not deterministic", n);
    }
    printf("random SPD n=1..60: worst residual %.3e (n=%d), max pivots %d, all exact %d, all ok %d\n", worst,
           worst_n, max_piv, all_exact, all_ok);
    free(A);
    free(b);
    free(f);
    free(f2);
    free(a);
}

/* ---------------------------------------------------------------------------------------------
 * 3. singular PSD problems
 * ------------------------------------------------------------------------------------------- */
/* Box (1 m x 1 m, 1 kg) wedged between a floor and two walls: contacts at both bottom corners
 * (normal +y), left wall at (-w/2, y1) (normal +x), right wall at (w/2, y2) (normal -x).
 * 4 rows on 3 DOF -> A is 4x4 of rank 3. */
static void test_wedged_box(lc_lcp_workspace *ws)
{
    const double m = 1.0, w = 1.0, h = 1.0, I = m * (w * w + h * h) / 12.0, y1 = 0.2, y2 = -0.1;
    const double c[2] = {0.0, 0.0};
    double J[12], Wd[3] = {1 / m, 1 / m, 1 / I}, A[16], b[4], f[4], a[4], JTf[3];
    double p[4][2] = {{-w / 2, -h / 2}, {w / 2, -h / 2}, {-w / 2, y1}, {w / 2, y2}};
    double nr[4][2] = {{0, 1}, {0, 1}, {1, 0}, {-1, 0}};
    int i, k, cas;
    lc_lcp_options o = lc_lcp_default_options();
    for (i = 0; i < 4; ++i) contact_row(J + 3 * i, 3, 0, c, -1, c, p[i], nr[i]);
    jwjt(4, 3, J, Wd, A);
    symmetrize(4, A);
    for (cas = 0; cas < 2; ++cas) {
        /* case 0: gravity only; case 1: plus a push F = 2 N to the right at the centre of mass */
        double F = cas == 0 ? 0.0 : 2.0, ext[3], fmin, ri, bound;
        lc_lcp_result r;
        ext[0] = F / m;
        ext[1] = -G;
        ext[2] = 0.0;
        for (i = 0; i < 4; ++i) b[i] = J[3 * i] * ext[0] + J[3 * i + 1] * ext[1] + J[3 * i + 2] * ext[2];
        lc_lcp_solve(4, A, b, f, a, &o, ws, &r);
        ri = indep_residual(4, A, b, f, &fmin);
        CHECK(r.status == 0, "wedged case %d status %d (residual %g)", cas, r.status, r.residual);
        CHECK(ri < 1e-8 && fmin >= 0.0, "wedged case %d residual %g fmin %g", cas, ri, fmin);
        /* The solution is not unique (null vector (-0.3, 0.3, 1, 1)), but J^T f is: the box is in
         * equilibrium, so J^T f = -(F, -m g, 0) exactly. Tolerance 1e-9 N: rounding on 10 N data. */
        for (k = 0; k < 3; ++k) {
            JTf[k] = 0.0;
            for (i = 0; i < 4; ++i) JTf[k] += J[3 * i + k] * f[i];
        }
        CHECK_NEAR(JTf[0], -F, 1e-9, "wedged: net contact force x [N]");
        CHECK_NEAR(JTf[1], m * G, 1e-9, "wedged: net contact force y [N]");
        CHECK_NEAR(JTf[2], 0.0, 1e-9, "wedged: net contact torque [N m]");
        /* Bound: every member of the solution set has f_i <= m g * max(1, w / (2 |y1 - y2|)) + F
         * (walls share the squeeze along the null vector, floor corners at most m g + torque share). */
        bound = m * G * (w / (2 * fabs(y1 - y2)) > 1.0 ? w / (2 * fabs(y1 - y2)) : 1.0) + F;
        for (i = 0; i < 4; ++i) CHECK(f[i] <= bound, "wedged case %d f[%d] = %g > bound %g", cas, i, f[i], bound);
        printf("wedged box case %d: f = (%.6f, %.6f, %.6f, %.6f) N, pivots %d, residual %.2e, exact %d\n", cas,
               f[0], f[1], f[2], f[3], r.pivots, r.residual, r.exact);
    }
    { /* the same singular problem by PGS: J^T f converges (f itself need not match) */
        lc_lcp_options oi = opts(-1, 100000, 1e-11);
        lc_lcp_result r;
        for (i = 0; i < 4; ++i) b[i] = J[3 * i + 1] * -G;
        lc_lcp_solve(4, A, b, f, a, &oi, ws, &r);
        CHECK(r.status == 0 && r.exact == 0, "wedged PGS status %d exact %d sweeps %d", r.status, r.exact, r.sweeps);
        for (k = 0; k < 3; ++k) {
            JTf[k] = 0.0;
            for (i = 0; i < 4; ++i) JTf[k] += J[3 * i + k] * f[i];
        }
        /* residual 1e-11 * g on accelerations, ||M|| ~ 1 -> net force error ~1e-9 N; allow 1e-8 */
        CHECK_NEAR(JTf[1], m * G, 1e-8, "wedged PGS: net contact force y [N]");
        CHECK_NEAR(JTf[2], 0.0, 1e-8, "wedged PGS: net contact torque [N m]");
    }
    (void)o;
}

/* Box on the floor with duplicated contact points (two contacts per corner): rows repeat. */
static void test_duplicate_contacts(lc_lcp_workspace *ws)
{
    const double m = 3.0, w = 2.0, h = 1.0, I = m * (w * w + h * h) / 12.0;
    const double c[2] = {0.0, 0.0}, up[2] = {0.0, 1.0};
    double p[4][2] = {{-w / 2, -h / 2}, {w / 2, -h / 2}, {-w / 2, -h / 2}, {w / 2, -h / 2}};
    double J[12], Wd[3] = {1 / m, 1 / m, 1 / I}, A[16], b[4], f[4], a[4], fmin, ri;
    int i;
    lc_lcp_options o = lc_lcp_default_options();
    lc_lcp_result r;
    for (i = 0; i < 4; ++i) {
        contact_row(J + 3 * i, 3, 0, c, -1, c, p[i], up);
        b[i] = -G;
    }
    jwjt(4, 3, J, Wd, A);
    lc_lcp_solve(4, A, b, f, a, &o, ws, &r);
    ri = indep_residual(4, A, b, f, &fmin);
    CHECK(r.status == 0 && r.exact == 1, "duplicates: status %d exact %d", r.status, r.exact);
    CHECK(ri < 1e-10 && fmin >= 0.0, "duplicates: residual %g fmin %g", ri, fmin);
    /* per corner the pair carries m g / 2 (rounding on ~15 N: 1e-12 N) */
    CHECK_NEAR(f[0] + f[2], m * G / 2, 1e-12, "duplicates: left corner pair [N]");
    CHECK_NEAR(f[1] + f[3], m * G / 2, 1e-12, "duplicates: right corner pair [N]");
    /* a basic solution: no force larger than the corner's total */
    for (i = 0; i < 4; ++i) CHECK(f[i] <= m * G / 2 + 1e-12, "duplicates: f[%d] = %g", i, f[i]);
}

/* Random rank-deficient A = J W J^T with m = 2d rows on d columns and a known solution f*. */
static void test_random_singular(lc_lcp_workspace *ws)
{
    lcg_t g = {987654321u};
    int trial, worst_piv = 0;
    double worst_res = 0.0, worst_ratio = 0.0;
    lc_lcp_options o = lc_lcp_default_options();
    for (trial = 0; trial < 40; ++trial) {
        int d = 2 + trial % 19, m = 2 * d + trial % 3, i, k;
        double *J = (double *)malloc((size_t)m * d * sizeof(double)), *Wd = (double *)malloc((size_t)d * sizeof(double));
        double *A = (double *)malloc((size_t)m * m * sizeof(double)), *b = (double *)malloc((size_t)m * sizeof(double));
        double *fs = (double *)malloc((size_t)m * sizeof(double)), *as = (double *)malloc((size_t)m * sizeof(double));
        double *f = (double *)malloc((size_t)m * sizeof(double)), *a = (double *)malloc((size_t)m * sizeof(double));
        double fmin, ri, jerr = 0.0, jscale = 0.0, fsmax = 0.0, fmax = 0.0;
        lc_lcp_result r;
        for (i = 0; i < m * d; ++i) J[i] = lcg_range(&g, -1.0, 1.0);
        for (k = 0; k < d; ++k) Wd[k] = lcg_range(&g, 0.5, 1.5);
        jwjt(m, d, J, Wd, A);
        symmetrize(m, A);
        for (i = 0; i < m; ++i) {
            double u = lcg_uniform(&g);
            if (u < 0.45) { /* active */
                fs[i] = lcg_range(&g, 0.1, 1.0);
                as[i] = 0.0;
            } else if (u < 0.9) { /* separating */
                fs[i] = 0.0;
                as[i] = lcg_range(&g, 0.1, 1.0);
            } else { /* degenerate: both zero */
                fs[i] = 0.0;
                as[i] = 0.0;
            }
        }
        matvec_plus(m, A, fs, NULL, b);
        for (i = 0; i < m; ++i) b[i] = as[i] - b[i];
        lc_lcp_solve(m, A, b, f, a, &o, ws, &r);
        ri = indep_residual(m, A, b, f, &fmin);
        CHECK(r.status == 0, "singular trial %d (m=%d d=%d): status %d residual %g exact %d", trial, m, d, r.status,
              r.residual, r.exact);
        CHECK(ri < 1e-8 && fmin >= 0.0, "singular trial %d: residual %g fmin %g", trial, ri, fmin);
        /* J^T f is unique (J has full column rank) and equals J^T f*; scale |J| |f*| ~ 1 */
        for (k = 0; k < d; ++k) {
            double s = 0.0, s0 = 0.0;
            for (i = 0; i < m; ++i) {
                s += J[i * d + k] * f[i];
                s0 += J[i * d + k] * fs[i];
            }
            if (fabs(s - s0) > jerr) jerr = fabs(s - s0);
            if (fabs(s0) > jscale) jscale = fabs(s0);
        }
        CHECK(jerr <= 1e-8 * (1.0 + jscale), "singular trial %d: |J^T f - J^T f*| = %g", trial, jerr);
        for (i = 0; i < m; ++i) {
            if (fs[i] > fsmax) fsmax = fs[i];
            if (f[i] > fmax) fmax = f[i];
        }
        /* Bounded: the answer is a basic solution, not a regularisation blow-up (which would be
         * ~1/1e-12). The bound 1e3 * max f* (f* <= 1) is far below that and far above what the
         * trials give (printed below). */
        CHECK(fmax <= 1e3 * (fsmax > 0.1 ? fsmax : 0.1), "singular trial %d: max f %g (max f* %g)", trial, fmax, fsmax);
        if (ri > worst_res) worst_res = ri;
        if (fmax / (fsmax > 0.1 ? fsmax : 0.1) > worst_ratio) worst_ratio = fmax / (fsmax > 0.1 ? fsmax : 0.1);
        if (r.pivots > worst_piv) worst_piv = r.pivots;
        free(J);
        free(Wd);
        free(A);
        free(b);
        free(fs);
        free(as);
        free(f);
        free(a);
    }
    printf("random singular J W J^T (40 trials, m=2d..2d+2, d=2..20): worst residual %.3e, max f / max f* %.2f, "
           "max pivots %d\n",
           worst_res, worst_ratio, worst_piv);
    (void)o;
}

/* A 3 x 4 grid of 1 m boxes (1 kg) packed exactly between two walls on a floor: floor, wall,
 * box-on-box and side-by-side contacts at both ends of every shared edge: 56 contacts on 36 DOF,
 * with self-stress states (a row of boxes squeezed between the walls: J^T y = 0 with y >= 0), so
 * the solution set is unbounded. Case 0: gravity. Case 1: plus a 3 N push to the right on the
 * middle box of row 1. Every box is fully held, so a = 0 and, per box, J^T f = -F_external. */
#define GC 3
#define GR 4
#define GB (GC * GR)
#define GN (2 * GC + 2 * GC * (GR - 1) + 2 * (GC - 1) * GR + 4 * GR)
static void test_packed_grid(lc_lcp_workspace *ws)
{
    const double m = 1.0, s = 1.0, I = m * (s * s + s * s) / 12.0;
    const int d = 3 * GB;
    static double J[GN * 3 * GB], A[GN * GN];
    double Wd[3 * GB], ext[3 * GB], b[GN], f[GN], a[GN], wrench[3 * GB];
    const double up[2] = {0.0, 1.0}, right[2] = {1.0, 0.0}, left[2] = {-1.0, 0.0};
    int row = 0, c, r, k, i, cas;
    double cen[GB][2];
    for (r = 0; r < GR; ++r)
        for (c = 0; c < GC; ++c) {
            k = r * GC + c;
            cen[k][0] = c * s + s / 2;
            cen[k][1] = r * s + s / 2;
            Wd[3 * k] = Wd[3 * k + 1] = 1 / m;
            Wd[3 * k + 2] = 1 / I;
        }
    for (r = 0; r < GR; ++r)
        for (c = 0; c < GC; ++c) {
            int e;
            k = r * GC + c;
            for (e = 0; e < 2; ++e) {
                double pb[2] = {c * s + e * s, r * s};  /* bottom edge ends */
                double pl[2] = {c * s, r * s + e * s};  /* left edge ends */
                double pr[2] = {c * s + s, r * s + e * s};
                /* below: floor or box (r-1, c) */
                contact_row(J + (row++) * d, d, 3 * k, cen[k], r == 0 ? -1 : 3 * (k - GC), r == 0 ? cen[k] : cen[k - GC], pb, up);
                /* left: wall (x = 0) or box (r, c-1), normal +x from the left body to this one */
                contact_row(J + (row++) * d, d, 3 * k, cen[k], c == 0 ? -1 : 3 * (k - 1), c == 0 ? cen[k] : cen[k - 1], pl, right);
                /* right wall (x = GC s), normal -x from the wall to the box */
                if (c == GC - 1) contact_row(J + (row++) * d, d, 3 * k, cen[k], -1, cen[k], pr, left);
            }
        }
    CHECK(row == GN, "grid rows %d vs %d", row, GN);
    jwjt(GN, d, J, Wd, A);
    symmetrize(GN, A);
    for (cas = 0; cas < 2; ++cas) {
        int method;
        for (k = 0; k < GB; ++k) {
            ext[3 * k] = (cas == 1 && k == 1 * GC + 1) ? 3.0 / m : 0.0;
            ext[3 * k + 1] = -G;
            ext[3 * k + 2] = 0.0;
        }
        for (i = 0; i < GN; ++i) {
            double sum = 0.0;
            for (k = 0; k < d; ++k) sum += J[i * d + k] * ext[k];
            b[i] = sum;
        }
        for (method = 0; method < 2; ++method) {
            lc_lcp_options o = method == 0 ? lc_lcp_default_options() : opts(-1, 100000, 1e-11);
            lc_lcp_result res;
            double fmin, ri, werr = 0.0, fmax = 0.0, amax = 0.0;
            lc_lcp_solve(GN, A, b, f, a, &o, ws, &res);
            ri = indep_residual(GN, A, b, f, &fmin);
            CHECK(res.status == 0 && res.exact == (method == 0), "grid case %d method %d: status %d exact %d residual %g",
                  cas, method, res.status, res.exact, res.residual);
            CHECK(ri < 1e-8 && fmin >= 0.0, "grid case %d method %d: residual %g fmin %g", cas, method, ri, fmin);
            for (k = 0; k < d; ++k) {
                double sum = 0.0;
                for (i = 0; i < GN; ++i) sum += J[i * d + k] * f[i];
                wrench[k] = sum;
                /* per box: contact wrench = -(M ext); M = diag(m, m, I) */
                sum += (k % 3 == 2 ? I : m) * ext[k];
                if (fabs(sum) > werr) werr = fabs(sum);
            }
            for (i = 0; i < GN; ++i) {
                if (f[i] > fmax) fmax = f[i];
                if (fabs(a[i]) > amax) amax = fabs(a[i]);
            }
            /* exact: rounding on ~40 N data -> 1e-9 N. PGS: residual 1e-11 * g on accelerations
             * times ||M|| ~ 1 per box, accumulated through 4 rows -> allow 1e-8 N */
            CHECK(werr < (method == 0 ? 1e-9 : 1e-8), "grid case %d method %d: per-box wrench error %g N", cas, method, werr);
            CHECK(amax < (method == 0 ? 1e-9 : 1e-8), "grid case %d method %d: max |a| %g (all boxes held)", cas, method, amax);
            /* Bounded although the solution set is not: the basic solution adds no self-stress, so no
             * contact carries more than the whole column's weight plus the push. */
            CHECK(fmax <= GR * m * G + 3.0, "grid case %d method %d: max force %g N", cas, method, fmax);
            printf("packed grid case %d %s: pivots %d sweeps %d residual %.2e, max f %.4f N, wrench error %.1e N\n", cas,
                   method == 0 ? "exact" : "PGS  ", res.pivots, res.sweeps, res.residual, fmax, werr);
        }
    }
    (void)wrench;
}

/* An infeasible problem (f1 - f2 >= 1 and f2 - f1 >= 1): the exact method finds no blocking pivot,
 * falls back, PGS hits its cap: status 1, finite f >= 0, residual reported. */
static void test_infeasible(lc_lcp_workspace *ws)
{
    double A[4] = {1.0, -1.0, -1.0, 1.0}, b[2] = {-1.0, -1.0}, f[2], a[2];
    lc_lcp_options o = opts(8, 50, 1e-10);
    lc_lcp_result r;
    lc_lcp_solve(2, A, b, f, a, &o, ws, &r);
    CHECK(r.status == 1, "infeasible: status %d", r.status);
    CHECK(r.fallback == 1 && r.sweeps == 50, "infeasible: fallback %d sweeps %d", r.fallback, r.sweeps);
    /* the work counted (lc_counters.solver_work) includes the fallback's sweeps, whichever answer is
     * kept: counting the pivots alone, fuzz/corpus/step-regressions/
     * slow-solver-work-fallback-sweeps-coincident-polygons ran 27 s within the solver-work cap */
    CHECK(lc_lcp_work(2, &r) == (uint64_t)(2 + r.pivots + 50) * 4u, "infeasible: work %llu for %d pivots and 50 sweeps",
          (unsigned long long)lc_lcp_work(2, &r), r.pivots);
    CHECK(isfinite(f[0]) && isfinite(f[1]) && f[0] >= 0.0 && f[1] >= 0.0, "infeasible: f = (%g, %g)", f[0], f[1]);
    CHECK(r.residual > 0.5, "infeasible: residual %g should show the violation (a1 + a2 = -2)", r.residual);
    { /* zero row with b < 0 */
        double Z[1] = {0.0}, bz[1] = {-1.0};
        lc_lcp_solve(1, Z, bz, f, a, &o, ws, &r);
        CHECK(r.status == 1 && f[0] == 0.0 && a[0] == -1.0, "zero row: status %d f %g a %g", r.status, f[0], a[0]);
    }
    { /* zero matrix and b >= 0: trivially solved */
        double Z[4] = {0.0, 0.0, 0.0, 0.0}, bz[2] = {0.0, 1.0};
        lc_lcp_solve(2, Z, bz, f, a, &o, ws, &r);
        CHECK(r.status == 0 && f[0] == 0.0 && f[1] == 0.0, "zero matrix: status %d", r.status);
    }
}

/* ---------------------------------------------------------------------------------------------
 * 4. ten-box stack: exact vs closed form vs PGS
 * ------------------------------------------------------------------------------------------- */
#define NBOX 10
#define NSTACK (2 * NBOX)
static void build_stack(double *A, double *b, double *fexp)
{
    const double m = 1.0, w = 1.0, h = 1.0, I = m * (w * w + h * h) / 12.0;
    const double up[2] = {0.0, 1.0};
    const int d = 3 * NBOX;
    double J[NSTACK * 3 * NBOX], Wd[3 * NBOX], ext[3 * NBOX];
    int k, s, i, j;
    for (k = 0; k < NBOX; ++k) {
        Wd[3 * k] = 1 / m;
        Wd[3 * k + 1] = 1 / m;
        Wd[3 * k + 2] = 1 / I;
        ext[3 * k] = 0.0;
        ext[3 * k + 1] = -G; /* M^-1 F_gravity */
        ext[3 * k + 2] = 0.0;
    }
    for (k = 0; k < NBOX; ++k) { /* contacts under box k: between box k-1 (or the floor) and box k */
        double cU[2] = {0.0, k * h + h / 2}, cL[2] = {0.0, (k - 1) * h + h / 2};
        for (s = 0; s < 2; ++s) {
            double p[2] = {s == 0 ? -w / 2 : w / 2, k * h};
            int row = 2 * k + s;
            contact_row(J + row * d, d, 3 * k, cU, k == 0 ? -1 : 3 * (k - 1), cL, p, up);
            /* box k carries the NBOX - k boxes above the contact: (NBOX - k) m g / 2 per corner */
            fexp[row] = (NBOX - k) * m * G / 2;
        }
    }
    jwjt(NSTACK, d, J, Wd, A);
    symmetrize(NSTACK, A);
    for (i = 0; i < NSTACK; ++i) {
        double sum = 0.0;
        for (j = 0; j < d; ++j) sum += J[i * d + j] * ext[j];
        b[i] = sum;
    }
}

static void test_stack(lc_lcp_workspace *ws)
{
    double A[NSTACK * NSTACK], b[NSTACK], fexp[NSTACK], fx[NSTACK], fi[NSTACK], a[NSTACK], fmin;
    lc_lcp_result r;
    lc_lcp_options oe = lc_lcp_default_options();
    lc_lcp_options oi = opts(-1, 200000, 1e-12);
    double err;
    build_stack(A, b, fexp);

    lc_lcp_solve(NSTACK, A, b, fx, a, &oe, ws, &r);
    CHECK(r.status == 0 && r.exact == 1, "stack exact: status %d exact %d", r.status, r.exact);
    /* forces up to 49 N; cond(A) = lambda_max / lambda_min < 1e3: 1e-10 N is rounding level */
    err = max_abs_diff(NSTACK, fx, fexp);
    CHECK(err < 1e-10, "stack exact vs closed form: max |f - m g (N-k)/2| = %g N", err);
    printf("stack exact: pivots %d residual %.2e, max force error %.2e N\n", r.pivots, r.residual, err);

    lc_lcp_solve(NSTACK, A, b, fi, a, &oi, ws, &r);
    CHECK(r.status == 0 && r.exact == 0, "stack PGS: status %d exact %d sweeps %d residual %g", r.status, r.exact,
          r.sweeps, r.residual);
    CHECK(r.iterations == r.sweeps && r.sweeps > 0, "stack PGS: iterations %d sweeps %d", r.iterations, r.sweeps);
    CHECK(indep_residual(NSTACK, A, b, fi, &fmin) <= 1e-12 && fmin >= 0.0, "stack PGS residual / sign");
    /* All 20 contacts are active, so A (f - f_exact) = a and |a_i| <= 1e-12 g (the residual).
     * ||f - f_exact||_inf <= sqrt(n) ||A^-1||_2 ||a||_inf with ||A^-1||_2 = 1/lambda_min(A) = 22.4
     * for this stack (inverse iteration): <= 4.5 * 22.4 * 1e-12 * 9.81 = 1e-9 N; allow 2e-9 N. */
    err = max_abs_diff(NSTACK, fi, fx);
    CHECK(err < 2e-9, "stack PGS vs exact: max force difference %g N", err);
    printf("stack PGS: sweeps %d residual %.2e, max force difference to exact %.2e N\n", r.sweeps, r.residual, err);

    /* the cap is honoured: 7 sweeps, status 1, best answer (f >= 0) and its true residual */
    oi.max_iterations = 7;
    lc_lcp_solve(NSTACK, A, b, fi, a, &oi, ws, &r);
    CHECK(r.status == 1 && r.sweeps == 7 && r.iterations == 7, "stack cap: status %d sweeps %d", r.status, r.sweeps);
    CHECK(r.residual > oi.tolerance, "stack cap: residual %g should be above tolerance", r.residual);
    CHECK_NEAR(r.residual, indep_residual(NSTACK, A, b, fi, &fmin), 1e-15, "stack cap: reported residual");
    CHECK(fmin >= 0.0, "stack cap: f >= 0 (min %g)", fmin);

    /* SOR w = 1.5 also converges to the same forces */
    oi.max_iterations = 200000;
    oi.relaxation = 1.5;
    lc_lcp_solve(NSTACK, A, b, fi, a, &oi, ws, &r);
    err = max_abs_diff(NSTACK, fi, fx);
    CHECK(r.status == 0 && err < 2e-9, "stack SOR 1.5: status %d error %g N (bound as above)", r.status, err);
    printf("stack SOR w=1.5: sweeps %d residual %.2e\n", r.sweeps, r.residual);

    /* warm start from the exact answer: converged immediately (0 sweeps) */
    oi.relaxation = 0.0;
    oi.warm_start = 1;
    memcpy(fi, fx, sizeof fi);
    lc_lcp_solve(NSTACK, A, b, fi, a, &oi, ws, &r);
    CHECK(r.status == 0 && r.sweeps <= 1, "stack warm start: status %d sweeps %d", r.status, r.sweeps);

    /* the exact method warm-started from its own answer: the block solve alone (1 pivot, where the
     * start from {b < 0} pivoted more) and the same forces to rounding (1e-10 N as above); from a
     * wrong guess (every row active but the first, so a row must come back in) the same forces too */
    {
        lc_lcp_options ow = lc_lcp_default_options();
        int cold;
        int k;
        lc_lcp_solve(NSTACK, A, b, fi, a, &oe, ws, &r);
        cold = r.pivots;
        ow.warm_start = 1;
        memcpy(fi, fx, sizeof fi);
        lc_lcp_solve(NSTACK, A, b, fi, a, &ow, ws, &r);
        err = max_abs_diff(NSTACK, fi, fexp);
        CHECK(r.status == 0 && r.exact == 1 && r.pivots == 1 && cold > 1,
              "stack exact warm: status %d pivots %d (cold %d)", r.status, r.pivots, cold);
        CHECK(err < 1e-10, "stack exact warm vs closed form: %g N", err);
        for (k = 0; k < NSTACK; ++k) fi[k] = k == 0 ? 0.0 : 1.0 + k;
        lc_lcp_solve(NSTACK, A, b, fi, a, &ow, ws, &r);
        err = max_abs_diff(NSTACK, fi, fexp);
        CHECK(r.status == 0 && r.exact == 1 && err < 1e-10, "stack exact from a wrong guess: status %d error %g N",
              r.status, err);
    }
}

/* ---------------------------------------------------------------------------------------------
 * 5. boxed solver: box on a slope with friction
 * ------------------------------------------------------------------------------------------- */
static void test_slope(lc_lcp_workspace *ws)
{
    /* Slope frame: x along the slope (downhill = -x), y normal. Box m = 2 kg, 1 m x 0.5 m, two bottom
     * corners in contact. Rows 0,1: normals; rows 2,3: friction at corners 0,1 (tangent +x). */
    const double m = 2.0, w = 1.0, h = 0.5, I = m * (w * w + h * h) / 12.0, th = 30.0 * 3.14159265358979323846 / 180.0;
    const double c[2] = {0.0, 0.0}, nx[2] = {0.0, 1.0}, tx[2] = {1.0, 0.0};
    double p[2][2] = {{-w / 2, -h / 2}, {w / 2, -h / 2}};
    double J[12], Wd[3] = {1 / m, 1 / m, 1 / I}, A[16], b[4], f[4], a[4];
    double ext[3] = {-G * sin(th), -G * cos(th), 0.0};
    int coupled[4] = {-1, -1, 0, 1};
    int i, cas;
    lc_lcp_options o = opts(0, 100000, 1e-12);
    contact_row(J + 0, 3, 0, c, -1, c, p[0], nx);
    contact_row(J + 3, 3, 0, c, -1, c, p[1], nx);
    contact_row(J + 6, 3, 0, c, -1, c, p[0], tx);
    contact_row(J + 9, 3, 0, c, -1, c, p[1], tx);
    jwjt(4, 3, J, Wd, A); /* rows 2 and 3 are identical: A is singular */
    symmetrize(4, A);
    for (i = 0; i < 4; ++i) b[i] = J[3 * i] * ext[0] + J[3 * i + 1] * ext[1] + J[3 * i + 2] * ext[2];
    for (cas = 0; cas < 2; ++cas) {
        /* tan 30 deg = 0.577: mu = 0.8 sticks, mu = 0.3 slides */
        double muv = cas == 0 ? 0.8 : 0.3, mu[4], N, T;
        lc_lcp_result r;
        mu[0] = mu[1] = 0.0;
        mu[2] = mu[3] = muv;
        lc_lcp_solve_boxed(4, A, b, NULL, NULL, coupled, mu, f, a, &o, ws, &r);
        N = f[0] + f[1];
        T = f[2] + f[3];
        CHECK(r.status == 0 && r.exact == 0, "slope mu=%g: status %d sweeps %d residual %g", muv, r.status, r.sweeps,
              r.residual);
        /* residual 1e-12 * g on accelerations, ||A^-1|| on the non-singular part ~ m: ~1e-10 N;
         * allow 1e-8 N */
        CHECK_NEAR(N, m * G * cos(th), 1e-8, "slope: total normal force m g cos [N]");
        CHECK(f[0] >= 0.0 && f[1] >= 0.0, "slope: normal forces >= 0 (%g, %g)", f[0], f[1]);
        for (i = 2; i < 4; ++i)
            CHECK(fabs(f[i]) <= muv * f[i - 2] + 1e-12, "slope: |friction %d| = %g > mu N = %g", i, f[i], muv * f[i - 2]);
        if (cas == 0) {
            CHECK_NEAR(T, m * G * sin(th), 1e-8, "slope stick: friction = m g sin [N]");
            for (i = 0; i < 4; ++i) CHECK_NEAR(a[i], 0.0, 1e-9, "slope stick: no acceleration at contacts [m/s^2]");
        } else {
            CHECK_NEAR(T, muv * m * G * cos(th), 1e-8, "slope slide: friction = mu N [N]");
            CHECK_NEAR(f[2], muv * f[0], 1e-10, "slope slide: corner 0 at the Coulomb bound [N]");
            CHECK_NEAR(f[3], muv * f[1], 1e-10, "slope slide: corner 1 at the Coulomb bound [N]");
            /* sliding acceleration along the slope: -g (sin - mu cos) */
            CHECK_NEAR(a[2], -G * (sin(th) - muv * cos(th)), 1e-9, "slope slide: tangential acceleration [m/s^2]");
            CHECK(a[2] < 0.0, "slope slide: friction at +bound needs a <= 0 (a = %g)", a[2]);
            /* friction below the centre of mass tilts the load to the downhill corner: N0 - N1 = T h / w */
            CHECK_NEAR(f[0] - f[1], T * h / w, 1e-8, "slope slide: normal force shift [N]");
        }
        printf("slope mu=%.1f: N = (%.6f, %.6f) T = (%.6f, %.6f) N, sweeps %d, residual %.2e\n", muv, f[0], f[1], f[2],
               f[3], r.sweeps, r.residual);
    }
    { /* plain boxes: hi bound active (f = 3, a = 2*3 - 10 = -4) and a free row (f = -b/A) */
        double A2[4] = {2.0, 0.0, 0.0, 4.0}, b2[2] = {-10.0, 6.0}, lo2[2] = {0.0, -HUGE_VAL}, hi2[2] = {3.0, HUGE_VAL};
        lc_lcp_result r;
        lc_lcp_solve_boxed(2, A2, b2, lo2, hi2, NULL, NULL, f, a, &o, ws, &r);
        CHECK(r.status == 0, "plain boxed: status %d", r.status);
        CHECK_NEAR(f[0], 3.0, 1e-14, "plain boxed: f at hi");
        CHECK_NEAR(a[0], -4.0, 1e-14, "plain boxed: a at hi");
        CHECK_NEAR(f[1], -1.5, 1e-14, "plain boxed: free row");
        CHECK_NEAR(a[1], 0.0, 1e-14, "plain boxed: free row a");
    }
}

/* ---------------------------------------------------------------------------------------------
 * 6. bad input
 * ------------------------------------------------------------------------------------------- */
static void fill(double *x, int n, double v)
{
    int i;
    for (i = 0; i < n; ++i) x[i] = v;
}

static void test_bad_input(lc_lcp_workspace *ws)
{
    double A[4] = {2.0, 1.0, 1.0, 2.0}, b[2] = {-1.0, -1.0}, f[2], a[2];
    lc_lcp_result r;
    lc_lcp_options o = lc_lcp_default_options();
    int st;

    /* n = 0: a valid empty problem, nothing touched, NULL arrays allowed */
    st = lc_lcp_solve(0, NULL, NULL, NULL, NULL, &o, ws, &r);
    CHECK(st == 0 && r.status == 0 && r.residual == 0.0, "n=0: status %d", st);
    st = lc_lcp_solve_boxed(0, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, &o, ws, &r);
    CHECK(st == 0, "boxed n=0: status %d", st);
    /* n < 0 */
    st = lc_lcp_solve(-1, A, b, f, a, &o, ws, &r);
    CHECK(st == 2 && r.status == 2, "n<0: status %d", st);
    /* NULL pointers */
    fill(f, 2, 7.0);
    st = lc_lcp_solve(2, NULL, b, f, a, &o, ws, &r);
    CHECK(st == 2 && f[0] == 0.0 && f[1] == 0.0, "A NULL: status %d f (%g, %g)", st, f[0], f[1]);
    st = lc_lcp_solve(2, A, NULL, f, a, &o, ws, &r);
    CHECK(st == 2, "b NULL: status %d", st);
    st = lc_lcp_solve(2, A, b, NULL, a, &o, ws, NULL);
    CHECK(st == 2, "f NULL: status %d", st);
    /* NaN in b: status 2, f and a zeroed */
    {
        double bn[2] = {-1.0, NAN};
        fill(f, 2, 7.0);
        fill(a, 2, 7.0);
        st = lc_lcp_solve(2, A, bn, f, a, &o, ws, &r);
        CHECK(st == 2 && r.status == 2, "NaN b: status %d", st);
        CHECK(f[0] == 0.0 && f[1] == 0.0 && a[0] == 0.0 && a[1] == 0.0, "NaN b: outputs zeroed");
        CHECK(isinf(r.residual), "NaN b: residual reported as inf (%g)", r.residual);
        st = lc_lcp_solve_boxed(2, A, bn, NULL, NULL, NULL, NULL, f, a, &o, ws, &r);
        CHECK(st == 2, "boxed NaN b: status %d", st);
    }
    /* infinite / NaN matrix entry, negative diagonal */
    {
        double Ai[4] = {2.0, INFINITY, INFINITY, 2.0}, An[4] = {2.0, 1.0, 1.0, NAN}, Ag[4] = {-2.0, 0.0, 0.0, 1.0};
        CHECK(lc_lcp_solve(2, Ai, b, f, a, &o, ws, &r) == 2, "inf in A");
        CHECK(lc_lcp_solve(2, An, b, f, a, &o, ws, &r) == 2, "NaN in A");
        CHECK(lc_lcp_solve(2, Ag, b, f, a, &o, ws, &r) == 2, "negative diagonal");
    }
    /* bad options */
    {
        lc_lcp_options ob = o;
        ob.tolerance = NAN;
        CHECK(lc_lcp_solve(2, A, b, f, a, &ob, ws, &r) == 2, "NaN tolerance");
        ob = o;
        ob.max_iterations = -1;
        CHECK(lc_lcp_solve(2, A, b, f, a, &ob, ws, &r) == 2, "negative max_iterations");
        ob = o;
        ob.relaxation = 2.5;
        CHECK(lc_lcp_solve(2, A, b, f, a, &ob, ws, &r) == 2, "relaxation 2.5");
    }
    /* boxed: lo > hi, NaN bound, bad coupling */
    {
        double lo[2] = {1.0, 0.0}, hi[2] = {0.0, 1.0}, lon[2] = {NAN, 0.0}, mu[2] = {0.0, 0.5};
        int c_self[2] = {-1, 1}, c_out[2] = {-1, 5}, c_ok[2] = {-1, 0}, c_chain[2] = {1, 0};
        CHECK(lc_lcp_solve_boxed(2, A, b, lo, hi, NULL, NULL, f, a, &o, ws, &r) == 2, "boxed lo > hi");
        CHECK(lc_lcp_solve_boxed(2, A, b, lon, NULL, NULL, NULL, f, a, &o, ws, &r) == 2, "boxed NaN lo");
        CHECK(lc_lcp_solve_boxed(2, A, b, NULL, NULL, c_self, mu, f, a, &o, ws, &r) == 2, "boxed self coupling");
        CHECK(lc_lcp_solve_boxed(2, A, b, NULL, NULL, c_out, mu, f, a, &o, ws, &r) == 2, "boxed coupling out of range");
        CHECK(lc_lcp_solve_boxed(2, A, b, NULL, NULL, c_ok, NULL, f, a, &o, ws, &r) == 2, "boxed coupling without mu");
        CHECK(lc_lcp_solve_boxed(2, A, b, NULL, NULL, c_chain, mu, f, a, &o, ws, &r) == 2, "boxed coupled chain");
        CHECK(lc_lcp_solve_boxed(2, A, b, NULL, NULL, c_ok, mu, f, a, &o, ws, &r) == 0, "boxed valid coupling solves");
    }
    /* NULL workspace, NULL options, NULL result, NULL a_out: works (temporary workspace) */
    st = lc_lcp_solve(2, A, b, f, NULL, NULL, NULL, NULL);
    /* f = -(A^-1) b = (1/3, 1/3) */
    CHECK(st == 0, "NULL ws/opt/res: status %d", st);
    CHECK_NEAR(f[0], 1.0 / 3.0, 1e-15, "NULL ws: f0");
    CHECK_NEAR(f[1], 1.0 / 3.0, 1e-15, "NULL ws: f1");
}

/* ---------------------------------------------------------------------------------------------
 * 7. measurements (printed, not asserted beyond sanity): exact vs iterative, n = 10, 50, 200
 * ------------------------------------------------------------------------------------------- */
static void measure(lc_lcp_workspace *ws)
{
    static const int sizes[3] = {10, 50, 200};
    lcg_t g = {2024u};
    int s;
    printf("measure (random SPD, cond <= ~100; contact-like rank-deficient J W J^T, m = n, d = n/2):\n");
    for (s = 0; s < 3; ++s) {
        int n = sizes[s], kind;
        double *A = (double *)malloc((size_t)n * n * sizeof(double)), *b = (double *)malloc((size_t)n * sizeof(double));
        double *f = (double *)malloc((size_t)n * sizeof(double)), *fe = (double *)malloc((size_t)n * sizeof(double));
        for (kind = 0; kind < 2; ++kind) {
            lc_lcp_options oe = opts(100000, 100000, 1e-10), oi = opts(-1, 20000, 1e-10);
            lc_lcp_result re, ri;
            clock_t t0, t1, t2;
            /* fixed repetition counts (enough for clock() resolution; the n = 200 rank-deficient PGS
             * case runs its whole 20000-sweep cap, about 0.2 s) */
            int reps_e = n == 10 ? 5000 : n == 50 ? 500 : 20, reps_i = n == 10 ? 500 : n == 50 ? 20 : 1, k;
            if (kind == 0) {
                random_spd(&g, n, A, b);
            } else {
                int d = n / 2, i;
                double *J = (double *)malloc((size_t)n * d * sizeof(double)), *Wd = (double *)malloc((size_t)d * sizeof(double));
                for (i = 0; i < n * d; ++i) J[i] = lcg_range(&g, -1.0, 1.0);
                for (i = 0; i < d; ++i) Wd[i] = lcg_range(&g, 0.5, 1.5);
                jwjt(n, d, J, Wd, A);
                symmetrize(n, A);
                /* b = J v with v random: b in the range of J (consistent like gravity) */
                for (i = 0; i < n; ++i) {
                    int k2;
                    b[i] = 0.0;
                    for (k2 = 0; k2 < d; ++k2) b[i] += J[i * d + k2] * ((k2 % 3) == 1 ? -1.0 : 0.3);
                }
                free(J);
                free(Wd);
            }
            t0 = clock();
            for (k = 0; k < reps_e; ++k) lc_lcp_solve(n, A, b, fe, NULL, &oe, ws, &re);
            t1 = clock();
            for (k = 0; k < reps_i; ++k) lc_lcp_solve(n, A, b, f, NULL, &oi, ws, &ri);
            t2 = clock();
            printf("  %-9s n=%3d exact: status %d exact %d pivots %4d residual %.1e time %9.4f ms | PGS: status %d "
                   "sweeps %6d residual %.1e time %9.4f ms\n",
                   kind == 0 ? "SPD" : "singular", n, re.status, re.exact, re.pivots, re.residual,
                   1e3 * (double)(t1 - t0) / CLOCKS_PER_SEC / reps_e, ri.status, ri.sweeps, ri.residual,
                   1e3 * (double)(t2 - t1) / CLOCKS_PER_SEC / reps_i);
            /* sanity: both answers respect f >= 0 and the exact one is accurate */
            {
                double fmin1, fmin2;
                double r1 = indep_residual(n, A, b, fe, &fmin1);
                (void)indep_residual(n, A, b, f, &fmin2);
                CHECK(r1 < 1e-8 && fmin1 >= 0.0 && fmin2 >= 0.0, "measure n=%d kind %d: exact residual %g", n, kind, r1);
            }
        }
        free(A);
        free(b);
        free(f);
        free(fe);
    }
}

int main(void)
{
    lc_lcp_workspace *ws = lc_lcp_workspace_create();
    CHECK(ws != NULL, "%s", "workspace");
    if (!ws) return CHECK_SUMMARY("test_lcp");
    test_small(ws);
    test_random_spd(ws);
    test_wedged_box(ws);
    test_duplicate_contacts(ws);
    test_random_singular(ws);
    test_packed_grid(ws);
    test_infeasible(ws);
    test_stack(ws);
    test_slope(ws);
    test_bad_input(ws);
    measure(ws);
    lc_lcp_workspace_destroy(ws);
    return CHECK_SUMMARY("test_lcp");
}
