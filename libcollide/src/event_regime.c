/* The event regime (docs/contact_regime.md), the engine's original exact path: integrate a trial
 * interval, look for vertices that entered another body, back up to the earliest time of impact, apply
 * the impulses there, and continue with the rest of the step; time is never dropped. Resting contact is
 * held by contact forces during the intervals and by the end-of-step projection after them. Its parts:
 * the touches (event_touches.c), the detection (event_crossings.c), the touch islands a time-of-impact
 * search advances (touch_islands.c) and the projection (event_projection.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "event_regime.h"
#include "event_crossings.h"
#include "event_projection.h"
#include "event_touches.h"
#include "events.h"
#include "islands.h"
#include "regime.h"
#include "touch_islands.h"
#include "tunables.h"

#define LC_STRINGIFY_(x) #x
#define LC_STRINGIFY(x) LC_STRINGIFY_(x)

struct lc_event_regime {
    lc_event_touches *touches;
    lc_event_crossings *crossings;
    lc_touch_islands *islands;
    lc_event_projection *projection;
    lc_buf state0, state1, scratch;  /* a pass's start and trial end, and integration scratch (count x 6) */
    lc_buf rows, moved, moved_rows;  /* the advanced rows; the bodies the last impact moved */
    lc_buf marks, at_best;           /* the energy check's marks; the best time of impact's state */
    lc_buf at_lo;                    /* a crossing's rows at the start of its bracket */
    lc_buf clock;                    /* lazy clocks: the time (from the pass's t0) each row's state is at, and its anchor's */
    lc_buf anchor;                   /* lazy clocks: each row's state at its last event */
    lc_buf own;                      /* lazy clocks: 1 where anchor holds the row's anchor */
    lc_buf in_rows;                  /* 1 for the advanced rows (spin_max) */
};

lc_event_regime *lc_event_regime_create(void)
{
    lc_event_regime *er = calloc(1, sizeof *er);
    if (er == NULL) return NULL;
    er->touches = lc_event_touches_create();
    er->crossings = lc_event_crossings_create();
    er->islands = lc_touch_islands_create();
    er->projection = lc_event_projection_create();
    if (!er->touches || !er->crossings || !er->islands || !er->projection) {
        lc_event_regime_destroy(er);
        return NULL;
    }
    return er;
}

void lc_event_regime_destroy(lc_event_regime *er)
{
    if (er == NULL) return;
    lc_event_touches_destroy(er->touches);
    lc_event_crossings_destroy(er->crossings);
    lc_touch_islands_destroy(er->islands);
    lc_event_projection_destroy(er->projection);
    lc_buf_free(&er->state0);
    lc_buf_free(&er->state1);
    lc_buf_free(&er->scratch);
    lc_buf_free(&er->rows);
    lc_buf_free(&er->moved);
    lc_buf_free(&er->moved_rows);
    lc_buf_free(&er->marks);
    lc_buf_free(&er->at_best);
    lc_buf_free(&er->at_lo);
    lc_buf_free(&er->clock);
    lc_buf_free(&er->anchor);
    lc_buf_free(&er->own);
    lc_buf_free(&er->in_rows);
    free(er);
}

void lc_event_regime_rows_shifted(lc_event_regime *er) { lc_event_touches_rows_shifted(er->touches); }

void lc_event_regime_forget_end(lc_event_regime *er) { lc_event_touches_forget_end(er->touches); }

/* 1 if every row moves in closed form (constant applied forces, no applied torque: its spin, which
 * sets the trial interval, stays as it is; no touch: the caller's). */
static int rows_closed_form(const lc_world *w, const int *rows, int nrows)
{
    int i;
    for (i = 0; i < nrows; ++i)
        if (!lc_body_forces_constant(w, rows[i]) || w->ext_torque[rows[i]] != 0.0) return 0;
    return 1;
}

/* Lazy clocks (free flight while the broad phase tracks the trial): an impact advances only the bodies
 * it involves and the ones it looks at to its time; every other body stays where its last event left
 * it until something near it looks at it or the trial ends. w->state and s0 hold each row at
 * clock[row] (the impact's rows are copied from w->state to s0 at the next pass's start). A row is
 * brought to a time in one closed-form advance from its anchor, the state its last event (an impact,
 * or the trial's start) left it in at anchor_t[row]: so its state at any time is the same bits however
 * often, and after whichever other bodies' events, it was looked at. Most rows keep the trial's start
 * as their anchor, and that is their row of s0 until s0's row is first written (keep_anchor): so the
 * clocks start without a copy of every row (at 20 000 bodies, a copy of a state that no longer fits
 * the cache at each trial's first impact). */
