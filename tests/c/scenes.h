/* scenes.h - shared helpers that build and inspect test scenes for the libcollide C tests
 * (header only, C99, all static inline). Include after check.h.
 *
 *   sc_world(def)                      - create a world (NULL def = defaults); failure is a failed CHECK
 *   sc_def_zero_g()                    - default settings with gravity 0
 *   sc_box(w, width, height, x, y, angle, vx, vy, omega, mass, e)  - add a dynamic w x h rectangle
 *   sc_static_box(w, width, height, x, y, e)                      - add a static rectangle
 *   sc_pyramid(w, base, mu, ids)       - Box2D's large-pyramid layout of unit boxes (no ground)
 *   sc_drop_on_pyramid(base)           - the contact bench's drop12 world: a 5 kg box at 8 m/s onto a pyramid
 *   sc_poly(w, verts, n, x, y, angle, mass)                        - add a dynamic polygon
 *   sc_row(w, id)                      - pointer to a body's 6 state doubles (x, y, angle, vx, vy, omega)
 *   sc_mass(w, id), sc_inertia(w, id)
 *   sc_energy(w)                       - lc_energy of the current state
 *   sc_kinetic(w), sc_momentum(w, &px, &py, &L)  - computed here from the state view (independent of
 *                                        the engine's energy code); L is about the world origin
 *   sc_separation(w, a, b)             - signed separation of two convex bodies (SAT): > 0 apart
 *                                        (a lower bound of the distance, exact for vertex-edge
 *                                        closest features), < 0 overlapping by that depth
 *   sc_min_y(w, id), sc_max_x(w, id)   - extreme world vertex coordinates
 *   sc_rng                              - small deterministic generator (no global state)
 *   sc_step_n(w, dt, n)                - n steps; stops and fails a CHECK on the first non-OK status
 *   sc_contacts(w, &cs)                - the last step's contacts and their count
 *   sc_world_vertices(w, id, out)      - world vertices, returns the count
 *   sc_static_box_rotated(w, width, height, x, y, angle, e)        - add a static rectangle turned by angle
 *   sc_potential(w, gx, gy)            - gravitational energy -sum m g.p of the dynamic bodies (J, zero at
 *                                        the origin), computed here from the state view
 *   sc_driven_blocks(d, seed, mouse, ids)  - walls, six seed blocks with random velocities, a spring,
 *                                        thrusters firing (and a mouse spring): every stateful feature
 */
#ifndef LC_TESTS_SCENES_H
#define LC_TESTS_SCENES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "collide/collide.h"
#include "check.h"

#define SC_PI 3.14159265358979323846

static inline lc_world *sc_world(const lc_world_def *def)
{
    char err[256];
    lc_world_def d = def ? *def : lc_default_world_def();
    lc_world *w;
    err[0] = '\0';
    w = lc_world_create(&d, err, sizeof err);
    CHECK(w != NULL, "lc_world_create failed: %s", err);
    return w;
}

static inline lc_world_def sc_def_zero_g(void)
{
    lc_world_def d = lc_default_world_def();
    d.gravity.x = 0.0;
    d.gravity.y = 0.0;
    return d;
}

static inline lc_body_id sc_add(lc_world *w, const lc_body_def *bd, const char *what)
{
    lc_body_id id = 0;
    lc_status s = lc_world_add_body(w, bd, &id);
    CHECK(s == LC_OK, "add_body(%s) -> %s: %s", what, lc_status_string(s), lc_world_last_error(w));
    return id;
}

static inline lc_body_id sc_box(lc_world *w, double width, double height, double x, double y, double angle,
                                double vx, double vy, double omega, double mass, double e)
{
    lc_vec2 v[4];
    lc_body_def bd = lc_default_body_def();
    lc_status s = lc_make_rectangle(width, height, v);
    CHECK(s == LC_OK, "lc_make_rectangle(%g, %g) -> %s", width, height, lc_status_string(s));
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.position.x = x;
    bd.position.y = y;
    bd.angle = angle;
    bd.velocity.x = vx;
    bd.velocity.y = vy;
    bd.angular_velocity = omega;
    bd.mass = mass;
    bd.elasticity = e;
    return sc_add(w, &bd, "box");
}

static inline lc_body_id sc_static_box(lc_world *w, double width, double height, double x, double y, double e)
{
    lc_vec2 v[4];
    lc_body_def bd = lc_default_body_def();
    lc_status s = lc_make_rectangle(width, height, v);
    CHECK(s == LC_OK, "lc_make_rectangle(%g, %g) -> %s", width, height, lc_status_string(s));
    bd.type = LC_BODY_STATIC;
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.position.x = x;
    bd.position.y = y;
    bd.elasticity = e;
    return sc_add(w, &bd, "static box");
}

