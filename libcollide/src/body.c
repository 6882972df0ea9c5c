/* Bodies: their rows and ids, adding them (one polygon, or the four walls of a box) and removing them,
 * reading and setting their states, poses, velocities, masses, inertias, materials and external forces,
 * and reading their vertices and centres of mass. A body is a row of the world's arrays, one array a
 * field, in insertion order. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "event_regime.h"

int lc_world_body_index(const lc_world *w, lc_body_id id)
{
    if (w == NULL || id == 0 || (size_t)id >= w->id_map_cap) return -1;
    return w->id_to_row[id];
}

int lc_world_body_count(const lc_world *w) { return w ? w->count : 0; }

lc_status lc_read_row(const lc_world *w, lc_body_id id, int outputs_ok, const char *what, int *row)
{
    if (w == NULL) return LC_ERR_NULL;
    if (!outputs_ok) return lc_fail((lc_world *)w, LC_ERR_NULL, "%s is NULL", what);
    *row = lc_world_body_index(w, id);
    if (*row < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
    return LC_OK;
}

/* A given inertia (kg*m^2) of a dynamic body of `mass` whose farthest vertex is `radius` from its centre
 * of mass: finite, > 0, its inverse finite, and at most mass * radius^2, the most any mass inside the
 * polygon can have. */
static lc_status check_inertia(lc_world *w, double inertia, double mass, double radius)
{
    double most = mass * radius * radius;
    LC_CHECK_FINITE(w, inertia, "inertia");
    if (!(inertia > 0.0) || !isfinite(1.0 / inertia))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "inertia = %g kg*m^2 must be > 0 (0 in a body def: the polygon's)", inertia);
    if (inertia > most)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "inertia = %g kg*m^2 exceeds mass * r^2 = %g (r = %g m, the farthest vertex "
                       "from the centre of mass): no mass inside the polygon has that much", inertia, most, radius);
    return LC_OK;
}

#define GROW(ptr, n) do { void *p_ = realloc((ptr), (size_t)(n) * sizeof *(ptr)); if (!p_) return 0; (ptr) = p_; } while (0)

/* Room for cap rows of the trig cache, starting on a cache line (world.h): 1, or 0 without memory. */
static int grow_trig(lc_world *w, int cap)
{
    unsigned char *block = malloc((size_t)cap * sizeof(lc_trig) + LC_TRIG_ALIGN - 1);
    size_t skip;
    if (block == NULL) return 0;
    skip = (LC_TRIG_ALIGN - (size_t)((uintptr_t)block % LC_TRIG_ALIGN)) % LC_TRIG_ALIGN;
    if (w->count > 0) memcpy(block + skip, w->trig, (size_t)w->count * sizeof(lc_trig));
    free(w->trig_block);
    w->trig_block = block;
    w->trig = (lc_trig *)(void *)(block + skip);
    return 1;
}

static int reserve_bodies(lc_world *w, int need)
{
    int cap;
    if (need <= w->capacity) return 1;
    cap = w->capacity ? w->capacity * 2 : 16;
    while (cap < need) cap *= 2;
    GROW(w->ids, cap); GROW(w->mass, cap); GROW(w->inertia, cap); GROW(w->inv_mass, cap);
    GROW(w->inv_inertia, cap); GROW(w->is_static, cap); GROW(w->elasticity, cap); GROW(w->friction, cap);
    GROW(w->ext_force, cap); GROW(w->ext_torque, cap); GROW(w->shape, cap); GROW(w->radius, cap);
    GROW(w->outline, cap); GROW(w->thrusters, cap); GROW(w->thruster_count, cap); GROW(w->rests_dissipative, cap);
    GROW(w->state, (size_t)cap * LC_STATE_SIZE);
    if (!grow_trig(w, cap)) return 0;
    w->capacity = cap;
    return 1;
}

static int reserve_id(lc_world *w, lc_body_id id)
{
    if ((size_t)id < w->id_map_cap) return 1;
    {
        size_t cap = w->id_map_cap ? w->id_map_cap * 2 : 64, i;
        int *p;
        while (cap <= (size_t)id) cap *= 2;
        p = realloc(w->id_to_row, cap * sizeof *p);
        if (p == NULL) return 0;
        for (i = w->id_map_cap; i < cap; ++i) p[i] = -1;
        w->id_to_row = p;
        w->id_map_cap = cap;
    }
    return 1;
}

