/* Exact frictional contact by active sets (contact_active_set.h). */
#include <math.h>
#include <string.h>
#include "contact_active_set.h"
#include "contact_delassus.h"
#include "tunables.h"

size_t lc_contact_active_set_scratch(int nrows)
{
    size_t m = (size_t)(nrows > 0 ? nrows : 1), n = 2 * m;
    /* A, the system E and its factors F (n^2 each), six vectors of n, and per point its states, the
     * conditions that failed and the factors' row order (6m ints, at most 3m doubles) */
    return 3 * n * n + 6 * n + 3 * m;
}

/* LU factors of the n x n matrix a (row-major, overwritten) with partial pivoting, the row order in piv;
 * returns 0 when it is singular. */
static int lu_factor(double *a, int n, int *piv)
{
    int i, j, k;
    for (i = 0; i < n; ++i) piv[i] = i;
    for (k = 0; k < n; ++k) {
        int p = k;
        for (i = k + 1; i < n; ++i)
            if (fabs(a[(size_t)i * (size_t)n + (size_t)k]) > fabs(a[(size_t)p * (size_t)n + (size_t)k])) p = i;
        if (!(fabs(a[(size_t)p * (size_t)n + (size_t)k]) > 0.0)) return 0;
        if (p != k) {
            int t = piv[k];
            piv[k] = piv[p];
            piv[p] = t;
            for (j = 0; j < n; ++j) {
                double x = a[(size_t)k * (size_t)n + (size_t)j];
                a[(size_t)k * (size_t)n + (size_t)j] = a[(size_t)p * (size_t)n + (size_t)j];
                a[(size_t)p * (size_t)n + (size_t)j] = x;
            }
        }
        for (i = k + 1; i < n; ++i) {
            double *ri = &a[(size_t)i * (size_t)n], f = ri[k] / a[(size_t)k * (size_t)n + (size_t)k];
            ri[k] = f;
            if (f == 0.0) continue;
            for (j = k + 1; j < n; ++j) ri[j] -= f * a[(size_t)k * (size_t)n + (size_t)j];
        }
    }
    return 1;
}

/* x of L U x = b in the row order piv (b is not changed). */
static void lu_solve(const double *a, int n, const int *piv, const double *b, double *x)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        double r = b[piv[i]];
        for (j = 0; j < i; ++j) r -= a[(size_t)i * (size_t)n + (size_t)j] * x[j];
        x[i] = r;
    }
    for (i = n - 1; i >= 0; --i) {
        double r = x[i];
        for (j = i + 1; j < n; ++j) r -= a[(size_t)i * (size_t)n + (size_t)j] * x[j];
        x[i] = r / a[(size_t)i * (size_t)n + (size_t)i];
    }
}

/* A point's state in the active-set solve. */
enum { N_OFF = 0, N_ON = 1 };
enum { T_ZERO = 0, T_STICK = 1, T_HI = 2, T_LO = 3 };

/* The friction bounds' coefficients: lambda_t in [-cl lambda_n, ch lambda_n] (contact_solver.h: a point
 * that slipped along +t at the start has no upper part of the cone, along -t no lower part). */
static void cone(const lc_contact_row *r, double *cl, double *ch)
{
    *cl = r->slip < 0 ? 0.0 : r->mu;
    *ch = r->slip > 0 ? 0.0 : r->mu;
}

/* Unknown i's condition failed at the answer x: a normal row turns on (sticking) or off; a sticking
 * friction row goes to the bound it crossed; a row on a bound whose slip turned sticks. */
static void change_state(const lc_contact_row *rows, int m, const double *x, int i, int *ns_, int *ts)
{
    int p = i < m ? i : i - m;
    double cl, ch;
    if (i < m) {
        ns_[p] = ns_[p] == N_ON ? N_OFF : N_ON;
        ts[p] = ns_[p] == N_ON && rows[p].mu > 0.0 ? T_STICK : T_ZERO;
    } else if (ts[p] == T_STICK) {
        cone(&rows[p], &cl, &ch);
        ts[p] = x[i] > ch * x[p] ? T_HI : T_LO;
    } else {
        ts[p] = T_STICK;
    }
}

