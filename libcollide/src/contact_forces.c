/* Resting contact forces (Baraff): relative normal accelerations a = A f + b with f >= 0, a >= 0,
 * f.a = 0, solved per group of touches that share moving bodies. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "tunables.h"

struct lc_contact_forces_state {
    lc_buf groups, sub;       /* the union-find and the touches in group order; one group's touches */
    lc_buf mat, vec, vec2;    /* a small group's response matrix, right-hand side and forces */
    lc_buf fric;              /* a small friction group's normal and tangent blocks */
    lc_buf rows;              /* a large group's right-hand sides, bounds and forces */
    lc_buf body;              /* per-body responses of a sparse product (count x 3) */
};

lc_contact_forces_state *lc_contact_forces_state_create(void) { return calloc(1, sizeof(lc_contact_forces_state)); }

void lc_contact_forces_state_destroy(lc_contact_forces_state *cf)
{
    if (cf == NULL) return;
    lc_buf_free(&cf->groups);
    lc_buf_free(&cf->sub);
    lc_buf_free(&cf->mat);
    lc_buf_free(&cf->vec);
    lc_buf_free(&cf->vec2);
    lc_buf_free(&cf->fric);
    lc_buf_free(&cf->rows);
    lc_buf_free(&cf->body);
    free(cf);
}

/* Union-find over body rows; static bodies never join groups (they do not transmit motion). */
static int find(int *parent, int x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* Relative acceleration along dir at a touch from the current (non-contact) accelerations:
 * dir.(a_pA - a_pB) + 2 (omega_B x dir).(v_pA - v_pB); the second term is the edge turning with
 * body B (and, for the tangent, the contact point sliding along it). */
static double free_acceleration(const lc_world *w, const double *state, const lc_touch *t, const double *acc,
                                lc_vec2 dir)
{
    const double *sa = &state[t->a * 6], *sb = &state[t->b * 6];
    const double *aa = &acc[t->a * 3], *ab = &acc[t->b * 3];
    double wa = sa[SW], wb = sb[SW];
    lc_vec2 acc_a = lc_v(0, 0), acc_b = lc_v(0, 0), va, vb;
    if (!w->is_static[t->a])
        acc_a = lc_sub(lc_add(lc_v(aa[0], aa[1]), lc_wcross(aa[2], t->ra)), lc_scale(t->ra, wa * wa));
    if (!w->is_static[t->b])
        acc_b = lc_sub(lc_add(lc_v(ab[0], ab[1]), lc_wcross(ab[2], t->rb)), lc_scale(t->rb, wb * wb));
    va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(wa, t->ra));
    vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(wb, t->rb));
    return lc_dot(dir, lc_sub(acc_a, acc_b)) + 2.0 * lc_dot(lc_wcross(wb, dir), lc_sub(va, vb));
}

static double tangential_velocity(const double *state, const lc_touch *t)
{
    const double *sa = &state[t->a * 6], *sb = &state[t->b * 6];
    lc_vec2 va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], t->ra));
    lc_vec2 vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], t->rb));
    return lc_dot(lc_tangent_of(t->n), lc_sub(va, vb));
}

/* The force tolerance of a group: tol while every touch of the group moves slower than 10
 * resting_speed (1 mm/s by default), which is what keeps a resting pile from creeping over minutes;
 * in a group in motion, LC_MOTION_TOLERANCE of its fastest touch's speed per step (v / h), but never
 * looser than LC_MOTION_TOLERANCE_CEILING of gravity's acceleration (tunables.h says why). */
static double group_tolerance(const lc_world *w, const double *state, const lc_touch *t, int m, double tol, double h)
{
    double vmax = 0.0, motion = 10.0 * w->def.resting_speed;
    double ceiling = LC_MOTION_TOLERANCE_CEILING * sqrt(w->def.gravity.x * w->def.gravity.x + w->def.gravity.y * w->def.gravity.y);
    int i;
    for (i = 0; i < m; ++i) vmax = fmax(vmax, fmax(fabs(t[i].vn), fabs(tangential_velocity(state, &t[i]))));
    return vmax > motion ? fmax(tol, fmin(ceiling, LC_MOTION_TOLERANCE * vmax / h)) : tol;
}

