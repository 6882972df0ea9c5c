/* World lifetime, settings validation, bodies, thrusters and springs: the bookkeeping side of the API. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "collide/version.h"
#include "world.h"
#include "sleep.h"
#include "islands.h"
#include "contact_regime.h"
#include "event_regime.h"

/* ---- scratch and errors ------------------------------------------------------------------ */

void *lc_buf_get(lc_buf *b, size_t bytes)
{
    if (bytes == 0) bytes = 1;
    if (b->cap < bytes) {
        size_t cap = b->cap ? b->cap : 256;
        void *p;
        while (cap < bytes) cap *= 2;
        p = realloc(b->p, cap);
        if (p == NULL) return NULL;
        b->p = p;
        b->cap = cap;
    }
    return b->p;
}

void lc_buf_free(lc_buf *b)
{
    free(b->p);
    b->p = NULL;
    b->cap = 0;
}

lc_status lc_fail(lc_world *w, lc_status s, const char *fmt, ...)
{
    va_list ap;
    if (w != NULL) {
        va_start(ap, fmt);
        vsnprintf(w->error, sizeof w->error, fmt, ap);
        va_end(ap);
    }
    return s;
}

static lc_status ok(lc_world *w)
{
    w->error[0] = '\0';
    return LC_OK;
}

/* ok() for a call that changed something a step reads: sleeping bodies wake (sleep.c) */
static lc_status changed(lc_world *w)
{
    w->api_changes++;
    return ok(w);
}

const char *lc_status_string(lc_status status)
{
    switch (status) {
    case LC_OK: return "ok";
    case LC_ERR_NULL: return "null pointer";
    case LC_ERR_NOT_FINITE: return "not a finite number";
    case LC_ERR_OUT_OF_RANGE: return "out of range";
    case LC_ERR_BAD_POLYGON: return "bad polygon";
    case LC_ERR_UNKNOWN_BODY: return "unknown body";
    case LC_ERR_UNKNOWN_SPRING: return "unknown spring";
    case LC_ERR_UNKNOWN_THRUSTER: return "unknown thruster";
    case LC_ERR_STATIC_BODY: return "static body";
    case LC_ERR_NO_MEMORY: return "out of memory";
    case LC_ERR_NUMERIC: return "numerical failure";
    case LC_ERR_BAD_ENUM: return "unknown enum value";
    }
    return "unknown status";
}

const char *lc_version(void) { return LC_VERSION_STRING; }

/* ---- defaults ------------------------------------------------------------------------------ */

lc_world_def lc_default_world_def(void)
{
    lc_world_def d;
    memset(&d, 0, sizeof d);
    d.gravity = lc_v(0.0, -9.81);
    d.zero_energy_level = 0.0;
    d.damping = 0.0;
    d.damping_rotation_ratio = 0.1;
    d.integrator = LC_INTEGRATOR_RK4;
    d.impact_mode = LC_IMPACT_SERIAL;
    d.toi_method = LC_TOI_ROOT_FINDER;
    d.toi_time_tolerance = 1e-10;
    d.toi_distance_tolerance = 1e-10;
    d.toi_max_iterations = 100;
    d.contact_gap = 1e-7;
    d.contact_distance = 1e-5;
    d.resting_speed = 1e-4;
    d.restitution_threshold = 1e-2;
    d.stabilization = LC_STABILIZE_VELOCITY;
    d.elasticity_rule = LC_MIX_MIN;
    d.friction_rule = LC_MIX_GEOMETRIC;
    d.max_events_per_step = 10000;
    d.max_serial_iterations = 1000;
    d.lcp_exact_max = 128;
    d.lcp_max_iterations = 200;
    d.lcp_tolerance = 1e-10;
    d.broadphase = LC_BROADPHASE_AUTO;
    d.broadphase_threshold = 32;
    d.regime = LC_REGIME_AUTO;
    d.contact_iterations = 30;
    d.contact_tolerance = 1e-10;
    d.allow_sleep = 0;
    d.sleep_time = 0.5;
    d.sleep_speed = 1e-4;
    return d;
}

lc_body_def lc_default_body_def(void)
{
    lc_body_def d;
    memset(&d, 0, sizeof d);
    d.type = LC_BODY_DYNAMIC;
    d.mass = 1.0;
    d.elasticity = 1.0;
    d.friction = 0.0;
    return d;
}

lc_spring_def lc_default_spring_def(void)
{
    lc_spring_def d;
    memset(&d, 0, sizeof d);
    d.body_b = LC_WORLD_ANCHOR;
    d.stiffness = 3.0;
    return d;
}

