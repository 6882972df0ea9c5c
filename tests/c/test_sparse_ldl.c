/* test_sparse_ldl: the sparse LDL^T factorization (sparse_ldl.h) and the projection's start by active sets
 * over it (projection_active_set.h).
 *  (1) A = J M^-1 J^T + 1e-3 I of a 20 x 20 grid of bodies with random contact rows (random normals,
 *      lever arms and masses) against dense Cholesky: all rows, then a random half of them (the
 *      inactive entries of x must be left as they were). Relative residual and difference <= 1e-10: the
 *      matrix's condition is ~1e4 (the 1e-3 against diagonal entries ~1-10), round-off ~1e-16 times that.
 *  (2) A column of ten boxes, each 1 mm into the one below and the lowest 1 mm into the floor, two
 *      points per face (each twice: dependent rows): the set (every row) settles in one round, and the
 *      only displacement that closes every overlap is box k lifted by (k + 1) mm, unturned and unshifted.
 *      The raised diagonal's relative 1e-6 times the column's condition (~1e3 for ten boxes of 1-10 kg)
 *      is what each of the two corrections leaves of the one before: held to 1e-9 of each lift, and every
 *      gap to 1e-12 m of 0.
 *  (3) A brick-wall pile, 12 layers of 12 boxes of random mass, each resting on two below at two points
 *      each, every box moved from contact by a random sink (up to 0.1 mm per layer below it), slide (up to
 *      0.1 mm) and turn (up to 1e-4 rad), as a flow leaves a pile (the gaps are those of rigid bodies;
 *      random gaps per row could not all be closed by any displacement): the start scores below no
 *      push, and Gauss-Seidel from it reaches the answer (1e-12 m) in fewer sweeps than from no push, to
 *      the same displacement (unique: the projection's primal is strictly convex in the mass-weighted
 *      norm) within 1e-9 m. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "contact_solver.h"
#include "projection_active_set.h"
#include "sparse_ldl.h"

/* a fixed generator (xorshift64*): the same problems on every platform */
static double uniform(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

typedef struct problem {
    int nb, m;
    lc_contact_row *rows;
    double *xy, *inv_mass, *inv_inertia;
} problem;

static void add_row(problem *p, int a, int b, double nx, double ny, double rna, double rnb, double x, double y)
{
    lc_contact_row *r = &p->rows[p->m];
    memset(r, 0, sizeof *r);
    r->a = a;
    r->b = b;
    r->nx = nx;
    r->ny = ny;
    r->rna = rna;
    r->rnb = rnb;
    p->xy[2 * p->m] = x;
    p->xy[2 * p->m + 1] = y;
    p->m++;
}

/* A = J M^-1 J^T (+ reg on the diagonal), dense, m x m */
static void dense_matrix(const problem *p, double reg, double *a)
{
    int i, j;
    double *ji = calloc((size_t)p->nb * 3, sizeof(double)), *disp = calloc((size_t)p->nb * 3, sizeof(double));
    (void)ji;
    for (j = 0; j < p->m; ++j) {
        memset(disp, 0, (size_t)p->nb * 3 * sizeof(double));
        lc_contact_row_apply(&p->rows[j], 1.0, 0.0, disp, p->inv_mass, p->inv_inertia);
        for (i = 0; i < p->m; ++i) {
            double un, ut;
            lc_contact_row_velocity(&p->rows[i], disp, &un, &ut);
            a[i * p->m + j] = un + (i == j ? reg : 0.0);
        }
    }
    free(ji);
    free(disp);
}

/* the entries of the same matrix as triplets, pair by pair of rows (dense scan: a test, not a hot path) */
static int triplets(const problem *p, const double *a, int *ti, int *tj, double *tv)
{
    int i, j, nz = 0;
    for (i = 0; i < p->m; ++i)
        for (j = i; j < p->m; ++j)
            if (a[i * p->m + j] != 0.0) {
                ti[nz] = j;   /* either triangle */
                tj[nz] = i;
                tv[nz++] = a[i * p->m + j];
            }
    return nz;
}

/* x = A_SS^-1 b_S by dense Cholesky on the rows with act[i] */
static void dense_solve(const double *a, int m, const unsigned char *act, const double *b, double *x)
{
    int *idx = malloc((size_t)m * sizeof(int)), n = 0, i, j, k;
    double *l, *y;
    for (i = 0; i < m; ++i)
        if (act[i]) idx[n++] = i;
    l = calloc((size_t)n * (size_t)n, sizeof(double));
    y = calloc((size_t)n, sizeof(double));
    for (i = 0; i < n; ++i)
        for (j = 0; j <= i; ++j) {
            double s = a[idx[i] * m + idx[j]];
            for (k = 0; k < j; ++k) s -= l[i * n + k] * l[j * n + k];
            l[i * n + j] = i == j ? sqrt(s) : s / l[j * n + j];
        }
    for (i = 0; i < n; ++i) {
        double s = b[idx[i]];
        for (k = 0; k < i; ++k) s -= l[i * n + k] * y[k];
        y[i] = s / l[i * n + i];
    }
    for (i = n - 1; i >= 0; --i) {
        double s = y[i];
        for (k = i + 1; k < n; ++k) s -= l[k * n + i] * y[k];
        y[i] = s / l[i * n + i];
    }
    for (i = 0; i < n; ++i) x[idx[i]] = y[i];
    free(idx);
    free(l);
    free(y);
}

/* nb bodies of random mass in [lo, hi] kg, inertia mass * r2, room for cap rows */
static void new_problem(problem *p, int nb, int cap, double lo, double hi, double r2, unsigned long long *seed)
{
    int i;
    p->nb = nb;
    p->m = 0;
    p->rows = calloc((size_t)cap, sizeof(lc_contact_row));
    p->xy = calloc((size_t)cap * 2, sizeof(double));
    p->inv_mass = calloc((size_t)nb, sizeof(double));
    p->inv_inertia = calloc((size_t)nb, sizeof(double));
    for (i = 0; i < nb; ++i) {
        double mass = lo + (hi - lo) * uniform(seed);
        p->inv_mass[i] = 1.0 / mass;
        p->inv_inertia[i] = 1.0 / (mass * r2);
    }
}

static void grid_problem(problem *p, int side, unsigned long long *seed)
{
    int i, j;
    new_problem(p, side * side, side * side * 6 + side, 0.5, 5.0, 1.0 / 6.0, seed);
    for (i = 0; i < side; ++i)
        for (j = 0; j < side; ++j) {
            int k = i * side + j, c;
            for (c = 0; c < 2; ++c) {
                double ang = 0.3 * (uniform(seed) - 0.5), lx = uniform(seed) - 0.5;
                /* on the body below (or the floor), and on the body to the left */
                add_row(p, k, i > 0 ? k - side : -1, sin(ang), cos(ang), lx, i > 0 ? -lx : 0.0, j + lx, i - 0.5);
                if (j > 0) add_row(p, k, k - 1, cos(ang), sin(ang), lx, -lx, j - 0.5, i + lx);
            }
        }
}

/* layers x width boxes 1 m x 0.5 m, odd layers shifted by half a box; rows on their supports (normal +y) */
static void brick_problem(problem *p, int layers, int width, unsigned long long *seed)
{
    int i, j;
    new_problem(p, layers * width, layers * width * 8, 1.0, 10.0, 1.25 / 12.0, seed);
    for (i = 0; i < layers; ++i)
        for (j = 0; j < width; ++j) {
            int k = i * width + j, q;
            double cx = j + 0.5 * (i % 2), y = 0.5 * i;
            if (i == 0) {
                add_row(p, k, -1, 0.0, 1.0, -0.5, 0.0, cx - 0.5, y - 0.25);
                add_row(p, k, -1, 0.0, 1.0, 0.5, 0.0, cx + 0.5, y - 0.25);
                continue;
            }
            for (q = 0; q < width; ++q) {
                int lower = (i - 1) * width + q;
                double lx = q + 0.5 * ((i - 1) % 2), lo = fmax(cx, lx) - 0.5, hi = fmin(cx, lx) + 0.5;
                if (hi - lo < 0.25) continue;
                /* the overlap's two ends: one a corner of this box, the other of the one below */
                add_row(p, k, lower, 0.0, 1.0, lo - cx, -(lo - lx), lo, y - 0.25);
                add_row(p, k, lower, 0.0, 1.0, hi - cx, -(hi - lx), hi, y - 0.25);
            }
        }
}

static void free_problem(problem *p)
{
    free(p->rows);
    free(p->xy);
    free(p->inv_mass);
    free(p->inv_inertia);
}

static void check_factor(void)
{
    unsigned long long seed = 0x9E3779B97F4A7C15ull;
    problem p;
    int *elem, *ti, *tj, nz, i, pass;
    double *a, *tv, *b, *x, *xd;
    unsigned char *act;
    lc_sparse_ldl *f = lc_sparse_ldl_create();
    grid_problem(&p, 20, &seed);
    a = calloc((size_t)p.m * (size_t)p.m, sizeof(double));
    dense_matrix(&p, 1e-3, a);
    ti = malloc((size_t)p.m * (size_t)p.m * sizeof(int));
    tj = malloc((size_t)p.m * (size_t)p.m * sizeof(int));
    tv = malloc((size_t)p.m * (size_t)p.m * sizeof(double));
    nz = triplets(&p, a, ti, tj, tv);
    elem = malloc((size_t)p.m * 2 * sizeof(int));
    for (i = 0; i < p.m; ++i) {
        elem[2 * i] = p.rows[i].a;
        elem[2 * i + 1] = p.rows[i].b;
    }
    b = malloc((size_t)p.m * sizeof(double));
    x = malloc((size_t)p.m * sizeof(double));
    xd = malloc((size_t)p.m * sizeof(double));
    act = malloc((size_t)p.m);
    CHECK(f != NULL && lc_sparse_ldl_order(f, p.m, p.xy, elem, p.nb) == 0 && lc_sparse_ldl_matrix(f, nz, ti, tj, tv) == 0,
          "%s", "ordering and matrix");
    for (pass = 0; pass < 2; ++pass) {
        double rmax = 0.0, dmax = 0.0, bmax = 0.0, xmax = 0.0;
        int untouched = 1, j;
        for (i = 0; i < p.m; ++i) {
            act[i] = (unsigned char)(pass == 0 || uniform(&seed) < 0.5);
            b[i] = uniform(&seed) - 0.5;
            x[i] = act[i] ? b[i] : 42.0;
            bmax = fmax(bmax, fabs(b[i]));
        }
        CHECK(lc_sparse_ldl_factor(f, act, NULL, 1e-13) == 0, "%s", "factor");
        lc_sparse_ldl_solve(f, x);
        dense_solve(a, p.m, act, b, xd);
        for (i = 0; i < p.m; ++i) {
            double r = -b[i];
            if (!act[i]) {
                if (x[i] != 42.0) untouched = 0;
                continue;
            }
            for (j = 0; j < p.m; ++j)
                if (act[j]) r += a[i * p.m + j] * x[j];
            rmax = fmax(rmax, fabs(r));
            dmax = fmax(dmax, fabs(x[i] - xd[i]));
            xmax = fmax(xmax, fabs(xd[i]));
        }
        CHECK(rmax <= 1e-10 * bmax, "pass %d: residual %.3g of |b| %.3g (%d rows, L %ld entries)", pass, rmax, bmax,
              p.m, lc_sparse_ldl_entries(f));
        CHECK(dmax <= 1e-10 * xmax, "pass %d: differs from dense Cholesky by %.3g of %.3g", pass, dmax, xmax);
        CHECK(untouched, "pass %d: %s", pass, "inactive entries left as they were");
    }
    /* nested dissection keeps L sparse: far below the dense triangle's m^2 / 2 */
    CHECK(lc_sparse_ldl_entries(f) < (long)p.m * p.m / 20, "L has %ld entries for %d rows", lc_sparse_ldl_entries(f), p.m);
    lc_sparse_ldl_destroy(f);
    free_problem(&p);
    free(a); free(ti); free(tj); free(tv); free(elem); free(b); free(x); free(xd); free(act);
}

static void gaps_after(const problem *p, const double *b, const double *lambda, double *disp, double *w)
{
    int i;
    memset(disp, 0, (size_t)p->nb * 3 * sizeof(double));
    for (i = 0; i < p->m; ++i)
        if (lambda[i] > 0.0) lc_contact_row_apply(&p->rows[i], lambda[i], 0.0, disp, p->inv_mass, p->inv_inertia);
    for (i = 0; i < p->m; ++i) {
        double un, ut;
        lc_contact_row_velocity(&p->rows[i], disp, &un, &ut);
        w[i] = b[i] + un;
    }
}

static void check_column(void)
{
    problem p;
    int k, c, rounds, i;
    double b[80], lambda[80], disp[30], w[80], value, worst = 0.0, off = 0.0, held = 0.0;
    lc_projection_active_set *ps = lc_projection_active_set_create();
    p.nb = 10;
    p.m = 0;
    p.rows = calloc(80, sizeof(lc_contact_row));
    p.xy = calloc(160, sizeof(double));
    p.inv_mass = calloc(10, sizeof(double));
    p.inv_inertia = calloc(10, sizeof(double));
    for (k = 0; k < 10; ++k) {
        p.inv_mass[k] = 1.0 / (1.0 + k);
        p.inv_inertia[k] = 12.0 / ((1.0 + k) * 1.25);
        for (c = 0; c < 4; ++c) {
            double lx = c % 2 == 0 ? -0.5 : 0.5;   /* corners, each twice */
            add_row(&p, k, k > 0 ? k - 1 : -1, 0.0, 1.0, lx, k > 0 ? -lx : 0.0, lx, k - 0.5);
            b[p.m - 1] = -1e-3;
        }
    }
    rounds = lc_projection_active_set_solve(ps, p.rows, p.xy, p.m, p.nb, p.inv_mass, p.inv_inertia, b, 1e-12, lambda,
                                            &value);
    CHECK(rounds == 1, "rounds %d", rounds);
    gaps_after(&p, b, lambda, disp, w);
    for (k = 0; k < 10; ++k) {
        worst = fmax(worst, fabs(disp[3 * k + 1] / ((k + 1) * 1e-3) - 1.0));
        off = fmax(off, fmax(fabs(disp[3 * k]), fabs(disp[3 * k + 2])));
    }
    for (i = 0; i < p.m; ++i) held = fmax(held, fabs(w[i]));
    CHECK(worst <= 1e-9, "box lifts off (k + 1) mm by a relative %.3g", worst);
    CHECK(off <= 1e-12, "sideways shift or turn %.3g", off);
    CHECK(held <= 1e-12, "gaps off 0 by up to %.3g m", held);
    CHECK(value < 0.0, "objective %.3g", value);
    lc_projection_active_set_destroy(ps);
    free_problem(&p);
}

/* sweeps of Gauss-Seidel on the projection rows from the impulses in lambda (NULL: none) to 1e-12 m;
 * the displacement into disp */
static int sweeps_from(const problem *p, const double *b, const double *lambda, double *disp)
{
    lc_contact_row *gs = calloc((size_t)p->m, sizeof(lc_contact_row));
    lc_contact_stop stop = lc_contact_stop_rule(1000000, 1e-12, 0);
    double *scratch = calloc((size_t)p->nb * 6, sizeof(double));
    lc_contact_solve s;
    int i;
    memcpy(gs, p->rows, (size_t)p->m * sizeof(lc_contact_row));
    for (i = 0; i < p->m; ++i) {
        gs[i].target_n = -b[i];
        gs[i].lambda_n = lambda != NULL ? lambda[i] : 0.0;
    }
    memset(disp, 0, (size_t)p->nb * 3 * sizeof(double));
    s = lc_contact_solver_run(gs, p->m, p->nb, disp, p->inv_mass, p->inv_inertia, &stop, scratch);
    free(gs);
    free(scratch);
    return s.residual <= 1e-12 ? s.sweeps : -1;
}

static void check_start(void)
{
    unsigned long long seed = 12345;
    problem p;
    int i, from_zero, from_start, rounds;
    double *b, *lambda, *d0, *d1, value, dmax = 0.0;
    lc_projection_active_set *ps = lc_projection_active_set_create();
    brick_problem(&p, 12, 12, &seed);
    b = calloc((size_t)p.m, sizeof(double));
    lambda = calloc((size_t)p.m, sizeof(double));
    d0 = calloc((size_t)p.nb * 3, sizeof(double));
    d1 = calloc((size_t)p.nb * 3, sizeof(double));
    for (i = 0; i < p.nb; ++i) {
        d0[3 * i] = 1e-4 * (2.0 * uniform(&seed) - 1.0);
        d0[3 * i + 1] = -1e-4 * uniform(&seed) * (1 + i / 12);
        d0[3 * i + 2] = 1e-4 * (2.0 * uniform(&seed) - 1.0);
    }
    for (i = 0; i < p.m; ++i) {
        double ut;
        lc_contact_row_velocity(&p.rows[i], d0, &b[i], &ut);
    }
    rounds = lc_projection_active_set_solve(ps, p.rows, p.xy, p.m, p.nb, p.inv_mass, p.inv_inertia, b, 1e-12, lambda,
                                            &value);
    CHECK(rounds >= 0, "rounds %d", rounds);
    from_zero = sweeps_from(&p, b, NULL, d0);
    from_start = sweeps_from(&p, b, lambda, d1);
    for (i = 0; i < p.nb * 3; ++i) dmax = fmax(dmax, fabs(d0[i] - d1[i]));
    CHECK(value < 0.0, "objective %.3g", value);
    CHECK(from_zero > 0 && from_start > 0 && from_start < from_zero, "sweeps from the start %d, from no push %d",
          from_start, from_zero);
    CHECK(dmax <= 1e-9, "displacements differ by %.3g", dmax);
    if (rounds > 0)
        printf("brick wall, %d rows: the set settled in %d rounds; Gauss-Seidel %d sweeps from the start, %d from no push\n",
               p.m, rounds, from_start, from_zero);
    else
        printf("brick wall, %d rows: the set did not settle; Gauss-Seidel %d sweeps from the start, %d from no push\n", p.m,
               from_start, from_zero);
    lc_projection_active_set_destroy(ps);
    free_problem(&p);
    free(b); free(lambda); free(d0); free(d1);
}

int main(void)
{
    check_factor();
    check_column();
    check_start();
    return CHECK_SUMMARY("test_sparse_ldl");
}
