/* test_free_flight: (1) free flight under constant gravity, with spin, against the analytic
 * parabola; (2) the measured order of accuracy of EULER, MIDPOINT and RK4 on a damped body pulled
 * by a zero-rest-length spring (a linear ODE with a closed-form solution). */
#include "check.h"
#include "scenes.h"

/* (1) A 1 x 2 block thrown with v0 = (3, 4) m/s, omega0 = 2 rad/s, in g = (0, -9.81), no walls.
 * x(t) = x0 + vx t, y(t) = y0 + vy t - g t^2/2, angle(t) = a0 + w t, vy(t) = vy - g t.
 * RK4 integrates polynomials of degree <= 4 exactly (and the engine may advance free flight in
 * closed form), so the only error is round-off: ~1e-16 * scale (|y| <= 20 m, |v| <= 20 m/s)
 * per step * 400 steps ~ 1e-12; tolerance 1e-10 (m, m/s, rad). */
static void parabola(lc_integrator integ)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id id;
    const double x0 = -1.0, y0 = 2.0, a0 = 0.3, vx = 3.0, vy = 4.0, om = 2.0, g = 9.81;
    int k;
    double maxerr_p = 0, maxerr_v = 0, maxerr_a = 0, e0, max_de = 0;
    const double m = 1.5, I = 1.5 * 5.0 / 12.0, zel = 0.5;
    d.integrator = integ;
    d.zero_energy_level = zel;
    w = sc_world(&d);
    if (!w) return;
    id = sc_box(w, 1.0, 2.0, x0, y0, a0, vx, vy, om, m, 1.0);
    /* Energy split (exact formulas, round-off only: 1e-12 relative): translational m|v|^2/2,
     * rotational I w^2/2, gravitational m g (y - zero_energy_level). */
    {
        lc_energy en = sc_energy(w);
        CHECK_REL(en.translational, 0.5 * m * (vx * vx + vy * vy), 1e-12, "translational energy m|v|^2/2");
        CHECK_REL(en.rotational, 0.5 * I * om * om, 1e-12, "rotational energy I w^2/2");
        CHECK_REL(en.gravitational, m * g * (y0 - zel), 1e-12, "gravitational energy m g (y - zero level)");
        CHECK_REL(en.total, en.translational + en.rotational + en.gravitational, 1e-12, "total = sum of parts");
        CHECK_REL(en.linear_momentum.x, m * vx, 1e-12, "linear momentum x");
        CHECK_REL(en.angular_momentum, m * (x0 * vy - y0 * vx) + I * om, 1e-12, "angular momentum about the origin");
        e0 = en.total;
    }
    for (k = 0; k < 400; k++) {
        const double *s;
        double t, ex, ey, ea, evx, evy;
        if (sc_step_n(w, 0.005, 1) != 1) break;
        s = sc_row(w, id);
        t = lc_world_get_time(w);
        ex = fabs(s[0] - (x0 + vx * t));
        ey = fabs(s[1] - (y0 + vy * t - 0.5 * g * t * t));
        ea = fabs(s[2] - (a0 + om * t));
        evx = fabs(s[3] - vx);
        evy = fabs(s[4] - (vy - g * t));
        if (ex > maxerr_p) maxerr_p = ex;
        if (ey > maxerr_p) maxerr_p = ey;
        if (ea > maxerr_a) maxerr_a = ea;
        if (evx > maxerr_v) maxerr_v = evx;
        if (evy > maxerr_v) maxerr_v = evy;
        if (fabs(s[5] - om) > maxerr_a) maxerr_a = fabs(s[5] - om);
        if (fabs(sc_energy(w).total - e0) > max_de) max_de = fabs(sc_energy(w).total - e0);
    }
    /* free flight conserves energy; round-off only (|E| ~ 100 J, 1e-10 relative) */
    CHECK_NEAR(max_de, 0.0, 1e-10 * fabs(e0), "free-flight energy conserved");
    CHECK_NEAR(lc_world_get_time(w), 2.0, 1e-12, "time after 400 steps of 5 ms (round-off of the sum)");
    printf("parabola (integrator %d): max |position error| %.3e m, |velocity error| %.3e m/s, "
           "|angle/omega error| %.3e\n", (int)integ, maxerr_p, maxerr_v, maxerr_a);
    if (integ == LC_INTEGRATOR_RK4) {
        CHECK_NEAR(maxerr_p, 0.0, 1e-10, "RK4 parabola position error (round-off only)");
        CHECK_NEAR(maxerr_v, 0.0, 1e-10, "RK4 parabola velocity error (round-off only)");
        CHECK_NEAR(maxerr_a, 0.0, 1e-10, "RK4 spin angle/omega error (round-off only)");
    } else {
        /* Explicit midpoint is also exact for constant acceleration:
         * x + dt (v + dt/2 a) = x + v dt + a dt^2/2. Same round-off tolerance. */
        CHECK_NEAR(maxerr_p, 0.0, 1e-10, "midpoint parabola position error (exact for constant acceleration)");
        CHECK_NEAR(maxerr_v, 0.0, 1e-10, "velocity under constant gravity is exact for every method");
        CHECK_NEAR(maxerr_a, 0.0, 1e-10, "constant spin is exact for every method");
    }
    lc_world_destroy(w);
}

