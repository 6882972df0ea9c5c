/* Kept touches (kept_touches.h): per island, a record of its rows, pairs, end state, search margins,
 * touches and still mark, in arenas written during a step and read in the next; islands are found by
 * their first row. */
#include <stdlib.h>
#include <string.h>
#include "kept_touches.h"
#include "snapshot_io.h"

typedef struct record {
    int first_row, nrows, npairs, ntouch;
    int still;           /* the island rested through the step that kept it, at one state (kept_touches.h) */
    double dt;
    unsigned long edits, api_changes;
    size_t touch_at, state_at, int_at;   /* offsets into the arenas */
} record;

typedef struct arena {
    lc_buf records, touches, states, ints;
    int nrecords;
    size_t ntouches, nstates, nints;
} arena;

struct lc_kept_touches {
    arena a[2];
    int read;            /* index of the readable arena; 1 - read is written */
    lc_buf b_index;      /* int per row: the readable record whose island starts at that row, or -1 */
    int index_rows;
};

lc_kept_touches *lc_kept_touches_create(void) { return calloc(1, sizeof(lc_kept_touches)); }

static void arena_free(arena *x)
{
    lc_buf_free(&x->records);
    lc_buf_free(&x->touches);
    lc_buf_free(&x->states);
    lc_buf_free(&x->ints);
}

void lc_kept_touches_destroy(lc_kept_touches *k)
{
    if (k == NULL) return;
    arena_free(&k->a[0]);
    arena_free(&k->a[1]);
    lc_buf_free(&k->b_index);
    free(k);
}

static void arena_empty(arena *x) { x->nrecords = 0, x->ntouches = x->nstates = x->nints = 0; }

int lc_kept_touches_next_step(lc_kept_touches *k)
{
    arena *r;
    const record *rec;
    int i, rows = 0, *index;
    k->read = 1 - k->read;
    r = &k->a[k->read];
    arena_empty(&k->a[1 - k->read]);
    rec = (const record *)r->records.p;
    for (i = 0; i < r->nrecords; ++i)
        if (rec[i].first_row + 1 > rows) rows = rec[i].first_row + 1;
    index = lc_buf_get(&k->b_index, (size_t)(rows > 0 ? rows : 1) * sizeof(int));
    if (index == NULL) {
        arena_empty(r);
        k->index_rows = 0;
        return -1;
    }
    for (i = 0; i < rows; ++i) index[i] = -1;
    for (i = 0; i < r->nrecords; ++i) index[rec[i].first_row] = i;
    k->index_rows = rows;
    return 0;
}

void lc_kept_touches_drop_stored(lc_kept_touches *k) { arena_empty(&k->a[1 - k->read]); }

void lc_kept_touches_clear(lc_kept_touches *k)
{
    arena_empty(&k->a[0]);
    arena_empty(&k->a[1]);
    k->index_rows = 0;
}

int lc_kept_touches_store(lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt, const lc_touch *t,
                          int n, const double *margin, int still)
{
    arena *x = &k->a[1 - k->read];
    record *rec;
    lc_touch *tt;
    double *st;
    int *in, i;
    if (isl->nrows == 0) return 0;
    rec = lc_buf_get(&x->records, (size_t)(x->nrecords + 1) * sizeof(record));
    tt = lc_buf_get(&x->touches, (x->ntouches + (size_t)n + 1) * sizeof(lc_touch));
    st = lc_buf_get(&x->states, (x->nstates + (size_t)isl->nrows * 6 + (size_t)isl->npairs) * sizeof(double));
    in = lc_buf_get(&x->ints, (x->nints + (size_t)isl->nrows + 2 * (size_t)isl->npairs) * sizeof(int));
    if (rec == NULL || tt == NULL || st == NULL || in == NULL) return -1;
    rec += x->nrecords;
    rec->first_row = isl->rows[0];
    rec->nrows = isl->nrows;
    rec->npairs = isl->npairs;
    rec->ntouch = n;
    rec->still = still != 0;
    rec->dt = dt;
    rec->edits = w->edits;
    rec->api_changes = w->api_changes;
    rec->touch_at = x->ntouches;
    rec->state_at = x->nstates;
    rec->int_at = x->nints;
    tt += x->ntouches;
    if (n > 0) memcpy(tt, t, (size_t)n * sizeof(lc_touch));
    for (i = 0; i < n; ++i) {
        /* the next step's start: velocities as the step left them (the energy guard may have scaled
         * them after the search), no impulse yet; a still set keeps the forces its resting contacts
         * were reported with (lc_kept_touches_still), which take() does not pass on */
        const double *sa = &w->state[tt[i].a * 6], *sb = &w->state[tt[i].b * 6];
        lc_vec2 va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], tt[i].ra));
        lc_vec2 vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], tt[i].rb));
        tt[i].vn = lc_dot(tt[i].n, lc_sub(va, vb));
        if (!still) tt[i].value = tt[i].tangent = 0.0;
        tt[i].vn_pre = tt[i].target_vn = 0.0;
    }
    for (i = 0; i < isl->nrows; ++i) memcpy(&st[x->nstates + (size_t)i * 6], &w->state[isl->rows[i] * 6], 6 * sizeof(double));
    memcpy(&in[x->nints], isl->rows, (size_t)isl->nrows * sizeof(int));
    if (isl->npairs > 0) {
        memcpy(&st[x->nstates + (size_t)isl->nrows * 6], margin, (size_t)isl->npairs * sizeof(double));
        memcpy(&in[x->nints + (size_t)isl->nrows], isl->pairs, 2 * (size_t)isl->npairs * sizeof(int));
    }
    x->nrecords++;
    x->ntouches += (size_t)n;
    x->nstates += (size_t)isl->nrows * 6 + (size_t)isl->npairs;
    x->nints += (size_t)isl->nrows + 2 * (size_t)isl->npairs;
    return 0;
}

