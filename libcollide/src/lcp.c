/* lcp.c - linear complementarity solvers (see lcp.h for the problem, methods and stopping rule). */
#include "lcp.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------------------------------
 * Workspace
 * ------------------------------------------------------------------------------------------- */
struct lc_lcp_workspace {
    double *d;
    size_t dcap; /* doubles */
    int *i;
    size_t icap; /* ints */
};

lc_lcp_workspace *lc_lcp_workspace_create(void)
{
    lc_lcp_workspace *ws = (lc_lcp_workspace *)calloc(1, sizeof *ws);
    return ws;
}

void lc_lcp_workspace_destroy(lc_lcp_workspace *ws)
{
    if (!ws) return;
    free(ws->d);
    free(ws->i);
    free(ws);
}

/* Returns 0 on success, -1 when out of memory (the old buffers stay valid). */
static int ws_reserve(lc_lcp_workspace *ws, size_t nd, size_t ni)
{
    if (nd > ws->dcap) {
        double *p;
        if (nd > SIZE_MAX / sizeof(double)) return -1;
        p = (double *)realloc(ws->d, nd * sizeof(double));
        if (!p) return -1;
        ws->d = p;
        ws->dcap = nd;
    }
    if (ni > ws->icap) {
        int *p;
        if (ni > SIZE_MAX / sizeof(int)) return -1;
        p = (int *)realloc(ws->i, ni * sizeof(int));
        if (!p) return -1;
        ws->i = p;
        ws->icap = ni;
    }
    return 0;
}

/* ---------------------------------------------------------------------------------------------
 * Options, validation, helpers
 * ------------------------------------------------------------------------------------------- */
lc_lcp_options lc_lcp_default_options(void)
{
    lc_lcp_options o;
    o.exact_max = 256;
    o.max_iterations = 1000;
    o.tolerance = 1e-10;
    o.regularization = 1e-12;
    o.relaxation = 1.0;
    o.warm_start = 0;
    return o;
}

/* Threshold tuning constants (relative). */
#define LCP_SING_REL 1e-9   /* warm-start add: Schur complement <= this * A_jj -> dependent row, skip */
#define LCP_DIR_REL 1e-11   /* |da_i| below this * maxdiag * max|df| is rounding noise */
#define LCP_DF_REL 1e-12    /* |df_i| below this * max|df| is rounding noise */
#define LCP_ACC_REL 1e-13   /* a_i >= -this * max|b| counts as non-negative when choosing to drive */
#define LCP_ZERO_DIAG 1e-14 /* A_ii <= this * max diag: a zero row (never pivoted in) */
#define LCP_REFRESH 32      /* PGS: recompute a = A f + b exactly every this many sweeps */

static int all_finite(const double *x, size_t m)
{
    size_t k;
    for (k = 0; k < m; ++k)
        if (!isfinite(x[k])) return 0;
    return 1;
}

static double max_abs(const double *x, int n)
{
    double m = 0.0;
    int k;
    for (k = 0; k < n; ++k) {
        double v = fabs(x[k]);
        if (v > m) m = v;
    }
    return m;
}

static int options_valid(const lc_lcp_options *o)
{
    if (o->max_iterations < 0) return 0;
    if (!(o->tolerance >= 0.0) || isinf(o->tolerance)) return 0;
    if (!(o->regularization >= 0.0) || isinf(o->regularization)) return 0;
    if (o->relaxation != 0.0 && !(o->relaxation > 0.0 && o->relaxation < 2.0)) return 0;
    return 1;
}

uint64_t lc_lcp_work(int n, const lc_lcp_result *res)
{
    uint64_t passes = 2u + (uint64_t)(res->pivots > 0 ? res->pivots : 0) + (uint64_t)(res->sweeps > 0 ? res->sweeps : 0);
    return n > 0 ? passes * (uint64_t)n * (uint64_t)n : 0u;
}

static void fill_fail(int n, double *f, double *a_out, lc_lcp_result *res)
{
    if (n > 0) {
        if (f) memset(f, 0, (size_t)n * sizeof(double));
        if (a_out) memset(a_out, 0, (size_t)n * sizeof(double));
    }
    if (res) {
        res->status = 2;
        res->exact = 0;
        res->iterations = 0;
        res->residual = HUGE_VAL;
        res->pivots = 0;
        res->sweeps = 0;
        res->fallback = 0;
    }
}

