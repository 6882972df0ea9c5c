/* fuzz_step: libFuzzer harness for the stepping API.
 *
 * The input bytes are read as a program: world settings (any value, in range or not), optional walls,
 * then up to MAX_COMMANDS commands - add/remove bodies with random, degenerate or huge polygons and
 * masses (0, negative, NaN, huge), poses, velocities, materials, external forces, thrusters, springs,
 * settings changes, state overwrites, getters with odd capacities, and steps with random dt.
 *
 * Invariants checked (a violation calls fz_fail(), fuzz_fail.h, which aborts the harness, never the
 * library):
 *  - every call either returns LC_OK or returns an error with a non-empty lc_world_last_error(),
 *    and a failed call leaves the state hash unchanged ("the world is unchanged on failure");
 *  - a step, successful or failed, needs at most FZ_MAX_FORCE_EVALS force evaluations,
 *    FZ_MAX_SERIAL_ITERS serial impulse iterations and FZ_MAX_SOLVER_WORK_PER_BODY solver work per body
 *    (work, not wall time: the verdict is the same on any machine, under any load, with or without
 *    sanitizers);
 *  - the input's final world survives a snapshot round trip, and corrupted copies of its snapshot are
 *    refused or load (fz_check_snapshot, fuzz_snapshot_checks.h, which lists what it checks);
 *  - after every step (successful or not): time and every state number are finite, and no two
 *    bodies (except static-static pairs, which the engine never separates) overlap by more than
 *    FZ_OVERLAP_TOL + round-off, measured here with our own separating-axis test on the world
 *    vertices the API reports.
 * Bodies are only kept when they do not overlap another at creation (the API allows spawning into
 * overlap; resolving that is not the step's job), and a pose change that creates an overlap is
 * undone the same way.
 *
 * Built two ways from this file and fuzz_snapshot_checks.c (which includes libcollide/src's internal
 * snapshot_checksum.h, so both builds add libcollide/src to the include path):
 *  - with clang -fsanitize=fuzzer,address,undefined: the libFuzzer target (fuzz/run);
 *  - with -DFZ_REPLAY_MAIN and any C99 compiler: a replayer that runs the files named on its
 *    command line (or every file in a directory) through the same code (ctest fuzz_step_regressions).
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "collide/collide.h"
#include "fuzz_fail.h"
#include "fuzz_snapshot_checks.h"

#define MAX_COMMANDS 48
#define MAX_STEPS 24
#define MAX_BODIES 12
#define MAX_SPRINGS 8
/* Work allowed in one step: right-hand-side evaluations of the ODE (lc_counters.force_evaluations).
 * Steps of up to MAX_BODIES bodies need thousands; a million is seconds of CPU, a performance cliff
 * reported as a finding (counted, so the verdict does not depend on the machine's speed). */
#ifndef FZ_MAX_FORCE_EVALS
#define FZ_MAX_FORCE_EVALS 1000000ULL
#endif
/* The other unbounded work of a step: serial impulse passes (lc_counters.serial_iterations), each a
 * small LCP solve. Passing seeds and regressions need at most ~1.2e4 in a step (the 10 000-event
 * cap, about one pass each); 1e5 is seconds of CPU under ASan. */
#ifndef FZ_MAX_SERIAL_ITERS
#define FZ_MAX_SERIAL_ITERS 100000ULL
#endif
/* The cost of those evaluations and passes: matrix entries the complementarity solves visited
 * (lc_counters.solver_work), per body of the world. The engine undoes a step past 1e9 per body
 * (libcollide/src/tunables.h); twice that means its cap failed to stop one (1.7e10 and 110 s for
 * corpus/step-regressions/slow-solver-work-coincident-tiny-decagons without it). */
#ifndef FZ_MAX_SOLVER_WORK_PER_BODY
#define FZ_MAX_SOLVER_WORK_PER_BODY 2e9
#endif
/* Long-run mode (fuzz/run --budget N compiles with -DFZ_INPUT_BUDGET=N): once an input has done N units
 * of work in all (force evaluations + time-of-impact iterations + serial impulse passes, the counters
 * that bound a step), it starts no further step. Work per input is very uneven (in a grown corpus of
 * 6 156 inputs, 1.6 % of them took 66 % of the replay time, most of it steps that hit the engine's
 * own work caps again and again); the budget trades those inputs' later steps for more inputs per
 * second. The per-step bounds above are still checked on every step that runs, so a step's
 * performance cliff is still a finding. Off (0) in the replayer, the ctests and a plain fuzz/run. */
#ifndef FZ_INPUT_BUDGET
#define FZ_INPUT_BUDGET 0ULL
#endif

/* Overlap allowed at the end of a step (m): the engine projects every touch back to contact_gap
 * (>= 1e-12 m), so anything deeper than 1e-9 m is a real overlap, not round-off of the projection. */
#define FZ_OVERLAP_TOL 1e-9

/* ---- reading the input -------------------------------------------------------------------------- */

typedef struct fz_in {
    const uint8_t *p;
    size_t n, i;
} fz_in;

static unsigned fz_u8(fz_in *in) { return in->i < in->n ? in->p[in->i++] : 0u; }
static unsigned fz_u16(fz_in *in) { unsigned a = fz_u8(in); return a | (fz_u8(in) << 8); }
static int fz_done(const fz_in *in) { return in->i >= in->n; }

