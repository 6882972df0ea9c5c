/* test_forces: thrusters (explicit points/directions, levels, mask, a body whose centre of mass is
 * off its local origin, and the default set), spring oscillation periods, exponential damping, and
 * a constant external force and torque, each against closed forms. g = 0 unless stated. */
#include "check.h"
#include "scenes.h"

/* Measured acceleration over one short step from rest. During a step of dt the body turns by
 * alpha dt^2 / 2, so a body-fixed force turns by that much and the mean acceleration differs from
 * the initial one by ~alpha dt^2 / 6 relative (alpha <= 2 rad/s^2, dt = 1e-4 -> 3e-9); round-off of
 * dv / dt with dv ~ 1e-4 m/s is ~1e-12 relative. Tolerance 1e-6 relative on the acceleration.
 * The torque of a body-fixed force about the centre of mass is constant, so omega = alpha dt
 * exactly: tolerance 1e-9 relative. */
#define SHORT_DT 1e-4

static void measure(lc_world *w, lc_body_id id, double *ax, double *ay, double *alpha)
{
    const double *s0 = sc_row(w, id);
    double vx0 = s0[3], vy0 = s0[4], w0 = s0[5];
    const double *s;
    sc_step_n(w, SHORT_DT, 1);
    s = sc_row(w, id);
    *ax = (s[3] - vx0) / SHORT_DT;
    *ay = (s[4] - vy0) / SHORT_DT;
    *alpha = (s[5] - w0) / SHORT_DT;
}

static void reset_body(lc_world *w, lc_body_id id, double x, double y, double angle)
{
    lc_vec2 c = {x, y}, z = {0, 0};
    CHECK(lc_body_set_pose(w, id, c, angle) == LC_OK, "%s", "set_pose");
    CHECK(lc_body_set_velocity(w, id, z, 0.0) == LC_OK, "%s", "set_velocity");
}