/* a = A f + b, skipping zero forces (bitwise the same as the full sum for finite A). */
static void compute_a(int n, const double *A, const double *b, const double *f, double *a)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        const double *row = A + (size_t)i * (size_t)n;
        double s = b[i];
        for (j = 0; j < n; ++j)
            if (f[j] != 0.0) s += row[j] * f[j];
        a[i] = s;
    }
}

/* Median of three. */
static double mid3(double x, double y, double z)
{
    double lo = x < y ? x : y, hi = x < y ? y : x;
    if (z < lo) return lo;
    if (z > hi) return hi;
    return z;
}

/* Bounds of row i for the boxed problem (lo/hi NULL -> 0/+inf). */
typedef struct {
    const double *lo, *hi, *mu;
    const int *coupled;
} lcp_bounds;

static void row_bounds(const lcp_bounds *bd, const double *f, int i, double *lo, double *hi)
{
    if (bd->coupled && bd->coupled[i] >= 0) {
        double fn = f[bd->coupled[i]];
        double h = bd->mu[i] * (fn > 0.0 ? fn : 0.0);
        *lo = -h;
        *hi = h;
        return;
    }
    *lo = bd->lo ? bd->lo[i] : 0.0;
    *hi = bd->hi ? bd->hi[i] : HUGE_VAL;
}

/* Unscaled residual max_i |mid(f_i - lo_i, f_i - hi_i, a_i)|. */
static double raw_residual(int n, const double *f, const double *a, const lcp_bounds *bd)
{
    double r = 0.0;
    int i;
    for (i = 0; i < n; ++i) {
        double lo, hi, v;
        row_bounds(bd, f, i, &lo, &hi);
        v = fabs(mid3(f[i] - lo, f[i] - hi, a[i]));
        if (!(v <= r)) r = v; /* also propagates NaN */
    }
    return r;
}

/* ---------------------------------------------------------------------------------------------
 * Projected Gauss-Seidel / SOR (shared by both entry points)
 * f: in = start (projected onto bounds here), out = answer. a: workspace (n), out = A f + b.
 * Returns the scaled residual; *sweeps_out = sweeps done.
 * ------------------------------------------------------------------------------------------- */
static double pgs_solve(int n, const double *A, const double *b, const lcp_bounds *bd, double *f,
                        double *a, int max_sweeps, double tol, double omega, double bscale,
                        int *sweeps_out)
{
    int i, k, sweep = 0;
    double r;
    /* project the start onto the bounds (normal rows first is not needed: friction bounds use the
     * projected normal value in the first sweep anyway). */
    for (i = 0; i < n; ++i) {
        double lo, hi;
        if (!isfinite(f[i])) f[i] = 0.0;
        row_bounds(bd, f, i, &lo, &hi);
        if (f[i] < lo) f[i] = lo;
        if (f[i] > hi) f[i] = hi;
        if (!isfinite(f[i])) f[i] = 0.0; /* only possible with an infinite lower bound above 0: excluded by validation */
    }
    compute_a(n, A, b, f, a);
    r = raw_residual(n, f, a, bd) / bscale;
    while (!(r <= tol) && sweep < max_sweeps) {
        ++sweep;
        for (i = 0; i < n; ++i) {
            const double *row = A + (size_t)i * (size_t)n;
            double aii = row[i], lo, hi, fn, delta;
            row_bounds(bd, f, i, &lo, &hi);
            if (aii > 0.0) {
                fn = f[i] - omega * a[i] / aii;
            } else {
                /* zero row (PSD => the whole row is 0): a_i = b_i cannot be changed; pick the bound
                 * the complementarity condition asks for, if finite. */
                fn = f[i];
                if (a[i] > 0.0 && isfinite(lo)) fn = lo;
                if (a[i] < 0.0 && isfinite(hi)) fn = hi;
            }
            if (fn < lo) fn = lo;
            if (fn > hi) fn = hi;
            delta = fn - f[i];
            if (delta != 0.0) {
                f[i] = fn;
                /* column i of A == row i (A symmetric) */
                for (k = 0; k < n; ++k) a[k] += row[k] * delta;
            }
        }
        if (sweep % LCP_REFRESH == 0) compute_a(n, A, b, f, a);
        r = raw_residual(n, f, a, bd) / bscale;
        if (r <= tol && sweep % LCP_REFRESH != 0) {
            /* confirm with an exact a before stopping */
            compute_a(n, A, b, f, a);
            r = raw_residual(n, f, a, bd) / bscale;
        }
    }
    compute_a(n, A, b, f, a);
    r = raw_residual(n, f, a, bd) / bscale;
    *sweeps_out = sweep;
    return r;
}