/* (2) Order of accuracy. A 1 x 1 block, m = 1 kg, I = 1/6 kg m^2, g = 0, world damping c = 0.5
 * N s/m (rotation ratio r = 0.3 m^2) and a spring k = 4 N/m, rest length 0, from its centre to the
 * world origin: x'' = -(k/m) x - (c/m) x' in each axis, omega' = -(c r / I) omega.
 * Closed form: x(t) = e^{-gam t} (A cos wd t + B sin wd t), gam = c/(2m), wd = sqrt(k/m - gam^2),
 * A = x0, B = (v0 + gam x0)/wd; omega(t) = w0 e^{-lam t}, angle = a0 + w0 (1 - e^{-lam t})/lam,
 * lam = c r / I. Error at T = 2 s (max over x, y, vx, vy, angle, omega) for dt = 0.1 .. 0.0125;
 * the least-squares slope of log(error) vs log(dt) must be within +-0.3 of the method's order:
 * the leading error term C dt^p dominates at these dt (RK4's smallest error ~1e-7 is far above
 * round-off ~1e-14), higher terms bend the slope by O(dt) ~ 0.1 at most. */
static const double K_SPRING = 4.0, C_DAMP = 0.5, R_ROT = 0.3;

static void exact_xv(double x0, double v0, double t, double *x, double *v)
{
    double gam = C_DAMP / 2.0, wd = sqrt(K_SPRING - gam * gam);
    double A = x0, B = (v0 + gam * x0) / wd, e = exp(-gam * t), c = cos(wd * t), s = sin(wd * t);
    *x = e * (A * c + B * s);
    *v = e * ((-gam * A + wd * B) * c + (-gam * B - wd * A) * s);
}

static double order_error(lc_integrator integ, double dt)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_body_id id;
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    const double x0 = 1.0, y0 = 0.5, vx0 = 0.0, vy0 = 1.0, a0 = 0.2, w0 = 3.0;
    const double inertia = 1.0 / 6.0;
    double t, ex, ev, err = 0, lam;
    const double *s;
    int n = (int)floor(2.0 / dt + 0.5);
    d.integrator = integ;
    d.damping = C_DAMP;
    d.damping_rotation_ratio = R_ROT;
    w = sc_world(&d);
    if (!w) return NAN;
    id = sc_box(w, 1.0, 1.0, x0, y0, a0, vx0, vy0, w0, 1.0, 1.0);
    sd.body_a = id;
    sd.body_b = LC_WORLD_ANCHOR;
    sd.stiffness = K_SPRING;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "add_spring: %s", lc_world_last_error(w));
    CHECK_REL(sc_inertia(w, id), inertia, 1e-12, "unit square inertia 1/6");
    sc_step_n(w, dt, n);
    t = lc_world_get_time(w);
    s = sc_row(w, id);
    exact_xv(x0, vx0, t, &ex, &ev);
    if (fabs(s[0] - ex) > err) err = fabs(s[0] - ex);
    if (fabs(s[3] - ev) > err) err = fabs(s[3] - ev);
    exact_xv(y0, vy0, t, &ex, &ev);
    if (fabs(s[1] - ex) > err) err = fabs(s[1] - ex);
    if (fabs(s[4] - ev) > err) err = fabs(s[4] - ev);
    lam = C_DAMP * R_ROT / inertia;
    if (fabs(s[5] - w0 * exp(-lam * t)) > err) err = fabs(s[5] - w0 * exp(-lam * t));
    if (fabs(s[2] - (a0 + w0 * (1.0 - exp(-lam * t)) / lam)) > err)
        err = fabs(s[2] - (a0 + w0 * (1.0 - exp(-lam * t)) / lam));
    lc_world_destroy(w);
    return err;
}

static void order(lc_integrator integ, double expected)
{
    const double dts[4] = {0.1, 0.05, 0.025, 0.0125};
    double lx[4], ly[4], mx = 0, my = 0, sxy = 0, sxx = 0, slope;
    int i;
    for (i = 0; i < 4; i++) {
        double e = order_error(integ, dts[i]);
        printf("integrator %d dt %.4f error %.3e\n", (int)integ, dts[i], e);
        CHECK(e > 0 && isfinite(e), "error must be positive and finite, got %g", e);
        lx[i] = log(dts[i]);
        ly[i] = log(e);
        mx += lx[i] / 4;
        my += ly[i] / 4;
    }
    for (i = 0; i < 4; i++) {
        sxy += (lx[i] - mx) * (ly[i] - my);
        sxx += (lx[i] - mx) * (lx[i] - mx);
    }
    slope = sxy / sxx;
    printf("integrator %d measured order %.3f (expected %.0f)\n", (int)integ, slope, expected);
    CHECK_NEAR(slope, expected, 0.3, "measured order of accuracy (slope of log error vs log dt)");
}

int main(void)
{
    parabola(LC_INTEGRATOR_RK4);
    parabola(LC_INTEGRATOR_MIDPOINT);
    order(LC_INTEGRATOR_EULER, 1.0);
    order(LC_INTEGRATOR_MIDPOINT, 2.0);
    order(LC_INTEGRATOR_RK4, 4.0);
    return CHECK_SUMMARY("test_free_flight");
}