static void thrusters_explicit(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id id, tri;
    lc_thruster_def td;
    int idx = -1, idx2 = -1, idx3 = -1;
    const double m = 2.0, th = 0.5, I = m * (4.0 + 1.0) / 12.0; /* 2 x 1 box */
    double ax, ay, al, fx, fy, tau;
    const lc_vec2 tv[3] = {{0, 0}, {3, 0}, {0, 3}};
    if (!w) return;
    id = sc_box(w, 2.0, 1.0, 1.0, -1.0, th, 0, 0, 0, m, 1.0);
    /* Thruster at body point (0.5, 0.3), direction (0, 2) (normalised to (0, 1)), 3 N. */
    td.point.x = 0.5;
    td.point.y = 0.3;
    td.direction.x = 0.0;
    td.direction.y = 2.0;
    td.magnitude = 3.0;
    CHECK(lc_body_add_thruster(w, id, &td, &idx) == LC_OK, "add_thruster: %s", lc_world_last_error(w));
    CHECK(idx == 0, "first thruster index %d", idx);
    CHECK(lc_body_thruster_count(w, id) == 1, "%s", "thruster count 1");
    /* World force = 3 R(th) (0,1) = 3 (-sin th, cos th); torque = p x d * 3 = 0.5 * 3 = 1.5 N m. */
    fx = -3.0 * sin(th);
    fy = 3.0 * cos(th);
    tau = 1.5;
    /* Off: no acceleration at all (exactly 0). */
    measure(w, id, &ax, &ay, &al);
    CHECK(ax == 0.0 && ay == 0.0 && al == 0.0, "thruster off: a = (%g, %g), alpha %g", ax, ay, al);
    reset_body(w, id, 1.0, -1.0, th);
    CHECK(lc_body_set_thruster_level(w, id, idx, 1.0) == LC_OK, "%s", "set level 1");
    measure(w, id, &ax, &ay, &al);
    CHECK_REL(ax, fx / m, 1e-6, "thruster ax = Fx/m");
    CHECK_REL(ay, fy / m, 1e-6, "thruster ay = Fy/m");
    CHECK_REL(al, tau / I, 1e-9, "thruster alpha = (p x F)/I");
    /* Level 0.5 halves everything. */
    reset_body(w, id, 1.0, -1.0, th);
    CHECK(lc_body_set_thruster_level(w, id, idx, 0.5) == LC_OK, "%s", "set level 0.5");
    measure(w, id, &ax, &ay, &al);
    CHECK_REL(ax, 0.5 * fx / m, 1e-6, "half level ax");
    CHECK_REL(ay, 0.5 * fy / m, 1e-6, "half level ay");
    CHECK_REL(al, 0.5 * tau / I, 1e-9, "half level alpha");
    /* Second thruster at (-1, -0.5) pointing (1, 0), 2 N: torque p x d = -1*0 - (-0.5)(2) = 1.0.
     * Third at (0, 0) pointing (-1, 0), 2 N: cancels the second's force, no torque.
     * Mask 0b011 -> thrusters 0 and 1 at level 1. */
    td.point.x = -1.0; td.point.y = -0.5; td.direction.x = 1.0; td.direction.y = 0.0; td.magnitude = 2.0;
    CHECK(lc_body_add_thruster(w, id, &td, &idx2) == LC_OK && idx2 == 1, "second thruster index %d", idx2);
    td.point.x = 0.0; td.point.y = 0.0; td.direction.x = -1.0; td.direction.y = 0.0;
    CHECK(lc_body_add_thruster(w, id, &td, &idx3) == LC_OK && idx3 == 2, "third thruster index %d", idx3);
    reset_body(w, id, 1.0, -1.0, th);
    CHECK(lc_body_set_thruster_mask(w, id, 0x3u) == LC_OK, "%s", "mask 3");
    measure(w, id, &ax, &ay, &al);
    CHECK_REL(ax, (fx + 2.0 * cos(th)) / m, 1e-6, "two thrusters ax");
    CHECK_REL(ay, (fy + 2.0 * sin(th)) / m, 1e-6, "two thrusters ay");
    CHECK_REL(al, (tau + 1.0) / I, 1e-9, "two thrusters alpha");
    reset_body(w, id, 1.0, -1.0, th);
    CHECK(lc_body_set_thruster_mask(w, id, 0x6u) == LC_OK, "%s", "mask 6");
    measure(w, id, &ax, &ay, &al);
    CHECK_NEAR(ax, 0.0, 1e-9, "opposed thrusters: no net force x (round-off of 2 N - 2 N)");
    CHECK_NEAR(ay, 0.0, 1e-9, "opposed thrusters: no net force y");
    CHECK_REL(al, 1.0 / I, 1e-9, "opposed thrusters: pure couple 1 N m");

    /* Triangle (0,0), (3,0), (0,3): centre of mass at (1,1) of the local frame, m = 1, I = 1.
     * Thruster at the local origin pointing +x, 2 N: r = (-1,-1), torque = -ry*Fx = 2 N m. */
    tri = sc_poly(w, tv, 3, 5.0, 5.0, 0.0, 1.0);
    td.point.x = 0.0; td.point.y = 0.0; td.direction.x = 1.0; td.direction.y = 0.0; td.magnitude = 2.0;
    CHECK(lc_body_add_thruster(w, tri, &td, &idx) == LC_OK, "%s", "triangle thruster");
    CHECK(lc_body_set_thruster_level(w, tri, idx, 1.0) == LC_OK, "%s", "triangle level");
    measure(w, tri, &ax, &ay, &al);
    CHECK_REL(ax, 2.0, 1e-6, "triangle ax = 2 N / 1 kg");
    CHECK_NEAR(ay, 0.0, 2e-6 * 2.0, "triangle ay (only the turn during the step: alpha dt^2/2 * |a|)");
    CHECK_REL(al, 2.0, 1e-9, "triangle alpha = torque about the centre of mass (point is local-frame)");
    lc_world_destroy(w);
}