/* A double that is usually in [lo, hi] but may be anything: special values, huge, raw bits. */
static double fz_num(fz_in *in, double lo, double hi)
{
    static const double special[] = {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 5e-324, 1e-12, 1e-9, 1e6, -1e6,
                                     1e9, -1e9, 1e12, 1e13, -1e13, 1e308, -1e308, 0.5, 2.0};
    unsigned mode = fz_u8(in);
    if (mode < 176) return lo + (hi - lo) * (double)fz_u16(in) / 65535.0;
    if (mode < 232) return special[fz_u8(in) % (sizeof special / sizeof special[0])];
    if (mode < 240) return NAN;
    if (mode < 244) return INFINITY;
    if (mode < 248) return -INFINITY;
    {
        uint64_t bits = 0;
        double d;
        int k;
        for (k = 0; k < 8; ++k) bits |= (uint64_t)fz_u8(in) << (8 * k);
        memcpy(&d, &bits, sizeof d);
        return d;
    }
}

static int fz_int(fz_in *in, int lo, int hi)
{
    unsigned mode = fz_u8(in);
    if (mode < 200) return lo + (int)(fz_u16(in) % (unsigned)(hi - lo + 1));
    switch (mode % 6) {
    case 0: return 0;
    case 1: return -1;
    case 2: return hi + 1;
    case 3: return lo - 1;
    case 4: return 2147483647;
    default: return (int)(0x80000000u | fz_u16(in));
    }
}

/* FZ_TRACE=1 in the environment: the replayer prints every command and step (to study a finding). */
static int fz_trace(void)
{
#ifdef FZ_REPLAY_MAIN
    static int t = -1; /* the replayer's only mutable static; the harness itself keeps none */
    if (t < 0) t = getenv("FZ_TRACE") != NULL;
    return t;
#else
    return 0;
#endif
}

/* ---- failure ------------------------------------------------------------------------------------ */

/* A call's status: OK, or an error that says why and left the world as it was. */
static lc_status fz_check(const lc_world *w, lc_status s, uint64_t hash_before, const char *call)
{
    char msg[512];
    if (s == LC_OK) return s;
    if (s < LC_OK || s > LC_ERR_CALLBACK) {
        snprintf(msg, sizeof msg, "%s returned unknown status %d", call, (int)s);
        fz_fail(msg, NULL);
    }
#ifndef FZ_ALLOW_EMPTY_MESSAGE /* only to explore past a failure of this check (fuzz/run --explore) */
    if (lc_world_last_error(w) == NULL || lc_world_last_error(w)[0] == '\0') {
        snprintf(msg, sizeof msg, "%s failed with %s but lc_world_last_error() is empty", call, lc_status_string(s));
        fz_fail(msg, NULL);
    }
#endif
    if (lc_world_state_hash(w) != hash_before) {
        snprintf(msg, sizeof msg, "%s failed (%s: %s) but changed the state", call, lc_status_string(s),
                 lc_world_last_error(w));
        fz_fail(msg, NULL);
    }
    return s;
}
#define FZ_CALL(w, expr) fz_check((w), (expr), fz_h_, #expr)

/* ---- geometry: our own separating-axis test ------------------------------------------------------ */

typedef struct fz_poly {
    int n;
    lc_vec2 v[LC_MAX_POLYGON_VERTICES];
    double scale; /* max |coordinate|, for the round-off allowance */
} fz_poly;

static int fz_world_poly(const lc_world *w, lc_body_id id, fz_poly *out)
{
    int i;
    out->n = lc_body_vertex_count(w, id);
    if (out->n < 3 || out->n > LC_MAX_POLYGON_VERTICES) return 0;
    if (lc_body_get_world_vertices(w, id, out->v, LC_MAX_POLYGON_VERTICES) != LC_OK) return 0;
    out->scale = 0.0;
    for (i = 0; i < out->n; ++i) out->scale = fmax(out->scale, fmax(fabs(out->v[i].x), fabs(out->v[i].y)));
    return 1;
}

/* Signed area twice (orientation of the reported vertices). */
static double fz_area2(const fz_poly *p)
{
    double a = 0.0;
    int i;
    for (i = 0; i < p->n; ++i) {
        lc_vec2 u = p->v[i], v = p->v[(i + 1) % p->n];
        a += u.x * v.y - u.y * v.x;
    }
    return a;
}

/* Largest separation of b's vertices from a's edges' lines (outward), i.e. SAT over a's normals. */
static double fz_sep_one_way(const fz_poly *a, const fz_poly *b)
{
    double best = -INFINITY, orient = fz_area2(a) > 0.0 ? 1.0 : -1.0;
    int i, j;
    for (i = 0; i < a->n; ++i) {
        lc_vec2 p = a->v[i], q = a->v[(i + 1) % a->n];
        double ex = q.x - p.x, ey = q.y - p.y, len = sqrt(ex * ex + ey * ey), nx, ny, m = INFINITY;
        if (!(len > 0.0)) continue;
        nx = orient * ey / len; /* outward normal of a counter-clockwise edge is (ey, -ex) */
        ny = -orient * ex / len;
        for (j = 0; j < b->n; ++j) m = fmin(m, nx * (b->v[j].x - p.x) + ny * (b->v[j].y - p.y));
        best = fmax(best, m);
    }
    return best;
}

/* > 0: apart by at least that; < 0: overlapping by that depth (exact for convex polygons). */
static double fz_separation(const fz_poly *a, const fz_poly *b)
{
    return fmax(fz_sep_one_way(a, b), fz_sep_one_way(b, a));
}

/* Round-off allowance: the world vertices are rotations of body-frame vertices, computed and
 * compared at the scale of the coordinates; a few hundred ulps of that scale is far below any real
 * overlap at everyday scales (1e-13 m at 10 m) and keeps bodies placed near 1e9 m honest too. */
static double fz_tol(const fz_poly *a, const fz_poly *b)
{
    return FZ_OVERLAP_TOL + 256.0 * DBL_EPSILON * fmax(a->scale, b->scale);
}

