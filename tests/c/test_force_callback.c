/* test_force_callback: the force callback (collide/force.h) against the external force it generalises
 * (same bits), a state-dependent force against closed forms (a harmonic oscillator at RK4's predicted
 * error, and the integrators' orders), mutual gravitation with its potential (energy and momentum), a
 * failing callback (the step undone, the world unchanged), the rules it brings (no sleep, no closed
 * form), removing it (the old behaviour, bit for bit) and snapshots (which do not hold it). */
#include <stdlib.h>
#include "check.h"
#include "scenes.h"

/* ---- force laws ---------------------------------------------------------------------------------- */

/* The same force and torque on every dynamic body. */
typedef struct constant_law {
    lc_vec2 force;
    double torque;
    int calls;
} constant_law;

static int constant_force(void *user, const lc_force_query *q, double *out)
{
    constant_law *c = user;
    int i;
    c->calls++;
    for (i = 0; i < q->row_count; ++i) {
        out[q->rows[i] * 3] = c->force.x;
        out[q->rows[i] * 3 + 1] = c->force.y;
        out[q->rows[i] * 3 + 2] = c->torque;
    }
    return 0;
}

/* A linear spring to the origin and a torsional one to angle 0: F = -k x, tau = -kappa theta. */
typedef struct spring_law {
    double k, kappa;
} spring_law;

static int spring_force(void *user, const lc_force_query *q, double *out)
{
    const spring_law *s = user;
    int i;
    for (i = 0; i < q->row_count; ++i) {
        int r = q->rows[i];
        const double *st = &q->bodies.state[r * 6];
        out[r * 3] = -s->k * st[0];
        out[r * 3 + 1] = -s->k * st[1];
        out[r * 3 + 2] = -s->kappa * st[2];
    }
    return 0;
}

/* Newtonian gravitation between every pair of dynamic bodies (centres of mass), G in N m^2 / kg^2. The
 * force on every body is written, listed or not (the engine reads the listed rows). */
typedef struct gravity_law {
    double G;
} gravity_law;

static int gravity_force(void *user, const lc_force_query *q, double *out)
{
    const gravity_law *g = user;
    const lc_state_view *b = &q->bodies;
    int i, j;
    for (i = 0; i < b->count; ++i)
        for (j = i + 1; j < b->count; ++j) {
            double dx, dy, r2, f;
            if (b->is_static[i] || b->is_static[j]) continue;
            dx = b->state[j * 6] - b->state[i * 6];
            dy = b->state[j * 6 + 1] - b->state[i * 6 + 1];
            r2 = dx * dx + dy * dy;
            f = g->G * b->mass[i] * b->mass[j] / (r2 * sqrt(r2));
            out[i * 3] += f * dx;
            out[i * 3 + 1] += f * dy;
            out[j * 3] -= f * dx;
            out[j * 3 + 1] -= f * dy;
        }
    return 0;
}

static int gravity_potential(void *user, const lc_force_query *q, double *out)
{
    const gravity_law *g = user;
    const lc_state_view *b = &q->bodies;
    int i, j;
    for (i = 0; i < b->count; ++i)
        for (j = i + 1; j < b->count; ++j) {
            double dx, dy;
            if (b->is_static[i] || b->is_static[j]) continue;
            dx = b->state[j * 6] - b->state[i * 6];
            dy = b->state[j * 6 + 1] - b->state[i * 6 + 1];
            *out -= g->G * b->mass[i] * b->mass[j] / sqrt(dx * dx + dy * dy);
        }
    return 0;
}

/* A force of 1 N along x that turns bad at evaluation `bad_at` (counted from 1): NaN, or a return of 7. */
typedef struct failing_law {
    int calls, bad_at, use_nan;
} failing_law;

static int failing_force(void *user, const lc_force_query *q, double *out)
{
    failing_law *f = user;
    int i;
    f->calls++;
    for (i = 0; i < q->row_count; ++i) out[q->rows[i] * 3] = 1.0;
    if (f->calls < f->bad_at) return 0;
    if (!f->use_nan) return 7;
    out[q->rows[0] * 3 + 1] = NAN;
    return 0;
}