/* Default set: 4 thrusters; 0 pushes the block to -x (left), 1 to +x (right), 2 to +y (up),
 * 3 to -y (down) in the body frame; the side ones act above the centre, so left turns the block
 * counter-clockwise (r = (0, +h), F = (-f, 0): torque = -h * (-f) > 0) and right clockwise.
 * "Sideways" components must vanish to the turn during the step (alpha dt^2 ~ 1e-8 relative):
 * tolerance 1e-6 of the main component. */
static void thrusters_default(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id id;
    int first = -1, i;
    double ax, ay, al;
    if (!w) return;
    id = sc_box(w, 1.0, 3.0, 0.0, 0.0, 0.0, 0, 0, 0, 1.0, 1.0);
    CHECK(lc_body_add_default_thrusters(w, id, 1.5, &first) == LC_OK, "default thrusters: %s",
          lc_world_last_error(w));
    CHECK(first == 0, "first index %d", first);
    CHECK(lc_body_thruster_count(w, id) == 4, "default thruster count %d", lc_body_thruster_count(w, id));
    for (i = 0; i < 4; i++) {
        reset_body(w, id, 0.0, 0.0, 0.0);
        CHECK(lc_body_set_thruster_mask(w, id, 1u << i) == LC_OK, "%s", "mask");
        measure(w, id, &ax, &ay, &al);
        printf("default thruster %d: a = (%.6g, %.6g) m/s^2, alpha = %.6g rad/s^2\n", i, ax, ay, al);
        switch (i) {
        case 0:
            CHECK(ax < 0 && fabs(ay) <= 1e-6 * fabs(ax), "left thruster a = (%g, %g)", ax, ay);
            CHECK(al > 0, "left thruster above the centre turns counter-clockwise, alpha %g", al);
            break;
        case 1:
            CHECK(ax > 0 && fabs(ay) <= 1e-6 * fabs(ax), "right thruster a = (%g, %g)", ax, ay);
            CHECK(al < 0, "right thruster above the centre turns clockwise, alpha %g", al);
            break;
        case 2:
            CHECK(ay > 0 && fabs(ax) <= 1e-6 * fabs(ay), "up thruster a = (%g, %g)", ax, ay);
            break;
        default:
            CHECK(ay < 0 && fabs(ax) <= 1e-6 * fabs(ay), "down thruster a = (%g, %g)", ax, ay);
            break;
        }
    }
    lc_world_destroy(w);
}

/* Root in [t0, t1] of the cubic Hermite interpolant of (x0, v0), (x1, v1) (sign change assumed).
 * Its error is x'''' dt^4 / 384 ~ w^4 dt^4 / 384 * amplitude ~ 1e-10 m for w^2 = 2.5, dt = 0.01,
 * i.e. ~1e-10 s in time at the crossing speed ~1.6 m/s. */
static double hermite_root(double t0, double t1, double x0, double v0, double x1, double v1)
{
    double h = t1 - t0, lo = 0.0, hi = 1.0, flo;
    int it;
    flo = x0;
    for (it = 0; it < 200; it++) {
        double s = 0.5 * (lo + hi), s2 = s * s, s3 = s2 * s;
        double f = (2 * s3 - 3 * s2 + 1) * x0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * x1 +
                   (s3 - s2) * h * v1;
        if ((f < 0) == (flo < 0)) { lo = s; flo = f; } else hi = s;
    }
    return t0 + 0.5 * (lo + hi) * h;
}

/* Spring period. Zero crossings of the stretch, interpolated with the cubic Hermite on the step's
 * end values (positions and velocities); period = 2 (t_last - t_first) / (crossings - 1).
 * RK4 phase error per step ~ (w dt)^5 / 120 ~ 1e-11 rad, ~1e-8 rad over 2000 steps: far below the
 * 1e-6 relative tolerance, which the interpolation (1e-10 s) also respects. */