/* 1 if body `id` overlaps any other non-static-pair body beyond the tolerance. */
static int fz_overlaps_any(const lc_world *w, lc_body_id id, double *depth, lc_body_id *other)
{
    lc_state_view v;
    fz_poly a, b;
    int i, ia;
    if (lc_world_get_state(w, &v) != LC_OK) return 0;
    ia = lc_world_body_index(w, id);
    if (ia < 0 || !fz_world_poly(w, id, &a)) return 0;
    for (i = 0; i < v.count; ++i) {
        double s;
        if (v.ids[i] == id || (v.is_static[i] && v.is_static[ia])) continue;
        if (!fz_world_poly(w, v.ids[i], &b)) continue;
        s = fz_separation(&a, &b);
        /* -inf: one polygon has no edge left in doubles (a 1e-12 m polygon flung past 1e4 m, where
         * its vertices round to one point); its overlap is not measurable, not infinite */
        if (!isfinite(s)) continue;
        if (s < -fz_tol(&a, &b)) {
            if (depth) *depth = -s;
            if (other) *other = v.ids[i];
            return 1;
        }
    }
    return 0;
}

static void fz_check_world(const lc_world *w, const char *after)
{
    lc_state_view v;
    char msg[512];
    int i, k;
    double t = lc_world_get_time(w);
    if (!isfinite(t)) fz_fail("time is not finite", after);
    if (lc_world_get_state(w, &v) != LC_OK) fz_fail("lc_world_get_state failed", after);
    for (i = 0; i < v.count * 6; ++i)
        if (!isfinite(v.state[i])) {
            snprintf(msg, sizeof msg, "state[%d][%d] = %g after %s", i / 6, i % 6, v.state[i], after);
            fz_fail("non-finite state", msg);
        }
    for (i = 0; i < v.count; ++i) {
        double depth = 0.0;
        lc_body_id other = 0;
        if (v.is_static[i]) continue; /* dynamic-vs-anything covers every pair that matters */
        if (fz_overlaps_any(w, v.ids[i], &depth, &other)) {
            snprintf(msg, sizeof msg, "bodies %u and %u overlap by %.3g m after %s (t = %.17g)",
                     (unsigned)v.ids[i], (unsigned)other, depth, after, t);
            fz_fail("overlap", msg);
        }
    }
    for (k = 0; k < v.count; ++k)
        if (!(v.mass[k] >= 0.0) || !isfinite(v.inertia[k])) fz_fail("mass or inertia not finite", after);
}

/* ---- building blocks ------------------------------------------------------------------------------ */

typedef struct fz_ctx {
    lc_world *w;
    lc_body_id bodies[MAX_BODIES];
    int nbodies;
    lc_spring_id springs[MAX_SPRINGS];
    int nsprings;
    int steps;
    unsigned long long work; /* work units of the input so far (FZ_INPUT_BUDGET) */
} fz_ctx;

/* Whether the input may start another step. */
static int fz_may_step(const fz_ctx *c)
{
    return c->steps < MAX_STEPS && (FZ_INPUT_BUDGET == 0ULL || c->work <= FZ_INPUT_BUDGET);
}

static lc_body_id fz_pick_body(fz_in *in, const fz_ctx *c)
{
    unsigned k = fz_u8(in);
    if (c->nbodies == 0 || k >= 240) return (lc_body_id)(k == 255 ? LC_WORLD_ANCHOR : k); /* unknown ids too */
    return c->bodies[k % (unsigned)c->nbodies];
}

static lc_spring_id fz_pick_spring(fz_in *in, const fz_ctx *c)
{
    unsigned k = fz_u8(in);
    if (c->nsprings == 0 || k >= 240) return (lc_spring_id)k;
    return c->springs[k % (unsigned)c->nsprings];
}

static void fz_forget_body(fz_ctx *c, lc_body_id id)
{
    int i, k = 0;
    for (i = 0; i < c->nbodies; ++i)
        if (c->bodies[i] != id) c->bodies[k++] = c->bodies[i];
    c->nbodies = k;
}

static lc_vec2 fz_vec(fz_in *in, double lo, double hi)
{
    lc_vec2 v;
    v.x = fz_num(in, lo, hi);
    v.y = fz_num(in, lo, hi);
    return v;
}

/* Polygon: a box, a perturbed regular k-gon (mostly valid), or raw points (mostly invalid). */
static int fz_polygon(fz_in *in, lc_vec2 *v, int cap)
{
    unsigned mode = fz_u8(in) % 4;
    int n, i;
    if (mode == 0) {
        double wd = fz_num(in, 0.05, 4.0), ht = fz_num(in, 0.05, 4.0);
        if (lc_make_rectangle(wd, ht, v) != LC_OK) { v[0].x = wd; v[0].y = ht; return 1; }
        return 4;
    }
    if (mode == 1 || mode == 2) {
        double r = fz_num(in, 0.05, 2.0), jitter = mode == 2 ? 0.3 : 0.0, phase = fz_num(in, 0.0, 6.283185307179586);
        n = 3 + (int)(fz_u8(in) % 14);
        if (fz_u8(in) == 0xFF) n = 2 + (int)(fz_u8(in) % 80); /* too few / too many sometimes */
        if (n > cap) n = cap;
        for (i = 0; i < n; ++i) {
            double a = phase + 6.283185307179586 * (double)i / (double)n;
            double rr = r * (1.0 + jitter * ((double)fz_u8(in) / 255.0 - 0.5));
            v[i].x = rr * cos(a);
            v[i].y = rr * sin(a);
        }
        if (fz_u8(in) & 1) /* clockwise winding */
            for (i = 0; i < n / 2; ++i) { lc_vec2 t = v[i]; v[i] = v[n - 1 - i]; v[n - 1 - i] = t; }
        return n;
    }
    n = (int)(fz_u8(in) % 10);
    if (n > cap) n = cap;
    for (i = 0; i < n; ++i) v[i] = fz_vec(in, -2.0, 2.0);
    return n;
}

