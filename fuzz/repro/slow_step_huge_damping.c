/* libcollide: with damping 1e6 N*s/m (allowed up to 1e9), one 1 ms step of a 0.1 kg triangle (a
 * fuzz_step regression input). Prints the step's status and force evaluations: the step's work is
 * bounded (a few thousand evaluations, the step undone with LC_ERR_NUMERIC), where integrating the stiff
 * damping to the end takes ~9e6 evaluations, seconds of CPU. */
#include <stdio.h>
#include "collide/collide.h"
int main(void) {
    lc_world_def d = lc_default_world_def();
    d.damping = 1e6; /* allowed: [0, 1e9] N*s/m */
    lc_world *w = lc_world_create(&d, NULL, 0);
    lc_vec2 v[3] = {{0.052648203250171666, 0}, {-0.026324101625085822, 0.045594681478255114},
                    {-0.026324101625085857, -0.0455946814782551}};
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_counters c;
    lc_status s;
    lc_world_add_walls(w, -6, -6, 6, 6, 1, 1, NULL);
    b.vertices = v; b.vertex_count = 3; b.mass = 0.1; b.elasticity = 0.0;
    b.position.x = -8; b.position.y = -8; b.angle = -3.2;
    b.velocity.x = -10; b.velocity.y = -10; b.angular_velocity = -5;
    s = lc_world_add_body(w, &b, &id); printf("add %s\n", lc_status_string(s));
    s = lc_world_step(w, 0.001);
    lc_world_get_counters(w, &c, NULL);
    printf("step: %s, force evaluations %llu, collisions %llu\n", lc_status_string(s),
           (unsigned long long)c.force_evaluations, (unsigned long long)c.collisions);
    lc_world_destroy(w);
    return 0;
}
