/* test_hard_impacts: hard cases (docs/hard_cases.md) with exact answers (the cradle is test_hard_cradle.c), run for 60 s at dt = 1/60 s, e = 1, no
 * friction, no damping, every other setting the engine's default (serial impacts).
 * (6) a small fast block against a thin wall, repeatedly: a 0.1 m x 0.1 m 0.1 kg block in the left
 *     half of a walled 10 m x 6 m box split by a static wall 0.05 m thick (x in [-0.025, 0.025],
 *     floor to ceiling), at 100-150 m/s (1.7-2.5 m per step, 33-50 wall thicknesses), head-on,
 *     oblique, spinning at 60 rad/s, with g = 9.8; a second one in the right half. Asserted at every
 *     step end: every vertex stays on its own side of the thin wall (exact geometry, margin 0), kinetic
 *     + potential energy kept to 1e-9 relative (e = 1 impulses at the TOI conserve energy exactly; the
 *     closed-form flight adds round-off only), and at least 100 reversals of vx (it keeps hitting).
 * (9) flat drop at e = 1: a 1 m x 0.5 m block, bottom face 2 m above a static floor, g = 9.8, 60 s
 *     (47 bounces). Exact: periodic, apex y + vy^2/(2g) = y0 at all times, no spin, no sideways
 *     velocity, angle 0. Tolerances: omega, vx, angle 1e-9 (symmetric impulses; the seed's serial rule
 *     spins it by O(1)); apex 1e-9 * y0 (free flight is exact, an e = 1 reversal keeps the energy
 *     wherever it happens); the number of impacts equals the exact count for a drop of 2 m - contact_gap
 *     (the engine bounces at gap contact_gap = 1e-7 m), and the centre height follows the exact
 *     periodic solution to 1e-6 m (a TOI error of toi_time_tolerance = 1e-10 s per bounce gives
 *     < 5e-9 s of phase after 47 bounces, i.e. < 5e-8 m at 10 m/s; the bound leaves 20x);
 *     the bottom never goes below the floor (>= -1e-12 m, round-off).
 * (10) a heavy fast block smashing into a grid of small blocks without gravity (bench smash():
 *     2 m x 2 m 40 kg block at 20 m/s into 10 x 10 blocks 0.4 m, 0.16 kg, spaced 0.5 m), e = 1:
 *     (a) in free space: linear and angular momentum conserved (equal and opposite impulses:
 *     round-off, 1e-9 relative of the initial |p| = 800 kg m/s and of |L| + |p| * 10 m), kinetic
 *     energy conserved to 1e-9 relative; (b) inside a walled 24 m x 24 m box so the blocks keep
 *     colliding for 60 s: energy to 1e-9 relative, containment and no overlap (monitor). */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

/* ---- (6) thin wall ------------------------------------------------------------------------- */
static void thin_wall(double g, double vx, double vy, double omega, const char *label)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4], thin, left, right;
    const double box[4] = {-5.0, -3.0, 5.0, 3.0};
    double lmax = -INFINITY, rmin = INFINITY, prev_l = vx, prev_r = -vx;
    int k, rev_l = 0, rev_r = 0;
    hc_mon m;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    hc_walls(w, -5.0, -3.0, 5.0, 3.0, 1.0, 0.0, walls);
    thin = hc_static(w, 0.05, 6.0, 0.0, 0.0, 1.0, 0.0);
    left = hc_box(w, 0.1, 0.1, -2.5, 0.3, 0.1, vx, vy, omega, 0.1, 1.0, 0.0);
    right = hc_box(w, 0.1, 0.1, 2.5, -0.7, -0.2, -1.5 * vx, -vy, -omega, 0.1, 1.0, 0.0);
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = 200000; /* ~40 wall hits per second per block; measured count printed */
    for (k = 1; k <= HC_STEPS; k++) {
        lc_vec2 p[LC_MAX_POLYGON_VERTICES];
        int n, i;
        const double *s;
        if (!hc_step(&m)) break;
        n = sc_world_vertices(w, left, p);
        for (i = 0; i < n; i++) if (p[i].x > lmax) lmax = p[i].x;
        n = sc_world_vertices(w, right, p);
        for (i = 0; i < n; i++) if (p[i].x < rmin) rmin = p[i].x;
        s = sc_row(w, left);
        if ((s[3] > 0) != (prev_l > 0)) rev_l++;
        prev_l = s[3];
        s = sc_row(w, right);
        if ((s[3] > 0) != (prev_r > 0)) rev_r++;
        prev_r = s[3];
    }
    hc_finish(&m, HC_STEPS);
    printf("%s: left block's rightmost vertex ever %.9f m, right block's leftmost %.9f m (wall faces -/+0.025), "
           "vx reversals %d / %d, relative energy change %.3e\n",
           label, lmax, rmin, rev_l, rev_r, (m.e_now - m.e0) / m.e0);
    CHECK(lmax < -0.025, "%s: left block reached x = %.9f, at or through the thin wall (face -0.025)", label, lmax);
    CHECK(rmin > 0.025, "%s: right block reached x = %.9f, at or through the thin wall (face 0.025)", label, rmin);
    CHECK(m.max_gain <= 1e-9 * m.e0, "%s: energy rose by %.3e J of %.6g", label, m.max_gain, m.e0);
    CHECK(m.max_loss <= 1e-9 * m.e0, "%s: energy fell by %.3e J of %.6g", label, m.max_loss, m.e0);
    CHECK(rev_l >= 100 && rev_r >= 100, "%s: only %d / %d vx reversals (stuck?)", label, rev_l, rev_r);
    (void)thin;
    hc_mon_free(&m);
    lc_world_destroy(w);
}

