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
#include <string.h>
#include "world.h"

/* Proportioning constant: release bound rows when their chopped gradient outweighs the free one. */
#define LC_MPRGP_GAMMA 1.0
/* Power iterations that estimate ||A|| for the expansion step length: from scratch, and when the
 * previous solve had as many rows (the same pile a moment later). Then its estimate is used as it is
 * and refreshed (kept if larger) only before the solve's first expansion step, the one place a low
 * estimate could do harm: a warm-started pile's solve usually takes none, and the refresh was 6 of
 * its 10 products. */
#define LC_MPRGP_POWER_ITERATIONS 12
#define LC_MPRGP_POWER_REFRESH 3

/* clamps without libm calls (fmin/fmax keep NaN rules and are not inlined): x is finite here */
static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

static lc_vec2 row_dir(const lc_touch *t, int tangent)
{
    return tangent ? lc_tangent_of(t->n) : t->n;
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
static double norm_estimate(const lc_world *w, const lc_touch *t, int m, int tangent, int iterations, double *v,
                            double *av, double *body)
{
    double lambda = 0.0, nv;
    int i, k;
    for (i = 0; i < m; ++i) v[i] = 1.0 + 0.001 * (double)(((unsigned)i * 2654435761u) % 1000u);
    for (k = 0; k < iterations; ++k) {
        nv = sqrt(dot(v, v, m));
        if (!(nv > 0.0)) break;
        for (i = 0; i < m; ++i) v[i] /= nv;
        lc_response_rows(w, t, m, tangent, v, tangent, body, av);
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
static double gradients(const double *x, const double *g, const double *lo, const double *hi, int m, double alpha,
                        double *phi, double *beta, double *bb, double *pp)
{
    double worst = 0.0, sb = 0.0, sp = 0.0;
    int i;
    for (i = 0; i < m; ++i) {
        double gi = g[i];
        phi[i] = beta[i] = 0.0;
        if (!(lo[i] < hi[i])) {
            continue;   /* a fixed row (friction of a touch without normal force): never moves */
        } else if (is_free(x[i], lo[i], hi[i])) {
            double room = gi > 0.0 ? (x[i] - lo[i]) / alpha : (x[i] - hi[i]) / alpha;
            double cut = gi > 0.0 ? (room < gi ? room : gi) : (room > gi ? room : gi);
            phi[i] = gi;
            sp += cut * gi;
        } else if (x[i] <= lo[i]) {
            beta[i] = gi < 0.0 ? gi : 0.0;
        } else {
            beta[i] = gi > 0.0 ? gi : 0.0;
        }
        sb += beta[i] * beta[i];
        if (fabs(phi[i] + beta[i]) > worst) worst = fabs(phi[i] + beta[i]);
    }
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
    double *body = lc_buf_get(&w->b_sparse_body, (size_t)w->count * 3 * sizeof(double));
    double *g = lc_buf_get(&w->b_sparse, (size_t)m * 6 * sizeof(double));
    double *p, *ap, *phi, *beta, *d, alpha, lambda, worst, bb, pp;
    int i, products = 0, restarted = 0, refreshed = 0;
    if (body == NULL || g == NULL) return -1;
    if (m == 0) {
        *violation = 0.0;
        return 0;
    }
    p = g + m;
    ap = p + m;
    phi = ap + m;
    beta = phi + m;
    d = beta + m;
    if (w->sparse_norm_rows[tangent != 0] == m) {
        lambda = w->sparse_norm[tangent != 0];
    } else {
        lambda = norm_estimate(w, t, m, tangent, LC_MPRGP_POWER_ITERATIONS, p, ap, body);
        products += LC_MPRGP_POWER_ITERATIONS;
        refreshed = 1;
        w->sparse_norm[tangent != 0] = lambda;
        w->sparse_norm_rows[tangent != 0] = m;
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
        return products;
    }
    /* the expansion step length: Dostal's bound is 2/||A||; the power estimate is from below (a few
     * per cent after 12 iterations), so 1.8 of it keeps within the bound */
    alpha = 1.8 / lambda;
    for (i = 0; i < m; ++i) {
        if (!isfinite(x[i])) x[i] = 0.0;
        x[i] = fmin(fmax(x[i], lo[i]), hi[i]);
    }
    lc_response_rows(w, t, m, tangent, x, tangent, body, g);
    products++;
    for (i = 0; i < m; ++i) g[i] += b[i];
    worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
    memcpy(p, phi, (size_t)m * sizeof(double));
    while (worst > tol && products < max_products) {
        if (bb <= LC_MPRGP_GAMMA * LC_MPRGP_GAMMA * pp) {
            double pap, acg, af;
            lc_response_rows(w, t, m, tangent, p, tangent, body, ap);
            products++;
            pap = dot(p, ap, m);
            if (!(pap > 0.0)) {
                /* p in the null space of A (redundant contacts): restart once from the free gradient */
                if (restarted) break;
                restarted = 1;
                memcpy(p, phi, (size_t)m * sizeof(double));
                continue;
            }
            restarted = 0;
            acg = dot(g, p, m) / pap;
            af = feasible_step(x, p, lo, hi, m);
            if (acg <= af) {
                double gamma;
                for (i = 0; i < m; ++i) {
                    /* within the feasible step: the clamp only takes off round-off past a bound */
                    x[i] = clamp(x[i] - acg * p[i], lo[i], hi[i]);
                    g[i] -= acg * ap[i];
                }
                worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
                gamma = dot(phi, ap, m) / pap;
                for (i = 0; i < m; ++i) p[i] = phi[i] - gamma * p[i];
            } else {
                /* expansion: up to the bound, then a projected gradient step with the fixed length */
                for (i = 0; i < m; ++i) {
                    x[i] = clamp(x[i] - af * p[i], lo[i], hi[i]);
                    g[i] -= af * ap[i];
                }
                if (!refreshed) {   /* p and ap are free until p is reset below */
                    double fresh = norm_estimate(w, t, m, tangent, LC_MPRGP_POWER_REFRESH, p, ap, body);
                    products += LC_MPRGP_POWER_REFRESH;
                    refreshed = 1;
                    if (fresh > lambda && isfinite(fresh)) {
                        lambda = fresh;
                        alpha = 1.8 / lambda;
                        w->sparse_norm[tangent != 0] = lambda;
                    }
                }
                worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
                for (i = 0; i < m; ++i) x[i] = clamp(x[i] - alpha * phi[i], lo[i], hi[i]);
                lc_response_rows(w, t, m, tangent, x, tangent, body, g);
                products++;
                for (i = 0; i < m; ++i) g[i] += b[i];
                worst = gradients(x, g, lo, hi, m, alpha, phi, beta, &bb, &pp);
                memcpy(p, phi, (size_t)m * sizeof(double));
            }
        } else {
            /* proportioning: move the rows that their bound holds against their gradient */
            double dad, step, cap;
            memcpy(d, beta, (size_t)m * sizeof(double));
            lc_response_rows(w, t, m, tangent, d, tangent, body, ap);
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
    *violation = worst;
    return products;
}