/* ---------------------------------------------------------------------------------------------
 * Exact method: Dantzig-Cottle / Baraff principal pivoting with an updated Cholesky factor.
 * ------------------------------------------------------------------------------------------- */
typedef struct {
    int n;
    const double *A;
    double *L;  /* k x k lower-triangular factor of A_CC (rows in list order), stride n */
    int *cl;    /* cl[p] = problem index of the p-th active row */
    int *pos;   /* pos[i] = position of i in cl, or -1 */
    int k;      /* active count */
    double *tmp;/* n scratch */
    int regularized;
} chol_t;

#define LROW(c, p) ((c)->L + (size_t)(p) * (size_t)(c)->n)

/* Forward solve L y = r (length k). */
static void chol_fwd(const chol_t *c, const double *r, double *y)
{
    int p, q;
    for (p = 0; p < c->k; ++p) {
        const double *lp = LROW(c, p);
        double s = r[p];
        for (q = 0; q < p; ++q) s -= lp[q] * y[q];
        y[p] = s / lp[p];
    }
}

/* Backward solve L^T x = y (in place). */
static void chol_bwd(const chol_t *c, double *x)
{
    int p, q;
    for (p = c->k - 1; p >= 0; --p) {
        double s = x[p];
        for (q = p + 1; q < c->k; ++q) s -= LROW(c, q)[p] * x[q];
        x[p] = s / LROW(c, p)[p];
    }
}

/* Solve A_CC x = r (both in list order, length k); r may alias x. */
static void chol_solve(const chol_t *c, const double *r, double *x)
{
    chol_fwd(c, r, x); /* forward solve reads r[p] before writing x[p]: aliasing is fine */
    chol_bwd(c, x);
}

/* Append index j. mode 0: skip a dependent row (return 0); mode 1: regularise a ~0 pivot.
 * Returns 1 if added. */
static int chol_add(chol_t *c, int j, int mode, double reg)
{
    const double *Aj = c->A + (size_t)j * (size_t)c->n;
    double *lk = LROW(c, c->k);
    double ajj = Aj[j], piv;
    int p;
    for (p = 0; p < c->k; ++p) c->tmp[p] = Aj[c->cl[p]];
    chol_fwd(c, c->tmp, lk);
    piv = ajj;
    for (p = 0; p < c->k; ++p) piv -= lk[p] * lk[p];
    if (!(piv > LCP_SING_REL * ajj)) {
        if (mode == 0) return 0;
        double r = reg > DBL_EPSILON ? reg : DBL_EPSILON;
        if (!(piv > r * ajj)) {
            piv = r * ajj; /* ajj > 0: zero rows never get here */
            c->regularized++;
        }
    }
    lk[c->k] = sqrt(piv);
    c->cl[c->k] = j;
    c->pos[j] = c->k;
    c->k++;
    return 1;
}

/* Remove the row at list position m: rank-1 update of the trailing factor, then compaction. */
static void chol_remove(chol_t *c, int m)
{
    int k = c->k, p, q;
    double *x = c->tmp;
    /* x = column m below the diagonal */
    for (p = m + 1; p < k; ++p) x[p] = LROW(c, p)[m];
    /* L33 L33^T + x x^T, Givens-style, on rows/cols m+1..k-1 */
    for (q = m + 1; q < k; ++q) {
        double *lq = LROW(c, q);
        double lqq = lq[q];
        double r = hypot(lqq, x[q]);
        double cs = r / lqq, sn = x[q] / lqq;
        lq[q] = r;
        for (p = q + 1; p < k; ++p) {
            double *lp = LROW(c, p);
            lp[q] = (lp[q] + sn * x[p]) / cs;
            x[p] = cs * x[p] - sn * lp[q];
        }
    }
    /* compaction: drop row m and column m */
    c->pos[c->cl[m]] = -1;
    for (p = m + 1; p < k; ++p) {
        double *src = LROW(c, p), *dst = LROW(c, p - 1);
        for (q = 0; q < m; ++q) dst[q] = src[q];
        for (q = m + 1; q <= p; ++q) dst[q - 1] = src[q];
        c->cl[p - 1] = c->cl[p];
        c->pos[c->cl[p - 1]] = p - 1;
    }
    c->k = k - 1;
}

