/* The reach grid (reach_grid.h): cells of one size in a compressed table (each cell's rows together,
 * built by a counting sort); a box wider than a few cells sits in a list that every query scans (walls
 * and floors). A moved row leaves its old entries in the table, marked stale, and gets entries in the
 * cells of its new box in per-cell lists beside the table (a wide new box: a list every query scans),
 * until those entries outnumber the rows, when the table is built anew: a move costs O(1) amortized
 * and a query what lies in its cells. (Scanning every moved row at each query instead cost a share of
 * the world per impact.) An entry left by an earlier move finds a row whose box has gone elsewhere: a
 * query tests each row's current box, once. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "reach_grid.h"
#include "grid_shape.h"

#ifndef LC_REACH_GRID_CELL
#define LC_REACH_GRID_CELL 2.0   /* the cell over the boxes' mean extent: a typical box covers one to four
                                    cells, and a build (every body, once per tracked interval) writes
                                    fewer entries than with cells of the mean extent, at little cost to
                                    the queries (a few per impact) */
#endif
#define LC_GRID_MAX_SPAN 4   /* a box over more cells than this along an axis goes to the wide list */

struct lc_reach_grid {
    int count;                       /* rows of the world */
    double x0, y0, cell, inv;        /* the grid's origin, cell size and 1 / cell */
    int nx, ny;
    lc_buf box;                      /* count x 4: each indexed row's box */
    lc_buf state;                    /* count: 0 not indexed, 1 in the table, 2 wide, 3 moved */
    lc_buf cell_start, cell_rows;    /* the table: rows of cell c at cell_rows[cell_start[c] .. cell_start[c + 1]) */
    lc_buf wide, moved;              /* rows in the wide list and moved rows with a wide box (counts below) */
    int nwide, nmoved, nindexed;
    lc_buf over_head, over_next, over_row;   /* moved rows' cell lists: cell c's first entry over_head[c]
                                                (-1: none), each entry's row and next (-1: the last) */
    int nover;
    lc_buf stamp, found;             /* a query's dedup stamps (count) and its result */
    unsigned stamp_now;
    lc_buf rows_tmp;                 /* the rebuild's row list */
    lc_buf range;                    /* the build's cell range of each row it indexes (4 ints by row) */
};

lc_reach_grid *lc_reach_grid_create(void) { return calloc(1, sizeof(lc_reach_grid)); }

void lc_reach_grid_destroy(lc_reach_grid *g)
{
    if (g == NULL) return;
    lc_buf_free(&g->box);
    lc_buf_free(&g->state);
    lc_buf_free(&g->cell_start);
    lc_buf_free(&g->cell_rows);
    lc_buf_free(&g->wide);
    lc_buf_free(&g->moved);
    lc_buf_free(&g->stamp);
    lc_buf_free(&g->found);
    lc_buf_free(&g->rows_tmp);
    lc_buf_free(&g->range);
    lc_buf_free(&g->over_head);
    lc_buf_free(&g->over_next);
    lc_buf_free(&g->over_row);
    free(g);
}

/* The cell range [i0, i1] x [j0, j1] a box covers, clamped to the grid. */
static void cell_range(const lc_reach_grid *g, const double *b, int *i0, int *j0, int *i1, int *j1)
{
    *i0 = lc_grid_cell_of(b[0], g->x0, g->inv, g->nx);
    *j0 = lc_grid_cell_of(b[1], g->y0, g->inv, g->ny);
    *i1 = lc_grid_cell_of(b[2], g->x0, g->inv, g->nx);
    *j1 = lc_grid_cell_of(b[3], g->y0, g->inv, g->ny);
}

static int is_wide(const lc_reach_grid *g, const double *b)
{
    return b[2] - b[0] > LC_GRID_MAX_SPAN * g->cell || b[3] - b[1] > LC_GRID_MAX_SPAN * g->cell;
}

