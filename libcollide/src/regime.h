/* The regime rule: which way each island is advanced this step (docs/contact_regime.md).
 *
 * LC_REGIME_AUTO puts an island in the contact regime when one of its bodies rested on a touch (a
 * vertex within contact_distance of an edge) between two bodies that are not perfectly elastic
 * (mixed elasticity e < 1) when the step began, and in the event regime otherwise: free flight and
 * impacts of bodies in flight are exact there and cheap; e = 1 chains (the cradle) need the sequential
 * impacts only the event regime gives; a body resting on a dissipative touch is where impacts turn
 * into an unending stream of micro-impacts (inelastic collapse) and the contact regime takes over.
 * An island with a body that moves farther than its own size in a step is taken in sub-steps
 * (lc_regime_substeps), and stays in the event regime only when it would need more than
 * LC_CONTACT_MAX_SUBSTEPS: one fast box falling into a pile of hundreds must not put the pile in the
 * event regime, whose every impact there re-integrates the pile. LC_REGIME_EVENT and LC_REGIME_CONTACT put every island in that regime. */
#ifndef LC_REGIME_H
#define LC_REGIME_H

#include "islands.h"
#include "world.h"

/* The regime of an island for a step of dt. */
lc_regime lc_regime_of(const lc_world *w, const lc_island *isl, double dt);
/* The sub-steps the contact regime takes a step of dt of the island in: enough that no body moves
 * farther than its own shortest edge in one (its centre, or its farthest vertex by turning), since the
 * contact regime sees each contact at its (sub-)step's start geometry and cannot follow a body through
 * several bounces in one; 0 when more than LC_CONTACT_MAX_SUBSTEPS would be needed (the event regime
 * then finds each impact). */
int lc_regime_substeps(const lc_world *w, const lc_island *isl, double dt);
/* lc_regime_substeps(w, isl, dt) == 0. */
int lc_regime_too_fast(const lc_world *w, const lc_island *isl, double dt);
/* Marks the bodies of touches t[0..n) between a pair with e < 1 (w->rests_dissipative). */
void lc_regime_mark(lc_world *w, const lc_touch *t, int n);
/* Makes w->rests_dissipative describe the current state if an API call changed bodies since the last
 * step marked them (a touch search over the whole world). 0, or -1 without memory. */
int lc_regime_refresh(lc_world *w);

#endif
