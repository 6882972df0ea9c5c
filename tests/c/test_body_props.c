/* test_body_props: a body's given moment of inertia and centre of mass, and the readers of every
 * settable body property (mass, inertia, material, external force, thruster levels and mask, stage
 * timing).
 *  - defaults: a zero inertia and no centre of mass keep the polygon's (uniform density) values;
 *  - a given inertia is kept exactly, lc_body_set_mass keeps the inertia per unit mass, and
 *    lc_body_set_inertia sets it (0: the polygon's again);
 *  - spin-up: an external torque tau turns a body of given inertia I at alpha = tau / I (closed-form
 *    free flight: omega and angle to round-off);
 *  - a given centre of mass is honoured everywhere: the state is that point, local vertices are about
 *    it, the default inertia is the polygon's about it (parallel axes), a free body turns about it
 *    (its vertices moving accordingly), a thruster at the frame origin turns the body by its lever
 *    arm, a spring attached there is attached to the centre of mass;
 *  - a physical pendulum (a box hung by a stiff spring at its geometric centre, centre of mass off
 *    it) swings with the period 2 pi sqrt((I + m d^2) / (m g d)) and hangs with its centre of mass
 *    below the pivot;
 *  - a box resting flat on a floor with its centre of mass off centre carries its weight on its two
 *    corners by the lever rule (event and automatic regimes); a leaning parallelogram stands or tips by where its centre of mass is;
 *  - energy: the seed's e = 1 walled box with blocks of given inertia and centre of mass keeps its
 *    energy to 1e-12 relative over 5 s;
 *  - errors: bad values, unknown ids and NULL outputs are refused with a message and the world
 *    unchanged. */
#include <string.h>
#include "check.h"
#include "scenes.h"

