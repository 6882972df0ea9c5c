/* Persistent contacts: the forces each contact point carried in the last step, by a key that survives
 * from one step to the next (the two bodies' ids, the vertex of body a and the edge of body b), so the
 * contact regime's solver starts near its answer (warm start). Forces rather than impulses, so a
 * change of dt keeps the warm start right. Entries of one step are written, then read the next. */
#ifndef LC_CONTACT_CACHE_H
#define LC_CONTACT_CACHE_H

#include <stddef.h>
#include <stdint.h>

typedef struct lc_contact_key {
    uint32_t a, b;      /* body ids */
    int vertex, edge;
} lc_contact_key;

typedef struct lc_contact_cache lc_contact_cache;

lc_contact_cache *lc_contact_cache_create(void);
void lc_contact_cache_destroy(lc_contact_cache *c);
/* Makes what was stored since the last call readable and starts an empty store. 0, or -1 without
 * memory (the cache is then empty). */
int lc_contact_cache_next_step(lc_contact_cache *c);
/* The normal and friction forces (N) stored for key in the last step: 1 if found, else 0 (and zeros). */
int lc_contact_cache_find(const lc_contact_cache *c, lc_contact_key key, double *force_n, double *force_t);
/* Stores a contact's forces for the next step. 0, or -1 without memory. */
int lc_contact_cache_store(lc_contact_cache *c, lc_contact_key key, double force_n, double force_t);
/* Drops what was stored since lc_contact_cache_next_step. */
void lc_contact_cache_drop_stored(lc_contact_cache *c);
/* Forgets everything (bodies removed: their ids are never reused, but a cleared world starts cold). */
void lc_contact_cache_clear(lc_contact_cache *c);

struct lc_writer;
struct lc_reader;
/* Snapshots (snapshot.c): what the next step reads, the entries stored since lc_contact_cache_next_step,
 * written, and read back into an empty cache. Load: 0, or -1 without memory (bad input: in->bad). */
void lc_contact_cache_save(const lc_contact_cache *c, struct lc_writer *out);
int lc_contact_cache_load(lc_contact_cache *c, struct lc_reader *in);

#endif
