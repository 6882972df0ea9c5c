/* test_drop_family: the contact bench's drop12 scene over pyramid bases 6 to 20 (sc_drop_on_pyramid: a
 * 5 kg box at 8 m/s onto a frictional pyramid of unit boxes, g = 10 m/s^2, no damping), 300 steps of
 * 1/60 s each, the bench's length. One pile is one chaotic trajectory: a change to the contact regime
 * can pass drop12 (test_pyramid_drop) by moving which steps of it need a precise retry while raising
 * the gains of the steps it keeps unresolved elsewhere; over fifteen piles it shows. Asserted for every
 * base: every step returns LC_OK, no step raises the total energy by more than 1e-9 of itself
 * (nothing drives the scene, the bound for a dissipative scene), and no step is kept
 * unresolved (lc_counters contact_unresolved: a nearly resting pile that no try could advance without
 * a gain is held at rest instead, contact_regime.c). Printed per base: the steps kept unresolved and
 * what they kept, the worst step's gain, the precise retries and the state hash (a change meant to keep
 * the physics keeps every hash). */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "scenes.h"

#define FIRST_BASE 6
#define LAST_BASE 20
#define STEPS 300
#define GAIN_TOL 1e-9

int main(void)
{
    int base;
    for (base = FIRST_BASE; base <= LAST_BASE; ++base) {
        lc_world *w = sc_drop_on_pyramid(base);
        lc_counters tot;
        lc_energy en;
        double e_prev, worst = -INFINITY;
        int k, ok = 1;
        if (!w) break;
        en = sc_energy(w);
        e_prev = en.total;
        for (k = 0; k < STEPS && ok; ++k) {
            lc_status st = lc_world_step(w, 1.0 / 60.0);
            CHECK(st == LC_OK, "base %d, step %d: status %d", base, k + 1, (int)st);
            ok = st == LC_OK;
            en = sc_energy(w);
            worst = fmax(worst, (en.total - e_prev) / fabs(e_prev));
            e_prev = en.total;
        }
        CHECK(lc_world_get_counters(w, NULL, &tot) == LC_OK, "%s", "counters");
        CHECK(worst <= GAIN_TOL, "base %d: a step gained %.3g of the energy, above %g", base, worst, GAIN_TOL);
        CHECK(tot.contact_unresolved == 0, "base %d: %llu steps kept unresolved (up to %.3g J)", base,
              (unsigned long long)tot.contact_unresolved, tot.max_unresolved_energy);
        printf("base %2d (%3d bodies): %llu steps unresolved keeping up to %.3g J, worst step gain %.3g, "
               "precise retries %llu, hash %016llx\n",
               base, base * (base + 1) / 2 + 1, (unsigned long long)tot.contact_unresolved,
               tot.max_unresolved_energy, worst, (unsigned long long)tot.contact_precise_retries,
               (unsigned long long)lc_world_state_hash(w));
        lc_world_destroy(w);
    }
    return CHECK_SUMMARY("test_drop_family");
}
