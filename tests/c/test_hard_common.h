/* test_hard_common.h - the per-step monitor shared by the hard-case stability suite (docs/hard_cases.md,
 * tests/c/test_hard_*.c). Header only, C99, include after check.h and scenes.h.
 *
 * A monitor (hc_mon) watches one world while the test steps it with hc_step():
 *  - every lc_world_step returns LC_OK (the first failure is a failed CHECK and ends the run);
 *  - the world's clock advances by exactly dt per step (to 1e-9 s: k additions of dt);
 *  - every dynamic state value is finite after every step (the engine undoes non-finite steps and
 *    returns LC_ERR_NUMERIC, so this also checks that contract);
 *  - optional box: no dynamic body's centre ever leaves [xmin, xmax] x [ymin, ymax];
 *  - no pair of bodies (dynamic-dynamic and dynamic-static) overlaps by more than mon.overlap_tol at
 *    any step end (HC_OVERLAP_TOL unless the test sets it): the engine handles impacts and holds resting
 *    contacts at gap contact_gap (1e-7 m) and projects points found inside a body out at the end of the
 *    step, so it guarantees no step ends overlapping; 1e-9 m (1 % of contact_gap) leaves room for
 *    round-off only. A pile's island (at least 16 bodies and 64 points, contact_regime.md) is projected
 *    to 1e-7 m and may end a step 2.5e-7 m deep (HC_PILE_OVERLAP_TOL). The separation
 *    is scenes.h's SAT (sc_sat_one_way_ both ways, the body of sc_separation) on vertices fetched
 *    once per step, tried only for pairs whose bounding boxes come within 1 mm;
 *  - the total mechanical energy, computed here from the state view (KE + m g.h with the world's
 *    gravity, independent of the engine's energy code): its largest rise and fall since the start.
 *  - optional impact budget (mon.max_collisions > 0): the run stops with a failed CHECK once the
 *    engine's cumulative collision count exceeds it. Each scene sets it from physics (a resting stack
 *    has no impacts at all) or far above its measured count; it keeps a failing scene (an impact
 *    storm at 300 ms per step) from running for half an hour - it is not a timing.
 * hc_finish() prints the figures and asserts the first four; energy bounds are asserted by the test
 * (they depend on the scene), from mon.max_gain / mon.max_loss. */
#ifndef LC_TESTS_HARD_COMMON_H
#define LC_TESTS_HARD_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scenes.h"

#define HC_OVERLAP_TOL 1e-9
#define HC_PILE_OVERLAP_TOL 2.5e-7 /* LC_CONTACT_OVERLAP_LEFT scaled with LC_CONTACT_PROJECTION_LARGE_SLACK */
#define HC_DT (1.0 / 60.0)
#define HC_T 60.0
#define HC_STEPS 3600 /* 60 s at dt = 1/60 s */
#define HC_MAX_BODIES 512

typedef struct hc_mon {
    lc_world *w;
    const char *label;
    double dt;
    double gx, gy;
    int has_box;
    double xmin, ymin, xmax, ymax;
    int n;                          /* bodies in the world (dynamic and static), row order */
    lc_vec2 *verts;                 /* n * 4 (boxes only; see hc_mon_init) */
    int *nv;
    double *aabb;                   /* n * 4: minx, miny, maxx, maxy */
    int steps_ok, failed, nonfinite, outside, bad_clock;
    double t_outside, t_nonfinite;
    double worst_overlap, t_overlap;
    double overlap_tol;             /* m, the deepest overlap allowed (HC_OVERLAP_TOL) */
    int overlap_a, overlap_b;       /* rows of the worst pair */
    double e0, e_now, max_gain, max_loss, t_gain;
    uint64_t max_collisions;        /* 0 = no budget */
} hc_mon;

/* Total mechanical energy (J): sum m|v|^2/2 + I w^2/2 - m g.x over dynamic bodies. */
static inline double hc_energy(const lc_world *w, double gx, double gy)
{
    lc_state_view v;
    double e = sc_kinetic(w);
    int i;
    if (lc_world_get_state(w, &v) != LC_OK) return NAN;
    for (i = 0; i < v.count; i++) {
        const double *s = v.state + 6 * i;
        if (v.is_static[i]) continue;
        e -= v.mass[i] * (gx * s[0] + gy * s[1]);
    }
    return e;
}

