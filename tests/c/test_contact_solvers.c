/* test_contact_solvers: the contact regime's two solvers of one step's contact problem
 * (contact_solver.h: Gauss-Seidel with momentum; contact_exact.h: Lemke's pivoting on the
 * Stewart-Trinkle LCP) on problems with closed-form answers. Blocks 1 m x 0.5 m, 1 kg, resting on a
 * static face (normal +y) on their two bottom corners; the step's gravity impulse g h along a 30-degree
 * ramp's axes is their start velocity (g = 9.81 m/s^2, h = 1/60 s, every target_n 0):
 *  (1) mu = 0.7 > tan 30: the block sticks; both solvers end with every velocity 0, and the impulses
 *      carry the gravity impulse: sum lambda_n = m g h cos 30, sum lambda_t = m g h sin 30;
 *  (2) mu = 0.3: the block slides at g h (sin 30 - mu cos 30) along the slope, does not turn and does not
 *      leave the face, and each point's friction is on its cone's edge, mu lambda_n;
 *  (3) a second block on the first (mu 0.7, four points, coupled through the lower block): both stick;
 *      the exact answer is a fixed point of the iteration (it ends in one sweep from there).
 * Tolerances: the iterative solver is run to 1e-12 m/s and held to that (and 1e-12 N s); the pivoting
 * solves a problem whose diagonal is raised by a relative 1e-10 (contact_exact.c: dependent points),
 * which moves impulses of ~0.1 N s on effective masses of ~0.3 kg by ~3e-11 m/s, so it is held to
 * 1e-10 m/s and 1e-10 N s, and to 1e-9 where the lower of two stacked blocks carries the upper's
 * impulses too (the error doubles through the coupling: ~1e-10 seen).
 */
#include <math.h>
#include <string.h>
#include "check.h"
#include "contact_exact.h"
#include "contact_solver.h"

#define G 9.81
#define H (1.0 / 60.0)
#define THETA (30.0 * 3.14159265358979323846 / 180.0)
#define INERTIA ((1.0 * 1.0 + 0.5 * 0.5) / 12.0)

/* a point of body a at offset (rx, ry) from its centre, on body b (-1: static) whose centre is at
 * offset (sx, sy) from the point, normal +y out of b */
static lc_contact_row row_at(int a, int b, double rx, double ry, double sx, double sy, double mu)
{
    lc_contact_row r;
    memset(&r, 0, sizeof r);
    r.a = a;
    r.b = b;
    r.nx = 0.0;
    r.ny = 1.0;
    /* cross(r, n) and cross(r, t) with t = (-ny, nx) = (-1, 0) */
    r.rna = rx;
    r.rta = ry;
    r.rnb = b >= 0 ? -sx : 0.0;
    r.rtb = b >= 0 ? -sy : 0.0;
    r.mu = mu;
    return r;
}

static void ramp_rows(lc_contact_row *r, double mu)
{
    r[0] = row_at(0, -1, -0.5, -0.25, 0, 0, mu);
    r[1] = row_at(0, -1, 0.5, -0.25, 0, 0, mu);
}

static void gravity_impulse(double *v, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        v[i * 3] = G * H * sin(THETA);
        v[i * 3 + 1] = -G * H * cos(THETA);
        v[i * 3 + 2] = 0.0;
    }
}