static void fz_add_body(fz_in *in, fz_ctx *c)
{
    lc_vec2 verts[LC_MAX_POLYGON_VERTICES + 20];
    lc_body_def d = lc_default_body_def();
    lc_body_id id = 0;
    uint64_t fz_h_ = lc_world_state_hash(c->w);
    unsigned t = fz_u8(in);
    if (c->nbodies >= MAX_BODIES) return;
    d.vertex_count = fz_polygon(in, verts, LC_MAX_POLYGON_VERTICES + 20);
    d.vertices = verts;
    d.type = t < 200 ? LC_BODY_DYNAMIC : t < 250 ? LC_BODY_STATIC : (lc_body_type)(int)t;
    d.position = fz_vec(in, -8.0, 8.0);
    d.angle = fz_num(in, -3.2, 3.2);
    d.velocity = fz_vec(in, -10.0, 10.0);
    d.angular_velocity = fz_num(in, -5.0, 5.0);
    d.mass = fz_num(in, 0.1, 10.0);
    d.elasticity = fz_num(in, 0.0, 1.0);
    d.friction = fz_num(in, 0.0, 1.0);
    if (fz_u8(in) == 7) d.vertices = NULL;
    if (fz_trace()) {
        int k;
        fprintf(stderr, "fuzz_step: add_body type=%d pos=(%.17g, %.17g) angle=%.17g v=(%.17g, %.17g) w=%.17g m=%.17g e=%.17g f=%.17g verts",
                (int)d.type, d.position.x, d.position.y, d.angle, d.velocity.x, d.velocity.y, d.angular_velocity,
                d.mass, d.elasticity, d.friction);
        for (k = 0; k < d.vertex_count && d.vertices; ++k) fprintf(stderr, " (%.17g, %.17g)", verts[k].x, verts[k].y);
        fprintf(stderr, "\n");
    }
    if (FZ_CALL(c->w, lc_world_add_body(c->w, &d, &id)) != LC_OK) return;
    if (fz_overlaps_any(c->w, id, NULL, NULL)) {
        /* spawned into another body: not a state the step is asked to start from */
        fz_h_ = lc_world_state_hash(c->w);
        if (FZ_CALL(c->w, lc_world_remove_body(c->w, id)) != LC_OK) fz_fail("cannot remove a new body", NULL);
        return;
    }
    c->bodies[c->nbodies++] = id;
}

static void fz_set_pose(fz_in *in, fz_ctx *c)
{
    lc_body_id id = fz_pick_body(in, c);
    lc_vec2 p = fz_vec(in, -8.0, 8.0);
    double a = fz_num(in, -3.2, 3.2);
    lc_state_view v;
    double old[3] = {0, 0, 0};
    int row = lc_world_body_index(c->w, id);
    uint64_t fz_h_ = lc_world_state_hash(c->w);
    if (row >= 0 && lc_world_get_state(c->w, &v) == LC_OK) memcpy(old, &v.state[row * 6], sizeof old);
    /* The dynamics may take a body beyond what lc_body_set_pose accepts (|x|, |angle| <= 1e9: a 1e-300 kg
     * body under a 1 N force is at 1e298 m after one step: corpus/step-regressions/
     * harness-pose-beyond-1e9m-featherweight-pushed); its pose could not be put back after a move into
     * overlap, so it is not moved */
    if (fabs(old[0]) > 1e9 || fabs(old[1]) > 1e9 || fabs(old[2]) > 1e9) return;
    if (FZ_CALL(c->w, lc_body_set_pose(c->w, id, p, a)) != LC_OK) return;
    if (fz_overlaps_any(c->w, id, NULL, NULL)) {
        lc_vec2 o;
        o.x = old[0];
        o.y = old[1];
        fz_h_ = lc_world_state_hash(c->w);
        if (FZ_CALL(c->w, lc_body_set_pose(c->w, id, o, old[2])) != LC_OK) fz_fail("cannot restore a pose", NULL);
    }
}

static void fz_set_def(fz_in *in, lc_world_def *d)
{
    unsigned n = fz_u8(in) % 6, k;
    for (k = 0; k < n; ++k) {
        switch (fz_u8(in) % 24) {
        case 0: d->gravity = fz_vec(in, -20.0, 20.0); break;
        case 1: d->zero_energy_level = fz_num(in, -10.0, 10.0); break;
        case 2: d->damping = fz_num(in, 0.0, 2.0); break;
        case 3: d->damping_rotation_ratio = fz_num(in, 0.0, 1.0); break;
        case 4: d->integrator = (lc_integrator)fz_int(in, 1, 4); break;
        case 5: d->impact_mode = (lc_impact_mode)fz_int(in, 0, 1); break;
        case 6: d->toi_method = (lc_toi_method)fz_int(in, 0, 1); break;
        case 7: d->toi_time_tolerance = fz_num(in, 1e-14, 1e-3); break;
        case 8: d->toi_distance_tolerance = fz_num(in, 1e-14, 1e-8); break;
        case 9: d->toi_max_iterations = fz_int(in, 4, 200); break;
        case 10: d->contact_gap = fz_num(in, 1e-10, 1e-5); break;
        case 11: d->contact_distance = fz_num(in, 1e-6, 1e-3); break;
        case 12:   /* the threshold follows from resting_speed, taking no byte, so the corpus keeps its decoding */
            d->resting_speed = fz_num(in, 0.0, 1e-2);
            d->restitution_threshold = 100.0 * d->resting_speed;
            break;
        case 13: d->stabilization = (lc_stabilization)fz_int(in, 0, 2); break;
        case 14: d->elasticity_rule = (lc_mix_rule)fz_int(in, 0, 3); break;
        case 15: d->friction_rule = (lc_mix_rule)fz_int(in, 0, 3); break;
        case 16: d->max_events_per_step = fz_int(in, 1, 2000); break;
        case 17: d->max_serial_iterations = fz_int(in, 1, 2000); break;
        case 18: d->lcp_exact_max = fz_int(in, 0, 256); break;
        case 19: d->lcp_max_iterations = fz_int(in, 1, 500); break;
        case 20: d->lcp_tolerance = fz_num(in, 0.0, 1e-6); break;
        case 21: d->broadphase = (lc_broadphase)fz_int(in, 0, 3); break;
        case 22: d->broadphase_threshold = fz_int(in, 2, 16); break;
        default: d->gravity.y = -9.81; break;
        }
    }
}