/* Call after every body has been added. box may be NULL (no containment check). */
static inline int hc_mon_init(hc_mon *m, lc_world *w, const char *label, double dt, const double *box)
{
    lc_world_def d;
    memset(m, 0, sizeof *m);
    m->w = w;
    m->label = label;
    m->dt = dt;
    lc_world_get_def(w, &d);
    m->gx = d.gravity.x;
    m->gy = d.gravity.y;
    if (box) {
        m->has_box = 1;
        m->xmin = box[0];
        m->ymin = box[1];
        m->xmax = box[2];
        m->ymax = box[3];
    }
    m->n = lc_world_body_count(w);
    CHECK(m->n > 0 && m->n <= HC_MAX_BODIES, "%s: %d bodies", label, m->n);
    m->verts = (lc_vec2 *)calloc((size_t)m->n * LC_MAX_POLYGON_VERTICES, sizeof(lc_vec2));
    m->nv = (int *)calloc((size_t)m->n, sizeof(int));
    m->aabb = (double *)calloc((size_t)m->n * 4, sizeof(double));
    CHECK(m->verts && m->nv && m->aabb, "%s: out of memory", label);
    m->e0 = m->e_now = hc_energy(w, m->gx, m->gy);
    m->worst_overlap = 0.0;
    m->overlap_tol = HC_OVERLAP_TOL;
    m->overlap_a = m->overlap_b = -1;
    return m->verts && m->nv && m->aabb;
}

static inline void hc_mon_free(hc_mon *m)
{
    free(m->verts);
    free(m->nv);
    free(m->aabb);
    m->verts = NULL;
    m->nv = NULL;
    m->aabb = NULL;
}

/* Worst overlap of the current state (also used once before the first step). */
static inline void hc_check_overlap(hc_mon *m)
{
    lc_state_view v;
    int i, j, k;
    double t = lc_world_get_time(m->w);
    if (lc_world_get_state(m->w, &v) != LC_OK) return;
    for (i = 0; i < v.count && i < m->n; i++) {
        lc_vec2 *p = m->verts + (size_t)i * LC_MAX_POLYGON_VERTICES;
        double *bb = m->aabb + 4 * i;
        m->nv[i] = sc_world_vertices(m->w, v.ids[i], p);
        bb[0] = bb[1] = INFINITY;
        bb[2] = bb[3] = -INFINITY;
        for (k = 0; k < m->nv[i]; k++) {
            if (p[k].x < bb[0]) bb[0] = p[k].x;
            if (p[k].y < bb[1]) bb[1] = p[k].y;
            if (p[k].x > bb[2]) bb[2] = p[k].x;
            if (p[k].y > bb[3]) bb[3] = p[k].y;
        }
    }
    for (i = 0; i < v.count && i < m->n; i++) {
        const double *a = m->aabb + 4 * i;
        for (j = i + 1; j < v.count && j < m->n; j++) {
            const double *b = m->aabb + 4 * j;
            double s1, s2, sep;
            if (v.is_static[i] && v.is_static[j]) continue;
            if (a[0] > b[2] + 1e-3 || b[0] > a[2] + 1e-3 || a[1] > b[3] + 1e-3 || b[1] > a[3] + 1e-3) continue;
            if (!m->nv[i] || !m->nv[j]) continue;
            s1 = sc_sat_one_way_(m->verts + (size_t)i * LC_MAX_POLYGON_VERTICES, m->nv[i],
                                 m->verts + (size_t)j * LC_MAX_POLYGON_VERTICES, m->nv[j]);
            s2 = sc_sat_one_way_(m->verts + (size_t)j * LC_MAX_POLYGON_VERTICES, m->nv[j],
                                 m->verts + (size_t)i * LC_MAX_POLYGON_VERTICES, m->nv[i]);
            sep = s1 > s2 ? s1 : s2;
            if (-sep > m->worst_overlap || sep != sep) {
                m->worst_overlap = sep != sep ? INFINITY : -sep;
                m->t_overlap = t;
                m->overlap_a = i;
                m->overlap_b = j;
            }
        }
    }
}

