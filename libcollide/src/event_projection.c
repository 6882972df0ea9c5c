/* The event regime's end-of-step projection (post-stabilisation): when a point ends the step closer
 * than half the contact gap (or inside another body), every touch is moved back to at least the
 * contact gap by the smallest displacement the response matrix allows (an LCP on positions). Positions
 * only: the contact forces stop relative motion (velocity stabilisation), and the slow drift of a
 * resting contact is taken out here, so holding a contact at the gap never leaves a velocity behind (a
 * distance term in the force would push faces that start touching apart at ~contact_gap/h, and a
 * push-only force cannot brake that). Crossings must start above half the gap's depth, so this is also
 * the backstop that keeps drift in a jammed pile from becoming an overlap nothing can see: no step ends
 * overlapping. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "event_projection.h"
#include "event_touches.h"
#include "tunables.h"

struct lc_event_projection {
    lc_buf found;           /* the touches a pass found */
    lc_buf mat, vec, vec2;  /* a pass's response matrix, right-hand side and multipliers */
};

lc_event_projection *lc_event_projection_create(void) { return calloc(1, sizeof(lc_event_projection)); }

void lc_event_projection_destroy(lc_event_projection *ep)
{
    if (ep == NULL) return;
    lc_buf_free(&ep->found);
    lc_buf_free(&ep->mat);
    lc_buf_free(&ep->vec);
    lc_buf_free(&ep->vec2);
    free(ep);
}

/* The projection of a large group (more touches than lcp_exact_max: a pile) by MPRGP on the sparse
 * response (sparse_lcp.c): O(touches) memory and per product where the dense problem would be
 * O(touches^2) (a 210-box pyramid starting with its faces at gap 0 has ~1200 touches: 11 MB and
 * seconds per pass). Converged when no gap is off by more than a thousandth of the contact gap. Its
 * budget is 5x the force solve's: it is the last line before a step fails, and a cold 5050-box
 * pyramid (100 layers lifted to the gap at once) needed more than 1000 products per pass. */
static int project_sparse(lc_world *w, lc_event_projection *ep, const lc_touch *t, int n)
{
    double *disp = lc_buf_get(&ep->vec, (size_t)w->count * 3 * sizeof(double));
    double *lam = lc_buf_get(&ep->vec2, (size_t)n * 4 * sizeof(double)), *b, *lo, *hi, viol;
    int i;
    if (!disp || !lam) return -1;
    b = lam + n;
    lo = b + n;
    hi = lo + n;
    for (i = 0; i < n; ++i) {
        lam[i] = 0.0;
        b[i] = t[i].gap - w->def.contact_gap;
        lo[i] = 0.0;
        hi[i] = INFINITY;
    }
    /* start from lifting each body by the gaps below it (static_load.c); hi is scratch for the
     * deficits until then */
    for (i = 0; i < n; ++i) hi[i] = -b[i];
    if (lc_static_load_lifts(w, t, n, hi, lam) != 0) return -1;
    for (i = 0; i < n; ++i) hi[i] = INFINITY;
    if (lc_sparse_lcp(w, t, n, 0, b, lo, hi, lam, 1e-3 * w->def.contact_gap, 25 * w->def.lcp_max_iterations,
                      &viol) < 0)
        return -1;
    memset(disp, 0, (size_t)w->count * 3 * sizeof(double));
    for (i = 0; i < n; ++i)
        if (lam[i] > 0.0 && isfinite(lam[i])) lc_touch_apply(w, &t[i], lc_scale(t[i].n, lam[i]), disp, 3);
    for (i = 0; i < w->count; ++i) {
        w->state[i * 6 + SX] += disp[i * 3 + 0];
        w->state[i * 6 + SY] += disp[i * 3 + 1];
        w->state[i * 6 + SA] += disp[i * 3 + 2];
    }
    return 1;
}

/* 1 projected, 0 nothing to do (*found: the touches in b_impact, all at w->state), -1 no memory */
static int project_once(lc_world *w, lc_event_projection *ep, lc_event_touches *et, double *deepest, int *found)
{
    int n = lc_event_gather_touches(w, et, w->state, &ep->found), i, k = 0;
    lc_touch *t = (lc_touch *)ep->found.p;
    double *A, *b, *lam;
    lc_lcp_options opt;
    lc_lcp_result res;
    *deepest = INFINITY;
    *found = n;
    if (n <= 0) return n;
    for (i = 0; i < n; ++i) {
        if (t[i].gap < 0.5 * w->def.contact_gap) k = 1;
        if (t[i].gap < *deepest) *deepest = t[i].gap;
    }
    if (!k) return 0;
    w->last.position_projections++;
    if (n > w->def.lcp_exact_max) return project_sparse(w, ep, t, n);
    /* every touch takes part, so pushing one pair apart does not push a neighbour in */
    A = lc_buf_get(&ep->mat, (size_t)n * (size_t)n * sizeof(double));
    b = lc_buf_get(&ep->vec, (size_t)n * sizeof(double));
    lam = lc_buf_get(&ep->vec2, (size_t)n * sizeof(double));
    if (!A || !b || !lam) return -1;
    lc_response_matrix(w, t, n, A);
    for (i = 0; i < n; ++i) {
        b[i] = t[i].gap - w->def.contact_gap;
        lam[i] = 0.0;
    }
    opt = lc_lcp_default_options();
    opt.exact_max = w->def.lcp_exact_max;
    opt.max_iterations = w->def.lcp_max_iterations;
    opt.tolerance = w->def.lcp_tolerance;
    lc_lcp_solve(n, A, b, lam, NULL, &opt, w->lcp, &res);
    w->last.solver_work += lc_lcp_work(n, &res);
    for (i = 0; i < n; ++i) {
        double l = lam[i] > 0.0 && isfinite(lam[i]) ? lam[i] : 0.0;
        if (l > 0.0) lc_touch_apply(w, &t[i], lc_scale(t[i].n, l), w->state, 6);
    }
    return 1;
}

/* 0 done, 1 still overlapping after every pass (forces far beyond what dt can resolve), -1 no memory. */
int lc_event_project(lc_world *w, lc_event_projection *ep, lc_event_touches *et)
{
    int pass, r = 0, found = 0;
    double deepest = INFINITY;
    for (pass = 0; pass <= LC_PROJECTION_PASSES; ++pass) {
        r = project_once(w, ep, et, &deepest, &found);
        if (r <= 0) break;
    }
    if (r < 0) return -1;
    /* the last search was at the state the step ends in: keep it for the next step's first gather */
    if (r == 0 && lc_event_touches_keep_end(w, et, &ep->found, found) != 0) return -1;
    /* the last pass projected again: its touches were measured before that pass */
    if (r > 0 && deepest < -LC_OVERLAP_TOLERANCE) return 1;
    return 0;
}