static void fz_step(fz_in *in, fz_ctx *c)
{
    unsigned n = 1 + fz_u8(in) % 4, k;
    double dt = fz_u8(in) < 224 ? 0.001 * (double)(1 + fz_u8(in) % 50) : fz_num(in, 0.0, 1.0);
    char after[96];
    for (k = 0; k < n && fz_may_step(c); ++k, ++c->steps) {
        uint64_t fz_h_ = lc_world_state_hash(c->w);
        lc_status s;
        if (fz_trace()) {
            lc_world_def d;
            lc_state_view v;
            int i;
            lc_world_get_def(c->w, &d);
            lc_world_get_state(c->w, &v);
            fprintf(stderr, "fuzz_step: step %d dt=%.17g integrator=%d impact=%d toi=%d tol=%g/%g it=%d gap=%g dist=%g rest=%g bounce=%g stab=%d ev=%d ser=%d lcpx=%d lcpit=%d lcptol=%g g=(%.17g, %.17g) z=%.17g damp=%.17g ratio=%.17g rules=%d/%d bp=%d/%d\n",
                    c->steps, dt, (int)d.integrator, (int)d.impact_mode, (int)d.toi_method, d.toi_time_tolerance,
                    d.toi_distance_tolerance, d.toi_max_iterations, d.contact_gap, d.contact_distance, d.resting_speed,
                    d.restitution_threshold, (int)d.stabilization, d.max_events_per_step, d.max_serial_iterations, d.lcp_exact_max,
                    d.lcp_max_iterations, d.lcp_tolerance, d.gravity.x, d.gravity.y, d.zero_energy_level, d.damping,
                    d.damping_rotation_ratio, (int)d.elasticity_rule, (int)d.friction_rule, (int)d.broadphase,
                    d.broadphase_threshold);
            for (i = 0; i < v.count; ++i)
                fprintf(stderr, "  body %u static=%d m=%g x=%g y=%g a=%g vx=%g vy=%g w=%g n=%d\n", (unsigned)v.ids[i],
                        v.is_static[i], v.mass[i], v.state[6 * i], v.state[6 * i + 1], v.state[6 * i + 2],
                        v.state[6 * i + 3], v.state[6 * i + 4], v.state[6 * i + 5], lc_body_vertex_count(c->w, v.ids[i]));
            for (i = 0; i < v.count; ++i) {
                lc_vec2 lv[LC_MAX_POLYGON_VERTICES];
                int k, nv = lc_body_vertex_count(c->w, v.ids[i]);
                if (v.is_static[i] || lc_body_get_world_vertices(c->w, v.ids[i], lv, LC_MAX_POLYGON_VERTICES) != LC_OK) continue;
                fprintf(stderr, "  body %u world vertices:", (unsigned)v.ids[i]);
                for (k = 0; k < nv; ++k) fprintf(stderr, " (%.17g, %.17g)", lv[k].x, lv[k].y);
                fprintf(stderr, "\n");
            }
        }
        s = lc_world_step(c->w, dt);
        if (fz_trace()) {
            lc_counters last;
            lc_world_get_counters(c->w, &last, NULL);
            fprintf(stderr, "fuzz_step: -> %s: collisions %llu, toi searches %llu, toi iterations %llu, serial %llu, "
                    "contact solves %llu, force evaluations %llu, solver work %.4g%s%s\n", lc_status_string(s),
                    (unsigned long long)last.collisions, (unsigned long long)last.toi_searches,
                    (unsigned long long)last.toi_iterations, (unsigned long long)last.serial_iterations,
                    (unsigned long long)last.contact_solves, (unsigned long long)last.force_evaluations,
                    (double)last.solver_work, s != LC_OK ? ": " : "", s != LC_OK ? lc_world_last_error(c->w) : "");
        }
        snprintf(after, sizeof after, "step %d (dt = %.17g, %s)", c->steps, dt, lc_status_string(s));
        if (s != LC_OK) {
            /* a failed step is undone: the hash must not change */
            fz_check(c->w, s, fz_h_, "lc_world_step");
        }
        fz_check_world(c->w, after);
        {
            lc_counters last;
            char msg[160];
            if (lc_world_get_counters(c->w, &last, NULL) != LC_OK) fz_fail("lc_world_get_counters failed", after);
            c->work += last.force_evaluations + last.toi_iterations + last.serial_iterations;
            /* failed steps too: a step that gives up after seconds of work is as slow as one that succeeds */
            if (last.force_evaluations > FZ_MAX_FORCE_EVALS) {
                snprintf(msg, sizeof msg, "%llu force evaluations in %s", (unsigned long long)last.force_evaluations, after);
                fz_fail("one step took more than FZ_MAX_FORCE_EVALS force evaluations", msg);
            }
            if (last.serial_iterations > FZ_MAX_SERIAL_ITERS) {
                snprintf(msg, sizeof msg, "%llu serial impulse iterations in %s", (unsigned long long)last.serial_iterations,
                         after);
                fz_fail("one step took more than FZ_MAX_SERIAL_ITERS serial impulse iterations", msg);
            }
            /* only a step that ran (kept or undone): a call refused before it runs (dt = inf) leaves the
             * counters of an earlier step, which may have had more bodies than the world has now */
            if ((s == LC_OK || s == LC_ERR_NUMERIC || s == LC_ERR_NO_MEMORY) &&
                (double)last.solver_work > FZ_MAX_SOLVER_WORK_PER_BODY * (double)lc_world_body_count(c->w)) {
                snprintf(msg, sizeof msg, "solver work %.3g with %d bodies in %s", (double)last.solver_work,
                         lc_world_body_count(c->w), after);
                fz_fail("one step's solves took more than FZ_MAX_SOLVER_WORK_PER_BODY per body", msg);
            }
        }
        if (s != LC_OK) break;
    }
}

