/* test_multi_impact: the seed's multiple-impact cases, g = 0, no damping, frictionless.
 *   A  two corners of a block on one wall (symmetric: no spin)
 *   A2 two corners of a block on one face of a free taller block (off-centre)
 *   B  two corners on two walls: a tilted block driven diagonally into a corner of the box
 *   C  two corners on different objects: a wide block lands on two tilted free blocks
 *   D  a tilted block wedged between two others that close in on it from both sides
 * Each scene is built from its configuration at the instant of impact t_i = 0.1 s (every contact
 * at gap exactly contact_gap, nothing rotating) and moved back along the velocities, so all of its
 * contacts reach contact_gap at the same instant and the impact geometry is known exactly.
 *
 * Simultaneous mode must give the solution of the impulse complementarity problem (solved here by
 * enumerating active sets): j >= 0, u' = u + A j >= -e u, j . (u' + e u) = 0, with
 * A_ik = sum over bodies X of s_iX s_kX (n_i.n_k / m_X + (r_iX x n_i)(r_kX x n_k) / I_X).
 * Tolerance 1e-8 relative to the speed scale: the only deviation is the impact timing (1e-10 s)
 * times the tangential sliding speed (<= 3 m/s), i.e. lever arms off by ~3e-10 m of ~1 m.
 * Both modes (serial results depend on the order, so only invariants are asserted there):
 *  - no contact approaches after the event: u' >= -resting_speed (slower approaches are the
 *    resting-contact solver's to hold, by the engine's definition);
 *  - momentum bookkeeping: for each body, m dv = sum of the reported impulses j n on it and
 *    d(L about the origin) = sum of P x (j n), to 1e-9 relative (round-off; moving P along n,
 *    vertex vs foot on the face, does not change P x n); with no static body in the scene, total
 *    linear and angular momentum conserved to 1e-12 relative;
 *  - energy never increases (e <= 1): KE_after <= KE_before (1 + 1e-12) at every later step; at
 *    e = 1 it is kept to 1e-6 relative (residual approaches below resting_speed may be removed
 *    inelastically: (1e-4 m/s)^2 m / 2 ~ 5e-9 J);
 *  - no penetration: every pair's separation >= -1e-9 m at every step end over 0.5 s after. */
#include "check.h"
#include "scenes.h"

#define MAXB 4
#define MAXC 4
#define T_HIT 0.1

typedef struct scene {
    const char *name;
    int nb, nc;
    int is_static[MAXB];
    double w[MAXB], h[MAXB], ang[MAXB], m[MAXB], e[MAXB];
    double cx[MAXB], cy[MAXB], vx[MAXB], vy[MAXB]; /* centre at the impact instant, velocity */
    int ca[MAXC], cb[MAXC];                          /* vertex owner, face owner */
    double px[MAXC], py[MAXC], nx[MAXC], ny[MAXC];  /* contact point and normal (out of cb) */
    double I[MAXB];
    int serial_exact; /* the serial answer must equal the simultaneous one (symmetric same-pair case) */
} scene;

static void corner(double w, double h, double ang, double sx, double sy, double *ox, double *oy)
{
    double c = cos(ang), s = sin(ang), lx = sx * w / 2, ly = sy * h / 2;
    *ox = c * lx - s * ly;
    *oy = s * lx + c * ly;
}

static int add_body(scene *sc, int st, double w, double h, double ang, double m, double e, double cx, double cy,
                    double vx, double vy)
{
    int i = sc->nb++;
    sc->is_static[i] = st;
    sc->w[i] = w; sc->h[i] = h; sc->ang[i] = ang; sc->m[i] = m; sc->e[i] = e;
    sc->cx[i] = cx; sc->cy[i] = cy; sc->vx[i] = vx; sc->vy[i] = vy;
    sc->I[i] = st ? 0.0 : m * (w * w + h * h) / 12.0;
    return i;
}

static void add_contact(scene *sc, int a, int b, double px, double py, double nx, double ny)
{
    int k = sc->nc++;
    sc->ca[k] = a; sc->cb[k] = b; sc->px[k] = px; sc->py[k] = py; sc->nx[k] = nx; sc->ny[k] = ny;
}

