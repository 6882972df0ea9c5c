/* The grid's searches over an interval from fat boxes kept between searches (lc_bp_pairs_of_fat): the
 * same pairs in the same order as the grid search of the boxes themselves. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "broad_phase_internal.h"

#ifndef LC_FAT_GROW
#define LC_FAT_GROW 0.25   /* a fat box over its box, on each side, in the boxes' mean extent: a spinning
                              free-flight block leaves one after a few steps; twice that made more fat
                              pairs to test than it saved in new fat boxes (callgrind, 5000 blocks) */
#endif

struct lc_bp_fat {
    /* each row's fat box (its box grown by fat_grow, 4 doubles by row) in fat_grid, and the pairs whose
     * fat boxes overlap (fat_count of them, in brute force's order; -1: none), with the world's rows,
     * edits and margin they were made for */
    lc_reach_grid *fat_grid;
    lc_buf fat_boxes, fat_pairs, fat_new, fat_rows;
    int fat_count, fat_n;
    double fat_margin, fat_grow;
    unsigned long fat_edits;
    lc_buf moved, moved_rows;   /* lc_bp_pairs_of_fat's rows whose boxes left their fat boxes */
};

lc_bp_fat *lc_bp_fat_create(void)
{
    lc_bp_fat *f = calloc(1, sizeof(lc_bp_fat));
    if (f == NULL) return NULL;
    f->fat_count = -1;
    f->fat_grid = lc_reach_grid_create();
    if (f->fat_grid == NULL) {
        free(f);
        return NULL;
    }
    return f;
}

void lc_bp_fat_destroy(lc_bp_fat *f)
{
    if (f == NULL) return;
    lc_buf_free(&f->fat_boxes);
    lc_buf_free(&f->fat_pairs);
    lc_buf_free(&f->fat_new);
    lc_buf_free(&f->fat_rows);
    lc_buf_free(&f->moved);
    lc_buf_free(&f->moved_rows);
    lc_reach_grid_destroy(f->fat_grid);
    free(f);
}

static int finite_box(const box *b)
{
    return b->x0 > -INFINITY && b->x1 < INFINITY && b->y0 > -INFINITY && b->y1 < INFINITY && b->x0 <= b->x1 &&
           b->y0 <= b->y1;
}

/* A box's fat box, grown by grow; 0 when it is not finite (a box far out, beyond what a double's sum
 * keeps finite: searched as it is). */
static int fat_of(const box *b, double grow, double f[4])
{
    f[0] = b->x0 - grow;
    f[1] = b->y0 - grow;
    f[2] = b->x1 + grow;
    f[3] = b->y1 + grow;
    return f[0] > -INFINITY && f[2] < INFINITY && f[1] > -INFINITY && f[3] < INFINITY;
}

/* The fat pairs made anew: every row's fat box from its box, in the fat grid, and the pairs whose fat
 * boxes overlap from the grid search (box_pairs.c), in brute force's order. 0, -1 without memory, -2
 * for a box the grid cannot hold (then the caller searches the boxes themselves). */
static int fat_build(lc_bp_fat *bp, lc_world *w, lc_box_pairs *scratch, const box *boxes, double margin)
{
    int n = w->count, i;
    double *fat = lc_buf_get(&bp->fat_boxes, (size_t)(n > 0 ? n : 1) * 4 * sizeof(double));
    int *rows = lc_buf_get(&bp->fat_rows, (size_t)(n > 0 ? n : 1) * sizeof(int));
    double ext = 0.0;
    lc_bp_grid_keep k;
    bp->fat_count = -1;
    if (fat == NULL || rows == NULL) return -1;
    for (i = 0; i < n; ++i) {
        if (!finite_box(&boxes[i])) return -2;
        ext += fmax(boxes[i].x1 - boxes[i].x0, boxes[i].y1 - boxes[i].y0);
    }
    bp->fat_grow = n > 0 ? LC_FAT_GROW * ext / n : 0.0;
    for (i = 0; i < n; ++i) {
        rows[i] = i;
        if (!fat_of(&boxes[i], bp->fat_grow, &fat[4 * i])) return -2;
    }
    if (lc_reach_grid_build(bp->fat_grid, fat, rows, n, n) != 0) return -1;
    k.w = w;
    k.buf = &bp->fat_pairs;
    k.count = 0;
    if (lc_box_pairs_find(scratch, fat, 4 * sizeof(double), n, lc_bp_keep_grid_pair, &k) != 0) return -1;
    if (k.count > 1 && lc_bp_order_pairs(w, (int *)bp->fat_pairs.p, k.count) != 0) return -1;
    bp->fat_count = k.count;
    bp->fat_n = n;
    bp->fat_margin = margin;
    bp->fat_edits = w->edits;
    return 0;
}

