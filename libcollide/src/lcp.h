/* lcp.h - linear complementarity solvers of libcollide (internal API).
 *
 * Problem (LCP):  find f such that  a = A f + b,  f >= 0,  a >= 0,  f . a = 0
 * with A (n x n, row-major double) symmetric positive SEMI-definite, possibly singular
 * (redundant contacts). In the engine f are contact forces [N] (or impulses [N s]) and a the
 * relative normal accelerations [m/s^2] (or velocity changes [m/s]); A = J M^-1 J^T.
 *
 * Methods
 * - Exact (n <= opt.exact_max): Dantzig-Cottle principal pivoting in Baraff's "drive to zero"
 *   form (Baraff 1994), which is finite for PSD matrices in exact arithmetic and keeps the active
 *   block A_CC non-singular by construction. It is warm-started from the guess C0 = {i : b_i < 0}
 *   (dependent rows skipped, negative forces dropped), the active block is factorised by a
 *   Cholesky factor updated in O(k^2) per pivot (add/delete row), and a pivot whose Schur
 *   complement is ~0 gets the relative diagonal regularisation opt.regularization * A_jj.
 *   A row whose driving direction is ~0 (it depends on the active rows) and whose a_d < 0 only by
 *   rounding (|a_d| <= 0.1 * tolerance * max|b|) is left at f_d = 0. Pivot cap 10 n + 50.
 *   The exact answer (clamped to f >= 0, a recomputed) is accepted when its residual is <=
 *   opt.tolerance. Otherwise (cap hit, infeasible / numerically stuck, or rounding above the
 *   tolerance) projected Gauss-Seidel is run warm-started from the exact iterate and the better of
 *   the two answers is returned (result.exact says which, result.fallback = 1).
 * - Iterative (n > opt.exact_max, and the boxed variant): projected Gauss-Seidel / SOR in fixed
 *   index order, f_i <- clamp(f_i - w a_i / A_ii, lo_i, hi_i), keeping a = A f + b up to date
 *   (recomputed exactly every 32 sweeps and before any decision to stop).
 *   Stopping rule: stop after the first sweep whose scaled residual (below, from an exactly
 *   recomputed a) is <= opt.tolerance (status 0; 0 sweeps if the start already meets it), or after
 *   opt.max_iterations sweeps (status 1).
 *   The answer always satisfies the bounds (f >= 0 for lc_lcp_solve).
 *
 * Residual (result.residual): max_i |mid(f_i - lo_i, f_i - hi_i, a_i)| / (max_i |b_i| + DBL_MIN),
 * which for lo = 0, hi = +inf is max_i |min(f_i, a_i)| (covers negativity of f and a and the
 * complementarity product). a is recomputed as A f + b from the returned f.
 *
 * Everything is deterministic (fixed orders, no RNG, no global state). Memory comes from the
 * workspace, which grows on demand and is reused across calls (not thread-safe: one workspace per
 * thread). The exact method needs n*n + O(n) doubles, the iterative one O(n).
 */
#ifndef LIBCOLLIDE_LCP_H
#define LIBCOLLIDE_LCP_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lc_lcp_workspace lc_lcp_workspace; /* opaque */

/* Returns NULL when out of memory. */
lc_lcp_workspace *lc_lcp_workspace_create(void);
/* NULL is accepted. */
void lc_lcp_workspace_destroy(lc_lcp_workspace *ws);

typedef struct lc_lcp_options {
    int exact_max;         /* n <= exact_max: exact pivoting method; larger: iterative (PGS/SOR).
                              Negative: always iterative. Default 256. */
    int max_iterations;    /* iterative sweeps cap (>= 0). Default 1000. */
    double tolerance;      /* target for result.residual (>= 0). Default 1e-10. */
    double regularization; /* relative diagonal regularisation for ~singular pivots (>= 0; values below
                              DBL_EPSILON act as DBL_EPSILON). Default 1e-12. */
    /* Fields below were added after the first interface; zero means "default". */
    double relaxation;     /* SOR factor w in (0, 2); 0 = default 1.0 (plain projected Gauss-Seidel). */
    int warm_start;        /* 1: the iterative method starts from the f passed in (projected onto the
                              bounds; non-finite entries -> 0), and the exact method (lc_lcp_solve) from
                              the active set {i : f_i > 0} of the f passed in, if any is; 0 (default):
                              from f = 0, the exact method from {i : b_i < 0}. */
} lc_lcp_options;

/* The defaults listed above. */
lc_lcp_options lc_lcp_default_options(void);

typedef struct lc_lcp_result {
    int status;      /* 0 = solved to tolerance, 1 = iterative cap reached / best answer returned,
                        2 = failure (no memory / invalid or non-finite input) */
    int exact;       /* 1 if the exact method produced the answer */
    int iterations;  /* pivots (exact) or sweeps (iterative) of the method that answered */
    double residual; /* see the file comment; +inf when status == 2 */
    /* Fields below were added after the first interface. */
    int pivots;      /* pivots done by the exact method (0 if not run) */
    int sweeps;      /* PGS sweeps done (0 if not run) */
    int fallback;    /* 1 if the exact method ran but the iterative one was then used */
} lc_lcp_result;

/* Matrix entries a solve of n rows visited, the unit of lc_counters.solver_work: n^2 for setting up
 * and for the answer, and n^2 per pivot and per sweep, the sweeps of a fallback after the pivots too. */
uint64_t lc_lcp_work(int n, const lc_lcp_result *res);

/* Solves a = A f + b, 0 <= f _|_ a >= 0. f and a_out (may be NULL) have n entries.
 * opt may be NULL (defaults); ws may be NULL (a temporary workspace is used); res may be NULL.
 * Returns res->status. n == 0 is a valid empty problem (status 0). On status 2 because of invalid
 * input (n < 0, NULL A/b/f with n > 0, non-finite or negative-diagonal A, non-finite b, bad
 * options) f and a_out are set to zeros when they are non-NULL. Deterministic. */
int lc_lcp_solve(int n, const double *A, const double *b, double *f, double *a_out,
                 const lc_lcp_options *opt, lc_lcp_workspace *ws, lc_lcp_result *res);

/* Boxed variant (for friction): lo[i] <= f[i] <= hi[i], complementary to a = A f + b
 * (f_i = lo_i -> a_i >= 0, f_i = hi_i -> a_i <= 0, strictly inside -> a_i = 0).
 * lo may be NULL (all 0), hi may be NULL (all +inf); +-INFINITY entries are allowed, NaN not.
 * If coupled != NULL and coupled[i] >= 0, row i is a friction row of the normal row coupled[i]
 * and its bounds are -mu[i]*max(f[coupled[i]],0) .. +mu[i]*max(f[coupled[i]],0) (lo/hi of that
 * row ignored; mu[i] >= 0 finite; coupled[i] != i, < n; a coupled row must not itself be coupled).
 * Solved by projected Gauss-Seidel in index order (result.exact = 0). */
int lc_lcp_solve_boxed(int n, const double *A, const double *b, const double *lo, const double *hi,
                       const int *coupled, const double *mu, double *f, double *a_out,
                       const lc_lcp_options *opt, lc_lcp_workspace *ws, lc_lcp_result *res);

#ifdef __cplusplus
}
#endif

#endif /* LIBCOLLIDE_LCP_H */
