/* The contact regime (contact_regime.h, docs/contact_regime.md): one island advanced by velocity-level
 * time stepping. A step of h is
 *   1. contacts: every vertex-edge point of the island's pairs within contact_distance, or within the
 *      distance the pair can close in the step (speculative points);
 *   2. impacts: points touching (or, in an island of several bodies, arriving within the first half of
 *      the step) that approach get the compression impulse that stops every approach, then Poisson's
 *      restitution e j_c where their approach was fast enough to bounce, then a second compression
 *      that stops what the restitution drove into other touches; in a Moreau-Jean sub-step (step 5)
 *      only when a touching point approaches faster than resting_speed; in a pile sub-step
 *      (LC_CONTACT_PILE_BODIES) never: the flow's targets hold Newton's restitution instead;
 *   3. flow: one complementarity problem in the contact impulses over h: with v = v_0 + h M^-1 F + M^-1
 *      J^T lambda, each point's normal velocity at the end keeps its gap at or above the contact gap
 *      under the sub-step's position update (trapezoidal: u_n >= -u_n0 - 2 (gap - contact_gap)^+ / h;
 *      Moreau-Jean: u_n >= -(gap - contact_gap)^+ / h; an impact point of a pile sub-step:
 *      u_n >= -e u_n0 if it bounces, else, arriving, u_n >= 0), Coulomb
 *      friction in the exact 2D cone, warm-started from the last step's forces (contact_cache.c),
 *      solved by nonsmooth Gauss-Seidel (contact_solver.c), and in a precise retry of few points exactly
 *      (contact_active_set.c, else contact_exact.c);
 *   4. in small islands, a stick-slip transition or a new contact's arrival inside the step cuts the
 *      step there, and the rest is taken again from step 1; in a settling sub-step (a large island
 *      moving slower than LC_CONTACT_SETTLE_SPEED, whose solves then run to convergence) an undriven
 *      island whose answer moves no point faster than LC_CONTACT_REST_SPEED rests: its velocities
 *      become 0; an island that rested through its last step at one state and starts this one from it,
 *      with nothing changed or driving it, is still: none of these steps is taken (hold_still);
 *   5. positions: x += h (v_0 + v) / 2 (exact under constant forces), or x += h v (Moreau-Jean) in a
 *      sub-step of several bodies and fewer than LC_CONTACT_MOREAU_JEAN_POINTS points, and in a pile
 *      sub-step;
 *   6. a projection moves overlapping points out by the smallest mass-weighted displacement (a large
 *      pass starting from active sets over a sparse factorization; in a pile sub-step first over the
 *      flow's points, then over a search: contact_projection.c), and an
 *      island without driving forces that still ends with more energy than it began with gives the
 *      excess back from its kinetic energy. An island this cannot keep apart, or whose kinetic energy
 *      cannot pay, is taken again by the event regime (step.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "contact_regime.h"
#include "contact_cache.h"
#include "contact_active_set.h"
#include "contact_exact.h"
#include "contact_solver.h"
#include "contact_island.h"
#include "contact_projection.h"
#include "events.h"
#include "kept_touches.h"
#include "tunables.h"
#include "world.h"

struct lc_contact_regime {
    lc_contact_cache *cache;
    lc_kept_touches *kept;
    lc_contact_projection *projection; /* step 6a */
    lc_buf b_local;      /* int per world row: the row's index in the island being advanced, else -1 */
    int local_rows;      /* rows of b_local that hold -1 outside an island */
    lc_buf b_touch;      /* the sub-step's touches */
    lc_buf b_end;        /* touches at the step's end */
    lc_buf b_rows;       /* solver rows of the flow */
    lc_buf b_irows;      /* solver rows of the impacts */
    lc_buf b_body;       /* per island body: see lc_island_bodies */
    lc_buf b_start;      /* island rows' states at the step's start, nb x 6 */
    lc_buf b_acc;        /* world-sized scratch for lc_applied_accelerations */
    lc_buf b_hash;       /* end touch -> flow row */
    lc_buf b_cold, b_cold_load; /* cold_start: the touching points, their loads and rows */
    lc_buf b_exact;      /* contact_exact.c's and contact_active_set.c's scratch */
    lc_buf b_vstart;     /* start velocities of an exact solve */
    lc_buf b_known;      /* per flow row: 1 if the last step kept a force for its point (even 0) */
    lc_buf b_margin;     /* per island pair: the margin of the last end-of-step search */
    lc_buf b_sweep;      /* the solver's scratch (lc_contact_solver_run) */
};

lc_contact_regime *lc_contact_regime_create(void)
{
    lc_contact_regime *cr = calloc(1, sizeof *cr);
    if (cr == NULL) return NULL;
    cr->cache = lc_contact_cache_create();
    cr->kept = lc_kept_touches_create();
    cr->projection = lc_contact_projection_create();
    if (cr->cache == NULL || cr->kept == NULL || cr->projection == NULL) {
        lc_contact_cache_destroy(cr->cache);
        lc_kept_touches_destroy(cr->kept);
        lc_contact_projection_destroy(cr->projection);
        free(cr);
        return NULL;
    }
    return cr;
}

void lc_contact_regime_destroy(lc_contact_regime *cr)
{
    if (cr == NULL) return;
    lc_contact_cache_destroy(cr->cache);
    lc_kept_touches_destroy(cr->kept);
    lc_contact_projection_destroy(cr->projection);
    lc_buf_free(&cr->b_local);
    lc_buf_free(&cr->b_touch);
    lc_buf_free(&cr->b_end);
    lc_buf_free(&cr->b_rows);
    lc_buf_free(&cr->b_irows);
    lc_buf_free(&cr->b_body);
    lc_buf_free(&cr->b_start);
    lc_buf_free(&cr->b_acc);
    lc_buf_free(&cr->b_hash);
    lc_buf_free(&cr->b_cold);
    lc_buf_free(&cr->b_cold_load);
    lc_buf_free(&cr->b_exact);
    lc_buf_free(&cr->b_vstart);
    lc_buf_free(&cr->b_known);
    lc_buf_free(&cr->b_margin);
    lc_buf_free(&cr->b_sweep);
    free(cr);
}

