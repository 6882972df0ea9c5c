/* The contact regime: velocity-level time stepping of one island (Moreau-Jean with the trapezoidal
 * position update), for islands with persistent or many contacts. The computation is explained once,
 * with its stopping rule and why it adds no energy, in docs/contact_regime.md. */
#ifndef LC_CONTACT_REGIME_H
#define LC_CONTACT_REGIME_H

#include "islands.h"

struct lc_world;

typedef struct lc_contact_regime lc_contact_regime;   /* owned by the world */

lc_contact_regime *lc_contact_regime_create(void);
void lc_contact_regime_destroy(lc_contact_regime *cr);
/* Called once at the start of every step, before any island is advanced: last step's contact forces
 * become the warm start. 0, or -1 without memory. */
int lc_contact_regime_begin_step(lc_contact_regime *cr);
/* The step is taken again: what this try stored is dropped. */
void lc_contact_regime_retry(lc_contact_regime *cr);
/* Forgets every kept contact force (the bodies changed wholesale). */
void lc_contact_regime_forget(lc_contact_regime *cr);
/* Snapshots (snapshot.c): what the next step reads, its warm start (contact_cache.c) and kept touches
 * (kept_touches.c), written, and read back into a new world's (w: its bodies already loaded). Load: 0,
 * or -1 without memory (bad input: in->bad). */
struct lc_writer;
struct lc_reader;
void lc_contact_regime_save(const lc_contact_regime *cr, const struct lc_world *w, struct lc_writer *out);
int lc_contact_regime_load(lc_contact_regime *cr, const struct lc_world *w, struct lc_reader *in);

/* Advances the island's bodies (w->state rows) by dt. Its impacts and the resting contacts at its
 * end go to the world's contacts, its work to w->last. Returns 0, -1 without memory or when the force
 * callback failed (lc_force_callback_failure), -2 when the island's state became non-finite (the
 * caller undoes the step), or -3 when an island of at most
 * LC_CONTACT_EVENT_FALLBACK_BODIES bodies ends, even with converged solves, with bodies overlapping
 * that the projection cannot separate or, without driving forces, with more energy than it began with
 * that its kinetic energy cannot pay for (the caller takes the step again with the island in the event
 * regime). A larger island keeps such a step and counts it in w->last.contact_unresolved. */
int lc_contact_advance(struct lc_world *w, lc_contact_regime *cr, const lc_island *isl, double dt);

#endif