/* ---- validation helpers ---------------------------------------------------------------------- */

#define CHECK_FINITE(w, val, name) \
    do { if (!isfinite(val)) return lc_fail((w), LC_ERR_NOT_FINITE, "%s is not finite (%g)", (name), (double)(val)); } while (0)
#define CHECK_RANGE(w, val, lo, hi, name) \
    do { CHECK_FINITE(w, val, name); \
         if ((val) < (lo) || (val) > (hi)) return lc_fail((w), LC_ERR_OUT_OF_RANGE, "%s = %g is outside [%g, %g]", (name), (double)(val), (double)(lo), (double)(hi)); } while (0)
#define CHECK_IRANGE(w, val, lo, hi, name) \
    do { if ((val) < (lo) || (val) > (hi)) return lc_fail((w), LC_ERR_OUT_OF_RANGE, "%s = %d is outside [%d, %d]", (name), (int)(val), (int)(lo), (int)(hi)); } while (0)

static int mix_rule_ok(lc_mix_rule r) { return r == LC_MIX_MIN || r == LC_MIX_MAX || r == LC_MIX_MEAN || r == LC_MIX_GEOMETRIC; }

static lc_status validate_world_def(lc_world *w, const lc_world_def *d)
{
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "world def is NULL");
    CHECK_RANGE(w, d->gravity.x, -1e6, 1e6, "gravity.x");
    CHECK_RANGE(w, d->gravity.y, -1e6, 1e6, "gravity.y");
    CHECK_RANGE(w, d->zero_energy_level, -1e9, 1e9, "zero_energy_level");
    CHECK_RANGE(w, d->damping, 0.0, 1e9, "damping");
    CHECK_RANGE(w, d->damping_rotation_ratio, 0.0, 1e9, "damping_rotation_ratio");
    if (d->integrator != LC_INTEGRATOR_EULER && d->integrator != LC_INTEGRATOR_MIDPOINT && d->integrator != LC_INTEGRATOR_RK4)
        return lc_fail(w, LC_ERR_BAD_ENUM, "integrator = %d is not an lc_integrator", (int)d->integrator);
    if (d->impact_mode != LC_IMPACT_SERIAL && d->impact_mode != LC_IMPACT_SIMULTANEOUS)
        return lc_fail(w, LC_ERR_BAD_ENUM, "impact_mode = %d is not an lc_impact_mode", (int)d->impact_mode);
    if (d->toi_method != LC_TOI_ROOT_FINDER && d->toi_method != LC_TOI_BINARY_SEARCH)
        return lc_fail(w, LC_ERR_BAD_ENUM, "toi_method = %d is not an lc_toi_method", (int)d->toi_method);
    CHECK_RANGE(w, d->toi_time_tolerance, 1e-15, 1e-2, "toi_time_tolerance");
    CHECK_RANGE(w, d->toi_distance_tolerance, 1e-15, 1e-2, "toi_distance_tolerance");
    CHECK_IRANGE(w, d->toi_max_iterations, 4, 1000, "toi_max_iterations");
    CHECK_RANGE(w, d->contact_gap, 1e-12, 1e-2, "contact_gap");
    CHECK_RANGE(w, d->contact_distance, 1e-12, 1.0, "contact_distance");
    if (!(d->contact_distance > d->contact_gap))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "contact_distance = %g must exceed contact_gap = %g", d->contact_distance, d->contact_gap);
    if (!(d->toi_distance_tolerance < d->contact_gap))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "toi_distance_tolerance = %g must be below contact_gap = %g", d->toi_distance_tolerance, d->contact_gap);
    CHECK_RANGE(w, d->resting_speed, 0.0, 10.0, "resting_speed");
    CHECK_RANGE(w, d->restitution_threshold, 0.0, 10.0, "restitution_threshold");
    if (d->stabilization != LC_STABILIZE_NONE && d->stabilization != LC_STABILIZE_VELOCITY && d->stabilization != LC_STABILIZE_VELOCITY_AND_DISTANCE)
        return lc_fail(w, LC_ERR_BAD_ENUM, "stabilization = %d is not an lc_stabilization", (int)d->stabilization);
    if (!mix_rule_ok(d->elasticity_rule)) return lc_fail(w, LC_ERR_BAD_ENUM, "elasticity_rule = %d is not an lc_mix_rule", (int)d->elasticity_rule);
    if (!mix_rule_ok(d->friction_rule)) return lc_fail(w, LC_ERR_BAD_ENUM, "friction_rule = %d is not an lc_mix_rule", (int)d->friction_rule);
    CHECK_IRANGE(w, d->max_events_per_step, 1, 1000000, "max_events_per_step");
    CHECK_IRANGE(w, d->max_serial_iterations, 1, 1000000, "max_serial_iterations");
    CHECK_IRANGE(w, d->lcp_exact_max, 0, 4096, "lcp_exact_max");
    CHECK_IRANGE(w, d->lcp_max_iterations, 1, 1000000, "lcp_max_iterations");
    CHECK_RANGE(w, d->lcp_tolerance, 0.0, 1.0, "lcp_tolerance");
    if (d->broadphase != LC_BROADPHASE_AUTO && d->broadphase != LC_BROADPHASE_BRUTE_FORCE && d->broadphase != LC_BROADPHASE_SORT_AND_SWEEP)
        return lc_fail(w, LC_ERR_BAD_ENUM, "broadphase = %d is not an lc_broadphase", (int)d->broadphase);
    CHECK_IRANGE(w, d->broadphase_threshold, 2, 1000000, "broadphase_threshold");
    if (d->regime != LC_REGIME_AUTO && d->regime != LC_REGIME_EVENT && d->regime != LC_REGIME_CONTACT)
        return lc_fail(w, LC_ERR_BAD_ENUM, "regime = %d is not an lc_regime", (int)d->regime);
    CHECK_IRANGE(w, d->contact_iterations, 1, 1000000, "contact_iterations");
    CHECK_RANGE(w, d->contact_tolerance, 0.0, 1.0, "contact_tolerance");
    CHECK_IRANGE(w, d->allow_sleep, 0, 1, "allow_sleep");
    CHECK_FINITE(w, d->sleep_time, "sleep_time");
    if (!(d->sleep_time > 0.0 && d->sleep_time <= 1e6))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "sleep_time = %g is outside (0, 1e6] s", d->sleep_time);
    CHECK_RANGE(w, d->sleep_speed, 0.0, 10.0, "sleep_speed");
    return LC_OK;
}

