/* The end-of-step position projection of a contact-regime island (contact_projection.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "contact_projection.h"
#include "projection_active_set.h"
#include "tunables.h"

struct lc_contact_projection {
    lc_projection_active_set *direct; /* the start of large passes */
    lc_buf b_rows;                    /* a pass's solver rows */
    lc_buf b_mprgp;                   /* project_by_mprgp's vectors */
    lc_buf b_direct;                  /* start_projection's points and impulses */
    lc_buf b_flow;                    /* project_flow_points's touches: the flow's, and a pass's */
    lc_buf b_sweep;                   /* the solver's scratch (lc_contact_solver_run) */
};

lc_contact_projection *lc_contact_projection_create(void)
{
    lc_contact_projection *cp = calloc(1, sizeof *cp);
    if (cp == NULL) return NULL;
    cp->direct = lc_projection_active_set_create();
    if (cp->direct == NULL) {
        free(cp);
        return NULL;
    }
    return cp;
}

void lc_contact_projection_destroy(lc_contact_projection *cp)
{
    if (cp == NULL) return;
    lc_projection_active_set_destroy(cp->direct);
    lc_buf_free(&cp->b_rows);
    lc_buf_free(&cp->b_mprgp);
    lc_buf_free(&cp->b_direct);
    lc_buf_free(&cp->b_flow);
    lc_buf_free(&cp->b_sweep);
    free(cp);
}

/* The projection by MPRGP (sparse_lcp.c, conjugate gradients with bound projections), when Gauss-Seidel
 * did not converge: it needs sweeps in the square of a chain's length (a block pushing a row of twenty
 * boxes left the row overlapping after 400), MPRGP products in its length. left: the deepest overlap the
 * pass starts from. A pass of at least LC_CONTACT_PROJECTION_LARGE points, or of a pile sub-step, starts
 * from the sweeps' answer (in rows) and stops near the overlap it starts from (tunables.h); another one
 * starts from zero and solves to the island's slack. The displacements land in b.disp. */
static int project_by_mprgp(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *t, int nt, double gp, double left, lc_contact_row *rows)
{
    lc_world *w = c->w;
    double *v = lc_buf_get(&cp->b_mprgp, (size_t)nt * 4 * sizeof(double)), *b, *lo, *hi, viol, tol;
    int i, large = nt >= LC_CONTACT_PROJECTION_LARGE || c->pile;
    if (v == NULL) return -1;
    b = v + nt;
    lo = b + nt;
    hi = lo + nt;
    for (i = 0; i < nt; ++i) {
        v[i] = large ? rows[i].lambda_n : 0.0;
        b[i] = t[i].gap - gp;
        lo[i] = 0.0;
        hi[i] = INFINITY;
    }
    tol = large ? fmax(c->slack, LC_CONTACT_PROJECTION_PASS_TOLERANCE * left) : c->slack;
    if (lc_sparse_lcp(w, t, nt, 0, b, lo, hi, v, tol, LC_CONTACT_PROJECTION_PRODUCTS, &viol) < 0) return -1;
    for (i = 0; i < nt; ++i)
        if (v[i] > 0.0 && isfinite(v[i])) lc_contact_row_apply(&rows[i], v[i], 0.0, c->b.disp, c->b.inv_mass, c->b.inv_inertia);
    return 0;
}

/* The start of a projection pass of at least LC_CONTACT_PROJECTION_DIRECT_ROWS points: active sets over
 * a sparse factorization (projection_active_set.h) into the rows' lambda_n, kept when their objective is
 * below no push's (0). Gauss-Seidel and MPRGP need sweeps and products in a pile's height (a settling
 * 1 000-box pile: 50 sweeps and ~1 400 products a step from no push); the factorizations do not, and the
 * sweeps and MPRGP that follow finish from the start (with it, such a pile's step takes about half the
 * instructions, callgrind). 0, or -1 without memory. */
static int start_projection(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *t, int nt, double gp, lc_contact_row *rows)
{
    double *xy = lc_buf_get(&cp->b_direct, (size_t)nt * 4 * sizeof(double)), *b, *lambda, value;
    int i;
    if (xy == NULL) return -1;
    b = xy + 2 * nt;
    lambda = b + nt;
    for (i = 0; i < nt; ++i) {
        xy[2 * i] = t[i].p.x;
        xy[2 * i + 1] = t[i].p.y;
        b[i] = t[i].gap - gp;
    }
    if (lc_projection_active_set_solve(cp->direct, rows, xy, nt, c->b.n, c->b.inv_mass, c->b.inv_inertia, b,
                                       c->slack, lambda, &value) < 0)
        return -1;
    if (value < 0.0)
        for (i = 0; i < nt; ++i) rows[i].lambda_n = lambda[i];
    return 0;
}

/* One pass over the touches t[0..nt) (gaps at the current state, deepest overlap left): their rows, the
 * start of a large pass, Gauss-Seidel, MPRGP where the sweeps did not converge; the displacements are
 * added to the island's positions. 0, or -1 without memory. */
