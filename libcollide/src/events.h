/* The impact event stream (lc_world_get_events): the collisions of every step, kept in a bounded ring
 * until the caller reads them. A step's impacts are staged while it runs and enter the ring only when
 * the step is taken, so an undone step, a try taken again or a sub-step solved again leaves none. */
#ifndef LC_EVENTS_H
#define LC_EVENTS_H

#include "world.h"

typedef struct lc_events lc_events;   /* owned by the world */

/* An empty stream holding at most `capacity` unread events (NULL without memory). */
lc_events *lc_events_create(int capacity);
void lc_events_destroy(lc_events *ev);
/* Records a collision of the step in progress at touch t (its impulse and pre-impact velocity filled):
 * the step's contact (lc_push_contact) and its staged event. 0, or -1 without memory. */
int lc_record_impact(lc_world *w, const lc_touch *t, lc_impact_kind kind);
/* Events staged by the step in progress. */
int lc_events_staged(const lc_events *ev);
/* Drops the staged events after the first `keep` (a try or a solve taken again from that point). */
void lc_events_unstage(lc_events *ev, int keep);
/* The step was taken: its staged events enter the ring, the oldest unread ones dropped (and counted)
 * past the capacity. */
void lc_events_commit(lc_events *ev);
/* A new capacity (lc_world_set_def): unread events past it are dropped, the oldest first, and counted.
 * Never fails. */
void lc_events_set_capacity(lc_events *ev, int capacity);

#endif