/* The friction box of a touch: |f_t| <= mu f_n and, while the point slips faster than resting_speed,
 * only against the slip (Coulomb friction never does positive work on a slipping point).
 * Why: the tangent row's target (stop sliding within h) is the velocity-stabilised form of static
 * friction. When the other forces already turn a slip around faster than that (a block rocking on a
 * corner: its normal force's moment), the boxed solve met the target with a friction force along
 * the slip, which does positive work: an upright block hopping on the floor (e 0.8, mu 0.5) gained
 * ~1.5e-4 J per rock and never came to rest (tests/c/test_hard_settle.c, "a hopping block"). Below
 * resting_speed the whole box stays open, so that static friction holds a resting body whose slip
 * is round-off of either sign. */
static void friction_box(const lc_world *w, const double *state, const lc_touch *t, double fn, double *lo,
                         double *hi)
{
    double slip = tangential_velocity(state, t), v = w->def.resting_speed;
    *hi = t->friction * fn;
    *lo = -*hi;
    if (slip > v) *hi = 0.0;
    else if (slip < -v) *lo = 0.0;
}

/* Tolerance of the next round's solves after round `round` (of `rounds`) changed the forces by
 * `change`: a tenth of that change (inexact block Gauss-Seidel, see solve_with_friction), never below
 * tol, and tol itself in the last round. */
static double next_round_tolerance(double tol, double change, int round, int rounds)
{
    return round + 2 < rounds ? fmax(tol, 0.1 * change) : tol;
}

/* Normal and Coulomb friction forces for a group with friction: normal rows (f >= 0) and tangent rows
 * with |f_t| <= mu f_n, the tangent target being to stop sliding within h. Solved by alternating an
 * exact normal solve (friction held fixed) with a boxed solve of the tangent rows (normal forces held
 * fixed): a resting pile, where friction is nearly zero, then gets the exact normal forces, which an
 * all-rows Gauss-Seidel approaches only slowly.
 * The alternation is a fixed-point iteration whose change shrinks by a steady ratio rho (~0.375 for a
 * box pushed sideways on the floor: its friction's moment shifts the normal forces, which shift the
 * friction). When two successive ratios agree to 10 %, the friction forces are extrapolated to the
 * limit of that geometric series, x + rho / (1 - rho) (x - x_old), clipped to the Coulomb cone, and
 * the alternation goes on from there: a box whose push had just begun slipped 5.4e-7 m/s in the first
 * step after the 8 rounds without it, 1e-17 m/s with it (tests/c/test_end_touches.c). Only the normal
 * block, which the pivoting solve needs, is formed; the coupling of normal and tangent rows goes
 * through the bodies. The pivoting starts from the active set of the touches' previous forces. */