/* ---- world --------------------------------------------------------------------------------- */

lc_world *lc_world_create(const lc_world_def *def, char *errbuf, size_t errbuf_len)
{
    lc_world *w = calloc(1, sizeof *w);
    lc_status s;
    if (w == NULL) {
        if (errbuf && errbuf_len) snprintf(errbuf, errbuf_len, "out of memory");
        return NULL;
    }
    s = validate_world_def(w, def);
    if (s == LC_OK) {
        w->step_state = lc_step_state_create();
        w->islands = lc_islands_create();
        w->event = lc_event_regime_create();
        w->contact = lc_contact_regime_create();
        w->broad_phase = lc_broad_phase_state_create();
        w->integrator = lc_integrator_state_create();
        w->contact_forces = lc_contact_forces_state_create();
        w->impulse = lc_impulse_state_create();
        w->sparse_lcp = lc_sparse_lcp_state_create();
        w->static_load = lc_static_load_state_create();
        w->sleep = lc_sleep_create();
        w->lcp = lc_lcp_workspace_create();
        if (!w->step_state || !w->islands || !w->event || !w->contact || !w->broad_phase || !w->integrator ||
            !w->contact_forces || !w->impulse || !w->sparse_lcp || !w->static_load || !w->sleep || !w->lcp)
            s = lc_fail(w, LC_ERR_NO_MEMORY, "out of memory");
    }
    if (s != LC_OK) {
        if (errbuf && errbuf_len) snprintf(errbuf, errbuf_len, "%s", w->error);
        lc_world_destroy(w);
        return NULL;
    }
    w->def = *def;
    w->next_body_id = 1;
    w->next_spring_id = 1;
    if (errbuf && errbuf_len) errbuf[0] = '\0';
    return w;
}

