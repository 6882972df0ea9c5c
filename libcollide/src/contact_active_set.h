/* Exact frictional contact for few points by active sets: the problem of contact_solver.h (Signorini's
 * condition on the normal impulses, friction in the exact 2D Coulomb cone, restricted against an
 * initial slip) with each point in one state:
 *     off:                 lambda_n = 0, lambda_t = 0           (open: u_n >= target_n)
 *     on, sticking:        u_n = target_n, u_t = 0              (lo_t <= lambda_t <= hi_t)
 *     on, at the upper bound:  u_n = target_n, lambda_t = hi_t  (u_t <= 0)
 *     on, at the lower bound:  u_n = target_n, lambda_t = lo_t  (u_t >= 0)
 * Given the states, the impulses solve a linear system of 2m equations in the 2m unknowns (u = u_start +
 * A lambda, A the Delassus operator, contact_delassus.h), by dense LU with A's diagonal raised by a
 * relative 1e-10 (dependent points: each corner of a face on a face twice) and refined against the
 * unraised system. The conditions in parentheses are then checked to round-off (1e-12 relative); every
 * point whose condition failed changes state (block pivoting, Judice and Pires 1994) while that cuts
 * the failures, else only the last one (Murty's rule). A good start (the warm start of a nearly resting
 * island) settles in two to four rounds; each costs ~(2m)^3 / 3 operations, where Lemke's method
 * (contact_exact.h) pivots over a tableau of (4m)^2 for every unknown that enters. */
#ifndef LC_CONTACT_ACTIVE_SET_H
#define LC_CONTACT_ACTIVE_SET_H

#include <stddef.h>
#include "contact_solver.h"

/* Doubles of scratch a problem of nrows points needs. */
size_t lc_contact_active_set_scratch(int nrows);

/* Solves rows[0..nrows) from velocities v (start velocities; the rows' impulses give the first states,
 * lambda_n > 0 on, lambda_t at a bound or inside) in at most LC_CONTACT_ACTIVE_SET_ITERATIONS rounds.
 * Returns the rounds, with the impulses in the rows and the answer's velocities in v; or -1 (a singular
 * system, or no consistent states within the cap), with v and the rows as they were. */
int lc_contact_solve_active_set(lc_contact_row *rows, int nrows, double *v, const double *inv_mass,
                                const double *inv_inertia, double *scratch);

#endif
