/* Collision impulses: eq. 11 of the seed generalised to several points as a complementarity problem,
 * resolved either serially, one touching body pair at a time, or simultaneously. The wall limit is
 * A's zero inverse mass for static bodies.
 *
 * Restitution follows Poisson's hypothesis: first the compression impulse j_c that just stops every
 * approach (a = A j_c + v_n >= 0, j_c >= 0, j_c.a = 0), then (1 + e) j_c is applied. With one e per
 * problem the kinetic energy changes by -(1 - e^2)/2 j_c.A j_c <= 0, so e = 1 keeps it exactly and
 * no e can gain energy. Newton's rule on several points (a = A j + (1 + e) v_n) can: two corners of
 * a face arriving at different speeds gain up to a few percent per hit. For one point both are
 * eq. 11: j = -(1 + e) v_n / (n.A n). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "tunables.h"

struct lc_impulse_state {
    lc_buf mat, vec, vec2;    /* a dense impact's response matrix, right-hand side and impulses */
    lc_buf fric, coupled;     /* the friction rows of an impact, and which of them are coupled */
    lc_buf body;              /* per-body responses of a sparse product (count x 3) */
};

lc_impulse_state *lc_impulse_state_create(void) { return calloc(1, sizeof(lc_impulse_state)); }

void lc_impulse_state_destroy(lc_impulse_state *is)
{
    if (is == NULL) return;
    lc_buf_free(&is->mat);
    lc_buf_free(&is->vec);
    lc_buf_free(&is->vec2);
    lc_buf_free(&is->fric);
    lc_buf_free(&is->coupled);
    lc_buf_free(&is->body);
    free(is);
}

/* Approach speed (m/s) above which an impact at this touch bounces: restitution_threshold, not below
 * resting_speed. Perfectly elastic pairs (e >= 1) bounce down to resting_speed, so energy is kept
 * exactly where the scene asks for it. */
double lc_bounce_speed(const lc_world *w, double elasticity)
{
    if (elasticity >= 1.0) return w->def.resting_speed;
    return fmax(w->def.resting_speed, w->def.restitution_threshold);
}

static double bounce_speed(const lc_world *w, const lc_touch *t) { return lc_bounce_speed(w, t->elasticity); }

static double normal_velocity(const double *state, const lc_touch *t)
{
    const double *sa = &state[t->a * 6], *sb = &state[t->b * 6];
    lc_vec2 va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], t->ra));
    lc_vec2 vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], t->rb));
    return lc_dot(t->n, lc_sub(va, vb));
}

/* Impacts with Coulomb friction: the compression problem's normal rows as without friction, tangent
 * rows aim to stop the sliding, bounded by |j_t| <= mu j_n (boxed complementarity, projected
 * Gauss-Seidel). Restitution scales the normal impulse only: the tangent impulse that stopped the
 * sliding stays inside the cone (1 + e) mu j_n and is not reversed into a tangential bounce. */
static int solve_block_friction(lc_world *w, double *state, lc_touch *t, int n, const double *bn,
                                int restitute, const lc_lcp_options *opt)
{
    int n2 = 2 * n, i, k, hits = 0;
    double *A = lc_buf_get(&w->impulse->mat, (size_t)n2 * (size_t)n2 * sizeof(double));
    double *b = lc_buf_get(&w->impulse->fric, (size_t)n2 * 3 * sizeof(double));
    int *coupled = lc_buf_get(&w->impulse->coupled, (size_t)n2 * sizeof(int));
    double *j, *mu;
    lc_lcp_options o = *opt;
    lc_lcp_result res;
    if (!A || !b || !coupled) return -1;
    j = b + n2;
    mu = j + n2;
    o.max_iterations = o.max_iterations > 1000 ? o.max_iterations : 1000;
    for (i = 0; i < n2; ++i) {
        const lc_touch *ti = &t[i % n];
        lc_vec2 di = i < n ? ti->n : lc_tangent_of(ti->n);
        for (k = 0; k < n2; ++k) {
            const lc_touch *tk = &t[k % n];
            A[i * n2 + k] = lc_response_dir(w, ti, di, tk, k < n ? tk->n : lc_tangent_of(tk->n));
        }
        if (i < n) {
            b[i] = bn[i];
            coupled[i] = -1;
            mu[i] = 0.0;
        } else {
            const double *sa = &state[ti->a * 6], *sb = &state[ti->b * 6];
            lc_vec2 va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], ti->ra));
            lc_vec2 vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], ti->rb));
            b[i] = lc_dot(di, lc_sub(va, vb));
            coupled[i] = i - n;
            mu[i] = ti->friction;
        }
        j[i] = 0.0;
    }
    lc_lcp_solve_boxed(n2, A, b, NULL, NULL, coupled, mu, j, NULL, &o, w->lcp, &res);
    w->last.impulse_solves++;
    w->last.solver_work += lc_lcp_work(n2, &res);
    for (i = 0; i < n; ++i) {
        double jn = j[i] > 0.0 && isfinite(j[i]) ? j[i] : 0.0;
        double jt = isfinite(j[n + i]) ? j[n + i] : 0.0;
        if (jn <= 0.0) continue;
        jn *= 1.0 + (restitute ? t[i].elasticity : 0.0);
        lc_touch_apply(w, &t[i], lc_add(lc_scale(t[i].n, jn), lc_scale(lc_tangent_of(t[i].n), jt)), state + 3, 6);
        t[i].value += jn;
        t[i].tangent += jt;
        hits++;
    }
    return hits;
}

