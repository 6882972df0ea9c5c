/* Broad phase: candidate body pairs from swept bounding boxes. Brute force for a few bodies,
 * sort-and-sweep along x from broadphase_threshold, pairs from a uniform grid (box_pairs.c) from
 * LC_GRID_MIN_ROWS (AUTO), over an interval from fat boxes the grid keeps between searches
 * (pairs_of_fat); all find the same pairs in the same order. A search at one state takes the last
 * interval search's pairs where it can (pairs_from_kept). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "reach_grid.h"
#include "box_pairs.h"
#include "tunables.h"

#ifndef LC_FAT_GROW
#define LC_FAT_GROW 0.25   /* a fat box over its box, on each side, in the boxes' mean extent: a spinning
                              free-flight block leaves one after a few steps; twice that made more fat
                              pairs to test than it saved in new fat boxes (callgrind, 5000 blocks) */
#endif

typedef struct box { double x0, y0, x1, y1; int row; } box;

struct lc_broad_phase_state {
    lc_buf boxes;                  /* every body's box of a search, by row */
    lc_buf bounds, have, marked;   /* lc_broad_phase_of: cheap bounds, which boxes it computed, its rows sorted */
    /* the rows in the last sort-and-sweep's x order (sweep_rows of them), the boxes being sorted, and the
     * counting sort of the pairs */
    lc_buf sweep_order, sweep_boxes, pair_start, pair_tmp;
    int sweep_rows;
    lc_box_pairs *grid_pairs;      /* the grid search's scratch */
    /* lc_broad_phase_track: where each body can be during the trial interval, in a grid, while tracked */
    lc_reach_grid *grid;
    int tracked;
    lc_buf reach, track_rows, box_stamp;
    unsigned stamp_now;
    /* The last whole-world search over an interval (s1 != s0): its pairs (kept_count, -1: none) and each
     * row's state its box came from (s1's row, a static body's s0's), with the world's edits, rows and
     * margin then. A whole-world search at one state later (the end-of-step projection's) takes from
     * them the pairs of the rows still at those states (pairs_from_kept). */
    lc_buf kept_pairs, kept_ref;
    int kept_count, kept_rows;
    double kept_margin;
    unsigned long kept_edits;
    /* while tracked: 1 for a row whose reach in the grid need not hold its box at kept_ref (a row the
     * track did not index from the kept search's states, or retracked since); track_kept: the tracked
     * reach holds every other row's box at kept_ref */
    lc_buf stale;
    int track_kept;
    /* pairs_from_kept's rows at the new state (moved: not at kept_ref, or stale), their boxes (stamped
     * when computed) and the pairs with a moved row */
    lc_buf moved, moved_rows, end_boxes, end_stamp, moved_pairs, moved_boxes;
    unsigned end_now;
    int end_rows;   /* the rows end_stamp was cleared for (-1: none) */
    /* The grid's searches over an interval (pairs_of_fat): each row's fat box (its box grown by
     * fat_grow, 4 doubles by row) in fat_grid, and the pairs whose fat boxes overlap (fat_count of them,
     * in brute force's order; -1: none), with the world's rows, edits and margin they were made for */
    lc_reach_grid *fat_grid;
    lc_buf fat_boxes, fat_pairs, fat_new, fat_out, fat_rows;
    int fat_count, fat_n;
    double fat_margin, fat_grow;
    unsigned long fat_edits;
};

lc_broad_phase_state *lc_broad_phase_state_create(void)
{
    lc_broad_phase_state *bp = calloc(1, sizeof(lc_broad_phase_state));
    if (bp == NULL) return NULL;
    bp->kept_count = bp->end_rows = bp->fat_count = -1;
    bp->grid = lc_reach_grid_create();
    bp->fat_grid = lc_reach_grid_create();
    bp->grid_pairs = lc_box_pairs_create();
    if (bp->grid == NULL || bp->fat_grid == NULL || bp->grid_pairs == NULL) {
        lc_reach_grid_destroy(bp->grid);
        lc_reach_grid_destroy(bp->fat_grid);
        lc_box_pairs_destroy(bp->grid_pairs);
        free(bp);
        return NULL;
    }
    return bp;
}

void lc_broad_phase_state_destroy(lc_broad_phase_state *bp)
{
    if (bp == NULL) return;
    lc_buf_free(&bp->boxes);
    lc_buf_free(&bp->bounds);
    lc_buf_free(&bp->have);
    lc_buf_free(&bp->marked);
    lc_buf_free(&bp->sweep_order);
    lc_buf_free(&bp->sweep_boxes);
    lc_buf_free(&bp->pair_start);
    lc_buf_free(&bp->pair_tmp);
    lc_buf_free(&bp->reach);
    lc_buf_free(&bp->track_rows);
    lc_buf_free(&bp->box_stamp);
    lc_buf_free(&bp->kept_pairs);
    lc_buf_free(&bp->kept_ref);
    lc_buf_free(&bp->stale);
    lc_buf_free(&bp->moved);
    lc_buf_free(&bp->moved_rows);
    lc_buf_free(&bp->end_boxes);
    lc_buf_free(&bp->end_stamp);
    lc_buf_free(&bp->moved_pairs);
    lc_buf_free(&bp->moved_boxes);
    lc_buf_free(&bp->fat_boxes);
    lc_buf_free(&bp->fat_pairs);
    lc_buf_free(&bp->fat_new);
    lc_buf_free(&bp->fat_out);
    lc_buf_free(&bp->fat_rows);
    lc_reach_grid_destroy(bp->grid);
    lc_reach_grid_destroy(bp->fat_grid);
    lc_box_pairs_destroy(bp->grid_pairs);
    free(bp);
}