static void spring_period(int two_body)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    lc_body_id a, b = 0;
    const double k = 5.0;
    double mu, T, prev_x = 0, prev_v = 0, prev_t = 0, t_first = -1, t_last = -1, e0, max_de = 0;
    int n_cross = 0, i;
    if (!w) return;
    if (!two_body) {
        /* m = 2 kg on a world anchor at the origin, rest length 0, released at x = 1 m. */
        a = sc_box(w, 0.5, 0.5, 1.0, 0.0, 0.0, 0, 0, 0, 2.0, 1.0);
        sd.body_a = a;
        sd.body_b = LC_WORLD_ANCHOR;
        mu = 2.0;
    } else {
        /* 1 kg and 3 kg joined centre to centre, rest length 2 m, released 3 m apart:
         * reduced mass mu = 1*3/4 = 0.75 kg; the closest approach (1 m) keeps the 0.5 m boxes apart. */
        a = sc_box(w, 0.5, 0.5, -1.5, 0.0, 0.0, 0, 0, 0, 1.0, 1.0);
        b = sc_box(w, 0.5, 0.5, 1.5, 0.0, 0.0, 0, 0, 0, 3.0, 1.0);
        sd.body_a = a;
        sd.body_b = b;
        sd.rest_length = 2.0;
        mu = 0.75;
    }
    sd.stiffness = k;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "add_spring: %s", lc_world_last_error(w));
    T = 2.0 * SC_PI * sqrt(mu / k);
    /* spring energy k stretch^2 / 2 (stretch 1 m at release): exact, round-off 1e-14 */
    CHECK_REL(sc_energy(w).spring, 0.5 * k * 1.0, 1e-14, "spring potential energy k stretch^2/2");
    e0 = sc_energy(w).total;
    for (i = 0; i <= 2000; i++) {
        const double *sa = sc_row(w, a);
        double x, v, t = lc_world_get_time(w);
        if (!two_body) {
            x = sa[0];
            v = sa[3];
        } else {
            const double *sb = sc_row(w, b);
            x = (sb[0] - sa[0]) - 2.0;
            v = sb[3] - sa[3];
        }
        if (i > 0 && ((prev_x < 0) != (x < 0))) {
            double tc = hermite_root(prev_t, t, prev_x, prev_v, x, v);
            if (t_first < 0) t_first = tc;
            t_last = tc;
            n_cross++;
        }
        prev_x = x; prev_v = v; prev_t = t;
        if (fabs(sc_energy(w).total - e0) > max_de) max_de = fabs(sc_energy(w).total - e0);
        if (i < 2000 && sc_step_n(w, 0.01, 1) != 1) break;
    }
    CHECK(n_cross >= 5, "spring crossed zero %d times in 20 s", n_cross);
    /* RK4 energy drift for an oscillator: ~ (w dt)^6 / 144 per step ~ 1e-13 relative, times 2000
     * steps: 1e-10; tolerance 1e-8 relative of the 2.5 J */
    CHECK_NEAR(max_de, 0.0, 1e-8 * e0, "spring oscillator energy (kinetic + spring) conserved");
    if (n_cross >= 2) {
        double Tm = 2.0 * (t_last - t_first) / (n_cross - 1);
        printf("spring (%s): period %.12f s, expected 2 pi sqrt(m/k) = %.12f s, rel err %.2e\n",
               two_body ? "two bodies" : "world anchor", Tm, T, fabs(Tm - T) / T);
        CHECK_REL(Tm, T, 1e-6, two_body ? "two-body spring period 2 pi sqrt(mu/k)" : "spring period 2 pi sqrt(m/k)");
    }
    lc_world_destroy(w);
}