static void fz_getters(fz_in *in, fz_ctx *c)
{
    const lc_contact *cs = NULL;
    int ncs = 0, i;
    lc_energy e;
    lc_counters last, total;
    lc_vec2 buf[LC_MAX_POLYGON_VERTICES], a, b;
    lc_spring_def sd;
    lc_world_def wd;
    lc_body_id id = fz_pick_body(in, c);
    lc_spring_id sid = fz_pick_spring(in, c);
    int cap = fz_int(in, 0, LC_MAX_POLYGON_VERTICES);
    uint64_t fz_h_ = lc_world_state_hash(c->w);
    if (cap > LC_MAX_POLYGON_VERTICES) cap = LC_MAX_POLYGON_VERTICES; /* our buffer's real size */
    if (FZ_CALL(c->w, lc_world_get_contacts(c->w, &cs, &ncs)) == LC_OK) {
        if (ncs < 0 || (ncs > 0 && cs == NULL)) fz_fail("contacts: bad count or pointer", NULL);
        for (i = 0; i < ncs; ++i)
            if (!isfinite(cs[i].point.x) || !isfinite(cs[i].point.y) || !isfinite(cs[i].normal.x) ||
                !isfinite(cs[i].gap) || !isfinite(cs[i].impulse) || !isfinite(cs[i].force))
                fz_fail("contact with a non-finite field", NULL);
    }
    (void)FZ_CALL(c->w, lc_world_get_energy(c->w, &e));
    (void)FZ_CALL(c->w, lc_world_get_counters(c->w, &last, &total));
    (void)FZ_CALL(c->w, lc_world_get_counters(c->w, NULL, NULL));
    (void)FZ_CALL(c->w, lc_world_get_def(c->w, &wd));
    (void)FZ_CALL(c->w, lc_body_get_local_vertices(c->w, id, buf, cap));
    (void)FZ_CALL(c->w, lc_body_get_world_vertices(c->w, id, buf, cap));
    (void)FZ_CALL(c->w, lc_body_get_center_offset(c->w, id, &a));
    (void)FZ_CALL(c->w, lc_spring_get_def(c->w, sid, &sd));
    (void)FZ_CALL(c->w, lc_spring_get_endpoints(c->w, sid, &a, &b));
    (void)FZ_CALL(c->w, lc_body_get_world_vertices(c->w, id, NULL, cap));
    (void)lc_body_thruster_count(c->w, id);
    (void)lc_body_vertex_count(c->w, id);
    (void)lc_world_spring_count(c->w);
}