static lc_vec2 vec(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

/* A w x h box centred on its local origin, with an optional given inertia and centre of mass. */
static lc_body_id box_def(lc_world *w, double wd, double h, double x, double y, double angle, double mass,
                          double inertia, const lc_vec2 *com)
{
    lc_vec2 v[4];
    lc_body_def bd = lc_default_body_def();
    lc_make_rectangle(wd, h, v);
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.position = vec(x, y);
    bd.angle = angle;
    bd.mass = mass;
    bd.inertia = inertia;
    if (com) {
        bd.custom_center_of_mass = 1;
        bd.center_of_mass = *com;
    }
    return sc_add(w, &bd, "box");
}

static double get_inertia(const lc_world *w, lc_body_id id)
{
    double I = NAN;
    CHECK(lc_body_get_inertia(w, id, &I) == LC_OK, "get_inertia: %s", lc_world_last_error(w));
    return I;
}

static void defaults(void)
{
    lc_body_def d = lc_default_body_def();
    lc_world *w = sc_world(NULL);
    lc_body_id b, s;
    lc_vec2 off, f;
    double m, I, e, mu, tq, lvl;
    uint32_t mask;
    int on = -1, idx;
    lc_thruster_def td;
    CHECK(d.inertia == 0.0 && d.custom_center_of_mass == 0 && d.center_of_mass.x == 0.0 && d.center_of_mass.y == 0.0,
          "%s", "the default body def gives no inertia and no centre of mass");
    b = box_def(w, 1.0, 3.0, 2.0, 1.0, 0.3, 2.0, 0.0, NULL);
    s = sc_static_box(w, 4.0, 1.0, 0.0, -5.0, 0.5);
    CHECK(lc_body_get_mass(w, b, &m) == LC_OK && m == 2.0, "mass %g", m);
    CHECK_REL(get_inertia(w, b), 2.0 * (1.0 + 9.0) / 12.0, 1e-15, "box inertia m (w^2 + h^2) / 12");
    CHECK(get_inertia(w, b) == sc_inertia(w, b), "%s", "lc_body_get_inertia reads the state view's inertia");
    CHECK(lc_body_get_center_offset(w, b, &off) == LC_OK && fabs(off.x) < 1e-15 && fabs(off.y) < 1e-15,
          "centroid (%g, %g)", off.x, off.y);
    CHECK(lc_body_get_mass(w, s, &m) == LC_OK && m == 0.0, "static mass %g", m);
    CHECK(lc_body_get_inertia(w, s, &I) == LC_OK && I == 0.0, "static inertia %g", I);
    CHECK(lc_body_get_material(w, b, &e, &mu) == LC_OK && e == 1.0 && mu == 0.0, "material %g %g", e, mu);
    CHECK(lc_body_get_material(w, s, &e, &mu) == LC_OK && e == 0.5 && mu == 0.0, "static material %g %g", e, mu);
    CHECK(lc_body_set_material(w, b, 0.25, 0.75) == LC_OK, "%s", "set_material");
    CHECK(lc_body_get_material(w, b, &e, &mu) == LC_OK && e == 0.25 && mu == 0.75, "material read back %g %g", e, mu);
    CHECK(lc_world_set_elasticity(w, 0.125) == LC_OK, "%s", "world elasticity");
    CHECK(lc_body_get_material(w, s, &e, &mu) == LC_OK && e == 0.125, "world elasticity read back on a wall: %g", e);
    CHECK(lc_body_get_external(w, b, &f, &tq) == LC_OK && f.x == 0.0 && f.y == 0.0 && tq == 0.0, "%s", "no external");
    CHECK(lc_body_set_external(w, b, vec(1.5, -2.5), 0.25) == LC_OK, "%s", "set_external");
    CHECK(lc_body_get_external(w, b, &f, &tq) == LC_OK && f.x == 1.5 && f.y == -2.5 && tq == 0.25,
          "external read back (%g, %g) %g", f.x, f.y, tq);
    CHECK(lc_body_get_external(w, s, &f, &tq) == LC_OK && f.x == 0.0 && tq == 0.0, "%s", "a static body's is zero");
    CHECK(lc_body_add_default_thrusters(w, b, 1.5, &idx) == LC_OK && idx == 0, "%s", "thrusters");
    td.point = vec(0.0, 1.0);
    td.direction = vec(1.0, 0.0);
    td.magnitude = 2.0;
    CHECK(lc_body_add_thruster(w, b, &td, &idx) == LC_OK && idx == 4, "%s", "fifth thruster");
    CHECK(lc_body_get_thruster_mask(w, b, &mask) == LC_OK && mask == 0u, "mask 0x%x", (unsigned)mask);
    CHECK(lc_body_set_thruster_mask(w, b, 0x15u) == LC_OK, "%s", "set mask");
    CHECK(lc_body_get_thruster_mask(w, b, &mask) == LC_OK && mask == 0x15u, "mask read back 0x%x", (unsigned)mask);
    CHECK(lc_body_get_thruster_level(w, b, 2, &lvl) == LC_OK && lvl == 1.0, "level %g", lvl);
    CHECK(lc_body_get_thruster_level(w, b, 1, &lvl) == LC_OK && lvl == 0.0, "level %g", lvl);
    CHECK(lc_body_set_thruster_level(w, b, 1, 0.375) == LC_OK, "%s", "set level");
    CHECK(lc_body_get_thruster_level(w, b, 1, &lvl) == LC_OK && lvl == 0.375, "level read back %g", lvl);
    CHECK(lc_body_get_thruster_mask(w, b, &mask) == LC_OK && mask == 0x17u, "a partial level fires: 0x%x", (unsigned)mask);
    CHECK(lc_body_get_thruster_mask(w, s, &mask) == LC_OK && mask == 0u, "%s", "a static body has no thrusters");
    CHECK(lc_world_get_stage_timing(w, &on) == LC_OK && on == 0, "stage timing %d", on);
    CHECK(lc_world_set_stage_timing(w, 1) == LC_OK && lc_world_get_stage_timing(w, &on) == LC_OK && on == 1,
          "stage timing read back %d", on);
    lc_world_destroy(w);
}

/* A given inertia is the body's; lc_body_set_mass scales it, lc_body_set_inertia replaces it; an
 * external torque tau spins it up at tau / I. */
static void given_inertia(void)
{
    lc_world_def wd = sc_def_zero_g();
    lc_world *w = sc_world(&wd);
    const double I = 0.7, tau = 0.3, m = 2.0;
    lc_body_id b = box_def(w, 1.0, 3.0, 0.0, 0.0, 0.0, m, I, NULL);
    const double *s;
    lc_energy e;
    double I2;
    CHECK(get_inertia(w, b) == I, "given inertia kept exactly: %.17g", get_inertia(w, b));
    CHECK(lc_body_set_external(w, b, vec(0.0, 0.0), tau) == LC_OK, "%s", "torque");
    sc_step_n(w, 0.01, 100);
    s = sc_row(w, b);
    CHECK_REL(s[5], tau / I * 1.0, 1e-13, "omega = tau / I * t");
    CHECK_REL(s[2], 0.5 * tau / I * 1.0, 1e-13, "angle = tau / (2 I) t^2");
    CHECK_NEAR(s[0], 0.0, 1e-15, "the centre of mass stays");
    e = sc_energy(w);
    CHECK_REL(e.rotational, 0.5 * I * s[5] * s[5], 1e-15, "rotational energy I omega^2 / 2");
    /* double the inertia: the spin-up halves */
    CHECK(lc_body_set_inertia(w, b, 2.0 * I) == LC_OK, "set_inertia: %s", lc_world_last_error(w));
    CHECK(get_inertia(w, b) == 2.0 * I, "set inertia read back %.17g", get_inertia(w, b));
    sc_step_n(w, 0.01, 100);
    s = sc_row(w, b);
    CHECK_REL(s[5], tau / I + tau / (2.0 * I), 1e-13, "omega after the inertia doubled");
    /* the mass doubles: the inertia per unit mass is kept */
    CHECK(lc_body_set_mass(w, b, 2.0 * m) == LC_OK, "%s", "set_mass");
    CHECK_REL(get_inertia(w, b), 4.0 * I, 1e-15, "set_mass keeps the radius of gyration of a given inertia");
    /* 0: the polygon's again, and then set_mass scales that */
    CHECK(lc_body_set_inertia(w, b, 0.0) == LC_OK, "%s", "set_inertia(0)");
    CHECK_REL(get_inertia(w, b), 2.0 * m * 10.0 / 12.0, 1e-15, "set_inertia(0): the polygon's");
    CHECK(lc_body_set_mass(w, b, m) == LC_OK, "%s", "set_mass back");
    I2 = get_inertia(w, b);
    CHECK(I2 == m * 10.0 / 12.0 || fabs(I2 - m * 10.0 / 12.0) < 1e-15, "polygon's inertia for mass %g: %.17g", m, I2);
    lc_world_destroy(w);
}

/* A given centre of mass: the state, the vertices, the default inertia, free rotation, thrusters and
 * springs all refer to it. */
static void given_center(void)
{
    lc_world_def wd = sc_def_zero_g();
    lc_world *w = sc_world(&wd);
    const lc_vec2 com = {0.3, -0.2};
    const double m = 1.5, w0 = 0.8, x0 = 1.0, y0 = 2.0, a0 = 0.4, T = 2.0;
    lc_body_id b = box_def(w, 1.0, 1.0, x0, y0, a0, m, 0.0, &com), t;
    lc_vec2 off, loc[4], wv[4], rect[4], pa, pb;
    const double *s;
    int i, k;
    lc_thruster_def td;
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sp;
    double c = cos(a0), sn = sin(a0), alpha;
    lc_make_rectangle(1.0, 1.0, rect);
    CHECK(lc_body_get_center_offset(w, b, &off) == LC_OK && off.x == com.x && off.y == com.y,
          "centre of mass read back (%g, %g)", off.x, off.y);
    s = sc_row(w, b);
    CHECK_NEAR(s[0], x0 + c * com.x - sn * com.y, 1e-15, "state x is the given centre of mass");
    CHECK_NEAR(s[1], y0 + sn * com.x + c * com.y, 1e-15, "state y is the given centre of mass");
    CHECK(lc_body_get_local_vertices(w, b, loc, 4) == LC_OK, "%s", "local vertices");
    for (i = 0; i < 4; ++i) {
        CHECK_NEAR(loc[i].x, rect[i].x - com.x, 1e-15, "local vertex x about the centre of mass");
        CHECK_NEAR(loc[i].y, rect[i].y - com.y, 1e-15, "local vertex y about the centre of mass");
    }
    CHECK_REL(get_inertia(w, b), m * (1.0 / 6.0 + com.x * com.x + com.y * com.y), 1e-14,
              "default inertia: the polygon's about the given centre of mass (parallel axes)");
    /* free rotation about the centre of mass */
    CHECK(lc_body_set_velocity(w, b, vec(0.0, 0.0), w0) == LC_OK, "%s", "spin");
    sc_step_n(w, 0.01, (int)(T / 0.01 + 0.5));
    s = sc_row(w, b);
    CHECK_NEAR(s[0], x0 + c * com.x - sn * com.y, 1e-14, "the centre of mass stays (x)");
    CHECK_NEAR(s[1], y0 + sn * com.x + c * com.y, 1e-14, "the centre of mass stays (y)");
    CHECK_NEAR(s[2], a0 + w0 * T, 1e-13, "angle");
    CHECK(lc_body_get_world_vertices(w, b, wv, 4) == LC_OK, "%s", "world vertices");
    c = cos(a0 + w0 * T);
    sn = sin(a0 + w0 * T);
    for (i = 0; i < 4; ++i) {
        lc_vec2 r = vec(rect[i].x - com.x, rect[i].y - com.y);
        double ex = x0 + cos(a0) * com.x - sin(a0) * com.y + c * r.x - sn * r.y;
        double ey = y0 + sin(a0) * com.x + cos(a0) * com.y + sn * r.x + c * r.y;
        CHECK_NEAR(wv[i].x, ex, 1e-13, "a vertex turns about the centre of mass (x)");
        CHECK_NEAR(wv[i].y, ey, 1e-13, "a vertex turns about the centre of mass (y)");
    }
    /* a spring attached at the centre of mass (local frame) ends at the state's point */
    sd.body_a = b;
    sd.point_a = com;
    sd.point_b = vec(5.0, 5.0);
    sd.stiffness = 0.0;
    CHECK(lc_world_add_spring(w, &sd, &sp) == LC_OK, "%s", "spring");
    CHECK(lc_spring_get_endpoints(w, sp, &pa, &pb) == LC_OK, "%s", "endpoints");
    CHECK(pa.x == s[0] && pa.y == s[1], "spring at the centre of mass: (%.17g, %.17g) vs (%.17g, %.17g)", pa.x, pa.y,
          s[0], s[1]);
    lc_world_destroy(w);

    /* thrusters: through the centre of mass no turn; at the frame origin the lever arm -com turns it */
    for (k = 0; k < 2; ++k) {
        const double F = 2.0, h = 1e-4;
        w = sc_world(&wd);
        t = box_def(w, 1.0, 1.0, 0.0, 0.0, 0.0, m, 0.0, &com);
        td.point = k == 0 ? com : vec(0.0, 0.0);
        td.direction = vec(0.0, 1.0);
        td.magnitude = F;
        CHECK(lc_body_add_thruster(w, t, &td, NULL) == LC_OK, "%s", "thruster");
        CHECK(lc_body_set_thruster_level(w, t, 0, 1.0) == LC_OK, "%s", "fire");
        sc_step_n(w, h, 1);
        s = sc_row(w, t);
        alpha = k == 0 ? 0.0 : (-com.x * F) / get_inertia(w, t);   /* cross((-com.x, -com.y), (0, F)) / I */
        CHECK_NEAR(s[5], alpha * h, 1e-9 * fabs(alpha * h) + 1e-18, k == 0 ? "thruster through the centre of mass"
                                                                            : "thruster at the frame origin: tau = r x F");
        CHECK_REL(s[4], F / m * h, 1e-6, "thrust accelerates the centre of mass at F / m");
        lc_world_destroy(w);
    }
}

/* Zero crossings of a - a_eq, linearly interpolated, give the period of a box hung from a stiff
 * spring at its geometric centre with its centre of mass d below: a physical pendulum. */
static void pendulum(double inertia)
{
    lc_world_def wd = lc_default_world_def();
    lc_world *w;
    const double m = 1.0, d = 0.3, g = 9.81, k = 1e6, h = 2e-4, th0 = 0.02;
    const double a_eq = -SC_PI / 2.0;
    const lc_vec2 com = {d, 0.0};
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sp;
    lc_body_id b;
    double I, T, prev = th0, t_prev = 0.0, crossings[8];
    int n = 0, i;
    lc_vec2 pa, pb;
    const double *s;
    wd.gravity = vec(0.0, -g);
    w = sc_world(&wd);
    /* the frame origin (the attachment) at the anchor, sagged by the spring's static stretch */
    b = box_def(w, 1.0, 1.0, 0.0, -m * g / k, a_eq + th0, m, inertia, &com);
    I = get_inertia(w, b);
    sd.body_a = b;
    sd.point_a = vec(0.0, 0.0);
    sd.point_b = vec(0.0, 0.0);
    sd.stiffness = k;
    CHECK(lc_world_add_spring(w, &sd, &sp) == LC_OK, "%s", "pivot spring");
    T = 2.0 * SC_PI * sqrt((I + m * d * d) / (m * g * d)) * (1.0 + th0 * th0 / 16.0);
    for (i = 0; i < (int)(3.2 * T / h) && n < 6; ++i) {
        double a;
        if (lc_world_step(w, h) != LC_OK) {
            CHECK(0, "pendulum step: %s", lc_world_last_error(w));
            break;
        }
        a = sc_row(w, b)[2] - a_eq;
        if ((prev > 0.0) != (a > 0.0)) crossings[n++] = t_prev + h * prev / (prev - a);
        prev = a;
        t_prev = lc_world_get_time(w);
    }
    CHECK(n >= 6, "pendulum: %d zero crossings", n);
    if (n >= 6) {
        double period = (crossings[5] - crossings[1]) / 2.0;
        printf("pendulum I = %g (about the centre of mass): period %.9f s, analytic %.9f s (rel %.2e)\n", I, period, T,
               fabs(period - T) / T);
        CHECK_REL(period, T, 2e-4, "period 2 pi sqrt((I + m d^2) / (m g d))");
    }
    /* the pivot is where the spring holds it: at the anchor to the spring's stretch */
    CHECK(lc_spring_get_endpoints(w, sp, &pa, &pb) == LC_OK, "%s", "endpoints");
    CHECK_NEAR(hypot(pa.x, pa.y), 0.0, 3.0 * m * g / k, "the attachment stays at the anchor");
    lc_world_destroy(w);

    /* with damping the box comes to rest hanging with its centre of mass below the pivot */
    wd.damping = 2.0;
    wd.damping_rotation_ratio = 0.5;
    w = sc_world(&wd);
    b = box_def(w, 1.0, 1.0, 0.0, 0.0, 0.0, m, inertia, &com);
    sd.body_a = b;
    sd.stiffness = 1e4;
    sd.damping = 50.0;
    CHECK(lc_world_add_spring(w, &sd, &sp) == LC_OK, "%s", "pivot spring");
    sc_step_n(w, 1e-3, 20000);
    s = sc_row(w, b);
    CHECK_NEAR(s[0], 0.0, 1e-6, "at rest the centre of mass is below the pivot (x)");
    CHECK_NEAR(s[1], -d - m * g / 1e4, 1e-6, "at rest the centre of mass is d below the pivot, with the sag (y)");
    CHECK_NEAR(remainder(s[2] - a_eq, 2.0 * SC_PI), 0.0, 1e-6, "at rest the box hangs turned by -pi/2");
    lc_world_destroy(w);
}

/* A 1 m box resting flat on a floor with its centre of mass x_c off centre: its corners carry
 * m g (1/2 -+ x_c) (lever rule); a leaning parallelogram stands when its centre of mass is above its
 * base and tips when it is beyond it. */
static void resting_and_tipping(lc_regime regime)
{
    lc_world_def wd = lc_default_world_def();
    lc_world *w;
    const double m = 2.0, g = 9.81, xc = 0.4;
    const lc_vec2 com = {xc, 0.1};
    const lc_vec2 para[4] = {{0.0, 0.0}, {1.0, 0.0}, {2.0, 1.0}, {1.0, 1.0}};
    const lc_contact *c;
    lc_body_id b;
    double left = 0.0, right = 0.0;
    int n, i, k;
    wd.regime = regime;
    w = sc_world(&wd);
    sc_static_box(w, 20.0, 1.0, 0.0, -0.5, 0.0);
    b = box_def(w, 1.0, 1.0, 0.0, 0.5 + 1e-7, 0.0, m, 0.0, &com);
    lc_body_set_material(w, b, 0.0, 0.8);
    sc_step_n(w, 0.01, 100);
    n = sc_contacts(w, &c);
    for (i = 0; i < n; ++i) {
        if (c[i].kind != LC_CONTACT_RESTING) continue;
        if (c[i].point.x < 0.0) left += c[i].force;
        else right += c[i].force;
    }
    printf("regime %d: resting corners carry %.12g N (left) and %.12g N (right)\n", (int)regime, left, right);
    CHECK_REL(left, m * g * (0.5 - xc), 1e-9, "left corner: m g (1/2 - x_c)");
    CHECK_REL(right, m * g * (0.5 + xc), 1e-9, "right corner: m g (1/2 + x_c)");
    CHECK_NEAR(sc_row(w, b)[2], 0.0, 1e-9, "the box rests flat");
    CHECK_NEAR(sc_row(w, b)[0], xc, 1e-9, "and does not move");
    lc_world_destroy(w);

    for (k = 0; k < 2; ++k) {
        lc_body_def bd = lc_default_body_def();
        lc_body_id p;
        double a;
        w = sc_world(&wd);
        sc_static_box(w, 20.0, 1.0, 0.0, -0.5, 0.0);
        bd.vertices = para;
        bd.vertex_count = 4;
        bd.position = vec(0.0, 1e-7);
        bd.mass = m;
        bd.elasticity = 0.0;
        bd.friction = 1.0;
        bd.custom_center_of_mass = 1;
        bd.center_of_mass = vec(k == 0 ? 0.7 : 1.3, 0.5);   /* above the base [0, 1], or beyond it */
        p = sc_add(w, &bd, "parallelogram");
        sc_step_n(w, 0.01, 100);
        a = sc_row(w, p)[2];
        if (k == 0) CHECK_NEAR(a, 0.0, 1e-9, "a centre of mass above the base: it stands");
        else CHECK(a < -0.3, "a centre of mass beyond the base: it tips clockwise (angle %g after 1 s)", a);
        lc_world_destroy(w);
    }
}

/* The seed's scene (walled box, e = 1, no friction, g = 0) with blocks of given inertia and centre of
 * mass: the total energy is kept to 1e-12 relative over 5 s. */
static void energy_seed_like(double gy)
{
    lc_world_def wd = lc_default_world_def();
    lc_world *w;
    const lc_vec2 com1 = {0.2, -0.9}, com3 = {-0.1, 0.4};
    lc_body_id b[3];
    double e0, worst = 0.0;
    int i;
    lc_counters tot;
    wd.gravity = vec(0.0, gy);
    wd.zero_energy_level = -6.0;
    w = sc_world(&wd);
    lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 1.0, NULL);
    b[0] = box_def(w, 1.0, 3.0, -2.5, 0.0, 0.0, 1.0, 0.4, &com1);
    b[1] = box_def(w, 1.0, 3.0, 2.5, 0.0, 0.0, 2.0, 3.5, NULL);
    b[2] = box_def(w, 3.0, 1.0, 0.0, 3.5, 0.3, 0.7, 0.0, &com3);
    lc_body_set_velocity(w, b[0], vec(3.0, 1.0), 2.0);
    lc_body_set_velocity(w, b[1], vec(-2.0, 2.5), -1.5);
    lc_body_set_velocity(w, b[2], vec(1.0, -3.0), 3.0);
    e0 = sc_energy(w).total;
    for (i = 0; i < 500; ++i) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        worst = fmax(worst, fabs(sc_energy(w).total - e0) / e0);
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("seed-like e = 1, g = %g, given inertia and centre of mass: %llu collisions in 5 s, worst relative "
           "energy drift %.2e\n", gy, (unsigned long long)tot.collisions, worst);
    CHECK(tot.collisions >= 10, "the blocks collide (%llu collisions)", (unsigned long long)tot.collisions);
    CHECK(worst <= 1e-12, "relative energy drift %.3e > 1e-12", worst);
    lc_world_destroy(w);
}