void lc_world_destroy(lc_world *w)
{
    if (w == NULL) return;
    free(w->ids); free(w->state); free(w->mass); free(w->inertia); free(w->inv_mass); free(w->inv_inertia);
    free(w->is_static); free(w->elasticity); free(w->friction); free(w->ext_force); free(w->ext_torque);
    free(w->shape); free(w->trig); free(w->thrusters); free(w->thruster_count); free(w->id_to_row);
    free(w->springs); free(w->contacts); free(w->rests_dissipative);
    lc_step_state_destroy(w->step_state);
    lc_islands_destroy(w->islands);
    lc_event_regime_destroy(w->event);
    lc_contact_regime_destroy(w->contact);
    lc_broad_phase_state_destroy(w->broad_phase);
    lc_integrator_state_destroy(w->integrator);
    lc_contact_forces_state_destroy(w->contact_forces);
    lc_impulse_state_destroy(w->impulse);
    lc_sparse_lcp_state_destroy(w->sparse_lcp);
    lc_static_load_state_destroy(w->static_load);
    lc_sleep_destroy(w->sleep);
    lc_lcp_workspace_destroy(w->lcp);
    lc_buf_free(&w->b_pairs);
    lc_buf_free(&w->b_touch);
    free(w);
}

const char *lc_world_last_error(const lc_world *w) { return w ? w->error : "world is NULL"; }

lc_status lc_world_get_def(const lc_world *w, lc_world_def *out)
{
    if (w == NULL || out == NULL) return LC_ERR_NULL;
    *out = w->def;
    return LC_OK;
}

lc_status lc_world_set_def(lc_world *w, const lc_world_def *def)
{
    lc_status s;
    if (w == NULL) return LC_ERR_NULL;
    s = validate_world_def(w, def);
    if (s != LC_OK) return s;
    w->def = *def;
    return changed(w);
}

lc_status lc_world_set_gravity(lc_world *w, lc_vec2 g)
{
    lc_world_def d;
    if (w == NULL) return LC_ERR_NULL;
    d = w->def;
    d.gravity = g;
    return lc_world_set_def(w, &d);
}

lc_status lc_world_set_damping(lc_world *w, double damping, double ratio)
{
    lc_world_def d;
    if (w == NULL) return LC_ERR_NULL;
    d = w->def;
    d.damping = damping;
    d.damping_rotation_ratio = ratio;
    return lc_world_set_def(w, &d);
}

lc_status lc_world_set_elasticity(lc_world *w, double e)
{
    int i;
    if (w == NULL) return LC_ERR_NULL;
    CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
    for (i = 0; i < w->count; ++i) w->elasticity[i] = e;
    w->edits++;
    return changed(w);
}

double lc_world_get_time(const lc_world *w) { return w ? w->time : 0.0; }

/* ---- bodies -------------------------------------------------------------------------------- */

static int row_of(const lc_world *w, lc_body_id id)
{
    if (w == NULL || id == 0 || (size_t)id >= w->id_map_cap) return -1;
    return w->id_to_row[id];
}

int lc_world_body_index(const lc_world *w, lc_body_id id) { return row_of(w, id); }
int lc_world_body_count(const lc_world *w) { return w ? w->count : 0; }

#define GROW(ptr, n) do { void *p_ = realloc((ptr), (size_t)(n) * sizeof *(ptr)); if (!p_) return 0; (ptr) = p_; } while (0)

static int reserve_bodies(lc_world *w, int need)
{
    int cap;
    if (need <= w->capacity) return 1;
    cap = w->capacity ? w->capacity * 2 : 16;
    while (cap < need) cap *= 2;
    GROW(w->ids, cap); GROW(w->mass, cap); GROW(w->inertia, cap); GROW(w->inv_mass, cap);
    GROW(w->inv_inertia, cap); GROW(w->is_static, cap); GROW(w->elasticity, cap); GROW(w->friction, cap);
    GROW(w->ext_force, cap); GROW(w->ext_torque, cap); GROW(w->shape, cap); GROW(w->trig, cap); GROW(w->thrusters, cap);
    GROW(w->thruster_count, cap); GROW(w->rests_dissipative, cap);
    GROW(w->state, (size_t)cap * LC_STATE_SIZE);
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

static lc_status check_vec(lc_world *w, lc_vec2 v, double limit, const char *name)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%s.x", name);
    CHECK_RANGE(w, v.x, -limit, limit, buf);
    snprintf(buf, sizeof buf, "%s.y", name);
    CHECK_RANGE(w, v.y, -limit, limit, buf);
    return LC_OK;
}

#define TRY(expr) do { lc_status s_ = (expr); if (s_ != LC_OK) return s_; } while (0)

