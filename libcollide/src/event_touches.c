/* The event regime's touches: the resting set of a pass (warm-started from the last pass's forces),
 * the group of touches an impact acts on, and the whole-world searches, which take the touches the
 * last step's projection found when nothing has moved since. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "event_touches.h"
#include "events.h"
#include "snapshot_io.h"

struct lc_event_touches {
    lc_buf pairs;          /* the broad phase's pairs of a search */
    lc_buf rest;           /* the resting set of the pass in progress */
    lc_buf impact;         /* the touches of an impact */
    lc_buf group;          /* an impact group's queue and marks */
    int group_rows;        /* the marks are all 0 for a world of this many rows (-1: unknown) */
    lc_buf warm, hash;     /* the last pass's resting touches and forces (warm_count), and their hash table */
    int warm_count;
    /* the touches the last step's projection found at the state it ended in (end_count, -1: none), that
     * state and the world's `edits` then */
    lc_buf end_touches, end_state;
    int end_count;
    unsigned long end_edits;
};

lc_event_touches *lc_event_touches_create(void)
{
    lc_event_touches *et = calloc(1, sizeof *et);
    if (et != NULL) {
        et->end_count = -1;
        et->group_rows = -1;
    }
    return et;
}

void lc_event_touches_destroy(lc_event_touches *et)
{
    if (et == NULL) return;
    lc_buf_free(&et->pairs);
    lc_buf_free(&et->rest);
    lc_buf_free(&et->impact);
    lc_buf_free(&et->group);
    lc_buf_free(&et->warm);
    lc_buf_free(&et->hash);
    lc_buf_free(&et->end_touches);
    lc_buf_free(&et->end_state);
    free(et);
}

void lc_event_touches_rows_shifted(lc_event_touches *et) { et->warm_count = 0; }

void lc_event_touches_forget_end(lc_event_touches *et) { et->end_count = -1; }

int lc_event_touches_end(const lc_event_touches *et, const lc_touch **t)
{
    *t = (const lc_touch *)et->end_touches.p;
    return et->end_count;
}

int lc_event_touches_keep_end(lc_world *w, lc_event_touches *et, lc_buf *found, int n)
{
    double *kept = lc_buf_get(&et->end_state, (size_t)w->count * 6 * sizeof(double));
    lc_buf swap = *found;
    if (kept == NULL) return -1;
    memcpy(kept, w->state, (size_t)w->count * 6 * sizeof(double));
    *found = et->end_touches;
    et->end_touches = swap;
    et->end_count = n;
    et->end_edits = w->edits;
    return 0;
}

/* The touches the last step's projection found at the state it ended in, moved into buf, if this
 * gather is at that same state (-1: none kept, or something changed since). The first gather of a
 * step is at the state the previous one ended in, so in a world at rest or in free flight one of the
 * two whole-world touch searches per step is saved (the projection has to look at the end state,
 * the next step's resting set at its start). One use: every later gather of the step is elsewhere. */
static int kept_end_touches(lc_world *w, lc_event_touches *et, const double *state, lc_buf *buf)
{
    int n = et->end_count;
    lc_buf swap;
    et->end_count = -1;
    if (n < 0 || et->end_edits != w->edits || state != w->state ||
        memcmp(et->end_state.p, state, (size_t)w->count * 6 * sizeof(double)) != 0)
        return -1;
    swap = *buf;
    *buf = et->end_touches;
    et->end_touches = swap;
    return n;
}

/* Touches at `state` with gap < contact_distance, appended to buf from 0: between all near pairs, or
 * (list != NULL) only the pairs with at least one of the listed bodies (marked[row] != 0). */
static int gather_touches_of(lc_world *w, lc_event_touches *et, const double *state, const uint8_t *marked,
                             const int *list, int nlist, lc_buf *buf)
{
    int np, i, n = 0;
    const int *pairs;
    if (list == NULL && (n = kept_end_touches(w, et, state, buf)) >= 0) return n;
    n = 0;
    np = list ? lc_broad_phase_of(w, state, state, w->def.contact_distance, marked, list, nlist, &et->pairs)
              : lc_broad_phase(w, state, state, w->def.contact_distance, &et->pairs);
    if (np < 0) return -1;
    pairs = (const int *)et->pairs.p;
    for (i = 0; i < np; ++i) {
        n = lc_collect_touches(w, state, pairs[2 * i], pairs[2 * i + 1], w->def.contact_distance, buf, n);
        if (n < 0) return -1;
    }
    return n;
}

