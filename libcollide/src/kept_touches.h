/* The touches a contact-regime island's step ended with, kept so that the island's next step begins
 * with them instead of searching its pairs again: the end of one step and the start of the next are the
 * same state, and the touch search is what a resting pile's step spends most on. A kept set is taken
 * only when the next step starts from exactly that state (the island's rows compared bit for bit, no API
 * change since), with the same rows, the same candidate pairs and the same dt, so what it gives is what
 * the search would find: the end search's margin is at least as wide as the next start search's
 * (contact_regime.c), and a kept set is cut down to the latter when taken. Written during a step, readable in the next, like the
 * contact cache. A set also records whether its island was still (rested through that step at one state):
 * such an island is not solved while it starts its steps from that state (contact_regime.c, hold_still). */
#ifndef LC_KEPT_TOUCHES_H
#define LC_KEPT_TOUCHES_H

#include "islands.h"
#include "world.h"

typedef struct lc_kept_touches lc_kept_touches;   /* owned by the contact regime */

lc_kept_touches *lc_kept_touches_create(void);
void lc_kept_touches_destroy(lc_kept_touches *k);
/* What was stored since the last call becomes readable; the store starts empty. 0, or -1 without memory
 * (nothing is readable then). */
int lc_kept_touches_next_step(lc_kept_touches *k);
/* Drops what was stored since lc_kept_touches_next_step (the step is taken again). */
void lc_kept_touches_drop_stored(lc_kept_touches *k);
/* Forgets everything. */
void lc_kept_touches_clear(lc_kept_touches *k);
/* Keeps touches t[0..n), found at w->state (the island's end state) for an island step of dt, the search
 * of pair k of isl having taken every point within margin[k] (m). Their normal velocities are recomputed
 * at that state. still: the island rested through that step at one state (it began and ended it at
 * w->state with every velocity 0: contact_regime.c, "Rest"); a still set keeps the touches' value and
 * tangent (the forces their contacts were reported with), another drops them. 0, or -1 without memory. */
int lc_kept_touches_store(lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt, const lc_touch *t,
                          int n, const double *margin, int still);
/* The touches kept for island isl if it starts a step of dt from the state they were kept at, and if for
 * every pair the margin the caller's search would use, want(ctx, a, b), is within the kept one: those
 * whose gap is below want(ctx, a, b), copied into buf. Returns their count, -2 when nothing fits (search
 * then), or -1 without memory. */
int lc_kept_touches_take(const lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt,
                         double (*want)(const void *ctx, int a, int b), const void *ctx, lc_buf *buf);
/* 1 if island isl starts a step of dt from the state a still set was kept at (as for take) and no API
 * call at all changed the world since (w->api_changes: a setting changes the problem without changing
 * the bodies), with that set's touches (their forces in value and tangent) in *t (*n of them) and its
 * pairs' margins in *margin, valid until the next lc_kept_touches_next_step; else 0. */
int lc_kept_touches_still(const lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt,
                          const lc_touch **t, int *n, const double **margin);

/* Snapshots (snapshot.c): the sets stored since lc_kept_touches_next_step that the next step may take
 * (kept at the world's current `edits`), written, and read back into an empty store of a new world (w: its bodies already loaded). Load: 0, or
 * -1 without memory (bad input: in->bad). */
struct lc_writer;
struct lc_reader;
void lc_kept_touches_save(const lc_kept_touches *k, const lc_world *w, struct lc_writer *out);
int lc_kept_touches_load(lc_kept_touches *k, const lc_world *w, struct lc_reader *in);

#endif