lc_status lc_world_add_body(lc_world *w, const lc_body_def *d, lc_body_id *out_id)
{
    lc_shape shape;
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
    TRY(check_vec(w, d->position, 1e9, "position"));
    CHECK_RANGE(w, d->angle, -1e9, 1e9, "angle");
    TRY(check_vec(w, d->velocity, 1e8, "velocity"));
    CHECK_RANGE(w, d->angular_velocity, -1e8, 1e8, "angular_velocity");
    if (d->type == LC_BODY_DYNAMIC) {
        CHECK_FINITE(w, d->mass, "mass");
        if (!(d->mass > 0.0) || d->mass > 1e12)
            return lc_fail(w, LC_ERR_OUT_OF_RANGE, "mass = %g must be in (0, 1e12] kg for a dynamic body", d->mass);
    }
    CHECK_RANGE(w, d->elasticity, 0.0, 1.0, "elasticity");
    CHECK_RANGE(w, d->friction, 0.0, 10.0, "friction");
    s = lc_shape_build(&shape, d->vertices, d->vertex_count, why, sizeof why);
    if (s != LC_OK) return lc_fail(w, s, "%s", why);
    if (w->next_body_id == LC_WORLD_ANCHOR) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body ids exhausted");
    if (!reserve_bodies(w, w->count + 1) || !reserve_id(w, w->next_body_id))
        return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory adding a body");
    row = w->count++;
    w->edits++;
    w->ids[row] = w->next_body_id;
    w->id_to_row[w->next_body_id] = row;
    if (out_id) *out_id = w->next_body_id;
    w->next_body_id++;
    w->shape[row] = shape;
    w->trig[row].angle[0] = w->trig[row].angle[1] = NAN;   /* NaN matches no angle: empty */
    w->trig[row].next = 0;
    w->trig[row].pose[0][2] = w->trig[row].pose[1][2] = NAN;
    w->trig[row].box_next = 0;
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
        w->inertia[row] = d->mass * shape.unit_inertia;
        w->inv_mass[row] = 1.0 / d->mass;
        w->inv_inertia[row] = 1.0 / w->inertia[row];
    }
    w->elasticity[row] = d->elasticity;
    w->friction[row] = d->friction;
    w->ext_force[row] = lc_v(0.0, 0.0);
    w->ext_torque[row] = 0.0;
    w->thruster_count[row] = 0;
    w->rests_dissipative[row] = 0;
    return changed(w);
}

lc_status lc_world_add_walls(lc_world *w, double xmin, double ymin, double xmax, double ymax,
                             double t, double e, lc_body_id out_ids[4])
{
    lc_vec2 v[4];
    lc_body_def d = lc_default_body_def();
    lc_body_id ids[4];
    int i, before;
    if (w == NULL) return LC_ERR_NULL;
    CHECK_RANGE(w, xmin, -1e9, 1e9, "xmin");
    CHECK_RANGE(w, ymin, -1e9, 1e9, "ymin");
    CHECK_RANGE(w, xmax, -1e9, 1e9, "xmax");
    CHECK_RANGE(w, ymax, -1e9, 1e9, "ymax");
    CHECK_RANGE(w, t, 1e-6, 1e6, "thickness");
    CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
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
    return changed(w);
}

static void remove_springs_of(lc_world *w, lc_body_id id)
{
    int i, j = 0;
    for (i = 0; i < w->spring_count; ++i) {
        if (w->springs[i].def.body_a == id || w->springs[i].def.body_b == id) continue;
        w->springs[j++] = w->springs[i];
    }
    w->spring_count = j;
}

lc_status lc_world_remove_body(lc_world *w, lc_body_id id)
{
    int row, i, n;
    if (w == NULL) return LC_ERR_NULL;
    row = row_of(w, id);
    if (row < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
    n = w->count - row - 1;
    /* shift rows down to keep insertion order (deterministic and what callers index by) */
#define SHIFT(arr, k) memmove(&(arr)[(size_t)row * (k)], &(arr)[(size_t)(row + 1) * (k)], (size_t)n * (k) * sizeof *(arr))
    SHIFT(w->ids, 1); SHIFT(w->mass, 1); SHIFT(w->inertia, 1); SHIFT(w->inv_mass, 1); SHIFT(w->inv_inertia, 1);
    SHIFT(w->is_static, 1); SHIFT(w->elasticity, 1); SHIFT(w->friction, 1); SHIFT(w->ext_force, 1);
    SHIFT(w->ext_torque, 1); SHIFT(w->shape, 1); SHIFT(w->trig, 1); SHIFT(w->thrusters, 1); SHIFT(w->thruster_count, 1);
    SHIFT(w->rests_dissipative, 1);
    SHIFT(w->state, LC_STATE_SIZE);
#undef SHIFT
    w->count--;
    w->edits++;
    w->id_to_row[id] = -1;
    for (i = row; i < w->count; ++i) w->id_to_row[w->ids[i]] = i;
    remove_springs_of(w, id);
    w->contact_count = 0;
    lc_event_regime_rows_shifted(w->event);   /* kept touches refer to rows, which just shifted */
    return changed(w);
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
    return changed(w);
}

#define GET_ROW(w, id, row) \
    do { if ((w) == NULL) return LC_ERR_NULL; (row) = row_of((w), (id)); \
         if ((row) < 0) return lc_fail((w), LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)(id)); } while (0)