/* Box2D's "large pyramid" layout (bench/scenes.py's pyramid): rows of 1 m, 1 kg boxes (e 0, friction
 * mu) touching side by side, row i (from 0) at y = 0.5 + i on row i - 1, the bottom row on y = 0,
 * centred on x = 0. The ground is the caller's. Writes the ids to ids when not NULL (base (base + 1) / 2
 * of them, row by row) and returns their count. */
static inline int sc_pyramid(lc_world *w, int base, double mu, lc_body_id *ids)
{
    int i, j, n = 0;
    for (i = 0; i < base; ++i)
        for (j = i; j < base; ++j) {
            lc_body_id id = sc_box(w, 1.0, 1.0, (i + 1.0) * 0.5 + (j - i) * 1.0 - 0.5 * base, 0.5 + i * 1.0, 0.0, 0.0,
                                   0.0, 0.0, 1.0, 0.0);
            lc_status s = lc_body_set_material(w, id, 0.0, mu);
            CHECK(s == LC_OK, "set_material(0, %g) -> %s", mu, lc_status_string(s));
            if (ids) ids[n] = id;
            n++;
        }
    return n;
}

/* bench/contact.py's drop12 (bench/scenes.py drop_on_pyramid): a new world (g 10 down, no damping) with
 * sc_pyramid(base) (mu 0.6, e 0), a static ground 2 base + 20 m x 1 m (top face y = 0, mu 0.6, e 0), then
 * a 5 kg unit box from 2 m above the top at 8 m/s down, turning at 1 rad/s (mu 0.6, e 0): the bench's
 * bodies in the bench's order, so its trajectory step for step. NULL if the world could not be made. */
static inline lc_world *sc_drop_on_pyramid(int base)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id id;
    d.gravity.x = 0.0;
    d.gravity.y = -10.0;
    d.damping = 0.0;
    w = sc_world(&d);
    if (!w) return NULL;
    sc_pyramid(w, base, 0.6, NULL);
    id = sc_static_box(w, 2.0 * base + 20.0, 1.0, 0.0, -0.5, 0.0);
    CHECK(lc_body_set_material(w, id, 0.0, 0.6) == LC_OK, "%s", "ground material");
    id = sc_box(w, 1.0, 1.0, 0.3, base + 2.0, 0.0, 0.0, -8.0, 1.0, 5.0, 0.0);
    CHECK(lc_body_set_material(w, id, 0.0, 0.6) == LC_OK, "%s", "box material");
    return w;
}

static inline lc_body_id sc_poly(lc_world *w, const lc_vec2 *verts, int n, double x, double y, double angle,
                                 double mass)
{
    lc_body_def bd = lc_default_body_def();
    bd.vertices = verts;
    bd.vertex_count = n;
    bd.position.x = x;
    bd.position.y = y;
    bd.angle = angle;
    bd.mass = mass;
    return sc_add(w, &bd, "polygon");
}

static inline const double *sc_row(const lc_world *w, lc_body_id id)
{
    static const double zeros[6] = {0, 0, 0, 0, 0, 0};
    lc_state_view v;
    int i = lc_world_body_index(w, id);
    if (i < 0 || lc_world_get_state(w, &v) != LC_OK) {
        CHECK(0, "body %u has no state row", (unsigned)id);
        return zeros;
    }
    return v.state + 6 * i;
}

static inline double sc_mass(const lc_world *w, lc_body_id id)
{
    lc_state_view v;
    int i = lc_world_body_index(w, id);
    if (i < 0 || lc_world_get_state(w, &v) != LC_OK) return NAN;
    return v.mass[i];
}

static inline double sc_inertia(const lc_world *w, lc_body_id id)
{
    lc_state_view v;
    int i = lc_world_body_index(w, id);
    if (i < 0 || lc_world_get_state(w, &v) != LC_OK) return NAN;
    return v.inertia[i];
}

static inline lc_energy sc_energy(const lc_world *w)
{
    lc_energy e;
    memset(&e, 0, sizeof e);
    CHECK(lc_world_get_energy(w, &e) == LC_OK, "%s", "lc_world_get_energy");
    return e;
}

