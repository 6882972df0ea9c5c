/* Sleep (sleep.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "sleep.h"
#include "world.h"
#include "snapshot_io.h"

struct lc_sleep {
    int n;                   /* rows the arrays describe */
    unsigned long changes;   /* w->api_changes when they were last valid */
    int any;                 /* some body sleeps */
    lc_buf b_asleep;         /* uint8 per row */
    lc_buf b_rest;           /* double per row: s the body has rested */
    lc_buf b_kept;           /* lc_contact: the resting contacts of sleeping bodies */
    int nkept;
};

lc_sleep *lc_sleep_create(void) { return calloc(1, sizeof(lc_sleep)); }

void lc_sleep_destroy(lc_sleep *s)
{
    if (s == NULL) return;
    lc_buf_free(&s->b_asleep);
    lc_buf_free(&s->b_rest);
    lc_buf_free(&s->b_kept);
    free(s);
}

static void wake_all(lc_sleep *s)
{
    if (s->n > 0) {
        memset(s->b_asleep.p, 0, (size_t)s->n);
        memset(s->b_rest.p, 0, (size_t)s->n * sizeof(double));
    }
    s->any = 0;
    s->nkept = 0;
}

/* Sleep is on: allowed, and no force callback, whose force on a sleeping body no step would evaluate. */
static int sleep_on(const lc_world *w) { return w->def.allow_sleep && !lc_force_callback_on(w); }

int lc_sleep_begin_step(lc_sleep *s, lc_world *w)
{
    const uint8_t *asleep;
    int i, dynamic = 0;
    if (!sleep_on(w)) {
        if (s->any) wake_all(s);
        return 0;
    }
    if (s->n != w->count || s->changes != w->api_changes) {
        int n = w->count > 0 ? w->count : 1;
        if (lc_buf_get(&s->b_asleep, (size_t)n) == NULL || lc_buf_get(&s->b_rest, (size_t)n * sizeof(double)) == NULL)
            return -1;
        s->n = w->count;
        s->changes = w->api_changes;
        wake_all(s);
        return 0;
    }
    if (!s->any) return 0;
    asleep = (const uint8_t *)s->b_asleep.p;
    for (i = 0; i < w->count; ++i) {
        if (w->is_static[i]) continue;
        if (!asleep[i]) return 0;
        dynamic++;
    }
    return dynamic > 0;
}

const uint8_t *lc_sleep_asleep(const lc_sleep *s) { return s->any ? (const uint8_t *)s->b_asleep.p : NULL; }

int lc_sleep_island(lc_sleep *s, lc_world *w, const lc_island *isl)
{
    uint8_t *asleep = (uint8_t *)s->b_asleep.p;
    double *rest = (double *)s->b_rest.p;
    int i, n = 0;
    if (!sleep_on(w) || !s->any) return 0;
    for (i = 0; i < isl->nrows; ++i) n += asleep[isl->rows[i]];
    if (n == isl->nrows && n > 0) return 1;
    if (n == 0) return 0;
    for (i = 0; i < isl->nrows; ++i) {
        asleep[isl->rows[i]] = 0;
        rest[isl->rows[i]] = 0.0;
    }
    w->last.islands_woken++;
    return 0;
}

/* A body that may fall asleep: nothing but gravity, damping and contacts acts on it. */
static int may_rest(const lc_world *w, int row)
{
    int k;
    lc_body_id id = w->ids[row];
    if (lc_body_driven(w, row)) return 0;
    for (k = 0; k < w->spring_count; ++k)
        if (w->springs[k].def.body_a == id || w->springs[k].def.body_b == id) return 0;
    return 1;
}

static int sleeping_contact(const lc_world *w, const uint8_t *asleep, const lc_contact *c)
{
    int a = lc_world_body_index(w, c->body_a), b = lc_world_body_index(w, c->body_b);
    if (a < 0 || b < 0) return 0;
    return (w->is_static[a] || asleep[a]) && (w->is_static[b] || asleep[b]);
}

static int append_contact(lc_world *w, const lc_contact *c)
{
    lc_contact *slot = lc_new_contact(w);
    if (slot == NULL) return -1;
    *slot = *c;
    slot->time = w->time;
    return 0;
}