static void ramp(double mu, int exact)
{
    lc_contact_row r[2];
    double v[3], im[1] = {1.0}, ii[1] = {1.0 / INERTIA}, scratch[4096];
    double slide = mu > tan(THETA) ? 0.0 : G * H * (sin(THETA) - mu * cos(THETA));
    const char *who = exact ? "exact" : "iterative";
    double tol = exact ? 1e-10 : 1e-12;
    ramp_rows(r, mu);
    gravity_impulse(v, 1);
    CHECK(lc_contact_exact_scratch(2) <= 4096, "scratch for 2 points fits (%zu)", lc_contact_exact_scratch(2));
    if (exact) {
        CHECK(lc_contact_solve_exact(r, 2, v, im, ii, scratch) >= 0, "%s mu %.1f: pivoting ends", who, mu);
    } else {
        lc_contact_solve s = lc_contact_solver_run(r, 2, v, im, ii, 10000, 1e-12, 32);
        CHECK(s.residual <= 1e-12, "%s mu %.1f: converges (%d sweeps, residual %.3g)", who, mu, s.sweeps,
              s.residual);
    }
    CHECK(fabs(v[0] - slide) <= tol && fabs(v[1]) <= tol && fabs(v[2]) <= tol,
          "%s mu %.1f: v = (%.15g, %.3g, %.3g), expected (%.15g, 0, 0)", who, mu, v[0], v[1], v[2], slide);
    CHECK(fabs(r[0].lambda_n + r[1].lambda_n - G * H * cos(THETA)) <= tol,
          "%s mu %.1f: normal impulses sum to m g h cos 30 (%.15g)", who, mu, r[0].lambda_n + r[1].lambda_n);
    if (slide == 0.0)
        CHECK(fabs(r[0].lambda_t + r[1].lambda_t - G * H * sin(THETA)) <= tol,
              "%s mu %.1f: friction impulses sum to m g h sin 30 (%.15g)", who, mu, r[0].lambda_t + r[1].lambda_t);
    else
        CHECK(fabs(r[0].lambda_t - mu * r[0].lambda_n) <= tol && fabs(r[1].lambda_t - mu * r[1].lambda_n) <= tol,
              "%s mu %.1f: friction on the cone's edge (%.15g / %.15g, %.15g / %.15g)", who, mu, r[0].lambda_t,
              r[0].lambda_n, r[1].lambda_t, r[1].lambda_n);
}

static void two_blocks(void)
{
    lc_contact_row r[4], again[4];
    double v[6], v1[6], im[2] = {1.0, 1.0}, ii[2] = {1.0 / INERTIA, 1.0 / INERTIA}, scratch[16384], worst = 0.0;
    lc_contact_solve s;
    int i;
    ramp_rows(r, 0.7);
    /* block 1's bottom corners on block 0's top face, block 0's centre 0.5 m below block 1's */
    r[2] = row_at(1, 0, -0.5, -0.25, 0.5, -0.25, 0.7);
    r[3] = row_at(1, 0, 0.5, -0.25, -0.5, -0.25, 0.7);
    gravity_impulse(v, 2);
    memcpy(v1, v, sizeof v);
    CHECK(lc_contact_exact_scratch(4) <= 16384, "scratch for 4 points fits (%zu)", lc_contact_exact_scratch(4));
    CHECK(lc_contact_solve_exact(r, 4, v, im, ii, scratch) >= 0, "stacked: pivoting ends");
    for (i = 0; i < 6; ++i) worst = fmax(worst, fabs(v[i]));
    CHECK(worst <= 1e-9, "stacked, mu 0.7: both blocks stick (largest |v| %.3g)", worst);
    CHECK(fabs(r[0].lambda_n + r[1].lambda_n - 2.0 * G * H * cos(THETA)) <= 1e-9,
          "stacked: the floor carries both blocks (%.15g)", r[0].lambda_n + r[1].lambda_n);
    /* the exact impulses as a warm start from the start velocities: one sweep changes them by no more
     * than their 1e-9 m/s */
    memcpy(again, r, sizeof r);
    s = lc_contact_solver_run(again, 4, v1, im, ii, 100, 1e-9, 32);
    CHECK(s.sweeps == 1 && s.residual <= 1e-9, "the exact answer is the iteration's fixed point (%d sweeps, %.3g)",
          s.sweeps, s.residual);
}

int main(void)
{
    ramp(0.7, 1);
    ramp(0.7, 0);
    ramp(0.3, 1);
    ramp(0.3, 0);
    two_blocks();
    return CHECK_SUMMARY("test_contact_solvers");
}