int lc_contact_regime_begin_step(lc_contact_regime *cr)
{
    int a = lc_contact_cache_next_step(cr->cache), b = lc_kept_touches_next_step(cr->kept);
    return a != 0 || b != 0 ? -1 : 0;
}

void lc_contact_regime_retry(lc_contact_regime *cr)
{
    lc_contact_cache_drop_stored(cr->cache);
    lc_kept_touches_drop_stored(cr->kept);
}

void lc_contact_regime_forget(lc_contact_regime *cr)
{
    lc_contact_cache_clear(cr->cache);
    lc_kept_touches_clear(cr->kept);
}

void lc_contact_regime_save(const lc_contact_regime *cr, const lc_world *w, struct lc_writer *out)
{
    lc_contact_cache_save(cr->cache, out);
    lc_kept_touches_save(cr->kept, w, out);
}

int lc_contact_regime_load(lc_contact_regime *cr, const lc_world *w, struct lc_reader *in)
{
    if (lc_contact_cache_load(cr->cache, in) != 0) return -1;
    return lc_kept_touches_load(cr->kept, w, in);
}

static lc_contact_key key_of(const lc_world *w, const lc_touch *t)
{
    lc_contact_key k;
    k.a = w->ids[t->a];
    k.b = w->ids[t->b];
    k.vertex = t->vertex;
    k.edge = t->edge;
    return k;
}

static int map_island(lc_contact_island *c)
{
    lc_world *w = c->w;
    lc_contact_regime *cr = c->cr;
    int i, nb = c->isl->nrows;
    double *d;
    c->local = lc_buf_get(&cr->b_local, (size_t)(w->count > 0 ? w->count : 1) * sizeof(int));
    if (c->local == NULL) return -1;
    if (cr->local_rows > w->count) cr->local_rows = w->count;
    for (i = cr->local_rows; i < w->count; ++i) c->local[i] = -1;
    cr->local_rows = w->count;
    for (i = 0; i < nb; ++i) c->local[c->isl->rows[i]] = i;
    d = lc_buf_get(&cr->b_body, (size_t)(nb > 0 ? nb : 1) * 14 * sizeof(double));
    if (d == NULL) return -1;
    c->b.n = nb;
    c->b.v0 = d;
    c->b.v = d + 3 * nb;
    c->b.acc = d + 6 * nb;
    c->b.disp = d + 9 * nb;
    c->b.inv_mass = d + 12 * nb;
    c->b.inv_inertia = d + 13 * nb;
    for (i = 0; i < nb; ++i) {
        int r = c->isl->rows[i];
        c->b.inv_mass[i] = w->inv_mass[r];
        c->b.inv_inertia[i] = w->inv_inertia[r];
    }
    return 0;
}

static void unmap_island(lc_contact_island *c)
{
    int i;
    for (i = 0; i < c->isl->nrows; ++i) c->local[c->isl->rows[i]] = -1;
}

/* Applied accelerations of the island's bodies at the current state into b.acc. */
static int applied(lc_contact_island *c)
{
    lc_world *w = c->w;
    int nb = c->b.n, i;
    double *acc = lc_buf_get(&c->cr->b_acc, (size_t)(w->count > 0 ? w->count : 1) * 3 * sizeof(double));
    if (acc == NULL) return -1;
    if (lc_applied_accelerations(w, w->state, c->isl->rows, nb, acc) != 0) return -1;
    for (i = 0; i < nb; ++i) memcpy(&c->b.acc[i * 3], &acc[c->isl->rows[i] * 3], 3 * sizeof(double));
    return 0;
}

static void count_solve(lc_contact_island *c, lc_contact_solve s, int rows);
static double rms_speed(const lc_contact_island *c);

/* Which solve of a sub-step: the impact stage's (step 2) or the flow's (step 3). */
enum { SOLVE_IMPACT, SOLVE_FLOW };

/* Solves rows[0..m) from the velocities in b.v (their start) into b.v: Gauss-Seidel with momentum from
 * the rows' warm start (contact_solver.c), at most contact_iterations sweeps (scaled up for fewer than
 * LC_CONTACT_SMALL_POINTS points), to contact_tolerance; the flow of an island of LC_CONTACT_PILE_BODIES
 * bodies or more moving slower than gravity changes a velocity in a step, on from there until the
 * largest change is a fraction of its motion (LC_CONTACT_PILE_FLOW_FRACTION); in a settling sub-step by
 * the settling rule
 * (tunables.h, LC_CONTACT_SETTLE_SPEED). In a
 * precise retry (lc_contact_advance) a problem of at most LC_CONTACT_PRECISE_EXACT_POINTS points is
 * solved exactly (contact_exact.c: active sets, else Lemke) and confirmed by sweeps from that answer, a larger one by up to
 * LC_CONTACT_PRECISE_SWEEPS sweeps. Returns 0, or -1 without memory. */
