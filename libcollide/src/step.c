/* The step: integrate, look for vertices that entered another body, back up to the earliest time of
 * impact, apply the impulses there, and continue with the rest of the step. Time is never dropped. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "islands.h"
#include "contact_regime.h"
#include "regime.h"
#include "tunables.h"

/* Most a body may turn (rad) within one collision-checked interval. */
#define LC_MAX_TRIAL_ROTATION 0.25
/* Most rotation-limited intervals in one step. */
#define LC_MAX_TRIALS 1024
/* Most work one step may do before it is undone with LC_ERR_NUMERIC: force evaluations and serial
 * impulse passes. A 210-box pyramid needs ~30 evaluations per step and the seed scene none; these
 * are reached only by inputs such as a 1e6 kg and a 1e-300 kg body at 1e6 m/s, or a stiff spring
 * anchored 1e6 m away, which would otherwise spend seconds on one step before failing anyway. */
#ifndef LC_MAX_FORCE_EVALUATIONS_PER_STEP
#define LC_MAX_FORCE_EVALUATIONS_PER_STEP 500000
#endif
#ifndef LC_MAX_SERIAL_ITERATIONS_PER_STEP
#define LC_MAX_SERIAL_ITERATIONS_PER_STEP 50000
#endif
/* and the complementarity solves' work (lc_counters.solver_work), per body of the world: one force
 * evaluation of four coincident decagons (a 120-row dense group) costs 150 of the settling scene's
 * (20 blocks), so evaluations alone let such a step run 110 s to their cap (fuzz finding 32).
 * Measured per body (bench/repro/solver_work_per_body.py): the hardest legitimate step, a box dropped
 * onto a 78-box frictional pyramid, does 1.1e8 (10.5 s of CPU), the bench scenes at most 3e5; that
 * input did 1.7e10 by the evaluation cap, and now stops at 1e9 after 3 s. */
#ifndef LC_MAX_SOLVER_WORK_PER_BODY
#define LC_MAX_SOLVER_WORK_PER_BODY 1000000000
#endif
/* The caps can be lowered at build time (-DLC_MAX_...=N, a plain decimal number): fuzz/run --engine-cap
 * does so, so that the fuzzer does not spend seconds on each input that ends at a cap anyway. */
#define LC_STRINGIFY_(x) #x
#define LC_STRINGIFY(x) LC_STRINGIFY_(x)

/* The touches the last step's projection found at the state it ended in, moved into buf, if this
 * gather is at that same state (-1: none kept, or something changed since). The first gather of a
 * step is at the state the previous one ended in, so in a world at rest or in free flight one of the
 * two whole-world touch searches per step is saved (the projection has to look at the end state,
 * the next step's resting set at its start). One use: every later gather of the step is elsewhere. */
static int kept_end_touches(lc_world *w, const double *state, lc_buf *buf)
{
    int n = w->end_touch_count;
    lc_buf swap;
    w->end_touch_count = -1;
    if (n < 0 || w->end_edits != w->edits || state != w->state ||
        memcmp(w->b_end_state.p, state, (size_t)w->count * 6 * sizeof(double)) != 0)
        return -1;
    swap = *buf;
    *buf = w->b_end_touches;
    w->b_end_touches = swap;
    return n;
}

/* Touches at `state` with gap < contact_distance, appended to buf from 0: between all near pairs, or
 * (list != NULL) only the pairs with at least one of the listed bodies (marked[row] != 0). */
static int gather_touches_of(lc_world *w, const double *state, const uint8_t *marked, const int *list, int nlist,
                             lc_buf *buf)
{
    int np, i, n = 0;
    const int *pairs;
    if (list == NULL && (n = kept_end_touches(w, state, buf)) >= 0) return n;
    n = 0;
    np = list ? lc_broad_phase_of(w, state, state, w->def.contact_distance, marked, list, nlist, &w->b_pairs)
              : lc_broad_phase(w, state, state, w->def.contact_distance, &w->b_pairs);
    if (np < 0) return -1;
    pairs = (const int *)w->b_pairs.p;
    for (i = 0; i < np; ++i) {
        n = lc_collect_touches(w, state, pairs[2 * i], pairs[2 * i + 1], w->def.contact_distance, buf, n);
        if (n < 0) return -1;
    }
    return n;
}

/* Touches between all near pairs at `state` with gap < contact_distance, appended to buf from 0. */
static int gather_touches(lc_world *w, const double *state, lc_buf *buf)
{
    return gather_touches_of(w, state, NULL, NULL, 0, buf);
}


/* Keys of a vertex against a body, and of a touch (vertex and edge), for the hash tables below. */
static uint32_t vertex_key(const lc_world *w, int a, int vertex, int b)
{
    uint32_t h = 2166136261u;
    h = (h ^ w->ids[a]) * 16777619u;
    h = (h ^ (uint32_t)vertex) * 16777619u;
    return (h ^ w->ids[b]) * 16777619u;
}

static uint32_t touch_key(const lc_world *w, const lc_touch *t)
{
    uint32_t h = 2166136261u;
    h = (h ^ w->ids[t->a]) * 16777619u;
    h = (h ^ (uint32_t)t->vertex) * 16777619u;
    h = (h ^ w->ids[t->b]) * 16777619u;
    h = (h ^ (uint32_t)t->edge) * 16777619u;
    return h;
}

/* Start each resting touch from the force it carried in the previous pass (same bodies, vertex and
 * edge): resting forces change little between steps, so the iterative solver starts near the answer. */
static int warm_start(lc_world *w, lc_touch *t, int n)
{
    const lc_touch *old = (const lc_touch *)w->b_warm.p;
    int m = w->warm_count, size = 1, i;
    int *table;
    if (m == 0 || n == 0) return 0;
    while (size < 2 * m) size *= 2;
    table = lc_buf_get(&w->b_hash, (size_t)size * sizeof(int));
    if (table == NULL) return -1;
    for (i = 0; i < size; ++i) table[i] = -1;
    for (i = 0; i < m; ++i) {
        uint32_t k = touch_key(w, &old[i]) & (uint32_t)(size - 1);
        while (table[k] >= 0) k = (k + 1) & (uint32_t)(size - 1);
        table[k] = i;
    }
    for (i = 0; i < n; ++i) {
        uint32_t k = touch_key(w, &t[i]) & (uint32_t)(size - 1);
        t[i].value = 0.0;
        t[i].tangent = 0.0;
        while (table[k] >= 0) {
            const lc_touch *o = &old[table[k]];
            if (o->a == t[i].a && o->b == t[i].b && o->vertex == t[i].vertex && o->edge == t[i].edge) {
                t[i].value = o->value;
                t[i].tangent = o->tangent;
                break;
            }
            k = (k + 1) & (uint32_t)(size - 1);
        }
    }
    return 0;
}

/* Resting set: touching points that approach no faster than resting_speed and separate no faster
 * than resting_speed (resting_speed / 100 between perfectly elastic bodies, see below).
 * Touches already inside the contact gap that still approach faster than that are impacts that no
 * crossing test can see any more (they start inside); they are resolved here, before the step.
 * Returns the resting count, -1 (no memory) or -2 (a point has passed deep into another body: the
 * step must fail). */