int lc_sleep_end_step(lc_sleep *s, lc_world *w, const lc_islands *is, double dt)
{
    uint8_t *asleep = (uint8_t *)s->b_asleep.p;
    double *rest = (double *)s->b_rest.p, v = w->def.sleep_speed;
    lc_contact *kept;
    int i, k, nk, reported, first_new;
    if (!sleep_on(w) || w->count == 0) return 0;
    for (i = 0; i < w->count; ++i) {
        const double *st = &w->state[i * 6];
        if (w->is_static[i] || asleep[i]) continue;
        if (may_rest(w, i) && st[SVX] * st[SVX] + st[SVY] * st[SVY] <= v * v && fabs(st[SW]) * w->shape[i].radius <= v)
            rest[i] += dt;
        else
            rest[i] = 0.0;
    }
    /* the kept contacts of bodies that woke this step go; the sleeping ones are reported again */
    kept = (lc_contact *)s->b_kept.p;
    for (k = 0, nk = 0; k < s->nkept; ++k)
        if (sleeping_contact(w, asleep, &kept[k])) kept[nk++] = kept[k];
    s->nkept = nk;
    reported = w->contact_count;
    for (k = 0; k < s->nkept; ++k)
        if (append_contact(w, &((lc_contact *)s->b_kept.p)[k]) != 0) return -1;
    /* islands whose bodies all rested long enough fall asleep, keeping this step's resting contacts */
    first_new = 0;
    for (k = 0; is != NULL && k < lc_islands_count(is); ++k) {
        lc_island isl = lc_islands_get(is, k);
        int ok = isl.nrows > 0;
        for (i = 0; i < isl.nrows && ok; ++i) ok = !asleep[isl.rows[i]] && rest[isl.rows[i]] >= w->def.sleep_time;
        if (!ok) continue;
        for (i = 0; i < isl.nrows; ++i) {
            double *st = &w->state[isl.rows[i] * 6];
            asleep[isl.rows[i]] = 1;
            st[SVX] = st[SVY] = st[SW] = 0.0;
        }
        s->any = 1;
        first_new = 1;
    }
    if (first_new)
        for (k = 0; k < reported; ++k)
            if (w->contacts[k].kind == LC_CONTACT_RESTING && sleeping_contact(w, asleep, &w->contacts[k])) {
                lc_contact *c = lc_buf_get(&s->b_kept, (size_t)(s->nkept + 1) * sizeof(lc_contact));
                if (c == NULL) return -1;
                c[s->nkept++] = w->contacts[k];
            }
    for (i = 0, nk = 0; i < w->count; ++i) nk += asleep[i];
    w->last.bodies_asleep = (uint64_t)nk;
    return 0;
}

void lc_sleep_save(const lc_sleep *s, lc_writer *out)
{
    const lc_contact *kept = (const lc_contact *)s->b_kept.p;
    int i;
    lc_put_i32(out, s->n);
    lc_put_u64(out, s->changes);
    lc_put_i32(out, s->any);
    for (i = 0; i < s->n; ++i) {
        lc_put_u8(out, ((const uint8_t *)s->b_asleep.p)[i]);
        lc_put_f64(out, ((const double *)s->b_rest.p)[i]);
    }
    lc_put_i32(out, s->nkept);
    for (i = 0; i < s->nkept; ++i) lc_put_contact(out, &kept[i]);
}

int lc_sleep_load(lc_sleep *s, const lc_world *w, lc_reader *in)
{
    int n = lc_get_count(in, 0, 1 << 24, 9, "the sleep records"), i, rows = n > w->count ? n : w->count;
    uint8_t *asleep;
    double *rest;
    lc_contact *kept;
    s->changes = (unsigned long)lc_get_u64(in);
    s->any = lc_get_i32(in);
    asleep = lc_buf_get(&s->b_asleep, (size_t)(rows > 0 ? rows : 1));
    rest = lc_buf_get(&s->b_rest, (size_t)(rows > 0 ? rows : 1) * sizeof(double));
    if (asleep == NULL || rest == NULL) return -1;
    memset(asleep, 0, (size_t)(rows > 0 ? rows : 1));
    memset(rest, 0, (size_t)(rows > 0 ? rows : 1) * sizeof(double));
    s->n = n;
    for (i = 0; i < n; ++i) {
        asleep[i] = (uint8_t)lc_get_u8(in);
        rest[i] = lc_get_finite(in, "a rest timer");
        if (asleep[i] > 1) lc_reader_fail(in, "row %d's sleep flag is %u", i, (unsigned)asleep[i]);
    }
    if (s->any != 0 && s->any != 1) lc_reader_fail(in, "the sleep flag is %d", s->any);
    s->nkept = 0;
    n = lc_get_count(in, 0, 1 << 30, 64, "the sleeping contacts");
    kept = lc_buf_get(&s->b_kept, (size_t)(n > 0 ? n : 1) * sizeof(lc_contact));
    if (kept == NULL) return -1;
    for (i = 0; i < n && !in->bad; ++i) lc_get_contact(in, &kept[i]);
    s->nkept = in->bad ? 0 : n;
    return 0;
}
