/* test_pile: blocks settling onto each other under gravity with e < 1 -- the seed scene's piles in
 * their general form, which must come to rest and never get stuck. Kept apart from
 * test_resting so a regression here (a step that never returns) is visible as its own ctest.
 * Scenes:
 *  (1) the seed's six 1 x 3 m blocks in the box [-6,6]^2 with fixed-seed random velocities,
 *      g = 9.81, e = 0.5 (and e = 0), 10 s at dt = 0.01 s, and at the seed's dt = 0.025 s;
 *  (2) four 3 x 1 m bricks in two rows in the box's corner, 1 mm apart sideways, dropped 0.2 m,
 *      the top-right one pushed sideways at 0.4 m/s, e = 0, 0.3, 0.5; 5 s.
 * Asserted at every step end:
 *  - lc_world_step returns LC_OK;
 *  - no pair overlaps by more than 1e-9 m (1 % of contact_gap; impacts and resting contacts are
 *    handled at gap contact_gap, so a correct engine never goes below zero);
 *  - no body leaves the box;
 *  - the total energy never exceeds its start by more than n m g contact_distance (the most the
 *    drift correction may lift n bodies) -- e <= 1 and no driving force, so energy can only fall. */
#include "check.h"
#include "scenes.h"

static void run(lc_world *w, const lc_body_id *b, int nb, const lc_body_id *walls, double T, double dt,
                const char *label)
{
    lc_world_def got;
    double e0, worst = 0, max_gain = 0, t_worst = 0;
    int k, i, j, steps = (int)(T / dt + 0.5), ok_steps = 0, outside = 0, wa = -1, wb = -1;
    lc_counters tot;
    lc_world_get_def(w, &got);
    e0 = sc_energy(w).total;
    for (k = 0; k < steps; k++) {
        lc_status s = lc_world_step(w, dt);
        double gain;
        if (s != LC_OK) {
            CHECK(0, "%s: step at t = %.2f returned %s: %s", label, lc_world_get_time(w), lc_status_string(s),
                  lc_world_last_error(w));
            break;
        }
        ok_steps++;
        for (i = 0; i < nb; i++) {
            const double *r = sc_row(w, b[i]);
            if (fabs(r[0]) > 6.0 || fabs(r[1]) > 6.0) outside++;
            for (j = i + 1; j < nb; j++) {
                double sp = sc_separation(w, b[i], b[j]);
                if (-sp > worst) { worst = -sp; t_worst = lc_world_get_time(w); wa = i; wb = j; }
            }
            for (j = 0; j < 4; j++) {
                double sp = sc_separation(w, b[i], walls[j]);
                if (-sp > worst) { worst = -sp; t_worst = lc_world_get_time(w); wa = i; wb = 100 + j; }
            }
        }
        gain = sc_energy(w).total - e0;
        if (gain > max_gain) max_gain = gain;
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("%s: %d steps ok, worst overlap %.3e m (t = %.2f), max energy gain %.3e J, final KE %.3e J, "
           "collisions %llu, fallbacks %llu, contact solves %llu\n", label, ok_steps, worst, t_worst, max_gain,
           sc_kinetic(w), (unsigned long long)tot.collisions, (unsigned long long)tot.inelastic_fallbacks,
           (unsigned long long)tot.contact_solves);
    CHECK(worst <= 1e-9, "%s: bodies overlapped by %.3e m at t = %.2f s (block %d with %s %d)", label, worst,
          t_worst, wa, wb >= 100 ? "wall" : "block", wb >= 100 ? wb - 100 : wb);
    CHECK(outside == 0, "%s: a body centre left the box %d times", label, outside);
    CHECK(max_gain <= nb * 9.81 * got.contact_distance, "%s: energy rose by %.3e J", label, max_gain);
}

static void six_blocks(double e, double dt)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_body_id walls[4], b[6];
    sc_rng rng = {42u};
    char label[64];
    int i;
    if (!w) return;
    snprintf(label, sizeof label, "six blocks, g = 9.81, e = %g, dt = %g", e, dt);
    CHECK(lc_world_add_walls(w, -6, -6, 6, 6, 1.0, e, walls) == LC_OK, "%s", "walls");
    for (i = 0; i < 6; i++)
        b[i] = sc_box(w, 1.0, 3.0, -5.0 + 2.0 * i, sc_uniform(&rng, -1.5, 1.5), sc_uniform(&rng, -0.2, 0.2),
                      sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -1.5, 1.5), 1.0, e);
    run(w, b, 6, walls, 10.0, dt, label);
    lc_world_destroy(w);
}

static void bricks(double e)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_body_id walls[4], b[4];
    char label[64];
    int i;
    if (!w) return;
    snprintf(label, sizeof label, "2 x 2 bricks, e = %g", e);
    CHECK(lc_world_add_walls(w, -6, -6, 6, 6, 1.0, e, walls) == LC_OK, "%s", "walls");
    for (i = 0; i < 4; i++)
        b[i] = sc_box(w, 3.0, 1.0, -4.499 + 3.001 * (i % 2), -5.3 + 1.2 * (i / 2), 0.0, i == 3 ? 0.4 : 0.0, 0.0,
                      0.0, 1.0, e);
    run(w, b, 4, walls, 5.0, 0.01, label);
    lc_world_destroy(w);
}

int main(void)
{
    bricks(0.5);
    bricks(0.0);
    bricks(0.3);
    six_blocks(0.5, 0.01);
    six_blocks(0.0, 0.01);
    six_blocks(0.5, 0.025); /* the seed's time step */
    return CHECK_SUMMARY("test_pile");
}