typedef struct lazy_clock {
    lc_world *w;
    double *s0, *clock, *anchor, *anchor_t;
    uint8_t *own;   /* 1: the row's anchor is in anchor; 0: it is the row of s0 */
    double now;     /* the time the rows looked at are brought to */
} lazy_clock;

/* Row r of s0 is about to be written: its anchor, if s0 held it, to anchor. */
static void keep_anchor(lazy_clock *lz, int r)
{
    if (lz->own[r]) return;
    memcpy(&lz->anchor[r * 6], &lz->s0[r * 6], 6 * sizeof(double));
    lz->own[r] = 1;
}

/* Row r of w->state at time t, from its anchor. */
static int row_at(lazy_clock *lz, int r, double t)
{
    return lc_integrate_rows(lz->w, lz->own[r] ? lz->anchor : lz->s0, t - lz->anchor_t[r], &r, 1, NULL, 0,
                             lz->w->state);
}

/* The rows' states in w->state are their new anchors, at time t. */
static void anchor_rows(lazy_clock *lz, const int *rows, int n, double t)
{
    int i;
    for (i = 0; i < n; ++i) {
        memcpy(&lz->anchor[rows[i] * 6], &lz->w->state[rows[i] * 6], 6 * sizeof(double));
        lz->own[rows[i]] = 1;
        lz->anchor_t[rows[i]] = t;
    }
}

static int sync_row(void *ctx, int r)
{
    lazy_clock *lz = ctx;
    lc_world *w = lz->w;
    if (w->is_static[r] || lz->clock[r] == lz->now) return 0;
    if (row_at(lz, r, lz->now) != 0) return -1;
    keep_anchor(lz, r);
    memcpy(&lz->s0[r * 6], &w->state[r * 6], 6 * sizeof(double));
    lz->clock[r] = lz->now;
    return 0;
}

static int sync_rows(lazy_clock *lz, const int *rows, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (sync_row(lz, rows[i]) != 0) return -1;
    return 0;
}

/* Brings every body the tracked broad phase finds near each of rows[0..n) (boxes between s and t,
 * grown by margin, as lc_broad_phase_of takes them) to lz->now. */
static int sync_near(lazy_clock *lz, const double *s, const double *t, const int *rows, int n, double margin)
{
    int k;
    for (k = 0; k < n; ++k) {
        double b[4];
        const int *near;
        int m;
        lc_swept_box(lz->w, s, t, rows[k], margin, b);
        m = lc_broad_phase_near(lz->w, b, &near);
        if (m == -1) return -1;
        if (m > 0 && sync_rows(lz, near, m) != 0) return -1;
    }
    return 0;
}

/* The fastest spin |omega| of the advanced rows in s0, which sets the trial interval. Visiting every
 * row at each pass cost a pass over the world per impact (a sixth of 20 000 free-flying blocks' step).
 * While the clocks are lazy, s0's spins change only where an impact's rows are copied in (closed form
 * without torque keeps each spin bit for bit), so the maximum follows those copies; a copy over a row
 * that may have held it asks for a new visit. The same maximum either way (a max of the same set). */
typedef struct spin_max {
    double w;
    int known;
    const uint8_t *in_rows;
} spin_max;

/* Row r of state into s0, keeping m. */
static void copy_row_spin(double *s0, const double *state, int r, spin_max *m)
{
    if (m->known && m->in_rows[r]) {
        if (fabs(s0[r * 6 + SW]) >= m->w) m->known = 0;
        else m->w = fmax(m->w, fabs(state[r * 6 + SW]));
    }
    memcpy(&s0[r * 6], &state[r * 6], 6 * sizeof(double));
}

/* c's pair from s0 to time t into out (erows advanced only where advance): where each crossing check starts. */
static int pair_state_at(lc_world *w, const double *s0, const lc_crossing *c, double t, int advance, const int *erows,
                         int nerows, lc_touch *erest, int nerest, double *out)
{
    memcpy(&out[c->a * 6], &s0[c->a * 6], 6 * sizeof(double));
    memcpy(&out[c->b * 6], &s0[c->b * 6], 6 * sizeof(double));
    return advance ? lc_integrate_rows(w, s0, t, erows, nerows, erest, nerest, out) : 0;
}

/* The time of impact of crossing c within [c->t_lo, h] from s0, advancing the rows erows[0..nerows)
 * with the touches erest[0..nerest) (lc_time_of_impact), or -1. A crossing bracketed within a part of
 * the interval (event_crossings.h) is searched from the part's start, where its vertex is outside
 * (at_lo: a world-sized buffer for the rows there). */
