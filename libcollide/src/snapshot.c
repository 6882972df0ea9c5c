/* World snapshots (lc_world_save, lc_world_load, lc_world_create_from_snapshot): everything a later step
 * reads, so that a world loaded from a snapshot steps on bit for bit as the saved one does.
 *
 * Layout (every number little-endian, doubles as their IEEE-754 bits; docs/events_and_snapshots.md):
 *   header   8 bytes magic "LCWORLD\x1a", u32 format version, u32 0, u64 payload bytes,
 *            u64 FNV-1a 64 of the payload (snapshot_checksum.h)
 *   payload  the world def field by field; time, the step's dt, the edit counters; the bodies in row
 *            order (id, state, mass properties, material, external force, shape, thrusters, regime
 *            mark); the springs; the last step's contacts; the counters; then what the engine keeps
 *            from one step to the next, each part written by its owner: sleep (sleep.c), the contact
 *            regime's warm start and kept touches (contact_regime.c), the event regime's warm start
 *            and end touches (event_regime.c), the sparse solver's norm estimates (sparse_lcp.c).
 * Not written, because a fresh one gives the same bits: scratch buffers, the per-body trig cache and
 * its boxes (a hit returns the very bits a miss computes, world.h), the sort-and-sweep order (any start
 * sorts to the same order, broad_phase.c), the impact event stream (the caller's reading, not the
 * world's state), the stage-timing setting and the force callback (the caller's functions: a load keeps
 * the world's own). tests/c/test_snapshot.c continues every regime bit for bit from a loaded snapshot,
 * which is what shows that list complete.
 *
 * A load builds a new world from the snapshot and, only when all of it was read and checked, swaps it
 * in: a bad snapshot leaves the world as it was. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "contact_regime.h"
#include "event_regime.h"
#include "sleep.h"
#include "snapshot_checksum.h"
#include "snapshot_io.h"

#define SNAP_MAGIC "LCWORLD\x1a"
#define SNAP_VERSION 2u
#define SNAP_HEADER LC_SNAPSHOT_HEADER_BYTES
#define COUNTER_WORDS (sizeof(lc_counters) / 8)
/* The largest body id a snapshot may hold: the id map takes an int per id up to the largest, so a corrupt
 * id could otherwise ask for gigabytes (2^28 ids: 1 GiB, the map of a world that created that many). */
#define LC_SNAPSHOT_MAX_ID (1u << 28)

/* lc_counters is all 8-byte fields (uint64_t and double), written as words: one word per field on
 * every machine. */
typedef char counters_are_words[sizeof(lc_counters) % 8 == 0 ? 1 : -1];

/* ---- writing ----------------------------------------------------------------------------------- */

static void put_def(lc_writer *o, const lc_world_def *d)
{
    lc_put_vec(o, d->gravity);
    lc_put_f64(o, d->zero_energy_level);
    lc_put_f64(o, d->damping);
    lc_put_f64(o, d->damping_rotation_ratio);
    lc_put_i32(o, (int)d->integrator);
    lc_put_i32(o, (int)d->impact_mode);
    lc_put_i32(o, (int)d->toi_method);
    lc_put_f64(o, d->toi_time_tolerance);
    lc_put_f64(o, d->toi_distance_tolerance);
    lc_put_i32(o, d->toi_max_iterations);
    lc_put_f64(o, d->contact_gap);
    lc_put_f64(o, d->contact_distance);
    lc_put_f64(o, d->resting_speed);
    lc_put_f64(o, d->restitution_threshold);
    lc_put_i32(o, (int)d->stabilization);
    lc_put_i32(o, (int)d->elasticity_rule);
    lc_put_i32(o, (int)d->friction_rule);
    lc_put_i32(o, d->max_events_per_step);
    lc_put_i32(o, d->max_serial_iterations);
    lc_put_i32(o, d->lcp_exact_max);
    lc_put_i32(o, d->lcp_max_iterations);
    lc_put_f64(o, d->lcp_tolerance);
    lc_put_i32(o, (int)d->broadphase);
    lc_put_i32(o, d->broadphase_threshold);
    lc_put_i32(o, (int)d->regime);
    lc_put_i32(o, d->contact_iterations);
    lc_put_f64(o, d->contact_tolerance);
    lc_put_i32(o, d->allow_sleep);
    lc_put_f64(o, d->sleep_time);
    lc_put_f64(o, d->sleep_speed);
    lc_put_i32(o, d->event_capacity);
}

