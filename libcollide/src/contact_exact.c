/* Exact frictional contact for few points: Lemke's algorithm on the Stewart-Trinkle LCP
 * (contact_exact.h). */
#include <math.h>
#include <string.h>
#include "contact_delassus.h"
#include "contact_exact.h"
#include "tunables.h"


size_t lc_contact_exact_scratch(int nrows)
{
    size_t m = (size_t)(nrows > 0 ? nrows : 1), n = 4 * m;
    /* A (2m)^2, the unknowns' list, M (n^2), q (n), the tableau n (2n + 2), basis and solution 2n, and
     * for the refinement M without regularization (n^2), its system (n^2) and two vectors (2n) */
    return 4 * m * m + n + n * n + n + n * (2 * n + 2) + 2 * n + 2 * n * n + 2 * n;
}

static void pivot(double *t, int n, int cols, int r, int c)
{
    double *row = &t[(size_t)r * (size_t)cols], p = row[c];
    int i, k;
    for (k = 0; k < cols; ++k) row[k] /= p;
    row[c] = 1.0;
    for (i = 0; i < n; ++i) {
        double *x = &t[(size_t)i * (size_t)cols], f;
        if (i == r) continue;
        f = x[c];
        if (f == 0.0) continue;
        for (k = 0; k < cols; ++k) x[k] -= f * row[k];
        x[c] = 0.0;
    }
}

/* Lemke's algorithm on w = M z + q, w, z >= 0, w.z = 0 (n unknowns, M row-major). The tableau holds the
 * basic variables' rows over the columns w (0..n), z (n..2n), the artificial z0 (2n) and the right-hand
 * side (2n + 1); basis[r] is the variable of row r. z: the answer. Returns the pivots, or -1. */
static int lemke(const double *M, const double *q, int n, double *t, double *basis_d, double *z)
{
    int cols = 2 * n + 2, r, c, k, i, pivots = 0, entering, leaving;
    double scale = 0.0, qmin = 0.0;
    for (k = 0; k < n * n; ++k) scale = fmax(scale, fabs(M[k]));
    for (r = 0; r < n; ++r) {
        z[r] = 0.0;
        if (q[r] < qmin) qmin = q[r];
    }
    if (qmin >= 0.0) return 0;
    for (r = 0; r < n; ++r) {
        double *row = &t[(size_t)r * (size_t)cols];
        for (c = 0; c < cols; ++c) row[c] = 0.0;
        row[r] = 1.0;
        for (c = 0; c < n; ++c) row[n + c] = -M[(size_t)r * (size_t)n + (size_t)c];
        row[2 * n] = -1.0;
        row[2 * n + 1] = q[r];
        basis_d[r] = (double)r;
    }
    r = 0;
    for (k = 1; k < n; ++k)
        if (q[k] < q[r]) r = k;
    pivot(t, n, cols, r, 2 * n);
    leaving = r;               /* w_r left the basis */
    basis_d[r] = (double)(2 * n);
    entering = n + leaving;    /* its complement z_r enters */
    for (;;) {
        double best = INFINITY, tol = 1e-12 * (1.0 + scale);
        int row = -1;
        if (++pivots > LC_LEMKE_PIVOTS_PER_UNKNOWN * n) return -1;
        for (i = 0; i < n; ++i) {
            const double *x = &t[(size_t)i * (size_t)cols];
            double ratio;
            if (!(x[entering] > tol)) continue;
            ratio = x[2 * n + 1] / x[entering];
            if (row < 0 || ratio < best - 1e-12 * fabs(best)) {
                best = ratio;
                row = i;
            } else if (ratio <= best + 1e-12 * fabs(best)) {
                /* ties (degenerate steps): the artificial variable leaves first, which ends it; else the
                 * lexicographic rule on the rows of B^-1 (the w columns) over the pivot entry, which
                 * cannot cycle */
                const double *y = &t[(size_t)row * (size_t)cols];
                if ((int)basis_d[i] == 2 * n) {
                    row = i;
                } else if ((int)basis_d[row] != 2 * n) {
                    for (k = 0; k < n; ++k) {
                        double a = x[k] / x[entering], b = y[k] / y[entering];
                        if (a != b) {
                            if (a < b) row = i;
                            break;
                        }
                    }
                }
                if (ratio < best) best = ratio;
            }
        }
        if (row < 0) {
            /* a ray, unless the artificial variable is already at zero (a degenerate step left it in
             * the basis at level 0: a point not touching that slips, whose cone row has q = 0): then
             * the basis is a complementary solution */
            for (i = 0; i < n && (int)basis_d[i] != 2 * n; ++i) continue;
            if (i < n && t[(size_t)i * (size_t)cols + (size_t)(2 * n + 1)] <= tol) break;
            return -1;
        }
        leaving = (int)basis_d[row];
        pivot(t, n, cols, row, entering);
        basis_d[row] = (double)entering;
        if (leaving == 2 * n) break;
        entering = leaving < n ? n + leaving : leaving - n;
    }
    for (r = 0; r < n; ++r) {
        int v = (int)basis_d[r];
        double x = t[(size_t)r * (size_t)cols + (size_t)(2 * n + 1)];
        if (v >= n && v < 2 * n) z[v - n] = x > 0.0 ? x : 0.0;
    }
    return pivots;
}