/* One step of the monitored world; returns 1 if it returned LC_OK (0 stops the run). */
static inline int hc_step(hc_mon *m)
{
    lc_state_view v;
    lc_status s;
    double t, e;
    int i, k;
    if (m->failed) return 0;
    s = lc_world_step(m->w, m->dt);
    if (s != LC_OK) {
        m->failed = 1;
        CHECK(0, "%s: lc_world_step(%g) after %d good steps (t = %.6f) -> %s: %s", m->label, m->dt, m->steps_ok,
              lc_world_get_time(m->w), lc_status_string(s), lc_world_last_error(m->w));
        return 0;
    }
    m->steps_ok++;
    t = lc_world_get_time(m->w);
    if (m->max_collisions > 0) {
        lc_counters tot;
        if (lc_world_get_counters(m->w, NULL, &tot) == LC_OK && tot.collisions > m->max_collisions) {
            m->failed = 1;
            CHECK(0, "%s: %llu impacts by t = %.4f s exceed the scene's budget of %llu (impact storm); run stopped",
                  m->label, (unsigned long long)tot.collisions, t, (unsigned long long)m->max_collisions);
            return 0;
        }
    }
    if (fabs(t - m->steps_ok * m->dt) > 1e-9) m->bad_clock++;
    if (lc_world_get_state(m->w, &v) == LC_OK) {
        for (i = 0; i < v.count; i++) {
            const double *r = v.state + 6 * i;
            if (v.is_static[i]) continue;
            for (k = 0; k < 6; k++)
                if (!isfinite(r[k])) {
                    if (!m->nonfinite) m->t_nonfinite = t;
                    m->nonfinite++;
                    break;
                }
            if (m->has_box && !(r[0] >= m->xmin && r[0] <= m->xmax && r[1] >= m->ymin && r[1] <= m->ymax)) {
                if (!m->outside) m->t_outside = t;
                m->outside++;
            }
        }
    }
    hc_check_overlap(m);
    e = hc_energy(m->w, m->gx, m->gy);
    m->e_now = e;
    if (e - m->e0 > m->max_gain || e != e) {
        m->max_gain = e != e ? INFINITY : e - m->e0;
        m->t_gain = t;
    }
    if (m->e0 - e > m->max_loss) m->max_loss = m->e0 - e;
    return 1;
}

/* Asserts the scene-independent properties; prints the run's figures and counters. */
static inline void hc_finish(hc_mon *m, int steps_expected)
{
    lc_counters tot;
    memset(&tot, 0, sizeof tot);
    lc_world_get_counters(m->w, NULL, &tot);
    printf("%s: %d/%d steps ok, t = %.4f s, worst overlap %.3e m (t = %.3f, rows %d/%d), energy E0 %.9g J, "
           "max gain %.3e J, max loss %.3e J, final %.9g J; collisions %llu, impulses %llu, fallbacks %llu, "
           "contact solves %llu, projections %llu\n",
           m->label, m->steps_ok, steps_expected, lc_world_get_time(m->w), m->worst_overlap, m->t_overlap,
           m->overlap_a, m->overlap_b, m->e0, m->max_gain, m->max_loss, m->e_now,
           (unsigned long long)tot.collisions, (unsigned long long)tot.impulses,
           (unsigned long long)tot.inelastic_fallbacks, (unsigned long long)tot.contact_solves,
           (unsigned long long)tot.position_projections);
    fflush(stdout);
    CHECK(m->steps_ok == steps_expected, "%s: %d of %d steps returned LC_OK", m->label, m->steps_ok,
          steps_expected);
    CHECK(m->bad_clock == 0, "%s: the clock did not advance by dt on %d steps", m->label, m->bad_clock);
    CHECK(m->nonfinite == 0, "%s: non-finite state on %d body-steps (first at t = %.4f)", m->label, m->nonfinite,
          m->t_nonfinite);
    CHECK(m->outside == 0, "%s: a body centre left the box %d times (first at t = %.4f)", m->label, m->outside,
          m->t_outside);
    CHECK(m->worst_overlap <= m->overlap_tol, "%s: bodies (rows %d and %d) overlapped by %.3e m at t = %.4f",
          m->label, m->overlap_a, m->overlap_b, m->worst_overlap, m->t_overlap);
}

