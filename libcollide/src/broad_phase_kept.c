/* The broad phase's reuse of the last whole-world search over an interval: a whole-world search at one
 * state later (the end-of-step projection's) takes from it the pairs of the rows still at the states
 * their boxes came from (lc_bp_pairs_from_kept). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "broad_phase_internal.h"

struct lc_bp_kept {
    /* The last whole-world search over an interval (s1 != s0): its pairs (kept_count, -1: none) and each
     * row's pose its box came from (s1's row, a static body's s0's; x, y and angle: a box depends on
     * nothing else, and half a state row is half the reads of a whole-world pass), with the world's
     * edits, rows and margin then. */
    lc_buf kept_pairs, kept_ref;
    int kept_count, kept_rows;
    double kept_margin;
    unsigned long kept_edits;
    /* while tracked: 1 for a row whose reach in the grid need not hold its box at kept_ref (a row the
     * track did not index from the kept search's states, or retracked since); track_kept: the tracked
     * reach holds every other row's box at kept_ref */
    lc_buf stale;
    int track_kept;
    /* lc_bp_pairs_from_kept's rows at the new state (moved: not at kept_ref, or stale), their boxes
     * (stamped when computed) and the pairs with a moved row */
    lc_buf moved, moved_rows, end_boxes, end_stamp, moved_pairs, moved_boxes;
    unsigned end_now;
    int end_rows;   /* the rows end_stamp was cleared for (-1: none) */
};

lc_bp_kept *lc_bp_kept_create(void)
{
    lc_bp_kept *k = calloc(1, sizeof(lc_bp_kept));
    if (k == NULL) return NULL;
    k->kept_count = k->end_rows = -1;
    return k;
}

void lc_bp_kept_destroy(lc_bp_kept *k)
{
    if (k == NULL) return;
    lc_buf_free(&k->kept_pairs);
    lc_buf_free(&k->kept_ref);
    lc_buf_free(&k->stale);
    lc_buf_free(&k->moved);
    lc_buf_free(&k->moved_rows);
    lc_buf_free(&k->end_boxes);
    lc_buf_free(&k->end_stamp);
    lc_buf_free(&k->moved_pairs);
    lc_buf_free(&k->moved_boxes);
    free(k);
}

void lc_bp_keep_search(lc_bp_kept *bp, const lc_world *w, const double *s0, const double *s1, double margin,
                       const lc_buf *buf, int count)
{
    int n = w->count, i;
    int *p = lc_buf_get(&bp->kept_pairs, (size_t)(count > 0 ? count : 1) * 2 * sizeof(int));
    double *ref = lc_buf_get(&bp->kept_ref, (size_t)(n > 0 ? n : 1) * 3 * sizeof(double));
    bp->kept_count = -1;
    bp->track_kept = 0;
    /* nothing kept without memory (the next search looks at every box), nor from a search that left
     * rows out: a later one may take them */
    if (p == NULL || ref == NULL || w->excluded != NULL) return;
    if (count > 0) memcpy(p, buf->p, (size_t)count * 2 * sizeof(int));
    for (i = 0; i < n; ++i) memcpy(&ref[i * 3], w->is_static[i] ? &s0[i * 6] : &s1[i * 6], 3 * sizeof(double));
    bp->kept_count = count;
    bp->kept_rows = n;
    bp->kept_margin = margin;
    bp->kept_edits = w->edits;
}

void lc_bp_kept_track(lc_bp_kept *bp, const lc_world *w, const double *s0, const double *s1, double margin, int all)
{
    int i;
    /* a row's reach holds its box at s1 (a static body's at s0): where that is its kept state, the
     * grid finds it for lc_bp_pairs_from_kept */
    bp->track_kept = 0;
    if (bp->kept_count >= 0 && bp->kept_rows == w->count && bp->kept_margin == margin && bp->kept_edits == w->edits &&
        all) {
        uint8_t *stale = lc_buf_get(&bp->stale, (size_t)(w->count > 0 ? w->count : 1));
        const double *ref = (const double *)bp->kept_ref.p;
        if (stale != NULL) {
            for (i = 0; i < w->count; ++i) stale[i] = !same_pose(w->is_static[i] ? &s0[i * 6] : &s1[i * 6], &ref[i * 3]);
            bp->track_kept = 1;
        }
    }
}

void lc_bp_kept_retracked(lc_bp_kept *bp, int row)
{
    if (bp->track_kept) ((uint8_t *)bp->stale.p)[row] = 1;   /* its reach is its new path's */
}

/* Row r's box at state s (margin grown), computed once per lc_bp_pairs_from_kept. */
static const box *end_box_of(lc_bp_kept *bp, lc_world *w, const double *s, int r, double margin)
{
    box *b = &((box *)bp->end_boxes.p)[r];
    unsigned *stamp = (unsigned *)bp->end_stamp.p;
    if (stamp[r] != bp->end_now) {
        lc_bp_swept_box(w, s, s, r, margin, b);
        stamp[r] = bp->end_now;
    }
    return b;
}