/* Records what the queries held: the engine lists only dynamic rows, each once, with the world's masses. */
typedef struct query_probe {
    int calls, bad_rows, bad_mass, max_rows;
    const lc_world *w;
} query_probe;

static int probe_force(void *user, const lc_force_query *q, double *out)
{
    query_probe *p = user;
    lc_state_view v;
    int i, j;
    (void)out;
    p->calls++;
    lc_world_get_state(p->w, &v);
    if (q->bodies.count != v.count || q->bodies.ids != v.ids || q->bodies.mass != v.mass) p->bad_mass++;
    for (i = 0; i < q->row_count; ++i) {
        if (q->rows[i] < 0 || q->rows[i] >= q->bodies.count || q->bodies.is_static[q->rows[i]]) p->bad_rows++;
        for (j = 0; j < i; ++j)
            if (q->rows[j] == q->rows[i]) p->bad_rows++;
    }
    if (q->row_count > p->max_rows) p->max_rows = q->row_count;
    return 0;
}

/* ---- scenes --------------------------------------------------------------------------------------- */

/* A 1 x 0.5 box of 2 kg thrown (2 m/s, spin 1 rad/s) above a static floor of elasticity e; damping
 * 0.3 when asked. */
static lc_world *throw_scene(double e, double damping, lc_body_id *box)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    d.damping = damping;
    w = sc_world(&d);
    if (w == NULL) return NULL;
    sc_static_box(w, 20.0, 1.0, 0.0, -0.5, e);
    *box = sc_box(w, 1.0, 0.5, -2.0, 1.5, 0.3, 2.0, 0.5, 1.0, 2.0, e);
    return w;
}

/* ---- tests ---------------------------------------------------------------------------------------- */

/* A callback giving the force an external force gives adds the same numbers in the same order (forces.c):
 * where both bodies go through the integrator (damping makes the forces non-constant) the two worlds
 * keep the same bits step for step, through the impacts on the floor and the resting contact (e = 0.2:
 * the contact regime, whose energy guard treats both bodies as driven). */
static void constant_force_same_bits(void)
{
    constant_law law = {{3.0, -1.5}, 0.25, 0};
    lc_body_id a, b;
    lc_world *wa = throw_scene(0.2, 0.3, &a), *wb = throw_scene(0.2, 0.3, &b);
    lc_counters ca, cb;
    int k, differ = -1;
    lc_vec2 ext = {3.0, -1.5};
    if (!wa || !wb) return;
    CHECK(lc_body_set_external(wa, a, ext, 0.25) == LC_OK, "%s", "set_external");
    CHECK(lc_world_set_force_callback(wb, constant_force, NULL, &law) == LC_OK, "set_force_callback: %s",
          lc_world_last_error(wb));
    for (k = 0; k < 240; ++k) {
        lc_status sa = lc_world_step(wa, 1.0 / 60.0), sb = lc_world_step(wb, 1.0 / 60.0);
        CHECK(sa == LC_OK && sb == LC_OK, "step %d: %s / %s", k, lc_world_last_error(wa), lc_world_last_error(wb));
        if (differ < 0 && lc_world_state_hash(wa) != lc_world_state_hash(wb)) differ = k;
    }
    CHECK(differ < 0, "constant callback force vs external force: states differ from step %d", differ);
    lc_world_get_counters(wa, NULL, &ca);
    lc_world_get_counters(wb, NULL, &cb);
    CHECK(ca.collisions > 0 && ca.contact_islands > 0, "the scene has impacts (%llu) and contact-regime steps (%llu)",
          (unsigned long long)ca.collisions, (unsigned long long)ca.contact_islands);
    CHECK(cb.force_evaluations == ca.force_evaluations, "same force evaluations (%llu vs %llu)",
          (unsigned long long)cb.force_evaluations, (unsigned long long)ca.force_evaluations);
    CHECK(law.calls > 0, "the callback was called (%d)", law.calls);
    lc_world_destroy(wa);
    lc_world_destroy(wb);
}