enum { ST_FREE = 0, ST_C = 1, ST_NC = 2, ST_DRIVE = 3, ST_DEP = 4 };

/* Re-anchor after a drive to remove the drift of the stepped f and a: f_C = -A_CC^{-1} b_C (all
 * other f = 0) is used only if it stays (rounding-level) non-negative; when A_CC is ill-conditioned
 * the re-solve can move f far along a near-null direction of A (a unchanged, f < 0), and then the
 * stepped f, which is on the feasible side by construction, is kept. a = A f + b either way. */
static void anchor(chol_t *c, const double *b, double *f, double *a, double *rhs)
{
    int p, n = c->n, ok = 1;
    double fmax = 0.0;
    for (p = 0; p < c->k; ++p) {
        double v = fabs(f[c->cl[p]]);
        if (v > fmax) fmax = v;
        rhs[p] = -b[c->cl[p]];
    }
    chol_solve(c, rhs, rhs);
    for (p = 0; p < c->k; ++p)
        if (!(rhs[p] >= -LCP_DF_REL * fmax)) ok = 0;
    if (ok) {
        memset(f, 0, (size_t)n * sizeof(double));
        for (p = 0; p < c->k; ++p) f[c->cl[p]] = rhs[p];
    }
    compute_a(n, c->A, b, f, a);
}

/* Returns 0 on success (f, a hold a complementary point up to clamping), 1 when the pivot cap was
 * hit, 2 when no blocking index was found (infeasible or numerically stuck). f/a always hold the
 * last iterate. */