static int project_pass(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *t, int nt, double gp, double left)
{
    lc_world *w = c->w;
    lc_contact_row *rows = lc_buf_get(&cp->b_rows, (size_t)(nt > 0 ? nt : 1) * sizeof(lc_contact_row));
    double *scratch = lc_buf_get(&cp->b_sweep, (size_t)(c->b.n > 0 ? c->b.n : 1) * 6 * sizeof(double));
    lc_contact_solve ps;
    lc_contact_stop stop;
    int i, k;
    if (rows == NULL || scratch == NULL) return -1;
    w->last.position_projections++;
    for (i = 0; i < nt; ++i) {
        lc_contact_island_row(c, &t[i], &rows[i]);
        rows[i].mu = 0.0;
        rows[i].target_n = gp - t[i].gap;
    }
    if (nt >= LC_CONTACT_PROJECTION_DIRECT_ROWS && start_projection(cp, c, t, nt, gp, rows) != 0) return -1;
    memset(c->b.disp, 0, (size_t)c->b.n * 3 * sizeof(double));
    stop = lc_contact_stop_rule(LC_CONTACT_PROJECTION_SWEEPS, c->slack, LC_CONTACT_STALL_SWEEPS);
    ps = lc_contact_solver_run(rows, nt, c->b.n, c->b.disp, c->b.inv_mass, c->b.inv_inertia, &stop, scratch);
    /* a pass that cut the overlap a hundredfold is kept: the next pass starts from there */
    if (ps.residual > c->slack && ps.residual > LC_CONTACT_PROJECTION_GAIN * left) {
        memset(c->b.disp, 0, (size_t)c->b.n * 3 * sizeof(double));
        if (project_by_mprgp(cp, c, t, nt, gp, left, rows) != 0) return -1;
    }
    for (i = 0; i < c->b.n; ++i) {
        double *s = &w->state[c->isl->rows[i] * 6];
        for (k = 0; k < 3; ++k) s[k] += c->b.disp[i * 3 + k];
    }
    return 0;
}

/* Passes over the flow's own points, in a pile sub-step (c->pile), while one overlaps: their vertex-edge
 * features at the current state (lc_touch_refresh: a vertex inside the other body takes the edge it is
 * least deep behind), no search. A pile's flow leaves its overlaps among the points it solved (its error:
 * micrometres at 1 ms, ~0.1 mm at 1/60 s), and a search of every pair of the island costs more than such
 * a pass's solve: the searches took 28 % of the instructions of a tumbling 200-box pile at 1 ms, three a
 * step; with these passes one a step is left, the search after them, which finds what they miss. Islands
 * of LC_CONTACT_LARGE_ISLAND_BODIES bodies or more (trapezoidal, with impacts) leave overlaps among
 * points their flow did not hold (a 1 000-box pile at 1/60 s: 2 mm among ~200 of 2 500 points), where
 * these passes were extra work. 0, or -1 without memory. */
static int project_flow_points(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *flow, int nflow, double gp)
{
    lc_world *w = c->w;
    lc_touch *f = lc_buf_get(&cp->b_flow, (size_t)(nflow > 0 ? nflow : 1) * 2 * sizeof(lc_touch)), *t;
    int pass, i, nt;
    if (f == NULL) return -1;
    t = f + nflow;
    if (nflow > 0) memcpy(f, flow, (size_t)nflow * sizeof(lc_touch));
    for (pass = 0; pass < LC_CONTACT_PROJECTION_PASSES; ++pass) {
        double left = 0.0;
        for (i = nt = 0; i < nflow; ++i)
            if (lc_touch_refresh(w, w->state, &f[i], w->def.contact_distance)) {
                t[nt++] = f[i];
                if (f[i].gap < -c->slack) left = fmax(left, -f[i].gap);
            }
        if (!(left > 0.0)) break;
        if (project_pass(cp, c, t, nt, gp, left) != 0) return -1;
    }
    return 0;
}

int lc_contact_project(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *flow, int nflow, lc_buf *end,
                       lc_buf *margins, double *left)
{
    lc_world *w = c->w;
    double gp = fmin(LC_CONTACT_PROJECTION_GAP, 1e-3 * w->def.contact_gap), reach = 0.0;
    double *margin = lc_buf_get(margins, (size_t)(c->isl->npairs > 0 ? c->isl->npairs : 1) * sizeof(double));
    int pass, i, nt = 0;
    if (margin == NULL) return -1;
    if (c->pile && project_flow_points(cp, c, flow, nflow, gp) != 0) return -1;
    for (pass = 0;; ++pass) {
        lc_touch *t;
        int any = 0;
        /* the points within twice the deepest overlap too: pushing a pair apart by that much can push
         * a neighbour in (a row of boxes), and a point the solve does not hold is one pass more each */
        nt = lc_contact_island_collect(c, c->dt, end, LC_SEARCH_NEXT_STEP, reach, margin);
        if (nt < 0) return -1;
        t = (lc_touch *)end->p;
        *left = 0.0;
        for (i = 0; i < nt; ++i)
            if (t[i].gap < -c->slack) {
                any = 1;
                *left = fmax(*left, -t[i].gap);
            }
        if (reach < 2.0 * *left) {
            reach = 2.0 * *left;
            nt = lc_contact_island_collect(c, c->dt, end, LC_SEARCH_NEXT_STEP, reach, margin);
            if (nt < 0) return -1;
            t = (lc_touch *)end->p;
        }
        if (!any || pass == LC_CONTACT_PROJECTION_PASSES) break;
        if (project_pass(cp, c, t, nt, gp, *left) != 0) return -1;
    }
    return nt;
}