static void fz_command(fz_in *in, fz_ctx *c)
{
    uint64_t fz_h_ = lc_world_state_hash(c->w);
    lc_world *w = c->w;
    unsigned op = fz_u8(in) % 22;
    if (fz_trace()) fprintf(stderr, "fuzz_step: command %u (%d bodies, %d springs)\n", op, lc_world_body_count(w), lc_world_spring_count(w));
    switch (op) {
    case 0: case 1: case 2: fz_add_body(in, c); break;
    case 3: {
        lc_body_id id = fz_pick_body(in, c);
        if (FZ_CALL(w, lc_world_remove_body(w, id)) == LC_OK) fz_forget_body(c, id);
        break;
    }
    case 4: fz_set_pose(in, c); break;
    case 5: {
        lc_body_id id = fz_pick_body(in, c);
        lc_vec2 v = fz_vec(in, -20.0, 20.0);
        (void)FZ_CALL(w, lc_body_set_velocity(w, id, v, fz_num(in, -10.0, 10.0)));
        break;
    }
    case 6: {
        lc_body_id id = fz_pick_body(in, c);
        (void)FZ_CALL(w, lc_body_set_mass(w, id, fz_num(in, 0.01, 100.0)));
        break;
    }
    case 7: {
        lc_body_id id = fz_pick_body(in, c);
        double e = fz_num(in, 0.0, 1.0);
        (void)FZ_CALL(w, lc_body_set_material(w, id, e, fz_num(in, 0.0, 2.0)));
        break;
    }
    case 8: {
        lc_body_id id = fz_pick_body(in, c);
        lc_vec2 f = fz_vec(in, -50.0, 50.0);
        (void)FZ_CALL(w, lc_body_set_external(w, id, f, fz_num(in, -20.0, 20.0)));
        break;
    }
    case 9: {
        lc_body_id id = fz_pick_body(in, c);
        lc_thruster_def td;
        int idx = -1;
        td.point = fz_vec(in, -1.0, 1.0);
        td.direction = fz_vec(in, -1.0, 1.0);
        td.magnitude = fz_num(in, 0.0, 20.0);
        (void)FZ_CALL(w, lc_body_add_thruster(w, id, &td, fz_u8(in) & 1 ? &idx : NULL));
        break;
    }
    case 10: {
        lc_body_id id = fz_pick_body(in, c);
        (void)FZ_CALL(w, lc_body_add_default_thrusters(w, id, fz_num(in, 0.0, 10.0), NULL));
        break;
    }
    case 11: {
        lc_body_id id = fz_pick_body(in, c);
        int idx = fz_int(in, 0, 5);
        (void)FZ_CALL(w, lc_body_set_thruster_level(w, id, idx, fz_num(in, 0.0, 1.0)));
        break;
    }
    case 12: {
        lc_body_id id = fz_pick_body(in, c);
        uint32_t mask = (uint32_t)fz_u16(in) | ((uint32_t)fz_u16(in) << 16);
        (void)FZ_CALL(w, lc_body_set_thruster_mask(w, id, mask));
        break;
    }
    case 13: {
        lc_spring_def sd = lc_default_spring_def();
        lc_spring_id sid = 0;
        if (c->nsprings >= MAX_SPRINGS) break;
        sd.body_a = fz_pick_body(in, c);
        sd.body_b = fz_u8(in) < 128 ? LC_WORLD_ANCHOR : fz_pick_body(in, c);
        sd.point_a = fz_vec(in, -0.5, 0.5);
        sd.point_b = fz_vec(in, -5.0, 5.0);
        sd.stiffness = fz_num(in, 0.0, 20.0);
        sd.damping = fz_num(in, 0.0, 2.0);
        sd.rest_length = fz_num(in, 0.0, 3.0);
        if (fz_trace())
            fprintf(stderr, "fuzz_step: add_spring a=%u b=%u pa=(%.17g, %.17g) pb=(%.17g, %.17g) k=%.17g d=%.17g L0=%.17g\n",
                    (unsigned)sd.body_a, (unsigned)sd.body_b, sd.point_a.x, sd.point_a.y, sd.point_b.x, sd.point_b.y,
                    sd.stiffness, sd.damping, sd.rest_length);
        if (FZ_CALL(w, lc_world_add_spring(w, &sd, fz_u8(in) == 3 ? NULL : &sid)) == LC_OK)
            c->springs[c->nsprings++] = sid;
        break;
    }
    case 14: {
        lc_spring_id sid = fz_pick_spring(in, c);
        if (FZ_CALL(w, lc_world_remove_spring(w, sid)) == LC_OK) {
            int i, k = 0;
            for (i = 0; i < c->nsprings; ++i)
                if (c->springs[i] != sid) c->springs[k++] = c->springs[i];
            c->nsprings = k;
        }
        break;
    }
    case 15: {
        lc_spring_id sid = fz_pick_spring(in, c);
        (void)FZ_CALL(w, lc_spring_set_target(w, sid, fz_vec(in, -8.0, 8.0)));
        break;
    }
    case 16: {
        lc_spring_id sid = fz_pick_spring(in, c);
        double k = fz_num(in, 0.0, 20.0), d = fz_num(in, 0.0, 2.0);
        (void)FZ_CALL(w, lc_spring_set_params(w, sid, k, d, fz_num(in, 0.0, 3.0)));
        break;
    }
    case 17: {
        unsigned which = fz_u8(in) % 4;
        if (which == 0) (void)FZ_CALL(w, lc_world_set_gravity(w, fz_vec(in, -20.0, 20.0)));
        else if (which == 1) {
            double k = fz_num(in, 0.0, 2.0);
            (void)FZ_CALL(w, lc_world_set_damping(w, k, fz_num(in, 0.0, 1.0)));
        } else if (which == 2) (void)FZ_CALL(w, lc_world_set_elasticity(w, fz_num(in, 0.0, 1.0)));
        else {
            lc_world_def d;
            if (lc_world_get_def(w, &d) != LC_OK) fz_fail("lc_world_get_def failed", NULL);
            fz_set_def(in, &d);
            (void)FZ_CALL(w, lc_world_set_def(w, fz_u8(in) == 9 ? NULL : &d));
        }
        break;
    }
    case 18: {
        /* overwrite velocities through set_state (positions kept: no teleporting into overlap) */
        lc_state_view v;
        double st[MAX_BODIES * 6 + 6];
        int i, count;
        if (lc_world_get_state(w, &v) != LC_OK || v.count > MAX_BODIES || v.count == 0) break;
        memcpy(st, v.state, (size_t)v.count * 6 * sizeof(double));
        for (i = 0; i < v.count; ++i) {
            st[i * 6 + 3] = fz_num(in, -10.0, 10.0);
            st[i * 6 + 4] = fz_num(in, -10.0, 10.0);
            st[i * 6 + 5] = fz_num(in, -5.0, 5.0);
        }
        count = fz_u8(in) == 1 ? v.count + 1 : v.count;
        (void)FZ_CALL(w, lc_world_set_state(w, st, count));
        break;
    }
    case 19: {
        lc_body_id ids[4];
        if (c->nbodies + 4 > MAX_BODIES) break;
        double x0 = fz_num(in, -30.0, -6.0), y0 = fz_num(in, -30.0, -6.0);
        double x1 = fz_num(in, 6.0, 30.0), y1 = fz_num(in, 6.0, 30.0);
        double th = fz_num(in, 0.1, 2.0);
        if (FZ_CALL(w, lc_world_add_walls(w, x0, y0, x1, y1, th, fz_num(in, 0.0, 1.0), ids)) == LC_OK) {
            int i;
            for (i = 0; i < 4; ++i) {
                if (fz_overlaps_any(w, ids[i], NULL, NULL)) {
                    fz_h_ = lc_world_state_hash(w);
                    if (FZ_CALL(w, lc_world_remove_body(w, ids[i])) != LC_OK) fz_fail("cannot remove a wall", NULL);
                } else {
                    c->bodies[c->nbodies++] = ids[i];
                }
            }
        }
        break;
    }
    case 20: fz_getters(in, c); break;
    default: fz_step(in, c); break;
    }
}

