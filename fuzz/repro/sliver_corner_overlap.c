/* libcollide: default settings, one 0.05 m x 0.716 m sliver (0.1 kg, e = 0, friction 0) thrown at
 * (-6.6, -10) m/s spinning at -5 rad/s into the bottom-left corner of the walled box, dt = 0.044 s
 * (a fuzz_step regression input, with ordinary values). Prints the lowest and leftmost vertex after
 * each step: neither may pass the walls' inner faces at -6 (the failure this guards against: the
 * third step ending ~0.3 mm inside the bottom wall). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include "collide/collide.h"
int main(void) {
    lc_world_def d = lc_default_world_def();
    lc_world *w = lc_world_create(&d, NULL, 0);
    lc_vec2 v[4], wv[4];
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_status s;
    int k, step;
    lc_world_add_walls(w, -6, -6, 6, 6, 1, 1, NULL);
    lc_make_rectangle(0.05, 0.71607843137254912, v);
    b.vertices = v; b.vertex_count = 4;
    b.position.x = -5.3019607843137253; b.position.y = -5.3019607843137253; b.angle = -2.1207843137254905;
    b.velocity.x = -6.6274509803921564; b.velocity.y = -10; b.angular_velocity = -5;
    b.mass = 0.1; b.elasticity = 0.0; b.friction = 0.0;
    s = lc_world_add_body(w, &b, &id); printf("add %s\n", lc_status_string(s));
    for (step = 0; step < 6; ++step) {
        double ymin = INFINITY, xmin = INFINITY;
        s = lc_world_step(w, 0.044);
        lc_body_get_world_vertices(w, id, wv, 4);
        for (k = 0; k < 4; ++k) { ymin = fmin(ymin, wv[k].y); xmin = fmin(xmin, wv[k].x); }
        printf("step %d %s: lowest vertex y = %.9f, leftmost x = %.9f (walls' inner faces at -6)\n", step,
               lc_status_string(s), ymin, xmin);
    }
    lc_world_destroy(w);
    return 0;
}