static void body_box(const lc_world *w, const double *s, int row, box *b)
{
    const lc_shape *sh = &w->shape[row];
    const double *st = &s[row * 6];
    lc_trig *cache = &w->trig[row];
    double c, sn, *out;
    int i, k;
    /* each pass asks for the boxes at its start state twice (resting set, then the trial) */
    for (k = 0; k < 2; ++k)
        if (memcmp(cache->pose[k], st, 3 * sizeof(double)) == 0) {
            b->x0 = cache->box[k][0]; b->y0 = cache->box[k][1];
            b->x1 = cache->box[k][2]; b->y1 = cache->box[k][3];
            b->row = row;
            return;
        }
    lc_body_trig(w, row, st[SA], &c, &sn);
    b->x0 = b->y0 = INFINITY;
    b->x1 = b->y1 = -INFINITY;
    for (i = 0; i < sh->count; ++i) {
        lc_vec2 p = lc_rot(c, sn, sh->v[i]);
        double x = st[SX] + p.x, y = st[SY] + p.y;
        if (x < b->x0) b->x0 = x;
        if (x > b->x1) b->x1 = x;
        if (y < b->y0) b->y0 = y;
        if (y > b->y1) b->y1 = y;
    }
    b->row = row;
    k = cache->box_next;
    cache->box_next = 1 - k;
    memcpy(cache->pose[k], st, 3 * sizeof(double));
    out = cache->box[k];
    out[0] = b->x0; out[1] = b->y0; out[2] = b->x1; out[3] = b->y1;
}

double lc_bounds_gap(const lc_world *w, const double *state, int a, int b)
{
    box ba, bb;
    double g;
    body_box(w, state, a, &ba);
    body_box(w, state, b, &bb);
    g = fmax(ba.x0 - bb.x1, bb.x0 - ba.x1);
    return fmax(g, fmax(ba.y0 - bb.y1, bb.y0 - ba.y1));
}

static int overlap(const box *a, const box *b)
{
    return a->x0 <= b->x1 && b->x0 <= a->x1 && a->y0 <= b->y1 && b->y0 <= a->y1;
}

static int add_pair(lc_buf *buf, int count, int a, int b)
{
    int *p = lc_buf_get(buf, (size_t)(count + 1) * 2 * sizeof(int));
    if (p == NULL) return -1;
    if (a > b) { int t = a; a = b; b = t; }
    p[2 * count] = a;
    p[2 * count + 1] = b;
    return count + 1;
}

/* A candidate pair when the two boxes overlap and not both bodies are static: count + 1, else count
 * (-1: no memory). */
static int add_if_near(const lc_world *w, lc_buf *buf, int count, const box *x, const box *y)
{
    if (w->is_static[x->row] && w->is_static[y->row]) return count;
    if (w->excluded && (w->excluded[x->row] || w->excluded[y->row])) return count;
    if (!overlap(x, y)) return count;
    return add_pair(buf, count, x->row, y->row);
}

static int cmp_box(const void *x, const void *y)
{
    const box *a = x, *b = y;
    if (a->x0 < b->x0) return -1;
    if (a->x0 > b->x0) return 1;
    return a->row - b->row;   /* ties broken by row: deterministic */
}

/* The boxes in cmp_box order. Bodies move little from one pass to the next, so the last sweep's order
 * is nearly sorted: an insertion sort from it is linear where qsort is n log n (the resting base-20
 * pyramid spent 5 % of its step in the two qsorts). The order is the same whatever the start (cmp_box
 * is a total order on finite boxes, ties by row); a start far from sorted (a reset, bodies added)
 * gives up on the insertion sort after a few moves per box and uses qsort. Returns the sorted array,
 * or NULL without memory. */
