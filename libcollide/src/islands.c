/* Islands (see islands.h): a swept broadphase over the step's predicted motion, then union-find over
 * the pairs of dynamic bodies and the springs between bodies. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "islands.h"
#include "tunables.h"
#include "world.h"

struct lc_islands {
    int count;
    lc_buf b_pred;        /* predicted end state, count x 6 */
    lc_buf b_acc;         /* applied accelerations, count x 3 */
    lc_buf b_all;         /* every row (the accelerations' list) */
    lc_buf b_pairs;       /* the broadphase's pairs, then grouped by island */
    lc_buf b_grouped;     /* pairs grouped by island */
    lc_buf b_of;          /* island of each row */
    lc_buf b_parent;      /* union-find */
    lc_buf b_rows;        /* rows grouped by island */
    lc_buf b_row_start;   /* count + 1 */
    lc_buf b_pair_start;  /* count + 1 */
    lc_buf b_boxes;       /* swept boxes, 4 per row */
    lc_buf b_set;         /* hash set of the pairs */
    lc_buf b_reach_boxes; /* lc_islands_unforeseen: the actual paths' boxes, and their pairs */
    lc_buf b_reach_pairs;
    int set_size;
};

lc_islands *lc_islands_create(void) { return calloc(1, sizeof(lc_islands)); }

void lc_islands_destroy(lc_islands *is)
{
    if (is == NULL) return;
    lc_buf_free(&is->b_pred);
    lc_buf_free(&is->b_acc);
    lc_buf_free(&is->b_all);
    lc_buf_free(&is->b_pairs);
    lc_buf_free(&is->b_grouped);
    lc_buf_free(&is->b_of);
    lc_buf_free(&is->b_parent);
    lc_buf_free(&is->b_rows);
    lc_buf_free(&is->b_row_start);
    lc_buf_free(&is->b_pair_start);
    lc_buf_free(&is->b_boxes);
    lc_buf_free(&is->b_set);
    lc_buf_free(&is->b_reach_boxes);
    lc_buf_free(&is->b_reach_pairs);
    free(is);
}