int lc_world_reserve(lc_world *w, int bodies, lc_body_id id) { return reserve_bodies(w, bodies) && reserve_id(w, id); }

lc_status lc_world_add_body(lc_world *w, const lc_body_def *d, lc_body_id *out_id)
{
    lc_shape shape;
    lc_vec2 store[2 * LC_MAX_POLYGON_VERTICES];
    char why[160];
    lc_status s;
    int row;
    double c, sn;
    lc_vec2 cm;
    if (w == NULL) return LC_ERR_NULL;
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "body def is NULL");
    if (out_id == NULL) return lc_fail(w, LC_ERR_NULL, "out_id is NULL (the new body's id must go somewhere)");
    if (d->type != LC_BODY_DYNAMIC && d->type != LC_BODY_STATIC)
        return lc_fail(w, LC_ERR_BAD_ENUM, "body type = %d is not an lc_body_type", (int)d->type);
    LC_TRY(lc_check_vec(w, d->position, 1e9, "position"));
    LC_CHECK_RANGE(w, d->angle, -1e9, 1e9, "angle");
    LC_TRY(lc_check_vec(w, d->velocity, 1e8, "velocity"));
    LC_CHECK_RANGE(w, d->angular_velocity, -1e8, 1e8, "angular_velocity");
    if (d->type == LC_BODY_DYNAMIC) {
        LC_CHECK_FINITE(w, d->mass, "mass");
        if (!(d->mass > 0.0) || d->mass > 1e12)
            return lc_fail(w, LC_ERR_OUT_OF_RANGE, "mass = %g must be in (0, 1e12] kg for a dynamic body", d->mass);
    }
    LC_CHECK_RANGE(w, d->elasticity, 0.0, 1.0, "elasticity");
    LC_CHECK_RANGE(w, d->friction, 0.0, 10.0, "friction");
    if (d->custom_center_of_mass != 0 && d->custom_center_of_mass != 1)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "custom_center_of_mass = %d is 0 (the centroid) or 1", d->custom_center_of_mass);
    s = lc_shape_build(&shape, store, d->vertices, d->vertex_count, d->custom_center_of_mass ? &d->center_of_mass : NULL,
                       why, sizeof why);
    if (s != LC_OK) return lc_fail(w, s, "%s", why);
    if (d->type == LC_BODY_DYNAMIC && d->inertia != 0.0) {
        LC_TRY(check_inertia(w, d->inertia, d->mass, shape.radius));
        shape.inertia_per_mass = d->inertia / d->mass;
    }
    if (w->next_body_id == LC_WORLD_ANCHOR) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body ids exhausted");
    if (!reserve_bodies(w, w->count + 1) || !reserve_id(w, w->next_body_id) || lc_shape_keep(&shape, shape.count) != 0)
        return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory adding a body");
    row = w->count++;
    w->edits++;
    w->ids[row] = w->next_body_id;
    w->id_to_row[w->next_body_id] = row;
    if (out_id) *out_id = w->next_body_id;
    w->next_body_id++;
    w->shape[row] = shape;
    w->radius[row] = shape.radius;
    w->outline[row].v = shape.v;
    w->outline[row].count = shape.count;
    lc_trig_clear(&w->trig[row]);
    c = cos(d->angle);
    sn = sin(d->angle);
    cm = lc_add(d->position, lc_rot(c, sn, shape.center_offset));
    w->is_static[row] = d->type == LC_BODY_STATIC;
    w->state[row * 6 + SX] = cm.x;
    w->state[row * 6 + SY] = cm.y;
    w->state[row * 6 + SA] = d->angle;
    if (w->is_static[row]) {
        w->state[row * 6 + SVX] = w->state[row * 6 + SVY] = w->state[row * 6 + SW] = 0.0;
        w->mass[row] = w->inertia[row] = w->inv_mass[row] = w->inv_inertia[row] = 0.0;
    } else {
        w->state[row * 6 + SVX] = d->velocity.x;
        w->state[row * 6 + SVY] = d->velocity.y;
        w->state[row * 6 + SW] = d->angular_velocity;
        w->mass[row] = d->mass;
        w->inertia[row] = d->inertia != 0.0 ? d->inertia : d->mass * shape.unit_inertia;
        w->inv_mass[row] = 1.0 / d->mass;
        w->inv_inertia[row] = 1.0 / w->inertia[row];
    }
    w->elasticity[row] = d->elasticity;
    w->friction[row] = d->friction;
    w->ext_force[row] = lc_v(0.0, 0.0);
    w->ext_torque[row] = 0.0;
    w->thruster_count[row] = 0;
    w->rests_dissipative[row] = 0;
    return lc_changed(w);
}

