/* test_friction: Coulomb friction at resting contacts and in impulses.
 * A block resting on a flat floor under gravity tilted by theta is a block on an incline of angle theta.
 * - mu > tan(theta): static friction holds it; it must not creep (|x drift| < 1e-6 m over 2 s: the
 *   tangent target removes sliding within one step, leaving round-off-level drift).
 * - mu < tan(theta): it slides with a = g (sin theta - mu cos theta). The boxed solver is iterative
 *   (projected Gauss-Seidel); with two contacts of equal load it converges to the saturated friction
 *   force, so a relative acceleration error of 1e-6 is the stated bound.
 * - an impact with friction: a block thrown down-and-sideways onto the floor at e = 0 keeps its
 *   sideways speed reduced by at most mu * |normal impulse| / m (Coulomb cone), and exactly by that
 *   when it slides through the impact. */
#include <math.h>
#include "check.h"
#include "scenes.h"

static void incline(double theta, double mu, const char *label)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id floor_id, blk;
    double g = 9.81, x0, v_end, a_meas, a_exp;
    int i;
    d.gravity.x = g * sin(theta);
    d.gravity.y = -g * cos(theta);
    w = sc_world(&d);
    if (!w) return;
    floor_id = sc_static_box(w, 100.0, 1.0, 0.0, -0.5, 0.0);
    CHECK(lc_body_set_material(w, floor_id, 0.0, mu) == LC_OK, "floor material");
    /* resting exactly at the contact gap, at rest */
    blk = sc_box(w, 1.0, 0.5, 0.0, 0.25 + 1e-7, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    CHECK(lc_body_set_material(w, blk, 0.0, mu) == LC_OK, "block material");
    x0 = sc_row(w, blk)[0];
    for (i = 0; i < 200; ++i)
        if (sc_step_n(w, 0.01, 1) != 1) break;
    v_end = sc_row(w, blk)[3];
    a_meas = v_end / 2.0;
    a_exp = g * (sin(theta) - mu * cos(theta));
    printf("%s: theta %.3f mu %.3f -> x drift %.3e m, v %.9f m/s, a %.9f (expected %.9f)\n", label, theta, mu,
           sc_row(w, blk)[0] - x0, v_end, a_meas, a_exp > 0 ? a_exp : 0.0);
    if (a_exp <= 0.0) {
        CHECK(fabs(sc_row(w, blk)[0] - x0) < 1e-6, "%s: static friction holds (drift %.3e m)", label,
              sc_row(w, blk)[0] - x0);
    } else {
        CHECK_REL(a_meas, a_exp, 1e-6, label);
    }
    CHECK(fabs(sc_row(w, blk)[5]) < 1e-6, "%s: no spin (%.3e rad/s)", label, sc_row(w, blk)[5]);
    CHECK(sc_min_y(w, blk) > 0.0, "%s: no penetration", label);
    lc_world_destroy(w);
}

static void friction_impact(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id floor_id, blk;
    double mu = 0.2, vx0 = 3.0, vy0 = -2.0;
    const lc_contact *cs;
    int nc, i;
    double jn = 0.0, jt = 0.0;
    if (!w) return;
    floor_id = sc_static_box(w, 100.0, 1.0, 0.0, -0.5, 0.0);
    lc_body_set_material(w, floor_id, 0.0, mu);
    blk = sc_box(w, 1.0, 0.5, 0.0, 0.5, 0.0, vx0, vy0, 0.0, 1.0, 0.0);
    lc_body_set_material(w, blk, 0.0, mu);
    for (i = 0; i < 20; ++i) {
        sc_step_n(w, 0.01, 1);
        nc = sc_contacts(w, &cs);
        for (int k = 0; k < nc; ++k)
            if (cs[k].kind == LC_CONTACT_COLLISION) { jn += cs[k].impulse; jt += cs[k].tangent_impulse; }
        if (jn > 0.0) break;
    }
    printf("friction impact: normal impulse %.9f, tangent impulse %.9f, vx after %.9f\n", jn, jt, sc_row(w, blk)[3]);
    /* e = 0, mass 1: the normal impulse stops the 2 m/s approach */
    CHECK_NEAR(jn, 2.0, 1e-9, "normal impulse = m |v_n| at e = 0");
    /* sliding throughout (mu jn = 0.4 < m vx0 = 3): the friction impulse is exactly mu jn, along the
     * contact tangent (-n.y, n.x) = (-1, 0), i.e. against the sliding. Both bottom corners land at once;
     * with the friction torque the two normal impulses differ but add up to m |v_n| and leave no spin.
     * The boxed solver is iterative: 1e-9 relative is its converged residual on this 4-row problem. */
    CHECK_NEAR(jt, mu * jn, 1e-9 * jn, "Coulomb-limited friction impulse");
    CHECK_NEAR(sc_row(w, blk)[3], vx0 - mu * jn, 1e-9, "sideways speed reduced by mu jn / m");
    CHECK_NEAR(sc_row(w, blk)[5], 0.0, 1e-9, "no spin after a flat landing with friction");
    lc_world_destroy(w);
}

int main(void)
{
    incline(0.3, 0.5, "sticks (mu > tan 0.3 = 0.309)");
    incline(0.3, 0.1, "slides (mu < tan)");
    incline(0.3, 0.0, "frictionless");
    friction_impact();
    return CHECK_SUMMARY("test_friction");
}
