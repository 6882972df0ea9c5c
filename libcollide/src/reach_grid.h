/* A uniform grid of boxes by body row, for neighbour queries that cost what is near instead of what
 * exists (reach_grid.c). The event regime's broad phase keeps in it where each body can be during a
 * trial interval (lc_broad_phase_track), so that after an impact the pairs of the impact's bodies and
 * the group the impact acts on are found without visiting every body. */
#ifndef LC_REACH_GRID_H
#define LC_REACH_GRID_H

#include "world.h"

typedef struct lc_reach_grid lc_reach_grid;   /* owned by the broad phase's state */

lc_reach_grid *lc_reach_grid_create(void);
void lc_reach_grid_destroy(lc_reach_grid *g);
/* Indexes rows[0..n) with their boxes boxes4[4 * row ..] (x0, y0, x1, y1; finite), in a world of
 * `count` rows. The grid is built anew: 0, or -1 without memory. */
int lc_reach_grid_build(lc_reach_grid *g, const double *boxes4, const int *rows, int n, int count);
/* Row `row`'s box is now box (x0, y0, x1, y1; finite): 0, or -1 without memory. */
int lc_reach_grid_move(lc_reach_grid *g, int row, const double box[4]);
/* The indexed rows whose box overlaps `box` (closed intervals), in ascending row order, into *out
 * (valid until the next call): their count, or -1 without memory. */
int lc_reach_grid_query(lc_reach_grid *g, const double box[4], const int **out);

#endif
