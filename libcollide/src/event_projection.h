/* The event regime's end-of-step projection (event_projection.c). */
#ifndef LC_EVENT_PROJECTION_H
#define LC_EVENT_PROJECTION_H

#include "world.h"

/* Moves every touch of w->state that ends closer than half the contact gap back to the gap, by the
 * smallest displacement (positions only), in up to LC_PROJECTION_PASSES passes; the touches of the
 * state it leaves are kept for the next step's first search. 0 done, 1 still overlapping by more than
 * LC_OVERLAP_TOLERANCE after every pass, -1 without memory. */
int lc_event_project(lc_world *w);

#endif
