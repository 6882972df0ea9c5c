/* The world itself: scratch buffers, errors and status strings, the default defs, the validation of a
 * world def and of a vector argument (lc_check_vec, shared by the setters of body.c, thruster.c and
 * spring.c), the world's lifetime and settings, its time and its state hash. Bodies, thrusters and
 * springs have files of their own; a step's contacts, counters and energy are read in results.c and
 * energy.c. */
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
#include "events.h"
#include "snapshot_checksum.h"   /* lc_fnv1a64: the state hash is the snapshot checksum's hash */

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
    case LC_ERR_BAD_SNAPSHOT: return "bad snapshot";
    case LC_ERR_CALLBACK: return "callback failed";
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
    d.event_capacity = 4096;
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

static int mix_rule_ok(lc_mix_rule r) { return r == LC_MIX_MIN || r == LC_MIX_MAX || r == LC_MIX_MEAN || r == LC_MIX_GEOMETRIC; }

static lc_status validate_world_def(lc_world *w, const lc_world_def *d)
{
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "world def is NULL");
    LC_CHECK_RANGE(w, d->gravity.x, -1e6, 1e6, "gravity.x");
    LC_CHECK_RANGE(w, d->gravity.y, -1e6, 1e6, "gravity.y");
    LC_CHECK_RANGE(w, d->zero_energy_level, -1e9, 1e9, "zero_energy_level");
    LC_CHECK_RANGE(w, d->damping, 0.0, 1e9, "damping");
    LC_CHECK_RANGE(w, d->damping_rotation_ratio, 0.0, 1e9, "damping_rotation_ratio");
    if (d->integrator != LC_INTEGRATOR_EULER && d->integrator != LC_INTEGRATOR_MIDPOINT && d->integrator != LC_INTEGRATOR_RK4)
        return lc_fail(w, LC_ERR_BAD_ENUM, "integrator = %d is not an lc_integrator", (int)d->integrator);
    if (d->impact_mode != LC_IMPACT_SERIAL && d->impact_mode != LC_IMPACT_SIMULTANEOUS)
        return lc_fail(w, LC_ERR_BAD_ENUM, "impact_mode = %d is not an lc_impact_mode", (int)d->impact_mode);
    if (d->toi_method != LC_TOI_ROOT_FINDER && d->toi_method != LC_TOI_BINARY_SEARCH)
        return lc_fail(w, LC_ERR_BAD_ENUM, "toi_method = %d is not an lc_toi_method", (int)d->toi_method);
    LC_CHECK_RANGE(w, d->toi_time_tolerance, 1e-15, 1e-2, "toi_time_tolerance");
    LC_CHECK_RANGE(w, d->toi_distance_tolerance, 1e-15, 1e-2, "toi_distance_tolerance");
    LC_CHECK_IRANGE(w, d->toi_max_iterations, 4, 1000, "toi_max_iterations");
    LC_CHECK_RANGE(w, d->contact_gap, 1e-12, 1e-2, "contact_gap");
    LC_CHECK_RANGE(w, d->contact_distance, 1e-12, 1.0, "contact_distance");
    if (!(d->contact_distance > d->contact_gap))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "contact_distance = %g must exceed contact_gap = %g", d->contact_distance, d->contact_gap);
    if (!(d->toi_distance_tolerance < d->contact_gap))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "toi_distance_tolerance = %g must be below contact_gap = %g", d->toi_distance_tolerance, d->contact_gap);
    LC_CHECK_RANGE(w, d->resting_speed, 0.0, 10.0, "resting_speed");
    LC_CHECK_RANGE(w, d->restitution_threshold, 0.0, 10.0, "restitution_threshold");
    if (d->stabilization != LC_STABILIZE_NONE && d->stabilization != LC_STABILIZE_VELOCITY && d->stabilization != LC_STABILIZE_VELOCITY_AND_DISTANCE)
        return lc_fail(w, LC_ERR_BAD_ENUM, "stabilization = %d is not an lc_stabilization", (int)d->stabilization);
    if (!mix_rule_ok(d->elasticity_rule)) return lc_fail(w, LC_ERR_BAD_ENUM, "elasticity_rule = %d is not an lc_mix_rule", (int)d->elasticity_rule);
    if (!mix_rule_ok(d->friction_rule)) return lc_fail(w, LC_ERR_BAD_ENUM, "friction_rule = %d is not an lc_mix_rule", (int)d->friction_rule);
    LC_CHECK_IRANGE(w, d->max_events_per_step, 1, 1000000, "max_events_per_step");
    LC_CHECK_IRANGE(w, d->max_serial_iterations, 1, 1000000, "max_serial_iterations");
    LC_CHECK_IRANGE(w, d->lcp_exact_max, 0, 4096, "lcp_exact_max");
    LC_CHECK_IRANGE(w, d->lcp_max_iterations, 1, 1000000, "lcp_max_iterations");
    LC_CHECK_RANGE(w, d->lcp_tolerance, 0.0, 1.0, "lcp_tolerance");
    if (d->broadphase != LC_BROADPHASE_AUTO && d->broadphase != LC_BROADPHASE_BRUTE_FORCE &&
        d->broadphase != LC_BROADPHASE_SORT_AND_SWEEP && d->broadphase != LC_BROADPHASE_GRID)
        return lc_fail(w, LC_ERR_BAD_ENUM, "broadphase = %d is not an lc_broadphase", (int)d->broadphase);
    LC_CHECK_IRANGE(w, d->broadphase_threshold, 2, 1000000, "broadphase_threshold");
    if (d->regime != LC_REGIME_AUTO && d->regime != LC_REGIME_EVENT && d->regime != LC_REGIME_CONTACT)
        return lc_fail(w, LC_ERR_BAD_ENUM, "regime = %d is not an lc_regime", (int)d->regime);
    LC_CHECK_IRANGE(w, d->contact_iterations, 1, 1000000, "contact_iterations");
    LC_CHECK_RANGE(w, d->contact_tolerance, 0.0, 1.0, "contact_tolerance");
    LC_CHECK_IRANGE(w, d->allow_sleep, 0, 1, "allow_sleep");
    LC_CHECK_FINITE(w, d->sleep_time, "sleep_time");
    if (!(d->sleep_time > 0.0 && d->sleep_time <= 1e6))
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "sleep_time = %g is outside (0, 1e6] s", d->sleep_time);
    LC_CHECK_RANGE(w, d->sleep_speed, 0.0, 10.0, "sleep_speed");
    LC_CHECK_IRANGE(w, d->event_capacity, 0, 1000000, "event_capacity");
    return LC_OK;
}

