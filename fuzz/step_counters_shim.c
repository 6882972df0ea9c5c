/* A replay aid, not part of the library or the harness: prints every step's status, solver work,
 * force evaluations and error message while fuzz_step.c replays an input. Linked with GNU ld's
 * -Wl,--wrap=lc_world_step, so the harness's calls land here and __real_lc_world_step is the
 * library's step (build command: fuzz/corpus/step-slow/README.md). */
#include <stdio.h>

#include "collide/collide.h"

lc_status __real_lc_world_step(lc_world *world, double dt);
lc_status __wrap_lc_world_step(lc_world *world, double dt);

lc_status __wrap_lc_world_step(lc_world *world, double dt)
{
    lc_status s = __real_lc_world_step(world, dt);
    lc_counters last, total;
    lc_world_get_counters(world, &last, &total);
    fprintf(stderr, "step: status %d, solver_work %.4g, force evaluations %llu%s%s\n", (int)s,
            (double)last.solver_work, (unsigned long long)last.force_evaluations, s != LC_OK ? ", " : "",
            s != LC_OK ? lc_world_last_error(world) : "");
    return s;
}
