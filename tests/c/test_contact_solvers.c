/* test_contact_solvers: the contact regime's three solvers of one step's contact problem
 * (contact_solver.h: Gauss-Seidel with momentum; contact_exact.h: Lemke's pivoting on the
 * Stewart-Trinkle LCP; contact_active_set.h: active sets by dense LU) on problems with closed-form
 * answers. Blocks 1 m x 0.5 m, 1 kg, resting on a
 * static face (normal +y) on their two bottom corners; the step's gravity impulse g h along a 30-degree
 * ramp's axes is their start velocity (g = 9.81 m/s^2, h = 1/60 s, every target_n 0):
 *  (1) mu = 0.7 > tan 30: the block sticks; both solvers end with every velocity 0, and the impulses
 *      carry the gravity impulse: sum lambda_n = m g h cos 30, sum lambda_t = m g h sin 30;
 *  (2) mu = 0.3: the block slides at g h (sin 30 - mu cos 30) along the slope, does not turn and does not
 *      leave the face, and each point's friction is on its cone's edge, mu lambda_n;
 *  (3) a second block on the first (mu 0.7, four points, coupled through the lower block): both stick;
 *      the exact answer is a fixed point of the iteration (it ends in one sweep from there);
 *  (4) stacks of three blocks on ramps of random slope, friction and start velocities: the active sets,
 *      from no impulses and from a perturbed answer, agree with Lemke's answer, and their answer is the
 *      iteration's fixed point. * Tolerances: the iterative solver is run to 1e-12 m/s and held to that (and 1e-12 N s); the pivoting
 * solves a problem whose diagonal is raised by a relative 1e-10 (contact_exact.c: dependent points),
 * which moves impulses of ~0.1 N s on effective masses of ~0.3 kg by ~3e-11 m/s, so it is held to
 * 1e-10 m/s and 1e-10 N s, and to 1e-9 where the lower of two stacked blocks carries the upper's
 * impulses too (the error doubles through the coupling: ~1e-10 seen). The active sets refine their
 * answer against the unraised equations, which takes that error down to round-off: held to 1e-12.
 */
#include <math.h>
#include <string.h>
#include "check.h"
#include "contact_active_set.h"
#include "contact_exact.h"
#include "contact_solver.h"

/* lc_contact_solver_run over nb bodies (at most 3) under the stop rule of max_sweeps, tolerance and
 * stall_sweeps. */
static lc_contact_solve run_solver(lc_contact_row *rows, int n, int nb, double *v, const double *im, const double *ii,
                                   int max_sweeps, double tolerance, int stall_sweeps)
{
    lc_contact_stop stop = lc_contact_stop_rule(max_sweeps, tolerance, stall_sweeps);
    double scratch[3 * 6];
    return lc_contact_solver_run(rows, n, nb, v, im, ii, &stop, scratch);
}

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

enum { ITERATIVE, EXACT, ACTIVE_SET };