/* A row's box that left its fat box gets a new one (its box grown by a share of the mean extent), moved
 * in the fat grid, and the fat pairs of those rows are found anew there; the pairs are then the fat
 * pairs whose boxes overlap (every box lies in its fat box, so two boxes that meet have fat boxes that
 * meet). Bodies move a little per step and most keep their fat boxes for several steps: the search
 * costs a test per row and per fat pair, not a build of the grid. */
int lc_bp_pairs_of_fat(lc_bp_fat *bp, lc_world *w, lc_box_pairs *scratch, const box *boxes, double margin,
                       lc_buf *buf)
{
    int n = w->count, i, k, m = 0, nn = 0, count = 0, r;
    double *fat;
    int *moved_rows, *fp, *out;
    uint8_t *moved;
    if (w->excluded != NULL) return -2;
    moved = lc_buf_get(&bp->moved, (size_t)(n > 0 ? n : 1));
    moved_rows = lc_buf_get(&bp->moved_rows, (size_t)(n > 0 ? n : 1) * sizeof(int));
    if (moved == NULL || moved_rows == NULL) return -1;
    if (bp->fat_count >= 0 && bp->fat_n == n && bp->fat_margin == margin && bp->fat_edits == w->edits) {
        fat = (double *)bp->fat_boxes.p;
        for (i = 0; i < n; ++i) {
            const box *b = &boxes[i];
            const double *f = &fat[4 * i];
            moved[i] = !(b->x0 >= f[0] && b->y0 >= f[1] && b->x1 <= f[2] && b->y1 <= f[3]);
            if (moved[i]) {
                if (!finite_box(b)) {
                    bp->fat_count = -1;
                    return -2;
                }
                moved_rows[m++] = i;
            }
        }
        if (m > n / 4) bp->fat_count = -1;   /* past a quarter of the boxes out of theirs, built anew */
    }
    if (bp->fat_count < 0) {
        r = fat_build(bp, w, scratch, boxes, margin);
        if (r != 0) return r;
        m = 0;
    }
    fat = (double *)bp->fat_boxes.p;
    if (m > 0) {
        int nf = 0;
        /* the moved rows' new fat boxes, in the grid */
        for (k = 0; k < m; ++k) {
            double *f = &fat[4 * moved_rows[k]];
            if (!fat_of(&boxes[moved_rows[k]], bp->fat_grow, f)) {
                bp->fat_count = -1;
                return -2;
            }
            if (lc_reach_grid_move(bp->fat_grid, moved_rows[k], f) != 0) {
                bp->fat_count = -1;
                return -1;
            }
        }
        /* their fat pairs: each from the lower row when both moved */
        for (k = 0; k < m; ++k) {
            const int *near;
            int a = moved_rows[k], q, nq = lc_reach_grid_query(bp->fat_grid, &fat[4 * a], &near);
            if (nq < 0) {
                bp->fat_count = -1;
                return -1;
            }
            for (q = 0; q < nq; ++q) {
                int b = near[q];
                if (b == a || (moved[b] && b < a) || (w->is_static[a] && w->is_static[b])) continue;
                if ((nn = add_pair(&bp->fat_new, nn, a, b)) < 0) {
                    bp->fat_count = -1;
                    return -1;
                }
            }
        }
        if (nn > 1) qsort(bp->fat_new.p, (size_t)nn, 2 * sizeof(int), cmp_pair);
        /* the other fat pairs (neither row moved) stay, in order; the new ones merged in */
        fp = lc_buf_get(&bp->fat_pairs, (size_t)(bp->fat_count + nn + 1) * 2 * sizeof(int));
        if (fp == NULL) {
            bp->fat_count = -1;
            return -1;
        }
        for (k = 0; k < bp->fat_count; ++k)
            if (!moved[fp[2 * k]] && !moved[fp[2 * k + 1]]) {
                fp[2 * nf] = fp[2 * k];
                fp[2 * nf + 1] = fp[2 * k + 1];
                nf++;
            }
        merge_pairs(fp, nf, (const int *)bp->fat_new.p, nn);
        bp->fat_count = nf + nn;
    }
    /* the fat pairs whose boxes overlap */
    fp = (int *)bp->fat_pairs.p;
    out = lc_buf_get(buf, (size_t)(bp->fat_count + 1) * 2 * sizeof(int));
    if (out == NULL) return -1;
    for (k = 0; k < bp->fat_count; ++k) {
        int a = fp[2 * k], b = fp[2 * k + 1];
        if (!overlap(&boxes[a], &boxes[b])) continue;
        out[2 * count] = a;
        out[2 * count + 1] = b;
        count++;
    }
    w->last.grid_steps++;
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}
