/* Resting contact forces (Baraff): relative normal accelerations a = A f + b with f >= 0, a >= 0,
 * f.a = 0, solved per group of touches that share moving bodies. */
#include <math.h>
#include <string.h>
#include "world.h"

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

/* Normal and Coulomb friction forces for a group with friction: rows 0..m-1 normal (f >= 0), rows
 * m..2m-1 tangent with |f_t| <= mu f_n, the tangent target being to stop sliding within h. Solved by
 * alternating an exact normal solve (friction held fixed) with a boxed solve of the tangent rows
 * (normal forces held fixed): a resting pile, where friction is nearly zero, then gets the exact
 * normal forces, which an all-rows Gauss-Seidel approaches only slowly. */
static int solve_with_friction(lc_world *w, const double *state, lc_touch *sub, int m, double *acc,
                               double kv, double kd, double h, const lc_lcp_options *opt)
{
    int n2 = 2 * m, i, j, outer;
    double *A = lc_buf_get(&w->b_mat, (size_t)n2 * (size_t)n2 * sizeof(double));
    double *b = lc_buf_get(&w->b_vec, (size_t)n2 * 8 * sizeof(double));
    double *f, *Ann, *Att, *bn, *bt, *lo, *hi, *fold;
    lc_lcp_result res;
    lc_lcp_options topt = *opt;
    if (!A || !b) return -1;
    f = b + n2;              /* normal forces then tangent forces */
    bn = f + n2;             /* per-subproblem right-hand sides (m each) */
    bt = bn + m;
    lo = bt + m;
    hi = lo + m;
    fold = hi + m;
    Ann = lc_buf_get(&w->b_cfric, (size_t)m * (size_t)m * 2 * sizeof(double));
    if (!Ann) return -1;
    Att = Ann + (size_t)m * (size_t)m;
    for (i = 0; i < n2; ++i) {
        const lc_touch *ti = &sub[i % m];
        lc_vec2 di = i < m ? ti->n : lc_tangent_of(ti->n);
        for (j = 0; j < n2; ++j) {
            const lc_touch *tj = &sub[j % m];
            A[i * n2 + j] = lc_response_dir(w, ti, di, tj, j < m ? tj->n : lc_tangent_of(tj->n));
        }
        if (i < m)
            b[i] = free_acceleration(w, state, ti, acc, ti->n) + kv * ti->vn + kd * (ti->gap - w->def.contact_gap);
        else
            b[i] = free_acceleration(w, state, ti, acc, lc_tangent_of(ti->n)) + tangential_velocity(state, ti) / h;
        f[i] = i < m ? 0.0 : (isfinite(ti->tangent) ? ti->tangent : 0.0);
    }
    for (i = 0; i < m; ++i)
        for (j = 0; j < m; ++j) {
            Ann[i * m + j] = A[i * n2 + j];
            Att[i * m + j] = A[(m + i) * n2 + (m + j)];
        }
    topt.exact_max = -1;     /* the boxed rows are always iterative */
    for (outer = 0; outer < 8; ++outer) {
        double change = 0.0, scale = 0.0;
        for (i = 0; i < m; ++i) {
            bn[i] = b[i];
            for (j = 0; j < m; ++j) bn[i] += A[i * n2 + (m + j)] * f[m + j];
            fold[i] = f[i];
        }
        lc_lcp_solve(m, Ann, bn, f, NULL, opt, w->lcp, &res);
        w->last.contact_solve_iterations += (uint64_t)res.iterations;
        for (i = 0; i < m; ++i) {
            double fn = f[i] > 0.0 && isfinite(f[i]) ? f[i] : 0.0;
            bt[i] = b[m + i];
            for (j = 0; j < m; ++j) bt[i] += A[(m + i) * n2 + j] * (f[j] > 0.0 ? f[j] : 0.0);
            hi[i] = sub[i].friction * fn;
            lo[i] = -hi[i];
            if (f[m + i] > hi[i]) f[m + i] = hi[i];
            if (f[m + i] < lo[i]) f[m + i] = lo[i];
            fold[i] = fabs(fold[i] - f[i]);
        }
        topt.warm_start = 1;
        lc_lcp_solve_boxed(m, Att, bt, lo, hi, NULL, NULL, f + m, NULL, &topt, w->lcp, &res);
        w->last.contact_solve_iterations += (uint64_t)res.iterations;
        for (i = 0; i < m; ++i) {
            change = fmax(change, fold[i]);
            scale = fmax(scale, fabs(f[i]));
        }
        if (outer > 0 && change <= 1e-10 * (scale + 1e-300)) break;
    }
    w->last.contact_solves++;
    w->last.resting_contacts += (uint64_t)m;
    if (res.residual > w->last.max_lcp_residual) w->last.max_lcp_residual = res.residual;
    for (i = 0; i < m; ++i) {
        double fn = f[i] > 0.0 && isfinite(f[i]) ? f[i] : 0.0;
        double ft = isfinite(f[m + i]) ? f[m + i] : 0.0;
        sub[i].value = fn;
        sub[i].tangent = ft;
        lc_touch_apply(w, &sub[i], lc_add(lc_scale(sub[i].n, fn), lc_scale(lc_tangent_of(sub[i].n), ft)), acc, 3);
    }
    return 0;
}