/* The normal rows of a large impact with the friction impulses jt held: jn (warm start and answer)
 * from MPRGP; rhs, lo, hi: scratch of n. Returns products of A used, or -1. */
static int normal_impulses(lc_world *w, const lc_touch *t, int n, const double *jt, const double *vn0, double *body,
                           double *rhs, double *lo, double *hi, double *jn, double tol, int budget, double *viol)
{
    int i;
    lc_response_rows(w, t, n, 1, jt, 0, body, rhs);
    for (i = 0; i < n; ++i) {
        rhs[i] += vn0[i];
        lo[i] = 0.0;
        hi[i] = INFINITY;
    }
    return lc_sparse_lcp(w, t, n, 0, rhs, lo, hi, jn, tol, budget, viol);
}

static void clip_to_cone(const lc_touch *t, int n, const double *jn, double *jt)
{
    int i;
    for (i = 0; i < n; ++i) {
        double c = t[i].friction * jn[i];
        jt[i] = jt[i] > c ? c : jt[i] < -c ? -c : jt[i];
    }
}

/* The impulse problem of a large group (more touches than lcp_exact_max: an impact into a pile, the
 * inelastic pass closing a jam) by MPRGP on the sparse response (sparse_lcp.c): O(touches) memory and
 * work per product instead of a dense n x n matrix (7000 touches of a base-50 pyramid: 392 MB). Same
 * model as the small problem: compression impulses, the tangent rows (stopping the sliding within
 * |j_t| <= mu j_n) alternated with the normal ones, then (1 + e) times the normal ones. Converged when
 * no point is left approaching faster than a thousandth of resting_speed, well inside what the
 * resting test treats as at rest. */
