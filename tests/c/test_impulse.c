/* test_impulse: single corner impacts against eq. 11 of the seed page in closed form.
 * (1) a rotated block hits a static wall with one corner (wall limit m_b, I_b -> infinity), with and
 *     without spin; (2) two free blocks, an eccentric corner-on-face impact; (3) the restitution
 *     threshold (below it an impact of a pair with e < 1 does not bounce).
 * g = 0, no damping, so between impacts the motion is uniform translation + rotation and the time
 * of impact can be found here independently (bisection to 1e-15 s on the analytic corner path).
 *
 * Conventions (types.h): body_a owns the vertex, body_b the edge, n points out of body_b; impacts
 * are handled when the gap reaches contact_gap (1e-7 m). Moving the impact point along n does not
 * change r x n, so the gap offset only enters through the impact time (the rotation during it).
 *
 * Tolerances: the engine's impact time is accurate to toi_time_tolerance = 1e-10 s (or its gap to
 * 1e-10 m, i.e. 1e-10 / 2.5 m/s ~ 4e-11 s); in that time the lever arm r (|r| ~ 1 m) turns by
 * |omega| * 1e-10 <= 1e-10 rad, changing j by ~1e-10 relative. Velocities: 1e-8 relative to the
 * speed scale (100x margin). Positions after the step: the post-impact velocity differs from the
 * pre-impact one by ~5 m/s, so a 1e-10 s timing error moves the body ~5e-10 m: tolerance 1e-8 m.
 * Momentum (only round-off, equal and opposite impulses): 1e-12 relative. */
#include "check.h"
#include "scenes.h"

typedef struct kin { /* uniform motion of a rectangle: centre c + v t, angle th + w t */
    double cx, cy, th, vx, vy, w, hw, hh;
} kin;

static void corner_at(const kin *k, double lx, double ly, double t, double *px, double *py)
{
    double a = k->th + k->w * t, c = cos(a), s = sin(a);
    *px = k->cx + k->vx * t + c * lx - s * ly;
    *py = k->cy + k->vy * t + s * lx + c * ly;
}

/* Largest x over the 4 corners at time t; which corner in *ix, *iy (local signs). */
static double max_corner_x(const kin *k, double t, double *lx, double *ly)
{
    double best = -INFINITY, px, py;
    int i;
    for (i = 0; i < 4; i++) {
        double cx = (i & 1) ? k->hw : -k->hw, cy = (i & 2) ? k->hh : -k->hh;
        corner_at(k, cx, cy, t, &px, &py);
        if (px > best) { best = px; *lx = cx; *ly = cy; }
    }
    return best;
}

/* First time the gap face_x(t) - max corner x(t) falls to target; face_x(t) = f0 + fv t. */
static double impact_time(const kin *k, double f0, double fv, double target, double tmax)
{
    double lo = 0, hi = 0, lx, ly, dt = 1e-3;
    while (hi < tmax) {
        hi = lo + dt;
        if ((f0 + fv * hi) - max_corner_x(k, hi, &lx, &ly) <= target) break;
        lo = hi;
    }
    while (hi - lo > 1e-15) {
        double mid = 0.5 * (lo + hi);
        if ((f0 + fv * mid) - max_corner_x(k, mid, &lx, &ly) <= target) hi = mid; else lo = mid;
        if (mid == lo && mid == hi) break;
    }
    return 0.5 * (lo + hi);
}

static double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/* Steps of dt until the first collision; returns the number of collision events seen. */
static uint64_t step_to_first_collision(lc_world *w, double dt, int max_steps)
{
    lc_counters tot;
    int i;
    for (i = 0; i < max_steps; i++) {
        if (sc_step_n(w, dt, 1) != 1) return 0;
        lc_world_get_counters(w, NULL, &tot);
        if (tot.collisions > 0) return tot.collisions;
    }
    return 0;
}