static int solve(lc_contact_island *c, lc_contact_row *rows, int m, int which)
{
    lc_world *w = c->w;
    lc_contact_solve s;
    double *scratch;
    int sweeps = c->precise && w->def.contact_iterations < LC_CONTACT_PRECISE_SWEEPS ? LC_CONTACT_PRECISE_SWEEPS
                                                                                     : w->def.contact_iterations;
    lc_contact_stop stop;
    if (!c->precise && m > 0 && m < LC_CONTACT_SMALL_POINTS)
        sweeps = (int)fmin((double)sweeps * LC_CONTACT_SMALL_POINTS / m, (double)LC_CONTACT_PRECISE_SWEEPS);
    stop = lc_contact_stop_rule(sweeps, w->def.contact_tolerance, c->precise ? 0 : LC_CONTACT_STALL_SWEEPS);
    if (which == SOLVE_FLOW && c->isl->nrows >= LC_CONTACT_PILE_BODIES && !c->settle && !c->precise) {
        double rms = rms_speed(c);
        if (rms < hypot(w->def.gravity.x, w->def.gravity.y) * c->dt) {
            stop.loose_after = stop.max_sweeps;
            stop.loose_tolerance = LC_CONTACT_PILE_FLOW_FRACTION * rms;
            if (stop.max_sweeps < LC_CONTACT_PILE_FLOW_SWEEPS) stop.max_sweeps = LC_CONTACT_PILE_FLOW_SWEEPS;
        }
    }
    if (c->settle) {
        if (stop.max_sweeps < LC_CONTACT_SETTLE_SWEEPS) stop.max_sweeps = LC_CONTACT_SETTLE_SWEEPS;
        stop.tolerance = fmax(stop.tolerance, LC_CONTACT_SETTLE_TOLERANCE);
        stop.stall_below = LC_CONTACT_REST_SPEED;
        stop.body_tolerance = LC_CONTACT_SETTLE_BODY_TOLERANCE;
    }
    if (c->precise && m > 0 && m <= LC_CONTACT_PRECISE_EXACT_POINTS) {
        size_t nv = (size_t)c->b.n * 3;
        size_t ns = lc_contact_exact_scratch(m), na = lc_contact_active_set_scratch(m);
        double *scratch = lc_buf_get(&c->cr->b_exact, (ns > na ? ns : na) * sizeof(double));
        double *vstart = lc_buf_get(&c->cr->b_vstart, nv * sizeof(double));
        if (scratch == NULL || vstart == NULL) return -1;
        memcpy(vstart, c->b.v, nv * sizeof(double));
        /* the exact answer becomes the rows' start; b.v is rebuilt from it by the sweeps. Active sets
         * from the warm start first: a few dense eliminations where Lemke pivots over a tableau of
         * (4m)^2 per unknown that enters (a 20-point pile: ~8x fewer operations) */
        if (lc_contact_solve_active_set(rows, m, c->b.v, c->b.inv_mass, c->b.inv_inertia, scratch) >= 0 ||
            lc_contact_solve_exact(rows, m, c->b.v, c->b.inv_mass, c->b.inv_inertia, scratch) >= 0)
            w->last.contact_exact_solves++;
        memcpy(c->b.v, vstart, nv * sizeof(double));
    }
    /* a precise retry runs its sweeps out: a perturbed pyramid's solve crawls, below the stall rule's
     * halving, to an answer whose energy the island can pay, where stopping left a gain */
    scratch = lc_buf_get(&c->cr->b_sweep, (size_t)(c->b.n > 0 ? c->b.n : 1) * 6 * sizeof(double));
    if (scratch == NULL) return -1;
    s = lc_contact_solver_run(rows, m, c->b.n, c->b.v, c->b.inv_mass, c->b.inv_inertia, &stop, scratch);
    count_solve(c, s, m);
    return 0;
}

static void count_solve(lc_contact_island *c, lc_contact_solve s, int rows)
{
    c->w->last.contact_sweeps += (uint64_t)s.sweeps;
    c->w->last.contact_points += (uint64_t)rows;
    if (s.residual > c->residual) c->residual = s.residual;
}

/* Whether a point approaching at un (< 0) is an impact at the sub-step's start: it touches, or, in an
 * island of several bodies (whose arrivals are not located), it would arrive within the first half of
 * the step: it bounces at its approach speed, at most half a step's travel early (under the
 * trapezoidal update it would need a bounce to keep its gap; under x += h v the flow would clip its
 * speed to what closes the gap by the step's end, a 3 m/s arrival 2 cm away to 1.2 m/s). */
static int impact_point(const lc_contact_island *c, const lc_touch *t, double un, double h)
{
    const lc_world *w = c->w;
    if (t->gap < w->def.contact_distance) return 1;
    return !c->small && un < 0.0 && t->gap - w->def.contact_gap < -0.5 * un * h;
}

/* Step 2: impacts at the start of the sub-step (none in a pile sub-step: its flow holds them). Changes
 * b.v0. Returns the points that received an impulse, or -1. */