int lc_reach_grid_build(lc_reach_grid *g, const double *boxes4, const int *rows, int n, int count)
{
    double *box = lc_buf_get(&g->box, (size_t)(count > 0 ? count : 1) * 4 * sizeof(double));
    uint8_t *state = lc_buf_get(&g->state, (size_t)(count > 0 ? count : 1));
    int *wide = lc_buf_get(&g->wide, (size_t)(n > 0 ? n : 1) * sizeof(int));
    int *moved = lc_buf_get(&g->moved, (size_t)(n > 0 ? n : 1) * sizeof(int));
    unsigned *stamp = lc_buf_get(&g->stamp, (size_t)(count > 0 ? count : 1) * sizeof(unsigned));
    int *range = lc_buf_get(&g->range, (size_t)(count > 0 ? count : 1) * 4 * sizeof(int));
    double ext = 0.0, xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
    int *start, *cells, i, k, ncell, small = 0;
    if (!box || !state || !wide || !moved || !stamp || !range) return -1;
    if (g->count != count) {
        memset(stamp, 0, (size_t)(count > 0 ? count : 1) * sizeof(unsigned));
        g->stamp_now = 0;
    }
    g->count = count;
    memset(state, 0, (size_t)(count > 0 ? count : 1));
    /* the cell: LC_REACH_GRID_CELL times the mean extent of the boxes */
    for (k = 0; k < n; ++k) {
        const double *b = &boxes4[4 * rows[k]];
        double wx = b[2] - b[0], wy = b[3] - b[1];
        if (b != &box[4 * rows[k]]) memcpy(&box[4 * rows[k]], b, 4 * sizeof(double));
        ext += wx > wy ? wx : wy;   /* finite boxes: comparisons, not calls to fmax and fmin */
    }
    g->cell = n > 0 && ext > 0.0 ? LC_REACH_GRID_CELL * ext / n : 1.0;
    for (k = 0; k < n; ++k) {
        const double *b = &box[4 * rows[k]];
        if (is_wide(g, b)) continue;
        if (b[0] < xmin) xmin = b[0];
        if (b[1] < ymin) ymin = b[1];
        if (b[2] > xmax) xmax = b[2];
        if (b[3] > ymax) ymax = b[3];
        small++;
    }
    if (small == 0) xmin = ymin = xmax = ymax = 0.0;
    if (lc_grid_shape(xmin, ymin, xmax, ymax, n, &g->cell, &g->nx, &g->ny) != 0) {
        /* finite reaches farther apart than a double spans: one cell holds them all (a query then scans
         * every row and keeps the ones that overlap it, the same answer) */
        xmin = ymin = 0.0;
        g->nx = g->ny = 1;
    }
    g->x0 = xmin;
    g->y0 = ymin;
    g->inv = 1.0 / g->cell;
    ncell = g->nx * g->ny;
    start = lc_buf_get(&g->cell_start, (size_t)(ncell + 1) * sizeof(int));
    {
        int *head = lc_buf_get(&g->over_head, (size_t)ncell * sizeof(int));
        if (start == NULL || head == NULL) return -1;
        for (i = 0; i < ncell; ++i) head[i] = -1;
    }
    memset(start, 0, (size_t)(ncell + 1) * sizeof(int));
    g->nwide = g->nmoved = g->nover = 0;
    for (k = 0; k < n; ++k) {
        int r = rows[k], *c = &range[4 * r], ii, jj;
        if (is_wide(g, &box[4 * r])) {
            state[r] = 2;
            wide[g->nwide++] = r;
            continue;
        }
        state[r] = 1;
        cell_range(g, &box[4 * r], &c[0], &c[1], &c[2], &c[3]);
        for (jj = c[1]; jj <= c[3]; ++jj)
            for (ii = c[0]; ii <= c[2]; ++ii) start[jj * g->nx + ii + 1]++;
    }
    for (i = 0; i < ncell; ++i) start[i + 1] += start[i];
    cells = lc_buf_get(&g->cell_rows, (size_t)(start[ncell] > 0 ? start[ncell] : 1) * sizeof(int));
    if (cells == NULL) return -1;
    /* rows in ascending order within each cell (the pass goes through rows in their given order, and
     * start[] counts forward: start[c] becomes the cell's end) */
    for (k = 0; k < n; ++k) {
        int r = rows[k], ii, jj;
        const int *c = &range[4 * r];
        if (state[r] != 1) continue;
        for (jj = c[1]; jj <= c[3]; ++jj)
            for (ii = c[0]; ii <= c[2]; ++ii) cells[start[jj * g->nx + ii]++] = r;
    }
    for (i = ncell; i > 0; --i) start[i] = start[i - 1];
    start[0] = 0;
    g->nindexed = n;
    return 0;
}

/* Entries for row `row` in the cell lists of the cells its box covers (not wide): 0, or -1 without
 * memory. */
static int add_cell_entries(lc_reach_grid *g, int row)
{
    int i0, j0, i1, j1, ii, jj, need, *head = (int *)g->over_head.p, *next, *rows;
    cell_range(g, &((const double *)g->box.p)[4 * row], &i0, &j0, &i1, &j1);
    need = g->nover + (i1 - i0 + 1) * (j1 - j0 + 1);
    next = lc_buf_get(&g->over_next, (size_t)need * sizeof(int));
    rows = lc_buf_get(&g->over_row, (size_t)need * sizeof(int));
    if (next == NULL || rows == NULL) return -1;
    for (jj = j0; jj <= j1; ++jj)
        for (ii = i0; ii <= i1; ++ii) {
            int c = jj * g->nx + ii;
            rows[g->nover] = row;
            next[g->nover] = head[c];
            head[c] = g->nover++;
        }
    return 0;
}