/* Returns the TOI gap-function evaluations used. */
static uint64_t wall_case(double omega, double e_block, lc_toi_method toi)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_counters tot;
    lc_world_def got;
    lc_body_id blk, wall;
    kin k = {3.5, 0.0, 0.3, 3.0, 1.0, 0.0, 0.5, 1.0};
    const double m = 2.0, I = m * (1.0 + 4.0) / 12.0, face = 5.0, dt = 0.01;
    double cg, ti, lx, ly, px, py, rx, ry, nx = -1.0, ny = 0.0, vpx, vpy, un, rn, j, vx2, vy2, w2, te;
    const lc_contact *cs;
    int nc, i, found = 0;
    const double *s;
    char label[64];
    d.toi_method = toi;
    w = sc_world(&d);
    if (!w) return 0;
    k.w = omega;
    snprintf(label, sizeof label, "wall omega=%g e=%g toi=%s", omega, e_block,
             toi == LC_TOI_ROOT_FINDER ? "root finder" : "bisection");
    lc_world_get_def(w, &got);
    cg = got.contact_gap;
    blk = sc_box(w, 1.0, 2.0, k.cx, k.cy, k.th, k.vx, k.vy, k.w, m, e_block);
    wall = sc_static_box(w, 1.0, 20.0, face + 0.5, 0.0, 1.0); /* left face at x = 5 */
    CHECK_REL(sc_inertia(w, blk), I, 1e-12, "block inertia m (w^2+h^2)/12");

    ti = impact_time(&k, face, 0.0, cg, 2.0);
    max_corner_x(&k, ti, &lx, &ly);
    corner_at(&k, lx, ly, ti, &px, &py);
    rx = px - (k.cx + k.vx * ti);
    ry = py - (k.cy + k.vy * ti);
    /* eq. 4 and the wall limit of eq. 11, then eqs. 7 and 9 */
    vpx = k.vx - k.w * ry;
    vpy = k.vy + k.w * rx;
    un = vpx * nx + vpy * ny;
    rn = cross(rx, ry, nx, ny);
    j = -(1.0 + e_block) * un / (1.0 / m + rn * rn / I); /* min(e_block, 1) = e_block */
    vx2 = k.vx + j * nx / m;
    vy2 = k.vy + j * ny / m;
    w2 = k.w + rn * j / I;
    printf("%s: impact at t=%.12f s, r=(%.6f, %.6f), v_n=%.6f, j=%.9f -> v=(%.9f, %.9f) w=%.9f\n", label, ti,
           rx, ry, un, j, vx2, vy2, w2);

    CHECK(step_to_first_collision(w, dt, 100) == 1, "%s: exactly one collision event", label);
    s = sc_row(w, blk);
    CHECK_NEAR(s[3], vx2, 1e-8 * 3.0, "post-impact vx vs eq. 11 wall limit");
    CHECK_NEAR(s[4], vy2, 1e-8 * 3.0, "post-impact vy vs eq. 11 wall limit");
    CHECK_NEAR(s[5], w2, 1e-8 * 3.0, "post-impact omega vs eq. 11 wall limit");
    /* position at the end of the step: impact position + post velocities * remaining time */
    te = lc_world_get_time(w);
    CHECK_NEAR(s[0], k.cx + k.vx * ti + vx2 * (te - ti), 1e-8, "x at the end of the impact step");
    CHECK_NEAR(s[1], k.cy + k.vy * ti + vy2 * (te - ti), 1e-8, "y at the end of the impact step");
    CHECK_NEAR(s[2], k.th + k.w * ti + w2 * (te - ti), 1e-8, "angle at the end of the impact step");
    /* the reported contact */
    nc = sc_contacts(w, &cs);
    for (i = 0; i < nc; i++) {
        if (cs[i].kind != LC_CONTACT_COLLISION) continue;
        found++;
        CHECK(cs[i].body_a == blk && cs[i].body_b == wall, "%s: vertex on the block, edge on the wall (a=%u b=%u)",
              label, (unsigned)cs[i].body_a, (unsigned)cs[i].body_b);
        CHECK_NEAR(cs[i].normal.x, nx, 1e-12, "contact normal x (out of the wall face)");
        CHECK_NEAR(cs[i].normal.y, ny, 1e-12, "contact normal y");
        CHECK_REL(cs[i].impulse, j, 1e-8, "reported impulse = eq. 11");
        CHECK_REL(cs[i].normal_velocity, un, 1e-8, "reported pre-impact normal velocity");
        CHECK_NEAR(cs[i].point.x, px, 2.0 * cg, "contact point x (vertex or its foot on the face)");
        CHECK_NEAR(cs[i].point.y, py, 1e-8, "contact point y");
        CHECK_NEAR(cs[i].time, ti, 1e-9, "reported impact time (toi_time_tolerance 1e-10 s + margin)");
    }
    CHECK(found == 1, "%s: one collision contact reported, got %d", label, found);
    lc_world_get_counters(w, NULL, &tot);
    printf("%s: toi searches %llu, gap evaluations %llu\n", label, (unsigned long long)tot.toi_searches,
           (unsigned long long)tot.toi_iterations);
    CHECK(tot.toi_searches >= 1, "%s: a TOI search was counted", label);
    lc_world_destroy(w);
    return tot.toi_iterations;
}