static int impacts(lc_contact_island *c, lc_touch *t, int nt, double h)
{
    lc_world *w = c->w;
    /* Under the trapezoidal update any closed point that approaches is an impact: the flow would
     * otherwise have to turn its approach into an equal separation to keep the gap (an elastic
     * micro-bounce that never dissipates; a pile at resting_speed 1e-2 kept bodies rocking at 2 mm/s
     * that way). Approaches slower than contact_tolerance are the solves' own noise. Under x += h v
     * (c->moreau_jean) the flow stops an approach itself, and the stage runs only for one faster than
     * resting_speed. Only approaches faster than resting_speed count and are reported as collisions. */
    double vmin = w->def.contact_tolerance, vr = w->def.resting_speed;
    int real = 0, bounced = 0;
    lc_contact_row *rows;
    int *which, i, m = 0, fast = 0, hits = 0;
    if (c->pile) return 0;
    rows = lc_buf_get(&c->cr->b_irows, (size_t)(nt > 0 ? nt : 1) * sizeof(lc_contact_row));
    if (rows == NULL) return -1;
    which = (int *)lc_buf_get(&c->cr->b_hash, (size_t)(nt > 0 ? nt : 1) * sizeof(int));
    if (which == NULL) return -1;
    for (i = 0; i < nt; ++i) {
        double un, ut;
        lc_contact_island_row(c, &t[i], &rows[m]);
        lc_contact_row_velocity(&rows[m], c->b.v0, &un, &ut);
        if (!impact_point(c, &t[i], un, h)) continue;
        t[i].vn_pre = un;
        /* under x += h v the flow itself stops an approach slower than resting_speed */
        if (un < -(c->moreau_jean ? vr : vmin)) fast = 1;
        which[m++] = i;
    }
    if (!fast) return 0;
    memcpy(c->b.v, c->b.v0, (size_t)c->b.n * 3 * sizeof(double));
    if (solve(c, rows, m, SOLVE_IMPACT) != 0) return -1;
    /* Poisson: e j_c more along the normal where the point's own approach was fast enough to bounce.
     * Those impulses push the bodies into their other touches too (a box hit from above, resting on
     * the floor), whose own e may be 0: a second compression stops every approach they start, as the
     * first did, so the restitution comes out of the bounce and never from the floor (without it a
     * block hit at 4 m/s was driven into the floor at 3 m/s and the step gained 2 J). */
    for (i = 0; i < m; ++i) {
        lc_touch *x = &t[which[i]];
        lc_contact_row *r = &rows[i];
        double e = x->vn_pre < -lc_bounce_speed(w, x->elasticity) ? x->elasticity : 0.0, extra;
        x->value = x->tangent = 0.0;
        if (!(r->lambda_n > 0.0)) continue;
        extra = e * r->lambda_n;
        if (extra > 0.0) {
            lc_contact_row_apply(r, extra, 0.0, c->b.v, c->b.inv_mass, c->b.inv_inertia);
            bounced = 1;
        }
        x->value = r->lambda_n + extra;
        x->tangent = r->lambda_t;
    }
    if (bounced) {
        for (i = 0; i < m; ++i) rows[i].lambda_n = rows[i].lambda_t = 0.0;
        if (solve(c, rows, m, SOLVE_IMPACT) != 0) return -1;
        for (i = 0; i < m; ++i) {
            t[which[i]].value += rows[i].lambda_n;
            t[which[i]].tangent += rows[i].lambda_t;
        }
    }
    for (i = 0; i < m; ++i) {
        lc_touch *x = &t[which[i]];
        if (!(x->value > 0.0)) continue;
        hits++;
        if (x->vn_pre < -vr) {
            real = 1;
            w->last.impulses++;
            if (lc_record_impact(w, x, LC_IMPACT_CONTACT) != 0) return -1;
        }
    }
    memcpy(c->b.v0, c->b.v, (size_t)c->b.n * 3 * sizeof(double));
    w->last.impulse_solves++;
    if (real) w->last.collisions++;
    return hits;
}

/* Touching points the last step kept no force for (new contacts) start from the weight they carry at
 * rest, shared down the "rests on" graph by the lever rule (static_load.c): a stack or pyramid created at
 * rest, or a body landing on one, starts at its answer, where Gauss-Seidel from zero needs sweeps in the
 * square of the stack's height (a 20-stack sagged and bounced for a second) and a 1000:1 mass ratio never
 * gets there. known[i]: row i's point had a kept force (a kept 0 too: a side contact that carries
 * nothing is not new, and re-spreading the loads every step cost a resting pyramid 3%). */
static int cold_start(lc_contact_island *c, const lc_touch *t, int nt, double h, const uint8_t *known, lc_contact_row *rows)
{
    lc_world *w = c->w;
    int i, m = 0, cold = 0;
    lc_touch *closed;
    int *which;
    double *f;
    for (i = 0; i < nt; ++i)
        if (t[i].gap < w->def.contact_distance && !known[i]) cold = 1;
    if (!cold) return 0;
    closed = lc_buf_get(&c->cr->b_cold, (size_t)nt * sizeof(lc_touch));
    f = lc_buf_get(&c->cr->b_cold_load, (size_t)nt * (sizeof(double) + sizeof(int)));
    if (closed == NULL || f == NULL) return -1;
    which = (int *)(f + nt);
    for (i = 0; i < nt; ++i)
        if (t[i].gap < w->def.contact_distance) {
            closed[m] = t[i];
            which[m] = i;
            f[m] = 0.0;
            m++;
        }
    if (lc_static_load_forces_of(w, closed, m, c->local, c->isl->rows, c->b.n, f) != 0) return -1;
    for (i = 0; i < m; ++i) {
        lc_contact_row *r = &rows[which[i]];
        if (!known[which[i]] && f[i] > 0.0) r->lambda_n = f[i] * h;
    }
    return 0;
}

/* Step 3: the flow over h from b.v0 into b.v. */
static int flow(lc_contact_island *c, const lc_touch *t, int nt, double h, lc_contact_row *rows)
{
    lc_world *w = c->w;
    double gc = w->def.contact_gap;
    int i, nb = c->b.n;
    uint8_t *known = lc_buf_get(&c->cr->b_known, (size_t)(nt > 0 ? nt : 1));
    /* the whole cone below the slip speed (tunables.h): a pile's points need it to stick */
    double slip_speed = c->small || c->precise ? LC_CONTACT_SLIP_SPEED : LC_CONTACT_PILE_SLIP_SPEED;
    if (known == NULL) return -1;
    for (i = 0; i < nb * 3; ++i) c->b.v[i] = c->b.v0[i] + h * c->b.acc[i];
    for (i = 0; i < nt; ++i) {
        lc_contact_row *r = &rows[i];
        double un, ut, fn, ft;
        lc_contact_island_row(c, &t[i], r);
        lc_contact_row_velocity(r, c->b.v0, &un, &ut);
        r->target_n = c->moreau_jean ? -fmax(t[i].gap - gc, 0.0) / h : -un - 2.0 * fmax(t[i].gap - gc, 0.0) / h;
        /* a pile sub-step's impacts (Newton's law): a bounce leaves at e times its approach, an arrival
         * within the step's first half stops now, as the impact stage would stop it */
        if (c->pile && un < 0.0 && impact_point(c, &t[i], un, h)) {
            if (un < -lc_bounce_speed(w, t[i].elasticity)) r->target_n = -t[i].elasticity * un;
            else if (!(t[i].gap < w->def.contact_distance)) r->target_n = 0.0;
        }
        r->slip = ut > slip_speed ? 1 : ut < -slip_speed ? -1 : 0;
        known[i] = (uint8_t)lc_contact_cache_find(c->cr->cache, key_of(w, &t[i]), &fn, &ft);
        if (known[i]) {
            r->lambda_n = fn * h;
            r->lambda_t = ft * h;
        }
    }
    if (cold_start(c, t, nt, h, known, rows) != 0) return -1;
    return solve(c, rows, nt, SOLVE_FLOW);
}