/* Without damping the external force is integrated in closed form and the callback's by RK4, which is
 * exact for a constant acceleration too: the two differ by round-off only. Each step computes
 * x + h v + h^2 a / 2 (closed form) or x + h/6 (k1 + 2 k2 + 2 k3 + k4) (RK4) with at most 8 roundings
 * of 2^-53 relative each on the state's scale, so after n steps the difference is below n * 8 * 1.1e-16
 * of the largest |component|: 1e-15 after one step, 1.1e-13 after 120. */
static void constant_force_closed_form(void)
{
    constant_law law = {{3.0, -1.5}, 0.25, 0};
    lc_world_def d = lc_default_world_def();
    lc_world *wa = sc_world(&d), *wb = sc_world(&d);
    lc_vec2 ext = {3.0, -1.5};
    lc_counters ca, cb;
    lc_body_id a, b;
    int n, k;
    if (!wa || !wb) return;
    a = sc_box(wa, 1.0, 0.5, -2.0, 1.5, 0.3, 2.0, 0.5, 1.0, 2.0, 1.0);
    b = sc_box(wb, 1.0, 0.5, -2.0, 1.5, 0.3, 2.0, 0.5, 1.0, 2.0, 1.0);
    CHECK(lc_body_set_external(wa, a, ext, 0.25) == LC_OK, "%s", "set_external");
    CHECK(lc_world_set_force_callback(wb, constant_force, NULL, &law) == LC_OK, "%s", "set_force_callback");
    for (n = 1; n <= 120; ++n) {
        const double *sa, *sb;
        double scale = 0.0, diff = 0.0;
        sc_step_n(wa, 1.0 / 60.0, 1);
        sc_step_n(wb, 1.0 / 60.0, 1);
        sa = sc_row(wa, a);
        sb = sc_row(wb, b);
        for (k = 0; k < 6; ++k) {
            scale = fmax(scale, fabs(sa[k]));
            diff = fmax(diff, fabs(sa[k] - sb[k]));
        }
        if (n == 1 || n == 120) CHECK(diff <= n * 8 * 1.1e-16 * scale, "after %d steps |diff| %g > %g", n, diff, n * 8 * 1.1e-16 * scale);
    }
    lc_world_get_counters(wa, NULL, &ca);
    lc_world_get_counters(wb, NULL, &cb);
    CHECK(ca.analytic_advances == 120 && cb.analytic_advances == 0,
          "closed form for the external force only (%llu, %llu)", (unsigned long long)ca.analytic_advances,
          (unsigned long long)cb.analytic_advances);
    /* the callback removed and the force made external: closed form again */
    CHECK(lc_world_set_force_callback(wb, NULL, NULL, NULL) == LC_OK, "%s", "remove");
    CHECK(lc_body_set_external(wb, b, ext, 0.25) == LC_OK, "%s", "set_external");
    sc_step_n(wb, 1.0 / 60.0, 1);
    lc_world_get_counters(wb, &cb, NULL);
    CHECK(cb.analytic_advances == 1, "removed: closed form again (%llu)", (unsigned long long)cb.analytic_advances);
    lc_world_destroy(wa);
    lc_world_destroy(wb);
}

/* The phase-space error (position, and velocity over omega) of a harmonic oscillator x'' = -omega^2 x
 * after one period T in n steps of the world's integrator, relative to the amplitude. A 1 x 1 box of 2 kg
 * (I = 1/3 kg m^2) starts at x = (1, 0), angle 0.4 rad, at rest; k = 8 N/m, kappa = I omega^2: both
 * oscillate at omega = 2 rad/s. Returns the larger of the translational and rotational errors. */
