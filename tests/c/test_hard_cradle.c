/* test_hard_cradle (docs/hard_cases.md): an exact answer, run for 60 s at dt = 1/60 s, e = 1, no
 * friction, no damping, every other setting the engine's default (serial impacts).
 * (5) Newton's cradle in a walled channel (g = 0): a 1 m x 0.5 m 1 kg striker at 5 m/s into five
 *     such blocks 5 cm apart, and into five such blocks with end faces touching; the channel's walls
 *     (inner faces x = -1.5 and x = 9) send the outgoing block back, so the chain runs back and forth ~40 times.
 *     Exact (sequential e = 1 exchanges between equal masses, face-on): at every step end exactly
 *     one block moves, at |vx| = 5 m/s, the others are at rest; no vy, no spin; the blocks keep
 *     their order. Tolerances: speeds 1e-6 m/s (serial passes stop once no contact approaches
 *     faster than a small threshold), vy and omega 1e-9 (symmetric two-point
 *     impulses: round-off only), kinetic energy 12.5 J to 1e-9 relative, |px| = 5 kg m/s to 1e-6.
 *
 *
 * The exact answer is asserted for the first T_EXACT = 3.5 s only, because the aligned motion is
 * unstable and round-off is amplified by the physics, not by the engine. A block tilted by theta
 * that is the reference face of a face-on impact pushes its neighbour along its own face normal,
 * whose line of action misses the neighbour's centre by (centre distance) * theta = 1 m * theta; with
 * the 5 N s impulse and I = 0.104 kg m^2 that spins the neighbour by ~48 theta rad/s, which turns it
 * by ~24 theta before its next impact 0.5 s later: a gain of ~20 per pass along the row. Measured:
 * the largest spin goes 1e-15 (round-off of the first symmetric impulse) -> 6e-12 (3 s) -> 4e-9 (5 s)
 * -> 5e-5 rad/s (8 s), after which a block tilted by 5e-5 rad (25 um over its 0.5 m face, far more
 * than the 1e-7 m contact gap) meets its neighbour corner first and the row breaks up, as a real
 * row would. No finite precision keeps the exact answer for 60 s; at 3.5 s the spin is ~1e-11, 100x
 * inside the 1e-9 bound. The whole 60 s still runs and is held to what the physics guarantees for
 * any motion: kinetic energy to 1e-9 relative (e = 1 impulses by Poisson's rule keep it exactly),
 * and the monitor's containment and no-overlap checks at every step end. */
#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

/* Exact answer asserted up to here (s); see the header. */
#define T_EXACT 3.5

/* ---- (5) Newton's cradle ------------------------------------------------------------------- */
static void cradle(double gap, const char *label)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_body_id walls[4], b[6];
    const double box[4] = {-1.5, -2.0, 9.0, 2.0};
    double ke0, max_rest = 0, max_vyw = 0, max_dke = 0, max_dp = 0, t_rest = 0;
    int i, k, bad_count = 0, bad_order = 0, sign_changes = 0, prev_sign = 1;
    hc_mon m;
    if (!w) return;
    hc_walls(w, -1.5, -2.0, 9.0, 2.0, 1.0, 0.0, walls);
    b[0] = hc_box(w, 1.0, 0.5, 0.0, 0.0, 0.0, 5.0, 0, 0, 1.0, 1.0, 0.0);
    for (i = 1; i <= 5; i++) b[i] = hc_box(w, 1.0, 0.5, 2.0 + (i - 1) * (1.0 + gap), 0.0, 0.0, 0, 0, 0, 1.0, 1.0, 0.0);
    if (!hc_mon_init(&m, w, label, HC_DT, box)) { lc_world_destroy(w); return; }
    m.max_collisions = 100000; /* ~80 chain passes x 6 impacts; measured in the hundreds */
    ke0 = sc_kinetic(w);
    for (k = 1; k <= HC_STEPS; k++) {
        int moving = 0;
        double px, py, L;
        if (!hc_step(&m)) break;
        if (fabs(sc_kinetic(w) - ke0) > max_dke) max_dke = fabs(sc_kinetic(w) - ke0);
        if (lc_world_get_time(w) > T_EXACT) continue;
        for (i = 0; i <= 5; i++) {
            const double *s = sc_row(w, b[i]);
            double rest = fabs(fabs(s[3]) - 5.0) < 1e-6 ? 0.0 : fabs(s[3]);
            if (fabs(fabs(s[3]) - 5.0) < 1e-6) moving++;
            else if (rest > max_rest) { max_rest = rest; t_rest = lc_world_get_time(w); }
            if (fabs(s[4]) > max_vyw) max_vyw = fabs(s[4]);
            if (fabs(s[5]) > max_vyw) max_vyw = fabs(s[5]);
            if (i > 0 && !(sc_row(w, b[i - 1])[0] < s[0])) bad_order++;
        }
        if (moving != 1) bad_count++;
        sc_momentum(w, &px, &py, &L);
        if (fabs(fabs(px) - 5.0) > max_dp) max_dp = fabs(fabs(px) - 5.0);
        if ((px > 0 ? 1 : -1) != prev_sign) { sign_changes++; prev_sign = px > 0 ? 1 : -1; }
    }
    hc_finish(&m, HC_STEPS);
    printf("%s (first %.1f s): steps without exactly one block at 5 m/s %d, largest resting speed %.3e m/s (t = %.3f), "
           "max |vy|,|omega| %.3e, max |dKE| %.3e J, max ||px| - 5| %.3e, momentum reversals %d\n",
           label, T_EXACT, bad_count, max_rest, t_rest, max_vyw, max_dke, max_dp, sign_changes);
    CHECK(bad_count == 0, "%s: %d step ends without exactly one block moving at 5 m/s", label, bad_count);
    CHECK(max_rest <= 1e-6, "%s: a block that should rest moves at %.3e m/s (t = %.3f)", label, max_rest, t_rest);
    CHECK(max_vyw <= 1e-9, "%s: vy or omega reached %.3e", label, max_vyw);
    CHECK(bad_order == 0, "%s: blocks out of order at %d step ends", label, bad_order);
    CHECK(max_dke <= 1e-9 * ke0, "%s: kinetic energy changed by %.3e J", label, max_dke);
    CHECK(max_dp <= 1e-6, "%s: |px| off 5 kg m/s by %.3e", label, max_dp);
    /* by 3.5 s the row has sent the moving block into the right wall (0.7 s) and the left (1.6 s) */
    CHECK(sign_changes >= 2, "%s: momentum reversed only %d times by %.1f s (the chain stopped?)", label, sign_changes,
          T_EXACT);
    hc_mon_free(&m);
    lc_world_destroy(w);
}

int main(void)
{
    cradle(0.05, "cradle, 5 cm gaps");
    /* Touching: each exchange is a simultaneous impact of the whole row, resolved by serial passes
     * into the sequential answer. After the row breaks up, blocks part slowly after an impact while
     * their rotation turns them back; a separating touch goes free (event_touches.c, lc_event_resting)
     * rather than being held by contact forces, which would add energy (4.8e-8 J, 3.8e-9 of E0, here;
     * measured -1.7e-9 J as it is). */
    cradle(0.0, "cradle, touching");
    return CHECK_SUMMARY("test_hard_cradle");
}