int lc_reach_grid_move(lc_reach_grid *g, int row, const double b[4])
{
    double *box = (double *)g->box.p;
    uint8_t *state = (uint8_t *)g->state.p;
    memcpy(&box[4 * row], b, 4 * sizeof(double));
    if (state[row] == 2) return 0;   /* scanned from the wide list already */
    if (state[row] == 0) g->nindexed++;
    state[row] = 3;
    if (is_wide(g, b)) {
        int *moved = lc_buf_get(&g->moved, (size_t)(g->nmoved + 1) * sizeof(int));
        if (moved == NULL) return -1;
        moved[g->nmoved++] = row;
    } else if (add_cell_entries(g, row) != 0) {
        return -1;
    }
    /* past a share of the rows (wide moved boxes, scanned by every query) or past more entries than
     * rows, a new table costs less */
    if (g->nmoved > 32 + g->nindexed / 16 || g->nover > 2 * g->nindexed + 64) {
        int *rows = lc_buf_get(&g->rows_tmp, (size_t)g->count * sizeof(int));
        int i, n = 0;
        if (rows == NULL) return -1;
        for (i = 0; i < g->count; ++i)
            if (state[i]) rows[n++] = i;
        return lc_reach_grid_build(g, box, rows, n, g->count);
    }
    return 0;
}

static int overlaps(const double *a, const double *b)
{
    return a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3];
}

static int cmp_int(const void *x, const void *y)
{
    int a = *(const int *)x, b = *(const int *)y;
    return (a > b) - (a < b);
}

int lc_reach_grid_query(lc_reach_grid *g, const double q[4], const int **out)
{
    const double *box = (const double *)g->box.p;
    const uint8_t *state = (const uint8_t *)g->state.p;
    const int *start = (const int *)g->cell_start.p, *cells = (const int *)g->cell_rows.p;
    unsigned *stamp = (unsigned *)g->stamp.p;
    int *found, n = 0, i0, j0, i1, j1, ii, jj, k, cap = 64;
    if (++g->stamp_now == 0) {   /* wrapped: every stamp is stale again */
        memset(stamp, 0, (size_t)g->count * sizeof(unsigned));
        g->stamp_now = 1;
    }
    found = lc_buf_get(&g->found, (size_t)cap * sizeof(int));
    if (found == NULL) return -1;
#define LC_GRID_TAKE(r)                                                                  \
    do {                                                                                 \
        int r_ = (r);                                                                    \
        if (stamp[r_] == g->stamp_now || !overlaps(&box[4 * r_], q)) break;              \
        stamp[r_] = g->stamp_now;                                                        \
        if (n == cap) {                                                                  \
            cap *= 2;                                                                    \
            if ((found = lc_buf_get(&g->found, (size_t)cap * sizeof(int))) == NULL) return -1; \
        }                                                                                \
        found[n++] = r_;                                                                 \
    } while (0)
    if (!(q[0] <= q[2] && q[1] <= q[3])) {
        *out = found;
        return 0;
    }
    /* boxes beyond the table's extent sit in its edge cells, and a query that meets one is clamped to
     * them too (the clamp keeps the order of interval ends) */
    cell_range(g, q, &i0, &j0, &i1, &j1);
    for (jj = j0; jj <= j1; ++jj)
        for (ii = i0; ii <= i1; ++ii) {
            int c = jj * g->nx + ii;
            for (k = start[c]; k < start[c + 1]; ++k)
                if (state[cells[k]] == 1) LC_GRID_TAKE(cells[k]);
            for (k = ((const int *)g->over_head.p)[c]; k >= 0; k = ((const int *)g->over_next.p)[k])
                LC_GRID_TAKE(((const int *)g->over_row.p)[k]);
        }
    for (k = 0; k < g->nwide; ++k) LC_GRID_TAKE(((const int *)g->wide.p)[k]);
    for (k = 0; k < g->nmoved; ++k) LC_GRID_TAKE(((const int *)g->moved.p)[k]);
#undef LC_GRID_TAKE
    /* a query finds a few rows: an insertion sort, without qsort's calls per comparison */
    if (n > 32) {
        qsort(found, (size_t)n, sizeof(int), cmp_int);
    } else {
        for (k = 1; k < n; ++k) {
            int r = found[k], q = k;
            while (q > 0 && found[q - 1] > r) {
                found[q] = found[q - 1];
                --q;
            }
            found[q] = r;
        }
    }
    *out = found;
    return n;
}