lc_status lc_check_vec(lc_world *w, lc_vec2 v, double limit, const char *name)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%s.x", name);
    LC_CHECK_RANGE(w, v.x, -limit, limit, buf);
    snprintf(buf, sizeof buf, "%s.y", name);
    LC_CHECK_RANGE(w, v.y, -limit, limit, buf);
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
        w->force_callback = lc_force_callback_create();
        w->lcp = lc_lcp_workspace_create();
        w->events = lc_events_create(def->event_capacity);
        if (!w->events || !w->step_state || !w->islands || !w->event || !w->contact || !w->broad_phase ||
            !w->integrator || !w->contact_forces || !w->impulse || !w->sparse_lcp || !w->static_load || !w->sleep ||
            !w->force_callback || !w->lcp)
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
    int i;
    if (w == NULL) return;
    for (i = 0; i < w->count; ++i) lc_shape_release(&w->shape[i]);
    free(w->ids); free(w->state); free(w->mass); free(w->inertia); free(w->inv_mass); free(w->inv_inertia);
    free(w->is_static); free(w->elasticity); free(w->friction); free(w->ext_force); free(w->ext_torque);
    free(w->shape); free(w->radius); free(w->outline); free(w->trig_block); free(w->thrusters); free(w->thruster_count); free(w->id_to_row);
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
    lc_force_callback_destroy(w->force_callback);
    lc_lcp_workspace_destroy(w->lcp);
    lc_events_destroy(w->events);
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
    lc_events_set_capacity(w->events, def->event_capacity);
    return lc_changed(w);
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
    LC_CHECK_RANGE(w, e, 0.0, 1.0, "elasticity");
    for (i = 0; i < w->count; ++i) w->elasticity[i] = e;
    w->edits++;
    return lc_changed(w);
}

double lc_world_get_time(const lc_world *w) { return w ? w->time : 0.0; }

uint64_t lc_world_state_hash(const lc_world *w)
{
    uint64_t h;
    if (w == NULL) return 0;
    h = lc_fnv1a64(LC_FNV1A64_BASIS, &w->time, sizeof w->time);
    h = lc_fnv1a64(h, w->state, (size_t)w->count * LC_STATE_SIZE * sizeof(double));
    return lc_fnv1a64(h, w->ids, (size_t)w->count * sizeof(lc_body_id));
}
