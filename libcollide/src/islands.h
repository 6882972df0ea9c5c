/* Islands: the groups of bodies a step advances independently of each other.
 *
 * Two dynamic bodies are in one island when their boxes, swept over the step along the motion their
 * applied forces predict (gravity, thrusters, springs, external force, damping: lc_applied_accelerations
 * held constant; contact forces only slow or redirect) and grown by contact_distance, overlap, or when a
 * spring joins them. Static bodies join nothing: they transmit no motion. So bodies of two islands
 * neither touch when the step begins nor meet during it, unless an impact throws one far off its
 * predicted path, which the step checks afterwards (step.c). Each island lists its candidate pairs
 * (its bodies among themselves and with static bodies). Rows and pairs are in row order, islands in
 * the order of their first row, so everything downstream is deterministic. */
#ifndef LC_ISLANDS_H
#define LC_ISLANDS_H

#include <stdint.h>

struct lc_world;

typedef struct lc_island {
    const int *rows;    /* the island's dynamic rows, ascending */
    int nrows;
    const int *pairs;   /* its candidate pairs (row a < row b), 2 ints each, in brute force's order */
    int npairs;
} lc_island;

typedef struct lc_islands lc_islands;   /* owned by the world */

lc_islands *lc_islands_create(void);
void lc_islands_destroy(lc_islands *is);

/* Builds the islands of w's current state for a step of dt. Bodies whose `frozen` entry is non-zero
 * (asleep; frozen may be NULL) are predicted not to move. `reach` (NULL, or 4 doubles per row: x0, y0,
 * x1, y1, empty when x0 > x1) adds to a body's swept box the region it is known to reach this step
 * (a retried step: where the first try took it). Returns 0, or -1 without memory or when the force
 * callback failed. */
int lc_islands_build(struct lc_world *w, lc_islands *is, double dt, const uint8_t *frozen, const double *reach);
/* The swept boxes of the last build, 4 doubles per row (x0, y0, x1, y1). */
const double *lc_islands_boxes(const lc_islands *is);
/* 1 if rows a < b were a candidate pair of the last build. */
int lc_islands_has_pair(const lc_islands *is, int a, int b);
int lc_islands_count(const lc_islands *is);
/* Island k of the last build. */
lc_island lc_islands_get(const lc_islands *is, int k);
/* The island of a row in the last build, -1 for a static body. */
int lc_islands_of(const lc_islands *is, int row);
/* After a step from state `start`: the bodies that went where the last build did not foresee. The boxes
 * their actual paths swept (start and end poses, the bulge of their turn, contact_distance) overlap
 * another body's where the build had no pair, so a contact between them could have been missed. Their
 * swept boxes are added to `reach` (4 doubles per row, as lc_islands_build takes it) for the next try.
 * Returns how many pairs that was, or -1 without memory. */
int lc_islands_unforeseen(struct lc_world *w, lc_islands *is, const double *start, double *reach);

#endif
