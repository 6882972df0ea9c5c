/* The contact regime's exact solver for few contact points: the same problem as contact_solver.h (normal
 * impulses with Signorini's condition, friction in the exact 2D Coulomb cone, friction restricted
 * against an initial slip), written as the linear complementarity problem of Stewart and Trinkle
 * (1996) in the unknowns (lambda_n, beta+, beta-, gamma) per point, lambda_t = beta+ - beta-, gamma
 * the slip speed:
 *     u_n - target_n >= 0   _|_  lambda_n >= 0
 *     u_t + gamma    >= 0   _|_  beta+    >= 0
 *    -u_t + gamma    >= 0   _|_  beta-    >= 0
 *     mu lambda_n - beta+ - beta- >= 0  _|_  gamma >= 0
 * with u = u_start + A lambda, A = J M^-1 J^T formed densely. In 2D the cone has exactly these two
 * edges, so this is Coulomb's law, not a polygonal approximation. Solved by Lemke's complementary
 * pivoting (a finite number of pivots, a solution exists for this class: Anitescu and Potra 1997),
 * with ties of the ratio test broken by the smallest index and a pivot cap as guards. */
#ifndef LC_CONTACT_EXACT_H
#define LC_CONTACT_EXACT_H

#include <stddef.h>
#include "contact_solver.h"

/* Doubles of scratch a problem of nrows points needs. */
size_t lc_contact_exact_scratch(int nrows);

/* Solves rows[0..nrows) from velocities v (start velocities: the rows' warm start is ignored) and
 * writes the impulses into the rows and the answer's velocities into v. Returns the pivots taken, or -1
 * when the pivoting failed (ray or cap: v and the rows are then left as they were). */
int lc_contact_solve_exact(lc_contact_row *rows, int nrows, double *v, const double *inv_mass,
                           const double *inv_inertia, double *scratch);

#endif