/* Touches between all near pairs at `state` with gap < contact_distance, appended to buf from 0. */
int lc_event_gather_touches(lc_world *w, lc_event_touches *et, const double *state, lc_buf *buf)
{
    return gather_touches_of(w, et, state, NULL, NULL, 0, buf);
}

/* Key of a touch (bodies, vertex and edge) for the warm start's hash table. */
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
static int warm_start(const lc_world *w, lc_event_touches *et, lc_touch *t, int n)
{
    const lc_touch *old = (const lc_touch *)et->warm.p;
    int m = et->warm_count, size = 1, i;
    int *table;
    if (m == 0 || n == 0) return 0;
    while (size < 2 * m) size *= 2;
    table = lc_buf_get(&et->hash, (size_t)size * sizeof(int));
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
int lc_event_resting(lc_world *w, lc_event_touches *et, double *state, int *impacts, const uint8_t *marked,
                     const int *list, int nlist, int mid_step, int *started_deep, int *persisting, lc_touch **rest)
{
    int n, i, k = 0, urgent = 0;
    lc_touch *t;
    n = gather_touches_of(w, et, state, marked, list, nlist, &et->rest);
    t = *rest = (lc_touch *)et->rest.p;
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
        lc_touch *x = lc_buf_get(&et->impact, (size_t)n * sizeof(lc_touch));
        if (x == NULL) return -1;
        memcpy(x, t, (size_t)n * sizeof(lc_touch));
        if (lc_resolve_impacts(w, state, x, n, *impacts < w->def.max_events_per_step) < 0) return -1;
        for (i = 0; i < n; ++i) {
            if (x[i].value > 0.0) {
                w->last.impulses++;
                if (lc_record_impact(w, &x[i], LC_IMPACT_EVENT) != 0) return -1;
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
    if (warm_start(w, et, t, k) != 0) return -1;
    return k;
}

/* Keeps this pass's resting touches and their forces for the next pass's warm start. */
int lc_event_keep_warm(lc_event_touches *et, const lc_touch *t, int n)
{
    lc_touch *dst = lc_buf_get(&et->warm, (size_t)(n > 0 ? n : 1) * sizeof(lc_touch));
    if (dst == NULL) return -1;
    if (n > 0) memcpy(dst, t, (size_t)n * sizeof(lc_touch));
    et->warm_count = n;
    return 0;
}

/* Impact set at the time of impact: every touch in the group of bodies connected by touches to the
 * bodies of the impacting crossing (so an impact travels through a row of touching blocks), found by
 * spreading out from those two bodies, so its cost follows the group's size rather than the world's.
 * When the time came from the pair's separation (by_pair), the crossing's vertex need not be the one
 * touching: the pair's touches are its separating-axis manifold alone. */
int lc_event_impact_group(lc_world *w, lc_event_touches *et, const double *state, const lc_crossing *c, int by_pair,
                          lc_touch **out, int (*sync)(void *ctx, int row), void *ctx)
{
    int *queue = lc_buf_get(&et->group, (size_t)w->count * (sizeof(int) + 1));
    uint8_t *seen;   /* 1 queued, 2 done */
    int n = 0, i, k, q, nq = 0, have = 0;
    lc_touch *t;
    if (queue == NULL) return -1;
    seen = (uint8_t *)(queue + w->count);
    /* only the queued bodies are marked, and cleared at the end: zeroing every mark at each impact
     * was a pass over the world per impact. After a failure, or for another world size, all of them. */
    if (et->group_rows != w->count) memset(seen, 0, (size_t)w->count);
    et->group_rows = -1;
    if (!w->is_static[c->a]) { seen[c->a] = 1; queue[nq++] = c->a; }
    if (!w->is_static[c->b]) { seen[c->b] = 1; queue[nq++] = c->b; }
    for (q = 0; q < nq; ++q) {
        int body = queue[q], m, j;
        const int *near = NULL;
        /* while the broad phase tracks the trial (free flight), only the bodies whose reach meets this
         * one's circle grown by contact_distance can pass the distance test below: the same bodies in
         * the same order, without visiting every body */
        {
            double qb[4], rq = w->shape[body].radius + w->def.contact_distance;
            qb[0] = state[body * 6 + SX] - rq;
            qb[1] = state[body * 6 + SY] - rq;
            qb[2] = state[body * 6 + SX] + rq;
            qb[3] = state[body * 6 + SY] + rq;
            m = lc_broad_phase_near(w, qb, &near);
            if (m == -1) return -1;
            if (m < 0) m = w->count;
        }
        for (j = 0; j < m; ++j) {
            double dx, dy, r;
            int before = n;
            k = near != NULL ? near[j] : j;
            if (k == body || seen[k] == 2) continue;   /* a pair with a finished body was collected */
            /* a body whose clock lags (event_regime.c) is brought to the impact's time first */
            if (near != NULL && sync != NULL && sync(ctx, k) != 0) return -1;
            if (w->excluded && w->excluded[k]) continue;   /* another island's */
            dx = state[body * 6 + SX] - state[k * 6 + SX];
            dy = state[body * 6 + SY] - state[k * 6 + SY];
            r = w->shape[body].radius + w->shape[k].radius + w->def.contact_distance;
            if (dx * dx + dy * dy > r * r) continue;
            n = lc_collect_touches(w, state, body < k ? body : k, body < k ? k : body, w->def.contact_distance,
                                   &et->impact, n);
            if (n < 0) return -1;
            if (n > before && !w->is_static[k] && !seen[k]) { seen[k] = 1; queue[nq++] = k; }
        }
        seen[body] = 2;
    }
    for (q = 0; q < nq; ++q) seen[queue[q]] = 0;
    et->group_rows = w->count;
    t = (lc_touch *)et->impact.p;
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
        lc_touch *x = lc_buf_get(&et->impact, (size_t)(n + 1) * sizeof(lc_touch));
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
    *out = (lc_touch *)et->impact.p;
    return n;
}

void lc_event_touches_save(const lc_event_touches *et, const lc_world *w, lc_writer *out)
{
    int i, end = et->end_count;
    lc_put_i32(out, et->warm_count);
    for (i = 0; i < et->warm_count; ++i) lc_put_touch(out, &((const lc_touch *)et->warm.p)[i]);
    /* end touches kept before an API change are never taken (kept_end_touches): written as none */
    if (et->end_edits != w->edits) end = -1;
    lc_put_i32(out, end);
    if (end < 0) return;
    lc_put_u64(out, et->end_edits);
    for (i = 0; i < end; ++i) lc_put_touch(out, &((const lc_touch *)et->end_touches.p)[i]);
    for (i = 0; i < w->count * 6; ++i) lc_put_f64(out, ((const double *)et->end_state.p)[i]);
}

int lc_event_touches_load(lc_event_touches *et, const lc_world *w, lc_reader *in)
{
    int n = lc_get_count(in, 0, 1 << 28, LC_TOUCH_BYTES, "the warm-start touches"), i;
    lc_touch *t = lc_buf_get(&et->warm, (size_t)(n > 0 ? n : 1) * sizeof(lc_touch));
    double *st;
    if (t == NULL) return -1;
    for (i = 0; i < n; ++i) lc_get_touch(in, w, &t[i]);
    et->warm_count = in->bad ? 0 : n;
    et->end_count = -1;
    n = lc_get_count(in, -1, 1 << 28, LC_TOUCH_BYTES, "the kept end touches");
    if (n < 0 || in->bad) return 0;
    et->end_edits = (unsigned long)lc_get_u64(in);
    t = lc_buf_get(&et->end_touches, (size_t)(n > 0 ? n : 1) * sizeof(lc_touch));
    st = lc_buf_get(&et->end_state, (size_t)(w->count > 0 ? w->count : 1) * 6 * sizeof(double));
    if (t == NULL || st == NULL) return -1;
    for (i = 0; i < n; ++i) lc_get_touch(in, w, &t[i]);
    for (i = 0; i < w->count * 6; ++i) st[i] = lc_get_f64(in);
    if (!in->bad) et->end_count = n;
    return 0;
}
