/* test_resting: the seed's "stuck" cases ((1) a block settling on the floor at e = 0.5, (2) two
 * blocks pushed together by a spring, and by a mouse spring against a wall), (3) a stack of ten,
 * (4) a thruster pushing a block into a block at the wall (contact forces = thrust).
 * Conventions: resting contacts are held at gap contact_gap (1e-7 m) and bodies "touch" below
 * contact_distance (1e-5 m). Tolerances:
 * - never penetrate more than PEN_TOL = 1e-9 m (1 % of contact_gap) at any step end: impacts are
 *   handled at contact_gap and resting contacts are held there, so a correct engine stays >= 0;
 * - at rest: the touching gap in [0, contact_distance], speed |v| < 1e-6 m/s and |omega| < 1e-6
 *   rad/s (well above the residual of the stabilisation and far below any bounce: with e = 0.5 a
 *   bounce at speed u lasts 2u/g, so 1e-6 m/s means the bouncing has ended);
 * - the resting contact forces carry the weight: sum of normal forces = m g to 1e-6 relative
 *   (Newton's second law at rest, minus the LCP residual <= 1e-10 relative);
 * - no step returns an error. */
#include "check.h"
#include "scenes.h"

#define PEN_TOL 1e-9

/* (1) a block settling on the floor with gravity and e = 0.5 (flat, and tilted with spin) */
static void settle(double angle, double omega, const char *label)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_world_def got;
    lc_body_id walls[4], blk;
    double min_gap = INFINITY, fsum = 0, gap;
    const double *s;
    const lc_contact *cs;
    int nc, i, n_rest = 0, n_steps;
    if (!w) return;
    lc_world_get_def(w, &got);
    CHECK(lc_world_add_walls(w, -5.0, 0.0, 5.0, 10.0, 1.0, 0.5, walls) == LC_OK, "add_walls: %s",
          lc_world_last_error(w));
    blk = sc_box(w, 1.0, 1.0, 0.0, 1.5, angle, 0.0, 0.0, omega, 1.0, 0.5);
    /* 10 s; a flat drop from 1 m settles in ~1.4 s (bounce times shrink by e = 0.5 each time) */
    for (n_steps = 0; n_steps < 1000; n_steps++) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        gap = sc_min_y(w, blk);
        if (gap < min_gap) min_gap = gap;
    }
    CHECK(n_steps == 1000, "%s: all 1000 steps returned LC_OK (stopped after %d)", label, n_steps);
    printf("%s: lowest corner over the run %.3e m\n", label, min_gap);
    CHECK(min_gap >= -PEN_TOL, "%s: penetrated the floor by %.3e m", label, -min_gap);
    s = sc_row(w, blk);
    gap = sc_min_y(w, blk);
    printf("%s: final y %.12f angle %.3e v (%.3e, %.3e) omega %.3e lowest corner %.3e m\n", label, s[1], s[2],
           s[3], s[4], s[5], gap);
    CHECK(gap >= 0.0 && gap <= got.contact_distance, "%s: resting gap %.3e m not in [0, %.1e]", label, gap,
          got.contact_distance);
    CHECK(sqrt(s[3] * s[3] + s[4] * s[4]) < 1e-6, "%s: at rest, |v| = %.3e m/s", label,
          sqrt(s[3] * s[3] + s[4] * s[4]));
    CHECK(fabs(s[5]) < 1e-6, "%s: at rest, |omega| = %.3e rad/s", label, fabs(s[5]));
    /* flat on the floor: both bottom corners touch (angle a multiple of pi/2 to within
     * contact_distance / 1 m) */
    {
        double a = fmod(fabs(s[2]), SC_PI / 2.0);
        if (a > SC_PI / 4.0) a = SC_PI / 2.0 - a;
        CHECK(a <= got.contact_distance, "%s: rests flat, tilt %.3e rad", label, a);
    }
    nc = sc_contacts(w, &cs);
    for (i = 0; i < nc; i++) {
        if (cs[i].kind != LC_CONTACT_RESTING) continue;
        n_rest++;
        fsum += cs[i].force * cs[i].normal.y; /* floor normal is +y */
        CHECK(cs[i].force >= 0.0, "%s: contact force must be >= 0, got %g", label, cs[i].force);
    }
    CHECK(n_rest >= 2, "%s: resting contacts at both bottom corners, got %d", label, n_rest);
    CHECK_REL(fsum, 1.0 * 9.81, 1e-6, "resting contact forces carry the weight m g");
    lc_world_destroy(w);
}