lc_status lc_world_add_walls(lc_world *w, double xmin, double ymin, double xmax, double ymax,
                             double t, double e, lc_body_id out_ids[4])
{
    lc_vec2 v[4];
    lc_body_def d = lc_default_body_def();
    lc_body_id ids[4];
    int i, before;
    if (w == NULL) return LC_ERR_NULL;
    LC_CHECK_RANGE(w, xmin, -1e9, 1e9, "xmin");
    LC_CHECK_RANGE(w, ymin, -1e9, 1e9, "ymin");
    LC_CHECK_RANGE(w, xmax, -1e9, 1e9, "xmax");
    LC_CHECK_RANGE(w, ymax, -1e9, 1e9, "ymax");
    LC_CHECK_RANGE(w, t, 1e-6, 1e6, "thickness");
    LC_CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
    if (!(xmax > xmin) || !(ymax > ymin))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "walls need xmax > xmin and ymax > ymin (got [%g, %g] x [%g, %g])", xmin, xmax, ymin, ymax);
    d.type = LC_BODY_STATIC;
    d.elasticity = e;
    d.vertices = v;
    d.vertex_count = 4;
    before = w->count;
    {
        /* bottom and top span the full outer width so the box has no open corners */
        double W = xmax - xmin + 2 * t, H = ymax - ymin;
        lc_vec2 pos[4];
        double wid[4], hei[4];
        pos[0] = lc_v((xmin + xmax) / 2, ymin - t / 2); wid[0] = W; hei[0] = t;
        pos[1] = lc_v(xmax + t / 2, (ymin + ymax) / 2); wid[1] = t; hei[1] = H;
        pos[2] = lc_v((xmin + xmax) / 2, ymax + t / 2); wid[2] = W; hei[2] = t;
        pos[3] = lc_v(xmin - t / 2, (ymin + ymax) / 2); wid[3] = t; hei[3] = H;
        for (i = 0; i < 4; ++i) {
            lc_status s = lc_make_rectangle(wid[i], hei[i], v);
            if (s == LC_OK) {
                d.position = pos[i];
                s = lc_world_add_body(w, &d, &ids[i]);
            } else {
                s = lc_fail(w, s, "wall %d has an invalid size", i);
            }
            if (s != LC_OK) {
                /* the rollback's successful removals clear the message: keep the failure's */
                char why[sizeof w->error];
                memcpy(why, w->error, sizeof why);
                while (w->count > before) lc_world_remove_body(w, w->ids[w->count - 1]);
                return lc_fail(w, s, "%s", why);
            }
        }
    }
    if (out_ids) for (i = 0; i < 4; ++i) out_ids[i] = ids[i];
    return lc_changed(w);
}