static void ramp(double mu, int solver)
{
    lc_contact_row r[2];
    double v[3], im[1] = {1.0}, ii[1] = {1.0 / INERTIA}, scratch[4096];
    double slide = mu > tan(THETA) ? 0.0 : G * H * (sin(THETA) - mu * cos(THETA));
    const char *who = solver == EXACT ? "exact" : solver == ACTIVE_SET ? "active sets" : "iterative";
    double tol = solver == EXACT ? 1e-10 : 1e-12;
    ramp_rows(r, mu);
    gravity_impulse(v, 1);
    CHECK(lc_contact_exact_scratch(2) <= 4096, "scratch for 2 points fits (%zu)", lc_contact_exact_scratch(2));
    CHECK(lc_contact_active_set_scratch(2) <= 4096, "active-set scratch for 2 points fits (%zu)",
          lc_contact_active_set_scratch(2));
    if (solver == EXACT) {
        CHECK(lc_contact_solve_exact(r, 2, v, im, ii, scratch) >= 0, "%s mu %.1f: pivoting ends", who, mu);
    } else if (solver == ACTIVE_SET) {
        int rounds = lc_contact_solve_active_set(r, 2, v, im, ii, scratch);
        CHECK(rounds >= 1, "%s mu %.1f: the states settle from none (%d rounds)", who, mu, rounds);
    } else {
        lc_contact_solve s = run_solver(r, 2, 1, v, im, ii, 10000, 1e-12, 32);
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
    s = run_solver(again, 4, 2, v1, im, ii, 100, 1e-9, 32);
    CHECK(s.sweeps == 1 && s.residual <= 1e-9, "the exact answer is the iteration's fixed point (%d sweeps, %.3g)",
          s.sweeps, s.residual);
}

/* A deterministic generator for the random problems (xorshift64*), uniform in [0, 1). */
static double uniform(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

static void random_stacks(void)
{
    unsigned long long seed = 0x9E3779B97F4A7C15ull;
    int trial, settled = 0, from_perturbed = 0, compared = 0;
    double worst = 0.0, worst_fixed = 0.0, worst_perturbed = 0.0;
    for (trial = 0; trial < 200; ++trial) {
        lc_contact_row r[6], lemke_rows[6], again[6];
        double v0[9], v[9], vl[9], vp[9], im[3] = {1.0, 0.5, 2.0}, ii[3] = {1.0 / INERTIA, 2.0 / INERTIA, 0.5 / INERTIA};
        double scratch[65536], theta = 0.7 * uniform(&seed);
        double mu = 1.2 * uniform(&seed), d = 0.0;
        int i, rounds;
        lc_contact_solve s;
        for (i = 0; i < 3; ++i) {
            v0[i * 3] = G * H * sin(theta) + 0.05 * (uniform(&seed) - 0.5);
            v0[i * 3 + 1] = -G * H * cos(theta) + 0.05 * (uniform(&seed) - 0.5);
            v0[i * 3 + 2] = 0.2 * (uniform(&seed) - 0.5);
        }
        ramp_rows(r, mu);
        r[2] = row_at(1, 0, -0.5, -0.25, 0.5, -0.25, mu);
        r[3] = row_at(1, 0, 0.5, -0.25, -0.5, -0.25, mu);
        r[4] = row_at(2, 1, -0.5, -0.25, 0.5, -0.25, mu);
        r[5] = row_at(2, 1, 0.5, -0.25, -0.5, -0.25, mu);
        /* a point that slips at the start has friction against that slip only */
        for (i = 0; i < 6; ++i) {
            double un, ut;
            lc_contact_row_velocity(&r[i], v0, &un, &ut);
            r[i].slip = ut > 1e-3 ? 1 : ut < -1e-3 ? -1 : 0;
        }
        memcpy(lemke_rows, r, sizeof r);
        memcpy(vl, v0, sizeof v0);
        if (lc_contact_solve_exact(lemke_rows, 6, vl, im, ii, scratch) < 0) continue;
        memcpy(v, v0, sizeof v0);
        rounds = lc_contact_solve_active_set(r, 6, v, im, ii, scratch);
        if (rounds < 0) continue;
        settled++;
        /* compared where Lemke's own answer is a fixed point: in some degenerate problems its path needs
         * a larger regularization and its answer is ~1e-7 m/s off (the sweeps after it take that) */
        memcpy(again, lemke_rows, sizeof r);
        memcpy(vp, v0, sizeof v0);
        if (run_solver(again, 6, 3, vp, im, ii, 1, 0.0, 0).residual <= 1e-9) {
            compared++;
            for (i = 0; i < 9; ++i) d = fmax(d, fabs(v[i] - vl[i]));
            worst = fmax(worst, d);
        }
        memcpy(again, r, sizeof r);
        memcpy(vp, v0, sizeof v0);
        s = run_solver(again, 6, 3, vp, im, ii, 1, 0.0, 0);
        worst_fixed = fmax(worst_fixed, s.residual);
        /* from the answer with every impulse off by up to 30 %: the states are found again */
        for (i = 0; i < 6; ++i) {
            again[i] = r[i];
            again[i].lambda_n *= 1.0 + 0.6 * (uniform(&seed) - 0.5);
            again[i].lambda_t *= 1.0 + 0.6 * (uniform(&seed) - 0.5);
        }
        memcpy(vp, v0, sizeof v0);
        if (lc_contact_solve_active_set(again, 6, vp, im, ii, scratch) >= 0) {
            from_perturbed++;
            d = 0.0;
            for (i = 0; i < 9; ++i) d = fmax(d, fabs(vp[i] - v[i]));
            worst_perturbed = fmax(worst_perturbed, d);
        }
    }
    /* Lemke's answer carries its regularization's ~1e-10 m/s, doubled through each block below (three
     * blocks: ~4e-10 seen), hence 1e-9; the active sets' refined answer is exact to round-off, 1e-12 */
    CHECK(settled == 200, "random stacks: the active sets settle in %d of 200 problems", settled);
    CHECK(compared >= 150 && worst <= 1e-9,
          "random stacks: the same velocities as Lemke's answer (%d compared, largest difference %.3g m/s)", compared,
          worst);
    CHECK(worst_fixed <= 1e-12, "random stacks: the answer is the iteration's fixed point (a sweep changes %.3g m/s)",
          worst_fixed);
    CHECK(from_perturbed == settled && worst_perturbed <= 1e-12,
          "random stacks: from a perturbed answer the same velocities (%d of %d, largest difference %.3g m/s)",
          from_perturbed, settled, worst_perturbed);
}

int main(void)
{
    ramp(0.7, EXACT);
    ramp(0.7, ITERATIVE);
    ramp(0.7, ACTIVE_SET);
    ramp(0.3, EXACT);
    ramp(0.3, ITERATIVE);
    ramp(0.3, ACTIVE_SET);
    two_blocks();
    random_stacks();
    return CHECK_SUMMARY("test_contact_solvers");
}
