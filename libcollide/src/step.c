/* The step (lc_world_step): the world is advanced island by island, each island in the regime it needs
 * (docs/contact_regime.md), in tries until every body stayed where its island's build foresaw it. This
 * file only orders the stages; each lives in its own file: the islands (islands.c), the rule that picks
 * an island's regime (regime.c), the event regime (event_regime.c) and the contact regime
 * (contact_regime.c). A step is taken whole or not at all: every failure undoes it (lc_step_undo). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "contact_regime.h"
#include "event_regime.h"
#include "events.h"
#include "islands.h"
#include "regime.h"
#include "sleep.h"
#include "tunables.h"

struct lc_step_state {
    lc_buf start, marks0;         /* the state and w->rests_dissipative the step began with */
    lc_buf force_event;           /* rows an earlier try sends to the event regime (lc_step_try) */
    lc_buf reach;                 /* where the tries' bodies went */
    lc_buf event_rows, excluded;  /* a try's event rows, and its contact islands' rows (w->excluded) */
};

lc_step_state *lc_step_state_create(void) { return calloc(1, sizeof(lc_step_state)); }

void lc_step_state_destroy(lc_step_state *ss)
{
    if (ss == NULL) return;
    lc_buf_free(&ss->start);
    lc_buf_free(&ss->marks0);
    lc_buf_free(&ss->force_event);
    lc_buf_free(&ss->reach);
    lc_buf_free(&ss->event_rows);
    lc_buf_free(&ss->excluded);
    free(ss);
}

/* The caller sees either the whole step or none of it: no half-advanced world, no contacts of a step
 * that did not happen. */
lc_status lc_step_undo(lc_world *w, const lc_step_try *step, lc_status s, const char *what)
{
    lc_status cs = LC_OK;
    const char *why = lc_force_callback_failure(w, &cs);
    lc_stage_end(w, &w->last.time_step, w->step_t0);
    memcpy(w->state, step->start, (size_t)w->count * 6 * sizeof(double));
    w->time = step->time0;
    w->contact_count = 0;
    lc_events_unstage(w->events, 0);
    /* a failed force callback is what stopped the step, whichever stage noticed it (its evaluations
     * return as an allocation failure would, and their NaN accelerations may trip a finiteness check) */
    if (why != NULL) return lc_fail(w, cs, "%s; the step was undone", why);
    return lc_fail(w, s, "%s; the step was undone", what);
}

/* The resting contacts reported since contact index `first` go (a sub-step's, which the next one
 * reports anew); its collisions stay. */
static void drop_resting(lc_world *w, int first)
{
    int i, n = first;
    for (i = first; i < w->contact_count; ++i)
        if (w->contacts[i].kind != LC_CONTACT_RESTING) w->contacts[n++] = w->contacts[i];
        else w->last.resting_contacts--;
    w->contact_count = n;
}

/* The contact advance of island isl over dt, in as many sub-steps as its fastest body needs
 * (lc_regime_substeps): LC_OK, or the step has failed (and is undone). *stuck is set to the island's
 * index + 1 when a sub-step ended with an overlap or an energy gain it could not resolve. */
static lc_status contact_island(lc_world *w, const lc_step_try *step, const lc_island *isl, int index, double dt,
                                int *stuck)
{
    double ts = lc_stage_begin(w);
    int k, r = 0, n = lc_regime_substeps(w, isl, dt);
    if (n < 1) n = LC_CONTACT_MAX_SUBSTEPS;   /* LC_REGIME_CONTACT forces it on an island faster than that */
    for (k = 0; k < n && r == 0; ++k) {
        int first = w->contact_count;
        r = lc_contact_advance(w, w->contact, isl, dt / n);
        if (r == 0 && k + 1 < n) drop_resting(w, first);
    }
    lc_stage_end(w, &w->last.time_contact_regime, ts);
    if (r == -1) return lc_step_undo(w, step, LC_ERR_NO_MEMORY, "out of memory during the step");
    if (r == -2)
        return lc_step_undo(w, step, LC_ERR_NUMERIC,
                            "the contact regime produced a non-finite state (forces too stiff for dt?)");
    if (r == -3) *stuck = index + 1;
    return LC_OK;
}

/* 1 if no island of this step can be in the contact regime or asleep: every body perfectly elastic (no
 * pair dissipates, so none comes to rest), sleep off, the regime not forced to CONTACT. Such a world is
 * advanced by one event pass without the island build, as islands would all be the event regime's
 * (a thousand blocks flying at e = 1: the build doubled the step). */
static int all_events(const lc_world *w)
{
    int i;
    if (w->def.regime == LC_REGIME_CONTACT || w->def.allow_sleep) return 0;
    for (i = 0; i < w->count; ++i)
        if (w->elasticity[i] < 1.0) return 0;
    return 1;
}