lc_status lc_world_remove_body(lc_world *w, lc_body_id id)
{
    int row, i, n;
    if (w == NULL) return LC_ERR_NULL;
    row = lc_world_body_index(w, id);
    if (row < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
    n = w->count - row - 1;
    lc_shape_release(&w->shape[row]);
    /* shift rows down to keep insertion order (deterministic and what callers index by) */
#define SHIFT(arr, k) memmove(&(arr)[(size_t)row * (k)], &(arr)[(size_t)(row + 1) * (k)], (size_t)n * (k) * sizeof *(arr))
    SHIFT(w->ids, 1); SHIFT(w->mass, 1); SHIFT(w->inertia, 1); SHIFT(w->inv_mass, 1); SHIFT(w->inv_inertia, 1);
    SHIFT(w->is_static, 1); SHIFT(w->elasticity, 1); SHIFT(w->friction, 1); SHIFT(w->ext_force, 1);
    SHIFT(w->ext_torque, 1); SHIFT(w->shape, 1); SHIFT(w->radius, 1); SHIFT(w->outline, 1); SHIFT(w->trig, 1);
    SHIFT(w->thrusters, 1); SHIFT(w->thruster_count, 1); SHIFT(w->rests_dissipative, 1);
    SHIFT(w->state, LC_STATE_SIZE);
#undef SHIFT
    w->count--;
    w->edits++;
    w->id_to_row[id] = -1;
    for (i = row; i < w->count; ++i) w->id_to_row[w->ids[i]] = i;
    lc_remove_springs_of(w, id);
    w->contact_count = 0;
    lc_event_regime_rows_shifted(w->event);   /* kept touches refer to rows, which just shifted */
    return lc_changed(w);
}

lc_status lc_world_get_state(const lc_world *w, lc_state_view *out)
{
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    out->count = w->count;
    out->ids = w->ids;
    out->state = w->state;
    out->mass = w->mass;
    out->inertia = w->inertia;
    out->is_static = w->is_static;
    return LC_OK;
}

lc_status lc_world_set_state(lc_world *w, const double *state, int count)
{
    int i, k;
    if (w == NULL) return LC_ERR_NULL;
    if (state == NULL) return lc_fail(w, LC_ERR_NULL, "state is NULL");
    if (count != w->count) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "state has %d rows but the world has %d bodies", count, w->count);
    for (i = 0; i < count; ++i) {
        if (w->is_static[i]) continue;
        for (k = 0; k < 6; ++k) {
            double lim = k < 3 ? 1e9 : 1e8;
            if (!isfinite(state[i * 6 + k]))
                return lc_fail(w, LC_ERR_NOT_FINITE, "state[%d][%d] is not finite", i, k);
            if (fabs(state[i * 6 + k]) > lim)
                return lc_fail(w, LC_ERR_OUT_OF_RANGE, "state[%d][%d] = %g exceeds %g", i, k, state[i * 6 + k], lim);
        }
    }
    for (i = 0; i < count; ++i)
        if (!w->is_static[i]) memcpy(&w->state[i * 6], &state[i * 6], 6 * sizeof(double));
    w->contact_count = 0;
    w->edits++;
    return lc_changed(w);
}

lc_status lc_body_set_pose(lc_world *w, lc_body_id id, lc_vec2 center, double angle)
{
    int row;
    LC_GET_ROW(w, id, row);
    LC_TRY(lc_check_vec(w, center, 1e9, "center"));
    LC_CHECK_RANGE(w, angle, -1e9, 1e9, "angle");
    w->state[row * 6 + SX] = center.x;
    w->state[row * 6 + SY] = center.y;
    w->state[row * 6 + SA] = angle;
    w->contact_count = 0;
    w->edits++;
    return lc_changed(w);
}

lc_status lc_body_set_velocity(lc_world *w, lc_body_id id, lc_vec2 v, double omega)
{
    int row;
    LC_GET_DYNAMIC_ROW(w, id, row);
    LC_TRY(lc_check_vec(w, v, 1e8, "velocity"));
    LC_CHECK_RANGE(w, omega, -1e8, 1e8, "angular_velocity");
    w->state[row * 6 + SVX] = v.x;
    w->state[row * 6 + SVY] = v.y;
    w->state[row * 6 + SW] = omega;
    w->edits++;
    return lc_changed(w);
}

lc_status lc_body_set_mass(lc_world *w, lc_body_id id, double mass)
{
    int row;
    LC_GET_DYNAMIC_ROW(w, id, row);
    LC_CHECK_FINITE(w, mass, "mass");
    if (!(mass > 0.0) || mass > 1e12) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "mass = %g must be in (0, 1e12] kg", mass);
    w->mass[row] = mass;
    w->inertia[row] = mass * w->shape[row].inertia_per_mass;
    w->inv_mass[row] = 1.0 / mass;
    w->inv_inertia[row] = 1.0 / w->inertia[row];
    w->edits++;
    return lc_changed(w);
}

/* The body's inertia (which = 1) or mass (which = 0): the readers of lc_body_get_mass and _inertia. */
static lc_status read_mass_or_inertia(const lc_world *w, lc_body_id id, int which, double *out)
{
    int row = -1;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    *out = which ? w->inertia[row] : w->mass[row];
    return LC_OK;
}