static box *sweep_sorted(lc_world *w, const box *by_row, int n)
{
    lc_broad_phase_state *bp = w->broad_phase;
    int *order = lc_buf_get(&bp->sweep_order, (size_t)n * sizeof(int));
    box *b = lc_buf_get(&bp->sweep_boxes, (size_t)n * sizeof(box));
    long moves = 0, limit = 8L * n + 64;
    int i, finite = 1;
    if (order == NULL || b == NULL) return NULL;
    if (bp->sweep_rows != n)
        for (i = 0; i < n; ++i) order[i] = i;
    for (i = 0; i < n; ++i) {
        b[i] = by_row[order[i]];
        if (!(b[i].x0 > -INFINITY && b[i].x0 < INFINITY)) finite = 0;
    }
    /* a non-finite coordinate makes cmp_box no total order: then qsort from row order, as always */
    if (!finite)
        for (i = 0; i < n; ++i) b[i] = by_row[i];
    for (i = 1; i < n && finite && moves <= limit; ++i) {
        box x = b[i];
        int q = i;
        while (q > 0 && cmp_box(&b[q - 1], &x) > 0 && moves <= limit) {
            b[q] = b[q - 1];
            --q;
            ++moves;
        }
        b[q] = x;
    }
    if (!finite || moves > limit) qsort(b, (size_t)n, sizeof(box), cmp_box);
    for (i = 0; i < n; ++i) order[i] = b[i].row;
    bp->sweep_rows = n;
    return b;
}

/* One stable counting-sort pass of the pairs in `from` by their entry `key` (0: a, 1: b) into `to`. */
static void pairs_by(const int *from, int *to, int count, int key, int *start, int n)
{
    int i, k;
    memset(start, 0, (size_t)(n + 1) * sizeof(int));
    for (k = 0; k < count; ++k) start[from[2 * k + key] + 1]++;
    for (i = 0; i < n; ++i) start[i + 1] += start[i];
    for (k = 0; k < count; ++k) {
        int at = start[from[2 * k + key]]++;
        to[2 * at] = from[2 * k];
        to[2 * at + 1] = from[2 * k + 1];
    }
}

/* The pairs in (a, b) order, as brute force finds them: a radix sort, by b and then stably by a, in
 * O(pairs + bodies) (a floor under thousands of boxes is one a with thousands of b's). Returns 0, or
 * -1 without memory. */
static int order_pairs(lc_world *w, int *p, int count)
{
    int *start = lc_buf_get(&w->broad_phase->pair_start, (size_t)(w->count + 1) * sizeof(int));
    int *q = lc_buf_get(&w->broad_phase->pair_tmp, (size_t)count * 2 * sizeof(int));
    if (start == NULL || q == NULL) return -1;
    pairs_by(p, q, count, 1, start, w->count);
    pairs_by(q, p, count, 0, start, w->count);
    return 0;
}

/* Body i's box over the interval (both end poses), grown by margin. */
static void bound_box(const lc_world *w, const double *s0, const double *s1, int i, double margin, box *out);

/* Body i's end poses' boxes, joined and grown by margin. */
static void end_box(lc_world *w, const double *s0, const double *s1, int i, double margin, box *out)
{
    box b0, b1;
    body_box(w, s0, i, &b0);
    if (s1 != s0 && !w->is_static[i]) {
        body_box(w, s1, i, &b1);
        if (b1.x0 < b0.x0) b0.x0 = b1.x0;
        if (b1.y0 < b0.y0) b0.y0 = b1.y0;
        if (b1.x1 > b0.x1) b0.x1 = b1.x1;
        if (b1.y1 > b0.y1) b0.y1 = b1.y1;
    }
    b0.x0 -= margin; b0.y0 -= margin; b0.x1 += margin; b0.y1 += margin;
    *out = b0;
}

/* Where body i can be between s0 and s1: its end poses' boxes, or, turning farther than a
 * rotation-limited interval allows (a free-flight step checks a fast spinner's pairs in parts), its
 * bounding circle's: its corners swing well outside the end boxes between them. */
static void swept_box(lc_world *w, const double *s0, const double *s1, int i, double margin, box *out)
{
    if (s1 != s0 && !w->is_static[i] && fabs(s1[i * 6 + SA] - s0[i * 6 + SA]) > LC_MAX_TRIAL_ROTATION)
        bound_box(w, s0, s1, i, margin, out);
    else
        end_box(w, s0, s1, i, margin, out);
}

/* Every body's swept box, indexed by row. */
static box *swept_boxes(lc_world *w, const double *s0, const double *s1, double margin)
{
    int n = w->count, i;
    box *boxes = lc_buf_get(&w->broad_phase->boxes, (size_t)(n > 0 ? n : 1) * sizeof(box));
    if (boxes == NULL) return NULL;
    for (i = 0; i < n; ++i) swept_box(w, s0, s1, i, margin, &boxes[i]);
    return boxes;
}

/* A box that holds body i's swept box, from its centres alone: every vertex lies within the bounding
 * radius of the centre at both end poses, so the swept box is inside the centres' box grown by that
 * radius and the margin (and a relative 1e-9 for round-off in the exact box). No cosine or sine. */
static void bound_box(const lc_world *w, const double *s0, const double *s1, int i, double margin, box *out)
{
    const double *p = &s0[i * 6], *q = (s1 != s0 && !w->is_static[i]) ? &s1[i * 6] : p;
    double x0 = p[SX] < q[SX] ? p[SX] : q[SX], x1 = p[SX] < q[SX] ? q[SX] : p[SX];
    double y0 = p[SY] < q[SY] ? p[SY] : q[SY], y1 = p[SY] < q[SY] ? q[SY] : p[SY];
    double r = w->shape[i].radius + margin;
    r += 1e-9 * (r + fabs(x0) + fabs(x1) + fabs(y0) + fabs(y1));
    out->x0 = x0 - r;
    out->x1 = x1 + r;
    out->y0 = y0 - r;
    out->y1 = y1 + r;
    out->row = i;
}