static double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/* Solve M x = r (n <= 4) by Gaussian elimination with partial pivoting; 0 if singular. */
static int solve(int n, double M[MAXC][MAXC], double *r, double *x)
{
    double a[MAXC][MAXC + 1];
    int i, j, k;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) a[i][j] = M[i][j];
        a[i][n] = r[i];
    }
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++) if (fabs(a[i][k]) > fabs(a[p][k])) p = i;
        if (fabs(a[p][k]) < 1e-14) return 0;
        for (j = 0; j <= n; j++) { double t = a[k][j]; a[k][j] = a[p][j]; a[p][j] = t; }
        for (i = k + 1; i < n; i++) {
            double f = a[i][k] / a[k][k];
            for (j = k; j <= n; j++) a[i][j] -= f * a[k][j];
        }
    }
    for (i = n - 1; i >= 0; i--) {
        double s = a[i][n];
        for (j = i + 1; j < n; j++) s -= a[i][j] * x[j];
        x[i] = s / a[i][i];
    }
    return 1;
}

static double sgn_of(const scene *sc, int k, int X) { return sc->ca[k] == X ? 1.0 : (sc->cb[k] == X ? -1.0 : 0.0); }

/* relative normal velocity at contact k for body velocities (vx, vy, w) */
static double normal_velocity(const scene *sc, int k, const double *vx, const double *vy, const double *w)
{
    double u = 0;
    int X;
    for (X = 0; X < sc->nb; X++) {
        double s = sgn_of(sc, k, X), rx = sc->px[k] - sc->cx[X], ry = sc->py[k] - sc->cy[X];
        if (s == 0.0 || sc->is_static[X]) continue;
        u += s * ((vx[X] - w[X] * ry) * sc->nx[k] + (vy[X] + w[X] * rx) * sc->ny[k]);
    }
    return u;
}

/* The simultaneous-impulse LCP by enumeration of active sets; writes post velocities. */
static int simultaneous_answer(const scene *sc, double *vx2, double *vy2, double *w2, double *j)
{
    double A[MAXC][MAXC], u[MAXC], e[MAXC], zero[MAXB] = {0, 0, 0, 0};
    int i, k, X, set;
    for (i = 0; i < sc->nc; i++) {
        u[i] = normal_velocity(sc, i, sc->vx, sc->vy, zero);
        e[i] = sc->e[sc->ca[i]] < sc->e[sc->cb[i]] ? sc->e[sc->ca[i]] : sc->e[sc->cb[i]];
        for (k = 0; k < sc->nc; k++) {
            A[i][k] = 0;
            for (X = 0; X < sc->nb; X++) {
                double si = sgn_of(sc, i, X), sk = sgn_of(sc, k, X);
                if (si == 0.0 || sk == 0.0 || sc->is_static[X]) continue;
                A[i][k] += si * sk *
                           ((sc->nx[i] * sc->nx[k] + sc->ny[i] * sc->ny[k]) / sc->m[X] +
                            cross(sc->px[i] - sc->cx[X], sc->py[i] - sc->cy[X], sc->nx[i], sc->ny[i]) *
                                cross(sc->px[k] - sc->cx[X], sc->py[k] - sc->cy[X], sc->nx[k], sc->ny[k]) / sc->I[X]);
            }
        }
    }
    for (set = (1 << sc->nc) - 1; set >= 0; set--) {
        double M[MAXC][MAXC], r[MAXC], x[MAXC];
        int idx[MAXC], n = 0, ok = 1;
        for (i = 0; i < sc->nc; i++) if (set & (1 << i)) idx[n++] = i;
        for (i = 0; i < n; i++) {
            for (k = 0; k < n; k++) M[i][k] = A[idx[i]][idx[k]];
            r[i] = -(1.0 + e[idx[i]]) * u[idx[i]];
        }
        for (i = 0; i < sc->nc; i++) j[i] = 0;
        if (n && !solve(n, M, r, x)) continue;
        for (i = 0; i < n; i++) {
            if (x[i] < 0) ok = 0;
            j[idx[i]] = x[i];
        }
        for (i = 0; i < sc->nc && ok; i++) {
            double up = u[i];
            for (k = 0; k < sc->nc; k++) up += A[i][k] * j[k];
            if (up < -e[i] * u[i] - 1e-12) ok = 0;
        }
        if (!ok) continue;
        for (X = 0; X < sc->nb; X++) {
            vx2[X] = sc->vx[X];
            vy2[X] = sc->vy[X];
            w2[X] = 0;
            if (sc->is_static[X]) continue;
            for (k = 0; k < sc->nc; k++) {
                double s = sgn_of(sc, k, X);
                vx2[X] += s * j[k] * sc->nx[k] / sc->m[X];
                vy2[X] += s * j[k] * sc->ny[k] / sc->m[X];
                w2[X] += s * j[k] * cross(sc->px[k] - sc->cx[X], sc->py[k] - sc->cy[X], sc->nx[k], sc->ny[k]) / sc->I[X];
            }
        }
        return 1;
    }
    return 0;
}