static double harmonic_error(lc_integrator integrator, int n)
{
    const double m = 2.0, I = m * (1.0 + 1.0) / 12.0, omega = 2.0, T = 2.0 * SC_PI / omega;
    spring_law law;
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_body_id id;
    const double *s;
    double ex, ea;
    d.integrator = integrator;
    w = sc_world(&d);
    if (!w) return INFINITY;
    law.k = m * omega * omega;
    law.kappa = I * omega * omega;
    id = sc_box(w, 1.0, 1.0, 1.0, 0.0, 0.4, 0.0, 0.0, 0.0, m, 1.0);
    CHECK(lc_world_set_force_callback(w, spring_force, NULL, &law) == LC_OK, "%s", "set_force_callback");
    sc_step_n(w, T / n, n);
    s = sc_row(w, id);
    /* exact after a period: back at the start, at rest (phase-space distance, velocities over omega) */
    ex = sqrt((s[0] - 1.0) * (s[0] - 1.0) + s[1] * s[1] + (s[3] / omega) * (s[3] / omega) + (s[4] / omega) * (s[4] / omega)) / 1.0;
    ea = sqrt((s[2] - 0.4) * (s[2] - 0.4) + (s[5] / omega) * (s[5] / omega)) / 0.4;
    CHECK_NEAR(lc_world_get_time(w), T, 1e-12, "one period of sim time");
    lc_world_destroy(w);
    return fmax(ex, ea);
}

/* RK4's step multiplies the oscillator's phase-space vector by R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 at
 * z = i omega h: |R| = 1 - (omega h)^6 / 144 + O(h^8), arg R = omega h - (omega h)^5 / 120 + O(h^7). Over a
 * period of n steps (n omega h = 2 pi) the phase lags by n (omega h)^5 / 120 = 2 pi (omega h)^4 / 120 and
 * the amplitude shrinks by n (omega h)^6 / 144: at n = 64 (omega h = 0.098) 4.9e-6 and 4.0e-7 relative,
 * whose combination sqrt(phase^2 + amp^2) is the predicted error. The measured one must be that within 2 %
 * (the O(h^7) terms are (omega h)^2 ~ 1 % of it): a callback evaluated once per step instead of at each
 * stage would be off by orders of magnitude. Halving h divides it by 2^4 = 16 (within 5 %); Euler and
 * midpoint show their orders 1 and 2 (ratios within 20 % and 10 % of 2 and 4: their leading terms, the
 * amplitude growth n (omega h)^2 / 2 and the phase n (omega h)^3 / 6, carry larger next-order terms). */
static void harmonic_oscillator(void)
{
    const int n = 64;
    double wh = 2.0 * SC_PI / n, phase = 2.0 * SC_PI * pow(wh, 4) / 120.0, amp = n * pow(wh, 6) / 144.0;
    double predicted = sqrt(phase * phase + amp * amp);
    double e64 = harmonic_error(LC_INTEGRATOR_RK4, 64), e128 = harmonic_error(LC_INTEGRATOR_RK4, 128);
    double eu1 = harmonic_error(LC_INTEGRATOR_EULER, 2000), eu2 = harmonic_error(LC_INTEGRATOR_EULER, 4000);
    double mp1 = harmonic_error(LC_INTEGRATOR_MIDPOINT, 200), mp2 = harmonic_error(LC_INTEGRATOR_MIDPOINT, 400);
    CHECK_REL(e64, predicted, 0.02, "RK4 error after one period at 64 steps vs (omega h)^4 prediction");
    CHECK(fabs(e64 / e128 / 16.0 - 1.0) < 0.05, "RK4 error ratio on halving h: %g (expected 16)", e64 / e128);
    CHECK(fabs(eu1 / eu2 / 2.0 - 1.0) < 0.2, "Euler error ratio on halving h: %g (expected 2)", eu1 / eu2);
    CHECK(fabs(mp1 / mp2 / 4.0 - 1.0) < 0.1, "midpoint error ratio on halving h: %g (expected 4)", mp1 / mp2);
}

/* Two boxes (3 kg and 1 kg, 0.2 m) orbiting their common centre of mass under G = 1: relative orbit of
 * semi-major axis a = 2 m and eccentricity 0.3 (started at pericentre, r = 1.4 m), period
 * T = 2 pi sqrt(a^3 / (G M)) = 4.44 s, over two periods. Momentum: the forces are equal and opposite at
 * every stage, so RK4 keeps sum m v up to round-off: per step a few ulps of each body's momentum
 * (<= 2.2 kg m/s), over 1600 steps below 1600 * 4 * 2.2e-16 * 2.2 = 3e-12 kg m/s; 1e-11 is asserted.
 * Energy with the potential: RK4's error is O(h^4) per unit time; at the pericentre the orbit turns at
 * omega_p = sqrt(G M (1 + e) / r_p^3) = 1.37 rad/s, so omega_p h = 7.6e-3 at h = T / 800, and a drift of
 * 2 periods x (omega_p h)^4 = 6.7e-9 of the total's scale (|U| = 2.1 J at pericentre) bounds it generously
 * for an order-4 method: 1.5e-8 J is asserted, and the drift must fall ~16x when h halves (within 30 %:
 * the drift is a sum of signed per-orbit errors). Without the potential lc_energy.total misses U, whose
 * swing over the orbit (0.9 J) is far beyond that. */