static void block_block_case(double e)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_world_def got;
    lc_body_id A, B;
    /* A: 1 x 2, 1 kg, rotated 0.4 rad, spinning 0.5 rad/s; B: 1 x 1, 1.5 kg, moving left. */
    kin k = {-1.95, 0.926, 0.4, 2.0, 0.3, 0.5, 0.5, 1.0};
    const double mA = 1.0, IA = 5.0 / 12.0, mB = 1.5, IB = 1.5 / 6.0, bx0 = 0.0, bvx = -0.5;
    double cg, ti, lx, ly, px, py, rax, ray, rbx, rby, nx = -1.0, ny = 0.0, un, ra, rb, K, j;
    double px0, py0, L0, px1, py1, L1, ke0, ke1, dke, pn;
    lc_energy en;
    const double *sa, *sb;
    char label[64];
    if (!w) return;
    snprintf(label, sizeof label, "block-block e=%g", e);
    lc_world_get_def(w, &got);
    cg = got.contact_gap;
    A = sc_box(w, 1.0, 2.0, k.cx, k.cy, k.th, k.vx, k.vy, k.w, mA, e);
    B = sc_box(w, 1.0, 1.0, bx0, 0.0, 0.0, bvx, 0.0, 0.0, mB, 1.0);
    sc_momentum(w, &px0, &py0, &L0);
    ke0 = sc_kinetic(w);

    /* B's left face: x = bx0 - 0.5 + bvx t */
    ti = impact_time(&k, bx0 - 0.5, bvx, cg, 2.0);
    max_corner_x(&k, ti, &lx, &ly);
    corner_at(&k, lx, ly, ti, &px, &py);
    CHECK(fabs(py) < 0.45, "scene check: A's corner hits B's left face inside it (y = %g)", py);
    rax = px - (k.cx + k.vx * ti);
    ray = py - (k.cy + k.vy * ti);
    rbx = px - (bx0 + bvx * ti);
    rby = py - 0.0;
    un = ((k.vx - k.w * ray) - bvx) * nx + ((k.vy + k.w * rax) - 0.0) * ny; /* eq. 4 . n */
    ra = cross(rax, ray, nx, ny);
    rb = cross(rbx, rby, nx, ny);
    K = 1.0 / mA + 1.0 / mB + ra * ra / IA + rb * rb / IB;
    j = -(1.0 + e) * un / K; /* eq. 11, e = min(e, 1) */
    dke = -(1.0 - e * e) * un * un / (2.0 * K);
    printf("%s: impact t=%.12f P=(%.6f, %.6f) v_n=%.6f j=%.9f dKE=%.9f\n", label, ti, px, py, un, j, dke);

    CHECK(step_to_first_collision(w, 0.01, 100) == 1, "%s: exactly one collision event", label);
    sa = sc_row(w, A);
    sb = sc_row(w, B);
    CHECK_NEAR(sa[3], k.vx + j * nx / mA, 3e-8, "A vx after (eq. 7)");
    CHECK_NEAR(sa[4], k.vy + j * ny / mA, 3e-8, "A vy after (eq. 7)");
    CHECK_NEAR(sa[5], k.w + ra * j / IA, 3e-8, "A omega after (eq. 9)");
    CHECK_NEAR(sb[3], bvx - j * nx / mB, 3e-8, "B vx after (eq. 8)");
    CHECK_NEAR(sb[4], 0.0 - j * ny / mB, 3e-8, "B vy after (eq. 8)");
    CHECK_NEAR(sb[5], 0.0 - rb * j / IB, 3e-8, "B omega after (eq. 10)");

    sc_momentum(w, &px1, &py1, &L1);
    pn = sqrt(px0 * px0 + py0 * py0);
    CHECK_NEAR(px1, px0, 1e-12 * pn, "linear momentum x conserved (1e-12 relative)");
    CHECK_NEAR(py1, py0, 1e-12 * pn, "linear momentum y conserved (1e-12 relative)");
    CHECK_REL(L1, L0, 1e-12, "angular momentum about the origin conserved (1e-12 relative)");
    ke1 = sc_kinetic(w);
    /* energy: KE_after = KE_before - (1 - e^2) u^2 / (2K); uncertainty from the timing as above */
    CHECK_NEAR(ke1, ke0 + dke, 1e-9 * ke0, "kinetic energy scaled as e predicts");
    en = sc_energy(w);
    CHECK_REL(en.translational + en.rotational, ke1, 1e-12, "lc_world_get_energy kinetic = sum m v^2/2 + I w^2/2");
    CHECK_NEAR(en.linear_momentum.x, px1, 1e-12 * pn, "lc_world_get_energy linear momentum x");
    CHECK_NEAR(en.linear_momentum.y, py1, 1e-12 * pn, "lc_world_get_energy linear momentum y");
    CHECK_REL(en.angular_momentum, L1, 1e-12, "lc_world_get_energy angular momentum about the origin");
    lc_world_destroy(w);
}