static int solve_with_friction(lc_world *w, const double *state, lc_touch *sub, int m, double *acc,
                               double kv, double kd, double h, const lc_lcp_options *opt)
{
    int i, outer;
    double *v = lc_buf_get(&w->contact_forces->vec, (size_t)m * 10 * sizeof(double));
    double *Ann = lc_buf_get(&w->contact_forces->fric, (size_t)m * (size_t)m * sizeof(double));
    double *body = lc_buf_get(&w->contact_forces->body, (size_t)w->count * 3 * sizeof(double));
    double *b_n, *b_t, *fn, *ft, *bn, *bt, *lo, *hi, *fold, *moved, viol = 0.0;
    double prev_change = -1.0, prev_rho = -1.0, inner, change = 0.0;
    /* a hundredth of the large groups' tolerance (see solve_large_group): at 2.5e-4 contact_gap / h^2
     * a 1:1000 mass-ratio stack crept 1.6e-8 m in 60 s, at this one 3e-12 m; the settling scene (20
     * blocks, e 0.8, mu 0.5) then cost ~27 ms per step against ~10 ms at the looser one */
    double tol = group_tolerance(w, state, sub, m, 2.5e-7 * w->def.contact_gap / (h * h), h);
    lc_lcp_result res;
    if (!v || !Ann || !body) return -1;
    b_n = v; b_t = b_n + m; fn = b_t + m; ft = fn + m; bn = ft + m; bt = bn + m;
    lo = bt + m; hi = lo + m; fold = hi + m; moved = fold + m;
    inner = tol;
    lc_response_matrix(w, sub, m, Ann);
    for (i = 0; i < m; ++i) {
        const lc_touch *ti = &sub[i];
        b_n[i] = free_acceleration(w, state, ti, acc, ti->n) + kv * ti->vn + kd * (ti->gap - w->def.contact_gap);
        b_t[i] = free_acceleration(w, state, ti, acc, lc_tangent_of(ti->n)) + tangential_velocity(state, ti) / h;
        fn[i] = ti->value > 0.0 && isfinite(ti->value) ? ti->value : 0.0;   /* the pivoting's start */
        ft[i] = isfinite(ti->tangent) ? ti->tangent : 0.0;
    }
    for (outer = 0; outer < LC_FRICTION_ROUNDS_SMALL; ++outer) {
        int k;
        change = 0.0;
        lc_response_rows(w, sub, m, 1, ft, 0, body, bn);
        for (i = 0; i < m; ++i) bn[i] += b_n[i];
        lc_lcp_solve(m, Ann, bn, fn, NULL, opt, w->lcp, &res);
        w->last.contact_solve_iterations += (uint64_t)res.iterations;
        w->last.solver_work += lc_lcp_work(m, &res);
        for (i = 0; i < m; ++i) if (!(fn[i] > 0.0) || !isfinite(fn[i])) fn[i] = 0.0;
        lc_response_rows(w, sub, m, 0, fn, 1, body, bt);
        for (i = 0; i < m; ++i) {
            bt[i] += b_t[i];
            friction_box(w, state, &sub[i], fn[i], &lo[i], &hi[i]);
            if (ft[i] > hi[i]) ft[i] = hi[i];
            if (ft[i] < lo[i]) ft[i] = lo[i];
            fold[i] = ft[i];
        }
        /* the tangent rows by MPRGP (sparse_lcp.c): the tangent rows of two corners on one face are
         * parallel, so Att is singular, and projected Gauss-Seidel crept to its sweep cap there at
         * every evaluation (75 % of a settling scene's time) */
        k = lc_sparse_lcp(w, sub, m, 1, bt, lo, hi, ft, inner, 5 * w->def.lcp_max_iterations, &viol);
        if (k < 0) return -1;
        w->last.contact_solve_iterations += (uint64_t)k;
        if (viol > res.residual) res.residual = viol;
        /* done when the new friction forces no longer change what the normal rows see */
        for (i = 0; i < m; ++i) fold[i] = ft[i] - fold[i];
        lc_response_rows(w, sub, m, 1, fold, 0, body, moved);
        for (i = 0; i < m; ++i) change = fmax(change, fabs(moved[i]));
        if (change <= tol && inner <= tol) break;
        /* The next tangent solve need only be a tenth as far off as this round's change (an inexact
         * block Gauss-Seidel): solving every round to tol while the rounds themselves still moved the
         * forces by ~1 m/s^2 cost ~100 products a round in a pile in motion. The last round, and a
         * round after one that changed nothing, are solved to tol, so a converged answer is as exact
         * as before. In a pile in motion the rounds' change stays at ~1-60 m/s^2 and can grow (the
         * split of the forces among its touches is not unique, and friction at the cone feeds back
         * into the normal forces): there the alternation stops, and what it still moved is reported
         * in the residual. Settling scene (20 blocks, e 0.8, mu 0.5): 0.79 -> 0.55 ms per step, 2 614
         * -> 2 367 impacts in 10 s; stopping as soon as the change stopped shrinking by 5 % a round
         * made 3 798. */
        inner = next_round_tolerance(tol, change, outer, LC_FRICTION_ROUNDS_SMALL);
        if (prev_change > 0.0 && change >= LC_FRICTION_STALL * prev_change) break;
        /* never in the last round: its forces would leave without a solve that checks them */
        if (prev_change > 0.0 && change < prev_change && outer + 1 < LC_FRICTION_ROUNDS_SMALL) {
            double rho = change / prev_change;
            if (rho < 0.95 && fabs(rho - prev_rho) <= 0.1 * rho) {
                double to_limit = rho / (1.0 - rho);
                for (i = 0; i < m; ++i) {
                    double x = ft[i] + to_limit * fold[i];   /* fold: this round's change */
                    ft[i] = x > hi[i] ? hi[i] : x < lo[i] ? lo[i] : x;
                }
                prev_change = prev_rho = -1.0;   /* two fresh ratios before the next extrapolation */
                continue;
            }
            prev_rho = rho;
        }
        prev_change = change;
    }
    /* what the last round still moved is part of the error (at most tol when it converged) */
    if (change > res.residual) res.residual = change;
    w->last.contact_solves++;
    w->last.resting_contacts += (uint64_t)m;
    if (res.residual > w->last.max_lcp_residual) w->last.max_lcp_residual = res.residual;
    for (i = 0; i < m; ++i) {
        double f_t = isfinite(ft[i]) ? ft[i] : 0.0;
        sub[i].value = fn[i];
        sub[i].tangent = f_t;
        lc_touch_apply(w, &sub[i], lc_add(lc_scale(sub[i].n, fn[i]), lc_scale(lc_tangent_of(sub[i].n), f_t)), acc, 3);
    }
    return 0;
}