static double orbit_energy_drift(int steps_per_period, double *momentum_err, double *swing)
{
    const double G = 1.0, m1 = 3.0, m2 = 1.0, M = m1 + m2, ecc = 0.3, a = 2.0, rp = a * (1.0 - ecc);
    const double T = 2.0 * SC_PI * sqrt(a * a * a / (G * M)), vp = sqrt(G * M * (1.0 + ecc) / rp);
    gravity_law law = {G};
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_energy e0, e;
    double drift = 0.0, lo = INFINITY, hi = -INFINITY, px, py, L;
    lc_body_id b1, b2;
    int k;
    lc_force_fn f;
    lc_potential_fn p;
    void *u;
    if (!w) return INFINITY;
    /* centre of mass at rest at the origin */
    b1 = sc_box(w, 0.2, 0.2, -rp * m2 / M, 0.0, 0.0, 0.0, -vp * m2 / M, 0.0, m1, 1.0);
    b2 = sc_box(w, 0.2, 0.2, rp * m1 / M, 0.0, 0.0, 0.0, vp * m1 / M, 0.0, m2, 1.0);
    CHECK(lc_world_set_force_callback(w, gravity_force, gravity_potential, &law) == LC_OK, "%s", "set callback");
    CHECK(lc_world_get_force_callback(w, &f, &p, &u) == LC_OK && f == gravity_force && p == gravity_potential &&
              u == &law, "%s", "get_force_callback gives back what was set");
    CHECK(lc_world_get_energy(w, &e0) == LC_OK, "%s", "energy");
    CHECK_REL(e0.callback, -G * m1 * m2 / rp, 1e-15, "potential at pericentre");
    CHECK_REL(e0.total, e0.translational + e0.callback, 1e-15, "total includes the potential");
    *momentum_err = 0.0;
    for (k = 0; k < 2 * steps_per_period; ++k) {
        sc_step_n(w, T / steps_per_period, 1);
        CHECK(lc_world_get_energy(w, &e) == LC_OK, "%s", "energy");
        drift = fmax(drift, fabs(e.total - e0.total));
        lo = fmin(lo, e.callback);
        hi = fmax(hi, e.callback);
        sc_momentum(w, &px, &py, &L);
        *momentum_err = fmax(*momentum_err, hypot(px, py));
    }
    *swing = hi - lo;
    CHECK(sc_separation(w, b1, b2) > 1.0, "%s", "the boxes never touched");
    lc_world_destroy(w);
    return drift;
}

static void mutual_gravitation(void)
{
    double p1, p2, swing, d1 = orbit_energy_drift(800, &p1, &swing), d2 = orbit_energy_drift(1600, &p2, &swing);
    CHECK(d1 < 1.5e-8, "energy drift over two orbits at T/800: %g J", d1);
    CHECK(d1 / d2 > 16.0 * 0.7 && d1 / d2 < 16.0 * 1.3, "energy drift ratio on halving h: %g (order 4: 16)", d1 / d2);
    CHECK(p1 < 1e-11 && p2 < 1e-11, "momentum stays 0 within round-off: %g, %g kg m/s", p1, p2);
    CHECK(swing > 0.5, "the potential swings over the orbit (%g J)", swing);
}

/* A callback that fails (returns non-zero, or gives a NaN) fails the step with LC_ERR_CALLBACK and the
 * reason; the state, time and contacts are the step's start. The failure may come at any evaluation
 * (the n-th of the step: the islands' prediction, an RK4 stage, a time-of-impact search, the contact
 * regime); the callback is not called again in that step, and the world steps on once it behaves. */
