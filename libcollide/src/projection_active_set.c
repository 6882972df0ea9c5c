/* Active sets over a sparse factorization: a start for the position projection (projection_active_set.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "projection_active_set.h"
#include "sparse_ldl.h"
#include "world.h"

/* Rounds of the set: from the overlapping rows the rows their neighbours push in join in the first
 * rounds; after that dependent rows trade places and a round gains less than it costs (a settling
 * 1 000-box pile, 12 steps: 3, 4, 6, 8, 12, 20 rounds took 5.1, 4.3, 3.9, 3.3, 3.4, 4.2 G instructions,
 * callgrind). */
#ifndef LC_PROJECTION_ACTIVE_SET_ROUNDS   /* -D to measure */
#define LC_PROJECTION_ACTIVE_SET_ROUNDS 8
#endif
/* A_SS's diagonal raised by this fraction (projection_active_set.h), and the corrections of a settled
 * set's answer against the unraised rows. */
#define LC_PROJECTION_REGULARIZATION 1e-6
#define LC_PROJECTION_REFINEMENTS 2
/* A pivot below this fraction of its diagonal entry is raised to it (sparse_ldl.h). */
#define LC_PROJECTION_MIN_PIVOT 1e-13

struct lc_projection_active_set {
    lc_sparse_ldl *ldl;
    lc_buf b_elem, b_bptr, b_brows, b_ti, b_tj, b_tv, b_active, b_vec, b_disp;
};

lc_projection_active_set *lc_projection_active_set_create(void)
{
    lc_projection_active_set *ps = calloc(1, sizeof *ps);
    if (ps == NULL) return NULL;
    ps->ldl = lc_sparse_ldl_create();
    if (ps->ldl == NULL) {
        free(ps);
        return NULL;
    }
    return ps;
}

void lc_projection_active_set_destroy(lc_projection_active_set *ps)
{
    if (ps == NULL) return;
    lc_sparse_ldl_destroy(ps->ldl);
    lc_buf_free(&ps->b_elem); lc_buf_free(&ps->b_bptr); lc_buf_free(&ps->b_brows); lc_buf_free(&ps->b_ti);
    lc_buf_free(&ps->b_tj); lc_buf_free(&ps->b_tv); lc_buf_free(&ps->b_active); lc_buf_free(&ps->b_vec);
    lc_buf_free(&ps->b_disp);
    free(ps);
}

/* Row r's normal direction at its body a (side 0) or b (side 1): the 3 entries of J there. */
static void row_j(const lc_contact_row *r, int side, double j[3])
{
    double s = side == 0 ? 1.0 : -1.0;
    j[0] = s * r->nx;
    j[1] = s * r->ny;
    j[2] = s * (side == 0 ? r->rna : r->rnb);
}

/* out = A x over every row (disp: nbodies x 3 scratch). */
static void product(const lc_contact_row *rows, int m, int nbodies, const double *inv_mass, const double *inv_inertia,
                    const double *x, double *disp, double *out)
{
    int i;
    memset(disp, 0, (size_t)nbodies * 3 * sizeof(double));
    for (i = 0; i < m; ++i)
        if (x[i] != 0.0) lc_contact_row_apply(&rows[i], x[i], 0.0, disp, inv_mass, inv_inertia);
    for (i = 0; i < m; ++i) {
        double ut;
        lc_contact_row_velocity(&rows[i], disp, &out[i], &ut);
    }
}

/* A's entries, body by body (rows that share a body couple through its mass and inertia), into the
 * factorization's matrix, after its ordering. Returns 0, or -1 without memory. */