/* The readable record of island isl if a step of dt starts from exactly the state it was kept at, with
 * the same rows and pairs and no API change since; else NULL. */
static const record *matching(const lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt)
{
    const arena *x = &k->a[k->read];
    const record *rec;
    const double *st;
    const int *in;
    int i;
    if (isl->nrows == 0 || isl->rows[0] >= k->index_rows) return NULL;
    i = ((const int *)k->b_index.p)[isl->rows[0]];
    if (i < 0) return NULL;
    rec = &((const record *)x->records.p)[i];
    if (rec->nrows != isl->nrows || rec->npairs != isl->npairs || rec->dt != dt || rec->edits != w->edits) return NULL;
    in = (const int *)x->ints.p + rec->int_at;
    if (memcmp(in, isl->rows, (size_t)isl->nrows * sizeof(int)) != 0 ||
        (isl->npairs > 0 && memcmp(in + isl->nrows, isl->pairs, 2 * (size_t)isl->npairs * sizeof(int)) != 0))
        return NULL;
    st = (const double *)x->states.p + rec->state_at;
    for (i = 0; i < isl->nrows; ++i)
        if (memcmp(&st[i * 6], &w->state[isl->rows[i] * 6], 6 * sizeof(double)) != 0) return NULL;
    return rec;
}

int lc_kept_touches_still(const lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt,
                          const lc_touch **t, int *n, const double **margin)
{
    const arena *x = &k->a[k->read];
    const record *rec = matching(k, w, isl, dt);
    /* a setting (gravity, damping, a contact parameter) changes the problem without changing edits */
    if (rec == NULL || !rec->still || rec->api_changes != w->api_changes) return 0;
    *t = (const lc_touch *)x->touches.p + rec->touch_at;
    *n = rec->ntouch;
    *margin = (const double *)x->states.p + rec->state_at + (size_t)rec->nrows * 6;
    return 1;
}

int lc_kept_touches_take(const lc_kept_touches *k, const lc_world *w, const lc_island *isl, double dt,
                         double (*want)(const void *ctx, int a, int b), const void *ctx, lc_buf *buf)
{
    const arena *x = &k->a[k->read];
    const record *rec = matching(k, w, isl, dt);
    const double *st;
    const lc_touch *t;
    lc_touch *out;
    int i, n = 0;
    if (rec == NULL) return -2;
    st = (const double *)x->states.p + rec->state_at;
    for (i = 0; i < isl->npairs; ++i)
        if (!(want(ctx, isl->pairs[2 * i], isl->pairs[2 * i + 1]) <= st[isl->nrows * 6 + i])) return -2;
    out = lc_buf_get(buf, (size_t)(rec->ntouch > 0 ? rec->ntouch : 1) * sizeof(lc_touch));
    if (out == NULL) return -1;
    t = (const lc_touch *)x->touches.p + rec->touch_at;
    {
        /* a pair's touches are consecutive: its margin once per run */
        int a = -1, b = -1;
        double m = 0.0;
        for (i = 0; i < rec->ntouch; ++i) {
            if (t[i].a != a || t[i].b != b) {
                a = t[i].a;
                b = t[i].b;
                m = want(ctx, a, b);
            }
            if (t[i].gap < m) {
                out[n] = t[i];
                out[n].value = out[n].tangent = 0.0;
                n++;
            }
        }
    }
    return n;
}