/* Projected Gauss-Seidel in body space for groups above lcp_exact_max: the matrix A = J M^-1 J^T is
 * never formed; each sweep costs O(points) instead of O(points^2). With bt != NULL each point also has
 * a friction row, clamped to the Coulomb cone of its current normal force. Starts from the touches'
 * previous forces (warm start). Returns sweeps (residual in *res) or -1. */
static int solve_sparse(lc_world *w, lc_touch *t, int m, const double *b, const double *bt, double *f,
                        double *ft, double *res)
{
    double *diag = lc_buf_get(&w->b_diag, (size_t)m * 2 * sizeof(double));
    double *dacc = lc_buf_get(&w->b_dacc, (size_t)w->count * 3 * sizeof(double));
    double *diag_t, bmax = 0.0, worst = 0.0;
    int i, sweep;
    if (!diag || !dacc) return -1;
    diag_t = diag + m;
    memset(dacc, 0, (size_t)w->count * 3 * sizeof(double));
    for (i = 0; i < m; ++i) {
        const lc_touch *ti = &t[i];
        lc_vec2 tan = lc_tangent_of(ti->n);
        diag[i] = lc_response_dir(w, ti, ti->n, ti, ti->n);
        f[i] = ti->value > 0.0 && isfinite(ti->value) ? ti->value : 0.0;
        if (fabs(b[i]) > bmax) bmax = fabs(b[i]);
        if (f[i] > 0.0) lc_touch_apply(w, ti, lc_scale(ti->n, f[i]), dacc, 3);
        if (bt) {
            diag_t[i] = lc_response_dir(w, ti, tan, ti, tan);
            ft[i] = isfinite(ti->tangent) ? ti->tangent : 0.0;
            if (fabs(ft[i]) > ti->friction * f[i]) ft[i] = ft[i] > 0.0 ? ti->friction * f[i] : -ti->friction * f[i];
            if (ft[i] != 0.0) lc_touch_apply(w, ti, lc_scale(tan, ft[i]), dacc, 3);
        }
    }
    for (sweep = 1; sweep <= w->def.lcp_max_iterations; ++sweep) {
        worst = 0.0;
        for (i = 0; i < m; ++i) {
            const lc_touch *ti = &t[i];
            double a = b[i] + lc_response_push(w, ti, ti->n, dacc), fn, df;
            if (fabs(fmin(f[i], a)) > worst) worst = fabs(fmin(f[i], a));
            if (diag[i] > 0.0) {
                fn = f[i] - a / diag[i];
                if (fn < 0.0) fn = 0.0;
                df = fn - f[i];
                f[i] = fn;
                if (df != 0.0) lc_touch_apply(w, ti, lc_scale(ti->n, df), dacc, 3);
            }
            if (bt && diag_t[i] > 0.0) {
                lc_vec2 tan = lc_tangent_of(ti->n);
                double at = bt[i] + lc_response_push(w, ti, tan, dacc);
                double lim = ti->friction * f[i], fnew = ft[i] - at / diag_t[i];
                if (fnew > lim) fnew = lim;
                if (fnew < -lim) fnew = -lim;
                if (fnew != ft[i]) {
                    lc_touch_apply(w, ti, lc_scale(tan, fnew - ft[i]), dacc, 3);
                    ft[i] = fnew;
                }
            }
        }
        if (worst <= w->def.lcp_tolerance * (bmax + 1e-300)) break;
    }
    *res = worst / (bmax + 1e-300);
    return sweep > w->def.lcp_max_iterations ? w->def.lcp_max_iterations : sweep;
}