int lc_contact_solve_active_set(lc_contact_row *rows, int nrows, double *v, const double *inv_mass,
                                const double *inv_inertia, double *scratch)
{
    /* the relative regularization of A's diagonal the exact solver starts with: dependent points (each
     * corner of a face on a face twice) leave A singular */
    const double reg = 1e-10;
    int m = nrows, n = 2 * m, i, j, k, it, best = -1, stale = 0;
    double *A = scratch, *E = A + (size_t)n * (size_t)n, *F = E + (size_t)n * (size_t)n, *q = F + (size_t)n * (size_t)n;
    double *rhs = q + n, *x = rhs + n, *u = x + n, *res = u + n, *dx = res + n, scale = 0.0;
    int *ns_ = (int *)(dx + n), *ts = ns_ + m, *bad = ts + m, *piv = bad + n;
    lc_contact_delassus(rows, m, inv_mass, inv_inertia, A);
    for (i = 0; i < m; ++i) {
        double un, ut, cl, ch, ln = rows[i].lambda_n, lt = rows[i].lambda_t;
        lc_contact_row_velocity(&rows[i], v, &un, &ut);
        q[i] = un - rows[i].target_n;
        q[m + i] = ut;
        scale = fmax(scale, fmax(fabs(q[i]), fabs(ut)));
        cone(&rows[i], &cl, &ch);
        ns_[i] = ln > 0.0 ? N_ON : N_OFF;
        if (!(ln > 0.0) || !(rows[i].mu > 0.0)) ts[i] = T_ZERO;
        else if (ch > 0.0 ? lt >= ch * ln * (1.0 - 1e-9) : lt >= 0.0) ts[i] = T_HI;
        else if (cl > 0.0 ? lt <= -cl * ln * (1.0 - 1e-9) : lt <= 0.0) ts[i] = T_LO;
        else ts[i] = T_STICK;
    }
    for (it = 0;; ++it) {
        int count = 0, last = -1;
        /* one equation per unknown: a velocity condition of an active row, or a bound; E x = rhs */
        for (i = 0; i < n; ++i) {
            double *row = &E[(size_t)i * (size_t)n];
            int p = i < m ? i : i - m, velocity;
            for (j = 0; j < n; ++j) row[j] = 0.0;
            velocity = i < m ? ns_[p] == N_ON : ns_[p] == N_ON && ts[p] == T_STICK;
            rhs[i] = 0.0;
            if (velocity) {
                for (j = 0; j < n; ++j) row[j] = A[(size_t)i * (size_t)n + (size_t)j];
                rhs[i] = -q[i];
            } else {
                row[i] = 1.0;
                if (i >= m && ns_[p] == N_ON && ts[p] != T_ZERO) {
                    double cl, ch;
                    cone(&rows[p], &cl, &ch);
                    row[p] = ts[p] == T_HI ? -ch : cl;   /* lambda_t = ch lambda_n, or = -cl lambda_n */
                }
            }
        }
        /* factored with A's diagonal raised by reg; the refinements against E itself remove what the
         * regularization moved, along the directions E determines */
        memcpy(F, E, (size_t)n * (size_t)n * sizeof(double));
        for (i = 0; i < n; ++i) F[(size_t)i * (size_t)n + (size_t)i] += reg * fabs(E[(size_t)i * (size_t)n + (size_t)i]);
        if (!lu_factor(F, n, piv)) return -1;
        lu_solve(F, n, piv, rhs, x);
        for (k = 0; k < LC_CONTACT_ACTIVE_SET_REFINEMENTS; ++k) {
            for (i = 0; i < n; ++i) {
                double r = rhs[i];
                for (j = 0; j < n; ++j) r -= E[(size_t)i * (size_t)n + (size_t)j] * x[j];
                res[i] = r;
            }
            lu_solve(F, n, piv, res, dx);
            for (i = 0; i < n; ++i) x[i] += dx[i];
        }
        for (i = 0; i < n; ++i) {
            double w = q[i];
            for (j = 0; j < n; ++j) w += A[(size_t)i * (size_t)n + (size_t)j] * x[j];
            u[i] = w;
        }
        /* the conditions each state leaves open, to round-off */
        for (i = 0; i < m; ++i) {
            double ln = x[i], lt = x[m + i], cl, ch, tl = 1e-12 * (1.0 + fabs(ln) + fabs(lt)), tw = 1e-12 * (1.0 + scale);
            cone(&rows[i], &cl, &ch);
            bad[i] = ns_[i] == N_ON ? !(ln >= -tl) : !(u[i] >= -tw);
            bad[m + i] = 0;
            if (ns_[i] == N_ON && ts[i] == T_STICK) bad[m + i] = !(lt <= ch * ln + tl && lt >= -cl * ln - tl);
            else if (ns_[i] == N_ON && ts[i] == T_HI) bad[m + i] = !(u[m + i] <= tw);
            else if (ns_[i] == N_ON && ts[i] == T_LO) bad[m + i] = !(u[m + i] >= -tw);
        }
        for (i = 0; i < n; ++i) count += bad[i];
        if (count == 0) break;
        if (it + 1 >= LC_CONTACT_ACTIVE_SET_ITERATIONS) return -1;
        /* every violated condition changes its state (block pivoting, Judice and Pires 1994) while that
         * cuts their number; when it has not for three rounds, only the last one does (Murty's rule) */
        if (best < 0 || count < best) {
            best = count;
            stale = 0;
        } else {
            stale++;
        }
        for (i = 0; i < n; ++i)
            if (bad[i]) {
                last = i;
                if (stale < 3) change_state(rows, m, x, i, ns_, ts);
            }
        if (stale >= 3) change_state(rows, m, x, last, ns_, ts);
    }
    for (i = 0; i < m; ++i) {
        rows[i].lambda_n = ns_[i] == N_ON && x[i] > 0.0 ? x[i] : 0.0;
        rows[i].lambda_t = ns_[i] == N_ON ? x[m + i] : 0.0;
        if (rows[i].lambda_n != 0.0 || rows[i].lambda_t != 0.0)
            lc_contact_row_apply(&rows[i], rows[i].lambda_n, rows[i].lambda_t, v, inv_mass, inv_inertia);
    }
    return it + 1;
}
