/* Large contact groups (a pile): the bound-constrained problem
 *     min 1/2 x'Ax + b'x   over lo <= x <= hi,   A = J M^-1 J' (PSD, never formed),
 * i.e. the LCP  y = Ax + b,  x at lo with y >= 0, at hi with y <= 0, or strictly between with y = 0,
 * solved by MPRGP (Dostal, "Optimal Quadratic Programming Algorithms", 2009, ch. 8): conjugate
 * gradients on the free rows, with gradient-projection expansion steps when a row hits a bound and
 * proportioning steps that release rows whose bound holds them wrongly. Its rate follows
 * sqrt(cond A) where Gauss-Seidel's follows cond A: a pile n layers high has cond A ~ n^2, so a
 * 50-layer pyramid converges in a few hundred products instead of tens of thousands of sweeps.
 * A product A x costs O(rows + bodies): each row's push is spread onto its two bodies, then read
 * back along each row's direction (response.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "snapshot_io.h"
#include "world.h"
#include "tunables.h"

struct lc_sparse_lcp_state {
    lc_buf vectors, body, rows;  /* a solve's vectors, the bodies' responses of a product, its rows */
    /* the last ||A|| estimate of normal [0] and tangent [1] rows, and their row count: a pile's A changes
     * little from one solve to the next, whichever module solves (contact forces, projections, the
     * contact regime), so the estimate is the module's, kept across solves */
    double norm[2];
    int norm_rows[2];
};

lc_sparse_lcp_state *lc_sparse_lcp_state_create(void) { return calloc(1, sizeof(lc_sparse_lcp_state)); }

void lc_sparse_lcp_state_destroy(lc_sparse_lcp_state *sp)
{
    if (sp == NULL) return;
    lc_buf_free(&sp->vectors);
    lc_buf_free(&sp->body);
    lc_buf_free(&sp->rows);
    free(sp);
}

/* Entries of A = J M^-1 J^T one row of a product visits: a touch's row of J has 6 (3 per body), read
 * once in J^T x and once in J; the unit of lc_counters.solver_work (a dense pivot visits m per row). */
#define LC_SPARSE_ROW_ENTRIES 12u


/* clamps without libm calls (fmin/fmax keep NaN rules and are not inlined): x is finite here */
static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static lc_vec2 row_dir(const lc_touch *t, int tangent)
{
    return tangent ? lc_tangent_of(t->n) : t->n;
}

/* A row of A as a solve's products need it: its direction, its bodies' offsets in the 3-per-body
 * response array (a3, b3; -1 for a static body), lever arms and inverse mass and inertia. A solve
 * takes up to thousands of products of the same rows; reading these from one compact array instead of
 * the touches, is_static, inv_mass and inv_inertia halves the loads of a product (the fuzz harness's
 * time is 60 % in this solver, under AddressSanitizer, which checks every load). */
typedef struct sparse_row {
    lc_vec2 d, ra, rb;
    double ima, iia, imb, iib;
    int a3, b3;
} sparse_row;

static void prepare_rows(const lc_world *w, const lc_touch *t, int m, int tangent, sparse_row *r)
{
    int i;
    for (i = 0; i < m; ++i) {
        r[i].d = row_dir(&t[i], tangent);
        r[i].ra = t[i].ra;
        r[i].rb = t[i].rb;
        r[i].a3 = w->is_static[t[i].a] ? -1 : t[i].a * 3;
        r[i].b3 = w->is_static[t[i].b] ? -1 : t[i].b * 3;
        r[i].ima = w->inv_mass[t[i].a];
        r[i].iia = w->inv_inertia[t[i].a];
        r[i].imb = w->inv_mass[t[i].b];
        r[i].iib = w->inv_inertia[t[i].b];
    }
}

/* out = A x over the prepared rows: lc_response_rows (response.c) with the same arithmetic in the same
 * order, so bit for bit its answer. body: 3 doubles per body of the world, scratch. */
