/* The event regime's touch islands (touch_islands.c): the bodies a time-of-impact search advances with
 * a crossing's two bodies. */
#ifndef LC_TOUCH_ISLANDS_H
#define LC_TOUCH_ISLANDS_H

#include "world.h"

typedef struct lc_touch_islands {
    int *of;                  /* island of each body row, -1 for static bodies */
    int *rows, *row_start;    /* rows of island k: rows[row_start[k] .. row_start[k + 1]) */
    lc_touch *touches;        /* resting touches of island k: likewise, with touch_start */
    int *touch_start;
    int count;
} lc_touch_islands;

/* The touch islands of rows[0..nrows) under the resting touches rest[0..nrest) and the springs. 0, or -1. */
int lc_touch_islands_build(lc_world *w, const int *rows, int nrows, const lc_touch *rest, int nrest,
                           lc_touch_islands *is);
/* The rows and resting touches of the islands of bodies a and b (one island, or both side by side). 0, or -1. */
int lc_touch_islands_of(lc_world *w, const lc_touch_islands *is, int a, int b, const int **rows, int *nrows,
                        lc_touch **touches, int *ntouches);

#endif