/* lc_box_pairs_find's keep: an overlapping pair of boxes is a candidate unless both bodies are static
 * or one is excluded (add_if_near's rules). */
typedef struct grid_keep { lc_world *w; lc_buf *buf; int count; } grid_keep;

static int keep_grid_pair(void *ctx, int a, int b)
{
    grid_keep *k = ctx;
    const lc_world *w = k->w;
    if (w->is_static[a] && w->is_static[b]) return 0;
    if (w->excluded && (w->excluded[a] || w->excluded[b])) return 0;
    k->count = add_pair(k->buf, k->count, a, b);
    return k->count < 0 ? -1 : 0;
}

/* The broadphase a search of n bodies uses. */
static lc_broadphase choose(const lc_world *w, int n)
{
    if (w->def.broadphase != LC_BROADPHASE_AUTO) return w->def.broadphase;
    if (n < w->def.broadphase_threshold) return LC_BROADPHASE_BRUTE_FORCE;
    return n < LC_GRID_MIN_ROWS ? LC_BROADPHASE_SORT_AND_SWEEP : LC_BROADPHASE_GRID;
}

/* The candidate pairs of boxes[0..count) (indexed by row). */
static int pairs_of(lc_world *w, box *boxes, lc_buf *buf)
{
    int n = w->count, i, j, count = 0;
    lc_broadphase mode = choose(w, n);
    if (mode == LC_BROADPHASE_GRID) {
        grid_keep k;
        k.w = w;
        k.buf = buf;
        k.count = 0;
        w->last.grid_steps++;
        if (lc_box_pairs_find(w->broad_phase->grid_pairs, boxes, sizeof(box), n, keep_grid_pair, &k) != 0) return -1;
        count = k.count;
        /* same pair order as brute force, so results do not depend on the broadphase */
        if (count > 1 && order_pairs(w, (int *)buf->p, count) != 0) return -1;
    } else if (mode != LC_BROADPHASE_SORT_AND_SWEEP) {
        w->last.brute_force_steps++;
        for (i = 0; i < n; ++i)
            for (j = i + 1; j < n; ++j)
                if ((count = add_if_near(w, buf, count, &boxes[i], &boxes[j])) < 0) return -1;
    } else {
        box *sorted = sweep_sorted(w, boxes, n);
        if (sorted == NULL) return -1;
        w->last.sort_and_sweep_steps++;
        for (i = 0; i < n; ++i)
            for (j = i + 1; j < n && sorted[j].x0 <= sorted[i].x1; ++j) {
                /* most boxes in the x band lie above or below (a wide world holds ~sqrt(n) in a band) */
                if (sorted[j].y0 > sorted[i].y1 || sorted[i].y0 > sorted[j].y1) continue;
                if ((count = add_if_near(w, buf, count, &sorted[i], &sorted[j])) < 0) return -1;
            }
        /* same pair order as brute force, so results do not depend on the broadphase */
        if (count > 1 && order_pairs(w, (int *)buf->p, count) != 0) return -1;
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}

static int cmp_pair(const void *x, const void *y)
{
    const int *a = x, *b = y;
    if (a[0] != b[0]) return (a[0] > b[0]) - (a[0] < b[0]);
    return (a[1] > b[1]) - (a[1] < b[1]);
}

/* The search over s0 -> s1 (s1 != s0) that found `count` pairs in buf, kept for pairs_from_kept. */
static void keep_search(lc_world *w, const double *s0, const double *s1, double margin, const lc_buf *buf, int count)
{
    lc_broad_phase_state *bp = w->broad_phase;
    int n = w->count, i;
    int *p = lc_buf_get(&bp->kept_pairs, (size_t)(count > 0 ? count : 1) * 2 * sizeof(int));
    double *ref = lc_buf_get(&bp->kept_ref, (size_t)(n > 0 ? n : 1) * 6 * sizeof(double));
    bp->kept_count = -1;
    bp->track_kept = 0;
    /* nothing kept without memory (the next search looks at every box), nor from a search that left
     * rows out: a later one may take them */
    if (p == NULL || ref == NULL || w->excluded != NULL) return;
    if (count > 0) memcpy(p, buf->p, (size_t)count * 2 * sizeof(int));
    memcpy(ref, s1, (size_t)n * 6 * sizeof(double));
    for (i = 0; i < n; ++i)
        if (w->is_static[i]) memcpy(&ref[i * 6], &s0[i * 6], 6 * sizeof(double));
    bp->kept_count = count;
    bp->kept_rows = n;
    bp->kept_margin = margin;
    bp->kept_edits = w->edits;
}

static int same_row(const double *a, const double *b) { return memcmp(a, b, 6 * sizeof(double)) == 0; }

static int pair_after(const int *x, const int *y) { return x[0] > y[0] || (x[0] == y[0] && x[1] > y[1]); }

/* Row r's box at state s (margin grown), computed once per pairs_from_kept. */
static const box *end_box_of(lc_world *w, const double *s, int r, double margin)
{
    lc_broad_phase_state *bp = w->broad_phase;
    box *b = &((box *)bp->end_boxes.p)[r];
    unsigned *stamp = (unsigned *)bp->end_stamp.p;
    if (stamp[r] != bp->end_now) {
        swept_box(w, s, s, r, margin, b);
        stamp[r] = bp->end_now;
    }
    return b;
}

/* The whole-world pairs at state s from the kept search over an interval, without a search of every
 * box: the same pairs in the same order as pairs_of(swept_boxes(s, s)), or -2 when they cannot be had
 * this way (then the caller searches), -1 without memory.
 * A row at its kept state has its box inside its box of the kept search (its box over the interval
 * holds its box at the interval's end, the same bits from the same state), so two such rows whose boxes
 * meet were a kept pair: those pairs are the kept ones whose boxes at s still meet, in the kept order.
 * A row not at its kept state (an impact moved it) meets one at it only where that one's reach in the
 * tracked grid is, which holds its box at the kept state: the moved rows' pairs come from the grid and
 * from each other, sorted and merged in. Without the grid they need the whole search, as do many of
 * them (past a quarter of the rows the search costs less). */
static int pairs_from_kept(lc_world *w, const double *s, double margin, lc_buf *buf)
{
    lc_broad_phase_state *bp = w->broad_phase;
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
        int use_stale = bp->tracked && bp->track_kept;
        for (i = 0; i < n; ++i) {
            moved[i] = !same_row(&s[i * 6], &ref[i * 6]) || (use_stale && stale[i]);
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
        if (moved[a] || moved[b] || !overlap(end_box_of(w, s, a, margin), end_box_of(w, s, b, margin))) continue;
        out[2 * count] = a;
        out[2 * count + 1] = b;
        count++;
    }
    /* the pairs with a moved row (add_if_near's rules: excluded is NULL here) */
    for (k = 0; k < m; ++k) {
        int a = mrows[k], nnear;
        const int *near;
        const box *ba = end_box_of(w, s, a, margin);
        double qb[4];
        qb[0] = ba->x0;
        qb[1] = ba->y0;
        qb[2] = ba->x1;
        qb[3] = ba->y1;
        nnear = lc_reach_grid_query(bp->grid, qb, &near);
        if (nnear < 0) return -1;
        for (q = 0; q < nnear; ++q) {
            int b = near[q];
            if (moved[b] || (w->is_static[a] && w->is_static[b])) continue;   /* moved pairs: below */
            if (!overlap(ba, end_box_of(w, s, b, margin))) continue;
            if ((nm = add_pair(&bp->moved_pairs, nm, a, b)) < 0) return -1;
        }
    }
    /* the moved rows among themselves: a sweep along x over their boxes (every impact of a step adds
     * moved rows, and testing each against each grew as the square of the world's size) */
    if (m > 1) {
        box *mb = lc_buf_get(&bp->moved_boxes, (size_t)m * sizeof(box));
        if (mb == NULL) return -1;
        for (k = 0; k < m; ++k) {
            mb[k] = *end_box_of(w, s, mrows[k], margin);
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
        int j, t;
        mp = (int *)bp->moved_pairs.p;
        if (nm > 1) qsort(mp, (size_t)nm, 2 * sizeof(int), cmp_pair);
        out = lc_buf_get(buf, (size_t)(count + nm) * 2 * sizeof(int));
        if (out == NULL) return -1;
        /* merged from the back: the two lists are sorted and share no pair */
        i = count - 1;
        j = nm - 1;
        for (t = count + nm - 1; j >= 0; --t) {
            if (i >= 0 && pair_after(&out[2 * i], &mp[2 * j])) {
                out[2 * t] = out[2 * i];
                out[2 * t + 1] = out[2 * i + 1];
                --i;
            } else {
                out[2 * t] = mp[2 * j];
                out[2 * t + 1] = mp[2 * j + 1];
                --j;
            }
        }
        count += nm;
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}

static int finite_box(const box *b)
{
    return b->x0 > -INFINITY && b->x1 < INFINITY && b->y0 > -INFINITY && b->y1 < INFINITY && b->x0 <= b->x1 &&
           b->y0 <= b->y1;
}

/* A box's fat box: grown by grow. */
static void fat_of(const box *b, double grow, double f[4])
{
    f[0] = b->x0 - grow;
    f[1] = b->y0 - grow;
    f[2] = b->x1 + grow;
    f[3] = b->y1 + grow;
}

/* The fat pairs made anew: every row's fat box from its box, in the fat grid, and the pairs whose fat
 * boxes overlap from the grid search (box_pairs.c), in brute force's order. 0, -1 without memory, -2
 * for a box the grid cannot hold (then the caller searches the boxes themselves). */
static int fat_build(lc_world *w, const box *boxes, double margin)
{
    lc_broad_phase_state *bp = w->broad_phase;
    int n = w->count, i;
    double *fat = lc_buf_get(&bp->fat_boxes, (size_t)(n > 0 ? n : 1) * 4 * sizeof(double));
    int *rows = lc_buf_get(&bp->fat_rows, (size_t)(n > 0 ? n : 1) * sizeof(int));
    double ext = 0.0;
    grid_keep k;
    bp->fat_count = -1;
    if (fat == NULL || rows == NULL) return -1;
    for (i = 0; i < n; ++i) {
        if (!finite_box(&boxes[i])) return -2;
        ext += fmax(boxes[i].x1 - boxes[i].x0, boxes[i].y1 - boxes[i].y0);
    }
    bp->fat_grow = n > 0 ? LC_FAT_GROW * ext / n : 0.0;
    for (i = 0; i < n; ++i) {
        fat_of(&boxes[i], bp->fat_grow, &fat[4 * i]);
        rows[i] = i;
        /* a box far out (beyond what a double's sum keeps finite) is searched as it is */
        if (!(fat[4 * i] > -INFINITY && fat[4 * i + 2] < INFINITY && fat[4 * i + 1] > -INFINITY && fat[4 * i + 3] < INFINITY))
            return -2;
    }
    if (lc_reach_grid_build(bp->fat_grid, fat, rows, n, n) != 0) return -1;
    k.w = w;
    k.buf = &bp->fat_pairs;
    k.count = 0;
    if (lc_box_pairs_find(bp->grid_pairs, fat, 4 * sizeof(double), n, keep_grid_pair, &k) != 0) return -1;
    if (k.count > 1 && order_pairs(w, (int *)bp->fat_pairs.p, k.count) != 0) return -1;
    bp->fat_count = k.count;
    bp->fat_n = n;
    bp->fat_margin = margin;
    bp->fat_edits = w->edits;
    return 0;
}

/* The grid's search of boxes[0..n) over an interval (pairs_of's, the same pairs in the same order),
 * from fat boxes kept between searches: a row's box that left its fat box gets a new one (its box grown
 * by a share of the mean extent), moved in the fat grid, and the fat pairs of those rows are found
 * anew there; the pairs are then the fat pairs whose boxes overlap (every box lies in its fat box, so
 * two boxes that meet have fat boxes that meet). Bodies move a little per step and most keep their fat
 * boxes for several steps: the search costs a test per row and per fat pair, not a build of the grid.
 * -1 without memory; -2 where it does not apply (then the caller searches). */
static int pairs_of_fat(lc_world *w, const box *boxes, double margin, lc_buf *buf)
{
    lc_broad_phase_state *bp = w->broad_phase;
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
        r = fat_build(w, boxes, margin);
        if (r != 0) return r;
        m = 0;
    }
    fat = (double *)bp->fat_boxes.p;
    if (m > 0) {
        int nf = 0, j, t;
        /* the moved rows' new fat boxes, in the grid */
        for (k = 0; k < m; ++k) {
            double *f = &fat[4 * moved_rows[k]];
            fat_of(&boxes[moved_rows[k]], bp->fat_grow, f);
            if (!(f[0] > -INFINITY && f[2] < INFINITY && f[1] > -INFINITY && f[3] < INFINITY)) {
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
        i = nf - 1;
        j = nn - 1;
        for (t = nf + nn - 1; j >= 0; --t) {
            const int *np = (const int *)bp->fat_new.p;
            if (i >= 0 && pair_after(&fp[2 * i], &np[2 * j])) {
                fp[2 * t] = fp[2 * i];
                fp[2 * t + 1] = fp[2 * i + 1];
                --i;
            } else {
                fp[2 * t] = np[2 * j];
                fp[2 * t + 1] = np[2 * j + 1];
                --j;
            }
        }
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

int lc_broad_phase(lc_world *w, const double *s0, const double *s1, double margin, lc_buf *buf)
{
    box *boxes;
    int count;
    if (s1 == s0) {
        count = pairs_from_kept(w, s0, margin, buf);
        if (count != -2) return count;
    }
    boxes = swept_boxes(w, s0, s1, margin);
    if (boxes == NULL) return -1;
    count = -2;
    if (s1 != s0 && choose(w, w->count) == LC_BROADPHASE_GRID) count = pairs_of_fat(w, boxes, margin, buf);
    if (count == -2) count = pairs_of(w, boxes, buf);
    if (count >= 0 && s1 != s0) keep_search(w, s0, s1, margin, buf, count);
    return count;
}

static void box_out(const box *b, double out[4])
{
    out[0] = b->x0;
    out[1] = b->y0;
    out[2] = b->x1;
    out[3] = b->y1;
}

void lc_swept_box(lc_world *w, const double *s0, const double *s1, int row, double margin, double out[4])
{
    box b;
    swept_box(w, s0, s1, row, margin, &b);
    box_out(&b, out);
}

void lc_end_poses_box(lc_world *w, const double *s0, const double *s1, int row, double margin, double out[4])
{
    box b;
    end_box(w, s0, s1, row, margin, &b);
    box_out(&b, out);
}

int lc_broad_phase_boxes(lc_world *w, const double *boxes4, lc_buf *buf)
{
    int n = w->count, i;
    box *boxes = lc_buf_get(&w->broad_phase->boxes, (size_t)(n > 0 ? n : 1) * sizeof(box));
    if (boxes == NULL) return -1;
    for (i = 0; i < n; ++i) {
        boxes[i].x0 = boxes4[4 * i];
        boxes[i].y0 = boxes4[4 * i + 1];
        boxes[i].x1 = boxes4[4 * i + 2];
        boxes[i].y1 = boxes4[4 * i + 3];
        boxes[i].row = i;
    }
    return pairs_of(w, boxes, buf);
}

/* Where body i can be while it moves from s0 to s1 over h under constant accelerations: its centres'
 * box grown by its bounding radius, the margin and the most a parabola strays from its chord
 * (|a| h^2 / 8), with bound_box's relative allowance for round-off; a static body's own box. */
static void reach_box(lc_world *w, const double *s0, const double *s1, double h, int i, double margin, double out[4])
{
    box b;
    if (w->is_static[i]) {
        swept_box(w, s0, s0, i, margin, &b);
    } else {
        double ax = w->def.gravity.x + w->ext_force[i].x * w->inv_mass[i];
        double ay = w->def.gravity.y + w->ext_force[i].y * w->inv_mass[i];
        bound_box(w, s0, s1, i, margin + sqrt(ax * ax + ay * ay) * h * h / 8.0, &b);
        /* bound_box's allowance is relative to its radius: grow by the same share of the stray */
        b.x0 -= 1e-9 * (fabs(b.x0) + 1.0);
        b.y0 -= 1e-9 * (fabs(b.y0) + 1.0);
        b.x1 += 1e-9 * (fabs(b.x1) + 1.0);
        b.y1 += 1e-9 * (fabs(b.y1) + 1.0);
    }
    out[0] = b.x0;
    out[1] = b.y0;
    out[2] = b.x1;
    out[3] = b.y1;
}

int lc_broad_phase_track(lc_world *w, const double *s0, const double *s1, double h, const int *rows, int nrows,
                         double margin)
{
    lc_broad_phase_state *bp = w->broad_phase;
    double *reach = lc_buf_get(&bp->reach, (size_t)(w->count > 0 ? w->count : 1) * 4 * sizeof(double));
    int *all = lc_buf_get(&bp->track_rows, (size_t)(w->count > 0 ? w->count : 1) * sizeof(int));
    int i, n = 0;
    bp->tracked = 0;
    if (reach == NULL || all == NULL) return -1;
    /* the rows and every static body, in row order */
    for (i = 0; i < w->count; ++i)
        if (w->is_static[i]) all[n++] = i;
    for (i = 0; i < nrows; ++i) all[n++] = rows[i];
    for (i = 0; i < n; ++i) reach_box(w, s0, s1, h, all[i], margin, &reach[4 * all[i]]);
    if (lc_reach_grid_build(bp->grid, reach, all, n, w->count) != 0) return -1;
    bp->tracked = 1;
    /* a row's reach holds its box at s1 (a static body's at s0): where that is its kept state, the
     * grid finds it for pairs_from_kept */
    bp->track_kept = 0;
    if (bp->kept_count >= 0 && bp->kept_rows == w->count && bp->kept_margin == margin && bp->kept_edits == w->edits &&
        n == w->count) {
        uint8_t *stale = lc_buf_get(&bp->stale, (size_t)(w->count > 0 ? w->count : 1));
        const double *ref = (const double *)bp->kept_ref.p;
        if (stale != NULL) {
            for (i = 0; i < w->count; ++i) stale[i] = !same_row(w->is_static[i] ? &s0[i * 6] : &s1[i * 6], &ref[i * 6]);
            bp->track_kept = 1;
        }
    }
    return 0;
}

int lc_broad_phase_retrack(lc_world *w, const double *s0, const double *s1, double h, const int *rows, int nrows,
                           double margin)
{
    lc_broad_phase_state *bp = w->broad_phase;
    int k;
    if (!bp->tracked) return 0;
    for (k = 0; k < nrows; ++k) {
        double r[4];
        if (bp->track_kept) ((uint8_t *)bp->stale.p)[rows[k]] = 1;   /* its reach is its new path's */
        reach_box(w, s0, s1, h, rows[k], margin, r);
        if (lc_reach_grid_move(bp->grid, rows[k], r) != 0) {
            bp->tracked = 0;
            return -1;
        }
    }
    return 0;
}

void lc_broad_phase_untrack(lc_world *w) { w->broad_phase->tracked = 0; }

int lc_broad_phase_near(lc_world *w, const double box4[4], const int **out)
{
    if (!w->broad_phase->tracked) return -2;
    return lc_reach_grid_query(w->broad_phase->grid, box4, out);
}

/* lc_broad_phase_of from the tracked reach: each listed row's partners are the bodies whose reach its
 * box meets (a body's box over the interval lies in its reach), then the same box test; the pairs in
 * brute force's order. */
static int pairs_of_tracked(lc_world *w, const double *s0, const double *s1, double margin, const uint8_t *marked,
                            const int *list, int nlist, lc_buf *buf)
{
    lc_broad_phase_state *bp = w->broad_phase;
    int n = w->count, k, q, count = 0;
    box *boxes = lc_buf_get(&bp->boxes, (size_t)(n > 0 ? n : 1) * sizeof(box));
    unsigned *have = lc_buf_get(&bp->box_stamp, (size_t)(n > 0 ? n : 1) * sizeof(unsigned));
    if (boxes == NULL || have == NULL) return -1;
    if (bp->stamp_now == 0 || ++bp->stamp_now == 0) {   /* first use, or wrapped */
        memset(have, 0, (size_t)(n > 0 ? n : 1) * sizeof(unsigned));
        bp->stamp_now = 1;
    }
    for (k = 0; k < nlist; ++k) {
        swept_box(w, s0, s1, list[k], margin, &boxes[list[k]]);
        have[list[k]] = bp->stamp_now;
    }
    for (k = 0; k < nlist; ++k) {
        const int *near;
        double qb[4];
        int a = list[k], m;
        qb[0] = boxes[a].x0;
        qb[1] = boxes[a].y0;
        qb[2] = boxes[a].x1;
        qb[3] = boxes[a].y1;
        m = lc_reach_grid_query(bp->grid, qb, &near);
        if (m < 0) return -1;
        for (q = 0; q < m; ++q) {
            int b = near[q];
            if (b == a || marked[b]) continue;   /* two listed rows: below */
            if (have[b] != bp->stamp_now) {
                swept_box(w, s0, s1, b, margin, &boxes[b]);
                have[b] = bp->stamp_now;
            }
            if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[b])) < 0) return -1;
        }
        for (q = k + 1; q < nlist; ++q)
            if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[list[q]])) < 0) return -1;
    }
    if (count > 1) qsort(buf->p, (size_t)count, 2 * sizeof(int), cmp_pair);
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}