static void run_scene(const scene *sc, lc_impact_mode mode)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_world_def got;
    lc_body_id id[MAXB];
    double px0, py0, L0, px1, py1, L1, ke0, ke1, pscale = 0, vscale = 0, worst_sep = INFINITY, max_ke = 0;
    double b_vx[MAXB], b_vy[MAXB], b_L[MAXB], a_vx[MAXB], a_vy[MAXB], a_w[MAXB], a_L[MAXB];
    double dpx[MAXB], dpy[MAXB], dL[MAXB];
    int X, Y, k, all_dynamic = 1, i;
    lc_counters tot;
    const lc_contact *cs;
    int nc, ncoll = 0;
    char label[96];
    snprintf(label, sizeof label, "%s (%s)", sc->name, mode == LC_IMPACT_SERIAL ? "serial" : "simultaneous");
    d.impact_mode = mode;
    w = sc_world(&d);
    if (!w) return;
    lc_world_get_def(w, &got);
    for (X = 0; X < sc->nb; X++) {
        lc_vec2 v[4];
        lc_body_def bd = lc_default_body_def();
        lc_make_rectangle(sc->w[X], sc->h[X], v);
        bd.type = sc->is_static[X] ? LC_BODY_STATIC : LC_BODY_DYNAMIC;
        bd.vertices = v;
        bd.vertex_count = 4;
        bd.position.x = sc->cx[X] - (sc->is_static[X] ? 0.0 : sc->vx[X] * T_HIT);
        bd.position.y = sc->cy[X] - (sc->is_static[X] ? 0.0 : sc->vy[X] * T_HIT);
        bd.angle = sc->ang[X];
        if (!sc->is_static[X]) {
            bd.velocity.x = sc->vx[X];
            bd.velocity.y = sc->vy[X];
            bd.mass = sc->m[X];
            pscale += sc->m[X] * hypot(sc->vx[X], sc->vy[X]);
            if (hypot(sc->vx[X], sc->vy[X]) > vscale) vscale = hypot(sc->vx[X], sc->vy[X]);
        } else {
            all_dynamic = 0;
        }
        bd.elasticity = sc->e[X];
        id[X] = sc_add(w, &bd, sc->name);
    }
    for (X = 0; X < sc->nb; X++)
        for (Y = X + 1; Y < sc->nb; Y++)
            CHECK(sc_separation(w, id[X], id[Y]) > 1e-3 || (sc->is_static[X] && sc->is_static[Y]),
                  "%s: scene check, bodies %d and %d start apart", label, X, Y);
    sc_momentum(w, &px0, &py0, &L0);
    ke0 = sc_kinetic(w);
    for (X = 0; X < sc->nb; X++) {
        const double *s = sc_row(w, id[X]);
        b_vx[X] = s[3]; b_vy[X] = s[4];
        b_L[X] = sc->m[X] * (s[0] * s[4] - s[1] * s[3]) + sc->I[X] * s[5];
    }
    /* step 0.05 s (no contact), then to 1 microsecond past the impact at t = 0.1 s, so that what
     * is read is this one event (spinning bodies may touch again soon after: in 1e-6 s a corner
     * moves < 1e-5 m, while the next nearest features are centimetres apart) */
    sc_step_n(w, 0.05, 1);
    lc_world_get_counters(w, NULL, &tot);
    CHECK(tot.collisions == 0, "%s: no collision before the impact instant", label);
    sc_step_n(w, 0.05 + 1e-6, 1);
    lc_world_get_counters(w, NULL, &tot);
    printf("%s: collision events %llu, impulses %llu, serial iterations %llu, impulse solves %llu, fallbacks %llu\n",
           label, (unsigned long long)tot.collisions, (unsigned long long)tot.impulses,
           (unsigned long long)tot.serial_iterations, (unsigned long long)tot.impulse_solves,
           (unsigned long long)tot.inelastic_fallbacks);
    CHECK(tot.collisions == 1, "%s: one impact event (all contacts at one instant), got %llu", label,
          (unsigned long long)tot.collisions);
    for (X = 0; X < sc->nb; X++) {
        const double *s = sc_row(w, id[X]);
        a_vx[X] = s[3]; a_vy[X] = s[4]; a_w[X] = s[5];
        a_L[X] = sc->m[X] * (s[0] * s[4] - s[1] * s[3]) + sc->I[X] * s[5];
        dpx[X] = dpy[X] = dL[X] = 0;
        printf("  body %d: v (%.9f, %.9f) omega %.9f\n", X, s[3], s[4], s[5]);
    }
    /* bookkeeping from the reported collision contacts */
    nc = sc_contacts(w, &cs);
    for (i = 0; i < nc; i++) {
        if (cs[i].kind != LC_CONTACT_COLLISION) continue;
        ncoll++;
        for (X = 0; X < sc->nb; X++) {
            double s = cs[i].body_a == id[X] ? 1.0 : (cs[i].body_b == id[X] ? -1.0 : 0.0);
            double jx = s * cs[i].impulse * cs[i].normal.x, jy = s * cs[i].impulse * cs[i].normal.y;
            dpx[X] += jx;
            dpy[X] += jy;
            dL[X] += cross(cs[i].point.x, cs[i].point.y, jx, jy);
        }
    }
    CHECK(ncoll >= 1, "%s: collision contacts reported", label);
    for (X = 0; X < sc->nb; X++) {
        if (sc->is_static[X]) continue;
        CHECK_NEAR(sc->m[X] * (a_vx[X] - b_vx[X]), dpx[X], 1e-9 * pscale, "m dvx = sum of reported impulses");
        CHECK_NEAR(sc->m[X] * (a_vy[X] - b_vy[X]), dpy[X], 1e-9 * pscale, "m dvy = sum of reported impulses");
        CHECK_NEAR(a_L[X] - b_L[X], dL[X], 1e-9 * pscale * 3.0, "dL = sum of P x J (|P| <= 3 m)");
    }
    /* nothing approaches after the event (geometry of the impact instant) */
    {
        double u[MAXC];
        for (k = 0; k < sc->nc; k++) {
            u[k] = normal_velocity(sc, k, a_vx, a_vy, a_w);
            CHECK(u[k] >= -got.resting_speed, "%s: contact %d still approaches at %.3e m/s", label, k, u[k]);
        }
    }
    sc_momentum(w, &px1, &py1, &L1);
    ke1 = sc_kinetic(w);
    if (all_dynamic) {
        CHECK_NEAR(px1, px0, 1e-12 * pscale, "total linear momentum x conserved");
        CHECK_NEAR(py1, py0, 1e-12 * pscale, "total linear momentum y conserved");
        CHECK_NEAR(L1, L0, 1e-12 * pscale * 3.0, "total angular momentum conserved");
    }
    CHECK(ke1 <= ke0 * (1 + 1e-12), "%s: kinetic energy increased %.12g -> %.12g", label, ke0, ke1);
    if (sc->e[0] == 1.0) CHECK_REL(ke1, ke0, 1e-6, "e = 1: kinetic energy kept");
    if (mode == LC_IMPACT_SIMULTANEOUS || sc->serial_exact) {
        double vx2[MAXB], vy2[MAXB], w2[MAXB], j[MAXC];
        CHECK(simultaneous_answer(sc, vx2, vy2, w2, j), "%s: reference LCP solved", label);
        for (X = 0; X < sc->nb; X++) {
            if (sc->is_static[X]) continue;
            printf("  expected body %d: v (%.9f, %.9f) omega %.9f\n", X, vx2[X], vy2[X], w2[X]);
            CHECK_NEAR(a_vx[X], vx2[X], 1e-8 * vscale, "simultaneous LCP vx");
            CHECK_NEAR(a_vy[X], vy2[X], 1e-8 * vscale, "simultaneous LCP vy");
            CHECK_NEAR(a_w[X], w2[X], 1e-8 * vscale, "simultaneous LCP omega");
        }
    }
    /* afterwards: no penetration, energy never grows */
    for (k = 0; k < 50; k++) {
        double ke;
        if (sc_step_n(w, 0.01, 1) != 1) break;
        for (X = 0; X < sc->nb; X++)
            for (Y = X + 1; Y < sc->nb; Y++) {
                double sp;
                if (sc->is_static[X] && sc->is_static[Y]) continue;
                sp = sc_separation(w, id[X], id[Y]);
                if (sp < worst_sep) worst_sep = sp;
            }
        ke = sc_kinetic(w);
        if (ke > max_ke) max_ke = ke;
    }
    CHECK(worst_sep >= -1e-9, "%s: overlap of %.3e m after the impact", label, -worst_sep);
    CHECK(max_ke <= ke0 * (1 + 1e-12), "%s: energy grew to %.12g from %.12g", label, max_ke, ke0);
    lc_world_destroy(w);
}