#define GET_DYNAMIC_ROW(w, id, row) \
    do { GET_ROW(w, id, row); if ((w)->is_static[row]) return lc_fail((w), LC_ERR_STATIC_BODY, "body %u is static", (unsigned)(id)); } while (0)

lc_status lc_body_set_pose(lc_world *w, lc_body_id id, lc_vec2 center, double angle)
{
    int row;
    GET_ROW(w, id, row);
    TRY(check_vec(w, center, 1e9, "center"));
    CHECK_RANGE(w, angle, -1e9, 1e9, "angle");
    w->state[row * 6 + SX] = center.x;
    w->state[row * 6 + SY] = center.y;
    w->state[row * 6 + SA] = angle;
    w->contact_count = 0;
    w->edits++;
    return changed(w);
}

lc_status lc_body_set_velocity(lc_world *w, lc_body_id id, lc_vec2 v, double omega)
{
    int row;
    GET_DYNAMIC_ROW(w, id, row);
    TRY(check_vec(w, v, 1e8, "velocity"));
    CHECK_RANGE(w, omega, -1e8, 1e8, "angular_velocity");
    w->state[row * 6 + SVX] = v.x;
    w->state[row * 6 + SVY] = v.y;
    w->state[row * 6 + SW] = omega;
    w->edits++;
    return changed(w);
}

lc_status lc_body_set_mass(lc_world *w, lc_body_id id, double mass)
{
    int row;
    GET_DYNAMIC_ROW(w, id, row);
    CHECK_FINITE(w, mass, "mass");
    if (!(mass > 0.0) || mass > 1e12) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "mass = %g must be in (0, 1e12] kg", mass);
    w->mass[row] = mass;
    w->inertia[row] = mass * w->shape[row].unit_inertia;
    w->inv_mass[row] = 1.0 / mass;
    w->inv_inertia[row] = 1.0 / w->inertia[row];
    w->edits++;
    return changed(w);
}

lc_status lc_body_set_material(lc_world *w, lc_body_id id, double e, double mu)
{
    int row;
    GET_ROW(w, id, row);
    CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
    CHECK_RANGE(w, mu, 0.0, 10.0, "friction");
    w->elasticity[row] = e;
    w->friction[row] = mu;
    w->edits++;
    return changed(w);
}

lc_status lc_body_set_external(lc_world *w, lc_body_id id, lc_vec2 force, double torque)
{
    int row;
    GET_DYNAMIC_ROW(w, id, row);
    TRY(check_vec(w, force, 1e12, "force"));
    CHECK_RANGE(w, torque, -1e12, 1e12, "torque");
    w->ext_force[row] = force;
    w->ext_torque[row] = torque;
    return changed(w);
}

int lc_body_vertex_count(const lc_world *w, lc_body_id id)
{
    int row = row_of(w, id);
    return row < 0 ? -1 : w->shape[row].count;
}

