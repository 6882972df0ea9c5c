/* Overlapping pairs from a uniform grid (box_pairs.h). Each box goes into every cell it covers, the
 * cells' boxes in a compressed table built by a counting sort; two boxes are tested in each cell they
 * share but reported only from the first of those cells (the lower-left corner of the intersection of
 * their cell ranges), so each pair comes out once. A box over more than a few cells along an axis
 * (walls, floors) stays out of the table and is tested against the table's boxes in the cells it
 * covers, by the same rule; a non-finite or inverted box against every box. The cell is twice the mean
 * extent of the boxes, so a typical box covers one to four cells and a cell holds a few boxes; bodies
 * strewn far apart make the cells larger, never the table larger than about four cells per box. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "box_pairs.h"
#include "grid_shape.h"

#define LC_BOX_PAIRS_MAX_SPAN 4   /* a box over more cells than this along an axis goes to the wide list */
#ifndef LC_BOX_PAIRS_CELL
#define LC_BOX_PAIRS_CELL 2.0     /* the cell over the boxes' mean extent: a typical box covers one to four
                                     cells (with the mean extent itself, about four: more entries to sort) */
#endif

struct lc_box_pairs {
    lc_buf range;                  /* n x 4 ints: each gridable box's cells i0, j0, i1, j1 (clamped) */
    lc_buf cell_start, cell_box;   /* box k of cell c: cell_box[cell_start[c] + k], up to cell_start[c + 1] */
    lc_buf wide;                   /* the boxes not in the table, ascending */
    lc_buf kind;                   /* each box's: SMALL, WIDE or ODD (below) */
};

lc_box_pairs *lc_box_pairs_create(void) { return calloc(1, sizeof(lc_box_pairs)); }

void lc_box_pairs_destroy(lc_box_pairs *g)
{
    if (g == NULL) return;
    lc_buf_free(&g->range);
    lc_buf_free(&g->cell_start);
    lc_buf_free(&g->cell_box);
    lc_buf_free(&g->wide);
    lc_buf_free(&g->kind);
    free(g);
}

static const double *box_at(const void *boxes, size_t stride, int k)
{
    return (const double *)(const void *)((const char *)boxes + (size_t)k * stride);
}

static int overlap(const double *a, const double *b)
{
    return a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3];
}

/* A box the grid can hold: finite and not inverted (an inverted box can still meet a box that spans
 * it under the closed-interval test, so it is tested against all, as brute force would). */
static int gridable(const double *b)
{
    /* NaN fails every comparison; x0 > -inf, x0 <= x1 and x1 < inf make both ends finite */
    return b[0] > -INFINITY && b[0] <= b[2] && b[2] < INFINITY && b[1] > -INFINITY && b[1] <= b[3] && b[3] < INFINITY;
}

/* kind[k] of box k */
enum { SMALL = 0, WIDE = 1, ODD = 2 };   /* in the table; over too many cells; not gridable */