/* ---- the scenes (impact configuration at t = T_HIT) ----------------------------------------------- */

static double CG = 1e-7; /* replaced by the world's contact_gap in main */

static scene scene_one_wall(double e)
{
    scene sc;
    int blk, wall;
    memset(&sc, 0, sizeof sc);
    sc.name = e == 1.0 ? "A two corners on one wall e=1" : "A two corners on one wall e=0.5";
    blk = add_body(&sc, 0, 2.0, 1.0, 0.0, 1.0, e, 5.0 - 1.0 - CG, 0.0, 3.0, 0.5);
    wall = add_body(&sc, 1, 1.0, 20.0, 0.0, 0, 1.0, 5.5, 0.0, 0, 0);
    add_contact(&sc, blk, wall, 5.0 - CG, -0.5, -1.0, 0.0);
    add_contact(&sc, blk, wall, 5.0 - CG, 0.5, -1.0, 0.0);
    sc.serial_exact = 1;
    return sc;
}

static scene scene_one_object(double e)
{
    scene sc;
    int a, b;
    memset(&sc, 0, sizeof sc);
    sc.name = e == 1.0 ? "A2 two corners on one object e=1" : "A2 two corners on one object e=0.5";
    a = add_body(&sc, 0, 1.0, 1.0, 0.0, 1.0, e, -0.5 - CG, 0.4, 3.0, 0.0);
    b = add_body(&sc, 0, 1.0, 3.0, 0.0, 1.0, e, 0.5, 0.0, 0.0, 0.0);
    add_contact(&sc, a, b, -CG, -0.1, -1.0, 0.0);
    add_contact(&sc, a, b, -CG, 0.9, -1.0, 0.0);
    return sc;
}