/* Damping k = 0.7 N s/m, rotation ratio r = 0.2 m^2, m = 2 kg, 1 x 2 box (I = 5/6 kg m^2):
 * v(t) = v0 e^{-k t/m}, x(t) = x0 + v0 (m/k)(1 - e^{-k t/m}), omega = w0 e^{-k r t / I}.
 * RK4 relative error per step (lam dt)^5/120 ~ 5e-15, times 500 steps ~ 3e-12; tolerance 1e-9
 * relative (absolute 1e-9 * scale for positions, scale = |v0| m / k). */
static void damping(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_body_id id;
    const double k = 0.7, r = 0.2, m = 2.0, I = 2.0 * 5.0 / 12.0, vx0 = 3.0, vy0 = -1.0, w0 = 2.0;
    int sec;
    d.damping = k;
    d.damping_rotation_ratio = r;
    w = sc_world(&d);
    if (!w) return;
    id = sc_box(w, 1.0, 2.0, 0.5, 0.25, 0.1, vx0, vy0, w0, m, 1.0);
    for (sec = 1; sec <= 5; sec++) {
        const double *s;
        double t, e, er;
        sc_step_n(w, 0.01, 100);
        s = sc_row(w, id);
        t = lc_world_get_time(w);
        e = exp(-k * t / m);
        er = exp(-k * r * t / I);
        CHECK_REL(s[3], vx0 * e, 1e-9, "damped vx = v0 exp(-k t/m)");
        CHECK_REL(s[4], vy0 * e, 1e-9, "damped vy = v0 exp(-k t/m)");
        CHECK_REL(s[5], w0 * er, 1e-9, "damped omega = w0 exp(-k r t/I)");
        CHECK_NEAR(s[0], 0.5 + vx0 * m / k * (1 - e), 1e-9 * fabs(vx0) * m / k, "damped x");
        CHECK_NEAR(s[1], 0.25 + vy0 * m / k * (1 - e), 1e-9 * fabs(vx0) * m / k, "damped y");
        CHECK_NEAR(s[2], 0.1 + w0 * I / (k * r) * (1 - er), 1e-9 * w0 * I / (k * r), "damped angle");
    }
    lc_world_destroy(w);
}

/* External force (2, -1) N and torque 0.5 N m on a 2 kg 1 x 2 box (I = 5/6), with gravity 9.81:
 * a = F/m + g, alpha = tau/I, both constant -> polynomials that RK4 integrates exactly; round-off
 * over 100 steps at scale 10 m ~ 1e-13; tolerance 1e-11. */
static void external(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_body_id id;
    lc_vec2 f = {2.0, -1.0};
    const double m = 2.0, I = 2.0 * 5.0 / 12.0, tau = 0.5, g = 9.81;
    const double *s;
    double t, ax, ay, al;
    if (!w) return;
    id = sc_box(w, 1.0, 2.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, m, 1.0);
    CHECK(lc_body_set_external(w, id, f, tau) == LC_OK, "set_external: %s", lc_world_last_error(w));
    sc_step_n(w, 0.01, 100);
    s = sc_row(w, id);
    t = lc_world_get_time(w);
    ax = f.x / m;
    ay = f.y / m - g;
    al = tau / I;
    CHECK_NEAR(s[3], 1.0 + ax * t, 1e-11, "external vx");
    CHECK_NEAR(s[4], ay * t, 1e-11, "external vy");
    CHECK_NEAR(s[5], al * t, 1e-11, "external omega");
    CHECK_NEAR(s[0], t + 0.5 * ax * t * t, 1e-11, "external x");
    CHECK_NEAR(s[1], 0.5 * ay * t * t, 1e-11, "external y");
    CHECK_NEAR(s[2], 0.5 * al * t * t, 1e-11, "external angle");
    lc_world_destroy(w);
}

int main(void)
{
    thrusters_explicit();
    thrusters_default();
    spring_period(0);
    spring_period(1);
    damping();
    external();
    return CHECK_SUMMARY("test_forces");
}