/* Kinetic energy (J) from the state view: sum m|v|^2/2 + I w^2/2 over dynamic bodies. */
static inline double sc_kinetic(const lc_world *w)
{
    lc_state_view v;
    double k = 0.0;
    int i;
    if (lc_world_get_state(w, &v) != LC_OK) return NAN;
    for (i = 0; i < v.count; i++) {
        const double *s = v.state + 6 * i;
        if (v.is_static[i]) continue;
        k += 0.5 * v.mass[i] * (s[3] * s[3] + s[4] * s[4]) + 0.5 * v.inertia[i] * s[5] * s[5];
    }
    return k;
}

/* Linear momentum (kg m/s) and angular momentum about the world origin (kg m^2/s). */
static inline void sc_momentum(const lc_world *w, double *px, double *py, double *L)
{
    lc_state_view v;
    int i;
    *px = *py = *L = 0.0;
    if (lc_world_get_state(w, &v) != LC_OK) return;
    for (i = 0; i < v.count; i++) {
        const double *s = v.state + 6 * i;
        if (v.is_static[i]) continue;
        *px += v.mass[i] * s[3];
        *py += v.mass[i] * s[4];
        *L += v.mass[i] * (s[0] * s[4] - s[1] * s[3]) + v.inertia[i] * s[5];
    }
}

/* World vertices of a body into out[LC_MAX_POLYGON_VERTICES]; returns the count (0 on error). */
static inline int sc_world_vertices(const lc_world *w, lc_body_id id, lc_vec2 *out)
{
    int n = lc_body_vertex_count(w, id);
    if (n < 3 || n > LC_MAX_POLYGON_VERTICES) return 0;
    if (lc_body_get_world_vertices(w, id, out, n) != LC_OK) return 0;
    return n;
}

/* max over the edges of P of min over the vertices of Q of the signed distance along the edge's
 * outward normal. */
static inline double sc_sat_one_way_(const lc_vec2 *p, int np, const lc_vec2 *q, int nq)
{
    double area2 = 0.0, best = -INFINITY;
    int i, j;
    for (i = 0; i < np; i++) {
        const lc_vec2 a = p[i], b = p[(i + 1) % np];
        area2 += a.x * b.y - b.x * a.y;
    }
    for (i = 0; i < np; i++) {
        const lc_vec2 a = p[i], b = p[(i + 1) % np];
        double ex = b.x - a.x, ey = b.y - a.y, len = sqrt(ex * ex + ey * ey), nx, ny, m = INFINITY;
        /* outward normal: right of the edge for counter-clockwise polygons */
        nx = ey / len;
        ny = -ex / len;
        if (area2 < 0) { nx = -nx; ny = -ny; }
        for (j = 0; j < nq; j++) {
            double d = (q[j].x - a.x) * nx + (q[j].y - a.y) * ny;
            if (d < m) m = d;
        }
        if (m > best) best = m;
    }
    return best;
}

static inline double sc_separation(const lc_world *w, lc_body_id a, lc_body_id b)
{
    lc_vec2 pa[LC_MAX_POLYGON_VERTICES], pb[LC_MAX_POLYGON_VERTICES];
    int na = sc_world_vertices(w, a, pa), nb = sc_world_vertices(w, b, pb);
    double s1, s2;
    if (!na || !nb) return NAN;
    s1 = sc_sat_one_way_(pa, na, pb, nb);
    s2 = sc_sat_one_way_(pb, nb, pa, na);
    return s1 > s2 ? s1 : s2;
}

static inline double sc_min_y(const lc_world *w, lc_body_id id)
{
    lc_vec2 p[LC_MAX_POLYGON_VERTICES];
    int n = sc_world_vertices(w, id, p), i;
    double m = INFINITY;
    if (!n) return NAN;
    for (i = 0; i < n; i++) if (p[i].y < m) m = p[i].y;
    return m;
}

static inline double sc_max_x(const lc_world *w, lc_body_id id)
{
    lc_vec2 p[LC_MAX_POLYGON_VERTICES];
    int n = sc_world_vertices(w, id, p), i;
    double m = -INFINITY;
    if (!n) return NAN;
    for (i = 0; i < n; i++) if (p[i].x > m) m = p[i].x;
    return m;
}

/* Deterministic generator (64-bit LCG, Knuth's MMIX constants); state lives in the caller. */
typedef struct sc_rng { uint64_t s; } sc_rng;

static inline double sc_rand(sc_rng *r) /* uniform in [0, 1) */
{
    r->s = r->s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(r->s >> 11) * (1.0 / 9007199254740992.0);
}

static inline double sc_uniform(sc_rng *r, double lo, double hi) { return lo + (hi - lo) * sc_rand(r); }

