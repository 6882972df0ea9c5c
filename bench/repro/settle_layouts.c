/* settle_layouts.c - the hard-case settling scene (tests/c/test_hard_settle.c: 20 blocks 1 m x 0.5 m,
 * e 0.8, mu 0.5, g 9.8, in a walled 10 m box, random cells, angles and velocities) over many random
 * layouts: impacts between 10 s and 30 s of each. The scene comes to rest in ~6 s, so late impacts
 * are a block that does not settle (a hopping block: docs/physics.md "Resting contact").
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include -Itests/c bench/repro/settle_layouts.c \
 *      build/libcollide.a -lm -o /tmp/settle_layouts && /tmp/settle_layouts [layouts 24]
 * Layout k uses sc_rng seed k (the test's is seed 1). Prints each layout with late impacts, then the
 * total and the number of such layouts. */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "scenes.h"
#include "test_hard_common.h"

static unsigned long long late_impacts(unsigned seed)
{
    const double g = 9.8, e = 0.8, mu = 0.5;
    lc_world_def d = lc_default_world_def();
    lc_body_id b[20];
    lc_counters c0, c1;
    int k;
    lc_world *w;
    d.gravity.y = -g;
    w = sc_world(&d);
    if (!w) return 0;
    hc_settling_layout(w, seed, e, mu, b);
    memset(&c0, 0, sizeof c0);
    for (k = 1; k <= 1800; k++) {
        if (lc_world_step(w, 1.0 / 60.0) != LC_OK) {
            fprintf(stderr, "layout %u, step %d: %s\n", seed, k, lc_world_last_error(w));
            break;
        }
        if (k == 600) lc_world_get_counters(w, NULL, &c0);
    }
    lc_world_get_counters(w, NULL, &c1);
    lc_world_destroy(w);
    return c1.collisions - c0.collisions;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 24, k, with = 0;
    unsigned long long total = 0;
    if (n < 1 || n > 100000) {
        fprintf(stderr, "usage: settle_layouts [layouts 1..100000]\n");
        return 2;
    }
    for (k = 1; k <= n; k++) {
        unsigned long long late = late_impacts((unsigned)k);
        if (late > 0) {
            printf("layout %d: %llu impacts between 10 s and 30 s\n", k, late);
            with++;
        }
        total += late;
    }
    printf("%d layouts: %llu impacts between 10 s and 30 s, in %d layouts\n", n, total, with);
    return 0;
}