/* One try at the step: the islands of the current state (their swept boxes grown to `reach`), each
 * advanced in its regime, or asleep. LC_OK, or the step has failed (and is undone). A try stops early,
 * with *stuck the island's index + 1, when a contact island ends overlapping. *built: 1 if the islands
 * were built (0: one event pass over the world, all_events). */
static lc_status advance_islands(lc_world *w, const lc_step_try *step, double dt, const double *reach,
                                 int *marks_known, int *stuck, int *built)
{
    int *event_rows = lc_buf_get(&w->step_state->event_rows, (size_t)w->count * sizeof(int));
    uint8_t *excluded = lc_buf_get(&w->step_state->excluded, (size_t)w->count);
    int n_event = 0, k, i, any_excluded = 0;
    double t0 = step->time0;
    lc_status st;
    if (!event_rows || !excluded) return lc_step_undo(w, step, LC_ERR_NO_MEMORY, "out of memory during the step");
    memset(excluded, 0, (size_t)w->count);
    *built = !all_events(w);
    if (*built) {
        if (lc_islands_build(w, w->islands, dt, lc_sleep_asleep(w->sleep), reach) != 0)
            return lc_step_undo(w, step, LC_ERR_NO_MEMORY, "out of memory during the step");
        for (k = 0; k < lc_islands_count(w->islands); ++k) {
            lc_island isl = lc_islands_get(w->islands, k);
            int sleeps = lc_sleep_island(w->sleep, w, &isl);
            if (!sleeps) w->last.islands++;
            if (!sleeps && lc_regime_of(w, &isl, dt) != LC_REGIME_CONTACT) continue;
            if (!sleeps && lc_any_marked(step->force_event, isl.rows, isl.nrows)) continue;   /* an earlier try's verdict */
            if (!sleeps) {
                st = contact_island(w, step, &isl, k, dt, stuck);
                if (st != LC_OK || *stuck) return st;
            }
            for (i = 0; i < isl.nrows; ++i) excluded[isl.rows[i]] = 1;
            any_excluded = 1;
        }
    } else {
        w->last.islands++;
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
        if (any_excluded) {
            /* the event regime's pairs leave out the contact islands' and the sleeping bodies, and its
             * kept end touches would not describe them */
            w->excluded = excluded;
            lc_event_regime_forget_end(w->event);
        }
        if (n_event == 0 && any_excluded) {
            /* every island was the contact regime's or asleep: no event pass (its broadphases would find
             * nothing) */
            w->excluded = NULL;
            *marks_known = 1;
            w->time = step->time0 + dt;
            if (lc_step_energy_blew_up(w, step->start, dt, 0))
                return lc_step_undo(w, step, LC_ERR_NUMERIC,
                                    "the step gained far more energy than its external forces and thrusters can give "
                                    "(speeds or spins beyond what dt can resolve)");
            return LC_OK;
        }
        st = lc_event_advance(w, w->event, step, step->time0 + dt - t0, t0, event_rows, n_event, marks_known,
                              w->def.regime == LC_REGIME_AUTO && *built ? &handover : NULL, &t_handover);
        w->excluded = NULL;
        if (st != LC_OK || handover < 0) break;
        {
            lc_island isl = lc_islands_get(w->islands, handover);
            t0 += t_handover;
            w->time = t0;
            st = contact_island(w, step, &isl, handover, step->time0 + dt - t0, stuck);
            if (st != LC_OK || *stuck) return st;
            for (i = 0; i < isl.nrows; ++i) excluded[isl.rows[i]] = 1;
            any_excluded = 1;
        }
    }
    if (any_excluded) lc_event_regime_forget_end(w->event);
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
    lc_events_unstage(w->events, 0);   /* the try's impacts happen again, or not, in the next */
    lc_contact_regime_retry(w->contact);
}

