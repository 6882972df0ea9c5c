/* free_flight_states.c - probe_scaling.c's scene (n seed blocks, e = 1, g = 0, walls sized for n / 0.8
 * cells of 2 m) after a fixed number of 1/60 s steps: writes every body's state (count x 6 doubles: x, y,
 * angle, vx, vy, omega) to a file and prints the relative energy drift, so that two libraries (built
 * from two commits) can be compared body by body:
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include -Itests/c bench/repro/free_flight_states.c \
 *      -L<lib dir> -lcollide -Wl,-rpath,<lib dir> -lm -o /tmp/ffs && /tmp/ffs 500 60 /tmp/states.bin
 *   python -c "import numpy as np,sys; a,b=(np.fromfile(f).reshape(-1,6) for f in sys.argv[1:]); \
 *      print(np.hypot(*(a[:,:2]-b[:,:2]).T).max())" /tmp/a.bin /tmp/b.bin   # largest position difference, m */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "test_hard_common.h"

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 500, steps = argc > 2 ? atoi(argv[2]) : 60, i, cells;
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id walls[4];
    lc_energy e0, e1;
    lc_state_view sv;
    sc_rng rng;
    FILE *out;
    if (argc < 4 || n < 1 || n > 100000 || steps < 0) {
        fprintf(stderr, "usage: free_flight_states n steps out.bin\n");
        return 2;
    }
    cells = (int)ceil(sqrt(n / 0.8));
    d.gravity.y = 0.0;
    d.damping = 0.0;
    w = sc_world(&d);
    hc_walls(w, 0.0, 0.0, 2.0 * cells, 2.0 * cells, 1.0, 0.0, walls);
    rng.s = 11;
    for (i = 0; i < n; i++)
        hc_box(w, 1.0, 0.5, 1.0 + 2.0 * (i % cells), 1.0 + 2.0 * (i / cells), sc_uniform(&rng, 0.0, SC_PI),
               sc_uniform(&rng, -3, 3), sc_uniform(&rng, -3, 3), sc_uniform(&rng, -2, 2), 1.0, 1.0, 0.0);
    e0 = sc_energy(w);
    if (sc_step_n(w, 1.0 / 60.0, steps) != steps) return 1;
    e1 = sc_energy(w);
    if (lc_world_get_state(w, &sv) != LC_OK || (out = fopen(argv[3], "wb")) == NULL) return 1;
    if (fwrite(sv.state, sizeof(double), (size_t)sv.count * 6, out) != (size_t)sv.count * 6) return 1;
    fclose(out);
    printf("%d blocks, %d steps: relative energy drift %.3g\n", n, steps, (e1.total - e0.total) / e0.total);
    lc_world_destroy(w);
    return 0;
}
