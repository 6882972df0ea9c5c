/* test_energy_box: six 1 m x 3 m blocks (the seed's) in the walled box [-6,6] x [-6,6], e = 1,
 * damping 0, g = 0, fixed-seed random velocities (|v| up to ~4 m/s, |omega| up to 1.5 rad/s),
 * stepped 100 s at dt = 0.01 s. Every impact is elastic and nothing else does work, so the total
 * energy must stay constant. Tolerance: 1e-6 relative (the project's requirement). Each impact
 * changes the energy only by round-off and by the timing of the impact (the engine's TOI
 * tolerance 1e-10 s; the impulse itself conserves energy at e = 1 for any geometry), free flight
 * is exact up to round-off, so hundreds of impacts stay far below 1e-6. Printed: the reached
 * relative error and the collision count. Also: hundreds of collisions happen (>= 200), no block
 * leaves the box, no two bodies overlap by more than 1e-9 m at any step end. */
#include "check.h"
#include "scenes.h"

int main(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_body_id walls[4], blk[6];
    sc_rng rng = {20261122u};
    double e0, max_err = 0, worst_overlap = 0;
    int i, j, k, escaped = 0;
    lc_counters tot;
    d.damping = 0.0;
    w = sc_world(&d);
    if (!w) return 1;
    CHECK(lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 1.0, walls) == LC_OK, "add_walls: %s",
          lc_world_last_error(w));
    for (i = 0; i < 6; i++) {
        /* columns at x = -5, -3, ..., 5 (1 m gaps), small random tilt and vertical offset */
        blk[i] = sc_box(w, 1.0, 3.0, -5.0 + 2.0 * i, sc_uniform(&rng, -1.5, 1.5), sc_uniform(&rng, -0.2, 0.2),
                        sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -1.5, 1.5),
                        1.0, 1.0);
    }
    for (i = 0; i < 6; i++)
        for (j = i + 1; j < 6; j++)
            CHECK(sc_separation(w, blk[i], blk[j]) > 0.1, "initial scene: blocks %d and %d too close", i, j);
    e0 = sc_energy(w).total;
    CHECK_REL(e0, sc_kinetic(w), 1e-14, "g = 0, no springs: total energy is kinetic");
    for (k = 0; k < 10000; k++) {
        double err;
        if (sc_step_n(w, 0.01, 1) != 1) break;
        err = fabs(sc_energy(w).total - e0) / e0;
        if (err > max_err) max_err = err;
        for (i = 0; i < 6; i++) {
            const double *s = sc_row(w, blk[i]);
            if (fabs(s[0]) > 6.0 || fabs(s[1]) > 6.0) escaped++;
            for (j = i + 1; j < 6; j++) {
                double sep = sc_separation(w, blk[i], blk[j]);
                if (-sep > worst_overlap) worst_overlap = -sep;
            }
            for (j = 0; j < 4; j++) {
                double sep = sc_separation(w, blk[i], walls[j]);
                if (-sep > worst_overlap) worst_overlap = -sep;
            }
        }
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("energy box: t = %.2f s, E0 = %.6f J, max relative energy error %.3e, final %.3e, "
           "collisions %llu, impulses %llu, toi searches %llu (iterations %llu), worst overlap %.3e m\n",
           lc_world_get_time(w), e0, max_err, fabs(sc_energy(w).total - e0) / e0,
           (unsigned long long)tot.collisions, (unsigned long long)tot.impulses,
           (unsigned long long)tot.toi_searches, (unsigned long long)tot.toi_iterations, worst_overlap);
    CHECK_NEAR(lc_world_get_time(w), 100.0, 1e-9, "ran 100 s");
    CHECK(max_err <= 1e-6, "relative energy error %.3e > 1e-6", max_err);
    CHECK(tot.collisions >= 200, "hundreds of collisions expected, got %llu", (unsigned long long)tot.collisions);
    CHECK(escaped == 0, "a block centre left the box %d times", escaped);
    CHECK(worst_overlap <= 1e-9, "bodies overlapped by %.3e m", worst_overlap);
    lc_world_destroy(w);
    return CHECK_SUMMARY("test_energy_box");
}
