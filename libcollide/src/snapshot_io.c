/* The snapshot's encoding (snapshot_io.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "snapshot_io.h"

static void put_bytes_le(lc_writer *o, uint64_t v, int bytes)
{
    int k;
    if (o->p != NULL && o->n + (size_t)bytes <= o->cap)
        for (k = 0; k < bytes; ++k) o->p[o->n + (size_t)k] = (uint8_t)(v >> (8 * k));
    o->n += (size_t)bytes;
}

void lc_put_u8(lc_writer *o, unsigned v) { put_bytes_le(o, v & 0xFFu, 1); }
void lc_put_u32(lc_writer *o, uint32_t v) { put_bytes_le(o, v, 4); }
void lc_put_i32(lc_writer *o, int v) { put_bytes_le(o, (uint32_t)(int32_t)v, 4); }
void lc_put_u64(lc_writer *o, uint64_t v) { put_bytes_le(o, v, 8); }

void lc_put_f64(lc_writer *o, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    put_bytes_le(o, bits, 8);
}

void lc_put_vec(lc_writer *o, lc_vec2 v)
{
    lc_put_f64(o, v.x);
    lc_put_f64(o, v.y);
}

void lc_put_touch(lc_writer *o, const lc_touch *t)
{
    lc_put_i32(o, t->a);
    lc_put_i32(o, t->b);
    lc_put_i32(o, t->vertex);
    lc_put_i32(o, t->edge);
    lc_put_f64(o, t->elasticity);
    lc_put_f64(o, t->friction);
    lc_put_vec(o, t->p);
    lc_put_vec(o, t->n);
    lc_put_vec(o, t->ra);
    lc_put_vec(o, t->rb);
    lc_put_f64(o, t->gap);
    lc_put_f64(o, t->vn);
    lc_put_f64(o, t->value);
    lc_put_f64(o, t->vn_pre);
    lc_put_f64(o, t->target_vn);
    lc_put_f64(o, t->tangent);
}

void lc_put_contact(lc_writer *o, const lc_contact *c)
{
    lc_put_u32(o, c->body_a);
    lc_put_u32(o, c->body_b);
    lc_put_vec(o, c->point);
    lc_put_vec(o, c->normal);
    lc_put_f64(o, c->gap);
    lc_put_f64(o, c->normal_velocity);
    lc_put_f64(o, c->impulse);
    lc_put_f64(o, c->tangent_impulse);
    lc_put_f64(o, c->force);
    lc_put_f64(o, c->time);
    lc_put_i32(o, (int)c->kind);
}

int lc_reader_fail(lc_reader *in, const char *fmt, ...)
{
    va_list ap;
    if (!in->bad) {
        va_start(ap, fmt);
        vsnprintf(in->why, sizeof in->why, fmt, ap);
        va_end(ap);
    }
    in->bad = 1;
    return 0;
}

static uint64_t get_bytes_le(lc_reader *in, int bytes)
{
    uint64_t v = 0;
    int k;
    if (in->bad) return 0;
    if (in->n - in->at < (size_t)bytes) {
        lc_reader_fail(in, "the snapshot ends early (truncated)");
        return 0;
    }
    for (k = 0; k < bytes; ++k) v |= (uint64_t)in->p[in->at + (size_t)k] << (8 * k);
    in->at += (size_t)bytes;
    return v;
}

unsigned lc_get_u8(lc_reader *in) { return (unsigned)get_bytes_le(in, 1); }
uint32_t lc_get_u32(lc_reader *in) { return (uint32_t)get_bytes_le(in, 4); }
int lc_get_i32(lc_reader *in) { return (int)(int32_t)(uint32_t)get_bytes_le(in, 4); }
uint64_t lc_get_u64(lc_reader *in) { return get_bytes_le(in, 8); }

double lc_get_f64(lc_reader *in)
{
    uint64_t bits = get_bytes_le(in, 8);
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

lc_vec2 lc_get_vec(lc_reader *in)
{
    lc_vec2 v;
    v.x = lc_get_f64(in);
    v.y = lc_get_f64(in);
    return v;
}

double lc_get_finite(lc_reader *in, const char *what)
{
    double v = lc_get_f64(in);
    if (!isfinite(v)) {
        lc_reader_fail(in, "%s is not finite", what);
        return 0.0;
    }
    return v;
}

int lc_get_count(lc_reader *in, int lo, int hi, size_t item_bytes, const char *what)
{
    int v = lc_get_i32(in);
    if (in->bad) return 0;
    if (v < lo || v > hi) return lc_reader_fail(in, "%s = %d is outside [%d, %d]", what, v, lo, hi);
    if (v > 0 && item_bytes > 0 && (size_t)v > (in->n - in->at) / item_bytes)
        return lc_reader_fail(in, "%s = %d is more than the rest of the snapshot holds (truncated)", what, v);
    return v;
}

void lc_get_touch(lc_reader *in, const lc_world *w, lc_touch *t)
{
    memset(t, 0, sizeof *t);
    t->a = lc_get_i32(in);
    t->b = lc_get_i32(in);
    t->vertex = lc_get_i32(in);
    t->edge = lc_get_i32(in);
    t->elasticity = lc_get_finite(in, "a touch's elasticity");
    t->friction = lc_get_finite(in, "a touch's friction");
    t->p = lc_get_vec(in);
    t->n = lc_get_vec(in);
    t->ra = lc_get_vec(in);
    t->rb = lc_get_vec(in);
    t->gap = lc_get_f64(in);
    t->vn = lc_get_f64(in);
    t->value = lc_get_f64(in);
    t->vn_pre = lc_get_f64(in);
    t->target_vn = lc_get_f64(in);
    t->tangent = lc_get_f64(in);
    if (in->bad) return;
    if (t->a < 0 || t->a >= w->count || t->b < 0 || t->b >= w->count || t->a == t->b ||
        t->vertex < 0 || t->vertex >= w->shape[t->a].count || t->edge < 0 || t->edge >= w->shape[t->b].count) {
        lc_reader_fail(in, "a kept touch names rows %d, %d, vertex %d, edge %d outside the world's bodies", t->a, t->b,
                       t->vertex, t->edge);
        memset(t, 0, sizeof *t);
    }
}

void lc_get_contact(lc_reader *in, lc_contact *c)
{
    int kind;
    memset(c, 0, sizeof *c);
    c->body_a = lc_get_u32(in);
    c->body_b = lc_get_u32(in);
    c->point = lc_get_vec(in);
    c->normal = lc_get_vec(in);
    c->gap = lc_get_f64(in);
    c->normal_velocity = lc_get_f64(in);
    c->impulse = lc_get_f64(in);
    c->tangent_impulse = lc_get_f64(in);
    c->force = lc_get_f64(in);
    c->time = lc_get_f64(in);
    kind = lc_get_i32(in);
    if (kind != LC_CONTACT_COLLISION && kind != LC_CONTACT_RESTING) lc_reader_fail(in, "a contact's kind is %d", kind);
    c->kind = kind == LC_CONTACT_RESTING ? LC_CONTACT_RESTING : LC_CONTACT_COLLISION;
}