static int gather_resting(lc_world *w, double *state, int *impacts, const uint8_t *marked, const int *list,
                          int nlist, int mid_step, int *started_deep, int *persisting)
{
    int n, i, k = 0, urgent = 0;
    lc_touch *t;
    n = gather_touches_of(w, state, marked, list, nlist, &w->b_touch);
    t = (lc_touch *)w->b_touch.p;
    if (n < 0) return -1;
    /* Within a step (mid_step: not its first pass) that started without one, a point a quarter of
     * the smaller body's size (and at least 100 contact_distances: a 1e-12 m polygon is not "deep" at
     * 1e-12 m) inside the other has passed through it: nothing legitimate gets there
     * within a step (impacts stop points at the gap, resting drift is ~contact_gap), only speeds or
     * spins far beyond what the step resolves (a 1e6 m sliver at 1e6 rad/s, found by the fuzzer).
     * Contact forces on such a point pumped energy without bound (velocities of 1e183 m/s); the step
     * fails instead. A step may start overlapping (bodies created or placed into each other, which
     * the API allows): then *started_deep is set and the end-of-step projection separates them. */
    for (i = 0; i < n && !*started_deep; ++i)
        if (t[i].gap < -fmax(0.25 * fmin(w->shape[t[i].a].radius, w->shape[t[i].b].radius),
                             100.0 * w->def.contact_distance)) {
            if (!mid_step) *started_deep = 1;   /* the projection's job, for this whole step */
            else return -2;
        }
    /* within the time-of-impact tolerance of the gap counts as at the gap, as it does for a crossing
     * (whose time of impact would be 0): all of them are resolved here in one group, not one pass each */
    for (i = 0; i < n; ++i)
        if (t[i].gap <= w->def.contact_gap + w->def.toi_distance_tolerance && t[i].vn < -w->def.resting_speed)
            urgent = 1;
    if (urgent) {
        lc_touch *x = lc_buf_get(&w->b_impact, (size_t)n * sizeof(lc_touch));
        if (x == NULL) return -1;
        memcpy(x, t, (size_t)n * sizeof(lc_touch));
        if (lc_resolve_impacts(w, state, x, n, *impacts < w->def.max_events_per_step) < 0) return -1;
        for (i = 0; i < n; ++i) {
            if (x[i].value > 0.0) {
                w->last.impulses++;
                if (lc_push_contact(w, &x[i], LC_CONTACT_COLLISION) != 0) return -1;
            }
            lc_touch_update(w, state, &t[i]);
        }
        w->last.collisions++;
        ++*impacts;
    }
    /* A point already deeper than half the gap and separating, at any speed, is resting too: the
     * crossing test cannot see it (a crossing starts above that depth), so if it turned back in (a
     * block rolling over a corner) only a contact force can stop it. A separating point above that
     * depth is left free, or a bouncing body would feel a sticky force.
     * A point at the gap between perfectly elastic bodies (e = 1) that separates faster than
     * resting_speed / 100 is left free as well, for the whole interval: a force on it holds apart two
     * bodies that part (the target a >= -vn/h lets vn decay by e^-1 per step), and its work f vn > 0
     * is energy from nowhere where the exact answer is a bounce. In the touching cradle (tests/c/
     * test_hard_cradle.c), blocks that part at up to 6e-5 m/s after an impact while their rotation
     * turns them back gained 4.8e-8 J that way. Left free, they part and meet again as a slow
     * impact or a resting touch (-1.5e-9 J over the 60 s; the same from resting_speed / 300 to / 3).
     * Below resting_speed / 100 a touch keeps its force: that is the solver's noise on a touch at
     * rest (~1e-9 m/s), and leaving those free turns resting touches into a chatter of tiny impacts
     * (at / 1e5: -1.8e-8 J in the cradle, 1-3 slow impacts a step). Pairs with e < 1 keep the force
     * at any separating speed up to resting_speed: their contacts dissipate, by far more than the
     * force's work (at most f vn h per parting), and freeing them made a chatter of slow impacts:
     * bench/run's 20-block settling scene at e = 0.8 went from 8.3 to 32.5 impacts and from 2.4 to
     * 15.5 ms per step, and an e = 0 six-block pile (tests/c/test_pile.c) from 277 impacts in 10 s
     * to 840 000 by 8.7 s. */
    /* A touch between bodies that are not perfectly elastic that neither approaches nor separates
     * faster than it could bounce will persist: the contact regime's (regime.h) */
    *persisting = -1;
    for (i = 0; i < n && *persisting < 0; ++i)
        if (t[i].elasticity < 1.0 && fabs(t[i].vn) <= fmax(w->def.resting_speed, lc_bounce_speed(w, t[i].elasticity)))
            *persisting = w->is_static[t[i].a] ? t[i].b : t[i].a;
    for (i = 0; i < n; ++i)
        if ((t[i].vn >= -w->def.resting_speed &&
             t[i].vn <= (t[i].elasticity >= 1.0 ? 1e-2 : 1.0) * w->def.resting_speed) ||
            (t[i].gap < -0.5 * w->def.contact_gap && t[i].vn > 0.0))
            t[k++] = t[i];
    if (warm_start(w, t, k) != 0) return -1;
    return k;
}

/* Keeps this pass's resting touches and their forces for the next pass's warm start. */
static int keep_for_warm_start(lc_world *w, const lc_touch *t, int n)
{
    lc_touch *dst = lc_buf_get(&w->b_warm, (size_t)(n > 0 ? n : 1) * sizeof(lc_touch));
    if (dst == NULL) return -1;
    if (n > 0) memcpy(dst, t, (size_t)n * sizeof(lc_touch));
    w->warm_count = n;
    return 0;
}

/* Impact set at the time of impact: every touch in the group of bodies connected by touches to the
 * bodies of the impacting crossing (so an impact travels through a row of touching blocks), found by
 * spreading out from those two bodies, so its cost follows the group's size rather than the world's.
 * When the time came from the pair's separation (by_pair), the crossing's vertex need not be the one
 * touching: the pair's touches are its separating-axis manifold alone. */
static int gather_impact(lc_world *w, const double *state, const lc_crossing *c, int by_pair)
{
    int *queue = lc_buf_get(&w->b_group, (size_t)w->count * (sizeof(int) + 1));
    uint8_t *seen;   /* 1 queued, 2 done */
    int n = 0, i, k, q, nq = 0, have = 0;
    lc_touch *t;
    if (queue == NULL) return -1;
    seen = (uint8_t *)(queue + w->count);
    memset(seen, 0, (size_t)w->count);
    if (!w->is_static[c->a]) { seen[c->a] = 1; queue[nq++] = c->a; }
    if (!w->is_static[c->b]) { seen[c->b] = 1; queue[nq++] = c->b; }
    for (q = 0; q < nq; ++q) {
        int body = queue[q];
        for (k = 0; k < w->count; ++k) {
            double dx, dy, r;
            int before = n;
            if (k == body || seen[k] == 2) continue;   /* a pair with a finished body was collected */
            if (w->excluded && w->excluded[k]) continue;   /* another island's */
            dx = state[body * 6 + SX] - state[k * 6 + SX];
            dy = state[body * 6 + SY] - state[k * 6 + SY];
            r = w->shape[body].radius + w->shape[k].radius + w->def.contact_distance;
            if (dx * dx + dy * dy > r * r) continue;
            n = lc_collect_touches(w, state, body < k ? body : k, body < k ? k : body, w->def.contact_distance,
                                   &w->b_impact, n);
            if (n < 0) return -1;
            if (n > before && !w->is_static[k] && !seen[k]) { seen[k] = 1; queue[nq++] = k; }
        }
        seen[body] = 2;
    }
    t = (lc_touch *)w->b_impact.p;
    for (i = 0; i < n && !by_pair; ++i)
        if (t[i].a == c->a && t[i].vertex == c->vertex && t[i].b == c->b) {
            /* at a corner two edges are equally near; the vertex came in through the crossing's edge */
            if (t[i].edge != c->edge) {
                t[i].edge = c->edge;
                lc_touch_update(w, state, &t[i]);
            }
            have = 1;
        }
    if (!have && !by_pair) {
        /* the crossing vertex was not found as a touch (e.g. it meets the other body's corner):
         * use the crossing itself so the impact is never lost */
        lc_touch *x = lc_buf_get(&w->b_impact, (size_t)(n + 1) * sizeof(lc_touch));
        if (x == NULL) return -1;
        memset(&x[n], 0, sizeof x[n]);
        x[n].a = c->a;
        x[n].b = c->b;
        x[n].vertex = c->vertex;
        x[n].edge = c->edge;
        x[n].elasticity = fmin(w->elasticity[c->a], w->elasticity[c->b]);
        x[n].friction = sqrt(w->friction[c->a] * w->friction[c->b]);
        lc_touch_update(w, state, &x[n]);
        n++;
    }
    return n;
}