static int exact_solve(int n, const double *A, const double *b, const double *guess, double *f, double *a,
                       double reg, double noise, double *dbuf, int *ibuf, int *pivots_out)
{
    chol_t ch;
    double *df = dbuf, *da = dbuf + n, *rhs = dbuf + 2 * (size_t)n;
    int *st = ibuf;
    int i, p, pivots = 0, cap = 10 * n + 50, ret = 0, moved;
    double maxdiag = 0.0, bmax = max_abs(b, n), acc_tol;

    ch.n = n;
    ch.A = A;
    ch.L = dbuf + 4 * (size_t)n;
    ch.tmp = dbuf + 3 * (size_t)n;
    ch.cl = ibuf + n;
    ch.pos = ibuf + 2 * (size_t)n;
    ch.k = 0;
    ch.regularized = 0;
    for (i = 0; i < n; ++i) {
        double d = A[(size_t)i * (size_t)n + i];
        if (d > maxdiag) maxdiag = d;
        st[i] = ST_FREE;
        ch.pos[i] = -1;
    }
    acc_tol = LCP_ACC_REL * bmax;

    /* --- start from a guessed active set: the rows with a force in `guess` (the previous answer,
     * when the caller warm-starts and has one), else {i : b_i < 0}. Add in index order, skipping
     * dependent rows, then drop rows whose force comes out negative until all are >= 0. A resting
     * pile's active set hardly changes between solves: from the previous one, a 15-box pyramid's
     * solve takes ~1 pivot instead of ~55. Any start gives the same answer (up to degeneracy). */
    {
        int any = 0;
        for (i = 0; guess != NULL && i < n && !any; ++i) any = guess[i] > 0.0 && isfinite(guess[i]);
        if (!any) guess = NULL;
    }
    for (i = 0; i < n; ++i) {
        double d = A[(size_t)i * (size_t)n + i];
        if ((guess ? guess[i] > 0.0 && isfinite(guess[i]) : b[i] < 0.0) && d > LCP_ZERO_DIAG * maxdiag) {
            if (chol_add(&ch, i, 0, reg)) st[i] = ST_C;
        }
    }
    for (;;) {
        int worst = -1;
        double wv = 0.0;
        for (p = 0; p < ch.k; ++p) rhs[p] = -b[ch.cl[p]];
        chol_solve(&ch, rhs, rhs);
        for (p = 0; p < ch.k; ++p)
            if (rhs[p] < wv) {
                wv = rhs[p];
                worst = p;
            }
        if (worst < 0) break;
        /* drop every negative one (largest position first so positions stay valid) */
        for (p = ch.k - 1; p >= 0; --p)
            if (rhs[p] < 0.0) {
                st[ch.cl[p]] = ST_FREE;
                chol_remove(&ch, p);
                ++pivots;
            }
    }
    ++pivots; /* the initial block solve: rhs holds f_C >= 0 */
    memset(f, 0, (size_t)n * sizeof(double));
    for (p = 0; p < ch.k; ++p) f[ch.cl[p]] = rhs[p];
    compute_a(n, A, b, f, a);

    /* --- drive every index with a_d < 0 to zero (Baraff's drive-to-zero) */
    for (;;) {
        int d = -1;
        double dv = -acc_tol;
        /* most negative a among the non-active rows; zero rows (a_i = b_i whatever f is) are
         * left at f_i = 0 - if b_i < 0 the problem is infeasible and the residual will say so */
        for (i = 0; i < n; ++i)
            if (st[i] != ST_C && st[i] != ST_DEP && a[i] < dv &&
                A[(size_t)i * (size_t)n + i] > LCP_ZERO_DIAG * maxdiag) {
                dv = a[i];
                d = i;
            }
        if (d < 0) break;
        st[d] = ST_DRIVE;
        moved = 0;
        for (;;) {
            const double *Ad = A + (size_t)d * (size_t)n;
            double dfmax = 1.0, tda, tdf, s = HUGE_VAL;
            int j = -1;
            if (pivots >= cap) {
                ret = 1;
                break;
            }
            /* direction: df_d = 1, A_CC df_C = -A_Cd */
            for (p = 0; p < ch.k; ++p) rhs[p] = -Ad[ch.cl[p]]; /* A symmetric: A_Cd = A_dC */
            chol_solve(&ch, rhs, rhs);
            for (p = 0; p < ch.k; ++p)
                if (fabs(rhs[p]) > dfmax) dfmax = fabs(rhs[p]);
            /* da = A df */
            for (i = 0; i < n; ++i) {
                const double *row = A + (size_t)i * (size_t)n;
                double sum = row[d];
                for (p = 0; p < ch.k; ++p) sum += row[ch.cl[p]] * rhs[p];
                da[i] = sum;
            }
            for (p = 0; p < ch.k; ++p) df[p] = rhs[p];
            tda = LCP_DIR_REL * maxdiag * dfmax;
            tdf = LCP_DF_REL * dfmax;
            /* ratio test, ties to the earliest candidate in index order; d itself wins ties */
            if (da[d] > tda) {
                s = -a[d] / da[d];
                if (s < 0.0) s = 0.0;
                j = d;
            }
            for (i = 0; i < n; ++i) {
                double si;
                if (st[i] == ST_C) {
                    double dfi = df[ch.pos[i]];
                    if (!(dfi < -tdf)) continue;
                    si = -f[i] / dfi;
                } else if (st[i] == ST_NC) {
                    if (!(da[i] < -tda)) continue;
                    si = -a[i] / da[i];
                } else {
                    continue;
                }
                if (si < 0.0) si = 0.0;
                if (si < s) {
                    s = si;
                    j = i;
                }
            }
            if (j < 0) {
                /* No blocking index: f_d can grow forever. If row d depends on the active rows
                 * (da_d ~ 0) and a_d < 0 only by rounding (|a_d| <= noise), leave f_d = 0 and mark d
                 * dependent (not driven again until the active set changes; the final residual
                 * check still judges it).
                 * Otherwise the problem is infeasible (or numerically stuck): give up. */
                if (!(da[d] > tda) && -a[d] <= noise) {
                    st[d] = ST_DEP;
                    break;
                }
                ret = 2;
                break;
            }
            /* step */
            moved = 1;
            f[d] += s;
            for (p = 0; p < ch.k; ++p) f[ch.cl[p]] += s * df[p];
            for (i = 0; i < n; ++i) a[i] += s * da[i];
            ++pivots;
            if (j == d) {
                chol_add(&ch, d, 1, reg);
                st[d] = ST_C;
                a[d] = 0.0;
                break;
            } else if (st[j] == ST_C) {
                chol_remove(&ch, ch.pos[j]);
                st[j] = ST_NC;
                f[j] = 0.0;
            } else {
                chol_add(&ch, j, 1, reg);
                st[j] = ST_C;
                a[j] = 0.0;
            }
        }
        if (ret != 0) break;
        if (moved) {
            /* the active set changed: rows marked dependent may not be any more */
            for (i = 0; i < n; ++i)
                if (st[i] == ST_DEP) st[i] = ST_FREE;
            anchor(&ch, b, f, a, rhs); /* remove drift of the stepped f and a */
        }
    }
    /* clamp to the feasible side and recompute a */
    for (i = 0; i < n; ++i)
        if (!(f[i] > 0.0)) f[i] = 0.0;
    compute_a(n, A, b, f, a);
    *pivots_out = pivots;
    return ret;
}

