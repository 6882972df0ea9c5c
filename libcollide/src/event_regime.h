/* The event regime (event_regime.c): bodies fly freely until a vertex enters another body, the step
 * backs up to the exact time of impact, applies the impulses there and goes on; resting contact is held
 * by contact forces. Exact, and cheap when impacts are isolated (docs/contact_regime.md). */
#ifndef LC_EVENT_REGIME_H
#define LC_EVENT_REGIME_H

#include "world.h"

/* Advances the dynamic rows[0..nrows) from time t0 by dt (the rest of the step `step` tries), every other
 * dynamic body left out of its pairs (w->excluded). With `handover` non-NULL it stops at the first
 * instant a touch between bodies that are not perfectly elastic rests (or after LC_HANDOVER_EVENTS
 * dissipative impacts), with every row advanced to that instant: *handover is then that touch's island
 * (islands.h) and *t_handover the time it took; otherwise *handover is -1 and the rows reach the end of
 * the step, projected. *marks_known: w->rests_dissipative describes the rows' end state. LC_OK, or the
 * step has failed (and is undone, lc_step_undo). */
lc_status lc_event_advance(lc_world *w, const lc_step_try *step, double dt, double t0, const int *rows, int nrows,
                           int *marks_known, int *handover, double *t_handover);

#endif