static void failure_undoes_step(void)
{
    int bad_at, nan;
    for (nan = 0; nan <= 1; ++nan)
        for (bad_at = 1; bad_at <= 40; bad_at += 3) {
            lc_body_id box;
            lc_world *w = throw_scene(0.2, 0.0, &box);
            failing_law law;
            lc_status s;
            uint64_t h0;
            double t0;
            int calls, k, failed = 0;
            if (!w) return;
            memset(&law, 0, sizeof law);
            law.bad_at = 1 << 30;
            law.use_nan = nan;
            CHECK(lc_world_set_force_callback(w, failing_force, NULL, &law) == LC_OK, "%s", "set callback");
            /* into the floor and resting on it: impacts and the contact regime */
            for (k = 0; k < 40 && !failed; ++k) {
                h0 = lc_world_state_hash(w);
                t0 = lc_world_get_time(w);
                law.bad_at = law.calls + bad_at;
                s = lc_world_step(w, 1.0 / 60.0);
                if (s == LC_OK) {
                    law.bad_at = 1 << 30;
                    continue;
                }
                failed = 1;
                calls = law.calls;
                CHECK(s == LC_ERR_CALLBACK, "status %s: %s", lc_status_string(s), lc_world_last_error(w));
                CHECK(strstr(lc_world_last_error(w), nan ? "non-finite force" : "returned 7") != NULL &&
                          strstr(lc_world_last_error(w), "the step was undone") != NULL,
                      "message: %s", lc_world_last_error(w));
                CHECK(lc_world_state_hash(w) == h0 && lc_world_get_time(w) == t0, "%s", "the world is unchanged");
                CHECK(calls == law.bad_at, "not called after it failed (%d calls, failed at %d)", calls, law.bad_at);
                {
                    const lc_contact *cs;
                    int nc = -1;
                    lc_world_get_contacts(w, &cs, &nc);
                    CHECK(nc == 0, "no contacts of the undone step (%d)", nc);
                }
                law.bad_at = 1 << 30;
                s = lc_world_step(w, 1.0 / 60.0);
                CHECK(s == LC_OK && lc_world_get_time(w) > t0, "steps on after a failure: %s", lc_world_last_error(w));
            }
            if (bad_at == 1) CHECK(failed, "%s", "a callback failing at its first evaluation fails the step");
            lc_world_destroy(w);
        }
}

/* A potential that fails or gives NaN: lc_world_get_energy refuses with LC_ERR_CALLBACK, *out untouched. */
static int bad_potential(void *user, const lc_force_query *q, double *out)
{
    (void)q;
    if (*(int *)user) return 3;
    *out = NAN;
    return 0;
}

static void potential_failure(void)
{
    constant_law law = {{0.0, 0.0}, 0.0, 0};
    lc_world *w = sc_world(NULL);
    lc_energy e;
    int mode;
    if (!w) return;
    sc_box(w, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0);
    for (mode = 0; mode <= 1; ++mode) {
        CHECK(lc_world_set_force_callback(w, constant_force, bad_potential, &mode) == LC_OK, "%s", "set");
        e.total = 42.0;
        CHECK(lc_world_get_energy(w, &e) == LC_ERR_CALLBACK && e.total == 42.0, "get_energy: %s",
              lc_world_last_error(w));
        CHECK(strstr(lc_world_last_error(w), mode ? "returned 3" : "non-finite energy") != NULL, "message: %s",
              lc_world_last_error(w));
    }
    (void)law;
    lc_world_destroy(w);
}

/* The queries list only dynamic rows, each once; bodies is the world's state view but for its state. */
static void query_contents(void)
{
    query_probe p;
    lc_body_id box;
    lc_world *w = throw_scene(0.2, 0.0, &box);
    if (!w) return;
    memset(&p, 0, sizeof p);
    p.w = w;
    sc_box(w, 0.5, 0.5, 3.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0, 0.2);
    CHECK(lc_world_set_force_callback(w, probe_force, NULL, &p) == LC_OK, "%s", "set");
    sc_step_n(w, 1.0 / 60.0, 120);
    CHECK(p.calls > 0 && p.bad_rows == 0 && p.bad_mass == 0, "calls %d, bad rows %d, bad views %d", p.calls,
          p.bad_rows, p.bad_mass);
    CHECK(p.max_rows == 2, "at most the two dynamic rows listed (%d)", p.max_rows);
    lc_world_destroy(w);
}

