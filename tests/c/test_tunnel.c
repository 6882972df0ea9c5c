/* test_tunnel: a small fast block must never pass through a thin wall, however large the step.
 * A 0.1 m square (0.1 kg) at 100+ m/s towards a static wall 0.05 m thick (x in [-0.025, 0.025],
 * 40 m tall), g = 0, e = 1, dt = 0.1 s: the block moves 10-15 m per step, 200-300 times the wall's
 * thickness, so a test of the end positions alone would miss it; the engine follows each vertex's
 * path over the step. Checked at every step end: every vertex of the block stays left of the
 * wall's left face (x < -0.025 m, exact geometry: any vertex at or beyond it has tunnelled or
 * penetrated), at least one collision happened, and the block comes back (vx < 0) with its
 * kinetic energy kept (e = 1: 1e-9 relative, the TOI timing does not change the energy).
 * Cases: head-on, head-on with a vertical component, and rotating fast (60 rad/s: 6 rad per step,
 * so a corner's path within a step is strongly curved). */
#include "check.h"
#include "scenes.h"

static void shoot(double vx, double vy, double angle, double omega, const char *label)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id wall, blk;
    double ke0, worst = -INFINITY;
    int k, came_back = 0;
    lc_counters tot;
    if (!w) return;
    wall = sc_static_box(w, 0.05, 40.0, 0.0, 0.0, 1.0);
    blk = sc_box(w, 0.1, 0.1, -3.0, 0.0, angle, vx, vy, omega, 0.1, 1.0);
    ke0 = sc_kinetic(w);
    for (k = 0; k < 5; k++) {
        const double *s;
        double mx;
        if (sc_step_n(w, 0.1, 1) != 1) break;
        mx = sc_max_x(w, blk);
        if (mx > worst) worst = mx;
        s = sc_row(w, blk);
        if (s[3] < 0) came_back = 1;
        CHECK(mx < -0.025, "%s: step %d ends with a vertex at x = %.6g (wall face at -0.025)", label, k + 1, mx);
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("%s: rightmost vertex ever %.9f m, collisions %llu, toi searches %llu, toi iterations %llu\n", label,
           worst, (unsigned long long)tot.collisions, (unsigned long long)tot.toi_searches,
           (unsigned long long)tot.toi_iterations);
    CHECK(tot.collisions >= 1, "%s: the wall was hit", label);
    CHECK(came_back, "%s: the block bounced back", label);
    CHECK_REL(sc_kinetic(w), ke0, 1e-9, "kinetic energy kept at e = 1");
    (void)wall;
    lc_world_destroy(w);
}

/* The block's lower half meets the wall's top end (wall top at y = 20 m here: wall spans
 * [-20, 20]): the wall's corner hits the block's face and the block's corner the wall's face at
 * once. It must bounce back, never overlapping the wall (separation >= -1e-9 m at step ends). */
static void top_end(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id wall, blk;
    double worst = INFINITY;
    int k;
    if (!w) return;
    wall = sc_static_box(w, 0.05, 40.0, 0.0, 0.0, 1.0);
    blk = sc_box(w, 0.1, 0.1, -3.0, 20.0, 0.0, 150.0, 0.0, 0.0, 0.1, 1.0);
    for (k = 0; k < 5; k++) {
        double sp;
        if (sc_step_n(w, 0.1, 1) != 1) break;
        sp = sc_separation(w, blk, wall);
        if (sp < worst) worst = sp;
    }
    printf("wall top end: min separation %.3e m, final vx %.6f\n", worst, sc_row(w, blk)[3]);
    CHECK(worst >= -1e-9, "block overlapped the wall's end by %.3e m", -worst);
    CHECK(sc_row(w, blk)[0] < 0.0, "block ended beyond the wall (x = %g)", sc_row(w, blk)[0]);
    lc_world_destroy(w);
}

/* No false positive: the same block passing 1 mm above the wall's top never touches it. Its path
 * is a straight line, so after 0.5 s it is exactly at x = -3 + 150 * 0.5 = 72 m (round-off 1e-12). */
static void clear_pass(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id blk;
    lc_counters tot;
    if (!w) return;
    sc_static_box(w, 0.05, 40.0, 0.0, 0.0, 1.0);
    blk = sc_box(w, 0.1, 0.1, -3.0, 20.0 + 0.05 + 1e-3, 0.0, 150.0, 0.0, 0.0, 0.1, 1.0);
    sc_step_n(w, 0.1, 5);
    lc_world_get_counters(w, NULL, &tot);
    CHECK(tot.collisions == 0, "passing 1 mm above the wall: %llu collisions", (unsigned long long)tot.collisions);
    CHECK_NEAR(sc_row(w, blk)[0], 72.0, 1e-12 * 72.0 * 5, "free path over the wall");
    CHECK_NEAR(sc_row(w, blk)[3], 150.0, 0.0, "velocity untouched");
    lc_world_destroy(w);
}

int main(void)
{
    shoot(150.0, 0.0, 0.0, 0.0, "head-on 150 m/s");
    shoot(120.0, 15.0, 0.2, 0.0, "oblique 121 m/s, tilted");
    shoot(100.0, 5.0, 0.3, 60.0, "rotating 60 rad/s at 100 m/s");
    shoot(300.0, -20.0, 0.0, -150.0, "rotating 150 rad/s at 300 m/s");
    top_end();
    clear_pass();
    return CHECK_SUMMARY("test_tunnel");
}