/* A large group (more touches than lcp_exact_max) by MPRGP on the sparse response (sparse_lcp.c):
 * the normal rows with the friction forces held, then, with friction, the tangent rows boxed by the
 * Coulomb cone of those normal forces, alternated until the friction forces stop changing what the
 * normal rows see (a resting pile carries little friction: one or two rounds). Warm-started from the
 * touches' previous forces, or, when none has one, from the weights they carry (static_load.c).
 * Converged when the unresolved relative acceleration would move a point by less than 2.5e-5
 * contact_gap over the step (9e-9 m/s^2 at 1/60 s): a direction nothing holds (a frictionless box
 * sideways) integrates what is left into a creep, ~t^2/2 of it. At 10x this tolerance the
 * frictionless base-20 pyramid crept 4.1e-4 m in 60 s (its bound is 1e-4 m), at this one 4.9e-5 m;
 * a warm pile needs 8-40 products per step here against 10-17 there (base 100: 0.04-0.05 s per step
 * either way: the products are no longer most of its cost). Returns products of A used, or -1. */
static int solve_large_group(lc_world *w, const double *state, lc_touch *sub, int m, const double *acc, double kv,
                             double kd, double h, int with_friction, double *resid)
{
    double *v = lc_buf_get(&w->contact_forces->rows, (size_t)m * 8 * sizeof(double));
    double *body = lc_buf_get(&w->contact_forces->body, (size_t)w->count * 3 * sizeof(double));
    double *bn, *bt, *fn, *ft, *lo, *hi, *rhs, *ft_old, tol, inner, viol = 0.0, tviol = 0.0, prev_moved = -1.0;
    int i, round, k, products = 0, budget = 5 * w->def.lcp_max_iterations;
    if (v == NULL || body == NULL) return -1;
    bn = v; bt = bn + m; fn = bt + m; ft = fn + m; lo = ft + m; hi = lo + m; rhs = hi + m; ft_old = rhs + m;
    inner = tol = group_tolerance(w, state, sub, m, 2.5e-5 * w->def.contact_gap / (h * h), h);
    for (i = 0; i < m; ++i) {
        bn[i] = free_acceleration(w, state, &sub[i], acc, sub[i].n) + kv * sub[i].vn +
                kd * (sub[i].gap - w->def.contact_gap);
        bt[i] = free_acceleration(w, state, &sub[i], acc, lc_tangent_of(sub[i].n)) + tangential_velocity(state, &sub[i]) / h;
        fn[i] = sub[i].value > 0.0 && isfinite(sub[i].value) ? sub[i].value : 0.0;
        ft[i] = with_friction && isfinite(sub[i].tangent) ? sub[i].tangent : 0.0;
    }
    /* a cold pile (no touch has a force yet): start from the weights it carries (static_load.c) */
    for (i = 0; i < m && fn[i] == 0.0; ++i) {}
    if (i == m && lc_static_load_forces(w, sub, m, fn) != 0) return -1;
    for (round = 0; round < (with_friction ? LC_FRICTION_ROUNDS : 1); ++round) {
        double moved = 0.0;
        /* normal rows, the friction forces held */
        lc_response_rows(w, sub, m, 1, ft, 0, body, rhs);
        for (i = 0; i < m; ++i) {
            rhs[i] += bn[i];
            lo[i] = 0.0;
            hi[i] = INFINITY;
        }
        k = lc_sparse_lcp(w, sub, m, 0, rhs, lo, hi, fn, inner, budget, &viol);
        if (k < 0) return -1;
        products += k;
        if (!with_friction) break;
        /* tangent rows boxed by the cone of these normal forces, the normal forces held */
        lc_response_rows(w, sub, m, 0, fn, 1, body, rhs);
        for (i = 0; i < m; ++i) {
            rhs[i] += bt[i];
            friction_box(w, state, &sub[i], fn[i], &lo[i], &hi[i]);
            ft_old[i] = ft[i];
        }
        k = lc_sparse_lcp(w, sub, m, 1, rhs, lo, hi, ft, inner, budget, &tviol);
        if (k < 0) return -1;
        products += k;
        /* how much the new friction forces change the normal rows' accelerations (ft_old: the change,
         * rhs: its effect) */
        for (i = 0; i < m; ++i) ft_old[i] = ft[i] - ft_old[i];
        lc_response_rows(w, sub, m, 1, ft_old, 0, body, rhs);
        for (i = 0; i < m; ++i) moved = fmax(moved, fabs(rhs[i]));
        if (moved <= tol && inner <= tol) break;
        /* not converged in the last round, or diverging (see solve_with_friction): stop, the change
         * left counted in the residual */
        if (round + 1 == LC_FRICTION_ROUNDS || (prev_moved > 0.0 && moved >= LC_FRICTION_STALL * prev_moved)) {
            viol = fmax(viol, moved);
            break;
        }
        prev_moved = moved;
        inner = next_round_tolerance(tol, moved, round, LC_FRICTION_ROUNDS);
    }
    for (i = 0; i < m; ++i) {
        sub[i].value = fn[i] > 0.0 && isfinite(fn[i]) ? fn[i] : 0.0;
        sub[i].tangent = with_friction && isfinite(ft[i]) ? ft[i] : 0.0;
    }
    *resid = fmax(viol, tviol);
    return products;
}

