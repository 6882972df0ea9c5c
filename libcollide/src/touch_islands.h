/* The event regime's touch islands (touch_islands.c): the bodies a time-of-impact search advances with
 * a crossing's two bodies. */
#ifndef LC_TOUCH_ISLANDS_H
#define LC_TOUCH_ISLANDS_H

#include "world.h"

typedef struct lc_touch_islands lc_touch_islands;   /* owned by the event regime */

lc_touch_islands *lc_touch_islands_create(void);
void lc_touch_islands_destroy(lc_touch_islands *is);
/* The touch islands of rows[0..nrows) under the resting touches rest[0..nrest) and the springs. 0, or -1. */
int lc_touch_islands_build(const lc_world *w, lc_touch_islands *is, const int *rows, int nrows, const lc_touch *rest,
                           int nrest);
/* The touch island of a row of the last build, -1 for a static body. */
int lc_touch_island(const lc_touch_islands *is, int row);
/* The rows and resting touches of the islands of bodies a and b (one island, or both side by side), valid
 * until the next call. 0, or -1 without memory. */
int lc_touch_islands_of(lc_touch_islands *is, int a, int b, const int **rows, int *nrows, lc_touch **touches,
                        int *ntouches);

#endif