void lc_kept_touches_save(const lc_kept_touches *k, const lc_world *w, lc_writer *out)
{
    const arena *x = &k->a[1 - k->read];
    const record *rec = (const record *)x->records.p;
    int r, i, n = 0;
    /* a set kept before an API change is never taken (its edits differ): written are the others, whose
     * rows are the world's */
    for (r = 0; r < x->nrecords; ++r) n += rec[r].edits == w->edits;
    lc_put_i32(out, n);
    for (r = 0; r < x->nrecords; ++r) {
        if (rec[r].edits != w->edits) continue;
        const int *in = (const int *)x->ints.p + rec[r].int_at;
        const double *st = (const double *)x->states.p + rec[r].state_at;
        const lc_touch *t = (const lc_touch *)x->touches.p + rec[r].touch_at;
        lc_put_i32(out, rec[r].nrows);
        lc_put_i32(out, rec[r].npairs);
        lc_put_i32(out, rec[r].ntouch);
        lc_put_i32(out, rec[r].still);
        lc_put_f64(out, rec[r].dt);
        lc_put_u64(out, rec[r].edits);
        lc_put_u64(out, rec[r].api_changes);
        for (i = 0; i < rec[r].nrows + 2 * rec[r].npairs; ++i) lc_put_i32(out, in[i]);
        for (i = 0; i < rec[r].nrows * 6 + rec[r].npairs; ++i) lc_put_f64(out, st[i]);
        for (i = 0; i < rec[r].ntouch; ++i) lc_put_touch(out, &t[i]);
    }
}

int lc_kept_touches_load(lc_kept_touches *k, const lc_world *w, lc_reader *in)
{
    arena *x = &k->a[1 - k->read];
    int nrec = lc_get_count(in, 0, 1 << 28, 32, "the kept touch sets"), r, i;
    arena_empty(x);
    for (r = 0; r < nrec && !in->bad; ++r) {
        int nrows = lc_get_count(in, 1, w->count, 52, "a kept set's rows");
        int npairs = lc_get_count(in, 0, 1 << 28, 16, "a kept set's pairs");
        int ntouch = lc_get_count(in, 0, 1 << 28, LC_TOUCH_BYTES, "a kept set's touches");
        int still = lc_get_i32(in);
        record *rec = lc_buf_get(&x->records, (size_t)(x->nrecords + 1) * sizeof(record));
        lc_touch *tt = lc_buf_get(&x->touches, (x->ntouches + (size_t)ntouch + 1) * sizeof(lc_touch));
        double *st = lc_buf_get(&x->states, (x->nstates + (size_t)nrows * 6 + (size_t)npairs + 1) * sizeof(double));
        int *ints = lc_buf_get(&x->ints, (x->nints + (size_t)nrows + 2 * (size_t)npairs + 1) * sizeof(int));
        if (rec == NULL || tt == NULL || st == NULL || ints == NULL) return -1;
        if (in->bad) break;
        rec += x->nrecords;
        rec->nrows = nrows;
        rec->npairs = npairs;
        rec->ntouch = ntouch;
        if (still != 0 && still != 1) lc_reader_fail(in, "a kept set's still flag is neither 0 nor 1");
        rec->still = still;
        rec->dt = lc_get_f64(in);
        rec->edits = (unsigned long)lc_get_u64(in);
        rec->api_changes = (unsigned long)lc_get_u64(in);
        rec->touch_at = x->ntouches;
        rec->state_at = x->nstates;
        rec->int_at = x->nints;
        ints += x->nints;
        for (i = 0; i < nrows + 2 * npairs; ++i) {
            ints[i] = lc_get_i32(in);
            if (ints[i] < 0 || ints[i] >= w->count || (i > 0 && i < nrows && ints[i] <= ints[i - 1]))
                lc_reader_fail(in, "a kept set's rows or pairs are not rows of the world in order");
        }
        rec->first_row = ints[0];
        st += x->nstates;
        for (i = 0; i < nrows * 6 + npairs; ++i) st[i] = lc_get_f64(in);
        /* a still set was kept at rest: a held island never keeps a velocity */
        for (i = 0; still && i < nrows; ++i)
            if (st[i * 6 + SVX] != 0.0 || st[i * 6 + SVY] != 0.0 || st[i * 6 + SW] != 0.0)
                lc_reader_fail(in, "a still kept set's bodies are moving");
        tt += x->ntouches;
        for (i = 0; i < ntouch; ++i) lc_get_touch(in, w, &tt[i]);
        if (in->bad) break;
        x->nrecords++;
        x->ntouches += (size_t)ntouch;
        x->nstates += (size_t)nrows * 6 + (size_t)npairs;
        x->nints += (size_t)nrows + 2 * (size_t)npairs;
    }
    return 0;
}