/* The collisions of a pile sub-step: its impact points that approached faster than resting_speed and
 * took an impulse, reported with the flow's impulses. 0, or -1 without memory. */
static int record_pile_impacts(lc_contact_island *c, lc_touch *t, const lc_contact_row *rows, int nt, double h)
{
    lc_world *w = c->w;
    int i, real = 0;
    for (i = 0; i < nt; ++i) {
        double un, ut;
        lc_contact_row_velocity(&rows[i], c->b.v0, &un, &ut);
        if (!(un < -w->def.resting_speed) || !(rows[i].lambda_n > 0.0) || !impact_point(c, &t[i], un, h)) continue;
        t[i].vn_pre = un;
        t[i].value = rows[i].lambda_n;
        t[i].tangent = rows[i].lambda_t;
        real = 1;
        w->last.impulses++;
        if (lc_record_impact(w, &t[i], LC_IMPACT_CONTACT) != 0) return -1;
    }
    if (real) w->last.collisions++;
    return 0;
}

/* Step 4: the fraction of h at which the first located transition happens (1: none). Arrivals: a
 * point not touching that approaches reaches the contact gap at (gap - contact_gap) / -u_n0. Stick:
 * the points of a body pair that slipped at the start and stick at the end stopped when the friction
 * impulse they used, at mu lambda_n per unit of time while slipping, ran out: at sum |lambda_t| /
 * (mu sum lambda_n) of the step (exact for a body sliding to rest on a level surface; elsewhere the
 * next sub-step refines it). */
static double first_transition(const lc_contact_island *c, const lc_touch *t, const lc_contact_row *rows, int nt, double h)
{
    const lc_world *w = c->w;
    double tau = 1.0, gc = w->def.contact_gap, vr = w->def.resting_speed;
    int i;
    for (i = 0; i < nt; ++i) {
        double un, ut;
        if (t[i].gap < w->def.contact_distance) continue;
        lc_contact_row_velocity(&rows[i], c->b.v0, &un, &ut);
        if (un < -vr) tau = fmin(tau, (t[i].gap - gc) / (-un * h));
    }
    i = 0;
    while (i < nt) {
        int j = i, any = 0;
        double lt = 0.0, ln = 0.0, mu = rows[i].mu;
        while (j < nt && ((t[j].a == t[i].a && t[j].b == t[i].b) || (t[j].a == t[i].b && t[j].b == t[i].a))) {
            const lc_contact_row *r = &rows[j];
            double un, ut;
            lc_contact_row_velocity(r, c->b.v0, &un, &ut);
            if (r->slip != 0 && r->lambda_n > 0.0 && fabs(ut) > vr) {
                lt += fabs(r->lambda_t);
                ln += r->lambda_n;
                if (fabs(r->lambda_t) < r->mu * r->lambda_n * (1.0 - 1e-9)) any = 1;
            }
            ++j;
        }
        /* a stop at the very start: nothing to locate (the point barely slipped) */
        if (any && mu > 0.0 && ln > 0.0 && lt > LC_CONTACT_CUT_EPSILON * mu * ln) tau = fmin(tau, lt / (mu * ln));
        i = j;
    }
    return tau;
}

/* Step 5: positions by the trapezoidal rule, or by x += h v in a Moreau-Jean sub-step; velocities
 * become the solver's. */
static void advance_positions(lc_contact_island *c, double h)
{
    lc_world *w = c->w;
    int i, k;
    for (i = 0; i < c->b.n; ++i) {
        double *s = &w->state[c->isl->rows[i] * 6];
        for (k = 0; k < 3; ++k) {
            s[k] += c->moreau_jean ? h * c->b.v[i * 3 + k] : 0.5 * h * (c->b.v0[i * 3 + k] + c->b.v[i * 3 + k]);
            s[3 + k] = c->b.v[i * 3 + k];
        }
    }
}

/* Energy of the island's bodies at state (world rows, or the island's own rows when !world_rows):
 * kinetic and gravitational; *kinetic gets the kinetic part, *size the sum of the terms' magnitudes
 * (the scale of its round-off). */
static double island_energy(const lc_world *w, const lc_island *isl, const double *state, int world_rows,
                            double *kinetic, double *size)
{
    double e = 0.0, ke = 0.0, mag = 0.0;
    int i;
    for (i = 0; i < isl->nrows; ++i) {
        int r = isl->rows[i];
        const double *s = world_rows ? &state[r * 6] : &state[i * 6];
        double k = 0.5 * w->mass[r] * (s[SVX] * s[SVX] + s[SVY] * s[SVY]) + 0.5 * w->inertia[r] * s[SW] * s[SW];
        double p = -w->mass[r] * (w->def.gravity.x * s[SX] + w->def.gravity.y * s[SY]);
        ke += k;
        e += k + p;
        mag += k + fabs(p);
    }
    *kinetic = ke;
    *size = mag;
    return e;
}

/* 1 if a force other than gravity and contacts can do work on the island: thrusters, external force or
 * torque, springs, the force callback (asked after the island's force evaluations, which record it). */