/* Post-stabilisation: when a point ends the step closer than half the contact gap (or inside another
 * body), every touch is moved back to at least the contact gap by the smallest displacement the
 * response matrix allows (an LCP on positions). Positions only: the contact forces stop relative
 * motion (velocity stabilisation), and the slow drift of a resting contact is taken out here, so
 * holding a contact at the gap never leaves a velocity behind (a distance term in the force would
 * push faces that start touching apart at ~contact_gap/h, and a push-only force cannot brake that).
 * Crossings must start above half the gap's depth, so this is also the backstop that keeps drift in
 * a jammed pile from becoming an overlap nothing can see: no step ends overlapping. */
/* The projection of a large group (more touches than lcp_exact_max: a pile) by MPRGP on the sparse
 * response (sparse_lcp.c): O(touches) memory and per product where the dense problem would be
 * O(touches^2) (a 210-box pyramid starting with its faces at gap 0 has ~1200 touches: 11 MB and
 * seconds per pass). Converged when no gap is off by more than a thousandth of the contact gap. Its
 * budget is 5x the force solve's: it is the last line before a step fails, and a cold 5050-box
 * pyramid (100 layers lifted to the gap at once) needed more than 1000 products per pass. */
static int project_sparse(lc_world *w, const lc_touch *t, int n)
{
    double *disp = lc_buf_get(&w->b_vec, (size_t)w->count * 3 * sizeof(double));
    double *lam = lc_buf_get(&w->b_vec2, (size_t)n * 4 * sizeof(double)), *b, *lo, *hi, viol;
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
static int project_once(lc_world *w, double *deepest, int *found)
{
    int n = gather_touches(w, w->state, &w->b_impact), i, k = 0;
    lc_touch *t = (lc_touch *)w->b_impact.p;
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
    if (n > w->def.lcp_exact_max) return project_sparse(w, t, n);
    /* every touch takes part, so pushing one pair apart does not push a neighbour in */
    A = lc_buf_get(&w->b_mat, (size_t)n * (size_t)n * sizeof(double));
    b = lc_buf_get(&w->b_vec, (size_t)n * sizeof(double));
    lam = lc_buf_get(&w->b_vec2, (size_t)n * sizeof(double));
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

/* The linearised rotation leaves a second-order remainder after a deep correction (a sliver's corner
 * millimetres in after an impact storm): a few passes take it below round-off. */
#define LC_PROJECTION_PASSES 16
/* Overlap (m) a step may end with: round-off of the projection. */
#define LC_OVERLAP_TOLERANCE 1e-9
/* 0 done, 1 still overlapping after every pass (forces far beyond what dt can resolve), -1 no memory. */
static int project_positions(lc_world *w)
{
    int pass, r = 0, found = 0;
    double deepest = INFINITY;
    for (pass = 0; pass <= LC_PROJECTION_PASSES; ++pass) {
        r = project_once(w, &deepest, &found);
        if (r <= 0) break;
    }
    if (r < 0) return -1;
    if (r == 0) {
        /* the last search was at the state the step ends in: keep it for the next step's first gather */
        double *kept = lc_buf_get(&w->b_end_state, (size_t)w->count * 6 * sizeof(double));
        lc_buf swap = w->b_impact;
        if (kept == NULL) return -1;
        memcpy(kept, w->state, (size_t)w->count * 6 * sizeof(double));
        w->b_impact = w->b_end_touches;
        w->b_end_touches = swap;
        w->end_touch_count = found;
        w->end_edits = w->edits;
    }
    /* the last pass projected again: its touches were measured before that pass */
    if (r > 0 && deepest < -LC_OVERLAP_TOLERANCE) return 1;
    return 0;
}

/* How far a vertex of one body can stray, in the other's frame, from the straight chord between its
 * positions at the ends of an interval of length h: turning by dtheta bends the path by r dtheta^2 / 8,
 * and a change dv of the relative velocity by dv h / 8 (relative: two blocks falling side by side
 * under gravity move on parallel parabolas, straight lines in each other's frame). */
static double chord_deviation(const lc_world *w, const double *s0, const double *s1, double h, int a, int b)
{
    double turn = fabs(s1[a * 6 + SA] - s0[a * 6 + SA]) + fabs(s1[b * 6 + SA] - s0[b * 6 + SA]);
    double dvx = (s1[a * 6 + SVX] - s0[a * 6 + SVX]) - (s1[b * 6 + SVX] - s0[b * 6 + SVX]);
    double dvy = (s1[a * 6 + SVY] - s0[a * 6 + SVY]) - (s1[b * 6 + SVY] - s0[b * 6 + SVY]);
    return turn * turn * (w->shape[a].radius + w->shape[b].radius) / 8.0 + hypot(dvx, dvy) * h / 8.0;
}

/* Distance between the bodies' bounding circles (negative when they overlap). */
static double circle_gap(const lc_world *w, const double *s, int a, int b)
{
    return hypot(s[a * 6 + SX] - s[b * 6 + SX], s[a * 6 + SY] - s[b * 6 + SY]) - w->shape[a].radius - w->shape[b].radius;
}

/* Vertices that dip into another body and come back out within the interval are invisible to the
 * end-point test. For pairs that end up closer than their chords can stray, the two bodies' motion is
 * sampled at LC_SWEEP_SAMPLES sub-times and every sub-interval is tested; a crossing found there
 * carries the sub-time by which it is inside as the upper end of its time-of-impact bracket.
 * A coupled pair (touching others, or tied by a spring) moves with the whole world, whose sub-time
 * states are computed once per interval and shared by every such pair: in a pile each of them costs
 * a contact-force solve of the whole pile per integrator stage, and a settling 1275-box pyramid has
 * hundreds of near pairs in one interval. */
#define LC_SWEEP_SAMPLES 8
static int swept_check(lc_world *w, const double *s0, const double *s1, double h, const int *pairs, int np, int nc,
                       const int *coupled, const int *all_rows, int n_all, lc_touch *rest, int nrest)
{
    size_t count6 = (size_t)w->count * 6, bytes = count6 * sizeof(double);
    double *own[2], *world_at = NULL;
    int have_world[LC_SWEEP_SAMPLES] = {0};
    int p, k, i;
    own[0] = own[1] = NULL;
    for (p = 0; p < np; ++p) {
        int a = pairs[2 * p], b = pairs[2 * p + 1], rows[2], nr = 0, have = 0, uncoupled;
        double dev, sep0;
        const double *prev, *cur;
        for (i = 0; i < nc; ++i) {
            const lc_crossing *c = &((const lc_crossing *)w->b_cross.p)[i];
            if ((c->a == a && c->b == b) || (c->a == b && c->b == a)) have = 1;
        }
        /* the end-point test already bracketed this pair; if another vertex (a corner meeting a
         * corner) dipped in before that crossing's time, the pair's time of impact finds it */
        if (have) continue;
        dev = chord_deviation(w, s0, s1, h, a, b);
        /* a path that strays from its chord by less than a quarter of the contact gap can dip at most
         * that far past what the end-point test sees: never into the other body (a settled pile) */
        if (dev < 0.25 * w->def.contact_gap) continue;
        /* bounding circles apart by more than the paths can stray, at both ends: nothing can dip in
         * (the circles' distance is a lower bound of the bodies' distance, as the separation is) */
        if (circle_gap(w, s0, a, b) > dev + w->def.contact_distance &&
            circle_gap(w, s1, a, b) > dev + w->def.contact_distance)
            continue;
        if (lc_bounds_gap(w, s0, a, b) > dev + w->def.contact_distance &&
            lc_bounds_gap(w, s1, a, b) > dev + w->def.contact_distance)
            continue;
        sep0 = lc_pair_separation(w, s0, a, b);
        /* touching at the start: resting contacts or impacts already guard the pair */
        if (sep0 < w->def.contact_distance) continue;
        if (sep0 > dev + w->def.contact_distance && lc_pair_separation(w, s1, a, b) > dev + w->def.contact_distance)
            continue;
        if (!w->is_static[a]) rows[nr++] = a;
        if (!w->is_static[b]) rows[nr++] = b;
        uncoupled = !coupled[a] && !coupled[b];
        prev = s0;
        for (k = 1; k <= LC_SWEEP_SAMPLES; ++k) {
            double tk = h * k / LC_SWEEP_SAMPLES;
            int before = nc;
            if (k == LC_SWEEP_SAMPLES) {
                cur = s1;
            } else if (uncoupled) {
                double *dst;
                if (own[0] == NULL) {
                    own[0] = lc_buf_get(&w->b_sample0, bytes);
                    own[1] = lc_buf_get(&w->b_sample1, bytes);
                    if (!own[0] || !own[1]) return -1;
                }
                dst = own[k & 1];   /* prev is the other one (or s0) */
                if (lc_integrate(w, s0, tk, rows, nr, NULL, 0, dst) != 0) return -1;
                cur = dst;
            } else {
                /* the whole world advanced with its resting contacts, exactly as in the trial */
                if (world_at == NULL) {
                    world_at = lc_buf_get(&w->b_swept, (LC_SWEEP_SAMPLES - 1) * bytes);
                    if (world_at == NULL) return -1;
                }
                if (!have_world[k]) {
                    if (lc_integrate(w, s0, tk, all_rows, n_all, rest, nrest, world_at + (size_t)(k - 1) * count6) != 0)
                        return -1;
                    have_world[k] = 1;
                }
                cur = world_at + (size_t)(k - 1) * count6;
            }
            nc = lc_find_crossings(w, prev, cur, a, b, &w->b_cross, nc);
            if (nc < 0) return -1;
            if (nc > before) {
                for (i = before; i < nc; ++i) ((lc_crossing *)w->b_cross.p)[i].t_hi = tk;
                break;
            }
            prev = cur;
        }
    }
    return nc;
}

/* Islands: bodies joined by resting touches or by springs between bodies move together, and apart
 * from every other island (static bodies join nothing: they transmit no motion). A time-of-impact
 * search needs only the islands of the crossing's two bodies; integrating the whole world there made
 * every evaluation in a settling scene (20 blocks, each on the floor) solve all of their contact
 * forces, ~2000 force evaluations per step. Rows and touches are sorted by island, in their order. */
typedef struct island_set {
    int *of;                  /* island of each body row, -1 for static bodies */
    int *rows, *row_start;    /* rows of island k: rows[row_start[k] .. row_start[k + 1]) */
    lc_touch *touches;        /* resting touches of island k: likewise, with touch_start */
    int *touch_start;
    int count;
} island_set;

static int island_root(int *parent, int x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static void island_join(int *parent, int a, int b)
{
    int ra = island_root(parent, a), rb = island_root(parent, b);
    if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
}

static int build_islands(lc_world *w, const int *rows, int nrows, const lc_touch *rest, int nrest, island_set *is)
{
    int *v = lc_buf_get(&w->b_isl, ((size_t)w->count * 2 + (size_t)nrows * 4 + 3) * sizeof(int));
    int *parent, *cursor, i, k;
    is->touches = lc_buf_get(&w->b_isl_touch, (size_t)(nrest > 0 ? nrest : 1) * sizeof(lc_touch));
    if (v == NULL || is->touches == NULL) return -1;
    is->of = v;
    parent = v + w->count;
    is->rows = parent + w->count;
    is->row_start = is->rows + nrows;
    is->touch_start = is->row_start + nrows + 1;
    cursor = is->touch_start + nrows + 1;
    for (i = 0; i < w->count; ++i) {
        parent[i] = i;
        is->of[i] = -1;
    }
    for (i = 0; i < nrest; ++i)
        if (!w->is_static[rest[i].a] && !w->is_static[rest[i].b]) island_join(parent, rest[i].a, rest[i].b);
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) {
            int a = lc_world_body_index(w, w->springs[i].def.body_a), b = lc_world_body_index(w, w->springs[i].def.body_b);
            if (a >= 0 && b >= 0 && !w->is_static[a] && !w->is_static[b]) island_join(parent, a, b);
        }
    /* number the islands by their first row; is->of[root] holds the number while counting */
    is->count = 0;
    for (i = 0; i < nrows; ++i) {
        int r = island_root(parent, rows[i]);
        if (is->of[r] < 0) is->of[r] = is->count++;
    }
    for (i = 0; i < nrows; ++i) is->of[rows[i]] = is->of[island_root(parent, rows[i])];
    for (k = 0; k <= is->count; ++k) is->row_start[k] = is->touch_start[k] = 0;
    for (i = 0; i < nrows; ++i) is->row_start[is->of[rows[i]] + 1]++;
    for (i = 0; i < nrest; ++i) is->touch_start[is->of[w->is_static[rest[i].a] ? rest[i].b : rest[i].a] + 1]++;
    for (k = 0; k < is->count; ++k) {
        is->row_start[k + 1] += is->row_start[k];
        is->touch_start[k + 1] += is->touch_start[k];
    }
    for (k = 0; k < is->count; ++k) cursor[k] = is->row_start[k];
    for (i = 0; i < nrows; ++i) is->rows[cursor[is->of[rows[i]]]++] = rows[i];
    for (k = 0; k < is->count; ++k) cursor[k] = is->touch_start[k];
    for (i = 0; i < nrest; ++i) is->touches[cursor[is->of[w->is_static[rest[i].a] ? rest[i].b : rest[i].a]]++] = rest[i];
    return 0;
}

/* The rows and resting touches of the islands of bodies a and b (one island, or both side by side). */
static int islands_of(lc_world *w, const island_set *is, int a, int b, const int **rows, int *nrows,
                      lc_touch **touches, int *ntouches)
{
    int ia = is->of[a], ib = is->of[b], nr, nt;
    int *r;
    lc_touch *t;
    if (ia < 0) ia = ib;
    if (ib < 0) ib = ia;
    if (ia < 0) {
        *nrows = *ntouches = 0;
        *rows = NULL;
        *touches = NULL;
        return 0;
    }
    if (ia == ib) {
        *rows = is->rows + is->row_start[ia];
        *nrows = is->row_start[ia + 1] - is->row_start[ia];
        *touches = is->touches + is->touch_start[ia];
        *ntouches = is->touch_start[ia + 1] - is->touch_start[ia];
        return 0;
    }
    nr = is->row_start[ia + 1] - is->row_start[ia];
    nt = is->touch_start[ia + 1] - is->touch_start[ia];
    r = lc_buf_get(&w->b_isl_pick, (size_t)(nr + is->row_start[ib + 1] - is->row_start[ib]) * sizeof(int));
    t = lc_buf_get(&w->b_isl_pick_touch,
                   (size_t)(nt + is->touch_start[ib + 1] - is->touch_start[ib] + 1) * sizeof(lc_touch));
    if (r == NULL || t == NULL) return -1;
    memcpy(r, is->rows + is->row_start[ia], (size_t)nr * sizeof(int));
    memcpy(r + nr, is->rows + is->row_start[ib], (size_t)(is->row_start[ib + 1] - is->row_start[ib]) * sizeof(int));
    memcpy(t, is->touches + is->touch_start[ia], (size_t)nt * sizeof(lc_touch));
    memcpy(t + nt, is->touches + is->touch_start[ib], (size_t)(is->touch_start[ib + 1] - is->touch_start[ib]) * sizeof(lc_touch));
    *rows = r;
    *nrows = nr + is->row_start[ib + 1] - is->row_start[ib];
    *touches = t;
    *ntouches = nt + is->touch_start[ib + 1] - is->touch_start[ib];
    return 0;
}

/* Most crossings one step may set aside as stalled before it stops looking for crossings at all. */
#define LC_MAX_STALLED 64

/* A crossing whose impact at time 0 had nothing to do (no point approaching: typically a resting point
 * that the contact forces did not hold exactly across the trial interval, crossing its own gap) would
 * stop time at that instant forever. Such a vertex is set aside for the rest of the step (the contact
 * forces and the end-of-step projection hold it), while every other vertex is still checked. */
static int drop_stalled(lc_world *w, const lc_crossing *stalled, int nstalled, int nc)
{
    lc_crossing *c = (lc_crossing *)w->b_cross.p;
    int i, k, kept = 0;
    for (i = 0; i < nc; ++i) {
        int skip = 0;
        for (k = 0; k < nstalled && !skip; ++k)
            skip = stalled[k].a == c[i].a && stalled[k].b == c[i].b && stalled[k].vertex == c[i].vertex;
        if (!skip) c[kept++] = c[i];
    }
    return kept;
}

/* A vertex held by a resting contact force can sink below its gap by what the force solver left
 * unresolved (a large pile, where the iterative solve stops at its sweep limit, leaves ~1e-2 m/s^2,
 * i.e. ~1e-6 m in a 1/60 s step). That is not an impact: the force still holds the vertex, and the
 * end-of-step projection lifts it back to the gap without touching velocities. Stopping time at it
 * would stop at every such vertex of the pile in turn, each stop re-solving the whole pile (a
 * 1275-box pyramid: thousands per step). A resting vertex that ends deeper than contact_distance is
 * more than solver residual and stays an impact. */
static int drop_resting_drift(lc_world *w, const lc_touch *rest, int nrest, const double *s1, int nc)
{
    lc_crossing *c = (lc_crossing *)w->b_cross.p;
    int size = 1, i, kept = 0;
    int *table;
    if (nrest == 0 || nc == 0) return nc;
    while (size < 2 * nrest) size *= 2;
    table = lc_buf_get(&w->b_rkeys, (size_t)size * sizeof(int));
    if (table == NULL) return -1;
    for (i = 0; i < size; ++i) table[i] = -1;
    for (i = 0; i < nrest; ++i) {
        uint32_t k = vertex_key(w, rest[i].a, rest[i].vertex, rest[i].b) & (uint32_t)(size - 1);
        while (table[k] >= 0) k = (k + 1) & (uint32_t)(size - 1);
        table[k] = i;
    }
    for (i = 0; i < nc; ++i) {
        uint32_t k = vertex_key(w, c[i].a, c[i].vertex, c[i].b) & (uint32_t)(size - 1);
        int resting = 0;
        while (table[k] >= 0 && !resting) {
            const lc_touch *r = &rest[table[k]];
            resting = r->a == c[i].a && r->vertex == c[i].vertex && r->b == c[i].b;
            k = (k + 1) & (uint32_t)(size - 1);
        }
        if (resting && lc_vertex_edge_gap(w, s1, c[i].a, c[i].vertex, c[i].b, c[i].edge) > -w->def.contact_distance)
            continue;
        c[kept++] = c[i];
    }
    return kept;
}

/* Crossings of the previous pass between two bodies the last impact did not touch, with their bracket
 * moved to the new start (tmin later). One whose bracket ended before the new start is dropped. */
static int keep_clean_crossings(lc_world *w, const uint8_t *dirty, double tmin)
{
    lc_crossing *c = (lc_crossing *)w->b_cross.p;
    int i, kept = 0, nc = w->cross_count;
    for (i = 0; i < nc; ++i) {
        if (dirty[c[i].a] || dirty[c[i].b]) continue;
        c[i].t_hi -= tmin;
        if (!(c[i].t_hi > 0.0)) continue;
        c[kept++] = c[i];
    }
    return kept;
}

static lc_status step_failed(lc_world *w, const double *backup, double time0, lc_status s, const char *what)
{
    lc_stage_end(w, &w->last.time_step, w->step_t0);
    memcpy(w->state, backup, (size_t)w->count * 6 * sizeof(double));
    w->time = time0;
    w->contact_count = 0;
    return lc_fail(w, s, "%s; the step was undone", what);
}

/* 1 if an earlier try of this step found the contact regime unable to keep the island apart. */
static int forced_event(const lc_world *w, const lc_island *isl)
{
    int i;
    for (i = 0; i < isl->nrows; ++i)
        if (w->force_event[isl->rows[i]]) return 1;
    return 0;
}

/* The event regime over the given dynamic rows from time t0 for dt (the rest of the step that began at
 * time0): every other dynamic body is left out of its pairs (w->excluded). With `handover` non-NULL it
 * stops at the first instant a touch between bodies that are not perfectly elastic rests, with every
 * event row advanced to that instant: *handover is then that touch's island and *t_handover the time
 * it took; otherwise *handover is -1 and the rows reach the end of the step. */
static lc_status event_step(lc_world *w, double dt, double t0, double time0, double *backup, const int *event_rows,
                            int nrows, int *marks_known, int *handover, double *t_handover)
{
    size_t bytes;
    double *s0, *s1, *scratch, remaining;
    int *rows, i, events = 0, nstalled = 0, nrest = 0, passes = 0, persisting = -1, last_impact_body = -1;
    int dissipative_events = 0;
    int *drows, ndirty = 0, local_next = 0, body_springs = 0, started_deep = 0;
    uint8_t *dirty;
    double last_tmin = 0.0, trial_left = 0.0, ts;
    lc_crossing stalled[LC_MAX_STALLED];
    bytes = (size_t)(w->count > 0 ? w->count : 1) * 6 * sizeof(double);
    s0 = lc_buf_get(&w->b_state0, bytes);
    s1 = lc_buf_get(&w->b_state1, bytes);
    scratch = lc_buf_get(&w->b_step_scratch, bytes);
    rows = lc_buf_get(&w->b_rows, (size_t)(w->count > 0 ? w->count : 1) * sizeof(int));
    if (!s0 || !s1 || !scratch || !rows) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memcpy(rows, event_rows, (size_t)nrows * sizeof(int));
    dirty = lc_buf_get(&w->b_dirty, (size_t)w->count);
    drows = lc_buf_get(&w->b_drows, (size_t)w->count * sizeof(int));
    if (!dirty || !drows) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memset(dirty, 0, (size_t)w->count);
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) body_springs = 1;

    remaining = dt;
    while (remaining > 0.0) {
        int np, nc = 0, nkept = 0, best = -1, nimp, hits, *coupled = NULL, by_pair = 0;
        island_set isl;
        double tmin = remaining;
        const int *pairs;
        lc_crossing *cross;
        lc_touch *rest;

        double trial = remaining, wmax = 0.0;
        int events_before = events, local = 0, can_reuse;
        /* after an impact in free flight only the impact's bodies can have come to touch anything:
         * every other pair was apart (nothing rested) and moved without an impact */
        ts = lc_stage_begin(w);
        if (local_next && !body_springs)
            nrest = gather_resting(w, w->state, &events, dirty, drows, ndirty, passes > 0, &started_deep, &persisting);
        else
            nrest = gather_resting(w, w->state, &events, NULL, NULL, 0, passes > 0, &started_deep, &persisting);
        lc_stage_end(w, &w->last.time_detection, ts);
        if (nrest == -2)
            return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                               "a body passed deep into another within the step (speeds or spins beyond what dt can resolve)");
        if (nrest < 0) goto oom;
        rest = (lc_touch *)w->b_touch.p;
        /* from here on that touch persists, which the contact regime advances (regime.h); so does a burst
         * of impacts (inelastic collapse: a block bouncing ever lower, e^k, where no speed threshold
         * stops it) */
        if (handover != NULL && persisting < 0 && dissipative_events >= LC_HANDOVER_EVENTS) persisting = last_impact_body;
        if (handover != NULL && persisting >= 0) {
            lc_island isl = lc_islands_get(w->islands, lc_islands_of(w->islands, persisting));
            if (!lc_regime_too_fast(w, &isl, remaining) && !forced_event(w, &isl)) {
                *handover = lc_islands_of(w->islands, persisting);
                *t_handover = dt - remaining;
                return LC_OK;
            }
        }
        memcpy(s0, w->state, (size_t)w->count * 6 * sizeof(double));
        /* Vertex paths are tested as straight lines in the other body's frame; that holds while bodies
         * turn little, so a fast spinner is checked over shorter trial intervals. */
        for (i = 0; i < nrows; ++i) wmax = fmax(wmax, fabs(s0[rows[i] * 6 + SW]));
        if (wmax * trial > LC_MAX_TRIAL_ROTATION) trial = LC_MAX_TRIAL_ROTATION / wmax;
        /* an absurd spin must not split the step without end: at most LC_MAX_TRIALS rotation-limited
         * intervals (the check is then coarser for that body) */
        if (trial < dt / LC_MAX_TRIALS) trial = fmin(remaining, dt / LC_MAX_TRIALS);
        /* the rest of the previous trial, if the turning limit allows it: then its end is the same */
        can_reuse = local_next && trial_left > 0.0 && trial_left <= trial;
        if (can_reuse) trial = trial_left;
        if (++passes > w->def.max_events_per_step + 2 * LC_MAX_TRIALS)
            return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                               "the step needed more than max_events_per_step impacts and intervals (stiff forces or extreme speeds?)");
        if (w->last.force_evaluations > LC_MAX_FORCE_EVALUATIONS_PER_STEP ||
            w->last.serial_iterations > LC_MAX_SERIAL_ITERATIONS_PER_STEP)
            return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                               "the step needed more than " LC_STRINGIFY(LC_MAX_FORCE_EVALUATIONS_PER_STEP)
                               " force evaluations or " LC_STRINGIFY(LC_MAX_SERIAL_ITERATIONS_PER_STEP)
                               " serial impulse passes (stiff forces or extreme speeds?)");
        if ((double)w->last.solver_work > (double)LC_MAX_SOLVER_WORK_PER_BODY * (double)w->count)
            return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                               "the step's contact and impulse solves needed more than " LC_STRINGIFY(LC_MAX_SOLVER_WORK_PER_BODY)
                               " matrix entries per body (lc_counters.solver_work; bodies piled onto one spot?)");
        /* After an impact in free flight (nothing resting, no spring between bodies, the same trial
         * end), only the bodies of that impact move differently: every other body keeps its trial
         * path to the previous trial's end, and the crossings found between two such bodies stay
         * valid. Then only the impact's bodies are re-advanced, to that same end, and only their pairs
         * are tested again, instead of the whole world. */
        local = can_reuse && nrest == 0 && events == events_before && !body_springs;
        ts = lc_stage_begin(w);
        if (local) {
            if (lc_integrate_rows(w, s0, trial, drows, ndirty, rest, 0, scratch) != 0) goto oom;
            for (i = 0; i < ndirty; ++i) memcpy(&s1[drows[i] * 6], &scratch[drows[i] * 6], 6 * sizeof(double));
        } else {
            if (lc_integrate(w, s0, trial, rows, nrows, rest, nrest, s1) != 0) goto oom;
        }
        lc_stage_end(w, &w->last.time_integration, ts);
        for (i = 0; i < nrows; ++i) {
            int k;
            for (k = 0; k < 6; ++k)
                if (!isfinite(s1[rows[i] * 6 + k]))
                    return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                                       "integration produced a non-finite state (forces too stiff for dt?)");
        }
        if (nrest > 0) {
            uint8_t *mark = lc_buf_get(&w->b_emark, (size_t)w->count);
            if (mark == NULL) goto oom;
            memset(mark, 0, (size_t)w->count);
            if (lc_contact_energy_blew_up(w, s0, s1, rest, nrest, mark))
                return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                                   "contact forces gained energy (speeds or spins beyond what dt can resolve)");
        }
        if (keep_for_warm_start(w, rest, nrest) != 0) goto oom;
        tmin = trial;

        /* vertices that entered another body during the trial step */
        ts = lc_stage_begin(w);
        if (local) {
            nc = nkept = keep_clean_crossings(w, dirty, last_tmin);
            np = lc_broad_phase_of(w, s0, s1, w->def.contact_distance, dirty, drows, ndirty, &w->b_pairs);
        } else {
            np = lc_broad_phase(w, s0, s1, w->def.contact_distance, &w->b_pairs);
        }
        if (np < 0) goto oom;
        pairs = (const int *)w->b_pairs.p;
        for (i = 0; i < np && nstalled <= LC_MAX_STALLED; ++i) {
            nc = lc_find_crossings(w, s0, s1, pairs[2 * i], pairs[2 * i + 1], &w->b_cross, nc);
            if (nc < 0) goto oom;
        }
        /* past LC_MAX_STALLED the list is full (and no crossing is looked for): only its entries */
        nc = drop_stalled(w, stalled, nstalled < LC_MAX_STALLED ? nstalled : LC_MAX_STALLED, nc);
        nc = drop_resting_drift(w, rest, nrest, s1, nc);
        if (nc < 0) goto oom;
        {
            /* a body touching nothing and tied by no spring to another body moves on its own: its
             * time-of-impact evaluations (and swept samples) need only the two bodies */
            coupled = lc_buf_get(&w->b_coupled, (size_t)w->count * sizeof(int));
            if (coupled == NULL) goto oom;
            memset(coupled, 0, (size_t)w->count * sizeof(int));
            for (i = 0; i < nrest; ++i) coupled[rest[i].a] = coupled[rest[i].b] = 1;
            for (i = 0; i < w->spring_count; ++i)
                if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) {
                    coupled[lc_world_body_index(w, w->springs[i].def.body_a)] = 1;
                    coupled[lc_world_body_index(w, w->springs[i].def.body_b)] = 1;
                }
        }
        for (i = nkept; i < nc; ++i) ((lc_crossing *)w->b_cross.p)[i].t_hi = trial;
        nc = swept_check(w, s0, s1, trial, pairs, np, nc, coupled, rows, nrows, rest, nrest);
        lc_stage_end(w, &w->last.time_detection, ts);
        if (nc < 0) goto oom;
        cross = (lc_crossing *)w->b_cross.p;
        w->cross_count = nc;
        /* earliest time of impact; a crossing whose gap is still open at the best time so far is later.
         * Each evaluation advances only the islands of the crossing's two bodies; those islands at
         * the best time so far are kept for the next crossing of the same islands (a pile is one
         * island, and each of its integrations solves the whole pile's contact forces). */
        ts = lc_stage_begin(w);
        if (nc > 0 && build_islands(w, rows, nrows, rest, nrest, &isl) != 0) goto oom;
        {
            double *at_best = NULL, at_t = -1.0;
            int at_ia = -2, at_ib = -2;
            for (i = 0; i < nc && !(best >= 0 && tmin == 0.0); ++i) {
                double tau;
                const int *erows;
                int nerows, nerest;
                lc_touch *erest;
                if (islands_of(w, &isl, cross[i].a, cross[i].b, &erows, &nerows, &erest, &nerest) != 0) goto oom;
                if (best >= 0) {
                    double g;
                    int ia = isl.of[cross[i].a], ib = isl.of[cross[i].b];
                    if (at_best == NULL && (at_best = lc_buf_get(&w->b_sample0, bytes)) == NULL) goto oom;
                    if (at_t != tmin || at_ia != ia || at_ib != ib) {
                        if (lc_integrate(w, s0, tmin, erows, nerows, erest, nerest, at_best) != 0) goto oom;
                        at_t = tmin;
                        at_ia = ia;
                        at_ib = ib;
                    }
                    g = lc_vertex_edge_gap(w, at_best, cross[i].a, cross[i].vertex, cross[i].b, cross[i].edge);
                    if (g > w->def.contact_gap) continue;
                }
                tau = lc_time_of_impact(w, s0, fmin(tmin, cross[i].t_hi), &cross[i], erows, nerows, erest, nerest,
                                        scratch);
                if (tau < 0.0) continue;
                if (best < 0 || tau < tmin) { tmin = tau; best = i; }
            }
        }
        lc_stage_end(w, &w->last.time_toi_search, ts);
        if (best < 0) {
            local_next = 0;
            memcpy(w->state, s1, (size_t)w->count * 6 * sizeof(double));
            remaining -= trial;
            if (remaining < 1e-14 * dt) remaining = 0.0;
            w->time = t0 + (dt - remaining);
            continue;
        }

        ts = lc_stage_begin(w);
        if (tmin > 0.0) {
            int ba = cross[best].a, bb = cross[best].b;
            if (lc_integrate_rows(w, s0, tmin, rows, nrows, rest, nrest, w->state) != 0) goto oom;
            /* another vertex of the pair (corner against corner) already inside, deeper than any
             * crossing test can see from here on: the pair met earlier, find when */
            if (lc_pair_separation(w, w->state, ba, bb) < -0.5 * w->def.contact_gap &&
                lc_pair_separation(w, s0, ba, bb) > w->def.contact_gap) {
                const int *erows;
                int nerows, nerest;
                lc_touch *erest;
                double t2;
                if (islands_of(w, &isl, ba, bb, &erows, &nerows, &erest, &nerest) != 0) goto oom;
                lc_stage_end(w, &w->last.time_integration, ts);
                ts = lc_stage_begin(w);
                t2 = lc_pair_time_of_impact(w, s0, tmin, ba, bb, erows, nerows, erest, nerest, scratch);
                lc_stage_end(w, &w->last.time_toi_search, ts);
                ts = lc_stage_begin(w);
                if (t2 < 0.0) goto oom;
                tmin = t2;
                by_pair = 1;
                if (lc_integrate_rows(w, s0, tmin, rows, nrows, rest, nrest, w->state) != 0) goto oom;
            }
        } else {
            memcpy(w->state, s0, (size_t)w->count * 6 * sizeof(double));
        }
        lc_stage_end(w, &w->last.time_integration, ts);
        remaining -= tmin;
        w->time = t0 + (dt - remaining);
        if (remaining < 1e-14 * dt) remaining = 0.0;

        ts = lc_stage_begin(w);
        nimp = gather_impact(w, w->state, &cross[best], by_pair);
        if (nimp < 0) goto oom;
        /* past max_events_per_step (an impact storm: extreme speeds in a small box, a jam at e > 0)
         * every further impact is inelastic, which ends the storm; the pass cap above still bounds it */
        hits = lc_resolve_impacts(w, w->state, (lc_touch *)w->b_impact.p, nimp, events < w->def.max_events_per_step);
        if (hits < 0) goto oom;
        {
            lc_touch *t = (lc_touch *)w->b_impact.p;
            int dissipative = 0;
            for (i = 0; i < nimp; ++i)
                if (t[i].value > 0.0) {
                    w->last.impulses++;
                    if (lc_push_contact(w, &t[i], LC_CONTACT_COLLISION) != 0) goto oom;
                    if (t[i].elasticity < 1.0) {
                        dissipative = 1;
                        last_impact_body = w->is_static[t[i].a] ? t[i].b : t[i].a;
                    }
                }
            dissipative_events += dissipative;
        }
        lc_stage_end(w, &w->last.time_impulses, ts);
        w->last.collisions++;
        events++;
        {
            /* the impact's bodies are the ones whose paths changed (see `local` above) */
            lc_touch *t = (lc_touch *)w->b_impact.p;
            for (i = 0; i < ndirty; ++i) dirty[drows[i]] = 0;
            ndirty = 0;
            for (i = 0; i < nimp; ++i) {
                int ab[2], q;
                ab[0] = t[i].a;
                ab[1] = t[i].b;
                for (q = 0; q < 2; ++q)
                    if (!w->is_static[ab[q]] && !dirty[ab[q]]) { dirty[ab[q]] = 1; drows[ndirty++] = ab[q]; }
            }
            local_next = nrest == 0;
            trial_left = trial - tmin;
            last_tmin = tmin;
        }
        if (hits == 0 && tmin == 0.0) {
            if (nstalled < LC_MAX_STALLED) stalled[nstalled] = cross[best];
            nstalled++;
        }
    }
    if (remaining == 0.0) w->time = t0 + dt;
    if (handover != NULL) *handover = -1;
    if (lc_step_energy_blew_up(w, backup, dt, started_deep))
        return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                           "the step gained far more energy than its external forces and thrusters can give "
                           "(speeds or spins beyond what dt can resolve)");
    {
        int pr;
        ts = lc_stage_begin(w);
        pr = project_positions(w);
        lc_stage_end(w, &w->last.time_projection, ts);
        if (pr < 0) goto oom;
        if (pr > 0)
            return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                               "bodies still overlap after the end-of-step projection (forces far too large for dt?)");
    }

    /* resting contacts at the end of the step, with the forces of the last evaluation */
    {
        lc_touch *rest = (lc_touch *)w->b_touch.p;
        for (i = 0; i < nrest; ++i) {
            lc_touch t = rest[i];
            lc_touch_update(w, w->state, &t);
            if (lc_push_contact(w, &t, LC_CONTACT_RESTING) != 0) goto oom;
        }
    }
    /* what the event rows rest on at the end, for the next step's regime (the projection's last search
     * was at the end state when it kept its touches) */
    for (i = 0; i < nrows; ++i) w->rests_dissipative[rows[i]] = 0;
    *marks_known = w->end_touch_count >= 0 || nrows == 0;
    if (w->end_touch_count >= 0) lc_regime_mark(w, (const lc_touch *)w->b_end_touches.p, w->end_touch_count);
    return LC_OK;
