/* test_hard_seed: the seed scene run long (docs/hard_cases.md). 6 and 20 blocks 1 m x 0.5 m, 1 kg,
 * in a walled 10 m x 10 m box (inner faces [0,10]^2, walls 1 m thick), placed on random cells of a
 * 2 m grid with random angle in [0, pi), v in [-3, 3]^2 m/s and omega in [-2, 2] rad/s (the layout
 * of bench/scenes.py seed(), here from sc_rng with a fixed seed); e = 1, no friction, no damping,
 * g = 0 and g = 9.8 m/s^2; 60 s at dt = 1/60 s, every other setting the engine's default.
 * Asserted (besides test_hard_common.h's per-step checks: LC_OK, clock, finite, no centre leaves
 * the box, no overlap > 1e-9 m):
 *  - energy: no driving force, e = 1 and no friction, so the exact energy is constant. The engine
 *    integrates free flight in closed form (round-off ~1e-16 per step) and every impact is an exact
 *    e = 1 impulse at the time of impact, so the only systematic change is the resting band: an
 *    approach slower than resting_speed = 1e-4 m/s is treated as resting, not bounced, which can
 *    remove at most m v^2 / 2 = 5e-9 J per event, and the drift correction may lift a body by at most
 *    contact_distance = 1e-5 m; neither happens in these flying scenes. Tolerance: |E - E0| <= 1e-9 E0
 *    at every step, both ways - the project's target for this scene (10 s), kept for 60 s: round-off
 *    over 3600 steps and ~1e4 impacts is ~1e-16 * 1e4 * a few ~ 1e-12 (measured 5e-15), while any
 *    modelling error - one impact resolved inelastically, a mistimed TOI under gravity, a resting
 *    band event at 1e-4 m/s - costs >= 5e-9 J, i.e. well above 1e-9 E0 only for the first two;
 *    5e-9 J against E0 >= 18 J is 3e-10 relative, so up to ~3 band events still pass.
 *  - no stuck state: every block travels at least 1 m (path length of its centre) in every 10 s
 *    window. The mean speed is ~2.4 m/s (g = 0; more with g = 9.8), so a block covers ~24 m per
 *    window; e = 1 exchanges can leave one block still for a while but never the whole window
 *    unless the engine locks it (the seed's "stuck" failure) - deterministic scene, measured
 *    minimum printed.
 *  - the clock reaches 60 s. */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

#define WIN_STEPS 600 /* 10 s windows */

static void seed_scene(int n, double g, uint64_t seed)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4], b[20];
    int cells[25], i, k;
    sc_rng rng;
    hc_mon m;
    char label[96];
    const double box[4] = {0.0, 0.0, 10.0, 10.0};
    double path[20], prev[20][2], min_window_path = INFINITY, gain_tol, loss_tol;
    int min_block = -1, min_win = -1;
    rng.s = seed;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    d.damping = 0.0;
    w = sc_world(&d);
    if (!w) return;
    snprintf(label, sizeof label, "seed scene %d blocks, g = %g, rng %llu", n, g, (unsigned long long)seed);
    hc_walls(w, 0.0, 0.0, 10.0, 10.0, 1.0, 0.0, walls);
    for (i = 0; i < 25; i++) cells[i] = i;
    for (i = 24; i > 0; i--) { /* Fisher-Yates */
        int j = (int)(sc_rand(&rng) * (i + 1)), t = cells[i];
        cells[i] = cells[j];
        cells[j] = t;
    }
    for (i = 0; i < n; i++) {
        double x = 1.0 + 2.0 * (cells[i] % 5), y = 1.0 + 2.0 * (cells[i] / 5);
        double a = sc_uniform(&rng, 0.0, SC_PI), vx = sc_uniform(&rng, -3, 3), vy = sc_uniform(&rng, -3, 3);
        double om = sc_uniform(&rng, -2, 2);
        b[i] = hc_box(w, 1.0, 0.5, x, y, a, vx, vy, om, 1.0, 1.0, 0.0);
    }
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    hc_check_overlap(&m);
    CHECK(m.worst_overlap == 0.0, "%s: initial layout overlaps by %.3e m", label, m.worst_overlap);
    for (i = 0; i < n; i++) {
        const double *r = sc_row(w, b[i]);
        path[i] = 0.0;
        prev[i][0] = r[0];
        prev[i][1] = r[1];
    }
    for (k = 1; k <= HC_STEPS; k++) {
        if (!hc_step(&m)) break;
        for (i = 0; i < n; i++) {
            const double *r = sc_row(w, b[i]);
            path[i] += hypot(r[0] - prev[i][0], r[1] - prev[i][1]);
            prev[i][0] = r[0];
            prev[i][1] = r[1];
        }
        if (k % WIN_STEPS == 0) {
            for (i = 0; i < n; i++) {
                if (path[i] < min_window_path) {
                    min_window_path = path[i];
                    min_block = i;
                    min_win = k / WIN_STEPS;
                }
                path[i] = 0.0;
            }
        }
    }
    hc_finish(&m, HC_STEPS);
    gain_tol = 1e-9 * m.e0;
    loss_tol = 1e-9 * m.e0;
    printf("%s: relative energy drift at 60 s %.3e (max gain %.3e J, tol %.3e; max loss %.3e J, tol %.3e); "
           "least path in a 10 s window %.3f m (block %d, window %d)\n",
           label, (m.e_now - m.e0) / m.e0, m.max_gain, gain_tol, m.max_loss, loss_tol, min_window_path, min_block,
           min_win);
    CHECK(m.max_gain <= gain_tol, "%s: energy rose by %.3e J (t = %.3f), tolerance %.3e J", label, m.max_gain,
          m.t_gain, gain_tol);
    CHECK(m.max_loss <= loss_tol, "%s: energy fell by %.3e J, tolerance %.3e J", label, m.max_loss, loss_tol);
    CHECK(min_window_path >= 1.0, "%s: block %d travelled only %.3e m in 10 s window %d (stuck?)", label,
          min_block, min_window_path, min_win);
    CHECK_NEAR(lc_world_get_time(w), HC_T, 1e-9, "clock at 60 s");
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    uint64_t seed;
    for (seed = 1; seed <= 3; seed++) { /* three layouts, as the benchmark's medians over seeds 1-3 */
        seed_scene(6, 0.0, seed);
        seed_scene(6, 9.8, seed);
        seed_scene(20, 0.0, seed);
        seed_scene(20, 9.8, seed);
    }
    return CHECK_SUMMARY("test_hard_seed");
}
