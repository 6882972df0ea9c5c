/* What the broad phase's files share: the boxes and their tests, the pair lists' order (brute force's:
 * by a, then b), and the modules the broad phase's state owns: the reuse of the last interval search's
 * pairs at one state (broad_phase_kept.c) and the fat boxes the grid keeps between interval searches
 * (broad_phase_fat.c). broad_phase.c computes the boxes and dispatches. */
#ifndef LC_BROAD_PHASE_INTERNAL_H
#define LC_BROAD_PHASE_INTERNAL_H

#include <string.h>
#include "world.h"
#include "reach_grid.h"
#include "box_pairs.h"

typedef struct box { double x0, y0, x1, y1; int row; } box;

static inline int overlap(const box *a, const box *b)
{
    return a->x0 <= b->x1 && b->x0 <= a->x1 && a->y0 <= b->y1 && b->y0 <= a->y1;
}

static inline int add_pair(lc_buf *buf, int count, int a, int b)
{
    int *p = lc_buf_get(buf, (size_t)(count + 1) * 2 * sizeof(int));
    if (p == NULL) return -1;
    if (a > b) { int t = a; a = b; b = t; }
    p[2 * count] = a;
    p[2 * count + 1] = b;
    return count + 1;
}

static inline int cmp_box(const void *x, const void *y)
{
    const box *a = x, *b = y;
    if (a->x0 < b->x0) return -1;
    if (a->x0 > b->x0) return 1;
    return a->row - b->row;   /* ties broken by row: deterministic */
}

static inline int cmp_pair(const void *x, const void *y)
{
    const int *a = x, *b = y;
    if (a[0] != b[0]) return (a[0] > b[0]) - (a[0] < b[0]);
    return (a[1] > b[1]) - (a[1] < b[1]);
}

/* 1 when a state row (x, y, angle, ...) has pose (x, y, angle): a body's box depends on its pose alone. */
static inline int same_pose(const double *row, const double *pose) { return memcmp(row, pose, 3 * sizeof(double)) == 0; }

static inline int pair_after(const int *x, const int *y) { return x[0] > y[0] || (x[0] == y[0] && x[1] > y[1]); }

/* Merges the sorted pairs add[0..nadd) into the sorted pairs p[0..count) (p holds count + nadd pairs),
 * from the back: the two lists share no pair. */
static inline void merge_pairs(int *p, int count, const int *add, int nadd)
{
    int i = count - 1, j = nadd - 1, t;
    for (t = count + nadd - 1; j >= 0; --t) {
        if (i >= 0 && pair_after(&p[2 * i], &add[2 * j])) {
            p[2 * t] = p[2 * i];
            p[2 * t + 1] = p[2 * i + 1];
            --i;
        } else {
            p[2 * t] = add[2 * j];
            p[2 * t + 1] = add[2 * j + 1];
            --j;
        }
    }
}

/* ---- broad_phase.c ---- */
/* Where body i can be between s0 and s1, grown by margin. */
void lc_bp_swept_box(lc_world *w, const double *s0, const double *s1, int i, double margin, box *out);
/* lc_box_pairs_find's keep (ctx: an lc_bp_grid_keep, whose count it adds to buf's pairs). */
typedef struct lc_bp_grid_keep { lc_world *w; lc_buf *buf; int count; } lc_bp_grid_keep;
int lc_bp_keep_grid_pair(void *ctx, int a, int b);
/* Sorts p's count pairs into brute force's order: 0, or -1 without memory. */
int lc_bp_order_pairs(lc_world *w, int *p, int count);

/* ---- broad_phase_kept.c ---- */
typedef struct lc_bp_kept lc_bp_kept;
lc_bp_kept *lc_bp_kept_create(void);
void lc_bp_kept_destroy(lc_bp_kept *k);
/* The search over s0 -> s1 (s1 != s0) that found `count` pairs in buf, kept for lc_bp_pairs_from_kept. */
void lc_bp_keep_search(lc_bp_kept *k, const lc_world *w, const double *s0, const double *s1, double margin,
                       const lc_buf *buf, int count);
/* The whole-world pairs at state s from the kept search: the same pairs in the same order as a search
 * of every box at s, -2 when they cannot be had this way (then the caller searches), -1 without memory.
 * tracked: the tracked reach grid (lc_broad_phase_track), NULL while untracked. */
int lc_bp_pairs_from_kept(lc_bp_kept *k, lc_world *w, lc_reach_grid *tracked, const double *s, double margin,
                          lc_buf *buf);
/* lc_broad_phase_track indexed the reach from s0 to s1 of `all` (every row, or not) in its grid. */
void lc_bp_kept_track(lc_bp_kept *k, const lc_world *w, const double *s0, const double *s1, double margin, int all);
/* lc_broad_phase_retrack gave row a new reach. */
void lc_bp_kept_retracked(lc_bp_kept *k, int row);

/* ---- broad_phase_fat.c ---- */
typedef struct lc_bp_fat lc_bp_fat;
lc_bp_fat *lc_bp_fat_create(void);
void lc_bp_fat_destroy(lc_bp_fat *f);
/* The grid's search of boxes[0..w->count) over an interval from the fat boxes kept between searches
 * (scratch: the grid search's): the pairs, -1 without memory, -2 where it does not apply (then the
 * caller searches). */
int lc_bp_pairs_of_fat(lc_bp_fat *f, lc_world *w, lc_box_pairs *scratch, const box *boxes, double margin,
                       lc_buf *buf);

#endif
