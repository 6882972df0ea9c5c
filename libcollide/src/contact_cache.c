/* Persistent contacts (contact_cache.h): an open-addressing hash table over the last step's entries. */
#include <stdlib.h>
#include <string.h>
#include "contact_cache.h"
#include "snapshot_io.h"

typedef struct entry {
    lc_contact_key key;
    double force_n, force_t;
} entry;

struct lc_contact_cache {
    entry *read, *write;     /* last step's entries (read), this step's (write) */
    int nread, nwrite, capread, capwrite;
    int *table;              /* indices into read, -1 = empty; size a power of two */
    int size, tablecap;
};

lc_contact_cache *lc_contact_cache_create(void) { return calloc(1, sizeof(lc_contact_cache)); }

void lc_contact_cache_destroy(lc_contact_cache *c)
{
    if (c == NULL) return;
    free(c->read);
    free(c->write);
    free(c->table);
    free(c);
}

static uint32_t hash(lc_contact_key k)
{
    uint32_t h = 2166136261u;
    h = (h ^ k.a) * 16777619u;
    h = (h ^ (uint32_t)k.vertex) * 16777619u;
    h = (h ^ k.b) * 16777619u;
    return (h ^ (uint32_t)k.edge) * 16777619u;
}

static int same(lc_contact_key x, lc_contact_key y)
{
    return x.a == y.a && x.b == y.b && x.vertex == y.vertex && x.edge == y.edge;
}

int lc_contact_cache_next_step(lc_contact_cache *c)
{
    entry *e = c->read;
    int cap = c->capread, size = 1, i;
    c->read = c->write;
    c->capread = c->capwrite;
    c->nread = c->nwrite;
    c->write = e;
    c->capwrite = cap;
    c->nwrite = 0;
    while (size < 2 * c->nread) size *= 2;
    if (size > c->tablecap) {
        int *t = realloc(c->table, (size_t)size * sizeof(int));
        if (t == NULL) {
            c->nread = 0;
            c->size = 0;
            return -1;
        }
        c->table = t;
        c->tablecap = size;
    }
    c->size = size;
    for (i = 0; i < size; ++i) c->table[i] = -1;
    for (i = 0; i < c->nread; ++i) {
        uint32_t k = hash(c->read[i].key) & (uint32_t)(size - 1);
        while (c->table[k] >= 0) k = (k + 1) & (uint32_t)(size - 1);
        c->table[k] = i;
    }
    return 0;
}

int lc_contact_cache_find(const lc_contact_cache *c, lc_contact_key key, double *force_n, double *force_t)
{
    uint32_t k;
    *force_n = *force_t = 0.0;
    if (c->nread == 0) return 0;
    k = hash(key) & (uint32_t)(c->size - 1);
    while (c->table[k] >= 0) {
        const entry *e = &c->read[c->table[k]];
        if (same(e->key, key)) {
            *force_n = e->force_n;
            *force_t = e->force_t;
            return 1;
        }
        k = (k + 1) & (uint32_t)(c->size - 1);
    }
    return 0;
}

int lc_contact_cache_store(lc_contact_cache *c, lc_contact_key key, double force_n, double force_t)
{
    if (c->nwrite == c->capwrite) {
        int cap = c->capwrite ? 2 * c->capwrite : 64;
        entry *e = realloc(c->write, (size_t)cap * sizeof(entry));
        if (e == NULL) return -1;
        c->write = e;
        c->capwrite = cap;
    }
    c->write[c->nwrite].key = key;
    c->write[c->nwrite].force_n = force_n;
    c->write[c->nwrite].force_t = force_t;
    c->nwrite++;
    return 0;
}

void lc_contact_cache_drop_stored(lc_contact_cache *c) { c->nwrite = 0; }

void lc_contact_cache_clear(lc_contact_cache *c)
{
    c->nread = c->nwrite = 0;
    c->size = 0;
}

void lc_contact_cache_save(const lc_contact_cache *c, lc_writer *out)
{
    int i;
    lc_put_i32(out, c->nwrite);
    for (i = 0; i < c->nwrite; ++i) {
        const entry *e = &c->write[i];
        lc_put_u32(out, e->key.a);
        lc_put_u32(out, e->key.b);
        lc_put_i32(out, e->key.vertex);
        lc_put_i32(out, e->key.edge);
        lc_put_f64(out, e->force_n);
        lc_put_f64(out, e->force_t);
    }
}

int lc_contact_cache_load(lc_contact_cache *c, lc_reader *in)
{
    int n = lc_get_count(in, 0, 1 << 30, 32, "the contact cache's entries"), i;
    for (i = 0; i < n && !in->bad; ++i) {
        lc_contact_key key;
        double fn, ft;
        key.a = lc_get_u32(in);
        key.b = lc_get_u32(in);
        key.vertex = lc_get_i32(in);
        key.edge = lc_get_i32(in);
        fn = lc_get_finite(in, "a kept contact force");
        ft = lc_get_finite(in, "a kept friction force");
        if (!in->bad && lc_contact_cache_store(c, key, fn, ft) != 0) return -1;
    }
    return 0;
}
