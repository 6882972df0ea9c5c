/* Springs: adding, removing and changing them, where their ends are, and dropping a removed body's
 * springs with it (lc_remove_springs_of, for body.c). forces.c turns them into forces and energy. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"

static int spring_index(const lc_world *w, lc_spring_id id)
{
    int i;
    if (w == NULL) return -1;
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].id == id) return i;
    return -1;
}

static lc_status check_spring_params(lc_world *w, double k, double d, double L0)
{
    LC_CHECK_RANGE(w, k, 0.0, 1e9, "stiffness");
    LC_CHECK_RANGE(w, d, 0.0, 1e9, "damping");
    LC_CHECK_RANGE(w, L0, 0.0, 1e6, "rest_length");
    return LC_OK;
}

lc_status lc_world_add_spring(lc_world *w, const lc_spring_def *d, lc_spring_id *out_id)
{
    int ra, rb = -1;
    if (w == NULL) return LC_ERR_NULL;
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "spring def is NULL");
    ra = lc_world_body_index(w, d->body_a);
    if (ra < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "spring body_a: no body with id %u", (unsigned)d->body_a);
    if (w->is_static[ra]) return lc_fail(w, LC_ERR_STATIC_BODY, "spring body_a %u is static", (unsigned)d->body_a);
    if (d->body_b != LC_WORLD_ANCHOR) {
        rb = lc_world_body_index(w, d->body_b);
        if (rb < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "spring body_b: no body with id %u", (unsigned)d->body_b);
        if (rb == ra) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "spring joins body %u to itself", (unsigned)d->body_a);
    }
    LC_TRY(lc_check_vec(w, d->point_a, 1e6, "point_a"));
    LC_TRY(lc_check_vec(w, d->point_b, 1e9, "point_b"));
    LC_TRY(check_spring_params(w, d->stiffness, d->damping, d->rest_length));
    if (w->spring_count == w->spring_cap) {
        int cap = w->spring_cap ? w->spring_cap * 2 : 8;
        void *p = realloc(w->springs, (size_t)cap * sizeof *w->springs);
        if (p == NULL) return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory adding a spring");
        w->springs = p;
        w->spring_cap = cap;
    }
    w->springs[w->spring_count].id = w->next_spring_id;
    w->springs[w->spring_count].def = *d;
    w->spring_count++;
    if (out_id) *out_id = w->next_spring_id;
    w->next_spring_id++;
    return lc_changed(w);
}

lc_status lc_world_remove_spring(lc_world *w, lc_spring_id id)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    memmove(&w->springs[i], &w->springs[i + 1], (size_t)(w->spring_count - i - 1) * sizeof *w->springs);
    w->spring_count--;
    return lc_changed(w);
}

void lc_remove_springs_of(lc_world *w, lc_body_id id)
{
    int i, j = 0;
    for (i = 0; i < w->spring_count; ++i) {
        if (w->springs[i].def.body_a == id || w->springs[i].def.body_b == id) continue;
        w->springs[j++] = w->springs[i];
    }
    w->spring_count = j;
}

lc_status lc_spring_set_target(lc_world *w, lc_spring_id id, lc_vec2 target)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    if (w->springs[i].def.body_b != LC_WORLD_ANCHOR)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "spring %u joins two bodies; it has no world target", (unsigned)id);
    LC_TRY(lc_check_vec(w, target, 1e9, "target"));
    w->springs[i].def.point_b = target;
    return lc_changed(w);
}

lc_status lc_spring_set_params(lc_world *w, lc_spring_id id, double k, double d, double L0)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    LC_TRY(check_spring_params(w, k, d, L0));
    w->springs[i].def.stiffness = k;
    w->springs[i].def.damping = d;
    w->springs[i].def.rest_length = L0;
    return lc_changed(w);
}

lc_status lc_spring_get_def(const lc_world *w, lc_spring_id id, lc_spring_def *out)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    if (i < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    *out = w->springs[i].def;
    return LC_OK;
}

/* World point of a body-local (local-origin frame) point at state. */
static lc_vec2 body_point(const lc_world *w, const double *state, int row, lc_vec2 local)
{
    const double *s = &state[row * 6];
    double c = cos(s[SA]), sn = sin(s[SA]);
    return lc_add(lc_v(s[SX], s[SY]), lc_rot(c, sn, lc_sub(local, w->shape[row].center_offset)));
}

lc_status lc_spring_get_endpoints(const lc_world *w, lc_spring_id id, lc_vec2 *a, lc_vec2 *b)
{
    int i = spring_index(w, id);
    const lc_spring_def *d;
    if (w == NULL) return LC_ERR_NULL;
    if (a == NULL || b == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "endpoint output is NULL");
    if (i < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    d = &w->springs[i].def;
    *a = body_point(w, w->state, lc_world_body_index(w, d->body_a), d->point_a);
    *b = d->body_b == LC_WORLD_ANCHOR ? d->point_b : body_point(w, w->state, lc_world_body_index(w, d->body_b), d->point_b);
    return LC_OK;
}

int lc_world_spring_count(const lc_world *w) { return w ? w->spring_count : 0; }