static int solve_block_sparse(lc_world *w, double *state, lc_touch *t, int n, int restitute)
{
    double *v = lc_buf_get(&w->impulse->fric, (size_t)n * 8 * sizeof(double));
    double *body = lc_buf_get(&w->impulse->body, (size_t)w->count * 3 * sizeof(double));
    double *jn, *jt, *vn0, *vt0, *lo, *hi, *rhs, *jt_old, tol, viol = 0.0;
    int i, round, k, hits = 0, with_friction = 0, budget = 5 * w->def.lcp_max_iterations;
    if (v == NULL || body == NULL) return -1;
    jn = v; jt = jn + n; vn0 = jt + n; vt0 = vn0 + n; lo = vt0 + n; hi = lo + n; rhs = hi + n; jt_old = rhs + n;
    tol = 1e-3 * w->def.resting_speed;
    for (i = 0; i < n; ++i) {
        const double *sa = &state[t[i].a * 6], *sb = &state[t[i].b * 6];
        lc_vec2 rel = lc_sub(lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], t[i].ra)),
                             lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], t[i].rb)));
        jn[i] = jt[i] = 0.0;
        vn0[i] = lc_dot(t[i].n, rel);
        vt0[i] = lc_dot(lc_tangent_of(t[i].n), rel);
        if (t[i].friction > 0.0) with_friction = 1;
    }
    for (round = 0; round < (with_friction ? LC_IMPULSE_FRICTION_ROUNDS : 1); ++round) {
        double moved = 0.0;
        if (normal_impulses(w, t, n, jt, vn0, body, rhs, lo, hi, jn, tol, budget, &viol) < 0) return -1;
        if (!with_friction) break;
        lc_response_rows(w, t, n, 0, jn, 1, body, rhs);
        for (i = 0; i < n; ++i) {
            rhs[i] += vt0[i];
            hi[i] = t[i].friction * jn[i];
            lo[i] = -hi[i];
            jt_old[i] = jt[i];
        }
        k = lc_sparse_lcp(w, t, n, 1, rhs, lo, hi, jt, tol, budget, &viol);
        if (k < 0) return -1;
        for (i = 0; i < n; ++i) jt_old[i] = jt[i] - jt_old[i];   /* the change, and in rhs its effect */
        lc_response_rows(w, t, n, 1, jt_old, 0, body, rhs);
        for (i = 0; i < n; ++i) moved = fmax(moved, fabs(rhs[i]));
        if (moved <= tol) break;
        if (round + 1 == LC_IMPULSE_FRICTION_ROUNDS) {
            /* Not converged (the alternation can crawl at a ratio of ~0.97 a round in a pile, whose
             * split of forces among its touches is not unique): the normal rows once more, with the
             * friction impulses clipped to the cone and held. Otherwise points are left approaching,
             * ~1 % of the impact speed, and each becomes another impact of the whole pile at the same
             * instant: a 5 kg box at 8 m/s into a frictional 78-box pyramid made 67 impacts in its
             * step, 38 with this. The last clip, to the cone of the final normal impulses, leaves a
             * far smaller approach. */
            clip_to_cone(t, n, jn, jt);
            if (normal_impulses(w, t, n, jt, vn0, body, rhs, lo, hi, jn, tol, budget, &viol) < 0) return -1;
            clip_to_cone(t, n, jn, jt);
        }
    }
    w->last.impulse_solves++;
    for (i = 0; i < n; ++i) {
        double j = jn[i] > 0.0 && isfinite(jn[i]) ? jn[i] : 0.0, tj = isfinite(jt[i]) ? jt[i] : 0.0;
        if (j <= 0.0) continue;
        j *= 1.0 + (restitute ? t[i].elasticity : 0.0);
        lc_touch_apply(w, &t[i], lc_add(lc_scale(t[i].n, j), lc_scale(lc_tangent_of(t[i].n), tj)), state + 3, 6);
        t[i].value += j;
        t[i].tangent += tj;
        hits++;
    }
    return hits;
}

/* Solves the impulse problem for touches t[0..n) and applies it: restitution (use_e) by Poisson's
 * rule, e = 0 when no point approaches faster than its bounce_speed. A block settling at e = 0.8
 * otherwise bounces ever smaller (the seed's Zeno "stuck" case) through every speed down to
 * resting_speed: ~20 more impacts per settling corner, each a time-of-impact search, for bounces no
 * higher than (e v)^2 / 2g = 3.3e-6 m below 1e-2 m/s. Returns the number of points that received a
 * positive impulse, or -1. */
static int solve_block(lc_world *w, double *state, lc_touch *t, int n, int use_e)
{
    double *A, *b, *j;
    lc_lcp_options opt;
    lc_lcp_result res;
    int i, hits = 0, with_friction = 0, restitute = 0;
    if (n > w->def.lcp_exact_max) {
        for (i = 0; i < n && !restitute; ++i)
            if (use_e && normal_velocity(state, &t[i]) < -bounce_speed(w, &t[i])) restitute = 1;
        return solve_block_sparse(w, state, t, n, restitute);
    }
    A = lc_buf_get(&w->impulse->mat, (size_t)n * (size_t)n * sizeof(double));
    b = lc_buf_get(&w->impulse->vec, (size_t)n * sizeof(double));
    j = lc_buf_get(&w->impulse->vec2, (size_t)n * sizeof(double));
    if (!A || !b || !j) return -1;
    opt = lc_lcp_default_options();
    opt.exact_max = w->def.lcp_exact_max;
    opt.max_iterations = w->def.lcp_max_iterations;
    opt.tolerance = w->def.lcp_tolerance;
    opt.regularization = 1e-12;
    lc_response_matrix(w, t, n, A);
    for (i = 0; i < n; ++i) {
        b[i] = normal_velocity(state, &t[i]);
        if (use_e && b[i] < -bounce_speed(w, &t[i])) restitute = 1;
        if (t[i].friction > 0.0) with_friction = 1;
        j[i] = 0.0;
    }
    if (with_friction) return solve_block_friction(w, state, t, n, b, restitute, &opt);
    if (n == 1) {
        j[0] = b[0] < 0.0 && A[0] > 0.0 ? -b[0] / A[0] : 0.0;
        memset(&res, 0, sizeof res);
        res.iterations = res.pivots = 1;
    } else {
        lc_lcp_solve(n, A, b, j, NULL, &opt, w->lcp, &res);
    }
    w->last.impulse_solves++;
    w->last.solver_work += lc_lcp_work(n, &res);
    for (i = 0; i < n; ++i) {
        double ji = j[i] > 0.0 && isfinite(j[i]) ? j[i] : 0.0;
        if (ji <= 0.0) continue;
        ji *= 1.0 + (restitute ? t[i].elasticity : 0.0);
        lc_touch_apply(w, &t[i], lc_scale(t[i].n, ji), state + 3, 6);
        t[i].value += ji;
        hits++;
    }
    return hits;
}