/* ---------------------------------------------------------------------------------------------
 * Entry points
 * ------------------------------------------------------------------------------------------- */
static int validate_matrix(int n, const double *A)
{
    int i;
    if (!all_finite(A, (size_t)n * (size_t)n)) return 0;
    for (i = 0; i < n; ++i)
        if (A[(size_t)i * (size_t)n + i] < 0.0) return 0;
    return 1;
}

int lc_lcp_solve(int n, const double *A, const double *b, double *f, double *a_out,
                 const lc_lcp_options *opt, lc_lcp_workspace *ws, lc_lcp_result *res)
{
    lc_lcp_options o = opt ? *opt : lc_lcp_default_options();
    lc_lcp_workspace *own = NULL;
    lcp_bounds bd = {NULL, NULL, NULL, NULL};
    double omega, bscale, r;
    double *a, *fx;
    int status, use_exact, sweeps = 0, pivots = 0, exact_used = 0, fallback = 0;
    size_t nn, nd, ni;

    if (n < 0 || (n > 0 && (!A || !b || !f)) || !options_valid(&o)) {
        fill_fail(n > 0 ? n : 0, f, a_out, res);
        return 2;
    }
    if (n == 0) {
        if (res) {
            memset(res, 0, sizeof *res);
            res->residual = 0.0;
        }
        return 0;
    }
    if (!all_finite(b, (size_t)n) || !validate_matrix(n, A)) {
        fill_fail(n, f, a_out, res);
        return 2;
    }
    omega = o.relaxation == 0.0 ? 1.0 : o.relaxation;
    bscale = max_abs(b, n) + DBL_MIN;
    use_exact = n <= o.exact_max;

    nn = (size_t)n;
    if (use_exact) {
        if (nn > (SIZE_MAX / sizeof(double) - 6 * nn) / nn) {
            fill_fail(n, f, a_out, res);
            return 2;
        }
        nd = nn * nn + 6 * nn; /* df, da, rhs, tmp, [L n*n], a, fx */
        ni = 3 * nn;
    } else {
        nd = 2 * nn;
        ni = 0;
    }
    if (!ws) {
        own = lc_lcp_workspace_create();
        ws = own;
    }
    if (!ws || ws_reserve(ws, nd, ni) != 0) {
        lc_lcp_workspace_destroy(own);
        fill_fail(n, f, a_out, res);
        return 2;
    }
    a = ws->d + (nd - 2 * nn);
    fx = ws->d + (nd - nn);

    if (use_exact) {
        /* rounding-level negative accelerations of dependent rows are tolerated up to a tenth of
         * the requested residual */
        double rex;
        (void)exact_solve(n, A, b, o.warm_start ? f : NULL, fx, a, o.regularization, 0.1 * o.tolerance * bscale,
                          ws->d, ws->i, &pivots);
        rex = raw_residual(n, fx, a, &bd) / bscale;
        exact_used = 1;
        /* the exact answer is accepted whenever its true residual meets the tolerance (also after
         * a cap / no-blocking exit, which can happen on rounding-level degeneracy) */
        if (rex <= o.tolerance) {
            memcpy(f, fx, nn * sizeof(double));
            r = rex;
        } else {
            /* fall back: PGS warm-started from the exact iterate; keep the better answer */
            double rp;
            fallback = 1;
            memcpy(f, fx, nn * sizeof(double));
            rp = pgs_solve(n, A, b, &bd, f, a, o.max_iterations, o.tolerance, omega, bscale, &sweeps);
            if (rp < rex || !(rex == rex)) {
                r = rp;
                exact_used = 0;
            } else {
                memcpy(f, fx, nn * sizeof(double));
                compute_a(n, A, b, f, a);
                r = rex;
            }
        }
    } else {
        if (!o.warm_start) memset(f, 0, nn * sizeof(double));
        r = pgs_solve(n, A, b, &bd, f, a, o.max_iterations, o.tolerance, omega, bscale, &sweeps);
    }
    status = (r <= o.tolerance) ? 0 : 1;
    if (a_out) memcpy(a_out, a, nn * sizeof(double));
    if (res) {
        res->status = status;
        res->exact = exact_used;
        res->iterations = exact_used ? pivots : sweeps;
        res->residual = r;
        res->pivots = pivots;
        res->sweeps = sweeps;
        res->fallback = fallback;
    }
    lc_lcp_workspace_destroy(own);
    return status;
}