static void product(const lc_world *w, const sparse_row *r, int m, const double *x, double *body, double *out)
{
    int i;
    if (2 * m < w->count) {
        for (i = 0; i < m; ++i) {
            if (r[i].a3 >= 0) memset(&body[r[i].a3], 0, 3 * sizeof(double));
            if (r[i].b3 >= 0) memset(&body[r[i].b3], 0, 3 * sizeof(double));
        }
    } else {
        memset(body, 0, (size_t)w->count * 3 * sizeof(double));
    }
    for (i = 0; i < m; ++i) {
        lc_vec2 push;
        if (x[i] == 0.0) continue;
        push = lc_scale(r[i].d, x[i]);
        if (r[i].a3 >= 0) {
            double *d = &body[r[i].a3];
            d[0] += push.x * r[i].ima;
            d[1] += push.y * r[i].ima;
            d[2] += lc_cross(r[i].ra, push) * r[i].iia;
        }
        if (r[i].b3 >= 0) {
            double *d = &body[r[i].b3];
            d[0] -= push.x * r[i].imb;
            d[1] -= push.y * r[i].imb;
            d[2] -= lc_cross(r[i].rb, push) * r[i].iib;
        }
    }
    for (i = 0; i < m; ++i) {
        double v = 0.0;
        if (r[i].a3 >= 0) {
            const double *a = &body[r[i].a3];
            v += lc_dot(r[i].d, lc_add(lc_v(a[0], a[1]), lc_wcross(a[2], r[i].ra)));
        }
        if (r[i].b3 >= 0) {
            const double *b = &body[r[i].b3];
            v -= lc_dot(r[i].d, lc_add(lc_v(b[0], b[1]), lc_wcross(b[2], r[i].rb)));
        }
        out[i] = v;
    }
}

static double dot(const double *x, const double *y, int m)
{
    double s = 0.0;
    int i;
    for (i = 0; i < m; ++i) s += x[i] * y[i];
    return s;
}

/* Largest eigenvalue of A, from below (power iteration). The start has unequal entries: the
 * all-ones vector can lie in A's null space (two opposite rows on one pair of bodies). */
static double norm_estimate(const lc_world *w, const sparse_row *r, int m, int iterations, double *v, double *av,
                            double *body)
{
    double lambda = 0.0, nv;
    int i, k;
    for (i = 0; i < m; ++i) v[i] = 1.0 + 0.001 * (double)(((unsigned)i * 2654435761u) % 1000u);
    for (k = 0; k < iterations; ++k) {
        nv = sqrt(dot(v, v, m));
        if (!(nv > 0.0)) break;
        for (i = 0; i < m; ++i) v[i] /= nv;
        product(w, r, m, v, body, av);
        lambda = dot(v, av, m);
        memcpy(v, av, (size_t)m * sizeof(double));
    }
    return lambda;
}

static int is_free(double x, double lo, double hi)
{
    return x > lo && x < hi;
}

/* Free gradient phi, chopped gradient beta, and their squared norms; returns the largest entry of the
 * projected gradient phi + beta (the LCP's violation). With alpha > 0 also phi~.phi, where phi~ is
 * the free gradient cut to the step that would reach the bound (the proportioning test's measure). */
/* One row of gradients(): phi and beta of the row, and its part of the sums and of the violation. */
static void gradient_row(double xi, double gi, double lo, double hi, double alpha, double *phi, double *beta,
                         double *sb, double *sp, double *worst)
{
    *phi = *beta = 0.0;
    if (!(lo < hi)) {
        return;   /* a fixed row (friction of a touch without normal force): never moves */
    } else if (is_free(xi, lo, hi)) {
        double room = gi > 0.0 ? (xi - lo) / alpha : (xi - hi) / alpha;
        double cut = gi > 0.0 ? (room < gi ? room : gi) : (room > gi ? room : gi);
        *phi = gi;
        *sp += cut * gi;
    } else if (xi <= lo) {
        *beta = gi < 0.0 ? gi : 0.0;
    } else {
        *beta = gi > 0.0 ? gi : 0.0;
    }
    *sb += *beta * *beta;
    if (fabs(*phi + *beta) > *worst) *worst = fabs(*phi + *beta);
}

static double gradients(const double *x, const double *g, const double *lo, const double *hi, int m, double alpha,
                        double *phi, double *beta, double *bb, double *pp)
{
    double worst = 0.0, sb = 0.0, sp = 0.0;
    int i;
    for (i = 0; i < m; ++i) gradient_row(x[i], g[i], lo[i], hi[i], alpha, &phi[i], &beta[i], &sb, &sp, &worst);
    *bb = sb;
    *pp = sp;
    return worst;
}