/* n steps of dt; returns the number of steps done (stops at the first failure, which is a failed CHECK). */
static inline int sc_step_n(lc_world *w, double dt, int n)
{
    int i;
    for (i = 0; i < n; i++) {
        lc_status s = lc_world_step(w, dt);
        if (s != LC_OK) {
            CHECK(0, "lc_world_step(%g) at t=%.9g -> %s: %s", dt, lc_world_get_time(w), lc_status_string(s),
                  lc_world_last_error(w));
            return i;
        }
    }
    return n;
}

/* The contacts of the last step (collisions and resting) into *out; returns their count. */
static inline int sc_contacts(const lc_world *w, const lc_contact **out)
{
    int n = 0;
    *out = NULL;
    if (lc_world_get_contacts(w, out, &n) != LC_OK) return 0;
    return n;
}

/* A static width x height rectangle centred on (x, y) and turned by angle (rad, counter-clockwise):
 * a ramp. */
static inline lc_body_id sc_static_box_rotated(lc_world *w, double width, double height, double x, double y,
                                               double angle, double e)
{
    lc_vec2 v[4];
    lc_body_def bd = lc_default_body_def();
    lc_status s = lc_make_rectangle(width, height, v);
    CHECK(s == LC_OK, "lc_make_rectangle(%g, %g) -> %s", width, height, lc_status_string(s));
    bd.type = LC_BODY_STATIC;
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.position.x = x;
    bd.position.y = y;
    bd.angle = angle;
    bd.elasticity = e;
    return sc_add(w, &bd, "rotated static box");
}

/* Gravitational energy (J) of the dynamic bodies in a uniform field (gx, gy), zero at the world origin:
 * -sum m (gx x + gy y), from the state view (independent of the engine's energy code). With the
 * default zero_energy_level 0 it equals lc_energy.gravitational. */
static inline double sc_potential(const lc_world *w, double gx, double gy)
{
    lc_state_view v;
    double u = 0.0;
    int i;
    if (lc_world_get_state(w, &v) != LC_OK) return NAN;
    for (i = 0; i < v.count; i++) {
        const double *s = v.state + 6 * i;
        if (v.is_static[i]) continue;
        u -= v.mass[i] * (gx * s[0] + gy * s[1]);
    }
    return u;
}

/* Walls (e 0.7) around six 1 m x 3 m blocks at e = 0.7 (block 0 2 kg, the others 1 kg) with positions,
 * angles and velocities drawn from sc_rng seed, damping 0.05, a spring between blocks 1 and 2, block 0's
 * thrusters 0 and 2 firing, and with mouse_spring a spring from block 3 to a fixed point: everything that
 * carries state or branches (the determinism, snapshot and event tests' scene). d: the settings to start
 * from; ids: the six blocks' ids, or NULL. NULL if the world could not be made. */
static inline lc_world *sc_driven_blocks(lc_world_def d, uint64_t seed, int mouse_spring, lc_body_id *ids)
{
    lc_world *w;
    lc_body_id b[6];
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    sc_rng rng;
    int i;
    rng.s = seed;
    d.damping = 0.05;
    w = sc_world(&d);
    if (!w) return NULL;
    lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 0.7, NULL);
    for (i = 0; i < 6; i++)
        b[i] = sc_box(w, 1.0, 3.0, -5.0 + 2.0 * i, sc_uniform(&rng, -2.0, 2.0), sc_uniform(&rng, -0.2, 0.2),
                      sc_uniform(&rng, -4.0, 4.0), sc_uniform(&rng, -4.0, 4.0), sc_uniform(&rng, -2.0, 2.0),
                      i == 0 ? 2.0 : 1.0, 0.7);
    sd.body_a = b[1];
    sd.body_b = b[2];
    sd.stiffness = 2.0;
    sd.rest_length = 2.0;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "%s", "spring");
    if (mouse_spring) {
        sd.body_a = b[3];
        sd.body_b = LC_WORLD_ANCHOR;
        sd.point_a.x = 0.2;
        sd.point_a.y = 1.0;
        sd.point_b.x = 0.0;
        sd.point_b.y = 3.0;
        sd.rest_length = 0.0;
        CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "%s", "mouse spring");
    }
    CHECK(lc_body_add_default_thrusters(w, b[0], 1.5, NULL) == LC_OK, "%s", "thrusters");
    CHECK(lc_body_set_thruster_mask(w, b[0], 0x5u) == LC_OK, "%s", "thruster mask");
    if (ids) memcpy(ids, b, sizeof b);
    return w;
}

#endif /* LC_TESTS_SCENES_H */
