/* The encoding of a world snapshot (lc_world_save / lc_world_load, snapshot.c): numbers written and
 * read little-endian whatever the machine, doubles as their IEEE-754 bits (so a value comes back bit
 * for bit), and the engine's records (touches) field by field. Each module that keeps state from one
 * step to the next writes and reads its own part with these. */
#ifndef LC_SNAPSHOT_IO_H
#define LC_SNAPSHOT_IO_H

#include <stddef.h>
#include <stdint.h>
#include "world.h"

/* A writer appends to p[0 .. cap); with p NULL, or past cap, it only counts (n is the size needed). */
typedef struct lc_writer {
    uint8_t *p;
    size_t cap, n;
} lc_writer;

void lc_put_u8(lc_writer *o, unsigned v);
void lc_put_u32(lc_writer *o, uint32_t v);
void lc_put_i32(lc_writer *o, int v);
void lc_put_u64(lc_writer *o, uint64_t v);
void lc_put_f64(lc_writer *o, double v);
void lc_put_vec(lc_writer *o, lc_vec2 v);
void lc_put_touch(lc_writer *o, const lc_touch *t);
void lc_put_contact(lc_writer *o, const lc_contact *c);

/* A reader takes from p[0 .. n); reading past the end, or a value a check refuses, sets `bad` (with the
 * reason in why) and yields zeros from then on, so a loader checks once at its end. */
typedef struct lc_reader {
    const uint8_t *p;
    size_t n, at;
    int bad;
    char why[160];
} lc_reader;

/* Marks the input bad with a reason (the first reason is kept). Returns 0. */
int lc_reader_fail(lc_reader *in, const char *fmt, ...);
unsigned lc_get_u8(lc_reader *in);
uint32_t lc_get_u32(lc_reader *in);
int lc_get_i32(lc_reader *in);
uint64_t lc_get_u64(lc_reader *in);
double lc_get_f64(lc_reader *in);
lc_vec2 lc_get_vec(lc_reader *in);
/* A finite double (else bad, naming `what`). */
double lc_get_finite(lc_reader *in, const char *what);
/* A count in [lo, hi] of items of at least `item_bytes` bytes each that the rest of the input can hold
 * (so a corrupt count cannot ask for a huge allocation); else bad and 0. */
int lc_get_count(lc_reader *in, int lo, int hi, size_t item_bytes, const char *what);
/* A touch between rows of w (its rows, vertex and edge checked against w's bodies, its numbers finite). */
void lc_get_touch(lc_reader *in, const lc_world *w, lc_touch *t);
/* A contact of a step's report (its numbers as written, its kind checked). */
void lc_get_contact(lc_reader *in, lc_contact *c);
/* Bytes a touch takes. */
#define LC_TOUCH_BYTES (4 * 4 + 16 * 8)

#endif