/* ---- entry point ----------------------------------------------------------------------------------- */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_in in;
    fz_ctx c;
    lc_world_def d = lc_default_world_def();
    char err[256];
    int k, no_errbuf;
    in.p = data;
    in.n = size;
    in.i = 0;
    memset(&c, 0, sizeof c);
    fz_set_def(&in, &d);
    err[0] = '\0';
    no_errbuf = fz_u8(&in) == 5;
    c.w = lc_world_create(&d, no_errbuf ? NULL : err, sizeof err);
    if (c.w == NULL) {
        if (!no_errbuf && err[0] == '\0') fz_fail("lc_world_create failed with an empty message", NULL);
        d = lc_default_world_def();
        c.w = lc_world_create(&d, err, sizeof err);
        if (c.w == NULL) fz_fail("lc_world_create failed on the default settings", err);
    }
    if (fz_u8(&in) < 160) { /* the seed's walled box */
        lc_body_id ids[4];
        if (lc_world_add_walls(c.w, -6.0, -6.0, 6.0, 6.0, 1.0, 1.0, ids) != LC_OK) fz_fail("walls", NULL);
        for (k = 0; k < 4; ++k) c.bodies[c.nbodies++] = ids[k];
    }
    for (k = 0; k < MAX_COMMANDS && !fz_done(&in) && fz_may_step(&c); ++k) fz_command(&in, &c);
    if (c.steps == 0) fz_step(&in, &c); /* every input steps at least once */
    fz_check_snapshot(c.w);
    lc_world_destroy(c.w);
#ifdef FZ_REPLAY_MAIN
    {
        /* a regression for slowness carries its own bound on the input's whole work (the replayer sets
         * FZ_WORK_BOUND from fuzz/corpus/step-work-bounds.txt): the per-step bounds above are far above
         * what such inputs do, so only their own bound catches their slowness coming back */
        const char *bound = getenv("FZ_WORK_BOUND");
        char msg[96];
        snprintf(msg, sizeof msg, "%llu units (bound %s)", c.work, bound ? bound : "none");
        if (fz_trace()) fprintf(stderr, "fuzz_step: work of the input: %s\n", msg);
        if (bound != NULL && c.work > strtoull(bound, NULL, 10))
            fz_fail("the input took more work than its bound in step-work-bounds.txt", msg);
    }
#endif
    return 0;
}

#ifdef FZ_REPLAY_MAIN
/* Replayer: runs each named file (or each file in a named directory) through the harness, each in
 * its own child process so one broken invariant (abort) or hang (alarm) does not hide the others. */
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

/* Slowness is judged by the work counters above (the same verdict on any machine); this alarm only
 * ends a step that never returns. Inputs within the work bounds take seconds under ASan; those over
 * them (findings) took up to 41 s under ASan on the 2-core machine at load 6, so 120 s is a hang. */
#define FZ_REPLAY_SECONDS 120

/* The work bound of an input (0: none) from the lines "name bound" of a bounds file, by base name. */
static unsigned long long fz_work_bound(const char *bounds_file, const char *path)
{
    FILE *f;
    char line[512], name[256];
    unsigned long long bound, found = 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (bounds_file == NULL || (f = fopen(bounds_file, "r")) == NULL) return 0;
    while (fgets(line, sizeof line, f) != NULL)
        if (line[0] != '#' && sscanf(line, "%255s %llu", name, &bound) == 2 && strcmp(name, base) == 0) found = bound;
    fclose(f);
    return found;
}

static int fz_replay_file(const char *path, const char *bounds_file)
{
    unsigned long long bound = fz_work_bound(bounds_file, path);
    FILE *f;
    uint8_t *buf;
    long n;
    pid_t pid;
    int status = 0;
    fflush(NULL);
    pid = fork();
    if (pid < 0) { perror("fork"); return 1; }
    if (pid > 0) {
        if (waitpid(pid, &status, 0) < 0) return 1;
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return 0;
        if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM)
            fprintf(stderr, "fuzz_step: FAIL %s: no result after %d s (hang)\n", path, FZ_REPLAY_SECONDS);
        else
            fprintf(stderr, "fuzz_step: FAIL %s (%s %d)\n", path, WIFSIGNALED(status) ? "signal" : "exit code",
                    WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
        return 1;
    }
    alarm(FZ_REPLAY_SECONDS);
    if (bound > 0) {
        char b[32];
        snprintf(b, sizeof b, "%llu", bound);
        if (setenv("FZ_WORK_BOUND", b, 1) != 0) _exit(2);
    }
    f = fopen(path, "rb");
    if (f == NULL) { fprintf(stderr, "fuzz_step: cannot open %s\n", path); _exit(2); }
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) _exit(2);
    buf = malloc((size_t)n + 1);
    if (buf == NULL || fread(buf, 1, (size_t)n, f) != (size_t)n) _exit(2);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, (size_t)n);
    free(buf);
    exit(0); /* exit, not _exit: sanitizer leak checks run at exit */
}

/* fuzz_step_replay [--work-bounds FILE] PATH...: each file, or each file of each directory */
int main(int argc, char **argv)
{
    int i = 1, files = 0, bad = 0;
    const char *bounds_file = NULL;
    if (argc > 2 && strcmp(argv[1], "--work-bounds") == 0) {
        FILE *f = fopen(argv[2], "r");
        if (f == NULL) { fprintf(stderr, "fuzz_step: cannot open %s\n", argv[2]); return 1; }
        fclose(f);
        bounds_file = argv[2];
        i = 3;
    }
    for (; i < argc; ++i) {
        struct stat st;
        if (stat(argv[i], &st) != 0) { fprintf(stderr, "fuzz_step: no such path %s\n", argv[i]); return 1; }
        if (S_ISDIR(st.st_mode)) {
            DIR *dir = opendir(argv[i]);
            struct dirent *e;
            char path[4096];
            if (dir == NULL) return 1;
            while ((e = readdir(dir)) != NULL) {
                if (e->d_name[0] == '.') continue;
                snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
                bad += fz_replay_file(path, bounds_file);
                files++;
            }
            closedir(dir);
        } else {
            bad += fz_replay_file(argv[i], bounds_file);
            files++;
        }
    }
    printf("fuzz_step: replayed %d inputs, %d failed\n", files, bad);
    return bad != 0 || files == 0;
}
#endif