/* The kinds of unknown of a point. */
enum { U_N = 0, U_BP = 1, U_BM = 2, U_G = 3 };

/* M and q of the LCP over the unknowns of list_d (point list_d[k] / 4, kind list_d[k] % 4), from A (the
 * normal rows 0..m, tangent rows m..2m) with its diagonal scaled by 1 + reg. */
static void build(const lc_contact_row *rows, int m, const double *A, const double *list_d, int n, const double *v,
                  double reg, double *M, double *q)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        int pi = (int)list_d[i] / 4, ki = (int)list_d[i] % 4;
        double un, ut;
        lc_contact_row_velocity(&rows[pi], v, &un, &ut);
        q[i] = ki == U_N ? un - rows[pi].target_n : ki == U_BP ? ut : ki == U_BM ? -ut : 0.0;
        for (j = 0; j < n; ++j) {
            int pj = (int)list_d[j] / 4, kj = (int)list_d[j] % 4;
            double e = 0.0;
            if (ki == U_G) {
                /* w_gamma = mu lambda_n - beta+ - beta- of the same point */
                if (pj == pi) e = kj == U_N ? rows[pi].mu : (kj == U_BP || kj == U_BM) ? -1.0 : 0.0;
            } else if (kj == U_G) {
                e = pj == pi && (ki == U_BP || ki == U_BM) ? 1.0 : 0.0;
            } else {
                /* the row's velocity (u_n, +u_t or -u_t) per unit of the column's impulse (lambda_n,
                 * +lambda_t or -lambda_t) */
                int ri = ki == U_N ? pi : m + pi, cj = kj == U_N ? pj : m + pj;
                double s = (ki == U_BM ? -1.0 : 1.0) * (kj == U_BM ? -1.0 : 1.0);
                e = s * A[ri * 2 * m + cj] * (ri == cj ? 1.0 + reg : 1.0);
            }
            M[(size_t)i * (size_t)n + (size_t)j] = e;
        }
    }
}

/* The answer of the active set Lemke ended on, again from the problem with the smallest regularization
 * (dependent points would make it singular without): the z that are basic solve (M z + q)_S = 0 over
 * them (Gaussian elimination with partial pivoting), the others are 0. Lemke's tableau carries the
 * round-off of every pivot and, after a fallback, a regularization of up to 1e-4, which left points
 * 1e-5 m/s off their conditions. Kept when it is a complementary answer to round-off (z_S >= 0,
 * w >= 0 elsewhere); returns 1 then, 0 otherwise. */