/* ---- errors: status, message, world unchanged ---- */

static void expect_fail(lc_world *w, lc_status got, lc_status want, const char *word, const char *what,
                        uint64_t hash_before)
{
    const char *msg = lc_world_last_error(w);
    CHECK(got == want, "%s: %s, expected %s (%s)", what, lc_status_string(got), lc_status_string(want), msg);
    CHECK(msg[0] != '\0' && strstr(msg, word) != NULL, "%s: message \"%s\" lacks \"%s\"", what, msg, word);
    CHECK(lc_world_state_hash(w) == hash_before, "%s: the world changed", what);
}

#define FAILS(call, want, word)                                              \
    do {                                                                     \
        uint64_t h_ = lc_world_state_hash(w);                                \
        int n_ = lc_world_body_count(w);                                     \
        expect_fail(w, (call), (want), (word), #call, h_);                   \
        CHECK(lc_world_body_count(w) == n_, "%s added a body", #call);       \
    } while (0)

static void errors(void)
{
    lc_world *w = sc_world(NULL);
    const lc_body_id bad = 4242u;
    lc_vec2 v[4], f;
    lc_body_def bd = lc_default_body_def();
    lc_body_id b, s, out;
    double x, y, I0;
    uint32_t mask;
    int on;
    const double nan = NAN;
    lc_make_rectangle(1.0, 1.0, v);
    b = box_def(w, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, NULL);
    s = sc_static_box(w, 4.0, 1.0, 0.0, -5.0, 1.0);
    I0 = get_inertia(w, b);
    /* readers: unknown body, NULL outputs, NULL world */
    FAILS(lc_body_get_mass(w, bad, &x), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_mass(w, b, NULL), LC_ERR_NULL, "out");
    FAILS(lc_body_get_inertia(w, bad, &x), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_inertia(w, b, NULL), LC_ERR_NULL, "out");
    FAILS(lc_body_get_material(w, bad, &x, &y), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_material(w, b, NULL, &y), LC_ERR_NULL, "elasticity");
    FAILS(lc_body_get_material(w, b, &x, NULL), LC_ERR_NULL, "friction");
    FAILS(lc_body_get_external(w, bad, &f, &x), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_external(w, b, NULL, &x), LC_ERR_NULL, "force");
    FAILS(lc_body_get_external(w, b, &f, NULL), LC_ERR_NULL, "torque");
    FAILS(lc_body_get_thruster_level(w, bad, 0, &x), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_thruster_level(w, b, 0, &x), LC_ERR_UNKNOWN_THRUSTER, "thruster 0");
    FAILS(lc_body_get_thruster_level(w, b, -1, &x), LC_ERR_UNKNOWN_THRUSTER, "thruster -1");
    FAILS(lc_body_get_thruster_level(w, b, 0, NULL), LC_ERR_NULL, "out");
    FAILS(lc_body_get_thruster_mask(w, bad, &mask), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_get_thruster_mask(w, b, NULL), LC_ERR_NULL, "out");
    FAILS(lc_world_get_stage_timing(w, NULL), LC_ERR_NULL, "out");
    CHECK(lc_body_get_mass(NULL, b, &x) == LC_ERR_NULL && lc_body_get_inertia(NULL, b, &x) == LC_ERR_NULL &&
          lc_body_get_material(NULL, b, &x, &y) == LC_ERR_NULL && lc_body_get_external(NULL, b, &f, &x) == LC_ERR_NULL &&
          lc_body_get_thruster_level(NULL, b, 0, &x) == LC_ERR_NULL &&
          lc_body_get_thruster_mask(NULL, b, &mask) == LC_ERR_NULL && lc_world_get_stage_timing(NULL, &on) == LC_ERR_NULL &&
          lc_body_set_inertia(NULL, b, 1.0) == LC_ERR_NULL, "%s", "a NULL world is LC_ERR_NULL");
    /* lc_body_set_inertia: the inertia is unchanged by each refusal */
    FAILS(lc_body_set_inertia(w, bad, 0.1), LC_ERR_UNKNOWN_BODY, "4242");
    FAILS(lc_body_set_inertia(w, s, 0.1), LC_ERR_STATIC_BODY, "static");
    FAILS(lc_body_set_inertia(w, b, nan), LC_ERR_NOT_FINITE, "inertia");
    FAILS(lc_body_set_inertia(w, b, INFINITY), LC_ERR_NOT_FINITE, "inertia");
    FAILS(lc_body_set_inertia(w, b, -0.1), LC_ERR_OUT_OF_RANGE, "inertia");
    FAILS(lc_body_set_inertia(w, b, 1e-320), LC_ERR_OUT_OF_RANGE, "inertia");
    FAILS(lc_body_set_inertia(w, b, 0.5 + 1e-12), LC_ERR_OUT_OF_RANGE, "mass * r^2");   /* 1 kg, r^2 = 1/2 */
    CHECK(get_inertia(w, b) == I0, "refused set_inertia left the inertia %.17g", get_inertia(w, b));
    CHECK(lc_body_set_inertia(w, b, 0.5) == LC_OK && lc_world_last_error(w)[0] == '\0', "%s", "mass * r^2 itself is allowed");
    /* lc_world_add_body with a bad inertia or centre of mass */
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.inertia = nan;
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_NOT_FINITE, "inertia");
    bd.inertia = -1.0;
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_OUT_OF_RANGE, "inertia");
    bd.inertia = 0.51;
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_OUT_OF_RANGE, "mass * r^2");
    bd.inertia = 0.0;
    bd.custom_center_of_mass = 2;
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_OUT_OF_RANGE, "custom_center_of_mass");
    bd.custom_center_of_mass = 1;
    bd.center_of_mass = vec(nan, 0.0);
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_NOT_FINITE, "center_of_mass");
    bd.center_of_mass = vec(0.0, -0.5 - 1e-6);
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_OUT_OF_RANGE, "outside the polygon");
    bd.center_of_mass = vec(0.6, 0.0);
    FAILS(lc_world_add_body(w, &bd, &out), LC_ERR_OUT_OF_RANGE, "outside the polygon");
    /* the boundary is inside; a static body ignores the inertia as it does the mass */
    bd.center_of_mass = vec(0.5, 0.5);
    bd.position = vec(3.0, 3.0);
    CHECK(lc_world_add_body(w, &bd, &out) == LC_OK, "a centre of mass at a corner: %s", lc_world_last_error(w));
    bd.type = LC_BODY_STATIC;
    bd.inertia = -5.0;
    bd.position = vec(-3.0, 3.0);
    CHECK(lc_world_add_body(w, &bd, &out) == LC_OK, "a static body ignores inertia: %s", lc_world_last_error(w));
    CHECK(lc_body_get_center_offset(w, out, &f) == LC_OK && f.x == 0.5 && f.y == 0.5, "%s", "a static body's centre of mass");
    lc_world_destroy(w);
}

int main(void)
{
    defaults();
    given_inertia();
    given_center();
    pendulum(0.05);
    pendulum(0.0);
    resting_and_tipping(LC_REGIME_EVENT);
    resting_and_tipping(LC_REGIME_AUTO);
    energy_seed_like(0.0);
    energy_seed_like(-9.81);
    errors();
    return CHECK_SUMMARY("test_body_props");
}