static double crossing_toi(lc_world *w, const double *s0, const lc_crossing *c, double h, const int *erows, int nerows,
                           lc_touch *erest, int nerest, double *at_lo, double *scratch)
{
    double lo = c->t_lo, tau;
    if (!(lo > 0.0)) return lc_time_of_impact(w, s0, h, c, erows, nerows, erest, nerest, scratch);
    if (!(lo < h)) return -1.0;
    if (pair_state_at(w, s0, c, lo, 1, erows, nerows, erest, nerest, at_lo) != 0) return -1.0;
    tau = lc_time_of_impact(w, at_lo, h - lo, c, erows, nerows, erest, nerest, scratch);
    return tau < 0.0 ? tau : lo + tau;
}

/* A vertex's time of impact is where it meets its edge's line at the contact gap. Over a long bracket
 * (a search of a whole part of the step, kept for the rest of the interval) that time is checked
 * against the pair's separation there, as the pass start's impact is (event_advance):
 *  - the pair apart there (by more than contact_distance): while the bodies turn, the vertex met the
 *    line beside the edge; an impulse there would act at no contact and make energy. The time is the
 *    pair's first touch after tau within the bracket, or none if it does not touch by its end;
 *  - another vertex of the pair already inside (corner against corner): the pair met earlier, at its
 *    first touch after the bracket's start.
 * Either is found by bisection on the pair's separation (continuous, negative exactly when the two
 * overlap; c->by_pair set). Returns the time, -1 for none, -2 without memory. */
static double check_touch(lc_world *w, const double *s0, lc_crossing *c, double tau, const int *erows, int nerows,
                          lc_touch *erest, int nerest, double *at, double *scratch)
{
    double sep, lo = c->t_lo, t2;
    if (pair_state_at(w, s0, c, tau, 1, erows, nerows, erest, nerest, at) != 0) return -2.0;
    sep = lc_pair_separation(w, at, c->a, c->b);
    if (sep > w->def.contact_distance) {
        /* the pair at the bracket's end: apart there, it has no touch to find */
        if (pair_state_at(w, s0, c, c->t_hi, 1, erows, nerows, erest, nerest, scratch) != 0) return -2.0;
        if (!(lc_pair_separation(w, scratch, c->a, c->b) < w->def.contact_gap)) return -1.0;
        lo = tau;
    } else if (sep < -0.5 * w->def.contact_gap) {
        /* the pair at the bracket's start */
        if (pair_state_at(w, s0, c, lo, lo > 0.0, erows, nerows, erest, nerest, at) != 0) return -2.0;
        if (!(lc_pair_separation(w, at, c->a, c->b) > w->def.contact_gap)) return tau;   /* touching there already */
    } else {
        return tau;
    }
    /* The impact at the answer resolves the pair's touches closer than contact_distance
     * (lc_event_impact_group): the time tolerance alone leaves the pair up to |v| tol apart (2.7e-5 m
     * at 27 m/s and 1e-6 s, beyond the 1e-5 m of contact_distance), where nothing is applied, and a
     * search from that nearer start would return the start itself again (the vertex then set aside as
     * stalled, and passing into the other body). So the bisection goes on until the pair is within
     * half the band between contact_gap and contact_distance (the round-off between the search's state
     * and the impact's stays far inside the other half); at the default 1e-10 s the time tolerance
     * alone gives that below 5e4 m/s. Free flight moves in closed form: its separation is continuous
     * and each halving brings it closer. */
    t2 = lc_pair_time_of_impact(w, at, (sep > 0.0 ? c->t_hi : tau) - lo, c->a, c->b, erows, nerows, erest, nerest,
                                0.5 * (w->def.contact_distance - w->def.contact_gap), scratch);
    if (t2 < 0.0) return -1.0;
    c->by_pair = 1;
    return lo + t2;
}

static lc_status event_advance(lc_world *w, lc_event_regime *er, const lc_step_try *step, double dt, double t0,
                               const int *event_rows, int nrows, int *marks_known, int *handover, double *t_handover);

lc_status lc_event_advance(lc_world *w, lc_event_regime *er, const lc_step_try *step, double dt, double t0,
                           const int *event_rows, int nrows, int *marks_known, int *handover, double *t_handover)
{
    lc_status st = event_advance(w, er, step, dt, t0, event_rows, nrows, marks_known, handover, t_handover);
    lc_broad_phase_untrack(w);   /* the tracked reach describes this pass's trial only */
    return st;
}

