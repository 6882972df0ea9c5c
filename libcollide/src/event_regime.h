/* The event regime (event_regime.c): bodies fly freely until a vertex enters another body, the step
 * backs up to the exact time of impact, applies the impulses there and goes on; resting contact is held
 * by contact forces. Exact, and cheap when impacts are isolated (docs/contact_regime.md). */
#ifndef LC_EVENT_REGIME_H
#define LC_EVENT_REGIME_H

#include "world.h"

typedef struct lc_event_regime lc_event_regime;   /* owned by the world */

lc_event_regime *lc_event_regime_create(void);
void lc_event_regime_destroy(lc_event_regime *er);
/* Rows shifted (a body was removed): what the regime kept by rows from the last pass is dropped. */
void lc_event_regime_rows_shifted(lc_event_regime *er);
/* The touches kept at the end of the last event pass no longer describe the state (the contact regime
 * moved bodies since). */
void lc_event_regime_forget_end(lc_event_regime *er);
/* Snapshots (snapshot.c): what the regime keeps from one step to the next (event_touches.h), written, and
 * read back into a new world's (w: its bodies already loaded). Load: 0, or -1 without memory (bad input:
 * in->bad). */
struct lc_writer;
struct lc_reader;
void lc_event_regime_save(const lc_event_regime *er, const lc_world *w, struct lc_writer *out);
int lc_event_regime_load(lc_event_regime *er, const lc_world *w, struct lc_reader *in);

/* Advances the dynamic rows[0..nrows) from time t0 by dt (the rest of the step `step` tries), every other
 * dynamic body left out of its pairs (w->excluded). With `handover` non-NULL it stops at the first
 * instant a touch between bodies that are not perfectly elastic rests (or after LC_HANDOVER_EVENTS
 * dissipative impacts), with every row advanced to that instant: *handover is then that touch's island
 * (islands.h) and *t_handover the time it took; otherwise *handover is -1 and the rows reach the end of
 * the step, projected. *marks_known: w->rests_dissipative describes the rows' end state. LC_OK, or the
 * error (the step undone by lc_step_undo, unless memory ran out before the first pass). */
lc_status lc_event_advance(lc_world *w, lc_event_regime *er, const lc_step_try *step, double dt, double t0,
                           const int *rows, int nrows, int *marks_known, int *handover, double *t_handover);

#endif