static void put_counters(lc_writer *o, const lc_counters *c)
{
    size_t k;
    lc_put_i32(o, (int)COUNTER_WORDS);
    for (k = 0; k < COUNTER_WORDS; ++k) {
        uint64_t word;
        memcpy(&word, (const unsigned char *)c + 8 * k, 8);
        lc_put_u64(o, word);
    }
}

static void put_body(lc_writer *o, const lc_world *w, int i)
{
    const lc_shape *s = &w->shape[i];
    int k;
    lc_put_u32(o, w->ids[i]);
    lc_put_u8(o, w->is_static[i]);
    for (k = 0; k < LC_STATE_SIZE; ++k) lc_put_f64(o, w->state[i * LC_STATE_SIZE + k]);
    lc_put_f64(o, w->mass[i]);
    lc_put_f64(o, w->inertia[i]);
    lc_put_f64(o, w->inv_mass[i]);
    lc_put_f64(o, w->inv_inertia[i]);
    lc_put_f64(o, w->elasticity[i]);
    lc_put_f64(o, w->friction[i]);
    lc_put_vec(o, w->ext_force[i]);
    lc_put_f64(o, w->ext_torque[i]);
    lc_put_u8(o, w->rests_dissipative[i]);
    lc_put_i32(o, s->count);
    for (k = 0; k < s->count; ++k) {
        lc_put_vec(o, s->v[k]);
        lc_put_vec(o, s->n[k]);
    }
    lc_put_vec(o, s->center_offset);
    lc_put_f64(o, s->radius);
    lc_put_f64(o, s->min_edge);
    lc_put_f64(o, s->area);
    lc_put_f64(o, s->unit_inertia);
    lc_put_f64(o, s->inertia_per_mass);
    lc_put_i32(o, w->thruster_count[i]);
    for (k = 0; k < w->thruster_count[i]; ++k) {
        const lc_thruster *t = &w->thrusters[i][k];
        lc_put_vec(o, t->point);
        lc_put_vec(o, t->direction);
        lc_put_f64(o, t->magnitude);
        lc_put_f64(o, t->level);
    }
}

static void put_payload(lc_writer *o, const lc_world *w)
{
    int i;
    put_def(o, &w->def);
    lc_put_f64(o, w->time);
    lc_put_f64(o, w->step_dt);
    lc_put_u64(o, w->edits);
    lc_put_u64(o, w->regime_edits);
    lc_put_u64(o, w->api_changes);
    lc_put_u32(o, w->next_body_id);
    lc_put_i32(o, w->count);
    for (i = 0; i < w->count; ++i) put_body(o, w, i);
    lc_put_u32(o, w->next_spring_id);
    lc_put_i32(o, w->spring_count);
    for (i = 0; i < w->spring_count; ++i) {
        const lc_spring_rec *r = &w->springs[i];
        lc_put_u32(o, r->id);
        lc_put_u32(o, r->def.body_a);
        lc_put_vec(o, r->def.point_a);
        lc_put_u32(o, r->def.body_b);
        lc_put_vec(o, r->def.point_b);
        lc_put_f64(o, r->def.stiffness);
        lc_put_f64(o, r->def.damping);
        lc_put_f64(o, r->def.rest_length);
    }
    lc_put_i32(o, w->contact_count);
    for (i = 0; i < w->contact_count; ++i) lc_put_contact(o, &w->contacts[i]);
    put_counters(o, &w->last);
    put_counters(o, &w->total);
    lc_sleep_save(w->sleep, o);
    lc_contact_regime_save(w->contact, w, o);
    lc_event_regime_save(w->event, w, o);
    lc_sparse_lcp_save(w->sparse_lcp, o);
}