static lc_status event_advance(lc_world *w, lc_event_regime *er, const lc_step_try *step, double dt, double t0,
                               const int *event_rows, int nrows, int *marks_known, int *handover, double *t_handover)
{
    size_t bytes;
    double *s0, *s1, *scratch, *at_lo, remaining, now_t = 0.0;
    int *rows, i, events = 0, nstalled = 0, nrest = 0, passes = 0, persisting = -1, last_impact_body = -1;
    int dissipative_events = 0;
    int *drows, ndirty = 0, local_next = 0, body_springs = 0, started_deep = 0, islands_alone = 0;
    int tracked = 0, may_track = 0, lazy = 0, fresh[2] = {-1, -1}, closed_form = -1;
    lazy_clock lz;
    spin_max spin;
    uint8_t *dirty, *in_rows;
    double last_tmin = 0.0, trial_left = 0.0, ts;
    lc_crossing stalled[LC_MAX_STALLED];
    lc_touch *rest = NULL;
    const lc_touch *end_touches;
    int nend;
    bytes = (size_t)(w->count > 0 ? w->count : 1) * 6 * sizeof(double);
    s0 = lc_buf_get(&er->state0, bytes);
    s1 = lc_buf_get(&er->state1, bytes);
    scratch = lc_buf_get(&er->scratch, bytes);
    at_lo = lc_buf_get(&er->at_lo, bytes);
    rows = lc_buf_get(&er->rows, (size_t)(w->count > 0 ? w->count : 1) * sizeof(int));
    if (!s0 || !s1 || !scratch || !at_lo || !rows) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memcpy(rows, event_rows, (size_t)nrows * sizeof(int));
    dirty = lc_buf_get(&er->moved, (size_t)w->count);
    drows = lc_buf_get(&er->moved_rows, (size_t)w->count * sizeof(int));
    if (!dirty || !drows) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memset(dirty, 0, (size_t)w->count);
    in_rows = lc_buf_get(&er->in_rows, (size_t)(w->count > 0 ? w->count : 1));
    if (!in_rows) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memset(in_rows, 0, (size_t)w->count);
    for (i = 0; i < nrows; ++i) in_rows[rows[i]] = 1;
    spin.w = 0.0;
    spin.known = 0;
    spin.in_rows = in_rows;
    lz.w = w;
    lz.s0 = s0;
    lz.clock = lc_buf_get(&er->clock, (size_t)(w->count > 0 ? w->count : 1) * 2 * sizeof(double));
    lz.anchor = lc_buf_get(&er->anchor, bytes);
    lz.own = lc_buf_get(&er->own, (size_t)(w->count > 0 ? w->count : 1));
    lz.now = 0.0;
    if (lz.clock == NULL || lz.anchor == NULL || lz.own == NULL)
        return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    lz.anchor_t = lz.clock + (w->count > 0 ? w->count : 1);
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) body_springs = 1;
    /* the force callback may tie any body to any other, as a spring between bodies does */
    if (lc_force_callback_on(w)) body_springs = 1;

    remaining = dt;
    while (remaining > 0.0) {
        int nc, best = -1, nimp, hits, by_pair = 0, adv[2], adv_n = 0, at_t_best, best_searched = 1;
        double tmin = remaining, t_best = 0.0;
        lc_crossing *cross;
        lc_touch *impact;

        double trial = remaining, wmax = 0.0;
        int events_before = events, local = 0, can_reuse, free_flight;
        /* after an impact in free flight only the impact's bodies can have come to touch anything:
         * every other pair was apart (nothing rested) and moved without an impact */
        ts = lc_stage_begin(w);
        lz.now = now_t;
        if (lazy) {
            /* the impact's rows to s0 and to their anchors, and what the resting search below looks at
             * to now */
            for (i = 0; i < ndirty; ++i) {
                keep_anchor(&lz, drows[i]);
                copy_row_spin(s0, w->state, drows[i], &spin);
            }
            anchor_rows(&lz, drows, ndirty, lz.now);
            for (i = 0; i < 2; ++i)
                if (fresh[i] >= 0) {
                    keep_anchor(&lz, fresh[i]);
                    copy_row_spin(s0, w->state, fresh[i], &spin);
                }
            if (sync_near(&lz, w->state, w->state, drows, ndirty, w->def.contact_distance) != 0) goto oom;
        }
        if (local_next && !body_springs)
            nrest = lc_event_resting(w, er->touches, w->state, &events, dirty, drows, ndirty, passes > 0, &started_deep,
                                     &persisting, &rest);
        else
            nrest = lc_event_resting(w, er->touches, w->state, &events, NULL, NULL, 0, passes > 0, &started_deep,
                                     &persisting, &rest);
        lc_stage_end(w, &w->last.time_detection, ts);
        if (nrest == -2)
            return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                "a body passed deep into another within the step (speeds or spins beyond what dt can resolve)");
        if (nrest < 0) goto oom;
        /* from here on that touch persists, which the contact regime advances (regime.h); so does a burst
         * of impacts (inelastic collapse: a block bouncing ever lower, e^k, where no speed threshold
         * stops it) */
        if (lazy && (nrest != 0 || events != events_before || !local_next ||
                     (handover != NULL && (persisting >= 0 || dissipative_events >= LC_HANDOVER_EVENTS)))) {
            /* not a local pass: every body to now, as the global clock has them */
            if (sync_rows(&lz, rows, nrows) != 0) goto oom;
            lazy = 0;
        }
        if (handover != NULL && persisting < 0 && dissipative_events >= LC_HANDOVER_EVENTS) persisting = last_impact_body;
        if (handover != NULL && persisting >= 0) {
            lc_island isl = lc_islands_get(w->islands, lc_islands_of(w->islands, persisting));
            if (!lc_regime_too_fast(w, &isl, remaining) && !lc_any_marked(step->force_event, isl.rows, isl.nrows)) {
                *handover = lc_islands_of(w->islands, persisting);
                *t_handover = dt - remaining;
                return LC_OK;
            }
        }
        if (!lazy) memcpy(s0, w->state, (size_t)w->count * 6 * sizeof(double));
        /* Vertex paths are tested as straight lines in the other body's frame; that holds while bodies
         * turn little, so a fast spinner is checked over shorter intervals. In free flight every pair
         * moves on its own and is checked in parts set by its own spin (event_crossings.h): the trial
         * runs to the step's end, and a body no impact reaches gets there in one closed-form advance.
         * Otherwise (resting touches, ties between bodies, forces that change along the path) the
         * fastest spin of the world cuts the trial. */
        /* every row's forces are the same through the step: looked at once, when first needed */
        if (closed_form < 0 && nrest == 0 && !body_springs) closed_form = rows_closed_form(w, rows, nrows);
        free_flight = closed_form == 1 && nrest == 0 && !body_springs;
        if (!free_flight) {
            if (lazy && spin.known) {
                wmax = spin.w;
            } else {
                for (i = 0; i < nrows; ++i) wmax = fmax(wmax, fabs(s0[rows[i] * 6 + SW]));
                spin.w = wmax;
                spin.known = 1;
            }
            if (wmax * trial > LC_MAX_TRIAL_ROTATION) trial = LC_MAX_TRIAL_ROTATION / wmax;
            /* an absurd spin must not split the step without end: at most LC_MAX_TRIALS rotation-limited
             * intervals (the check is then coarser for that body) */
            if (trial < dt / LC_MAX_TRIALS) trial = fmin(remaining, dt / LC_MAX_TRIALS);
        }
        /* the rest of the previous trial, if the turning limit allows it: then its end is the same */
        can_reuse = local_next && trial_left > 0.0 && trial_left <= trial;
        if (lazy && !can_reuse) {
            /* a new trial interval: every body to now (s0 of the lagging rows was theirs) */
            if (sync_rows(&lz, rows, nrows) != 0) goto oom;
            lazy = 0;
        }
        if (can_reuse) trial = trial_left;
        if (++passes > w->def.max_events_per_step + 2 * LC_MAX_TRIALS)
            return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                "the step needed more than max_events_per_step impacts and intervals (stiff forces or extreme speeds?)");
        if (w->last.force_evaluations > LC_MAX_FORCE_EVALUATIONS_PER_STEP ||
            w->last.serial_iterations > LC_MAX_SERIAL_ITERATIONS_PER_STEP)
            return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                "the step needed more than " LC_STRINGIFY(LC_MAX_FORCE_EVALUATIONS_PER_STEP)
                                " force evaluations or " LC_STRINGIFY(LC_MAX_SERIAL_ITERATIONS_PER_STEP)
                                " serial impulse passes (stiff forces or extreme speeds?)");
        if ((double)w->last.solver_work > (double)LC_MAX_SOLVER_WORK_PER_BODY * (double)w->count)
            return lc_step_undo(w, step, LC_ERR_NUMERIC,
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
        /* a local pass wrote only the impact's rows (the others were checked when written) */
        for (i = 0; i < (local ? ndirty : nrows); ++i) {
            int k, r = local ? drows[i] : rows[i];
            for (k = 0; k < 6; ++k)
                if (!isfinite(s1[r * 6 + k]))
                    return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                        "integration produced a non-finite state (forces too stiff for dt?)");
        }
        /* A trial interval's first impact is followed by local passes (above): from that impact on,
         * where every body can be until the interval ends is tracked in a grid (below), and each
         * impact's bodies only are moved in it; their pairs and impact groups are then found among what
         * is near them, not among every body. Free flight only: a body in closed form stays on its
         * path. */
        if (!local) {
            lc_broad_phase_untrack(w);
            tracked = 0;
            may_track = free_flight && nrows >= LC_TRACK_MIN_ROWS;
        } else if (tracked) {
            if (lc_broad_phase_retrack(w, s0, s1, trial, drows, ndirty, w->def.contact_distance) != 0) goto oom;
        }
        /* what this pass's pairs look at (the bodies near the impact's), to now */
        if (lazy && sync_near(&lz, s0, s1, drows, ndirty, w->def.contact_distance) != 0) goto oom;
        if (nrest > 0) {
            uint8_t *mark = lc_buf_get(&er->marks, (size_t)w->count);
            if (mark == NULL) goto oom;
            memset(mark, 0, (size_t)w->count);
            if (lc_contact_energy_blew_up(w, s0, s1, rest, nrest, mark))
                return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                    "contact forces gained energy (speeds or spins beyond what dt can resolve)");
        }
        if (lc_event_keep_warm(er->touches, rest, nrest) != 0) goto oom;
        tmin = trial;

        /* vertices that entered another body during the trial step */
        {
            lc_trial tr;
            lc_moved moved;
            tr.s0 = s0;
            tr.s1 = s1;
            tr.h = trial;
            tr.rows = rows;
            tr.nrows = nrows;
            tr.rest = rest;
            tr.nrest = nrest;
            tr.min_part = free_flight ? dt / LC_MAX_TRIALS : 0.0;
            moved.marked = dirty;
            moved.rows = drows;
            moved.n = ndirty;
            moved.since = last_tmin;
            ts = lc_stage_begin(w);
            nc = lc_event_crossings_find(w, er->crossings, &tr, local ? &moved : NULL, stalled, nstalled, &cross);
            lc_stage_end(w, &w->last.time_detection, ts);
            if (nc < 0) goto oom;
        }
        /* earliest time of impact. Each evaluation advances only the islands of the crossing's two bodies.
         * In free flight every crossing's search is its own: over its whole bracket, once, its result
         * kept while its bodies keep their paths (an impact costs the searches of the crossings it
         * makes, not of every crossing pending in the interval). Otherwise a crossing whose gap is
         * still open at the best time so far is later; those islands at the best time so far are kept
         * for the next crossing of the same islands (a pile is one island, and each of its
         * integrations solves the whole pile's contact forces). */
        ts = lc_stage_begin(w);
        /* a local pass has no resting touch and no spring between bodies: the islands of the last build
         * without touches are still every row on its own */
        if (nc > 0 && !(local && islands_alone) && lc_touch_islands_build(w, er->islands, rows, nrows, rest, nrest) != 0)
            goto oom;
        if (nc > 0) islands_alone = nrest == 0 && !body_springs;
        {
            double *at_best = NULL, at_t = -1.0;
            int at_ia = -2, at_ib = -2;
            for (i = 0; i < nc && !(best >= 0 && tmin == 0.0); ++i) {
                double tau;
                const int *erows;
                int nerows, nerest;
                lc_touch *erest;
                if (free_flight) {
                    int searched = 0;   /* from this pass's start */
                    if (cross[i].toi < 0.0 && cross[i].clear_to < cross[i].t_hi) {
                        /* its bodies to now, for its search from s0 */
                        if (lazy && (sync_row(&lz, cross[i].a) != 0 || sync_row(&lz, cross[i].b) != 0)) goto oom;
                        if (lc_touch_islands_of(er->islands, cross[i].a, cross[i].b, &erows, &nerows, &erest, &nerest) != 0)
                            goto oom;
                        tau = crossing_toi(w, s0, &cross[i], cross[i].t_hi, erows, nerows, erest, nerest, at_lo, scratch);
                        if (tau >= 0.0) {
                            tau = check_touch(w, s0, &cross[i], tau, erows, nerows, erest, nerest, at_lo, scratch);
                            if (tau < -1.5) goto oom;
                        }
                        if (tau < 0.0) cross[i].clear_to = cross[i].t_hi;
                        else cross[i].toi = lz.now + tau;
                        searched = 1;
                    }
                    if (cross[i].toi >= 0.0 && (best < 0 || cross[i].toi < t_best)) {
                        t_best = cross[i].toi;
                        tmin = fmax(t_best - lz.now, 0.0);
                        best = i;
                        best_searched = searched;
                    }
                    continue;
                }
                if (lc_touch_islands_of(er->islands, cross[i].a, cross[i].b, &erows, &nerows, &erest, &nerest) != 0) goto oom;
                if (best >= 0) {
                    double g;
                    int ia = lc_touch_island(er->islands, cross[i].a), ib = lc_touch_island(er->islands, cross[i].b);
                    if (at_best == NULL && (at_best = lc_buf_get(&er->at_best, bytes)) == NULL) goto oom;
                    if (at_t != tmin || at_ia != ia || at_ib != ib) {
                        /* the two islands' rows only: every crossing read here has its bodies in them,
                         * or static (copied below) */
                        if (lc_integrate_rows(w, s0, tmin, erows, nerows, erest, nerest, at_best) != 0) goto oom;
                        at_t = tmin;
                        at_ia = ia;
                        at_ib = ib;
                    }
                    if (w->is_static[cross[i].a]) memcpy(&at_best[cross[i].a * 6], &s0[cross[i].a * 6], 6 * sizeof(double));
                    if (w->is_static[cross[i].b]) memcpy(&at_best[cross[i].b * 6], &s0[cross[i].b * 6], 6 * sizeof(double));
                    g = lc_vertex_edge_gap(w, at_best, cross[i].a, cross[i].vertex, cross[i].b, cross[i].edge);
                    if (g > w->def.contact_gap) continue;
                }
                tau = crossing_toi(w, s0, &cross[i], fmin(tmin, cross[i].t_hi), erows, nerows, erest, nerest, at_lo,
                                   scratch);
                if (tau < 0.0) continue;
                if (best < 0 || tau < tmin) { tmin = tau; best = i; }
            }
        }
        /* the impact's bodies to now (a time of impact kept from the last pass did not look at them) */
        if (best >= 0 && lazy && (sync_row(&lz, cross[best].a) != 0 || sync_row(&lz, cross[best].b) != 0)) goto oom;
        lc_stage_end(w, &w->last.time_toi_search, ts);
        if (best < 0) {
            local_next = 0;
            lazy = 0;   /* every row to the trial's end */
            memcpy(w->state, s1, (size_t)w->count * 6 * sizeof(double));
            remaining -= trial;
            if (remaining < 1e-14 * dt) remaining = 0.0;
            now_t = dt - remaining;
            w->time = t0 + (dt - remaining);
            continue;
        }

        if (may_track) {
            /* the interval's first impact: where every body can be until the interval ends is tracked
             * from here on, and every row, at now, keeps its own clock */
            may_track = 0;
            if (lc_broad_phase_track(w, s0, s1, trial, rows, nrows, w->def.contact_distance) != 0) goto oom;
            tracked = 1;
            lazy = 1;
            memset(lz.own, 0, (size_t)w->count);   /* every row's anchor is its row of s0 */
            for (i = 0; i < nrows; ++i) lz.clock[rows[i]] = lz.anchor_t[rows[i]] = lz.now;
        }
        ts = lc_stage_begin(w);
        /* lazy clocks: only the crossing's two bodies go to the impact's time here (the others it acts
         * on are brought there as the impact group finds them) */
        adv_n = 0;
        if (lazy) {
            if (!w->is_static[cross[best].a]) adv[adv_n++] = cross[best].a;
            if (!w->is_static[cross[best].b]) adv[adv_n++] = cross[best].b;
        }
        by_pair = cross[best].by_pair;
        at_t_best = 0;
        if (tmin > 0.0) {
            int ba = cross[best].a, bb = cross[best].b;
            if (lazy && free_flight && t_best >= 0.0) {
                /* from their anchors, as every lazy row (below) */
                for (i = 0; i < adv_n; ++i)
                    if (row_at(&lz, adv[i], t_best) != 0) goto oom;
                at_t_best = 1;
            } else if (lc_integrate_rows(w, s0, tmin, lazy ? adv : rows, lazy ? adv_n : nrows, rest, nrest, w->state) != 0) {
                goto oom;
            }
            /* another vertex of the pair (corner against corner) already inside, deeper than any
             * crossing test can see from here on: the pair met earlier, find when */
            if (lc_pair_separation(w, w->state, ba, bb) < -0.5 * w->def.contact_gap &&
                lc_pair_separation(w, s0, ba, bb) > w->def.contact_gap) {
                const int *erows;
                int nerows, nerest;
                lc_touch *erest;
                double t2;
                if (lc_touch_islands_of(er->islands, ba, bb, &erows, &nerows, &erest, &nerest) != 0) goto oom;
                lc_stage_end(w, &w->last.time_integration, ts);
                ts = lc_stage_begin(w);
                t2 = lc_pair_time_of_impact(w, s0, tmin, ba, bb, erows, nerows, erest, nerest, INFINITY, scratch);
                lc_stage_end(w, &w->last.time_toi_search, ts);
                ts = lc_stage_begin(w);
                if (t2 < 0.0) goto oom;
                tmin = t2;
                t_best = -1.0;   /* the time from this pass's start */
                at_t_best = 0;
                by_pair = 1;
                if (lc_integrate_rows(w, s0, tmin, lazy ? adv : rows, lazy ? adv_n : nrows, rest, nrest, w->state) != 0)
                    goto oom;
            }
        } else if (!lazy) {
            memcpy(w->state, s0, (size_t)w->count * 6 * sizeof(double));
        }
        lc_stage_end(w, &w->last.time_integration, ts);
        /* in free flight the impact's time is its crossing's, kept from the step's start: the same bits
         * whichever other impacts came between (not a sum of their intervals) */
        if (free_flight && t_best >= 0.0) {
            remaining = dt - t_best;
            w->time = t0 + t_best;
        } else {
            remaining -= tmin;
            w->time = t0 + (dt - remaining);
        }
        if (remaining < 1e-14 * dt) remaining = 0.0;
        now_t = free_flight && t_best >= 0.0 && remaining > 0.0 ? t_best : dt - remaining;

        lz.now = now_t;
        for (i = 0; i < adv_n; ++i) {
            /* the crossing's two bodies at the impact's time from their anchors, unless they are */
            if (!(at_t_best && now_t == t_best) && lz.clock[adv[i]] != now_t && row_at(&lz, adv[i], now_t) != 0) goto oom;
            lz.clock[adv[i]] = now_t;
        }
        fresh[0] = adv_n > 0 ? adv[0] : -1;
        fresh[1] = adv_n > 1 ? adv[1] : -1;
        ts = lc_stage_begin(w);
        nimp = lc_event_impact_group(w, er->touches, w->state, &cross[best], by_pair, &impact, lazy ? sync_row : NULL, &lz);
        if (nimp < 0) goto oom;
        /* past max_events_per_step (an impact storm: extreme speeds in a small box, a jam at e > 0)
         * every further impact is inelastic, which ends the storm; the pass cap above still bounds it */
        hits = lc_resolve_impacts(w, w->state, impact, nimp, events < w->def.max_events_per_step);
        if (hits < 0) goto oom;
        {
            lc_touch *t = impact;
            int dissipative = 0;
            for (i = 0; i < nimp; ++i)
                if (t[i].value > 0.0) {
                    w->last.impulses++;
                    if (lc_record_impact(w, &t[i], LC_IMPACT_EVENT) != 0) goto oom;
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
            lc_touch *t = impact;
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
            /* free flight: the trial ends with the step */
            trial_left = free_flight ? remaining : trial - tmin;
            last_tmin = tmin;
        }
        if (hits == 0 && free_flight && !best_searched) {
            /* A time kept from an earlier search applied nothing (its vertex farther than
             * contact_distance there, or no touch of the pair approaching): that is not yet a stalled
             * vertex. It is searched again from here, as every crossing is in the other path; only a
             * search from here that applies nothing at once sets it aside. */
            cross[best].toi = -1.0;
            cross[best].clear_to = 0.0;
        } else if (hits == 0 && tmin == 0.0) {
            if (nstalled < LC_MAX_STALLED) stalled[nstalled] = cross[best];
            nstalled++;
        }
    }
    if (lazy) {
        /* every body to the end of the step */
        lz.now = dt - remaining;
        if (sync_rows(&lz, rows, nrows) != 0) goto oom;
    }
    if (remaining == 0.0) w->time = t0 + dt;
    if (handover != NULL) *handover = -1;
    if (lc_step_energy_blew_up(w, step->start, dt, started_deep))
        return lc_step_undo(w, step, LC_ERR_NUMERIC,
                            "the step gained far more energy than its external forces and thrusters can give "
                            "(speeds or spins beyond what dt can resolve)");
    {
        int pr;
        ts = lc_stage_begin(w);
        pr = lc_event_project(w, er->projection, er->touches);
        lc_stage_end(w, &w->last.time_projection, ts);
        if (pr < 0) goto oom;
        if (pr > 0)
            return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                "bodies still overlap after the end-of-step projection (forces far too large for dt?)");
    }

    /* resting contacts at the end of the step, with the forces of the last evaluation */
    for (i = 0; i < nrest; ++i) {
        lc_touch t = rest[i];
        lc_touch_update(w, w->state, &t);
        if (lc_push_contact(w, &t, LC_CONTACT_RESTING) != 0) goto oom;
    }
    /* what the event rows rest on at the end, for the next step's regime (the projection's last search
     * was at the end state when it kept its touches) */
    for (i = 0; i < nrows; ++i) w->rests_dissipative[rows[i]] = 0;
    nend = lc_event_touches_end(er->touches, &end_touches);
    *marks_known = nend >= 0 || nrows == 0;
    if (nend >= 0) lc_regime_mark(w, end_touches, nend);
    return LC_OK;
oom:
    return lc_step_undo(w, step, LC_ERR_NO_MEMORY, "out of memory during the step");
}

void lc_event_regime_save(const lc_event_regime *er, const lc_world *w, struct lc_writer *out)
{
    lc_event_touches_save(er->touches, w, out);
}

int lc_event_regime_load(lc_event_regime *er, const lc_world *w, struct lc_reader *in)
{
    return lc_event_touches_load(er->touches, w, in);
}