/* Whether any touch of an impact (vn up to date) approaches fast enough to bounce. */
static int any_bounce(const lc_world *w, const lc_touch *t, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (t[i].elasticity > 0.0 && t[i].vn < -bounce_speed(w, &t[i])) return 1;
    return 0;
}

static int same_pair(const lc_touch *x, const lc_touch *y)
{
    return (x->a == y->a && x->b == y->b) || (x->a == y->b && x->b == y->a);
}

int lc_resolve_impacts(lc_world *w, double *state, lc_touch *t, int n, int elastic)
{
    int i, hits = 0, iter;
    /* a tiny fraction of the approach speed counts as "still approaching": round-off, not physics */
    double vmax = 0.0, eps;
    if (n == 0) return 0;
    for (i = 0; i < n; ++i) {
        lc_touch_update(w, state, &t[i]);
        t[i].vn_pre = t[i].vn;
        t[i].value = 0.0;
        t[i].tangent = 0.0;
        if (-t[i].vn > vmax) vmax = -t[i].vn;
    }
    eps = 1e-12 * (1.0 + vmax);
    if (w->def.impact_mode == LC_IMPACT_SIMULTANEOUS) {
        int k = solve_block(w, state, t, n, elastic);
        if (k < 0) return -1;
        hits += k;
    } else if (n > w->def.lcp_exact_max && !(elastic && any_bounce(w, t, n))) {
        /* A large impact in which no point bounces (into a pile at e = 0, or slower than
         * restitution_threshold): the serial passes are Gauss-Seidel on the very problem that the
         * simultaneous inelastic solve answers, and in a pile they ran to their cap (~4 per pair)
         * before that solve closed the impact anyway. A 5 kg box dropped into a frictional base-12
         * pyramid spent 21 000-50 000 passes a step that way, until a step was undone at the step's
         * cap of 50 000 (bench/repro/drop_into_pyramid.py). */
        int k = solve_block(w, state, t, n, 0);
        if (k < 0) return -1;
        hits += k;
    } else {
        /* A pair resolved over and over is a jam (blocks pressed together, a resting pile), not a
         * propagating impact: after a few passes per pair the inelastic simultaneous pass closes it. */
        int pairs = 1, cap;
        for (i = 1; i < n; ++i) if (!same_pair(&t[i], &t[i - 1])) ++pairs;
        cap = 4 * pairs + 16;
        if (cap > w->def.max_serial_iterations) cap = w->def.max_serial_iterations;
        for (iter = 0; iter < cap; ++iter) {
            int worst = -1, start, end, k;
            double vworst = -eps;
            for (i = 0; i < n; ++i) {
                double vn = normal_velocity(state, &t[i]);
                if (vn < vworst) { vworst = vn; worst = i; }
            }
            if (worst < 0) break;
            /* the touches of one body pair are contiguous (collected per pair): resolve them together,
             * so a flat face landing on two corners gets one symmetric impulse and no spin */
            start = end = worst;
            while (start > 0 && same_pair(&t[start - 1], &t[worst])) --start;
            while (end + 1 < n && same_pair(&t[end + 1], &t[worst])) ++end;
            w->last.serial_iterations++;
            k = solve_block(w, state, t + start, end - start + 1, elastic);
            if (k < 0) return -1;
            hits += k;
            if (k == 0) break;   /* the solver found nothing to do: avoid spinning */
        }
        if (iter == cap) {
            /* e.g. e = 1 between bodies wedged against each other: close the event inelastically */
            int k = solve_block(w, state, t, n, 0);
            if (k < 0) return -1;
            hits += k;
            w->last.inelastic_fallbacks++;
        }
    }
    return hits;
}
