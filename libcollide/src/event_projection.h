/* The event regime's end-of-step projection (event_projection.c). */
#ifndef LC_EVENT_PROJECTION_H
#define LC_EVENT_PROJECTION_H

#include "world.h"
#include "event_touches.h"

typedef struct lc_event_projection lc_event_projection;   /* owned by the event regime */

lc_event_projection *lc_event_projection_create(void);
void lc_event_projection_destroy(lc_event_projection *ep);
/* Moves every touch of w->state that ends closer than half the contact gap back to the gap, by the
 * smallest displacement (positions only), in up to LC_PROJECTION_PASSES passes; the touches of the
 * state it leaves are kept in `et` for the next step's first search. 0 done, 1 still overlapping by more
 * than LC_OVERLAP_TOLERANCE after every pass, -1 without memory. */
int lc_event_project(lc_world *w, lc_event_projection *ep, lc_event_touches *et);

#endif