lc_status lc_body_get_local_vertices(const lc_world *w, lc_body_id id, lc_vec2 *out, int capacity)
{
    int row = row_of(w, id), i;
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    if (row < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
    if (capacity < w->shape[row].count)
        return lc_fail((lc_world *)w, LC_ERR_OUT_OF_RANGE, "capacity %d is below the body's %d vertices", capacity, w->shape[row].count);
    for (i = 0; i < w->shape[row].count; ++i) out[i] = w->shape[row].v[i];
    return LC_OK;
}

lc_status lc_body_get_world_vertices(const lc_world *w, lc_body_id id, lc_vec2 *out, int capacity)
{
    int row = row_of(w, id), i;
    double c, s;
    const double *st;
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    if (row < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
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
    int row = row_of(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    if (row < 0) return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)id);
    *out = w->shape[row].center_offset;
    return LC_OK;
}

/* ---- thrusters ----------------------------------------------------------------------------- */

lc_status lc_body_add_thruster(lc_world *w, lc_body_id id, const lc_thruster_def *d, int *out_index)
{
    int row, k;
    double len;
    lc_thruster *t;
    GET_DYNAMIC_ROW(w, id, row);
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "thruster def is NULL");
    TRY(check_vec(w, d->point, 1e6, "thruster point"));
    TRY(check_vec(w, d->direction, 1e6, "thruster direction"));
    CHECK_RANGE(w, d->magnitude, 0.0, 1e9, "thruster magnitude");
    len = sqrt(lc_dot(d->direction, d->direction));
    if (!(len > 1e-12)) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "thruster direction is zero");
    k = w->thruster_count[row];
    if (k >= LC_MAX_THRUSTERS) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body %u already has %d thrusters", (unsigned)id, LC_MAX_THRUSTERS);
    t = &w->thrusters[row][k];
    /* stored about the centre of mass so force evaluation needs no offset */
    t->point = lc_sub(d->point, w->shape[row].center_offset);
    t->direction = lc_scale(d->direction, 1.0 / len);
    t->magnitude = d->magnitude;
    t->level = 0.0;
    w->thruster_count[row] = k + 1;
    if (out_index) *out_index = k;
    return changed(w);
}

lc_status lc_body_add_default_thrusters(lc_world *w, lc_body_id id, double thrust, int *out_first)
{
    int row, i, first;
    double top = 0.0, bottom = 0.0;
    lc_thruster_def d[4];
    GET_DYNAMIC_ROW(w, id, row);
    CHECK_RANGE(w, thrust, 0.0, 1e9, "thrust");
    if (w->thruster_count[row] + 4 > LC_MAX_THRUSTERS)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body %u has no room for 4 more thrusters", (unsigned)id);
    for (i = 0; i < w->shape[row].count; ++i) {
        top = fmax(top, w->shape[row].v[i].y);
        bottom = fmin(bottom, w->shape[row].v[i].y);
    }
    /* As the seed: side thrusters (0.4 of the thrust) act at 0.8 of the height so they also turn the
     * block; up/down act through the centre of mass. Points are given in the local-origin frame. */
    {
        lc_vec2 c = w->shape[row].center_offset;
        double side_y = bottom + 0.8 * (top - bottom);
        d[0].point = lc_add(c, lc_v(0.0, side_y)); d[0].direction = lc_v(-1, 0); d[0].magnitude = 0.4 * thrust;
        d[1].point = lc_add(c, lc_v(0.0, side_y)); d[1].direction = lc_v(1, 0);  d[1].magnitude = 0.4 * thrust;
        d[2].point = c;                            d[2].direction = lc_v(0, 1);  d[2].magnitude = thrust;
        d[3].point = c;                            d[3].direction = lc_v(0, -1); d[3].magnitude = thrust;
    }
    first = w->thruster_count[row];
    for (i = 0; i < 4; ++i) TRY(lc_body_add_thruster(w, id, &d[i], NULL));
    if (out_first) *out_first = first;
    return changed(w);
}

lc_status lc_body_set_thruster_level(lc_world *w, lc_body_id id, int index, double level)
{
    int row;
    GET_DYNAMIC_ROW(w, id, row);
    if (index < 0 || index >= w->thruster_count[row])
        return lc_fail(w, LC_ERR_UNKNOWN_THRUSTER, "body %u has no thruster %d (it has %d)", (unsigned)id, index, w->thruster_count[row]);
    CHECK_RANGE(w, level, 0.0, 1.0, "thruster level");
    w->thrusters[row][index].level = level;
    return changed(w);
}

lc_status lc_body_set_thruster_mask(lc_world *w, lc_body_id id, uint32_t mask)
{
    int row, i;
    GET_DYNAMIC_ROW(w, id, row);
    if (w->thruster_count[row] < 32 && (mask >> w->thruster_count[row]) != 0)
        return lc_fail(w, LC_ERR_UNKNOWN_THRUSTER, "mask 0x%x names thrusters body %u does not have (it has %d)", (unsigned)mask, (unsigned)id, w->thruster_count[row]);
    for (i = 0; i < w->thruster_count[row]; ++i) w->thrusters[row][i].level = (mask >> i) & 1u ? 1.0 : 0.0;
    return changed(w);
}

int lc_body_thruster_count(const lc_world *w, lc_body_id id)
{
    int row = row_of(w, id);
    return row < 0 ? -1 : w->thruster_count[row];
}