static scene scene_two_walls(double e)
{
    scene sc;
    int blk, left, floor_;
    double ox1, oy1, ox2, oy2, cx, cy;
    const double th = 0.3;
    memset(&sc, 0, sizeof sc);
    sc.name = e == 1.0 ? "B two corners on two walls e=1" : "B two corners on two walls e=0.5";
    corner(1.0, 2.0, th, -1, 1, &ox1, &oy1);  /* leftmost corner */
    corner(1.0, 2.0, th, -1, -1, &ox2, &oy2); /* lowest corner */
    cx = -5.0 - ox1 + CG;
    cy = -5.0 - oy2 + CG;
    blk = add_body(&sc, 0, 1.0, 2.0, th, 1.0, e, cx, cy, -2.0, -3.0);
    left = add_body(&sc, 1, 1.0, 12.0, 0.0, 0, 1.0, -5.5, 0.0, 0, 0);
    floor_ = add_body(&sc, 1, 12.0, 1.0, 0.0, 0, 1.0, 0.0, -5.5, 0, 0);
    add_contact(&sc, blk, left, cx + ox1, cy + oy1, 1.0, 0.0);
    add_contact(&sc, blk, floor_, cx + ox2, cy + oy2, 0.0, 1.0);
    return sc;
}

static scene scene_two_objects(double e)
{
    scene sc;
    int a, b, c;
    const double phi = 0.1, s = 0.1;
    double ox, oy, dy = CG / cos(phi);
    memset(&sc, 0, sizeof sc);
    sc.name = e == 1.0 ? "C two corners on two objects e=1" : "C two corners on two objects e=0.5";
    /* A 3 x 1 lands with its bottom corners (-1.5, 0) and (1.5, 0) on the top faces of B (tilted -phi)
     * and C (tilted +phi) at face coordinates +s and -s; A is lifted by dy so both gaps are CG */
    a = add_body(&sc, 0, 3.0, 1.0, 0.0, 1.0, e, 0.0, 0.5 + dy, 0.0, -2.0);
    corner(1.0, 1.0, -phi, 2 * s, 1, &ox, &oy); /* local (s, 0.5) of B */
    b = add_body(&sc, 0, 1.0, 1.0, -phi, 1.0, e, -1.5 - ox, 0.0 - oy, 0, 0);
    corner(1.0, 1.0, phi, -2 * s, 1, &ox, &oy); /* local (-s, 0.5) of C */
    c = add_body(&sc, 0, 1.0, 1.0, phi, 1.5, e, 1.5 - ox, 0.0 - oy, 0, 0);
    add_contact(&sc, a, b, -1.5, dy, -sin(-phi), cos(-phi));
    add_contact(&sc, a, c, 1.5, dy, -sin(phi), cos(phi));
    return sc;
}