static int refine(const double *M, const double *q, int n, const double *basis_d, double *z, double *sys,
                  double *x)
{
    int S[256], ns = 0, i, j, k, ok = 1;
    double scale = 0.0;
    for (i = 0; i < n; ++i) {
        int b = (int)basis_d[i];
        if (b >= n && b < 2 * n) S[ns++] = b - n;
    }
    if (ns > 256) return 0;
    for (i = 0; i < ns; ++i) {
        for (j = 0; j < ns; ++j) sys[i * (ns + 1) + j] = M[(size_t)S[i] * (size_t)n + (size_t)S[j]];
        sys[i * (ns + 1) + ns] = -q[S[i]];
        scale = fmax(scale, fabs(q[S[i]]));
    }
    for (k = 0; k < ns; ++k) {
        int piv = k;
        for (i = k + 1; i < ns; ++i)
            if (fabs(sys[i * (ns + 1) + k]) > fabs(sys[piv * (ns + 1) + k])) piv = i;
        if (!(fabs(sys[piv * (ns + 1) + k]) > 0.0)) return 0;
        if (piv != k)
            for (j = 0; j <= ns; ++j) {
                double tmp = sys[k * (ns + 1) + j];
                sys[k * (ns + 1) + j] = sys[piv * (ns + 1) + j];
                sys[piv * (ns + 1) + j] = tmp;
            }
        for (i = k + 1; i < ns; ++i) {
            double f = sys[i * (ns + 1) + k] / sys[k * (ns + 1) + k];
            if (f == 0.0) continue;
            for (j = k; j <= ns; ++j) sys[i * (ns + 1) + j] -= f * sys[k * (ns + 1) + j];
        }
    }
    for (k = ns - 1; k >= 0; --k) {
        double r = sys[k * (ns + 1) + ns];
        for (j = k + 1; j < ns; ++j) r -= sys[k * (ns + 1) + j] * x[j];
        x[k] = r / sys[k * (ns + 1) + k];
    }
    for (k = 0; k < ns && ok; ++k)
        if (!(x[k] >= -1e-12 * (1.0 + fabs(x[k])))) ok = 0;
    for (i = 0; i < n && ok; ++i) {
        double w = q[i];
        int basic = 0;
        for (k = 0; k < ns; ++k) {
            w += M[(size_t)i * (size_t)n + (size_t)S[k]] * x[k];
            if (S[k] == i) basic = 1;
        }
        if (!basic && !(w >= -1e-12 * (1.0 + scale))) ok = 0;
    }
    if (!ok) return 0;
    for (i = 0; i < n; ++i) z[i] = 0.0;
    for (k = 0; k < ns; ++k) z[S[k]] = x[k] > 0.0 ? x[k] : 0.0;
    return 1;
}

int lc_contact_solve_exact(lc_contact_row *rows, int nrows, double *v, const double *inv_mass,
                           const double *inv_inertia, double *scratch)
{
    /* Regularizations tried in turn: a pile's points are often dependent (a face on a face gives each
     * corner twice, once from each body), and Lemke's path can end on a ray in such a degenerate
     * problem; a relative 1e-10 on A's diagonal moves the answer by that fraction and almost always
     * ends it, larger ones are the fallbacks (the Gauss-Seidel sweeps that follow take the rest). */
    static const double regularizations[3] = {1e-10, 1e-7, 1e-4};
    int m = nrows, n = 0, i, p = -1, k;
    double *A = scratch, *list_d = A + 4 * m * m, *M, *q, *t, *basis, *z;
    for (i = 0; i < m; ++i) {
        list_d[n++] = 4.0 * i + U_N;
        if (!(rows[i].mu > 0.0)) continue;
        if (rows[i].slip <= 0) list_d[n++] = 4.0 * i + U_BP;
        if (rows[i].slip >= 0) list_d[n++] = 4.0 * i + U_BM;
        list_d[n++] = 4.0 * i + U_G;
    }
    M = list_d + 4 * m;
    q = M + (size_t)n * (size_t)n;
    t = q + n;
    basis = t + (size_t)n * (size_t)(2 * n + 2);
    z = basis + n;
    lc_contact_delassus(rows, m, inv_mass, inv_inertia, A);
    for (k = 0; k < 3 && p < 0; ++k) {
        build(rows, m, A, list_d, n, v, regularizations[k], M, q);
        p = lemke(M, q, n, t, basis, z);
    }
    if (p < 0) return -1;
    {
        double *M0 = z + n, *sys = M0 + (size_t)n * (size_t)n, *x = sys + (size_t)n * (size_t)(n + 1);
        build(rows, m, A, list_d, n, v, regularizations[0], M0, q);
        refine(M0, q, n, basis, z, sys, x);
    }
    for (i = 0; i < m; ++i) rows[i].lambda_n = rows[i].lambda_t = 0.0;
    for (i = 0; i < n; ++i) {
        int pi = (int)list_d[i] / 4, ki = (int)list_d[i] % 4;
        if (ki == U_N) rows[pi].lambda_n = z[i];
        else if (ki == U_BP) rows[pi].lambda_t += z[i];
        else if (ki == U_BM) rows[pi].lambda_t -= z[i];
    }
    for (i = 0; i < m; ++i)
        if (rows[i].lambda_n != 0.0 || rows[i].lambda_t != 0.0)
            lc_contact_row_apply(&rows[i], rows[i].lambda_n, rows[i].lambda_t, v, inv_mass, inv_inertia);
    return p;
}