static int root(int *parent, int x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static void join(int *parent, int a, int b)
{
    int ra = root(parent, a), rb = root(parent, b);
    if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
}

/* Where each dynamic, awake body would be after dt under its applied accelerations held constant. */
static int predict(lc_world *w, lc_islands *is, double dt, const uint8_t *frozen, double **out)
{
    int n = w->count, i, k, *all;
    double *pred = lc_buf_get(&is->b_pred, (size_t)n * 6 * sizeof(double));
    double *acc = lc_buf_get(&is->b_acc, (size_t)n * 3 * sizeof(double));
    all = lc_buf_get(&is->b_all, (size_t)n * sizeof(int));
    if (!pred || !acc || !all) return -1;
    for (i = 0; i < n; ++i) all[i] = i;
    if (lc_applied_accelerations(w, w->state, all, n, acc) != 0) return -1;
    memcpy(pred, w->state, (size_t)n * 6 * sizeof(double));
    for (i = 0; i < n; ++i) {
        const double *s = &w->state[i * 6];
        double *p = &pred[i * 6];
        if (w->is_static[i] || (frozen && frozen[i])) continue;
        for (k = 0; k < 3; ++k) {
            p[k] = s[k] + dt * s[3 + k] + 0.5 * dt * dt * acc[i * 3 + k];
            p[3 + k] = s[3 + k] + dt * acc[i * 3 + k];
        }
    }
    *out = pred;
    return 0;
}

static uint32_t pair_hash(int a, int b) { return ((uint32_t)a * 2654435761u) ^ ((uint32_t)b * 40503u); }

/* The pairs in a hash set (open addressing, pairs of rows packed as a * count + b). */
static int index_pairs(lc_islands *is, const int *pairs, int np)
{
    int size = 1, k;
    int *set;
    while (size < 2 * np) size *= 2;
    set = lc_buf_get(&is->b_set, (size_t)size * 2 * sizeof(int));
    if (set == NULL) return -1;
    for (k = 0; k < 2 * size; ++k) set[k] = -1;
    for (k = 0; k < np; ++k) {
        uint32_t h = pair_hash(pairs[2 * k], pairs[2 * k + 1]) & (uint32_t)(size - 1);
        while (set[2 * h] >= 0) h = (h + 1) & (uint32_t)(size - 1);
        set[2 * h] = pairs[2 * k];
        set[2 * h + 1] = pairs[2 * k + 1];
    }
    is->set_size = size;
    return 0;
}

int lc_islands_has_pair(const lc_islands *is, int a, int b)
{
    const int *set = (const int *)is->b_set.p;
    uint32_t h;
    if (is->set_size == 0) return 0;
    h = pair_hash(a, b) & (uint32_t)(is->set_size - 1);
    while (set[2 * h] >= 0) {
        if (set[2 * h] == a && set[2 * h + 1] == b) return 1;
        h = (h + 1) & (uint32_t)(is->set_size - 1);
    }
    return 0;
}

int lc_islands_build(lc_world *w, lc_islands *is, double dt, const uint8_t *frozen, const double *reach)
{
    int n = w->count, np, i, k, *parent, *of, *rows, *row_start, *pair_start, *grouped, *cursor;
    const int *pairs;
    double *pred, *boxes;
    is->count = 0;
    is->set_size = 0;
    if (n == 0) return 0;
    if (predict(w, is, dt, frozen, &pred) != 0) return -1;
    boxes = lc_buf_get(&is->b_boxes, (size_t)n * 4 * sizeof(double));
    if (boxes == NULL) return -1;
    for (i = 0; i < n; ++i) {
        double *b = &boxes[4 * i], turn = fabs(pred[i * 6 + SA] - w->state[i * 6 + SA]);
        /* the boxes of the two end poses miss the arc a turning vertex bulges out by between them */
        double bulge = w->shape[i].radius * (turn < 3.0 ? turn * turn / 8.0 : 1.0);
        /* a body in a pile strays from its predicted path by what the contacts do to it */
        double pile = w->rests_dissipative[i] ? LC_ISLAND_MARGIN * w->shape[i].min_edge : 0.0;
        lc_end_poses_box(w, w->state, pred, i, w->def.contact_distance + bulge + pile, b);
        if (reach != NULL && reach[4 * i] <= reach[4 * i + 2]) {
            b[0] = fmin(b[0], reach[4 * i]);
            b[1] = fmin(b[1], reach[4 * i + 1]);
            b[2] = fmax(b[2], reach[4 * i + 2]);
            b[3] = fmax(b[3], reach[4 * i + 3]);
        }
    }
    np = lc_broad_phase_boxes(w, boxes, &is->b_pairs);
    if (np < 0 || index_pairs(is, (const int *)is->b_pairs.p, np) != 0) return -1;
    parent = lc_buf_get(&is->b_parent, (size_t)n * sizeof(int));
    of = lc_buf_get(&is->b_of, (size_t)n * sizeof(int));
    rows = lc_buf_get(&is->b_rows, (size_t)n * sizeof(int));
    row_start = lc_buf_get(&is->b_row_start, (size_t)(n + 1) * sizeof(int));
    pair_start = lc_buf_get(&is->b_pair_start, (size_t)(n + 1) * sizeof(int));
    grouped = lc_buf_get(&is->b_grouped, (size_t)(np > 0 ? np : 1) * 2 * sizeof(int));
    if (!parent || !of || !rows || !row_start || !pair_start || !grouped) return -1;
    pairs = (const int *)is->b_pairs.p;
    for (i = 0; i < n; ++i) {
        parent[i] = i;
        of[i] = -1;
    }
    for (k = 0; k < np; ++k) {
        int a = pairs[2 * k], b = pairs[2 * k + 1];
        if (!w->is_static[a] && !w->is_static[b]) join(parent, a, b);
    }
    for (k = 0; k < w->spring_count; ++k)
        if (w->springs[k].def.body_b != LC_WORLD_ANCHOR) {
            int a = lc_world_body_index(w, w->springs[k].def.body_a);
            int b = lc_world_body_index(w, w->springs[k].def.body_b);
            if (a >= 0 && b >= 0 && !w->is_static[a] && !w->is_static[b]) join(parent, a, b);
        }
    /* number the islands by their first row; of[root] holds the number while counting */
    for (i = 0; i < n; ++i) {
        int r;
        if (w->is_static[i]) continue;
        r = root(parent, i);
        if (of[r] < 0) of[r] = is->count++;
        of[i] = of[r];
    }
    memset(row_start, 0, (size_t)(is->count + 1) * sizeof(int));
    memset(pair_start, 0, (size_t)(is->count + 1) * sizeof(int));
    for (i = 0; i < n; ++i)
        if (of[i] >= 0) row_start[of[i] + 1]++;
    for (k = 0; k < np; ++k) {
        int a = pairs[2 * k], b = pairs[2 * k + 1];
        pair_start[(w->is_static[a] ? of[b] : of[a]) + 1]++;
    }
    for (k = 0; k < is->count; ++k) {
        row_start[k + 1] += row_start[k];
        pair_start[k + 1] += pair_start[k];
    }
    /* the rows in ascending order and the pairs in the broadphase's order, within each island: parent
     * is free again as the cursor */
    cursor = parent;
    for (k = 0; k < is->count; ++k) cursor[k] = row_start[k];
    for (i = 0; i < n; ++i)
        if (of[i] >= 0) rows[cursor[of[i]]++] = i;
    for (k = 0; k < is->count; ++k) cursor[k] = pair_start[k];
    for (k = 0; k < np; ++k) {
        int a = pairs[2 * k], b = pairs[2 * k + 1], at = cursor[w->is_static[a] ? of[b] : of[a]]++;
        grouped[2 * at] = a;
        grouped[2 * at + 1] = b;
    }
    return 0;
}

int lc_islands_count(const lc_islands *is) { return is->count; }

const double *lc_islands_boxes(const lc_islands *is) { return (const double *)is->b_boxes.p; }

lc_island lc_islands_get(const lc_islands *is, int k)
{
    lc_island out;
    const int *row_start = (const int *)is->b_row_start.p, *pair_start = (const int *)is->b_pair_start.p;
    out.rows = (const int *)is->b_rows.p + row_start[k];
    out.nrows = row_start[k + 1] - row_start[k];
    out.pairs = (const int *)is->b_grouped.p + 2 * pair_start[k];
    out.npairs = pair_start[k + 1] - pair_start[k];
    return out;
}

int lc_islands_of(const lc_islands *is, int row) { return ((const int *)is->b_of.p)[row]; }

/* How far body row r's points can have moved over the step from `start` (m): its centre's displacement
 * and the arc of its farthest vertex. */
static double point_travel(const lc_world *w, const double *start, int r)
{
    const double *s0 = &start[r * 6], *s1 = &w->state[r * 6];
    return hypot(s1[SX] - s0[SX], s1[SY] - s0[SY]) + fabs(s1[SA] - s0[SA]) * w->shape[r].radius;
}

/* 1 if an unforeseen pair cannot have met in a way the step missed: the two bodies end apart (the
 * separating axis test), and neither moved as far, relative to the other, as the shorter of their
 * shortest edges, so neither can have passed through the other on the way. A pair that met only
 * within contact_distance is then found by the next step's build, as any approaching pair is. */
static int met_harmlessly(const lc_world *w, const double *start, int a, int b)
{
    double travel = (w->is_static[a] ? 0.0 : point_travel(w, start, a)) + (w->is_static[b] ? 0.0 : point_travel(w, start, b));
    if (!(travel < fmin(w->shape[a].min_edge, w->shape[b].min_edge))) return 0;
    return lc_pair_separation(w, w->state, a, b) > 0.0;
}

int lc_islands_unforeseen(lc_world *w, lc_islands *is, const double *start, double *reach)
{
    int n = w->count, i, np, found = 0, outside = 0;
    double *boxes = lc_buf_get(&is->b_reach_boxes, (size_t)n * 4 * sizeof(double));
    const double *built = (const double *)is->b_boxes.p;
    const int *pairs;
    if (boxes == NULL) return -1;
    for (i = 0; i < n; ++i) {
        double turn = fabs(w->state[i * 6 + SA] - start[i * 6 + SA]);
        double bulge = w->shape[i].radius * (turn < 3.0 ? turn * turn / 8.0 : 1.0);
        const double *b = &boxes[4 * i], *p = &built[4 * i];
        lc_end_poses_box(w, start, w->state, i, w->def.contact_distance + bulge, &boxes[4 * i]);
        if (b[0] < p[0] || b[1] < p[1] || b[2] > p[2] || b[3] > p[3]) outside = 1;
    }
    /* every path inside the box its island was built with: the build's pairs hold every meeting */
    if (!outside) return 0;
    np = lc_broad_phase_boxes(w, boxes, &is->b_reach_pairs);
    if (np < 0) return -1;
    pairs = (const int *)is->b_reach_pairs.p;
    for (i = 0; i < np; ++i) {
        int a = pairs[2 * i], b = pairs[2 * i + 1], q;
        if (lc_islands_has_pair(is, a, b)) continue;
        if (met_harmlessly(w, start, a, b)) continue;
        found++;
        for (q = 0; q < 2; ++q) {
            int r = q ? b : a;
            double *x = &reach[4 * r];
            const double *y = &boxes[4 * r];
            if (w->is_static[r]) continue;
            if (x[0] > x[2]) {
                memcpy(x, y, 4 * sizeof(double));
            } else {
                x[0] = fmin(x[0], y[0]);
                x[1] = fmin(x[1], y[1]);
                x[2] = fmax(x[2], y[2]);
                x[3] = fmax(x[3], y[3]);
            }
        }
    }
    return found;
}