static scene scene_wedged(double e)
{
    scene sc;
    int a, b, c;
    const double th = 0.05;
    double lx, ly, rx, ry;
    memset(&sc, 0, sizeof sc);
    sc.name = e == 1.0 ? "D block wedged between two e=1" : "D block wedged between two e=0.5";
    corner(1.0, 1.0, th, -1, 1, &lx, &ly);  /* A's leftmost corner */
    corner(1.0, 1.0, th, 1, -1, &rx, &ry);  /* A's rightmost corner */
    a = add_body(&sc, 0, 1.0, 1.0, th, 1.0, e, 0.0, 0.0, 0.0, 0.0);
    b = add_body(&sc, 0, 1.0, 1.0, 0.0, 2.0, e, lx - 0.5 - CG, 0.0, 2.0, 0.0);
    c = add_body(&sc, 0, 1.0, 1.0, 0.0, 1.5, e, rx + 0.5 + CG, 0.0, -1.0, 0.0);
    add_contact(&sc, a, b, lx, ly, 1.0, 0.0);
    add_contact(&sc, a, c, rx, ry, -1.0, 0.0);
    return sc;
}

int main(void)
{
    lc_world_def d = lc_default_world_def();
    scene (*makers[5])(double) = {scene_one_wall, scene_one_object, scene_two_walls, scene_two_objects, scene_wedged};
    const double es[2] = {1.0, 0.5};
    int m, k;
    CG = d.contact_gap;
    for (m = 0; m < 5; m++)
        for (k = 0; k < 2; k++) {
            scene sc = makers[m](es[k]);
            run_scene(&sc, LC_IMPACT_SIMULTANEOUS);
            run_scene(&sc, LC_IMPACT_SERIAL);
            if (m == 0) {
                /* symmetric two corners on one wall: serial mode must not spin it either */
                double vx2[MAXB], vy2[MAXB], w2[MAXB], j[MAXC];
                CHECK(simultaneous_answer(&sc, vx2, vy2, w2, j), "%s", "reference");
                CHECK_NEAR(vx2[0], -3.0 * es[k], 1e-12, "reference check: vx' = -e vx");
                CHECK_NEAR(w2[0], 0.0, 1e-12, "reference check: no spin");
            }
        }
    return CHECK_SUMMARY("test_multi_impact");
}