int lc_box_pairs_find(lc_box_pairs *g, const void *boxes, size_t stride, int n,
                      int (*keep)(void *ctx, int a, int b), void *ctx)
{
    size_t m = (size_t)(n > 0 ? n : 1);
    int *range = lc_buf_get(&g->range, m * 4 * sizeof(int));
    int *wide = lc_buf_get(&g->wide, m * sizeof(int));
    uint8_t *kind = lc_buf_get(&g->kind, m);
    int *start, *cell_box, nwide = 0, nx, ny, ncell, small = 0, k, c, p, q;
    double ext = 0.0, cell, inv, span, xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
    if (range == NULL || wide == NULL || kind == NULL) return -1;
    for (k = 0; k < n; ++k) {
        const double *b = box_at(boxes, stride, k);
        kind[k] = gridable(b) ? SMALL : ODD;
        if (kind[k] == SMALL) {
            double wx = b[2] - b[0], wy = b[3] - b[1];
            ext += wx > wy ? wx : wy;   /* finite: comparisons, not calls to fmax and fmin, here and below */
            small++;
        }
    }
    cell = small > 0 && ext > 0.0 && isfinite(ext) ? LC_BOX_PAIRS_CELL * ext / small : 1.0;
    span = LC_BOX_PAIRS_MAX_SPAN * cell;
    small = 0;
    for (k = 0; k < n; ++k) {
        const double *b = box_at(boxes, stride, k);
        if (kind[k] != SMALL || b[2] - b[0] > span || b[3] - b[1] > span) continue;
        if (b[0] < xmin) xmin = b[0];
        if (b[1] < ymin) ymin = b[1];
        if (b[2] > xmax) xmax = b[2];
        if (b[3] > ymax) ymax = b[3];
        small++;
    }
    if (small == 0) xmin = ymin = xmax = ymax = 0.0;
    if (lc_grid_shape(xmin, ymin, xmax, ymax, n, &cell, &nx, &ny) != 0) {
        /* finite boxes farther apart than a double spans: no grid, every box against every box */
        for (k = 0; k < n; ++k) kind[k] = ODD;
        xmin = ymin = 0.0;
        nx = ny = 1;
    }
    span = LC_BOX_PAIRS_MAX_SPAN * cell;
    inv = 1.0 / cell;
    ncell = nx * ny;
    start = lc_buf_get(&g->cell_start, (size_t)(ncell + 1) * sizeof(int));
    if (start == NULL) return -1;
    memset(start, 0, (size_t)(ncell + 1) * sizeof(int));
    for (k = 0; k < n; ++k) {
        const double *b = box_at(boxes, stride, k);
        int *r = &range[4 * k], ii, jj;
        if (kind[k] == ODD) {
            wide[nwide++] = k;
            continue;
        }
        r[0] = lc_grid_cell_of(b[0], xmin, inv, nx);
        r[1] = lc_grid_cell_of(b[1], ymin, inv, ny);
        r[2] = lc_grid_cell_of(b[2], xmin, inv, nx);
        r[3] = lc_grid_cell_of(b[3], ymin, inv, ny);
        if (b[2] - b[0] > span || b[3] - b[1] > span) {
            kind[k] = WIDE;
            wide[nwide++] = k;
            continue;
        }
        for (jj = r[1]; jj <= r[3]; ++jj)
            for (ii = r[0]; ii <= r[2]; ++ii) start[jj * nx + ii + 1]++;
    }
    for (c = 0; c < ncell; ++c) start[c + 1] += start[c];
    cell_box = lc_buf_get(&g->cell_box, (size_t)(start[ncell] > 0 ? start[ncell] : 1) * sizeof(int));
    if (cell_box == NULL) return -1;
    /* boxes ascending within each cell: start[c] counts forward to the cell's end, then shifts back */
    for (k = 0; k < n; ++k) {
        const int *r = &range[4 * k];
        int ii, jj;
        if (kind[k] != SMALL) continue;
        for (jj = r[1]; jj <= r[3]; ++jj)
            for (ii = r[0]; ii <= r[2]; ++ii) cell_box[start[jj * nx + ii]++] = k;
    }
    for (c = ncell; c > 0; --c) start[c] = start[c - 1];
    start[0] = 0;
    for (c = 0; c < ncell; ++c) {
        int ci = c % nx, cj = c / nx;
        for (p = start[c]; p < start[c + 1]; ++p) {
            int a = cell_box[p];
            const int *ra = &range[4 * a];
            const double *ba = box_at(boxes, stride, a);
            for (q = p + 1; q < start[c + 1]; ++q) {
                int b = cell_box[q];
                const int *rb = &range[4 * b];
                /* only from the first cell the two share */
                if ((ra[0] > rb[0] ? ra[0] : rb[0]) != ci || (ra[1] > rb[1] ? ra[1] : rb[1]) != cj) continue;
                if (overlap(ba, box_at(boxes, stride, b)) && keep(ctx, a, b) != 0) return -1;
            }
        }
    }
    /* a wide box against the table's boxes in the cells it covers (each from the first cell the two
     * share), an odd one against every table box; the wide and odd boxes against each other */
    for (p = 0; p < nwide; ++p) {
        int a = wide[p];
        const double *ba = box_at(boxes, stride, a);
        if (kind[a] == WIDE) {
            const int *ra = &range[4 * a];
            int ii, jj;
            for (jj = ra[1]; jj <= ra[3]; ++jj)
                for (ii = ra[0]; ii <= ra[2]; ++ii)
                    for (q = start[jj * nx + ii]; q < start[jj * nx + ii + 1]; ++q) {
                        int b = cell_box[q];
                        const int *rb = &range[4 * b];
                        if ((ra[0] > rb[0] ? ra[0] : rb[0]) != ii || (ra[1] > rb[1] ? ra[1] : rb[1]) != jj) continue;
                        if (overlap(ba, box_at(boxes, stride, b)) && keep(ctx, a < b ? a : b, a < b ? b : a) != 0)
                            return -1;
                    }
        } else {
            for (k = 0; k < n; ++k)
                if (kind[k] == SMALL && overlap(ba, box_at(boxes, stride, k)) &&
                    keep(ctx, a < k ? a : k, a < k ? k : a) != 0)
                    return -1;
        }
        for (q = p + 1; q < nwide; ++q) {
            int b = wide[q];
            if (overlap(ba, box_at(boxes, stride, b)) && keep(ctx, a, b) != 0) return -1;
        }
    }
    return 0;
}