lc_status lc_body_get_mass(const lc_world *w, lc_body_id id, double *out)
{
    return read_mass_or_inertia(w, id, 0, out);
}

lc_status lc_body_set_inertia(lc_world *w, lc_body_id id, double inertia)
{
    int row;
    lc_shape *sh;
    LC_GET_DYNAMIC_ROW(w, id, row);
    sh = &w->shape[row];
    if (inertia != 0.0) LC_TRY(check_inertia(w, inertia, w->mass[row], sh->radius));
    sh->inertia_per_mass = inertia != 0.0 ? inertia / w->mass[row] : sh->unit_inertia;
    w->inertia[row] = inertia != 0.0 ? inertia : w->mass[row] * sh->unit_inertia;
    w->inv_inertia[row] = 1.0 / w->inertia[row];
    w->edits++;
    return lc_changed(w);
}

lc_status lc_body_get_inertia(const lc_world *w, lc_body_id id, double *out)
{
    return read_mass_or_inertia(w, id, 1, out);
}

lc_status lc_body_set_material(lc_world *w, lc_body_id id, double e, double mu)
{
    int row;
    LC_GET_ROW(w, id, row);
    LC_CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
    LC_CHECK_RANGE(w, mu, 0.0, 10.0, "friction");
    w->elasticity[row] = e;
    w->friction[row] = mu;
    w->edits++;
    return lc_changed(w);
}

lc_status lc_body_get_material(const lc_world *w, lc_body_id id, double *e, double *mu)
{
    int row = -1;
    LC_TRY(lc_read_row(w, id, e != NULL && mu != NULL, "elasticity or friction output", &row));
    *e = w->elasticity[row];
    *mu = w->friction[row];
    return LC_OK;
}

lc_status lc_body_set_external(lc_world *w, lc_body_id id, lc_vec2 force, double torque)
{
    int row;
    LC_GET_DYNAMIC_ROW(w, id, row);
    LC_TRY(lc_check_vec(w, force, 1e12, "force"));
    LC_CHECK_RANGE(w, torque, -1e12, 1e12, "torque");
    w->ext_force[row] = force;
    w->ext_torque[row] = torque;
    return lc_changed(w);
}

lc_status lc_body_get_external(const lc_world *w, lc_body_id id, lc_vec2 *force, double *torque)
{
    int row = -1;
    LC_TRY(lc_read_row(w, id, force != NULL && torque != NULL, "force or torque output", &row));
    *force = w->ext_force[row];
    *torque = w->ext_torque[row];
    return LC_OK;
}

int lc_body_vertex_count(const lc_world *w, lc_body_id id)
{
    int row = lc_world_body_index(w, id);
    return row < 0 ? -1 : w->shape[row].count;
}

lc_status lc_body_get_local_vertices(const lc_world *w, lc_body_id id, lc_vec2 *out, int capacity)
{
    int row = -1, i;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    if (capacity < w->shape[row].count)
        return lc_fail((lc_world *)w, LC_ERR_OUT_OF_RANGE, "capacity %d is below the body's %d vertices", capacity, w->shape[row].count);
    for (i = 0; i < w->shape[row].count; ++i) out[i] = w->shape[row].v[i];
    return LC_OK;
}

lc_status lc_body_get_world_vertices(const lc_world *w, lc_body_id id, lc_vec2 *out, int capacity)
{
    int row = -1, i;
    double c, s;
    const double *st;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    if (capacity < w->shape[row].count)
        return lc_fail((lc_world *)w, LC_ERR_OUT_OF_RANGE, "capacity %d is below the body's %d vertices", capacity, w->shape[row].count);
    st = &w->state[row * 6];
    c = cos(st[SA]);
    s = sin(st[SA]);
    for (i = 0; i < w->shape[row].count; ++i)
        out[i] = lc_add(lc_v(st[SX], st[SY]), lc_rot(c, s, w->shape[row].v[i]));
    return LC_OK;
}

lc_status lc_body_get_center_offset(const lc_world *w, lc_body_id id, lc_vec2 *out)
{
    int row = -1;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    *out = w->shape[row].center_offset;
    return LC_OK;
}