lc_status lc_world_step(lc_world *w, double dt)
{
    size_t bytes;
    double *backup, *reach = NULL, time0;
    uint8_t *marks0, *force_event;
    int i, try, marks_known = 0;
    lc_status st;
    lc_step_try step;
    lc_step_state *ss;
    if (w == NULL) return LC_ERR_NULL;
    ss = w->step_state;
    /* a bad dt is refused before anything changes */
    if (!isfinite(dt)) return lc_fail(w, LC_ERR_NOT_FINITE, "dt is not finite (%g)", dt);
    if (!(dt > 0.0) || dt > 1.0) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "dt = %g is outside (0, 1] s", dt);
    /* this step's counters and contacts start empty; the stabilisation's time scale is dt */
    memset(&w->last, 0, sizeof w->last);
    w->step_t0 = lc_stage_begin(w);
    w->last.steps = 1;
    w->step_dt = dt;
    w->contact_count = 0;
    lc_events_unstage(w->events, 0);
    time0 = w->time;
    bytes = (size_t)(w->count > 0 ? w->count : 1) * 6 * sizeof(double);
    backup = lc_buf_get(&ss->start, bytes);
    marks0 = lc_buf_get(&ss->marks0, (size_t)(w->count > 0 ? w->count : 1));
    force_event = lc_buf_get(&ss->force_event, (size_t)(w->count > 0 ? w->count : 1));
    if (!backup || !marks0 || !force_event) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory in step");
    memset(force_event, 0, (size_t)(w->count > 0 ? w->count : 1));
    if (w->count == 0) {
        /* nothing to move: time still passes */
        w->time += dt;
        lc_stage_end(w, &w->last.time_step, w->step_t0);
        lc_counters_add(&w->total, &w->last);
        w->error[0] = '\0';
        return LC_OK;
    }
    /* where the step begins: every try restarts from it, every failure goes back to it */
    memcpy(backup, w->state, (size_t)w->count * 6 * sizeof(double));
    step.start = backup;
    step.time0 = time0;
    step.force_event = force_event;
    /* the force callback forgets the last step's failure and peak forces; what each body rests on picks
     * its island's regime: searched again only if an API call changed the bodies since the last step
     * marked them; the contact regime's kept forces become its warm start */
    if (lc_force_callback_begin_step(w) != 0 || lc_regime_refresh(w) != 0 ||
        lc_contact_regime_begin_step(w->contact) != 0)
        return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
    /* every body asleep: nothing moves, the sleeping contacts are reported again */
    i = lc_sleep_begin_step(w->sleep, w);
    if (i == 1) {
        w->time = time0 + dt;
        if (lc_sleep_end_step(w->sleep, w, NULL, dt) != 0)
            return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
        lc_stage_end(w, &w->last.time_step, w->step_t0);
        lc_counters_add(&w->total, &w->last);
        w->error[0] = '\0';
        return LC_OK;
    }
    if (i < 0) return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
    memcpy(marks0, w->rests_dissipative, (size_t)w->count);
    /* Tries: a try whose bodies went where their islands' build did not foresee is taken again with
     * those islands grown to where they went (LC_MAX_ISLAND_TRIES at most); one whose contact island
     * ended overlapping for no such reason is taken again with that island in the event regime (once
     * per island: its rows stay marked for the step, so this ends). */
    for (try = 0;; ++try) {
        int found = 0, stuck = 0, built = 0;
        st = advance_islands(w, &step, dt, reach, &marks_known, &stuck, &built);
        if (st != LC_OK) {
            memcpy(w->rests_dissipative, marks0, (size_t)w->count);
            lc_events_unstage(w->events, 0);
            return st;
        }
        if (built && try < LC_MAX_ISLAND_TRIES - 1) {
            if (reach == NULL) {
                reach = lc_buf_get(&ss->reach, (size_t)w->count * 4 * sizeof(double));
                if (reach == NULL) return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
                for (i = 0; i < w->count; ++i) {
                    reach[4 * i] = 1.0;
                    reach[4 * i + 2] = -1.0;
                }
            }
            found = lc_islands_unforeseen(w, w->islands, backup, reach);
            if (found < 0) return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
        }
        if (found == 0 && stuck) {
            lc_island isl = lc_islands_get(w->islands, stuck - 1);
            for (i = 0; i < isl.nrows; ++i) force_event[isl.rows[i]] = 1;
            --try;
        } else if (found == 0) {
            break;
        }
        restart_step(w, backup, marks0, time0);
    }
    w->time = time0 + dt;
    /* no stage may keep a step whose force callback failed (a time-of-impact search reads a failed
     * evaluation as "no impact") */
    if (lc_force_callback_failure(w, &st) != NULL) return lc_step_undo(w, &step, st, "the force callback failed");
    /* a non-finite state would poison every later step: refuse the step instead */
    for (i = 0; i < w->count * 6; ++i)
        if (!isfinite(w->state[i])) return lc_step_undo(w, &step, LC_ERR_NUMERIC, "the state became non-finite");
    /* the marks describe the end state unless the event regime could not tell (the next step looks) */
    w->regime_edits = marks_known ? w->edits : w->edits - 1;
    /* islands that rested long enough fall asleep */
    if (lc_sleep_end_step(w->sleep, w, w->islands, dt) != 0)
        return lc_step_undo(w, &step, LC_ERR_NO_MEMORY, "out of memory during the step");
    lc_events_commit(w->events);   /* the step is taken: its impacts are reported */
    lc_stage_end(w, &w->last.time_step, w->step_t0);
    lc_counters_add(&w->total, &w->last);
    w->error[0] = '\0';
    return LC_OK;
}