int lc_contact_forces(lc_world *w, const double *state, lc_touch *touches, int n, double *acc)
{
    int *parent, *order, *group;
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

    parent = lc_buf_get(&w->b_island, (size_t)(rows + 2 * n) * sizeof(int));
    if (parent == NULL) return -1;
    order = parent + rows;
    group = order + n;
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
        order[i] = i;
    }
    /* stable insertion sort of touch indices by group keeps the original order inside a group */
    for (i = 1; i < n; ++i) {
        int v = order[i], j = i - 1;
        while (j >= 0 && group[order[j]] > group[v]) { order[j + 1] = order[j]; --j; }
        order[j + 1] = v;
    }
    for (g0 = 0; g0 < n;) {
        int g1 = g0, m, j;
        double *A, *b, *f;
        lc_touch *sub;
        lc_lcp_result res;
        while (g1 < n && group[order[g1]] == group[order[g0]]) ++g1;
        m = g1 - g0;
        sub = lc_buf_get(&w->b_rest, (size_t)m * sizeof(lc_touch));
        A = lc_buf_get(&w->b_mat, m > w->def.lcp_exact_max ? sizeof(double) : (size_t)m * (size_t)m * sizeof(double));
        b = lc_buf_get(&w->b_vec, (size_t)m * sizeof(double));
        f = lc_buf_get(&w->b_vec2, (size_t)m * sizeof(double));
        if (!sub || !A || !b || !f) return -1;
        for (j = 0; j < m; ++j) sub[j] = touches[order[g0 + j]];
        {
            int with_friction = 0;
            for (j = 0; j < m; ++j) if (sub[j].friction > 0.0) with_friction = 1;
            if (with_friction && m > w->def.lcp_exact_max) {
                double resid, *bt = lc_buf_get(&w->b_cfric, (size_t)m * 2 * sizeof(double)), *ft;
                int sweeps;
                if (bt == NULL) return -1;
                ft = bt + m;
                for (j = 0; j < m; ++j) {
                    b[j] = free_acceleration(w, state, &sub[j], acc, sub[j].n) + kv * sub[j].vn +
                           kd * (sub[j].gap - w->def.contact_gap);
                    bt[j] = free_acceleration(w, state, &sub[j], acc, lc_tangent_of(sub[j].n)) +
                            tangential_velocity(state, &sub[j]) / h;
                }
                sweeps = solve_sparse(w, sub, m, b, bt, f, ft, &resid);
                if (sweeps < 0) return -1;
                w->last.contact_solves++;
                w->last.contact_solve_iterations += (uint64_t)sweeps;
                w->last.resting_contacts += (uint64_t)m;
                if (resid > w->last.max_lcp_residual) w->last.max_lcp_residual = resid;
                for (j = 0; j < m; ++j) {
                    lc_touch *t = &touches[order[g0 + j]];
                    double fn = f[j] > 0.0 && isfinite(f[j]) ? f[j] : 0.0, ftj = isfinite(ft[j]) ? ft[j] : 0.0;
                    t->value = fn;
                    t->tangent = ftj;
                    lc_touch_apply(w, t, lc_add(lc_scale(t->n, fn), lc_scale(lc_tangent_of(t->n), ftj)), acc, 3);
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
        if (m > w->def.lcp_exact_max) {
            double resid;
            int sweeps;
            for (j = 0; j < m; ++j)
                b[j] = free_acceleration(w, state, &sub[j], acc, sub[j].n) + kv * sub[j].vn +
                       kd * (sub[j].gap - w->def.contact_gap);
            sweeps = solve_sparse(w, sub, m, b, NULL, f, NULL, &resid);
            if (sweeps < 0) return -1;
            res.iterations = sweeps;
            res.residual = resid;
        } else {
        lc_response_matrix(w, sub, m, A);
        for (j = 0; j < m; ++j) {
            b[j] = free_acceleration(w, state, &sub[j], acc, sub[j].n) + kv * sub[j].vn +
                   kd * (sub[j].gap - w->def.contact_gap);
            f[j] = 0.0;
        }
        lc_lcp_solve(m, A, b, f, NULL, &opt, w->lcp, &res);
        }
        w->last.contact_solves++;
        w->last.contact_solve_iterations += (uint64_t)res.iterations;
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