/* Largest |v| (m/s) and |omega| (rad/s) over the dynamic bodies. */
static inline void hc_max_speeds(const lc_world *w, double *vmax, double *wmax)
{
    lc_state_view v;
    int i;
    *vmax = *wmax = 0.0;
    if (lc_world_get_state(w, &v) != LC_OK) return;
    for (i = 0; i < v.count; i++) {
        const double *s = v.state + 6 * i;
        double sp = sqrt(s[3] * s[3] + s[4] * s[4]);
        if (v.is_static[i]) continue;
        if (sp > *vmax || sp != sp) *vmax = sp;
        if (fabs(s[5]) > *wmax || s[5] != s[5]) *wmax = fabs(s[5]);
    }
}

/* Distance from angle a to the nearest multiple of pi/2 (rad): the tilt of a box meant to be upright. */
static inline double hc_tilt(double a)
{
    double r = fmod(fabs(a), SC_PI / 2.0);
    return r > SC_PI / 4.0 ? SC_PI / 2.0 - r : r;
}

/* A static box with material (e, mu): floors and walls of scenes with friction. */
static inline lc_body_id hc_static(lc_world *w, double width, double height, double x, double y, double e, double mu)
{
    lc_body_id id = sc_static_box(w, width, height, x, y, e);
    lc_status s = lc_body_set_material(w, id, e, mu);
    CHECK(s == LC_OK, "set_material(static, %g, %g) -> %s", e, mu, lc_status_string(s));
    return id;
}

/* A dynamic box with material (e, mu). */
static inline lc_body_id hc_box(lc_world *w, double width, double height, double x, double y, double angle,
                                double vx, double vy, double omega, double mass, double e, double mu)
{
    lc_body_id id = sc_box(w, width, height, x, y, angle, vx, vy, omega, mass, e);
    lc_status s = lc_body_set_material(w, id, e, mu);
    CHECK(s == LC_OK, "set_material(%g, %g) -> %s", e, mu, lc_status_string(s));
    return id;
}

/* Four walls (1 m thick) whose inner faces bound [xmin,xmax] x [ymin,ymax], with material (e, mu). */
static inline void hc_walls(lc_world *w, double xmin, double ymin, double xmax, double ymax, double e, double mu,
                            lc_body_id out[4])
{
    int i;
    lc_status s = lc_world_add_walls(w, xmin, ymin, xmax, ymax, 1.0, e, out);
    CHECK(s == LC_OK, "add_walls -> %s: %s", lc_status_string(s), lc_world_last_error(w));
    for (i = 0; i < 4; i++) lc_body_set_material(w, out[i], e, mu);
}

/* The settling scene's layout (bench settling(), layout `seed`): walls bounding [0, 10]^2 and 20 blocks
 * 1 m x 0.5 m of 1 kg in random cells of a 5 x 5 grid with random angles, velocities and spins, all with
 * material (e, mu); the blocks' ids in out[20]. */
static inline void hc_settling_layout(lc_world *w, uint64_t seed, double e, double mu, lc_body_id out[20])
{
    lc_body_id walls[4];
    sc_rng rng;
    int cells[25], i;
    rng.s = seed;
    hc_walls(w, 0.0, 0.0, 10.0, 10.0, e, mu, walls);
    for (i = 0; i < 25; i++) cells[i] = i;
    for (i = 24; i > 0; i--) {
        int j = (int)(sc_rand(&rng) * (i + 1)), t = cells[i];
        cells[i] = cells[j];
        cells[j] = t;
    }
    for (i = 0; i < 20; i++) {
        double x = 1.0 + 2.0 * (cells[i] % 5), y = 1.0 + 2.0 * (cells[i] / 5);
        double a = sc_uniform(&rng, 0.0, SC_PI), vx = sc_uniform(&rng, -3, 3), vy = sc_uniform(&rng, -3, 3);
        double om = sc_uniform(&rng, -2, 2);
        out[i] = hc_box(w, 1.0, 0.5, x, y, a, vx, vy, om, 1.0, e, mu);
    }
}

#endif /* LC_TESTS_HARD_COMMON_H */
