/* Broad phase: candidate body pairs from swept bounding boxes. Brute force for a few bodies,
 * sort-and-sweep along x from broadphase_threshold, pairs from a uniform grid (box_pairs.c) from
 * LC_GRID_MIN_ROWS (AUTO), over an interval from fat boxes the grid keeps between searches
 * (broad_phase_fat.c); all find the same pairs in the same order. A search at one state takes the
 * last interval search's pairs where it can (broad_phase_kept.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "broad_phase_internal.h"
#include "tunables.h"

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
    lc_bp_kept *kept;              /* the last interval search, for the searches at one state */
    lc_bp_fat *fat;                /* the grid's fat boxes, for the searches over an interval */
};

lc_broad_phase_state *lc_broad_phase_state_create(void)
{
    lc_broad_phase_state *bp = calloc(1, sizeof(lc_broad_phase_state));
    if (bp == NULL) return NULL;
    bp->grid = lc_reach_grid_create();
    bp->grid_pairs = lc_box_pairs_create();
    bp->kept = lc_bp_kept_create();
    bp->fat = lc_bp_fat_create();
    if (bp->grid == NULL || bp->grid_pairs == NULL || bp->kept == NULL || bp->fat == NULL) {
        lc_broad_phase_state_destroy(bp);
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
    lc_reach_grid_destroy(bp->grid);
    lc_box_pairs_destroy(bp->grid_pairs);
    lc_bp_kept_destroy(bp->kept);
    lc_bp_fat_destroy(bp->fat);
    free(bp);
}

/* The box about the centre of mass of the body's vertices turned as the entry's angle says, into
 * the entry. */
static void shape_extent(const lc_outline *o, lc_trig_entry *e)
{
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    int i;
    for (i = 0; i < o->count; ++i) {
        lc_vec2 p = lc_rot(e->c, e->s, o->v[i]);
        if (p.x < x0) x0 = p.x;
        if (p.x > x1) x1 = p.x;
        if (p.y < y0) y0 = p.y;
        if (p.y > y1) y1 = p.y;
    }
    e->ext[0] = x0;
    e->ext[1] = y0;
    e->ext[2] = x1;
    e->ext[3] = y1;
}

/* Body row's box at state s: its centre plus the turned vertices' box, kept with the angle's trig (a
 * step asks for each body's box at the same few angles many times). Rounding is monotone, so the
 * least of x + p over the vertices p is x + the least p: the same bits as the box of the vertices
 * placed one by one. */
static void body_box(const lc_world *w, const double *s, int row, box *b)
{
    const double *st = &s[row * 6];
    lc_trig_entry *e = lc_body_trig_entry(w, row, st[SA]);
    if (isnan(e->ext[0])) shape_extent(&w->outline[row], e);
    b->x0 = st[SX] + e->ext[0];
    b->y0 = st[SY] + e->ext[1];
    b->x1 = st[SX] + e->ext[2];
    b->y1 = st[SY] + e->ext[3];
    b->row = row;
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

/* A candidate pair when the two boxes overlap and not both bodies are static: count + 1, else count
 * (-1: no memory). */
static int add_if_near(const lc_world *w, lc_buf *buf, int count, const box *x, const box *y)
{
    if (w->is_static[x->row] && w->is_static[y->row]) return count;
    if (w->excluded && (w->excluded[x->row] || w->excluded[y->row])) return count;
    if (!overlap(x, y)) return count;
    return add_pair(buf, count, x->row, y->row);
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
int lc_bp_order_pairs(lc_world *w, int *p, int count)
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
void lc_bp_swept_box(lc_world *w, const double *s0, const double *s1, int i, double margin, box *out)
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
    for (i = 0; i < n; ++i) lc_bp_swept_box(w, s0, s1, i, margin, &boxes[i]);
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
    double r = w->radius[i] + margin;
    r += 1e-9 * (r + fabs(x0) + fabs(x1) + fabs(y0) + fabs(y1));
    out->x0 = x0 - r;
    out->x1 = x1 + r;
    out->y0 = y0 - r;
    out->y1 = y1 + r;
    out->row = i;
}

/* lc_box_pairs_find's keep: an overlapping pair of boxes is a candidate unless both bodies are static
 * or one is excluded (add_if_near's rules). */
int lc_bp_keep_grid_pair(void *ctx, int a, int b)
{
    lc_bp_grid_keep *k = ctx;
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
        lc_bp_grid_keep k;
        k.w = w;
        k.buf = buf;
        k.count = 0;
        w->last.grid_steps++;
        if (lc_box_pairs_find(w->broad_phase->grid_pairs, boxes, sizeof(box), n, lc_bp_keep_grid_pair, &k) != 0)
            return -1;
        count = k.count;
        /* same pair order as brute force, so results do not depend on the broadphase */
        if (count > 1 && lc_bp_order_pairs(w, (int *)buf->p, count) != 0) return -1;
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
        if (count > 1 && lc_bp_order_pairs(w, (int *)buf->p, count) != 0) return -1;
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}

int lc_broad_phase(lc_world *w, const double *s0, const double *s1, double margin, lc_buf *buf)
{
    lc_broad_phase_state *bp = w->broad_phase;
    box *boxes;
    int count;
    if (s1 == s0) {
        count = lc_bp_pairs_from_kept(bp->kept, w, bp->tracked ? bp->grid : NULL, s0, margin, buf);
        if (count != -2) return count;
    }
    boxes = swept_boxes(w, s0, s1, margin);
    if (boxes == NULL) return -1;
    count = -2;
    if (s1 != s0 && choose(w, w->count) == LC_BROADPHASE_GRID)
        count = lc_bp_pairs_of_fat(bp->fat, w, bp->grid_pairs, boxes, margin, buf);
    if (count == -2) count = pairs_of(w, boxes, buf);
    if (count >= 0 && s1 != s0) lc_bp_keep_search(bp->kept, w, s0, s1, margin, buf, count);
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
    lc_bp_swept_box(w, s0, s1, row, margin, &b);
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
        lc_bp_swept_box(w, s0, s0, i, margin, &b);
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
    lc_bp_kept_track(bp->kept, w, s0, s1, margin, n == w->count);
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
        lc_bp_kept_retracked(bp->kept, rows[k]);
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
        lc_bp_swept_box(w, s0, s1, list[k], margin, &boxes[list[k]]);
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
                lc_bp_swept_box(w, s0, s1, b, margin, &boxes[b]);
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
        lc_bp_swept_box(w, s0, s1, list[k], margin, &boxes[list[k]]);
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
                    lc_bp_swept_box(w, s0, s1, b, margin, &boxes[b]);
                    have[b] = 1;
                }
                if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[b])) < 0) return -1;
            }
        } else {
            while (first < nlist && sorted[first] <= a) ++first;
            for (k = first; k < nlist; ++k) {
                if (!have[a]) {
                    if (!overlap(&bounds[a], &boxes[sorted[k]])) continue;
                    lc_bp_swept_box(w, s0, s1, a, margin, &boxes[a]);
                    have[a] = 1;
                }
                if ((count = add_if_near(w, buf, count, &boxes[a], &boxes[sorted[k]])) < 0) return -1;
            }
        }
    }
    w->last.broadphase_pairs += (uint64_t)count;
    return count;
}