/* (2) two blocks pulled together by a spring (rest length 0) between their centres, e = 0.5, g = 0:
 * they bounce with decaying speed and end touching at rest (total momentum 0). And the mouse case:
 * block A pulled by a world-anchored spring into block B, which rests against the right wall. */
static void spring_pair(int mouse)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_world_def got;
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    lc_body_id walls[4], A, B;
    double min_sep = INFINITY, sep;
    const double *sa, *sb;
    int k;
    const char *label = mouse ? "mouse spring into a block at the wall" : "two blocks joined by a spring";
    if (!w) return;
    lc_world_get_def(w, &got);
    CHECK(lc_world_add_walls(w, -5.0, -5.0, 5.0, 5.0, 1.0, 0.5, walls) == LC_OK, "%s", "add_walls");
    A = sc_box(w, 1.0, 1.0, -2.0, 0.0, 0.0, 0, 0, 0, 1.0, 0.5);
    B = sc_box(w, 1.0, 1.0, mouse ? 4.0 : 2.0, 0.0, 0.0, 0, 0, 0, 1.0, 0.5);
    sd.body_a = A;
    sd.stiffness = 3.0;
    if (mouse) {
        sd.body_b = LC_WORLD_ANCHOR;
        sd.point_b.x = 5.0; /* the mouse, on the wall face behind B */
        sd.point_b.y = 0.0;
    } else {
        sd.body_b = B;
    }
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "add_spring: %s", lc_world_last_error(w));
    for (k = 0; k < 2000; k++) { /* 20 s */
        if (sc_step_n(w, 0.01, 1) != 1) break;
        sep = sc_separation(w, A, B);
        if (sep < min_sep) min_sep = sep;
        if (mouse) {
            sep = sc_separation(w, B, walls[1]);
            if (sep < min_sep) min_sep = sep;
        }
    }
    sa = sc_row(w, A);
    sb = sc_row(w, B);
    sep = sc_separation(w, A, B);
    printf("%s: final separation %.3e m, vA (%.3e, %.3e) vB (%.3e, %.3e), min separation %.3e m\n", label, sep,
           sa[3], sa[4], sb[3], sb[4], min_sep);
    CHECK(min_sep >= -PEN_TOL, "%s: overlap of %.3e m", label, -min_sep);
    CHECK(sep >= 0.0 && sep <= got.contact_distance, "%s: ends touching, separation %.3e m", label, sep);
    CHECK(hypot(sa[3], sa[4]) < 1e-6 && hypot(sb[3], sb[4]) < 1e-6, "%s: at rest |vA| %.3e |vB| %.3e", label,
          hypot(sa[3], sa[4]), hypot(sb[3], sb[4]));
    CHECK(fabs(sa[5]) < 1e-6 && fabs(sb[5]) < 1e-6, "%s: no spin, %.3e %.3e", label, sa[5], sb[5]);
    if (mouse) {
        sep = sc_separation(w, B, walls[1]);
        CHECK(sep >= 0.0 && sep <= got.contact_distance, "%s: B ends touching the wall, %.3e m", label, sep);
    }
    lc_world_destroy(w);
}

/* (3) a stack of ten 1 m blocks on the floor, placed with gaps of contact_gap, g = 9.81, e = 0.5:
 * it rests for 10 s; sink (drop of each block) < 1e-5 m, sideways creep < 1e-5 m, tilt < 1e-5 rad,
 * no overlap beyond PEN_TOL, final speeds < 1e-6 m/s. */
static void stack(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    lc_world_def got;
    lc_body_id walls[4], b[10];
    double y0[10], cg, max_sink = 0, max_creep = 0, max_tilt = 0, min_sep = INFINITY, max_v = 0;
    int i, k;
    lc_counters tot;
    if (!w) return;
    lc_world_get_def(w, &got);
    cg = got.contact_gap;
    CHECK(lc_world_add_walls(w, -5.0, 0.0, 5.0, 20.0, 1.0, 0.5, walls) == LC_OK, "%s", "add_walls");
    for (i = 0; i < 10; i++) {
        y0[i] = 0.5 + cg + i * (1.0 + cg);
        b[i] = sc_box(w, 1.0, 1.0, 0.0, y0[i], 0.0, 0, 0, 0, 1.0, 0.5);
    }
    for (k = 0; k < 1000; k++) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        for (i = 0; i < 10; i++) {
            const double *s = sc_row(w, b[i]);
            double sep = i ? sc_separation(w, b[i - 1], b[i]) : sc_min_y(w, b[0]);
            if (y0[i] - s[1] > max_sink) max_sink = y0[i] - s[1];
            if (fabs(s[0]) > max_creep) max_creep = fabs(s[0]);
            if (fabs(s[2]) > max_tilt) max_tilt = fabs(s[2]);
            if (sep < min_sep) min_sep = sep;
            if (k == 999 && hypot(s[3], s[4]) > max_v) max_v = hypot(s[3], s[4]);
        }
    }
    lc_world_get_counters(w, NULL, &tot);
    printf("stack of 10: max sink %.3e m, max creep %.3e m, max tilt %.3e rad, min gap %.3e m, final max |v| "
           "%.3e m/s; contact solves %llu, collisions %llu\n", max_sink, max_creep, max_tilt, min_sep, max_v,
           (unsigned long long)tot.contact_solves, (unsigned long long)tot.collisions);
    CHECK(max_sink < 1e-5, "stack sank %.3e m", max_sink);
    CHECK(max_creep < 1e-5, "stack crept sideways %.3e m", max_creep);
    CHECK(max_tilt < 1e-5, "stack tilted %.3e rad", max_tilt);
    CHECK(min_sep >= -PEN_TOL, "stack overlap %.3e m", -min_sep);
    CHECK(max_v < 1e-6, "stack at rest, max |v| %.3e m/s", max_v);
    lc_world_destroy(w);
}

