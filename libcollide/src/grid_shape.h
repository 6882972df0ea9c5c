/* The shape of a uniform grid over boxes (box_pairs.c, reach_grid.c): its cell size, its columns and
 * rows, and the cell of a coordinate. */
#ifndef LC_GRID_SHAPE_H
#define LC_GRID_SHAPE_H

#include <math.h>

/* Cells over the bounds [xmin, xmax] x [ymin, ymax] of n boxes, from *cell (> 0, finite) doubled until
 * the table has at most about four cells per box: bodies strewn far apart make the cells larger, not the
 * table. Returns 0 with *cell, *nx, *ny; or -1, nothing changed, when the bounds are wider than a
 * double spans (finite boxes near both ends of the range), where the doubling would not end. */
static inline int lc_grid_shape(double xmin, double ymin, double xmax, double ymax, int n, double *cell, int *nx,
                                int *ny)
{
    double c = *cell;
    if (!(xmax - xmin < INFINITY && ymax - ymin < INFINITY)) return -1;
    for (;;) {
        double nxd = floor((xmax - xmin) / c) + 1.0, nyd = floor((ymax - ymin) / c) + 1.0;
        if (nxd * nyd <= 4.0 * n + 16.0) {
            *cell = c;
            *nx = (int)nxd;
            *ny = (int)nyd;
            return 0;
        }
        c *= 2.0;
    }
}

/* The cell of coordinate v along an axis of `cells` cells from origin o (inv: 1 / cell), clamped to the
 * grid. Any mapping monotone in v serves, as long as a grid's builds, moves and queries share it:
 * clamping keeps the order of interval ends, so two overlapping boxes still share a cell. The product
 * by 1 / cell is monotone, and the cast truncates, which is the floor from 1 up: no call to floor and
 * no division, for a map of every box of a build. */
static inline int lc_grid_cell_of(double v, double o, double inv, int cells)
{
    double f = (v - o) * inv;
    return f < 1.0 ? 0 : (f >= cells ? cells - 1 : (int)f);
}

#endif
