/* The Delassus operator A = J M^-1 J^T of contact points, formed densely for the direct solvers
 * (contact_exact.c, contact_active_set.c): the relative velocity each row (a point's normal or tangent)
 * gets per unit impulse along each row, through the bodies the two rows share. */
#ifndef LC_CONTACT_DELASSUS_H
#define LC_CONTACT_DELASSUS_H

#include "contact_solver.h"

/* A (2m x 2m, row-major) over the normal rows 0..m and the tangent rows m..2m of rows[0..m). */
void lc_contact_delassus(const lc_contact_row *rows, int m, const double *inv_mass, const double *inv_inertia,
                         double *A);

#endif
