/* One island as the contact regime's stages see it (contact_regime.c, contact_projection.c): its bodies
 * in the solver's arrays, the step's settings, and the searches and rows every stage builds from them. */
#ifndef LC_CONTACT_ISLAND_H
#define LC_CONTACT_ISLAND_H

#include "contact_solver.h"
#include "islands.h"
#include "world.h"

struct lc_contact_regime;

/* The island's bodies as the solver sees them: velocities at the start of the sub-step (v0), the
 * solver's velocities (v), inverse mass and inertia, applied accelerations (acc), projection
 * displacements (disp). */
typedef struct lc_island_bodies {
    int n;
    double *v0, *v, *inv_mass, *inv_inertia, *acc, *disp;
} lc_island_bodies;

typedef struct lc_contact_island {
    lc_world *w;
    struct lc_contact_regime *cr;   /* the regime's scratch (contact_regime.c) */
    const lc_island *isl;
    int *local;          /* world row -> island index, -1 outside */
    lc_island_bodies b;
    int small;           /* transitions are located (LC_CONTACT_LOCATE_MAX_BODIES) */
    int moreau_jean;     /* this sub-step moves positions by h v (LC_CONTACT_MOREAU_JEAN_POINTS) */
    int pile;            /* this sub-step is a pile sub-step: one solve, restitution in the flow (LC_CONTACT_PILE_BODIES) */
    int precise;         /* solves run to convergence (LC_CONTACT_PRECISE_SWEEPS, _EXACT_POINTS) */
    int settle;          /* this sub-step is a settling one (LC_CONTACT_SETTLE_SPEED) */
    int rested;          /* the last advance() held the island at rest (LC_CONTACT_REST_SPEED) */
    int hold;            /* the last try of a step no other could take: the island, at rest when the step
                            began, is held at rest whatever its solves' answer (lc_contact_advance) */
    double max_h;        /* s, the longest sub-step (0: the whole step, cut only at transitions) */
    double slack;        /* m, the projection's stop and trigger (LC_CONTACT_PROJECTION_SLACK or _LARGE_SLACK) */
    double start_h;      /* lc_contact_island_start_margin's h */
    double dt;           /* the island's step */
    double residual;
    double overlap;      /* m, deepest overlap the last advance() left */
    double unpaid;       /* J, energy gain the last advance() kept (its kinetic energy could not pay) */
} lc_contact_island;

enum { LC_SEARCH_NEAR, LC_SEARCH_STEP, LC_SEARCH_NEXT_STEP };

/* The search margin of a pair at the start of a step of h: contact_distance and what the pair can close
 * in h (speculative points). ctx: the lc_contact_island, h in its field start_h. */
double lc_contact_island_start_margin(const void *ctx, int a, int b);

/* Every contact point of the island's pairs at the current state within contact_distance plus `reach`,
 * and: LC_SEARCH_STEP, within what the pair can close in h (speculative points); LC_SEARCH_NEXT_STEP,
 * within what it can close in a next step of h, with the acceleration term doubled (the accelerations
 * there are those of the end state, which springs may have changed), so the touches can begin that step
 * (kept_touches.h). margin: NULL, or per pair the margin searched. Returns the count or -1. */
int lc_contact_island_collect(lc_contact_island *c, double h, lc_buf *buf, int mode, double reach, double *margin);

/* The solver row of touch t: its bodies in the island's numbering (-1 static), directions and lever arms,
 * its friction; no target, slip or impulses. */
void lc_contact_island_row(const lc_contact_island *c, const lc_touch *t, lc_contact_row *r);

#endif