int lc_broad_phase_of(lc_world *w, const double *s0, const double *s1, double margin, const uint8_t *marked,
                      const int *list, int nlist, lc_buf *buf)
{
    int n = w->count, a, b, k, first = 0, count = 0;
    lc_broad_phase_state *bp = w->broad_phase;
    box *boxes = lc_buf_get(&bp->boxes, (size_t)(n > 0 ? n : 1) * sizeof(box));
    box *bounds = lc_buf_get(&bp->bounds, (size_t)(n > 0 ? n : 1) * sizeof(box));
    uint8_t *have = lc_buf_get(&bp->have, (size_t)(n > 0 ? n : 1));
    int *sorted = lc_buf_get(&bp->marked, (size_t)(nlist > 0 ? nlist : 1) * sizeof(int));
    if (boxes == NULL || bounds == NULL || have == NULL || sorted == NULL) return -1;
    if (bp->tracked) return pairs_of_tracked(w, s0, s1, margin, marked, list, nlist, buf);
    /* The listed rows' boxes now; another body's only when it could be near one of them. After an
     * impact every body has moved to the impact's time, and computing all their boxes again (a
     * cosine and sine each) was a third of a 2000-body free-flight step's time, at each impact. The
     * pairs are the same as with every box computed. */
    memset(have, 0, (size_t)n);
    for (a = 0; a < n; ++a) bound_box(w, s0, s1, a, margin, &bounds[a]);
    for (k = 0; k < nlist; ++k) {
        swept_box(w, s0, s1, list[k], margin, &boxes[list[k]]);
        have[list[k]] = 1;
    }
    /* the listed rows in row order (list is in the order the impact found them; a few rows, so an
     * insertion sort), so the pairs come out in brute force's order (a, then b) without sorting them */
    for (k = 0; k < nlist; ++k) {
        int r = list[k], q = k;
        while (q > 0 && sorted[q - 1] > r) { sorted[q] = sorted[q - 1]; --q; }
        sorted[q] = r;
    }
    /* neither brute force nor sort-and-sweep over the world: not counted as either */
    for (a = 0; a < n; ++a) {
        if (marked[a]) {
            for (b = a + 1; b < n; ++b) {
                if (!have[b]) {
                    if (!overlap(&bounds[b], &boxes[a])) continue;
                    swept_box(w, s0, s1, b, margin, &boxes[b]);
                    have[b] = 1;
                }
                if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[b])) < 0) return -1;
            }
        } else {
            while (first < nlist && sorted[first] <= a) ++first;
            for (k = first; k < nlist; ++k) {
                if (!have[a]) {
                    if (!overlap(&bounds[a], &boxes[sorted[k]])) continue;
                    swept_box(w, s0, s1, a, margin, &boxes[a]);
                    have[a] = 1;
                }
                if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[sorted[k]])) < 0) return -1;
            }
        }
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}