lc_status lc_world_save(const lc_world *w, void *buf, size_t capacity, size_t *out_size)
{
    lc_writer o;
    size_t payload;
    if (w == NULL) return LC_ERR_NULL;
    if (out_size == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out_size is NULL");
    if (w->count > 0 && w->ids[w->count - 1] > LC_SNAPSHOT_MAX_ID)
        return lc_fail((lc_world *)w, LC_ERR_OUT_OF_RANGE, "body id %u is above the %u a snapshot can hold",
                       (unsigned)w->ids[w->count - 1], LC_SNAPSHOT_MAX_ID);
    memset(&o, 0, sizeof o);
    put_payload(&o, w);
    payload = o.n;
    *out_size = SNAP_HEADER + payload;
    if (buf == NULL) {
        ((lc_world *)w)->error[0] = '\0';
        return LC_OK;
    }
    if (capacity < *out_size)
        return lc_fail((lc_world *)w, LC_ERR_OUT_OF_RANGE, "capacity = %zu bytes is below the snapshot's %zu",
                       capacity, *out_size);
    o.p = (uint8_t *)buf + SNAP_HEADER;
    o.cap = payload;
    o.n = 0;
    put_payload(&o, w);
    memcpy(buf, SNAP_MAGIC, 8);
    o.p = (uint8_t *)buf + 8;
    o.cap = SNAP_HEADER - 8;
    o.n = 0;
    lc_put_u32(&o, SNAP_VERSION);
    lc_put_u32(&o, 0);
    lc_put_u64(&o, payload);
    lc_put_u64(&o, lc_snapshot_checksum((const uint8_t *)buf, SNAP_HEADER + payload));
    ((lc_world *)w)->error[0] = '\0';
    return LC_OK;
}

/* ---- reading ----------------------------------------------------------------------------------- */

static lc_world_def get_def(lc_reader *in)
{
    lc_world_def d = lc_default_world_def();
    d.gravity = lc_get_vec(in);
    d.zero_energy_level = lc_get_f64(in);
    d.damping = lc_get_f64(in);
    d.damping_rotation_ratio = lc_get_f64(in);
    d.integrator = (lc_integrator)lc_get_i32(in);
    d.impact_mode = (lc_impact_mode)lc_get_i32(in);
    d.toi_method = (lc_toi_method)lc_get_i32(in);
    d.toi_time_tolerance = lc_get_f64(in);
    d.toi_distance_tolerance = lc_get_f64(in);
    d.toi_max_iterations = lc_get_i32(in);
    d.contact_gap = lc_get_f64(in);
    d.contact_distance = lc_get_f64(in);
    d.resting_speed = lc_get_f64(in);
    d.restitution_threshold = lc_get_f64(in);
    d.stabilization = (lc_stabilization)lc_get_i32(in);
    d.elasticity_rule = (lc_mix_rule)lc_get_i32(in);
    d.friction_rule = (lc_mix_rule)lc_get_i32(in);
    d.max_events_per_step = lc_get_i32(in);
    d.max_serial_iterations = lc_get_i32(in);
    d.lcp_exact_max = lc_get_i32(in);
    d.lcp_max_iterations = lc_get_i32(in);
    d.lcp_tolerance = lc_get_f64(in);
    d.broadphase = (lc_broadphase)lc_get_i32(in);
    d.broadphase_threshold = lc_get_i32(in);
    d.regime = (lc_regime)lc_get_i32(in);
    d.contact_iterations = lc_get_i32(in);
    d.contact_tolerance = lc_get_f64(in);
    d.allow_sleep = lc_get_i32(in);
    d.sleep_time = lc_get_f64(in);
    d.sleep_speed = lc_get_f64(in);
    d.event_capacity = lc_get_i32(in);
    return d;
}

static void get_counters(lc_reader *in, lc_counters *c)
{
    size_t k;
    int words = lc_get_i32(in);
    if (words != (int)COUNTER_WORDS) {
        lc_reader_fail(in, "the counters hold %d words, not %d", words, (int)COUNTER_WORDS);
        return;
    }
    for (k = 0; k < COUNTER_WORDS; ++k) {
        uint64_t word = lc_get_u64(in);
        memcpy((unsigned char *)c + 8 * k, &word, 8);
    }
}

/* A range check of a double read from the input (NaN fails). */
static double get_in(lc_reader *in, double lo, double hi, const char *what)
{
    double v = lc_get_f64(in);
    if (!(v >= lo && v <= hi)) {
        lc_reader_fail(in, "%s = %g is outside [%g, %g]", what, v, lo, hi);
        return lo;
    }
    return v;
}

/* Body row i (rows 0 .. i-1 read), its id entered in the id map: 0, or -1 without memory. */
static int get_body(lc_reader *in, lc_world *w, int i)
{
    lc_shape *s = &w->shape[i];
    lc_trig *tr = &w->trig[i];
    int k;
    lc_body_id id;
    unsigned flag;
    /* the row counts as read whatever fails below (the caller's w->count), so its shape owns no block yet */
    s->v = s->n = NULL;
    id = lc_get_u32(in);
    flag = lc_get_u8(in);
    if (in->bad) return 0;
    /* rows are in insertion order, so ids increase along them */
    if (id <= (i > 0 ? w->ids[i - 1] : 0) || id >= w->next_body_id || id > LC_SNAPSHOT_MAX_ID)
        return lc_reader_fail(in, "body row %d has id %u, not above the last row's and below %u", i, (unsigned)id,
                              (unsigned)(w->next_body_id < LC_SNAPSHOT_MAX_ID ? w->next_body_id : LC_SNAPSHOT_MAX_ID));
    if (!lc_world_reserve(w, w->count + 1, id)) return -1;
    if (flag > 1) lc_reader_fail(in, "body %u's static flag is %u", (unsigned)id, flag);
    w->ids[i] = id;
    w->id_to_row[id] = i;
    w->is_static[i] = (uint8_t)flag;
    for (k = 0; k < LC_STATE_SIZE; ++k) w->state[i * LC_STATE_SIZE + k] = lc_get_finite(in, "a state number");
    w->mass[i] = get_in(in, 0.0, 1e12, "a mass");
    w->inertia[i] = get_in(in, 0.0, INFINITY, "an inertia");
    w->inv_mass[i] = get_in(in, 0.0, INFINITY, "an inverse mass");
    w->inv_inertia[i] = get_in(in, 0.0, INFINITY, "an inverse inertia");
    w->elasticity[i] = get_in(in, 0.0, 1.0, "an elasticity");
    w->friction[i] = get_in(in, 0.0, 10.0, "a friction coefficient");
    w->ext_force[i].x = lc_get_finite(in, "an external force");
    w->ext_force[i].y = lc_get_finite(in, "an external force");
    w->ext_torque[i] = lc_get_finite(in, "an external torque");
    flag = lc_get_u8(in);
    if (flag > 1) lc_reader_fail(in, "body %u's regime mark is %u", (unsigned)id, flag);
    w->rests_dissipative[i] = (uint8_t)flag;
    memset(s, 0, sizeof *s);
    s->count = lc_get_count(in, 3, LC_MAX_POLYGON_VERTICES, 32, "a polygon's vertex count");
    if (lc_shape_keep(s, s->count) != 0) return -1;
    for (k = 0; k < s->count; ++k) {
        s->v[k].x = lc_get_finite(in, "a vertex");
        s->v[k].y = lc_get_finite(in, "a vertex");
        s->n[k].x = lc_get_finite(in, "an edge normal");
        s->n[k].y = lc_get_finite(in, "an edge normal");
    }
    s->center_offset.x = lc_get_finite(in, "a centre of mass offset");
    s->center_offset.y = lc_get_finite(in, "a centre of mass offset");
    s->radius = get_in(in, 0.0, INFINITY, "a polygon's radius");
    w->radius[i] = s->radius;
    w->outline[i].v = s->v;
    w->outline[i].count = s->count;
    s->min_edge = get_in(in, 0.0, INFINITY, "a polygon's shortest edge");
    s->area = get_in(in, 0.0, INFINITY, "a polygon's area");
    s->unit_inertia = get_in(in, 0.0, INFINITY, "a polygon's unit inertia");
    s->inertia_per_mass = get_in(in, 0.0, INFINITY, "an inertia per mass");
    w->thruster_count[i] = lc_get_count(in, 0, LC_MAX_THRUSTERS, 48, "a body's thruster count");
    for (k = 0; k < w->thruster_count[i]; ++k) {
        lc_thruster *t = &w->thrusters[i][k];
        t->point.x = lc_get_finite(in, "a thruster point");
        t->point.y = lc_get_finite(in, "a thruster point");
        t->direction.x = lc_get_finite(in, "a thruster direction");
        t->direction.y = lc_get_finite(in, "a thruster direction");
        t->magnitude = get_in(in, 0.0, 1e9, "a thruster magnitude");
        t->level = get_in(in, 0.0, 1.0, "a thruster level");
    }
    /* the caches start empty, as for a new body: NaN matches no angle */
    lc_trig_clear(tr);
    return 0;
}

static void get_spring(lc_reader *in, lc_world *w, lc_spring_rec *r)
{
    int a, b, k;
    r->id = lc_get_u32(in);
    r->def.body_a = lc_get_u32(in);
    r->def.point_a.x = get_in(in, -1e6, 1e6, "a spring's point_a");
    r->def.point_a.y = get_in(in, -1e6, 1e6, "a spring's point_a");
    r->def.body_b = lc_get_u32(in);
    r->def.point_b.x = get_in(in, -1e9, 1e9, "a spring's point_b");
    r->def.point_b.y = get_in(in, -1e9, 1e9, "a spring's point_b");
    r->def.stiffness = get_in(in, 0.0, 1e9, "a spring's stiffness");
    r->def.damping = get_in(in, 0.0, 1e9, "a spring's damping");
    r->def.rest_length = get_in(in, 0.0, 1e6, "a spring's rest length");
    if (in->bad) return;
    a = lc_world_body_index(w, r->def.body_a);
    b = r->def.body_b == LC_WORLD_ANCHOR ? -2 : lc_world_body_index(w, r->def.body_b);
    if (r->id == 0 || r->id >= w->next_spring_id) lc_reader_fail(in, "spring id %u is not below %u", (unsigned)r->id, (unsigned)w->next_spring_id);
    for (k = 0; k < w->spring_count; ++k)
        if (w->springs[k].id == r->id) lc_reader_fail(in, "spring id %u appears twice", (unsigned)r->id);
    if (a < 0 || w->is_static[a] || b == -1 || b == a)
        lc_reader_fail(in, "spring %u joins bodies %u and %u, which it cannot", (unsigned)r->id, (unsigned)r->def.body_a,
                       (unsigned)r->def.body_b);
}

/* The world a snapshot describes, or NULL with the status in *st and the reason in why. */
static lc_world *from_snapshot(const void *buf, size_t size, lc_status *st, char *why, size_t why_len)
{
    const uint8_t *p = (const uint8_t *)buf;
    lc_reader hdr, in;
    lc_world_def def;
    lc_world *w = NULL;
    uint32_t version, reserved;
    uint64_t payload, sum;
    int i, n;
    *st = LC_ERR_BAD_SNAPSHOT;
    if (size < SNAP_HEADER || memcmp(p, SNAP_MAGIC, 8) != 0) {
        snprintf(why, why_len, "not a libcollide world snapshot (%s)", size < SNAP_HEADER ? "too short" : "no magic");
        return NULL;
    }
    memset(&hdr, 0, sizeof hdr);
    hdr.p = p + 8;
    hdr.n = SNAP_HEADER - 8;
    version = lc_get_u32(&hdr);
    reserved = lc_get_u32(&hdr);
    payload = lc_get_u64(&hdr);
    sum = lc_get_u64(&hdr);
    if (version != SNAP_VERSION || reserved != 0) {
        snprintf(why, why_len, "snapshot format %u.%u; this library reads format %u", (unsigned)version, (unsigned)reserved,
                 SNAP_VERSION);
        return NULL;
    }
    if (payload != size - SNAP_HEADER) {
        snprintf(why, why_len, "the snapshot holds %zu bytes after its header where it says %llu (truncated?)",
                 size - SNAP_HEADER, (unsigned long long)payload);
        return NULL;
    }
    if (lc_snapshot_checksum(p, size) != sum) {
        snprintf(why, why_len, "the snapshot's checksum does not match its contents (corrupt)");
        return NULL;
    }
    memset(&in, 0, sizeof in);
    in.p = p + SNAP_HEADER;
    in.n = (size_t)payload;
    def = get_def(&in);
    if (in.bad) {
        snprintf(why, why_len, "%s", in.why);
        return NULL;
    }
    w = lc_world_create(&def, why, why_len);
    if (w == NULL) {
        char inner[200];
        snprintf(inner, sizeof inner, "%s", why);
        *st = strstr(inner, "out of memory") ? LC_ERR_NO_MEMORY : LC_ERR_BAD_SNAPSHOT;
        snprintf(why, why_len, "the snapshot's settings: %s", inner);
        return NULL;
    }
    w->time = lc_get_finite(&in, "the time");
    w->step_dt = lc_get_f64(&in);
    w->edits = (unsigned long)lc_get_u64(&in);
    w->regime_edits = (unsigned long)lc_get_u64(&in);
    w->api_changes = (unsigned long)lc_get_u64(&in);
    w->next_body_id = lc_get_u32(&in);
    if (w->next_body_id == 0) lc_reader_fail(&in, "the next body id is 0");
    n = lc_get_count(&in, 0, 1 << 24, 200, "the body count");
    if (!in.bad && !lc_world_reserve(w, n > 0 ? n : 1, 1)) goto oom;
    for (i = 0; i < n && !in.bad; ++i) {
        if (get_body(&in, w, i) != 0) goto oom;
        w->count = i + 1;   /* rows read so far: lc_world_body_index sees them */
    }
    w->next_spring_id = lc_get_u32(&in);
    n = lc_get_count(&in, 0, 1 << 24, 68, "the spring count");
    if (!in.bad && n > 0) {
        w->springs = malloc((size_t)n * sizeof *w->springs);
        if (w->springs == NULL) goto oom;
        w->spring_cap = n;
    }
    for (i = 0; i < n && !in.bad; ++i) {
        get_spring(&in, w, &w->springs[i]);
        w->spring_count = i + 1;
    }
    n = lc_get_count(&in, 0, 1 << 28, 92, "the contact count");
    for (i = 0; i < n && !in.bad; ++i) {
        lc_contact *c = lc_new_contact(w);
        if (c == NULL) goto oom;
        lc_get_contact(&in, c);
    }
    get_counters(&in, &w->last);
    get_counters(&in, &w->total);
    if (!in.bad && lc_sleep_load(w->sleep, w, &in) != 0) goto oom;
    if (!in.bad && lc_contact_regime_load(w->contact, w, &in) != 0) goto oom;
    if (!in.bad && lc_event_regime_load(w->event, w, &in) != 0) goto oom;
    if (!in.bad) lc_sparse_lcp_load(w->sparse_lcp, &in);
    if (!in.bad && in.at != in.n) lc_reader_fail(&in, "%zu bytes follow the snapshot's last part", in.n - in.at);
    if (in.bad) {
        snprintf(why, why_len, "%s", in.why);
        lc_world_destroy(w);
        return NULL;
    }
    *st = LC_OK;
    return w;
oom:
    lc_world_destroy(w);
    *st = LC_ERR_NO_MEMORY;
    snprintf(why, why_len, "out of memory loading a snapshot");
    return NULL;
}

lc_status lc_world_load(lc_world *w, const void *buf, size_t size)
{
    char why[256];
    lc_status st;
    lc_world *loaded, old;
    struct lc_force_callback *fresh_callback;
    if (w == NULL) return LC_ERR_NULL;
    if (buf == NULL) return lc_fail(w, LC_ERR_NULL, "buf is NULL");
    loaded = from_snapshot(buf, size, &st, why, sizeof why);
    if (loaded == NULL) return lc_fail(w, st, "%s; the world is unchanged", why);
    fresh_callback = loaded->force_callback;
    /* the loaded world's contents into w, w's old contents freed with the shell */
    old = *w;
    *w = *loaded;
    *loaded = old;
    w->stage_timing = loaded->stage_timing;
    /* the force callback stays too: its functions are the caller's, not the world's state (the loaded
     * world's fresh, empty one goes with the shell) */
    w->force_callback = old.force_callback;
    loaded->force_callback = fresh_callback;
    lc_world_destroy(loaded);
    w->error[0] = '\0';
    return LC_OK;
}

lc_world *lc_world_create_from_snapshot(const void *buf, size_t size, char *errbuf, size_t errbuf_len)
{
    char why[256];
    lc_status st;
    lc_world *w;
    if (buf == NULL) {
        if (errbuf && errbuf_len) snprintf(errbuf, errbuf_len, "buf is NULL");
        return NULL;
    }
    w = from_snapshot(buf, size, &st, why, sizeof why);
    if (errbuf && errbuf_len) snprintf(errbuf, errbuf_len, "%s", w ? "" : why);
    return w;
}