static int island_driven(const lc_contact_island *c)
{
    const lc_world *w = c->w;
    int i, k;
    for (i = 0; i < c->isl->nrows; ++i)
        if (lc_body_driven(w, c->isl->rows[i])) return 1;
    for (k = 0; k < w->spring_count; ++k) {
        int a = lc_world_body_index(w, w->springs[k].def.body_a);
        int b = w->springs[k].def.body_b == LC_WORLD_ANCHOR ? -1 : lc_world_body_index(w, w->springs[k].def.body_b);
        if ((a >= 0 && c->local[a] >= 0) || (b >= 0 && c->local[b] >= 0)) return 1;
    }
    return 0;
}

/* The mass-weighted rms speed of the island's centres at the sub-step's start (b.v0). */
static double rms_speed(const lc_contact_island *c)
{
    double mass = 0.0, mv2 = 0.0;
    int k;
    for (k = 0; k < c->b.n; ++k) {
        const double *v = &c->b.v0[k * 3];
        double m;
        if (!(c->b.inv_mass[k] > 0.0)) continue;
        m = 1.0 / c->b.inv_mass[k];
        mass += m;
        mv2 += m * (v[0] * v[0] + v[1] * v[1]);
    }
    return mass > 0.0 ? sqrt(mv2 / mass) : 0.0;
}

/* Whether a sub-step starting from b.v0 settles (LC_CONTACT_SETTLE_SPEED): the island is large enough
 * and its mass-weighted rms speed is below the speed. A precise retry keeps its own solves. */
static int settling(const lc_contact_island *c)
{
    if (c->precise || c->isl->nrows < LC_CONTACT_SETTLE_BODIES) return 0;
    return rms_speed(c) < LC_CONTACT_SETTLE_SPEED;
}

/* Whether none of the island's bodies' points (centre speed plus |omega| times the body's radius) moves
 * at `speed` with the velocities v: body k's vx, vy, omega at v[k * stride]. */
static int below_speed(const lc_contact_island *c, const double *v, int stride, double speed)
{
    int k;
    for (k = 0; k < c->b.n; ++k) {
        const double *x = &v[k * stride];
        if (hypot(x[0], x[1]) + fabs(x[2]) * c->w->radius[c->isl->rows[k]] >= speed) return 0;
    }
    return 1;
}

/* Rest (LC_CONTACT_REST_SPEED): after a settling sub-step's solves, an undriven island none of whose
 * bodies' points moves faster than the rest speed keeps still: b.v becomes 0. In a held try (c->hold)
 * it keeps still whatever the solves' answer, and b.v0 becomes 0 too, so that no position moves. */
static void hold_at_rest(lc_contact_island *c)
{
    if (!c->hold && !below_speed(c, c->b.v, 3, LC_CONTACT_REST_SPEED)) return;
    if (island_driven(c)) return;
    memset(c->b.v, 0, (size_t)c->b.n * 3 * sizeof(double));
    if (c->hold) memset(c->b.v0, 0, (size_t)c->b.n * 3 * sizeof(double));
    c->w->last.contact_rests++;
    c->rested = 1;
}

/* A touch at the end of an island's step (gap within contact_distance) with its forces in value and
 * tangent: reported as a resting contact, kept as the next step's warm start, counted, and its bodies
 * marked when the pair is dissipative (finish and hold_still). 0, or -1 without memory. */
static int report_resting(lc_contact_island *c, const lc_touch *x)
{
    lc_world *w = c->w;
    if (x->elasticity < 1.0) w->rests_dissipative[x->a] = w->rests_dissipative[x->b] = 1;
    if (lc_push_contact(w, x, LC_CONTACT_RESTING) != 0) return -1;
    if (lc_contact_cache_store(c->cr->cache, key_of(w, x), x->value, x->tangent) != 0) return -1;
    w->last.resting_contacts++;
    return 0;
}

/* A still island (kept_touches.h): it rested through its last step at the state it starts this one from,
 * nothing drives it and nothing changed since (no API change, the same rows, pairs and dt). This step's
 * solve would meet the problem it met then and hold the island at rest again, with the state unchanged,
 * so it is not solved: its resting contacts are reported with the forces the last solve found, which
 * also stay the warm start, and its touches are kept for the next step. Counted in contact_rests. */
static int hold_still(lc_contact_island *c, const lc_touch *kept, int n, const double *margin)
{
    lc_world *w = c->w;
    int i;
    for (i = 0; i < n; ++i)
        if (kept[i].gap < w->def.contact_distance && report_resting(c, &kept[i]) != 0) return -1;
    w->last.contact_rests++;
    return lc_kept_touches_store(c->cr->kept, w, c->isl, c->dt, kept, n, margin, 1);
}

/* Whether the island's state is bit for bit the one it started the step from (start: nrows x 6). */
static int unmoved(const lc_contact_island *c, const double *start)
{
    int i;
    for (i = 0; i < c->isl->nrows; ++i)
        if (memcmp(&start[i * 6], &c->w->state[c->isl->rows[i] * 6], 6 * sizeof(double)) != 0) return 0;
    return 1;
}

/* Step 6b: an island no force but gravity and contacts drives ends with at most the energy it began
 * with (the flow and the impacts dissipate; the projection's lift and the rotation's nonlinearity may
 * not); an excess is taken from the kinetic energy by scaling the velocities. Returns the part the
 * kinetic energy could not pay (J, 0 when all was paid). */
static double energy_guard(lc_contact_island *c, double e0, double size0)
{
    lc_world *w = c->w;
    double ke, size1, e1 = island_energy(w, c->isl, w->state, 1, &ke, &size1), excess, f;
    int i;
    excess = e1 - e0;
    /* round-off of the two sums: a few ulps of the larger sum of magnitudes */
    if (!(excess > 64.0 * 2.2e-16 * fmax(size0, size1))) return 0.0;
    w->last.energy_clamps++;
    f = ke > excess ? sqrt((ke - excess) / ke) : 0.0;
    for (i = 0; i < c->isl->nrows; ++i) {
        double *s = &w->state[c->isl->rows[i] * 6];
        s[SVX] *= f;
        s[SVY] *= f;
        s[SW] *= f;
    }
    return ke < excess ? excess - ke : 0.0;
}