/* A row at its kept state has its box inside its box of the kept search (its box over the interval
 * holds its box at the interval's end, the same bits from the same state), so two such rows whose boxes
 * meet were a kept pair: those pairs are the kept ones whose boxes at s still meet, in the kept order.
 * A row not at its kept state (an impact moved it) meets one at it only where that one's reach in the
 * tracked grid is, which holds its box at the kept state: the moved rows' pairs come from the grid and
 * from each other, sorted and merged in. Without the grid they need the whole search, as do many of
 * them (past a quarter of the rows the search costs less). */
int lc_bp_pairs_from_kept(lc_bp_kept *bp, lc_world *w, lc_reach_grid *tracked, const double *s, double margin,
                          lc_buf *buf)
{
    const double *ref = (const double *)bp->kept_ref.p;
    const int *kept = (const int *)bp->kept_pairs.p;
    const uint8_t *stale = (const uint8_t *)bp->stale.p;
    int n = w->count, i, k, q, m = 0, count = 0, nm = 0, *out, *mp;
    uint8_t *moved;
    int *mrows;
    if (bp->kept_count < 0 || bp->kept_rows != n || bp->kept_margin != margin || bp->kept_edits != w->edits ||
        w->excluded != NULL)
        return -2;
    moved = lc_buf_get(&bp->moved, (size_t)(n > 0 ? n : 1));
    mrows = lc_buf_get(&bp->moved_rows, (size_t)(n > 0 ? n : 1) * sizeof(int));
    if (moved == NULL || mrows == NULL || lc_buf_get(&bp->end_boxes, (size_t)(n > 0 ? n : 1) * sizeof(box)) == NULL ||
        lc_buf_get(&bp->end_stamp, (size_t)(n > 0 ? n : 1) * sizeof(unsigned)) == NULL)
        return -1;
    {
        int use_stale = tracked != NULL && bp->track_kept;
        for (i = 0; i < n; ++i) {
            moved[i] = !same_pose(&s[i * 6], &ref[i * 3]) || (use_stale && stale[i]);
            if (moved[i]) {
                if (m >= n / 4 + 1 || !use_stale) return -2;
                mrows[m++] = i;
            }
        }
    }
    if (bp->end_rows != n || ++bp->end_now == 0) {   /* another world size, or the stamps wrapped */
        memset(bp->end_stamp.p, 0, (size_t)(n > 0 ? n : 1) * sizeof(unsigned));
        bp->end_rows = n;
        bp->end_now = 1;
    }
    /* the kept pairs of two unmoved rows whose boxes still meet, in the kept (brute force's) order */
    out = lc_buf_get(buf, (size_t)(bp->kept_count + 1) * 2 * sizeof(int));
    if (out == NULL) return -1;
    for (k = 0; k < bp->kept_count; ++k) {
        int a = kept[2 * k], b = kept[2 * k + 1];
        if (moved[a] || moved[b] || !overlap(end_box_of(bp, w, s, a, margin), end_box_of(bp, w, s, b, margin)))
            continue;
        out[2 * count] = a;
        out[2 * count + 1] = b;
        count++;
    }
    /* the pairs with a moved row (broad_phase.c's add_if_near rules: excluded is NULL here) */
    for (k = 0; k < m; ++k) {
        int a = mrows[k], nnear;
        const int *near;
        const box *ba = end_box_of(bp, w, s, a, margin);
        double qb[4];
        qb[0] = ba->x0;
        qb[1] = ba->y0;
        qb[2] = ba->x1;
        qb[3] = ba->y1;
        nnear = lc_reach_grid_query(tracked, qb, &near);
        if (nnear < 0) return -1;
        for (q = 0; q < nnear; ++q) {
            int b = near[q];
            if (moved[b] || (w->is_static[a] && w->is_static[b])) continue;   /* moved pairs: below */
            if (!overlap(ba, end_box_of(bp, w, s, b, margin))) continue;
            if ((nm = add_pair(&bp->moved_pairs, nm, a, b)) < 0) return -1;
        }
    }
    /* the moved rows among themselves: a sweep along x over their boxes (every impact of a step adds
     * moved rows, and testing each against each grew as the square of the world's size) */
    if (m > 1) {
        box *mb = lc_buf_get(&bp->moved_boxes, (size_t)m * sizeof(box));
        if (mb == NULL) return -1;
        for (k = 0; k < m; ++k) {
            mb[k] = *end_box_of(bp, w, s, mrows[k], margin);
            /* a non-finite box leaves cmp_box no total order: the whole search instead */
            if (!(mb[k].x0 > -INFINITY && mb[k].x1 < INFINITY)) return -2;
        }
        qsort(mb, (size_t)m, sizeof(box), cmp_box);
        for (k = 0; k < m; ++k)
            for (q = k + 1; q < m && mb[q].x0 <= mb[k].x1; ++q) {
                if (w->is_static[mb[k].row] && w->is_static[mb[q].row]) continue;
                if (!overlap(&mb[k], &mb[q])) continue;
                if ((nm = add_pair(&bp->moved_pairs, nm, mb[k].row, mb[q].row)) < 0) return -1;
            }
    }
    if (nm > 0) {
        mp = (int *)bp->moved_pairs.p;
        if (nm > 1) qsort(mp, (size_t)nm, 2 * sizeof(int), cmp_pair);
        out = lc_buf_get(buf, (size_t)(count + nm) * 2 * sizeof(int));
        if (out == NULL) return -1;
        merge_pairs(out, count, mp, nm);
        count += nm;
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}