/* ---- springs ------------------------------------------------------------------------------- */

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
    CHECK_RANGE(w, k, 0.0, 1e9, "stiffness");
    CHECK_RANGE(w, d, 0.0, 1e9, "damping");
    CHECK_RANGE(w, L0, 0.0, 1e6, "rest_length");
    return LC_OK;
}

lc_status lc_world_add_spring(lc_world *w, const lc_spring_def *d, lc_spring_id *out_id)
{
    int ra, rb = -1;
    if (w == NULL) return LC_ERR_NULL;
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "spring def is NULL");
    ra = row_of(w, d->body_a);
    if (ra < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "spring body_a: no body with id %u", (unsigned)d->body_a);
    if (w->is_static[ra]) return lc_fail(w, LC_ERR_STATIC_BODY, "spring body_a %u is static", (unsigned)d->body_a);
    if (d->body_b != LC_WORLD_ANCHOR) {
        rb = row_of(w, d->body_b);
        if (rb < 0) return lc_fail(w, LC_ERR_UNKNOWN_BODY, "spring body_b: no body with id %u", (unsigned)d->body_b);
        if (rb == ra) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "spring joins body %u to itself", (unsigned)d->body_a);
    }
    TRY(check_vec(w, d->point_a, 1e6, "point_a"));
    TRY(check_vec(w, d->point_b, 1e9, "point_b"));
    TRY(check_spring_params(w, d->stiffness, d->damping, d->rest_length));
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
    return changed(w);
}

lc_status lc_world_remove_spring(lc_world *w, lc_spring_id id)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    memmove(&w->springs[i], &w->springs[i + 1], (size_t)(w->spring_count - i - 1) * sizeof *w->springs);
    w->spring_count--;
    return changed(w);
}

lc_status lc_spring_set_target(lc_world *w, lc_spring_id id, lc_vec2 target)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    if (w->springs[i].def.body_b != LC_WORLD_ANCHOR)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "spring %u joins two bodies; it has no world target", (unsigned)id);
    TRY(check_vec(w, target, 1e9, "target"));
    w->springs[i].def.point_b = target;
    return changed(w);
}

lc_status lc_spring_set_params(lc_world *w, lc_spring_id id, double k, double d, double L0)
{
    int i = spring_index(w, id);
    if (w == NULL) return LC_ERR_NULL;
    if (i < 0) return lc_fail(w, LC_ERR_UNKNOWN_SPRING, "no spring with id %u", (unsigned)id);
    TRY(check_spring_params(w, k, d, L0));
    w->springs[i].def.stiffness = k;
    w->springs[i].def.damping = d;
    w->springs[i].def.rest_length = L0;
    return changed(w);
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
    *a = body_point(w, w->state, row_of(w, d->body_a), d->point_a);
    *b = d->body_b == LC_WORLD_ANCHOR ? d->point_b : body_point(w, w->state, row_of(w, d->body_b), d->point_b);
    return LC_OK;
}

int lc_world_spring_count(const lc_world *w) { return w ? w->spring_count : 0; }

/* ---- results ---------------------------------------------------------------------------------- */

lc_status lc_world_get_contacts(const lc_world *w, const lc_contact **out, int *out_count)
{
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL || out_count == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out or out_count is NULL");
    *out = w->contacts;
    *out_count = w->contact_count;
    return LC_OK;
}

lc_status lc_world_get_energy(const lc_world *w, lc_energy *out)
{
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    lc_compute_energy(w, w->state, out);
    return LC_OK;
}

lc_status lc_world_get_counters(const lc_world *w, lc_counters *last, lc_counters *total)
{
    if (w == NULL) return LC_ERR_NULL;
    if (last) *last = w->last;
    if (total) *total = w->total;
    return LC_OK;
}

uint64_t lc_world_state_hash(const lc_world *w)
{
    uint64_t h = 1469598103934665603ULL;
    const unsigned char *p;
    size_t i, n;
    if (w == NULL) return 0;
    p = (const unsigned char *)&w->time;
    for (i = 0; i < sizeof w->time; ++i) { h ^= p[i]; h *= 1099511628211ULL; }
    p = (const unsigned char *)w->state;
    n = (size_t)w->count * LC_STATE_SIZE * sizeof(double);
    for (i = 0; i < n; ++i) { h ^= p[i]; h *= 1099511628211ULL; }
    p = (const unsigned char *)w->ids;
    n = (size_t)w->count * sizeof(lc_body_id);
    for (i = 0; i < n; ++i) { h ^= p[i]; h *= 1099511628211ULL; }
    return h;
}
