/* Every overlapping pair of a set of boxes from a uniform grid (box_pairs.c): the broad phase's search
 * over the whole world for many bodies, in time linear in the boxes and the pairs, where a sweep along
 * one axis visits about sqrt(n) boxes per box in a square world. */
#ifndef LC_BOX_PAIRS_H
#define LC_BOX_PAIRS_H

#include <stddef.h>
#include "world.h"

typedef struct lc_box_pairs lc_box_pairs;   /* scratch owned by the broad phase's state */

lc_box_pairs *lc_box_pairs_create(void);
void lc_box_pairs_destroy(lc_box_pairs *g);
/* Calls keep(ctx, a, b) once for each pair a < b of boxes[0..n) whose closed boxes overlap (the set
 * brute force finds: a box with a NaN meets none, an infinite one may meet many), in no set order.
 * Box k's x0, y0, x1, y1 are the four doubles at (const char *)boxes + k * stride. keep returns 0 to
 * go on or -1 to stop. Returns 0, or -1 without memory or when keep stopped. */
int lc_box_pairs_find(lc_box_pairs *g, const void *boxes, size_t stride, int n,
                      int (*keep)(void *ctx, int a, int b), void *ctx);

#endif