static int contact_forces(lc_world *w, const double *state, lc_touch *touches, int n, double *acc)
{
    int *parent, *order, *group, *start;
    int i, g0, rows = w->count;
    double h = w->step_dt > 0.0 ? w->step_dt : 1e-3;
    double kv = 0.0, kd = 0.0;
    lc_lcp_options opt;
    if (n == 0) return 0;
    if (w->def.stabilization == LC_STABILIZE_VELOCITY) kv = 1.0 / h;
    if (w->def.stabilization == LC_STABILIZE_VELOCITY_AND_DISTANCE) { kv = 2.0 / h; kd = 1.0 / (h * h); }
    opt = lc_lcp_default_options();
    opt.exact_max = w->def.lcp_exact_max;
    opt.max_iterations = w->def.lcp_max_iterations;
    opt.tolerance = w->def.lcp_tolerance;
    opt.regularization = 1e-12;
    /* the exact solve of a small group starts from the active set of the touches' previous forces */
    opt.warm_start = 1;

    parent = lc_buf_get(&w->contact_forces->groups, (size_t)(2 * rows + 1 + 2 * n) * sizeof(int));
    if (parent == NULL) return -1;
    order = parent + rows;
    group = order + n;
    start = group + n;
    for (i = 0; i < rows; ++i) parent[i] = i;
    for (i = 0; i < n; ++i) {
        lc_touch *t = &touches[i];
        lc_touch_update(w, state, t);
        if (!w->is_static[t->a] && !w->is_static[t->b]) {
            int ra = find(parent, t->a), rb = find(parent, t->b);
            if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        }
    }
    for (i = 0; i < n; ++i) {
        lc_touch *t = &touches[i];
        group[i] = find(parent, w->is_static[t->a] ? t->b : t->a);
    }
    /* touch indices by group (a counting sort on the group's root row: O(touches + bodies), where an
     * insertion sort was O(touches^2) for thousands of boxes each alone on a floor), in their
     * original order inside a group */
    for (i = 0; i <= rows; ++i) start[i] = 0;
    for (i = 0; i < n; ++i) start[group[i] + 1]++;
    for (i = 0; i < rows; ++i) start[i + 1] += start[i];
    for (i = 0; i < n; ++i) order[start[group[i]]++] = i;
    for (g0 = 0; g0 < n;) {
        int g1 = g0, m, j;
        double *A, *b, *f;
        lc_touch *sub;
        lc_lcp_result res;
        while (g1 < n && group[order[g1]] == group[order[g0]]) ++g1;
        m = g1 - g0;
        sub = lc_buf_get(&w->contact_forces->sub, (size_t)m * sizeof(lc_touch));
        A = lc_buf_get(&w->contact_forces->mat,
                       m > w->def.lcp_exact_max ? sizeof(double) : (size_t)m * (size_t)m * sizeof(double));
        b = lc_buf_get(&w->contact_forces->vec, (size_t)m * sizeof(double));
        f = lc_buf_get(&w->contact_forces->vec2, (size_t)m * sizeof(double));
        if (!sub || !A || !b || !f) return -1;
        for (j = 0; j < m; ++j) sub[j] = touches[order[g0 + j]];
        {
            int with_friction = 0;
            for (j = 0; j < m; ++j) if (sub[j].friction > 0.0) with_friction = 1;
            if (m > w->def.lcp_exact_max) {
                double resid;
                int products = solve_large_group(w, state, sub, m, acc, kv, kd, h, with_friction, &resid);
                if (products < 0) return -1;
                w->last.contact_solves++;
                w->last.contact_solve_iterations += (uint64_t)products;
                w->last.resting_contacts += (uint64_t)m;
                if (resid > w->last.max_lcp_residual) w->last.max_lcp_residual = resid;
                for (j = 0; j < m; ++j) {
                    lc_touch *t = &touches[order[g0 + j]];
                    t->value = sub[j].value;
                    t->tangent = sub[j].tangent;
                    lc_touch_apply(w, t, lc_add(lc_scale(t->n, t->value), lc_scale(lc_tangent_of(t->n), t->tangent)),
                                   acc, 3);
                }
                g0 = g1;
                continue;
            }
            if (with_friction) {
                if (solve_with_friction(w, state, sub, m, acc, kv, kd, h, &opt) != 0) return -1;
                for (j = 0; j < m; ++j) {
                    touches[order[g0 + j]].value = sub[j].value;
                    touches[order[g0 + j]].tangent = sub[j].tangent;
                }
                g0 = g1;
                continue;
            }
        }
        lc_response_matrix(w, sub, m, A);
        for (j = 0; j < m; ++j) {
            b[j] = free_acceleration(w, state, &sub[j], acc, sub[j].n) + kv * sub[j].vn +
                   kd * (sub[j].gap - w->def.contact_gap);
            f[j] = sub[j].value > 0.0 && isfinite(sub[j].value) ? sub[j].value : 0.0;
        }
        lc_lcp_solve(m, A, b, f, NULL, &opt, w->lcp, &res);
        w->last.contact_solves++;
        w->last.contact_solve_iterations += (uint64_t)res.iterations;
        w->last.solver_work += lc_lcp_work(m, &res);
        w->last.resting_contacts += (uint64_t)m;
        if (res.residual > w->last.max_lcp_residual) w->last.max_lcp_residual = res.residual;
        for (j = 0; j < m; ++j) {
            lc_touch *t = &touches[order[g0 + j]];
            double fj = f[j] > 0.0 && isfinite(f[j]) ? f[j] : 0.0;
            t->value = fj;
            t->tangent = 0.0;
            lc_touch_apply(w, t, lc_scale(t->n, fj), acc, 3);
        }
        g0 = g1;
    }
    return 0;
}

int lc_contact_forces(lc_world *w, const double *state, lc_touch *touches, int n, double *acc)
{
    double t0 = lc_stage_begin(w);
    int r = contact_forces(w, state, touches, n, acc);
    lc_stage_end(w, &w->last.time_contact_forces, t0);
    return r;
}
