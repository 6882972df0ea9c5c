/* libcollide: a 1e-300 kg body with a 8.9 N*m torque spins up so fast that the rotation-limited
 * trial interval (0.25 rad / omega) becomes smaller than an ulp of the remaining step time, where
 * remaining -= trial changes nothing (a fuzz_step regression input). lc_world_step must still return:
 * it ends at the max_events_per_step cap with LC_ERR_NUMERIC and the step undone. */
#include <stdio.h>
#include "collide/collide.h"
int main(void) {
    lc_world_def d = lc_default_world_def();
    lc_world *w = lc_world_create(&d, NULL, 0);
    lc_vec2 v[4], f = {0.0, 1.0};
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_status s;
    lc_world_add_walls(w, -6, -6, 6, 6, 1, 1, NULL);
    lc_make_rectangle(0.05, 0.158, v);
    b.vertices = v; b.vertex_count = 4; b.mass = 1e-300;
    s = lc_world_add_body(w, &b, &id); printf("add %s\n", lc_status_string(s));
    s = lc_body_set_external(w, id, f, 8.86); printf("external %s\n", lc_status_string(s));
    fflush(stdout);
    s = lc_world_step(w, 0.001);  /* LC_ERR_NUMERIC at the interval cap, not an endless loop */
    printf("step: %s %s\n", lc_status_string(s), lc_world_last_error(w));
    lc_world_destroy(w);
    return 0;
}