/* (3) The restitution threshold, g = 0: a block (e_block, the floor's e 1, mixed by min) moving down
 * at v onto a static floor 1 mm below. Above the threshold it leaves at e v (eq. 11, one point per
 * corner pair, flat); below it the impact is inelastic and the block stays at the floor (|vy| below
 * resting_speed, where contact forces hold it); at e = 1 it bounces at any speed above
 * resting_speed, so energy is kept. Velocities to 1e-9 m/s: a 1e-10 s timing error changes nothing
 * here (g = 0, no spin). */
static void threshold_case(double v, double e_block, double threshold, double expect_vy)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_body_id b;
    double vy;
    d.restitution_threshold = threshold;
    w = sc_world(&d);
    if (!w) return;
    sc_static_box(w, 10.0, 1.0, 0.0, -0.5, 1.0);
    b = sc_box(w, 1.0, 0.5, 0.0, 0.25 + 1e-3, 0.0, 0.0, -v, 0.0, 1.0, e_block);
    sc_step_n(w, 0.01, (int)(2e-3 / v / 0.01) + 2);
    vy = sc_row(w, b)[4];
    printf("threshold %g m/s, e %g, v %g m/s: leaves at %.12g m/s (expected %g)\n", threshold, e_block, v, vy,
           expect_vy);
    CHECK(fabs(vy - expect_vy) <= 1e-9, "threshold %g, e %g, v %g: vy %.12g, expected %g", threshold, e_block, v, vy,
          expect_vy);
    lc_world_destroy(w);
}

int main(void)
{
    uint64_t it_root, it_bisect;
    wall_case(0.0, 1.0, LC_TOI_ROOT_FINDER);
    wall_case(0.0, 0.7, LC_TOI_ROOT_FINDER);
    wall_case(0.8, 1.0, LC_TOI_ROOT_FINDER);
    it_root = wall_case(0.8, 0.7, LC_TOI_ROOT_FINDER);
    /* Bisection (LC_TOI_BINARY_SEARCH) reaches the same impact to the same tolerances, with more gap
     * evaluations: halving a 0.01 s step down to 1e-10 s takes ~27 of them, while the root finder
     * converges superlinearly, so it needs few. */
    wall_case(0.0, 0.7, LC_TOI_BINARY_SEARCH);
    it_bisect = wall_case(0.8, 0.7, LC_TOI_BINARY_SEARCH);
    CHECK(it_root < it_bisect, "root finder used %llu gap evaluations, bisection %llu", (unsigned long long)it_root,
          (unsigned long long)it_bisect);
    block_block_case(1.0);
    block_block_case(0.6);
    threshold_case(0.5, 0.5, 1e-2, 0.25);      /* above the default threshold: eq. 11 */
    threshold_case(5e-3, 0.5, 1e-2, 0.0);      /* below: inelastic, then resting */
    threshold_case(5e-3, 0.5, 0.0, 2.5e-3);    /* threshold 0: bounces down to resting_speed */
    threshold_case(5e-3, 1.0, 1e-2, 5e-3);     /* e = 1 keeps bouncing: energy kept */
    return CHECK_SUMMARY("test_impulse");
}
