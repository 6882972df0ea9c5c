/* test_ramp: a block on a 30-degree ramp with Coulomb friction, built two ways.
 * Scenes (g = 9.81 m/s^2, dt = 1/60 s, default settings otherwise; elasticity 0.5 on both bodies,
 * which no resting contact may turn into a bounce; friction mu set on both bodies, so the default
 * geometric-mean rule gives the pair mu):
 *  - rotated geometry: a static 20 m x 1 m box centred on the origin and turned by theta = 30 degrees
 *    (the ramp), gravity (0, -g) vertical; a 1 m x 0.5 m, 1 kg block lies flat on its upper face,
 *    turned by theta too, its centre 5 m up the slope from the ramp's middle and its lower face
 *    exactly contact_gap (default 1e-7 m) from the ramp's upper face, at rest: the resting position
 *    the engine holds.
 *  - tilted gravity: a static 100 m x 1 m floor (top face y = 0), the same block flat on it at the
 *    contact gap, gravity (g sin theta, -g cos theta): the same physics with axis-aligned geometry,
 *    so an error present only in the rotated scene comes from rotated geometry (contact normal and
 *    points, tangent direction), one present in both from the friction model.
 * Cases:
 *  (a) both scenes, mu = 0.7 > tan 30 deg = 0.577: static friction holds the block. Over 10 s its
 *      centre moves less than 1e-6 m and its angle less than 1e-6 rad. The friction needed,
 *      m g sin theta = 4.9 N, is inside the cone mu m g cos theta = 5.9 N, so the exact answer is no
 *      motion at all; 1e-6 m over 600 steps is a mean creep below 1.7e-9 m per step, the size of
 *      the solver's converged residual integrated over a step, far below any slip the friction
 *      model could produce (a step of unopposed slip moves the block by g sin theta dt^2 / 2 =
 *      6.8e-4 m).
 *  (b) the rotated ramp and (c) tilted gravity, mu = 0.3 < tan 30 deg: the block slides down the
 *      slope with the constant acceleration a = g (sin theta - mu cos theta) = 2.356 m/s^2 (the
 *      normal force m g cos theta is constant and the friction is mu times it, against the slide).
 *      At the end of the first step and at t = 0.5, 1, 2, 3 s (engine clock; by 3 s it has slid
 *      10.6 m and its lower corner is still 3.9 m from the ramp's lower end) its velocity along the
 *      slope equals a t within 1e-6 relative and the distance it travelled along the slope equals
 *      a t^2 / 2 within 1e-6 relative: the friction force is exactly mu N, and a constant force is
 *      integrated exactly (position by the mean of the step's start and end velocities, as
 *      closed-form free flight does); 1e-6 relative is the accuracy of an iteratively solved
 *      friction row, as in test_friction. At every step end: the velocity normal to the slope
 *      stays below 1e-9 m/s (the block neither sinks nor lifts: round-off only, the normal load is
 *      constant), the spin below 1e-6 rad/s and the angle within 1e-6 rad of theta (the friction's
 *      moment about the centre, mu m g cos theta x 0.25 m = 0.64 N m, is balanced by shifting the
 *      normal load towards the lower corner, which can take up to m g cos theta x 0.5 m = 4.25 N m
 *      with both corners loaded), and the block never overlaps the ramp by more than 1e-9 m (1 % of
 *      the contact gap: contacts are held at the gap, so a correct engine never goes below zero).
 * The static case (a) asserts the overlap bound too. Every step returns LC_OK. */
#include "check.h"
#include "scenes.h"

#define G 9.81
#define THETA (SC_PI / 6.0)
#define DT (1.0 / 60.0)

typedef struct ramp_scene {
    lc_world *w;
    lc_body_id ramp, block;
    double d[2];  /* unit vector down the slope (world) */
    double n[2];  /* unit normal of the ramp's upper face (world) */
    double angle0;
} ramp_scene;

/* rotated = 1: a turned ramp and vertical gravity; 0: a flat floor and tilted gravity. */
static int build(ramp_scene *sc, int rotated, double mu)
{
    lc_world_def def = lc_default_world_def();
    double phi = rotated ? THETA : 0.0, t[2], gx, gy, gap, x, y;
    if (rotated) {
        gx = 0.0;
        gy = -G;
    } else {
        gx = G * sin(THETA);
        gy = -G * cos(THETA);
    }
    def.gravity.x = gx;
    def.gravity.y = gy;
    gap = def.contact_gap;
    sc->w = sc_world(&def);
    if (!sc->w) return 0;
    t[0] = cos(phi);
    t[1] = sin(phi);
    sc->n[0] = -sin(phi);
    sc->n[1] = cos(phi);
    /* down the slope: along the face, the way gravity pulls */
    if (gx * t[0] + gy * t[1] >= 0.0) {
        sc->d[0] = t[0];
        sc->d[1] = t[1];
    } else {
        sc->d[0] = -t[0];
        sc->d[1] = -t[1];
    }
    if (rotated) {
        sc->ramp = sc_static_box_rotated(sc->w, 20.0, 1.0, 0.0, 0.0, phi, 0.5);
        /* 5 m up the slope, lower face at the gap above the ramp's upper face (0.5 m from its centre) */
        x = -5.0 * sc->d[0] + (0.5 + 0.25 + gap) * sc->n[0];
        y = -5.0 * sc->d[1] + (0.5 + 0.25 + gap) * sc->n[1];
    } else {
        sc->ramp = sc_static_box(sc->w, 100.0, 1.0, 0.0, -0.5, 0.5);
        x = 0.0;
        y = 0.25 + gap;
    }
    sc->angle0 = phi;
    sc->block = sc_box(sc->w, 1.0, 0.5, x, y, phi, 0.0, 0.0, 0.0, 1.0, 0.5);
    CHECK(lc_body_set_material(sc->w, sc->ramp, 0.5, mu) == LC_OK, "%s", "ramp material");
    CHECK(lc_body_set_material(sc->w, sc->block, 0.5, mu) == LC_OK, "%s", "block material");
    return 1;
}