/* Largest step along -d that keeps x within its bounds. */
static double feasible_step(const double *x, const double *d, const double *lo, const double *hi, int m)
{
    double a = INFINITY;
    int i;
    for (i = 0; i < m; ++i) {
        double s = INFINITY;
        if (d[i] > 0.0 && lo[i] > -INFINITY) s = (x[i] - lo[i]) / d[i];
        else if (d[i] < 0.0 && hi[i] < INFINITY) s = (x[i] - hi[i]) / d[i];
        if (s < a) a = s;
    }
    return a > 0.0 ? a : 0.0;
}

int lc_sparse_lcp(lc_world *w, const lc_touch *t, int m, int tangent, const double *b, const double *lo,
                  const double *hi, double *x, double tol, int max_products, double *violation)
{
    lc_sparse_lcp_state *sp = w->sparse_lcp;
    double *body = lc_buf_get(&sp->body, (size_t)w->count * 3 * sizeof(double));
    double *g = lc_buf_get(&sp->vectors, (size_t)m * 7 * sizeof(double));
    double *p, *ap, *phi, *beta, *d, *kept, alpha, lambda, worst, kept_worst, bb, pp;
    sparse_row *rows;
    int i, products = 0, restarted = 0, refreshed = 0;
    if (body == NULL || g == NULL) return -1;
    if (m == 0) {
        *violation = 0.0;
        return 0;
    }
    rows = lc_buf_get(&sp->rows, (size_t)m * sizeof(sparse_row));
    if (rows == NULL) return -1;
    prepare_rows(w, t, m, tangent, rows);
    p = g + m;
    ap = p + m;
    phi = ap + m;
    beta = phi + m;
    d = beta + m;
    kept = d + m;
    if (sp->norm_rows[tangent != 0] == m) {
        lambda = sp->norm[tangent != 0];
    } else {
        lambda = norm_estimate(w, rows, m, LC_MPRGP_POWER_ITERATIONS, p, ap, body);
        products += LC_MPRGP_POWER_ITERATIONS;
        refreshed = 1;
        sp->norm[tangent != 0] = lambda;
        sp->norm_rows[tangent != 0] = m;
    }
    if (!(lambda > 0.0) || !isfinite(lambda)) {
        /* a row with a positive diagonal entry: A is not 0 after all, and its largest diagonal entry
         * is a lower bound of ||A|| */
        for (i = 0; i < m; ++i) {
            double dii = lc_response_dir(w, &t[i], row_dir(&t[i], tangent), &t[i], row_dir(&t[i], tangent));
            if (dii > lambda && isfinite(dii)) lambda = dii;
        }
    }
    if (!(lambda > 0.0) || !isfinite(lambda)) {
        /* A = 0 (every row between static bodies): any x in bounds with y = b is the answer */
        for (i = 0; i < m; ++i) x[i] = b[i] > 0.0 ? lo[i] : b[i] < 0.0 ? hi[i] : fmin(fmax(x[i], lo[i]), hi[i]);
        for (i = 0; i < m; ++i) if (!isfinite(x[i])) x[i] = 0.0;
        *violation = 0.0;
        w->last.solver_work += (uint64_t)products * (uint64_t)m * LC_SPARSE_ROW_ENTRIES;
        return products;
    }
    /* the expansion step length: Dostal's bound is 2/||A||; the power estimate is from below (a few
     * per cent after 12 iterations), so 1.8 of it keeps within the bound */
    alpha = 1.8 / lambda;
    for (i = 0; i < m; ++i) {
        if (!isfinite(x[i])) x[i] = 0.0;
        x[i] = fmin(fmax(x[i], lo[i]), hi[i]);
    }
    product(w, rows, m, x, body, g);
    products++;
    for (i = 0; i < m; ++i) g[i] += b[i];
    worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
    memcpy(p, phi, (size_t)m * sizeof(double));
    memcpy(kept, x, (size_t)m * sizeof(double));
    kept_worst = worst;
    while (worst > tol && products < max_products) {
        /* kept only at halvings: a few copies per solve, not one per step */
        if (worst < 0.5 * kept_worst) {
            memcpy(kept, x, (size_t)m * sizeof(double));
            kept_worst = worst;
        } else if (!(worst <= LC_MPRGP_DIVERGED * kept_worst)) {
            break;
        }
        if (bb <= LC_MPRGP_GAMMA * LC_MPRGP_GAMMA * pp) {
            double pap, gp, acg, af;
            product(w, rows, m, p, body, ap);
            products++;
            /* p.Ap, g.p and the feasible step in one pass (each sum in the order dot() takes) */
            pap = 0.0;
            gp = 0.0;
            af = INFINITY;
            for (i = 0; i < m; ++i) {
                double si = INFINITY;
                pap += p[i] * ap[i];
                gp += g[i] * p[i];
                if (p[i] > 0.0 && lo[i] > -INFINITY) si = (x[i] - lo[i]) / p[i];
                else if (p[i] < 0.0 && hi[i] < INFINITY) si = (x[i] - hi[i]) / p[i];
                if (si < af) af = si;
            }
            if (!(af > 0.0)) af = 0.0;
            if (!(pap > 0.0)) {
                /* p in the null space of A (redundant contacts): restart once from the free gradient */
                if (restarted) break;
                restarted = 1;
                memcpy(p, phi, (size_t)m * sizeof(double));
                continue;
            }
            restarted = 0;
            acg = gp / pap;
            if (acg <= af) {
                double phap = 0.0, sb = 0.0, sp = 0.0, gamma;
                worst = 0.0;
                /* the step, the new gradients and phi.Ap in one pass (the order gradients() and dot() take) */
                for (i = 0; i < m; ++i) {
                    /* within the feasible step: the clamp only takes off round-off past a bound */
                    x[i] = clamp(x[i] - acg * p[i], lo[i], hi[i]);
                    g[i] -= acg * ap[i];
                    gradient_row(x[i], g[i], lo[i], hi[i], alpha, &phi[i], &beta[i], &sb, &sp, &worst);
                    phap += phi[i] * ap[i];
                }
                bb = sb;
                pp = sp;
                gamma = phap / pap;
                for (i = 0; i < m; ++i) p[i] = phi[i] - gamma * p[i];
            } else {
                /* expansion: up to the bound, then a projected gradient step with the fixed length */
                for (i = 0; i < m; ++i) {
                    x[i] = clamp(x[i] - af * p[i], lo[i], hi[i]);
                    g[i] -= af * ap[i];
                }
                if (!refreshed) {   /* p and ap are free until p is reset below */
                    double fresh = norm_estimate(w, rows, m, LC_MPRGP_POWER_REFRESH, p, ap, body);
                    products += LC_MPRGP_POWER_REFRESH;
                    refreshed = 1;
                    if (fresh > lambda && isfinite(fresh)) {
                        lambda = fresh;
                        alpha = 1.8 / lambda;
                        sp->norm[tangent != 0] = lambda;
                    }
                }
                worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
                for (i = 0; i < m; ++i) x[i] = clamp(x[i] - alpha * phi[i], lo[i], hi[i]);
                product(w, rows, m, x, body, g);
                products++;
                for (i = 0; i < m; ++i) g[i] += b[i];
                worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
                memcpy(p, phi, (size_t)m * sizeof(double));
            }
        } else {
            /* proportioning: move the rows that their bound holds against their gradient */
            double dad, step, cap;
            memcpy(d, beta, (size_t)m * sizeof(double));
            product(w, rows, m, d, body, ap);
            products++;
            dad = dot(d, ap, m);
            if (!(dad > 0.0)) break;
            step = dot(g, d, m) / dad;
            cap = feasible_step(x, d, lo, hi, m);
            if (step > cap) step = cap;
            for (i = 0; i < m; ++i) {
                x[i] = clamp(x[i] - step * d[i], lo[i], hi[i]);
                g[i] -= step * ap[i];
            }
            worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
            memcpy(p, phi, (size_t)m * sizeof(double));
        }
    }
    /* diverged, or the last step ran into NaN (which ends the loop by its condition) */
    if (!(worst <= LC_MPRGP_DIVERGED * kept_worst)) {
        memcpy(x, kept, (size_t)m * sizeof(double));
        worst = kept_worst;
    }
    *violation = worst;
    w->last.solver_work += (uint64_t)products * (uint64_t)m * LC_SPARSE_ROW_ENTRIES;
    return products;
}

void lc_sparse_lcp_save(const lc_sparse_lcp_state *sp, lc_writer *out)
{
    int k;
    for (k = 0; k < 2; ++k) {
        lc_put_f64(out, sp->norm[k]);
        lc_put_i32(out, sp->norm_rows[k]);
    }
}

void lc_sparse_lcp_load(lc_sparse_lcp_state *sp, lc_reader *in)
{
    int k;
    for (k = 0; k < 2; ++k) {
        sp->norm[k] = lc_get_f64(in);
        sp->norm_rows[k] = lc_get_i32(in);
    }
}