/* A touch's slot in a table of mask + 1 (a power of two) entries: its bodies, vertex and edge packed into
 * 64 bits and mixed by two multiplications (splitmix's finaliser), so that a pile's neighbouring rows and
 * small vertex and edge numbers do not land in runs of adjacent slots and lengthen the probes. */
static uint32_t touch_slot(const lc_touch *t, uint32_t mask)
{
    uint64_t key = ((uint64_t)(uint32_t)t->a << 32 | (uint32_t)t->b) ^ ((uint64_t)(uint32_t)t->vertex << 48) ^
                   ((uint64_t)(uint32_t)t->edge << 16);
    uint64_t h = key * 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    return (uint32_t)(h >> 32) & mask;
}

/* The touches at the end, their forces from the last flow's rows (matched by vertex and edge), reported
 * as resting contacts and kept for the next step's warm start; bodies on a pair with e < 1 are marked. */
static int finish(lc_contact_island *c, lc_touch *end, int nend, const lc_touch *t, const lc_contact_row *rows, int nt,
                  double h)
{
    lc_world *w = c->w;
    int size = 1, i, *table;
    while (size < 2 * nt) size *= 2;
    table = lc_buf_get(&c->cr->b_hash, (size_t)size * sizeof(int));
    if (table == NULL) return -1;
    for (i = 0; i < size; ++i) table[i] = -1;
    for (i = 0; i < nt; ++i) {
        uint32_t k = touch_slot(&t[i], (uint32_t)(size - 1));
        while (table[k] >= 0) k = (k + 1) & (uint32_t)(size - 1);
        table[k] = i;
    }
    for (i = 0; i < nend; ++i) {
        lc_touch *x = &end[i];
        if (!(x->gap < w->def.contact_distance)) continue;   /* held near by the projection only */
        uint32_t k = touch_slot(x, (uint32_t)(size - 1));
        double fn = 0.0, ft = 0.0;
        while (table[k] >= 0) {
            const lc_touch *y = &t[table[k]];
            if (y->a == x->a && y->b == x->b && y->vertex == x->vertex && y->edge == x->edge) {
                fn = rows[table[k]].lambda_n / h;
                ft = rows[table[k]].lambda_t / h;
                break;
            }
            k = (k + 1) & (uint32_t)(size - 1);
        }
        x->value = fn;
        x->tangent = ft;
        if (report_resting(c, x) != 0) return -1;
    }
    return 0;
}

/* Steps 1-6 over dt from the island's current state. Returns 0, -1 without memory or when the force
 * callback failed, or -3 (see lc_contact_advance); on 0 the touches at the end are in cr->b_end (*nend),
 * the last flow's touches and rows in cr->b_touch and cr->b_rows (*nt, *h_last). */
static int advance(lc_contact_island *c, double dt, double e0, double size0, int *nend, int *nt, double *h_last)
{
    lc_world *w = c->w;
    lc_contact_regime *cr = c->cr;
    const lc_island *isl = c->isl;
    double left = dt, h = dt, overlap = 0.0;
    int i, cuts = 0;
    lc_touch *t;
    lc_contact_row *rows;
    *nt = 0;
    c->rested = 0;
    while (left > 0.0) {
        double tau;
        h = left;
        if (c->max_h > 0.0 && h > c->max_h * (1.0 + LC_CONTACT_CUT_EPSILON)) h = c->max_h;
        if (applied(c) != 0) return -1;
        /* the step's first search is usually the last step's end search, kept */
        c->start_h = h;
        *nt = left == dt ? lc_kept_touches_take(cr->kept, w, isl, dt, lc_contact_island_start_margin, c, &cr->b_touch) : -2;
        if (*nt == -2) *nt = lc_contact_island_collect(c, h, &cr->b_touch, LC_SEARCH_STEP, 0.0, NULL);
        if (*nt < 0) return -1;
        t = (lc_touch *)cr->b_touch.p;
        rows = lc_buf_get(&cr->b_rows, (size_t)(*nt > 0 ? *nt : 1) * sizeof(lc_contact_row));
        if (rows == NULL) return -1;
        c->pile = isl->nrows >= LC_CONTACT_PILE_BODIES && isl->nrows < LC_CONTACT_LARGE_ISLAND_BODIES &&
                  *nt >= LC_CONTACT_MOREAU_JEAN_POINTS;
        c->moreau_jean = !c->small && (*nt < LC_CONTACT_MOREAU_JEAN_POINTS || c->pile);
        c->slack = c->pile || isl->nrows >= LC_CONTACT_LARGE_ISLAND_BODIES ? LC_CONTACT_PROJECTION_LARGE_SLACK
                                                                            : LC_CONTACT_PROJECTION_SLACK;
        for (i = 0; i < isl->nrows; ++i) memcpy(&c->b.v0[i * 3], &w->state[isl->rows[i] * 6 + 3], 3 * sizeof(double));
        c->settle = settling(c);
        if (impacts(c, t, *nt, h) < 0 || flow(c, t, *nt, h, rows) != 0) return -1;
        if (c->pile && record_pile_impacts(c, t, rows, *nt, h) != 0) return -1;
        tau = c->small && cuts < LC_CONTACT_MAX_CUTS ? first_transition(c, t, rows, *nt, h) : 1.0;
        if (tau < 1.0 - LC_CONTACT_CUT_EPSILON) {
            /* solved again over the part of the step before the transition */
            h = tau * h;
            if (flow(c, t, *nt, h, rows) != 0) return -1;
            cuts++;
            w->last.contact_cuts++;
        }
        if (c->settle || c->hold) hold_at_rest(c);
        advance_positions(c, h);
        left = h < left ? left - h : 0.0;
        if (left < 1e-14 * dt) left = 0.0;
    }
    *h_last = h;
    /* the touches at the end: projection, results, warm start */
    *nend = lc_contact_project(cr->projection, c, (const lc_touch *)cr->b_touch.p, *nt, &cr->b_end, &cr->b_margin,
                               &overlap);
    if (*nend < 0) return -1;
    /* bodies the projection cannot separate (wedged deep into a corner within one step), or an energy
     * gain the island's kinetic energy cannot pay for */
    c->overlap = overlap;
    c->unpaid = island_driven(c) ? 0.0 : energy_guard(c, e0, size0);
    if (overlap > LC_CONTACT_OVERLAP_LEFT * (c->slack / LC_CONTACT_PROJECTION_SLACK) ||
        c->unpaid > LC_CONTACT_ENERGY_LEFT * size0)
        return -3;
    return 0;
}

