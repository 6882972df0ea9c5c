/* The event regime's touches (event_touches.c): the resting set of a pass, the group an impact acts on,
 * and the whole-world search, which reuses the touches the last step's projection found when nothing
 * has moved or changed since. */
#ifndef LC_EVENT_TOUCHES_H
#define LC_EVENT_TOUCHES_H

#include "world.h"

typedef struct lc_event_touches lc_event_touches;   /* owned by the event regime */

lc_event_touches *lc_event_touches_create(void);
void lc_event_touches_destroy(lc_event_touches *et);
/* Rows shifted (a body was removed): the last pass's forces, kept by rows, are dropped. */
void lc_event_touches_rows_shifted(lc_event_touches *et);

/* Touches between all near pairs at `state` with gap < contact_distance, into buf from 0. Returns the
 * count, or -1 without memory. */
int lc_event_gather_touches(lc_world *w, lc_event_touches *et, const double *state, lc_buf *buf);
/* The resting set at `state` (into *rest, valid until the next call), warm-started from the last pass's
 * forces: between all near pairs, or (list != NULL) only the pairs with one of the listed bodies
 * (marked[row] != 0). Touches inside the gap that still approach are resolved first as one impact
 * (++*impacts). mid_step: not the step's first pass. *started_deep is set when the step starts with a
 * point deep inside another body; *persisting is a body on a dissipative touch at rest (the contact
 * regime's), or -1. Returns the count, -1 without memory, or -2 when a point passed deep into another
 * body within the step. */
int lc_event_resting(lc_world *w, lc_event_touches *et, double *state, int *impacts, const uint8_t *marked,
                     const int *list, int nlist, int mid_step, int *started_deep, int *persisting, lc_touch **rest);
/* Keeps a pass's resting touches and their forces for the next pass's warm start. 0, or -1. */
int lc_event_keep_warm(lc_event_touches *et, const lc_touch *t, int n);
/* The touches an impact at crossing c acts on (into *out, valid until the next call): every touch of the
 * group of bodies joined by touches to c's two, or (by_pair) that pair's own. While the broad phase
 * tracks the trial, sync (when not NULL) is called on each body near the group before it is looked at
 * (it brings that row of `state` to the impact's time; 0, or -1 without memory). Returns the count, or
 * -1. */
int lc_event_impact_group(lc_world *w, lc_event_touches *et, const double *state, const lc_crossing *c, int by_pair,
                          lc_touch **out, int (*sync)(void *ctx, int row), void *ctx);

/* The touches `found` (n of them) were searched at w->state, where the step ends: they are kept (buffers
 * swapped) for the next step's first whole-world search. 0, or -1 without memory. */
int lc_event_touches_keep_end(lc_world *w, lc_event_touches *et, lc_buf *found, int n);
/* The kept end touches into *t: their count, or -1 when none are kept. */
int lc_event_touches_end(const lc_event_touches *et, const lc_touch **t);
/* The kept end touches no longer describe the end state (another regime moved bodies). */
void lc_event_touches_forget_end(lc_event_touches *et);

/* Snapshots (snapshot.c): the last pass's warm start and the kept end touches, written, and read back
 * into a new world's (w: its bodies already loaded). Load: 0, or -1 without memory (bad input: in->bad). */
struct lc_writer;
struct lc_reader;
void lc_event_touches_save(const lc_event_touches *et, const lc_world *w, struct lc_writer *out);
int lc_event_touches_load(lc_event_touches *et, const lc_world *w, struct lc_reader *in);

#endif
