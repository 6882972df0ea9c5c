/* libcollide: a 0.05 m x 2.4 m sliver (1e-9 kg, e = 1e-9) moving up at 1e6 m/s (allowed: |v| <= 1e8)
 * inside the walled box, one 1 ms step (a fuzz_step regression input). Prints the sliver's vertices,
 * which must end at or below the top wall's inner face y = 6 (the failure this guards against: the
 * step ending ~2 mm inside the wall). */
#include <math.h>
#include <stdio.h>
#include "collide/collide.h"
int main(void) {
    lc_world_def d = lc_default_world_def();
    lc_world *w = lc_world_create(&d, NULL, 0);
    lc_vec2 v[4], wv[4];
    lc_body_def b = lc_default_body_def();
    lc_body_id id, walls[4];
    lc_status s;
    int k;
    lc_world_add_walls(w, -6, -6, 6, 6, 1, 1, walls);
    lc_make_rectangle(0.05, 2.4045098039215688, v);
    b.vertices = v; b.vertex_count = 4;
    b.position.x = 3.8588235294117652; b.position.y = -4.9254901960784316; b.angle = 2.5055558098725879;
    b.velocity.x = -6.1959258411535822; b.velocity.y = 1e6; b.angular_velocity = 1e-9;
    b.mass = 1e-9; b.elasticity = 1e-9; b.friction = 0.79177538719768059;
    s = lc_world_add_body(w, &b, &id); printf("add %s\n", lc_status_string(s));
    s = lc_world_step(w, 0.001);
    lc_body_get_world_vertices(w, id, wv, 4);
    printf("step %s; top wall inner face y = 6, body vertices:", lc_status_string(s));
    for (k = 0; k < 4; ++k) printf(" (%.6f, %.6f)", wv[k].x, wv[k].y);
    printf("\n");
    lc_world_destroy(w);
    return 0;
}
