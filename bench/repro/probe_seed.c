/* probe_seed.c - CPU time per step of a seed-like scene straight through the C API (no Python), for
 * before/after comparisons of engine changes that the cffi benchmark's run-to-run noise would hide.
 * 20 blocks 1 m x 0.5 m, 1 kg, e = 1, at random cells of a 2 m grid in a walled 10 m box, random angle,
 * v in [-3, 3]^2 m/s, omega in [-2, 2] rad/s (a fixed xorshift generator, not bench/scenes.py's).
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include bench/repro/probe_seed.c build/libcollide.a -lm \
 *      -o /tmp/probe_seed && /tmp/probe_seed [blocks 20] [g 0] [steps 600] [repeats 10]
 * Prints the mean CPU time per step over all repeats and the relative energy error of the last one;
 * for a comparison, build it against both libraries and alternate the runs. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "collide/collide.h"

static lc_vec2 vec(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double uniform(unsigned long long *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static int add_box(lc_world *w, double width, double height, lc_vec2 at, double angle, lc_vec2 v, double omega,
                   int is_static)
{
    lc_vec2 corners[4];
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_make_rectangle(width, height, corners);
    b.vertices = corners;
    b.vertex_count = 4;
    b.position = at;
    b.angle = angle;
    b.velocity = v;
    b.angular_velocity = omega;
    if (is_static) b.type = LC_BODY_STATIC;
    if (lc_world_add_body(w, &b, &id) != LC_OK) {
        fprintf(stderr, "%s\n", lc_world_last_error(w));
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 20, steps = argc > 3 ? atoi(argv[3]) : 600;
    int repeats = argc > 4 ? atoi(argv[4]) : 10, r, k;
    double g = argc > 2 ? atof(argv[2]) : 0.0, total = 0.0, err = 0.0;
    unsigned long long seed = 88172645463325252ULL;
    if (n < 1 || n > 25 || steps < 1 || repeats < 1) {
        fprintf(stderr, "usage: probe_seed [blocks 1..25] [g] [steps] [repeats]\n");
        return 2;
    }
    for (r = 0; r < repeats; ++r) {
        lc_world_def d = lc_default_world_def();
        char msg[256];
        lc_world *w;
        lc_energy e0, e1;
        int used[25] = {0};
        double t0;
        d.gravity = vec(0.0, -g);
        w = lc_world_create(&d, msg, sizeof msg);
        if (w == NULL) {
            fprintf(stderr, "%s\n", msg);
            return 1;
        }
        for (k = 0; k < n; ++k) {
            int c;
            do c = (int)(uniform(&seed) * 25.0); while (c > 24 || used[c]);
            used[c] = 1;
            if (add_box(w, 1.0, 0.5, vec(1.0 + 2.0 * (c % 5), 1.0 + 2.0 * (c / 5)), uniform(&seed) * 3.14159,
                        vec(6.0 * uniform(&seed) - 3.0, 6.0 * uniform(&seed) - 3.0), 4.0 * uniform(&seed) - 2.0, 0))
                return 1;
        }
        if (add_box(w, 12.0, 1.0, vec(5.0, -0.5), 0.0, vec(0, 0), 0.0, 1) ||
            add_box(w, 12.0, 1.0, vec(5.0, 10.5), 0.0, vec(0, 0), 0.0, 1) ||
            add_box(w, 1.0, 12.0, vec(-0.5, 5.0), 0.0, vec(0, 0), 0.0, 1) ||
            add_box(w, 1.0, 12.0, vec(10.5, 5.0), 0.0, vec(0, 0), 0.0, 1))
            return 1;
        lc_world_get_energy(w, &e0);
        t0 = cpu_seconds();
        for (k = 0; k < steps; ++k)
            if (lc_world_step(w, 1.0 / 60.0) != LC_OK) {
                fprintf(stderr, "step %d: %s\n", k, lc_world_last_error(w));
                return 1;
            }
        total += cpu_seconds() - t0;
        lc_world_get_energy(w, &e1);
        err = fabs(e1.total - e0.total) / fabs(e0.total);
        lc_world_destroy(w);
    }
    printf("%d blocks, g %g: %.2f us per step (mean of %d x %d steps), relative energy error %.2e\n", n, g,
           1e6 * total / ((double)steps * repeats), repeats, steps, err);
    return 0;
}