oom:
    return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
}

/* The bodies that went where their island's build did not foresee: the boxes their actual paths swept
 * (start and end poses, the bulge of their turn, contact_distance) overlap another body's where the
 * build had no pair, so a contact between them could have been missed. Their swept boxes are added to
 * `reach` for the next try. Returns how many pairs that was, or -1 without memory. */
static int unforeseen_pairs(lc_world *w, const double *backup, double *reach)
{
    int n = w->count, i, np, found = 0, outside = 0;
    double *boxes = lc_buf_get(&w->b_reach_boxes, (size_t)n * 4 * sizeof(double));
    const double *built = lc_islands_boxes(w->islands);
    const int *pairs;
    if (boxes == NULL) return -1;
    for (i = 0; i < n; ++i) {
        double turn = fabs(w->state[i * 6 + SA] - backup[i * 6 + SA]);
        double bulge = w->shape[i].radius * (turn < 3.0 ? turn * turn / 8.0 : 1.0);
        const double *b = &boxes[4 * i], *p = &built[4 * i];
        lc_swept_box(w, backup, w->state, i, w->def.contact_distance + bulge, &boxes[4 * i]);
        if (b[0] < p[0] || b[1] < p[1] || b[2] > p[2] || b[3] > p[3]) outside = 1;
    }
    /* every path inside the box its island was built with: the build's pairs hold every meeting */
    if (!outside) return 0;
    np = lc_broad_phase_boxes(w, boxes, &w->b_pairs);
    if (np < 0) return -1;
    pairs = (const int *)w->b_pairs.p;
    for (i = 0; i < np; ++i) {
        int a = pairs[2 * i], b = pairs[2 * i + 1], q;
        if (lc_islands_has_pair(w->islands, a, b)) continue;
        found++;
        for (q = 0; q < 2; ++q) {
            int r = q ? b : a;
            double *x = &reach[4 * r];
            const double *y = &boxes[4 * r];
            if (w->is_static[r]) continue;
            if (x[0] > x[2]) {
                memcpy(x, y, 4 * sizeof(double));
            } else {
                x[0] = fmin(x[0], y[0]);
                x[1] = fmin(x[1], y[1]);
                x[2] = fmax(x[2], y[2]);
                x[3] = fmax(x[3], y[3]);
            }
        }
    }
    return found;
}

