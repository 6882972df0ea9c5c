/* pile_products.c - work of the contact-force solves in Box2D's resting large pyramid (bench/scenes.py's
 * pyramid(base), unit boxes on a ground box, all with mu 0.6, g = 10, dt = 1/60): force
 * evaluations, contact solves and products A x of the large-group solver (sparse_lcp.c) per step, for
 * changes to that solver. The first step (the cold start from the static load) is left out.
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include -Itests/c bench/repro/pile_products.c \
 *      build/libcollide.a -lm -o /tmp/pile_products && /tmp/pile_products [base 20] [steps 300] [order 0]
 * order 0 adds the ground after the boxes, as the benchmark does; 1 before them. The two differ only in
 * round-off (row order), and the solves' work per step is that sensitive: compare changes over both
 * orders and several bases, not one run.
 * Prints every tenth of the run's steps and any step over 200 products, then the means per step and
 * the largest. */
#include <stdio.h>
#include <stdlib.h>

#include "test_hard_common.h"

int main(int argc, char **argv)
{
    int base = argc > 1 ? atoi(argv[1]) : 20, steps = argc > 2 ? atoi(argv[2]) : 300, i;
    int ground_first = argc > 3 ? atoi(argv[3]) : 0;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_counters last, total, start;
    unsigned long long most = 0;
    if (base < 1 || steps < 10) {
        fprintf(stderr, "usage: pile_products [base >= 1] [steps >= 10]\n");
        return 2;
    }
    d.gravity.y = -10.0;
    w = sc_world(&d);
    if (ground_first) hc_static(w, 2.0 * base + 20.0, 1.0, 0.0, -0.5, 0.0, 0.6);
    sc_pyramid(w, base, 0.6, NULL);
    if (!ground_first) hc_static(w, 2.0 * base + 20.0, 1.0, 0.0, -0.5, 0.0, 0.6);
    if (sc_step_n(w, 1.0 / 60.0, 1) != 1) return 1;
    lc_world_get_counters(w, &last, &start);
    for (i = 0; i < steps; i++) {
        if (sc_step_n(w, 1.0 / 60.0, 1) != 1) return 1;
        lc_world_get_counters(w, &last, &total);
        if (last.contact_solve_iterations > most) most = last.contact_solve_iterations;
        if (i % (steps / 10) == 0 || last.contact_solve_iterations > 200)
            printf("step %4d: %llu force evaluations, %llu solves, %4llu products, residual %.2e m/s^2\n", i + 1,
                   (unsigned long long)last.force_evaluations, (unsigned long long)last.contact_solves,
                   (unsigned long long)last.contact_solve_iterations, last.max_lcp_residual);
    }
    printf("pyramid base %d (ground %s), %d steps: per step %.2f force evaluations, %.2f solves, %.2f products (most %llu)\n",
           base, ground_first ? "first" : "last", steps, (double)(total.force_evaluations - start.force_evaluations) / steps,
           (double)(total.contact_solves - start.contact_solves) / steps,
           (double)(total.contact_solve_iterations - start.contact_solve_iterations) / steps, most);
    lc_world_destroy(w);
    return 0;
}
