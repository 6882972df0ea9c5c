/* probe_pyramid.c - CPU time per step of Box2D's large-pyramid layout straight through the C API (no
 * Python), for before/after comparisons of engine changes that the cffi benchmark's noise would hide.
 * The layout of bench/scenes.py's pyramid(base): unit boxes (1 kg, e 0, mu 0.6) in rows that touch,
 * on a static ground box, g = 10, dt = 1/60.
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include bench/repro/probe_pyramid.c build/libcollide.a -lm \
 *      -o /tmp/probe_pyramid && /tmp/probe_pyramid [base 20] [steps 300] [repeats 5]
 * Prints the median over repeats of the mean CPU time per step (the first step, which starts the pile
 * from its static load, excluded), force evaluations per step, and how far the top box moved. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "collide/collide.h"

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int add_box(lc_world *w, double width, double height, double x, double y, int is_static)
{
    lc_vec2 corners[4];
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_make_rectangle(width, height, corners);
    b.vertices = corners;
    b.vertex_count = 4;
    b.position.x = x;
    b.position.y = y;
    b.elasticity = 0.0;
    b.friction = 0.6;
    if (is_static) b.type = LC_BODY_STATIC;
    if (lc_world_add_body(w, &b, &id) != LC_OK) {
        fprintf(stderr, "%s\n", lc_world_last_error(w));
        return -1;
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    int base = argc > 1 ? atoi(argv[1]) : 20, steps = argc > 2 ? atoi(argv[2]) : 300;
    int repeats = argc > 3 ? atoi(argv[3]) : 5, r, i, j, k, top;
    double per_step[64], moved = 0.0, evals = 0.0;
    if (base < 1 || base > 200 || steps < 2 || repeats < 1 || repeats > 64) {
        fprintf(stderr, "usage: probe_pyramid [base 1..200] [steps >= 2] [repeats 1..64]\n");
        return 2;
    }
    for (r = 0; r < repeats; ++r) {
        lc_world_def d = lc_default_world_def();
        char msg[256];
        lc_world *w;
        lc_state_view v;
        lc_counters c;
        double t0, y0;
        d.gravity.x = 0.0;
        d.gravity.y = -10.0;
        w = lc_world_create(&d, msg, sizeof msg);
        if (w == NULL) {
            fprintf(stderr, "%s\n", msg);
            return 1;
        }
        for (i = 0; i < base; ++i)
            for (j = i; j < base; ++j)
                if (add_box(w, 1.0, 1.0, (i + 1.0) * 0.5 + (j - i) * 1.0 - 0.5 * base, 0.5 + i * 1.0, 0)) return 1;
        if (add_box(w, 2.0 * base + 20.0, 1.0, 0.0, -0.5, 1)) return 1;
        top = base * (base + 1) / 2 - 1;   /* the last box added is the top one */
        if (lc_world_step(w, 1.0 / 60.0) != LC_OK) {
            fprintf(stderr, "step 0: %s\n", lc_world_last_error(w));
            return 1;
        }
        lc_world_get_state(w, &v);
        y0 = v.state[top * 6 + 1];
        t0 = cpu_seconds();
        for (k = 1; k < steps; ++k)
            if (lc_world_step(w, 1.0 / 60.0) != LC_OK) {
                fprintf(stderr, "step %d: %s\n", k, lc_world_last_error(w));
                return 1;
            }
        per_step[r] = (cpu_seconds() - t0) / (steps - 1);
        lc_world_get_counters(w, NULL, &c);
        evals = (double)c.force_evaluations / steps;
        lc_world_get_state(w, &v);
        moved = fabs(v.state[top * 6 + 1] - y0);
        lc_world_destroy(w);
    }
    qsort(per_step, (size_t)repeats, sizeof(double), cmp_double);
    printf("pyramid base %d: %.3f ms per step (median of %d x %d steps), %.2f force evaluations per step, "
           "top box moved %.2e m\n", base, 1e3 * per_step[repeats / 2], repeats, steps - 1, evals, moved);
    return 0;
}
