/* test_flat_drop: a flat 2 m x 1 m block (1 kg) dropped from rest onto the floor at e = 1 (default
 * serial mode, and simultaneous mode too; g = 9.81, no damping). Its two bottom corners hit
 * together; it must bounce straight back to its height without gaining any spin, for several
 * bounces.
 * - |omega| < 1e-9 rad/s and |vx| < 1e-9 m/s: the two impulses are symmetric, anything else is a
 *   modelling error (the seed's serial rule spins it up by O(1) rad/s).
 * - Energy (translational + gravitational, zero level at y = 0, E = m g 3.5 = 34.3 J): free flight
 *   is integrated exactly (round-off ~1e-15 * 3.5 m * 4000 steps ~ 1e-11 relative) and an e = 1
 *   reversal conserves energy wherever it happens (the 1e-7 m contact gap moves the bounce point,
 *   not the energy): tolerance 1e-9 relative. The apex y + vy^2/(2g) is the energy in metres:
 *   tolerance 1e-9 * 3.5 m.
 * - The block never penetrates the floor: lowest corner >= 0 at every step end (the impact is at
 *   gap contact_gap = 1e-7 m; tolerance 0 up to 1e-12 m round-off). */
#include "check.h"
#include "scenes.h"

static void drop(lc_impact_mode mode)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4], blk;
    const double g = 9.81, y0 = 3.5, m = 1.0;
    double e0, maxw = 0, maxvx = 0, maxang = 0, min_gap = INFINITY, max_apex_err = 0, max_e_err = 0;
    int k, bounces = 0, prev_up = 0;
    lc_counters tot;
    d.impact_mode = mode;
    w = sc_world(&d);
    if (!w) return;
    CHECK(lc_world_add_walls(w, -10.0, 0.0, 10.0, 20.0, 1.0, 1.0, walls) == LC_OK, "add_walls: %s",
          lc_world_last_error(w));
    blk = sc_box(w, 2.0, 1.0, 0.0, y0, 0.0, 0, 0, 0, m, 1.0);
    e0 = m * g * y0;
    CHECK_REL(sc_energy(w).total, e0, 1e-14, "initial energy m g y (zero level 0)");
    /* 4 bounces: period 2 sqrt(2 * 3 / g) = 1.564 s */
    for (k = 0; k < 6500; k++) {
        const double *s;
        double apex, gy;
        lc_energy en;
        if (sc_step_n(w, 0.001, 1) != 1) break;
        s = sc_row(w, blk);
        if (fabs(s[5]) > maxw) maxw = fabs(s[5]);
        if (fabs(s[3]) > maxvx) maxvx = fabs(s[3]);
        if (fabs(s[2]) > maxang) maxang = fabs(s[2]);
        gy = sc_min_y(w, blk);
        if (gy < min_gap) min_gap = gy;
        apex = s[1] + s[4] * s[4] / (2.0 * g);
        if (fabs(apex - y0) > max_apex_err) max_apex_err = fabs(apex - y0);
        en = sc_energy(w);
        if (fabs(en.total - e0) > max_e_err) max_e_err = fabs(en.total - e0);
        if (s[4] > 0 && !prev_up) bounces++;
        prev_up = s[4] > 0;
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("flat drop (%s): %d bounces, %llu collision events, %llu impulses, max |omega| %.3e, max |vx| %.3e, "
           "max |angle| %.3e, min gap %.3e m, max apex error %.3e m, max energy error %.3e J\n",
           mode == LC_IMPACT_SERIAL ? "serial" : "simultaneous", bounces, (unsigned long long)tot.collisions, (unsigned long long)tot.impulses, maxw, maxvx, maxang,
           min_gap, max_apex_err, max_e_err);
    CHECK(bounces == 4, "expected 4 bounces in 6.5 s, got %d", bounces);
    CHECK_NEAR(maxw, 0.0, 1e-9, "no spin from a flat landing");
    CHECK_NEAR(maxvx, 0.0, 1e-9, "no sideways velocity from a flat landing");
    CHECK_NEAR(maxang, 0.0, 1e-9, "stays flat");
    CHECK(min_gap >= -1e-12, "lowest corner went below the floor: %.3e m", min_gap);
    CHECK_NEAR(max_apex_err, 0.0, 1e-9 * y0, "bounces back to its height (y + vy^2/2g = y0)");
    CHECK_NEAR(max_e_err, 0.0, 1e-9 * e0, "total energy conserved at e = 1");
    lc_world_destroy(w);
}

int main(void)
{
    drop(LC_IMPACT_SERIAL);       /* the default impact model */
    drop(LC_IMPACT_SIMULTANEOUS); /* symmetric LCP: equal impulses at both corners */
    return CHECK_SUMMARY("test_flat_drop");
}