int lc_lcp_solve_boxed(int n, const double *A, const double *b, const double *lo, const double *hi,
                       const int *coupled, const double *mu, double *f, double *a_out,
                       const lc_lcp_options *opt, lc_lcp_workspace *ws, lc_lcp_result *res)
{
    lc_lcp_options o = opt ? *opt : lc_lcp_default_options();
    lc_lcp_workspace *own = NULL;
    lcp_bounds bd;
    double omega, bscale, r;
    int i, status, sweeps = 0;
    size_t nn;

    if (n < 0 || (n > 0 && (!A || !b || !f)) || !options_valid(&o)) {
        fill_fail(n > 0 ? n : 0, f, a_out, res);
        return 2;
    }
    if (n == 0) {
        if (res) {
            memset(res, 0, sizeof *res);
            res->residual = 0.0;
        }
        return 0;
    }
    if (!all_finite(b, (size_t)n) || !validate_matrix(n, A)) {
        fill_fail(n, f, a_out, res);
        return 2;
    }
    for (i = 0; i < n; ++i) {
        int c = coupled ? coupled[i] : -1;
        if (c >= 0) {
            if (c >= n || c == i || !mu || !(mu[i] >= 0.0) || isinf(mu[i]) || coupled[c] >= 0) {
                fill_fail(n, f, a_out, res);
                return 2;
            }
        } else {
            double l = lo ? lo[i] : 0.0, h = hi ? hi[i] : HUGE_VAL;
            /* NaN, lo > hi, lo = +inf or hi = -inf are invalid */
            if (l != l || h != h || l > h || l == HUGE_VAL || h == -HUGE_VAL) {
                fill_fail(n, f, a_out, res);
                return 2;
            }
        }
    }
    bd.lo = lo;
    bd.hi = hi;
    bd.mu = mu;
    bd.coupled = coupled;
    omega = o.relaxation == 0.0 ? 1.0 : o.relaxation;
    bscale = max_abs(b, n) + DBL_MIN;
    nn = (size_t)n;
    if (!ws) {
        own = lc_lcp_workspace_create();
        ws = own;
    }
    if (!ws || ws_reserve(ws, nn, 0) != 0) {
        lc_lcp_workspace_destroy(own);
        fill_fail(n, f, a_out, res);
        return 2;
    }
    if (!o.warm_start) memset(f, 0, nn * sizeof(double));
    r = pgs_solve(n, A, b, &bd, f, ws->d, o.max_iterations, o.tolerance, omega, bscale, &sweeps);
    status = (r <= o.tolerance) ? 0 : 1;
    if (a_out) memcpy(a_out, ws->d, nn * sizeof(double));
    if (res) {
        res->status = status;
        res->exact = 0;
        res->iterations = sweeps;
        res->residual = r;
        res->pivots = 0;
        res->sweeps = sweeps;
        res->fallback = 0;
    }
    lc_lcp_workspace_destroy(own);
    return status;
}