/* The contact advance of island isl over dt: LC_OK, or the step has failed (and is undone). *stuck is
 * set to the island's index + 1 when its projection could not separate its bodies. */
static lc_status contact_island(lc_world *w, const lc_island *isl, int index, double dt, double time0,
                                double *backup, int *stuck)
{
    double ts = lc_stage_begin(w);
    int r = lc_contact_advance(w, w->contact, isl, dt);
    lc_stage_end(w, &w->last.time_contact_regime, ts);
    if (r == -1) return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
    if (r == -2)
        return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                           "the contact regime produced a non-finite state (forces too stiff for dt?)");
    if (r == -3) *stuck = index + 1;
    return LC_OK;
}

/* One try at the step: the islands of the current state (their swept boxes grown to `reach`), each
 * advanced in its regime. LC_OK, or the step has failed (and is undone). A try stops early, with
 * *stuck the island's index + 1, when a contact island ends overlapping. */
static lc_status advance_islands(lc_world *w, double dt, double time0, double *backup, const double *reach,
                                 int *marks_known, int *stuck)
{
    int *event_rows = lc_buf_get(&w->b_event_rows, (size_t)w->count * sizeof(int));
    uint8_t *excluded = lc_buf_get(&w->b_excluded, (size_t)w->count);
    int n_event = 0, k, i, any_contact = 0;
    double t0 = time0;
    lc_status st;
    if (!event_rows || !excluded || lc_islands_build(w, w->islands, dt, NULL, reach) != 0)
        return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
    memset(excluded, 0, (size_t)w->count);
    for (k = 0; k < lc_islands_count(w->islands); ++k) {
        lc_island isl = lc_islands_get(w->islands, k);
        w->last.islands++;
        if (lc_regime_of(w, &isl, dt) != LC_REGIME_CONTACT || forced_event(w, &isl)) continue;
        st = contact_island(w, &isl, k, dt, time0, backup, stuck);
        if (st != LC_OK || *stuck) return st;
        for (i = 0; i < isl.nrows; ++i) excluded[isl.rows[i]] = 1;
        any_contact = 1;
    }
    /* the event islands' rows together, in row order; an island whose touch comes to rest is handed to
     * the contact regime at that instant, and the others go on from there */
    for (;;) {
        int handover = -1;
        double t_handover = 0.0;
        n_event = 0;
        for (i = 0; i < w->count; ++i)
            if (!w->is_static[i] && !excluded[i]) event_rows[n_event++] = i;
        w->time = t0;
        if (any_contact) {
            /* the event regime's pairs leave out the contact islands' bodies, and its kept end touches
             * would not describe them */
            w->excluded = excluded;
            w->end_touch_count = -1;
        }
        if (n_event == 0 && any_contact) {
            /* every island was the contact regime's: no event pass (its broadphases would find nothing) */
            w->excluded = NULL;
            *marks_known = 1;
            w->time = time0 + dt;
            if (lc_step_energy_blew_up(w, backup, dt, 0))
                return step_failed(w, backup, time0, LC_ERR_NUMERIC,
                                   "the step gained far more energy than its external forces and thrusters can give "
                                   "(speeds or spins beyond what dt can resolve)");
            return LC_OK;
        }
        st = event_step(w, time0 + dt - t0, t0, time0, backup, event_rows, n_event, marks_known,
                        w->def.regime == LC_REGIME_AUTO ? &handover : NULL, &t_handover);
        w->excluded = NULL;
        if (st != LC_OK || handover < 0) break;
        {
            lc_island isl = lc_islands_get(w->islands, handover);
            t0 += t_handover;
            w->time = t0;
            st = contact_island(w, &isl, handover, time0 + dt - t0, time0, backup, stuck);
            if (st != LC_OK || *stuck) return st;
            for (i = 0; i < isl.nrows; ++i) excluded[isl.rows[i]] = 1;
            any_contact = 1;
        }
    }
    if (any_contact) w->end_touch_count = -1;
    return st;
}

