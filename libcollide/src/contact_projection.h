/* Step 6a of the contact regime (contact_regime.c): points that end a step overlapping are moved out, to
 * a gap of LC_CONTACT_PROJECTION_GAP (never more than a thousandth of contact_gap), by the smallest
 * mass-weighted displacement: a complementarity problem in positions, the contact solver with
 * displacements for velocities. Only out of the overlap, not up to the contact gap: every metre of lift
 * against gravity is energy the step did not have (a contact_gap of 1 mm made that 1e-5 J per body). The
 * touches are searched again after each pass, for at most LC_CONTACT_PROJECTION_PASSES passes: pushing
 * one pair apart can turn another into the other body; in a pile sub-step, passes over the flow's own
 * points at their new positions come first, without a search. A pass is solved by Gauss-Seidel; MPRGP takes
 * over where the sweeps do not converge (a chain's length squared), and a pass of at least
 * LC_CONTACT_PROJECTION_DIRECT_ROWS points starts from active sets over a sparse factorization
 * (projection_active_set.h). */
#ifndef LC_CONTACT_PROJECTION_H
#define LC_CONTACT_PROJECTION_H

#include "contact_island.h"

typedef struct lc_contact_projection lc_contact_projection;   /* owned by the contact regime */

lc_contact_projection *lc_contact_projection_create(void);
void lc_contact_projection_destroy(lc_contact_projection *cp);

/* Projects the island's bodies (w->state rows) to the island's slack (c->slack); flow[0..nflow): the last
 * flow's touches. Leaves the touches at
 * the final state in `end` (the last pass's search, LC_SEARCH_NEXT_STEP) and each pair's margin of that
 * search in `margins` (doubles, per island pair); returns their count, or -1 without memory; *left: the
 * deepest overlap left after the last pass (m). */
int lc_contact_project(lc_contact_projection *cp, lc_contact_island *c, const lc_touch *flow, int nflow, lc_buf *end,
                       lc_buf *margins, double *left);

#endif
