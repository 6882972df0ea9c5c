/* libcollide: a custom force law (mutual gravitation, a field, a drag law) as a callback. Included by
 * collide/collide.h.
 *
 * The engine calls the force callback wherever it evaluates the applied forces (gravity, damping,
 * thrusters, springs, external force): at every stage of the integrator (RK4's four, so a force that
 * depends on the state keeps the integrator's order), at the start of each contact-regime sub-step, and
 * once per step to predict where bodies go. Each call gets every body's state at that evaluation and
 * returns a force (N, world frame, at the centre of mass) and a torque (N*m) per body. The callback must
 * be a pure function of what it is given (and of data the caller changes only between steps), or the
 * engine is not deterministic; it must not call libcollide on the world being stepped.
 *
 * While a callback is set: every dynamic body is integrated by the world's integrator (never in closed
 * form), no body sleeps, the callback's force may couple any bodies (the event regime advances them
 * together), and a body the callback pushed in a step counts as driven (the contact regime does not
 * take the callback's work back). The callback's work is not in lc_energy.total unless a potential
 * function is given too. A callback that fails, or a force that is not finite, fails the step with
 * LC_ERR_CALLBACK and the step is undone. */
#ifndef COLLIDE_FORCE_H
#define COLLIDE_FORCE_H

#include "collide/export.h"
#include "collide/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a force (or potential) evaluation is asked about. */
typedef struct lc_force_query {
    lc_state_view bodies;  /* every body, static ones included, at the evaluation's state: count, ids, state
                              (count x 6: x, y, angle, vx, vy, omega of each centre of mass), mass, inertia,
                              is_static, in row order. Valid during the call only */
    const int *rows;       /* the dynamic rows whose force the engine reads from this evaluation, each once, in
                              no set order (the potential: every dynamic row) */
    int row_count;
} lc_force_query;

/* Writes the force and torque on each body into out[row * 3 + 0..2] (fx, fy in N, world frame, at the centre
 * of mass; torque in N*m). out holds query->bodies.count x 3 doubles, all 0 on entry; only the listed rows
 * are read. Returns 0, or any other value to fail the step. */
typedef int (*lc_force_fn)(void *user, const lc_force_query *query, double *out);

/* Writes the potential energy (J) of the force law at the query's state into *out (one double, 0 on entry):
 * the function whose negative gradient the force callback gives, so that lc_energy.total is conserved where
 * the force law conserves energy. Returns 0, or any other value on failure. */
typedef int (*lc_potential_fn)(void *user, const lc_force_query *query, double *out);

/* Sets the force callback (NULL: none), its potential (may be NULL) and the pointer both receive. */
LC_API lc_status lc_world_set_force_callback(lc_world *world, lc_force_fn force, lc_potential_fn potential,
                                             void *user);
/* The force callback, its potential and user pointer (NULL when none is set; every output required). */
LC_API lc_status lc_world_get_force_callback(const lc_world *world, lc_force_fn *force, lc_potential_fn *potential,
                                             void **user);

#ifdef __cplusplus
}
#endif

#endif /* COLLIDE_FORCE_H */