/* With a callback set no body sleeps (its force would never be evaluated on a sleeping body); setting one
 * wakes a sleeping body, and removing it lets the body sleep again. */
static void no_sleep_with_callback(void)
{
    constant_law law = {{0.0, 0.0}, 0.0, 0};
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters c;
    d.allow_sleep = 1;
    w = sc_world(&d);
    if (!w) return;
    sc_static_box(w, 20.0, 1.0, 0.0, -0.5, 0.0);
    sc_box(w, 1.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    sc_step_n(w, 1.0 / 60.0, 120);
    lc_world_get_counters(w, &c, NULL);
    CHECK(c.bodies_asleep == 1, "without a callback the resting box sleeps (%llu)", (unsigned long long)c.bodies_asleep);
    CHECK(lc_world_set_force_callback(w, constant_force, NULL, &law) == LC_OK, "%s", "set");
    sc_step_n(w, 1.0 / 60.0, 240);
    lc_world_get_counters(w, &c, NULL);
    CHECK(c.bodies_asleep == 0 && law.calls > 0, "with a callback it stays awake (%llu asleep, %d calls)",
          (unsigned long long)c.bodies_asleep, law.calls);
    CHECK(lc_world_set_force_callback(w, NULL, NULL, NULL) == LC_OK, "%s", "remove");
    sc_step_n(w, 1.0 / 60.0, 120);
    lc_world_get_counters(w, &c, NULL);
    CHECK(c.bodies_asleep == 1, "removed: it sleeps again (%llu)", (unsigned long long)c.bodies_asleep);
    lc_world_destroy(w);
}

/* A callback set and removed leaves the engine as it was: the same bits as a world that never had one
 * (closed form and sleep come back too: constant_force_closed_form, no_sleep_with_callback). */
static void removal_restores(void)
{
    constant_law law = {{0.0, 0.0}, 0.0, 0};
    lc_body_id a, b;
    lc_world *wa = throw_scene(0.2, 0.0, &a), *wb = throw_scene(0.2, 0.0, &b);
    lc_force_fn f;
    lc_potential_fn p;
    void *u;
    int k, differ = -1;
    if (!wa || !wb) return;
    CHECK(lc_world_set_force_callback(wb, constant_force, NULL, &law) == LC_OK, "%s", "set");
    CHECK(lc_world_set_force_callback(wb, NULL, NULL, NULL) == LC_OK, "%s", "remove");
    CHECK(lc_world_get_force_callback(wb, &f, &p, &u) == LC_OK && f == NULL && p == NULL && u == NULL, "%s",
          "removed: none reported");
    for (k = 0; k < 200; ++k) {
        sc_step_n(wa, 1.0 / 60.0, 1);
        sc_step_n(wb, 1.0 / 60.0, 1);
        if (differ < 0 && lc_world_state_hash(wa) != lc_world_state_hash(wb)) differ = k;
    }
    CHECK(differ < 0, "set and removed: differs from a world without one from step %d", differ);
    CHECK(law.calls == 0, "a removed callback is not called (%d)", law.calls);
    lc_world_destroy(wa);
    lc_world_destroy(wb);
}

/* A snapshot holds no callback: lc_world_load keeps the world's own, a world created from a snapshot has
 * none; with the same callback set again, a loaded world steps on bit for bit (the thrown box and a
 * second one attracting each other over the floor: impacts and the contact regime). */
static void snapshot_and_callback(void)
{
    gravity_law law = {50.0};
    constant_law other_law = {{1.0, 0.0}, 0.0, 0};
    lc_body_id box;
    lc_world *w = throw_scene(0.2, 0.0, &box), *copy, *other = sc_world(NULL);
    size_t n = 0, m = 0;
    unsigned char *buf;
    lc_force_fn f;
    lc_potential_fn p;
    void *u;
    char err[256];
    uint64_t h;
    if (!w || !other) return;
    sc_box(w, 0.5, 0.5, 2.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0, 0.2);
    CHECK(lc_world_set_force_callback(w, gravity_force, gravity_potential, &law) == LC_OK, "%s", "set");
    sc_step_n(w, 1.0 / 60.0, 60);
    CHECK(lc_world_save(w, NULL, 0, &n) == LC_OK && n > 0, "%s", "snapshot size");
    buf = malloc(n);
    if (buf == NULL) return;
    CHECK(lc_world_save(w, buf, n, &m) == LC_OK && m == n, "%s", "save");
    sc_step_n(w, 1.0 / 60.0, 120);
    h = lc_world_state_hash(w);
    copy = lc_world_create_from_snapshot(buf, n, err, sizeof err);
    CHECK(copy != NULL, "create_from_snapshot: %s", err);
    if (copy != NULL) {
        CHECK(lc_world_get_force_callback(copy, &f, &p, &u) == LC_OK && f == NULL && p == NULL && u == NULL, "%s",
              "a world created from a snapshot has no callback");
        CHECK(lc_world_set_force_callback(copy, gravity_force, gravity_potential, &law) == LC_OK, "%s", "set again");
        sc_step_n(copy, 1.0 / 60.0, 120);
        CHECK(lc_world_state_hash(copy) == h, "%s", "created from the snapshot, same callback: the same bits");
        lc_world_destroy(copy);
    }
    CHECK(lc_world_set_force_callback(other, constant_force, NULL, &other_law) == LC_OK, "%s", "set on other");
    CHECK(lc_world_load(other, buf, n) == LC_OK, "load: %s", lc_world_last_error(other));
    CHECK(lc_world_get_force_callback(other, &f, &p, &u) == LC_OK && f == constant_force && p == NULL &&
              u == &other_law, "%s", "lc_world_load keeps the world's own callback");
    CHECK(lc_world_set_force_callback(other, gravity_force, gravity_potential, &law) == LC_OK, "%s", "set");
    sc_step_n(other, 1.0 / 60.0, 120);
    CHECK(lc_world_state_hash(other) == h, "%s", "loaded, same callback: the same bits");
    free(buf);
    lc_world_destroy(w);
    lc_world_destroy(other);
}

/* Bad calls change nothing and say why. */
static void bad_calls(void)
{
    constant_law law = {{1.0, 0.0}, 0.0, 0};
    lc_world *w = sc_world(NULL);
    lc_force_fn f;
    lc_potential_fn p;
    void *u;
    if (!w) return;
    CHECK(lc_world_set_force_callback(NULL, constant_force, NULL, &law) == LC_ERR_NULL, "%s", "NULL world");
    CHECK(lc_world_get_force_callback(NULL, &f, &p, &u) == LC_ERR_NULL, "%s", "get: NULL world");
    CHECK(lc_world_set_force_callback(w, constant_force, NULL, &law) == LC_OK, "%s", "set");
    CHECK(lc_world_set_force_callback(w, NULL, gravity_potential, &law) == LC_ERR_NULL &&
              strstr(lc_world_last_error(w), "potential") != NULL,
          "a potential without a force: %s", lc_world_last_error(w));
    CHECK(lc_world_get_force_callback(w, &f, &p, &u) == LC_OK && f == constant_force && p == NULL && u == &law, "%s",
          "the refused call left the callback as it was");
    CHECK(lc_world_get_force_callback(w, NULL, &p, &u) == LC_ERR_NULL && lc_world_get_force_callback(w, &f, NULL, &u) ==
              LC_ERR_NULL && lc_world_get_force_callback(w, &f, &p, NULL) == LC_ERR_NULL,
          "%s", "get: each output required");
    CHECK(strcmp(lc_status_string(LC_ERR_CALLBACK), "callback failed") == 0, "%s", "status name");
    lc_world_destroy(w);
}

int main(void)
{
    constant_force_same_bits();
    constant_force_closed_form();
    harmonic_oscillator();
    mutual_gravitation();
    failure_undoes_step();
    potential_failure();
    query_contents();
    no_sleep_with_callback();
    removal_restores();
    snapshot_and_callback();
    bad_calls();
    return CHECK_SUMMARY("test_force_callback");
}