/* ---- (9) flat drop ----------------------------------------------------------------------------- */
/* Exact centre height of a block whose bottom starts h above the bounce level, released at rest. */
static double drop_exact_y(double t, double y_top, double h, double g)
{
    double t1 = sqrt(2.0 * h / g), period = 2.0 * t1, tau;
    if (t <= t1) return y_top - 0.5 * g * t * t;
    tau = fmod(t - t1, period) - t1; /* time from the apex, in [-t1, t1) */
    return y_top - 0.5 * g * tau * tau;
}

static void flat_drop(void)
{
    const double g = 9.8, h = 2.0, y0 = h + 0.25;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_world_def got;
    lc_body_id floor_id, blk;
    const double box[4] = {-10.0, 0.0, 10.0, 10.0};
    double maxw = 0, maxvx = 0, maxang = 0, min_gap = INFINITY, max_apex = 0, max_dy = 0, t1, period, hb;
    int k, impacts = 0, expect, prev_up = 0;
    hc_mon m;
    d.gravity.x = 0.0;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return;
    lc_world_get_def(w, &got);
    floor_id = hc_static(w, 20.0, 1.0, 0.0, -0.5, 1.0, 0.0);
    blk = hc_box(w, 1.0, 0.5, 0.0, y0, 0.0, 0, 0, 0, 1.0, 1.0, 0.0);
    if (!hc_mon_init(&m, w, "flat drop, e = 1, 60 s", HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = 1000;
    hb = h - got.contact_gap; /* the engine reverses the block at gap contact_gap */
    t1 = sqrt(2.0 * hb / g);
    period = 2.0 * t1;
    expect = (int)floor((HC_T - t1) / period) + 1;
    for (k = 1; k <= HC_STEPS; k++) {
        const double *s;
        double apex, dy;
        if (!hc_step(&m)) break;
        s = sc_row(w, blk);
        if (fabs(s[5]) > maxw) maxw = fabs(s[5]);
        if (fabs(s[3]) > maxvx) maxvx = fabs(s[3]);
        if (fabs(s[2]) > maxang) maxang = fabs(s[2]);
        if (sc_min_y(w, blk) < min_gap) min_gap = sc_min_y(w, blk);
        apex = s[1] + s[4] * s[4] / (2.0 * g);
        if (fabs(apex - y0) > max_apex) max_apex = fabs(apex - y0);
        dy = fabs(s[1] - drop_exact_y(lc_world_get_time(w), y0, hb, g));
        if (dy > max_dy) max_dy = dy;
        if (s[4] > 0 && !prev_up) impacts++;
        prev_up = s[4] > 0;
    }
    hc_finish(&m, HC_STEPS);
    printf("flat drop: %d impacts (exact %d), max |omega| %.3e, max |vx| %.3e, max |angle| %.3e, lowest point %.3e m, "
           "max apex error %.3e m, max |y - y_exact| %.3e m\n",
           impacts, expect, maxw, maxvx, maxang, min_gap, max_apex, max_dy);
    CHECK(impacts == expect, "flat drop: %d impacts in 60 s, exact %d", impacts, expect);
    CHECK(maxw <= 1e-9, "flat drop: spin %.3e rad/s", maxw);
    CHECK(maxvx <= 1e-9, "flat drop: sideways velocity %.3e m/s", maxvx);
    CHECK(maxang <= 1e-9, "flat drop: angle %.3e rad", maxang);
    CHECK(min_gap >= -1e-12, "flat drop: went %.3e m below the floor", -min_gap);
    CHECK(max_apex <= 1e-9 * y0, "flat drop: apex off by %.3e m", max_apex);
    CHECK(max_dy <= 1e-6, "flat drop: centre height off the exact periodic motion by %.3e m", max_dy);
    CHECK(m.max_gain <= 1e-9 * m.e0 && m.max_loss <= 1e-9 * m.e0, "flat drop: energy change +%.3e / -%.3e J",
          m.max_gain, m.max_loss);
    (void)floor_id;
    hc_mon_free(&m);
    lc_world_destroy(w);
}

/* ---- (10) smash ---------------------------------------------------------------------------------- */
static void smash(int boxed, const char *label)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id walls[4];
    const double box[4] = {-8.0, -8.0, 16.0, 16.0};
    double px0, py0, L0, px, py, L, max_dp = 0, max_dl = 0, pscale, lscale;
    int r, c, k;
    hc_mon m;
    if (!w) return;
    if (boxed) hc_walls(w, -8.0, -8.0, 16.0, 16.0, 1.0, 0.0, walls);
    hc_box(w, 2.0, 2.0, -3.0, 0.5 * 9 * 0.5, 0.0, 20.0, 0, 0, 40.0, 1.0, 0.0);
    for (r = 0; r < 10; r++)
        for (c = 0; c < 10; c++) hc_box(w, 0.4, 0.4, 0.5 * c, 0.5 * r, 0.0, 0, 0, 0, 0.16, 1.0, 0.0);
    if (!hc_mon_init(&m, w, label, HC_DT, boxed ? box : NULL)) { lc_world_destroy(w); return; }
    m.max_collisions = 2000000;
    sc_momentum(w, &px0, &py0, &L0);
    pscale = hypot(px0, py0);
    lscale = fabs(L0) + pscale * 10.0;
    for (k = 1; k <= HC_STEPS; k++) {
        if (!hc_step(&m)) break;
        if (!boxed) {
            sc_momentum(w, &px, &py, &L);
            if (hypot(px - px0, py - py0) > max_dp) max_dp = hypot(px - px0, py - py0);
            if (fabs(L - L0) > max_dl) max_dl = fabs(L - L0);
        }
    }
    hc_finish(&m, HC_STEPS);
    printf("%s: relative energy change %.3e (max gain %.3e J, max loss %.3e J of %.6g); max |dp| %.3e kg m/s, "
           "max |dL| %.3e kg m^2/s\n", label, (m.e_now - m.e0) / m.e0, m.max_gain, m.max_loss, m.e0, max_dp, max_dl);
    CHECK(m.max_gain <= 1e-9 * m.e0, "%s: energy rose by %.3e J", label, m.max_gain);
    CHECK(m.max_loss <= 1e-9 * m.e0, "%s: energy fell by %.3e J", label, m.max_loss);
    if (!boxed) {
        CHECK(max_dp <= 1e-9 * pscale, "%s: linear momentum changed by %.3e kg m/s", label, max_dp);
        CHECK(max_dl <= 1e-9 * lscale, "%s: angular momentum changed by %.3e kg m^2/s", label, max_dl);
    }
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    thin_wall(0.0, 100.0, 0.0, 0.0, "thin wall, head-on 100 m/s");
    thin_wall(0.0, 120.0, 15.0, 0.0, "thin wall, oblique 121 m/s");
    thin_wall(0.0, 100.0, 5.0, 60.0, "thin wall, spinning 60 rad/s at 100 m/s");
    thin_wall(9.8, 100.0, 10.0, 20.0, "thin wall, g = 9.8, 100 m/s, 20 rad/s");
    flat_drop();
    smash(0, "smash 10 x 10, free space");
    smash(1, "smash 10 x 10, walled 24 m box");
    return CHECK_SUMMARY("test_hard_impacts");
}
