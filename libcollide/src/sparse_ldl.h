/* Sparse LDL^T factorization of a symmetric positive definite matrix whose rows are points in the plane
 * coupled through shared elements (contact rows through the bodies they touch), ordered by geometric
 * nested dissection.
 *
 * Ordering. The rows are split at the median of their wider coordinate; every element with rows on both
 * sides gives the rows on its smaller side to the separator, which then disconnects the two halves; the
 * halves are ordered the same way, recursively, and the separator after them (George 1973). A planar
 * contact graph of n rows then factors in O(n^1.5) operations with O(n log n) entries in L, where a
 * pile's banded order costs n times its width squared.
 * Factorization. Up-looking: row k of L solves a sparse triangular system whose pattern is the reach of
 * column k's entries in the elimination tree; column counts come from the same walk first (Liu 1990;
 * Davis, "Direct Methods for Sparse Linear Systems", 2006, ch. 4). No pivoting: the matrix is
 * positive definite. A pivot that round-off drives to or below `min_pivot` times its diagonal entry is
 * raised to that (dependent rows); the caller's refinement takes the error out. */
#ifndef LC_SPARSE_LDL_H
#define LC_SPARSE_LDL_H

typedef struct lc_sparse_ldl lc_sparse_ldl;

lc_sparse_ldl *lc_sparse_ldl_create(void);
void lc_sparse_ldl_destroy(lc_sparse_ldl *f);

/* Orders rows [0, n): xy[2i], xy[2i+1] row i's point; elem[2i], elem[2i+1] the (at most two) elements
 * it belongs to, -1 for none, each < nelem. 0, or -1 without memory. */
int lc_sparse_ldl_order(lc_sparse_ldl *f, int n, const double *xy, const int *elem, int nelem);

/* The matrix of the last ordering's rows, as nz entries (ti[k], tj[k], tv[k]) in the rows' own
 * numbering: a diagonal entry once, an off-diagonal one once in either triangle, repeated entries summed.
 * 0, or -1 without memory. */
int lc_sparse_ldl_matrix(lc_sparse_ldl *f, int nz, const int *ti, const int *tj, const double *tv);

/* Factors the last matrix's rows and columns of the rows with active[i] != 0, with add[i] added to row
 * i's diagonal entry (add: NULL for none; the matrix must hold every row's diagonal entry). 0, or -1
 * without memory. */
int lc_sparse_ldl_factor(lc_sparse_ldl *f, const unsigned char *active, const double *add, double min_pivot);

/* x (length n, the rows' numbering): in the right-hand side, out the solution on the active rows; the
 * inactive entries are left as they are. */
void lc_sparse_ldl_solve(const lc_sparse_ldl *f, double *x);

/* Entries of the last factor's L (its cost: a solve visits each twice). */
long lc_sparse_ldl_entries(const lc_sparse_ldl *f);

#endif