static int build_matrix(lc_projection_active_set *ps, const lc_contact_row *rows, const double *xy, int m,
                        int nbodies, const double *inv_mass, const double *inv_inertia)
{
    size_t mm = (size_t)(m > 0 ? m : 1), nb = (size_t)(nbodies > 0 ? nbodies : 1), cap = 0;
    int *elem = lc_buf_get(&ps->b_elem, 2 * mm * sizeof(int));
    int *bptr = lc_buf_get(&ps->b_bptr, (nb + 1) * sizeof(int));
    int *brows = lc_buf_get(&ps->b_brows, 2 * mm * sizeof(int));
    int *ti, *tj, i, k, p, q, nz = 0;
    double *tv;
    if (elem == NULL || bptr == NULL || brows == NULL) return -1;
    for (i = 0; i < m; ++i) {
        elem[2 * i] = rows[i].a;
        elem[2 * i + 1] = rows[i].b;
    }
    for (k = 0; k <= nbodies; ++k) bptr[k] = 0;
    for (i = 0; i < 2 * m; ++i)
        if (elem[i] >= 0) bptr[elem[i] + 1]++;
    for (k = 0; k < nbodies; ++k) {
        cap += (size_t)bptr[k + 1] * (size_t)(bptr[k + 1] + 1) / 2;
        bptr[k + 1] += bptr[k];
    }
    for (i = 0; i < m; ++i)
        for (k = 0; k < 2; ++k)
            if (elem[2 * i + k] >= 0) brows[bptr[elem[2 * i + k]]++] = 2 * i + k;
    for (k = nbodies; k > 0; --k) bptr[k] = bptr[k - 1];
    bptr[0] = 0;
    ti = lc_buf_get(&ps->b_ti, (cap > 0 ? cap : 1) * sizeof(int));
    tj = lc_buf_get(&ps->b_tj, (cap > 0 ? cap : 1) * sizeof(int));
    tv = lc_buf_get(&ps->b_tv, (cap > 0 ? cap : 1) * sizeof(double));
    if (ti == NULL || tj == NULL || tv == NULL) return -1;
    for (k = 0; k < nbodies; ++k)
        for (p = bptr[k]; p < bptr[k + 1]; ++p) {
            int ri = brows[p] / 2;
            double ji[3];
            row_j(&rows[ri], brows[p] % 2, ji);
            for (q = p; q < bptr[k + 1]; ++q) {
                double jj[3];
                row_j(&rows[brows[q] / 2], brows[q] % 2, jj);
                ti[nz] = ri;
                tj[nz] = brows[q] / 2;
                tv[nz++] = inv_mass[k] * (ji[0] * jj[0] + ji[1] * jj[1]) + inv_inertia[k] * ji[2] * jj[2];
            }
        }
    if (lc_sparse_ldl_order(ps->ldl, m, xy, elem, nbodies) != 0) return -1;
    return lc_sparse_ldl_matrix(ps->ldl, nz, ti, tj, tv);
}

int lc_projection_active_set_solve(lc_projection_active_set *ps, const lc_contact_row *rows, const double *xy,
                                   int m, int nbodies, const double *inv_mass, const double *inv_inertia,
                                   const double *b, double tol, double *lambda, double *objective)
{
    size_t mm = (size_t)(m > 0 ? m : 1);
    double *vec = lc_buf_get(&ps->b_vec, mm * 3 * sizeof(double));
    double *disp = lc_buf_get(&ps->b_disp, (size_t)(nbodies > 0 ? nbodies : 1) * 3 * sizeof(double));
    unsigned char *active = lc_buf_get(&ps->b_active, mm);
    double *reg, *x, *w, value = 0.0;
    int i, round, rounds, settled = 0;
    if (vec == NULL || disp == NULL || active == NULL) return -1;
    reg = vec;
    x = reg + m;
    w = x + m;
    if (build_matrix(ps, rows, xy, m, nbodies, inv_mass, inv_inertia) != 0) return -1;
    for (i = 0; i < m; ++i) {
        double k = 0.0;
        if (rows[i].a >= 0) k += inv_mass[rows[i].a] + rows[i].rna * rows[i].rna * inv_inertia[rows[i].a];
        if (rows[i].b >= 0) k += inv_mass[rows[i].b] + rows[i].rnb * rows[i].rnb * inv_inertia[rows[i].b];
        reg[i] = LC_PROJECTION_REGULARIZATION * k;
        active[i] = (unsigned char)(b[i] < 0.0);
        lambda[i] = 0.0;
    }
    for (round = 0; round < LC_PROJECTION_ACTIVE_SET_ROUNDS && !settled; ++round) {
        int changes = 0;
        if (lc_sparse_ldl_factor(ps->ldl, active, reg, LC_PROJECTION_MIN_PIVOT) != 0) return -1;
        for (i = 0; i < m; ++i) x[i] = active[i] ? -b[i] : 0.0;
        lc_sparse_ldl_solve(ps->ldl, x);
        product(rows, m, nbodies, inv_mass, inv_inertia, x, disp, w);
        for (i = 0; i < m; ++i) {
            lambda[i] = x[i];
            if (active[i] && x[i] < 0.0) {
                active[i] = 0;
                changes++;
            } else if (!active[i] && b[i] + w[i] < -tol) {
                active[i] = 1;
                changes++;
            }
        }
        settled = changes == 0;
    }
    rounds = round;
    /* a settled set's equations hold together: corrections through the same factor take out the raised
     * diagonal's error, a factor of its relative size each */
    for (round = 0; settled && round < LC_PROJECTION_REFINEMENTS; ++round) {
        product(rows, m, nbodies, inv_mass, inv_inertia, lambda, disp, w);
        for (i = 0; i < m; ++i) x[i] = active[i] ? -(b[i] + w[i]) : 0.0;
        lc_sparse_ldl_solve(ps->ldl, x);
        for (i = 0; i < m; ++i)
            if (active[i]) lambda[i] += x[i];
    }
    for (i = 0; i < m; ++i)
        if (!(lambda[i] > 0.0)) lambda[i] = 0.0;
    product(rows, m, nbodies, inv_mass, inv_inertia, lambda, disp, w);
    for (i = 0; i < m; ++i) value += 0.5 * lambda[i] * w[i] + b[i] * lambda[i];
    *objective = value;
    return settled ? rounds : 0;
}