/* (4) g = 0: a thruster (1.5 N along +x at A's centre) pushes block A into block B, which rests
 * against the right wall. At rest the forces balance: the A-B contact force and the B-wall contact
 * force both equal the thrust, 1.5 N (to 1e-6 relative: the LCP residual is <= 1e-10 relative and
 * the bodies are at rest); both gaps in [0, contact_distance], speeds < 1e-6 m/s. */
static void pushed_chain(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id walls[4], A, B;
    lc_thruster_def td;
    const lc_contact *cs;
    double f_ab = 0, f_bw = 0, s_ab, s_bw;
    int i, nc;
    if (!w) return;
    CHECK(lc_world_add_walls(w, -5, -5, 5, 5, 1.0, 0.5, walls) == LC_OK, "%s", "walls");
    A = sc_box(w, 1.0, 1.0, 2.0, 0.0, 0.0, 0, 0, 0, 1.0, 0.5);
    B = sc_box(w, 1.0, 1.0, 4.0, 0.0, 0.0, 0, 0, 0, 2.0, 0.5);
    td.point.x = 0.0; td.point.y = 0.0; td.direction.x = 1.0; td.direction.y = 0.0; td.magnitude = 1.5;
    CHECK(lc_body_add_thruster(w, A, &td, NULL) == LC_OK, "%s", "thruster");
    CHECK(lc_body_set_thruster_level(w, A, 0, 1.0) == LC_OK, "%s", "level");
    CHECK(sc_step_n(w, 0.01, 2000) == 2000, "%s", "20 s without error");
    nc = sc_contacts(w, &cs);
    for (i = 0; i < nc; i++) {
        if (cs[i].kind != LC_CONTACT_RESTING) continue;
        if ((cs[i].body_a == A && cs[i].body_b == B) || (cs[i].body_a == B && cs[i].body_b == A)) f_ab += cs[i].force;
        else if (cs[i].body_a == walls[1] || cs[i].body_b == walls[1]) f_bw += cs[i].force;
    }
    s_ab = sc_separation(w, A, B);
    s_bw = sc_separation(w, B, walls[1]);
    printf("pushed chain: F(A,B) %.12f N, F(B,wall) %.12f N, gaps %.3e %.3e m, |vA| %.3e |vB| %.3e\n", f_ab, f_bw,
           s_ab, s_bw, hypot(sc_row(w, A)[3], sc_row(w, A)[4]), hypot(sc_row(w, B)[3], sc_row(w, B)[4]));
    CHECK_REL(f_ab, 1.5, 1e-6, "contact force A-B = thrust");
    CHECK_REL(f_bw, 1.5, 1e-6, "contact force B-wall = thrust");
    CHECK(s_ab >= 0 && s_ab <= d.contact_distance && s_bw >= 0 && s_bw <= d.contact_distance,
          "pushed chain: gaps %.3e %.3e not in [0, contact_distance]", s_ab, s_bw);
    CHECK(hypot(sc_row(w, A)[3], sc_row(w, A)[4]) < 1e-6 && hypot(sc_row(w, B)[3], sc_row(w, B)[4]) < 1e-6, "%s",
          "pushed chain at rest");
    lc_world_destroy(w);
}

int main(void)
{
    settle(0.0, 0.0, "flat block settling on the floor");
    settle(0.3, 1.0, "tilted spinning block settling on the floor");
    spring_pair(0);
    spring_pair(1);
    stack();
    pushed_chain();
    return CHECK_SUMMARY("test_resting");
}