static void holds(int rotated)
{
    ramp_scene sc;
    const double *r;
    double x0, y0, a0, dmove, worst = 0.0;
    int k, steps = 600;
    const char *label = rotated ? "(a) rotated ramp, mu 0.7" : "(a) tilted gravity, mu 0.7";
    if (!build(&sc, rotated, 0.7)) return;
    r = sc_row(sc.w, sc.block);
    x0 = r[0];
    y0 = r[1];
    a0 = r[2];
    for (k = 0; k < steps; k++) {
        double sp;
        if (sc_step_n(sc.w, DT, 1) != 1) break;
        sp = sc_separation(sc.w, sc.block, sc.ramp);
        if (-sp > worst) worst = -sp;
    }
    r = sc_row(sc.w, sc.block);
    dmove = hypot(r[0] - x0, r[1] - y0);
    printf("%s: after %.3f s the centre moved %.3e m, the angle %.3e rad; worst overlap %.3e m\n", label,
           lc_world_get_time(sc.w), dmove, r[2] - a0, worst);
    CHECK(dmove < 1e-6, "%s: the block crept %.3e m in 10 s (bound 1e-6 m)", label, dmove);
    CHECK(fabs(r[2] - a0) < 1e-6, "%s: the block turned by %.3e rad (bound 1e-6 rad)", label, r[2] - a0);
    CHECK(worst <= 1e-9, "%s: the block overlapped the ramp by %.3e m", label, worst);
    lc_world_destroy(sc.w);
}

static void slides(int rotated)
{
    static const double marks[] = {0.5, 1.0, 2.0, 3.0};
    ramp_scene sc;
    const double mu = 0.3;
    const double a = G * (sin(THETA) - mu * cos(THETA));
    const double *r;
    double x0, y0, vn_max = 0.0, w_max = 0.0, da_max = 0.0, worst = 0.0;
    int k, m = 0, steps = 180;
    const char *label = rotated ? "(b) rotated ramp, mu 0.3" : "(c) tilted gravity, mu 0.3";
    if (!build(&sc, rotated, mu)) return;
    r = sc_row(sc.w, sc.block);
    x0 = r[0];
    y0 = r[1];
    printf("%s: expected a = g (sin 30 - mu cos 30) = %.12f m/s^2\n", label, a);
    for (k = 1; k <= steps; k++) {
        double t, u, s, vn, sp;
        if (sc_step_n(sc.w, DT, 1) != 1) break;
        r = sc_row(sc.w, sc.block);
        t = lc_world_get_time(sc.w);
        u = r[3] * sc.d[0] + r[4] * sc.d[1];
        s = (r[0] - x0) * sc.d[0] + (r[1] - y0) * sc.d[1];
        vn = r[3] * sc.n[0] + r[4] * sc.n[1];
        sp = sc_separation(sc.w, sc.block, sc.ramp);
        if (fabs(vn) > vn_max) vn_max = fabs(vn);
        if (fabs(r[5]) > w_max) w_max = fabs(r[5]);
        if (fabs(r[2] - sc.angle0) > da_max) da_max = fabs(r[2] - sc.angle0);
        if (-sp > worst) worst = -sp;
        if (k == 1 || (m < 4 && fabs(t - marks[m]) < 0.5 * DT)) {
            char what[96];
            printf("%s: t = %.6f s: v along %.12f (a t %.12f, rel err %.3e), distance %.12f (a t^2/2 %.12f, "
                   "rel err %.3e)\n", label, t, u, a * t, fabs(u - a * t) / (a * t), s, 0.5 * a * t * t,
                   fabs(s - 0.5 * a * t * t) / (0.5 * a * t * t));
            snprintf(what, sizeof what, "%s: velocity along the slope = a t at t = %.4f s", label, t);
            CHECK_REL(u, a * t, 1e-6, what);
            snprintf(what, sizeof what, "%s: distance along the slope = a t^2 / 2 at t = %.4f s", label, t);
            CHECK_REL(s, 0.5 * a * t * t, 1e-6, what);
            if (k != 1) m++;
        }
    }
    CHECK(m == 4, "%s: reached only %d of the 4 check times", label, m);
    printf("%s: max |v normal| %.3e m/s, max |omega| %.3e rad/s, max |angle - theta0| %.3e rad, worst overlap "
           "%.3e m\n", label, vn_max, w_max, da_max, worst);
    CHECK(vn_max < 1e-9, "%s: velocity normal to the slope reached %.3e m/s (bound 1e-9)", label, vn_max);
    CHECK(w_max < 1e-6, "%s: spin reached %.3e rad/s (bound 1e-6)", label, w_max);
    CHECK(da_max < 1e-6, "%s: angle left theta0 by %.3e rad (bound 1e-6)", label, da_max);
    CHECK(worst <= 1e-9, "%s: the block overlapped the ramp by %.3e m", label, worst);
    lc_world_destroy(sc.w);
}

int main(void)
{
    holds(1);
    holds(0);
    slides(1);
    slides(0);
    return CHECK_SUMMARY("test_ramp");
}