/* Back to the state the step began in, for another try. */
static void restart_step(lc_world *w, const double *backup, const uint8_t *marks0, double time0)
{
    w->last.island_retries++;
    memcpy(w->state, backup, (size_t)w->count * 6 * sizeof(double));
    memcpy(w->rests_dissipative, marks0, (size_t)w->count);
    w->time = time0;
    w->contact_count = 0;
    lc_contact_regime_retry(w->contact);
}

lc_status lc_world_step(lc_world *w, double dt)
{
    size_t bytes;
    double *backup, *reach = NULL, time0;
    uint8_t *marks0;
    int i, try, marks_known = 0;
    lc_status st;
    if (w == NULL) return LC_ERR_NULL;
    if (!isfinite(dt)) return lc_fail(w, LC_ERR_NOT_FINITE, "dt is not finite (%g)", dt);
    if (!(dt > 0.0) || dt > 1.0) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "dt = %g is outside (0, 1] s", dt);
    memset(&w->last, 0, sizeof w->last);
    w->step_t0 = lc_stage_begin(w);
    w->last.steps = 1;
    w->step_dt = dt;
    w->contact_count = 0;
    time0 = w->time;
    bytes = (size_t)(w->count > 0 ? w->count : 1) * 6 * sizeof(double);
    backup = lc_buf_get(&w->b_backup, bytes);
    marks0 = lc_buf_get(&w->b_marks0, (size_t)(w->count > 0 ? w->count : 1));
    w->force_event = lc_buf_get(&w->b_force_event, (size_t)(w->count > 0 ? w->count : 1));
    if (!backup || !marks0 || !w->force_event) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memset(w->force_event, 0, (size_t)(w->count > 0 ? w->count : 1));
    if (w->count == 0) {
        /* nothing to move: time still passes */
        w->time += dt;
        lc_stage_end(w, &w->last.time_step, w->step_t0);
        lc_counters_add(&w->total, &w->last);
        w->error[0] = '\0';
        return LC_OK;
    }
    memcpy(backup, w->state, (size_t)w->count * 6 * sizeof(double));
    if (lc_regime_refresh(w) != 0 || lc_contact_regime_begin_step(w->contact) != 0)
        return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
    memcpy(marks0, w->rests_dissipative, (size_t)w->count);
    /* Tries: a try whose bodies went where their islands' build did not foresee is taken again with
     * those islands grown to where they went (LC_MAX_ISLAND_TRIES at most); one whose contact island
     * ended overlapping for no such reason is taken again with that island in the event regime (once
     * per island: its rows stay marked for the step, so this ends). */
    for (try = 0;; ++try) {
        int found = 0, stuck = 0;
        st = advance_islands(w, dt, time0, backup, reach, &marks_known, &stuck);
        if (st != LC_OK) {
            memcpy(w->rests_dissipative, marks0, (size_t)w->count);
            return st;
        }
        if (try < LC_MAX_ISLAND_TRIES - 1) {
            if (reach == NULL) {
                reach = lc_buf_get(&w->b_reach, (size_t)w->count * 4 * sizeof(double));
                if (reach == NULL) return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
                for (i = 0; i < w->count; ++i) {
                    reach[4 * i] = 1.0;
                    reach[4 * i + 2] = -1.0;
                }
            }
            found = unforeseen_pairs(w, backup, reach);
            if (found < 0) return step_failed(w, backup, time0, LC_ERR_NO_MEMORY, "out of memory during the step");
        }
        if (found == 0 && stuck) {
            lc_island isl = lc_islands_get(w->islands, stuck - 1);
            for (i = 0; i < isl.nrows; ++i) w->force_event[isl.rows[i]] = 1;
            --try;
        } else if (found == 0) {
            break;
        }
        restart_step(w, backup, marks0, time0);
    }
    w->time = time0 + dt;
    for (i = 0; i < w->count * 6; ++i)
        if (!isfinite(w->state[i])) return step_failed(w, backup, time0, LC_ERR_NUMERIC, "the state became non-finite");
    /* the marks describe the end state unless the event regime could not tell (the next step looks) */
    w->regime_edits = marks_known ? w->edits : w->edits - 1;
    lc_stage_end(w, &w->last.time_step, w->step_t0);
    lc_counters_add(&w->total, &w->last);
    w->error[0] = '\0';
    return LC_OK;
}
