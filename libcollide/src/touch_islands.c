/* The event regime's touch islands (finer than the step's islands of islands.c): bodies joined by
 * resting touches or by springs between bodies (all of them while a force callback is set) move
 * together, and apart from every other touch island (static bodies join nothing: they transmit no
 * motion). A time-of-impact search needs only the islands
 * of the crossing's two bodies; integrating the whole world there made every evaluation in a settling
 * scene (20 blocks, each on the floor) solve all of their contact forces, ~2000 force evaluations per
 * step. Rows and touches are sorted by island, in their order. */
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "touch_islands.h"

struct lc_touch_islands {
    int *of;                  /* island of each body row, -1 for static bodies */
    int *rows, *row_start;    /* rows of island k: rows[row_start[k] .. row_start[k + 1]) */
    lc_touch *touches;        /* resting touches of island k: likewise, with touch_start */
    int *touch_start;
    int count;
    lc_buf ints, sorted;      /* of, the union-find's parents, rows, row_start, touch_start, cursors; touches */
    lc_buf pick, pick_touches; /* the rows and touches of two islands side by side */
};

lc_touch_islands *lc_touch_islands_create(void) { return calloc(1, sizeof(lc_touch_islands)); }

void lc_touch_islands_destroy(lc_touch_islands *is)
{
    if (is == NULL) return;
    lc_buf_free(&is->ints);
    lc_buf_free(&is->sorted);
    lc_buf_free(&is->pick);
    lc_buf_free(&is->pick_touches);
    free(is);
}

int lc_touch_island(const lc_touch_islands *is, int row) { return is->of[row]; }

static int island_root(int *parent, int x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static void island_join(int *parent, int a, int b)
{
    int ra = island_root(parent, a), rb = island_root(parent, b);
    if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
}

int lc_touch_islands_build(const lc_world *w, lc_touch_islands *is, const int *rows, int nrows, const lc_touch *rest,
                           int nrest)
{
    int *v = lc_buf_get(&is->ints, ((size_t)w->count * 2 + (size_t)nrows * 4 + 3) * sizeof(int));
    int *parent, *cursor, i, k;
    is->touches = lc_buf_get(&is->sorted, (size_t)(nrest > 0 ? nrest : 1) * sizeof(lc_touch));
    if (v == NULL || is->touches == NULL) return -1;
    is->of = v;
    parent = v + w->count;
    is->rows = parent + w->count;
    is->row_start = is->rows + nrows;
    is->touch_start = is->row_start + nrows + 1;
    cursor = is->touch_start + nrows + 1;
    for (i = 0; i < w->count; ++i) {
        parent[i] = i;
        is->of[i] = -1;
    }
    for (i = 0; i < nrest; ++i)
        if (!w->is_static[rest[i].a] && !w->is_static[rest[i].b]) island_join(parent, rest[i].a, rest[i].b);
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) {
            int a = lc_world_body_index(w, w->springs[i].def.body_a), b = lc_world_body_index(w, w->springs[i].def.body_b);
            if (a >= 0 && b >= 0 && !w->is_static[a] && !w->is_static[b]) island_join(parent, a, b);
        }
    /* the force callback may tie any body to any other: the bodies move together */
    if (lc_force_callback_on(w))
        for (i = 1; i < nrows; ++i) island_join(parent, rows[0], rows[i]);
    /* number the islands by their first row; is->of[root] holds the number while counting */
    is->count = 0;
    for (i = 0; i < nrows; ++i) {
        int r = island_root(parent, rows[i]);
        if (is->of[r] < 0) is->of[r] = is->count++;
    }
    for (i = 0; i < nrows; ++i) is->of[rows[i]] = is->of[island_root(parent, rows[i])];
    for (k = 0; k <= is->count; ++k) is->row_start[k] = is->touch_start[k] = 0;
    for (i = 0; i < nrows; ++i) is->row_start[is->of[rows[i]] + 1]++;
    for (i = 0; i < nrest; ++i) is->touch_start[is->of[w->is_static[rest[i].a] ? rest[i].b : rest[i].a] + 1]++;
    for (k = 0; k < is->count; ++k) {
        is->row_start[k + 1] += is->row_start[k];
        is->touch_start[k + 1] += is->touch_start[k];
    }
    for (k = 0; k < is->count; ++k) cursor[k] = is->row_start[k];
    for (i = 0; i < nrows; ++i) is->rows[cursor[is->of[rows[i]]]++] = rows[i];
    for (k = 0; k < is->count; ++k) cursor[k] = is->touch_start[k];
    for (i = 0; i < nrest; ++i) is->touches[cursor[is->of[w->is_static[rest[i].a] ? rest[i].b : rest[i].a]]++] = rest[i];
    return 0;
}

/* The rows and resting touches of the islands of bodies a and b (one island, or both side by side). */
int lc_touch_islands_of(lc_touch_islands *is, int a, int b, const int **rows, int *nrows, lc_touch **touches,
                        int *ntouches)
{
    int ia = is->of[a], ib = is->of[b], nr, nt;
    int *r;
    lc_touch *t;
    if (ia < 0) ia = ib;
    if (ib < 0) ib = ia;
    if (ia < 0) {
        *nrows = *ntouches = 0;
        *rows = NULL;
        *touches = NULL;
        return 0;
    }
    if (ia == ib) {
        *rows = is->rows + is->row_start[ia];
        *nrows = is->row_start[ia + 1] - is->row_start[ia];
        *touches = is->touches + is->touch_start[ia];
        *ntouches = is->touch_start[ia + 1] - is->touch_start[ia];
        return 0;
    }
    nr = is->row_start[ia + 1] - is->row_start[ia];
    nt = is->touch_start[ia + 1] - is->touch_start[ia];
    r = lc_buf_get(&is->pick, (size_t)(nr + is->row_start[ib + 1] - is->row_start[ib]) * sizeof(int));
    t = lc_buf_get(&is->pick_touches,
                   (size_t)(nt + is->touch_start[ib + 1] - is->touch_start[ib] + 1) * sizeof(lc_touch));
    if (r == NULL || t == NULL) return -1;
    memcpy(r, is->rows + is->row_start[ia], (size_t)nr * sizeof(int));
    memcpy(r + nr, is->rows + is->row_start[ib], (size_t)(is->row_start[ib + 1] - is->row_start[ib]) * sizeof(int));
    memcpy(t, is->touches + is->touch_start[ia], (size_t)nt * sizeof(lc_touch));
    memcpy(t + nt, is->touches + is->touch_start[ib], (size_t)(is->touch_start[ib + 1] - is->touch_start[ib]) * sizeof(lc_touch));
    *rows = r;
    *nrows = nr + is->row_start[ib + 1] - is->row_start[ib];
    *touches = t;
    *ntouches = nt + is->touch_start[ib + 1] - is->touch_start[ib];
    return 0;
}