/* The island back at its start (states, contacts and impact events of the try undone), for a retry. */
static void undo_try(lc_world *w, const lc_island *isl, const double *start, int ncontacts, int nevents)
{
    int i;
    w->last.contact_precise_retries++;
    for (i = 0; i < isl->nrows; ++i) memcpy(&w->state[isl->rows[i] * 6], &start[i * 6], 6 * sizeof(double));
    w->contact_count = ncontacts;
    lc_events_unstage(w->events, nevents);
}

int lc_contact_advance(lc_world *w, lc_contact_regime *cr, const lc_island *isl, double dt)
{
    lc_contact_island c;
    double e0 = 0.0, ke0 = 0.0, size0 = 0.0, h = dt;
    int i, k, nt = 0, nend = 0, nkept = 0, status, ncontacts = w->contact_count, nevents = lc_events_staged(w->events);
    double *start;
    const lc_touch *kept;
    const double *kept_margin;
    memset(&c, 0, sizeof c);
    c.w = w;
    c.cr = cr;
    c.isl = isl;
    c.small = isl->nrows <= LC_CONTACT_LOCATE_MAX_BODIES;
    c.dt = dt;
    if (map_island(&c) != 0) return -1;
    w->last.contact_islands++;
    start = lc_buf_get(&cr->b_start, (size_t)(isl->nrows > 0 ? isl->nrows : 1) * 6 * sizeof(double));
    if (start == NULL) goto oom;
    for (i = 0; i < isl->nrows; ++i) {
        memcpy(&start[i * 6], &w->state[isl->rows[i] * 6], 6 * sizeof(double));
        w->rests_dissipative[isl->rows[i]] = 0;
    }
    if (!lc_force_callback_on(w) && lc_kept_touches_still(cr->kept, w, isl, dt, &kept, &nkept, &kept_margin) &&
        !island_driven(&c)) {
        status = hold_still(&c, kept, nkept, kept_margin);
        unmap_island(&c);
        return status;
    }
    e0 = island_energy(w, isl, start, 0, &ke0, &size0);
    status = advance(&c, dt, e0, size0, &nend, &nt, &h);
    if (status == -3) {
        /* once more with every solve run to convergence (solve()): a nearly resting island whose solve
         * stopped at contact_iterations can end overlapping or with a gain its kinetic energy cannot pay */
        undo_try(w, isl, start, ncontacts, nevents);
        c.precise = 1;
        status = advance(&c, dt, e0, size0, &nend, &nt, &h);
    }
    if (status == -3 && isl->nrows > LC_CONTACT_EVENT_FALLBACK_BODIES) {
        /* an island too large for the event regime: once more, precise, in LC_CONTACT_SPLIT_SUBSTEPS
         * sub-steps, whose velocities drift less between solves (tunables.h) */
        undo_try(w, isl, start, ncontacts, nevents);
        c.max_h = dt / LC_CONTACT_SPLIT_SUBSTEPS;
        status = advance(&c, dt, e0, size0, &nend, &nt, &h);
    }
    if (status == -3 && isl->nrows > LC_CONTACT_EVENT_FALLBACK_BODIES && !island_driven(&c) &&
        below_speed(&c, start + 3, 6, LC_CONTACT_HOLD_SPEED)) {
        /* an island at rest when the step began that no try could advance without an overlap or a gain
         * (a pile whose solves end a few 1e-6 m/s off, driving bodies into each other, and whose
         * projection then lifts them higher than they sank): held at rest, as a settling step holds
         * one whose answer is below the rest speed; its state stays, so it gains nothing */
        undo_try(w, isl, start, ncontacts, nevents);
        c.max_h = 0.0;
        c.hold = 1;
        status = advance(&c, dt, e0, size0, &nend, &nt, &h);
    }
    if (status == -3 && isl->nrows > LC_CONTACT_EVENT_FALLBACK_BODIES) {
        w->last.contact_unresolved++;
        if (c.overlap > w->last.max_unresolved_overlap) w->last.max_unresolved_overlap = c.overlap;
        if (c.unpaid > w->last.max_unresolved_energy) w->last.max_unresolved_energy = c.unpaid;
        status = 0;
    }
    if (status == -1) goto oom;
    for (i = 0; i < isl->nrows && status == 0; ++i)
        for (k = 0; k < 6; ++k)
            if (!isfinite(w->state[isl->rows[i] * 6 + k])) status = -2;
    if (status == 0 &&
        (finish(&c, (lc_touch *)cr->b_end.p, nend, (lc_touch *)cr->b_touch.p, (lc_contact_row *)cr->b_rows.p, nt, h) != 0 ||
         lc_kept_touches_store(cr->kept, w, isl, dt, (const lc_touch *)cr->b_end.p, nend, (const double *)cr->b_margin.p,
                               c.rested && unmoved(&c, start)) != 0))
        goto oom;
    if (c.residual > w->last.max_contact_residual) w->last.max_contact_residual = c.residual;
    unmap_island(&c);
    return status;
oom:
    unmap_island(&c);
    return -1;
}
