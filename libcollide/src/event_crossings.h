/* The event regime's detection (event_crossings.c): the crossings of a trial interval. */
#ifndef LC_EVENT_CROSSINGS_H
#define LC_EVENT_CROSSINGS_H

#include "world.h"

typedef struct lc_event_crossings lc_event_crossings;   /* owned by the event regime */

lc_event_crossings *lc_event_crossings_create(void);
void lc_event_crossings_destroy(lc_event_crossings *ec);

/* A trial interval: rows[0..nrows) advanced from s0 over h to s1, with the resting touches rest[0..nrest)
 * held by contact forces. */
typedef struct lc_trial {
    const double *s0, *s1;
    double h;
    const int *rows;
    int nrows;
    lc_touch *rest;
    int nrest;
    /* > 0 in free flight (no resting touch, no tie between bodies, every row in closed form without
     * torque): h is not cut by the fastest spin of the world; a pair whose faster body turns more than
     * LC_MAX_TRIAL_ROTATION over h is tested over equal parts of it in which that body turns at most
     * that much, none shorter than min_part (its crossings bracketed within their part). 0: every
     * pair over the whole interval (h already rotation-limited). */
    double min_part;
} lc_trial;

/* The bodies the last impact moved (marked[row] != 0 for rows[0..n)), `since` s before the interval. */
typedef struct lc_moved {
    const uint8_t *marked;
    const int *rows;
    int n;
    double since;
} lc_moved;

/* The crossings of the trial interval (each with t_hi, a time by which its vertex is inside), into *out
 * (valid until the next search): of every pair, or (moved != NULL: after an impact in free flight, to
 * the same interval's end) of the pairs with a moved body, the previous search's others kept. Crossings
 * of the first min(nstalled, LC_MAX_STALLED) entries of `stalled` are left out; past LC_MAX_STALLED none
 * is looked for. Returns the count, or -1 without memory. */
int lc_event_crossings_find(lc_world *w, lc_event_crossings *ec, const lc_trial *tr, const lc_moved *moved,
                            const lc_crossing *stalled, int nstalled, lc_crossing **out);

#endif
