/* A start for the position projection of a large island: active sets over a sparse factorization for
 *     find lambda >= 0 with  w = b + A lambda >= 0,  lambda_i w_i = 0,   A = J M^-1 J^T
 * (normal rows only: the displacement d = M^-1 J^T lambda moves each point i out to b_i + (J d)_i >= 0).
 *
 * Method. Given the set S of rows held (w_i = 0), lambda_S solves (A_SS + eps D) lambda_S = -b_S, D the
 * diagonal of A_SS and eps = 1e-6, by sparse LDL^T (sparse_ldl.h, nested dissection over the rows'
 * points). Rows of S whose lambda came out negative leave it and rows outside whose w is below -tol join
 * it, all at once (block pivoting, Judice and Pires 1994), from S = the overlapping rows, for at most
 * LC_PROJECTION_ACTIVE_SET_ROUNDS rounds. The raised diagonal keeps dependent rows (a face on a face
 * gives each corner twice; a box wedged between two others) from splitting a push into large parts of
 * both signs, at the price of an answer off by ~eps times A_SS's condition (4e-4 of the lifts of a
 * ten-box column, test_sparse_ldl); once the set settles, two corrections through the same factor
 * against the unraised rows take that out.
 * What it is for. Gauss-Seidel and MPRGP need sweeps and products in the height of a pile (cond A ~
 * n^2); a factorization of a planar contact graph costs O(m^1.5) whatever the height. In a pile the set
 * rarely settles (dependent rows trade places), so the rounds' answer is a start: the caller's sweeps
 * and MPRGP finish the projection from it, and take it only when it scores below no push. */
#ifndef LC_PROJECTION_ACTIVE_SET_H
#define LC_PROJECTION_ACTIVE_SET_H

#include "contact_solver.h"

typedef struct lc_projection_active_set lc_projection_active_set;

lc_projection_active_set *lc_projection_active_set_create(void);
void lc_projection_active_set_destroy(lc_projection_active_set *ps);

/* rows[0..m): the rows' bodies (indices < nbodies, -1 static), directions and lever arms; xy[2i..2i+1]
 * row i's point (for the ordering); b the rows' constants (m). Out: lambda (m), the last round's answer
 * with its negative parts dropped, and *objective, its value of 1/2 lambda' A lambda + b' lambda (the
 * problem's minimum over lambda >= 0 is the answer; no push scores 0). Returns the
 * rounds taken when the set settled (>= 1), 0 when it did not within LC_PROJECTION_ACTIVE_SET_ROUNDS,
 * or -1 without memory. */
int lc_projection_active_set_solve(lc_projection_active_set *ps, const lc_contact_row *rows, const double *xy,
                                   int m, int nbodies, const double *inv_mass, const double *inv_inertia,
                                   const double *b, double tol, double *lambda, double *objective);

#endif
