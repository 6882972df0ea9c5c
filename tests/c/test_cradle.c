/* test_cradle: Newton's cradle. A 1 m, 1 kg striker at 5 m/s hits a row of five 1 m, 1 kg blocks,
 * e = 1, g = 0, no damping.
 * - serial mode, touching row (gaps = contact_gap, the engine's touching distance): only the last
 *   block moves, at 5 m/s; striker and the others stop.
 * - serial and simultaneous mode, 5 cm gaps: separate two-body impacts; same outcome.
 * - simultaneous mode, touching row: one complementarity problem over the 5 contacts. With every
 *   impulse active: u1 - u0 = 5 (restitution 1 at the struck contact), u1 = ... = u5 (the touching
 *   contacts, relative velocity 0 before, must not approach after), momentum u0 + 5 u1 = 5
 *   -> u1..u5 = 5/3 m/s, striker u0 = -10/3 m/s (impulses 25/3, 20/3, 5, 10/3, 5/3 > 0, so the
 *   guess is the LCP solution); kinetic energy (100/9 + 5 * 25/9)/2 = 12.5 J is conserved too.
 * Tolerances: velocities 1e-6 m/s (serial passes stop once no contact approaches
 * faster than a small threshold; exact two-body e = 1 swaps are round-off);
 * energy 1e-6 relative (a 1e-6 m/s residual on a 5 m/s body is 5e-6 J of 12.5 J);
 * momentum 1e-12 relative (equal and opposite impulses: round-off only). */
#include "check.h"
#include "scenes.h"

static void cradle(lc_impact_mode mode, double gap, const char *label)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w;
    lc_world_def got;
    lc_body_id ids[6];
    double cg, px0, py0, L0, px1, py1, L1, ke0, ke1, spacing;
    int i;
    lc_counters tot;
    d.impact_mode = mode;
    w = sc_world(&d);
    if (!w) return;
    lc_world_get_def(w, &got);
    cg = got.contact_gap;
    spacing = 1.0 + (gap > 0 ? gap : cg);
    ids[0] = sc_box(w, 1.0, 1.0, -2.0, 0.0, 0.0, 5.0, 0.0, 0.0, 1.0, 1.0);
    for (i = 1; i <= 5; i++) ids[i] = sc_box(w, 1.0, 1.0, (i - 1) * spacing, 0.0, 0.0, 0, 0, 0, 1.0, 1.0);
    sc_momentum(w, &px0, &py0, &L0);
    ke0 = sc_kinetic(w);
    sc_step_n(w, 0.01, 100);
    lc_world_get_counters(w, NULL, &tot);
    printf("%s: collisions %llu impulses %llu serial iterations %llu impulse solves %llu\n", label,
           (unsigned long long)tot.collisions, (unsigned long long)tot.impulses,
           (unsigned long long)tot.serial_iterations, (unsigned long long)tot.impulse_solves);
    /* One impact event per real impact: 1 for the touching row (all contacts at one instant),
     * 5 with gaps. Touching co-moving or resting blocks (relative normal velocity 0) are not
     * impacts; allow a factor 2 for events the engine may split. */
    CHECK(tot.collisions <= 10, "%s: %llu collision events for at most 5 impacts", label,
          (unsigned long long)tot.collisions);
    for (i = 0; i <= 5; i++) {
        const double *s = sc_row(w, ids[i]);
        double expect;
        if (mode == LC_IMPACT_SIMULTANEOUS && gap <= 0)
            expect = (i == 0) ? -10.0 / 3.0 : 5.0 / 3.0;
        else
            expect = (i == 5) ? 5.0 : 0.0;
        printf("  %s block %d: vx %.12f vy %.3e omega %.3e\n", label, i, s[3], s[4], s[5]);
        CHECK_NEAR(s[3], expect, 1e-6, label);
        CHECK_NEAR(s[4], 0.0, 1e-6, "no sideways velocity");
        CHECK_NEAR(s[5], 0.0, 1e-6, "no spin");
        if (i > 0) {
            double sep = sc_separation(w, ids[i - 1], ids[i]);
            CHECK(sep >= -1e-9, "%s: blocks %d and %d overlap by %.3e m", label, i - 1, i, -sep);
        }
    }
    sc_momentum(w, &px1, &py1, &L1);
    ke1 = sc_kinetic(w);
    CHECK_NEAR(px1, px0, 1e-12 * px0, "linear momentum conserved");
    CHECK_NEAR(py1, py0, 1e-12 * px0, "no vertical momentum");
    CHECK_REL(ke1, ke0, 1e-6, "kinetic energy conserved at e = 1");
    lc_world_destroy(w);
}

int main(void)
{
    cradle(LC_IMPACT_SERIAL, 0.0, "serial touching");
    cradle(LC_IMPACT_SERIAL, 0.05, "serial 5 cm gaps");
    cradle(LC_IMPACT_SIMULTANEOUS, 0.05, "simultaneous 5 cm gaps");
    cradle(LC_IMPACT_SIMULTANEOUS, 0.0, "simultaneous touching");
    return CHECK_SUMMARY("test_cradle");
}
