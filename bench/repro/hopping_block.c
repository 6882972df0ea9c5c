/* hopping_block.c - an upright 1 m x 0.5 m block (1 kg, e 0.8, mu 0.5) rocking from corner to corner
 * on a static floor while it drifts sideways: the state one block of the hard-case settling scene
 * (tests/c/test_hard_settle.c, sc_rng seed 1) can reach at 10 s, to 17 digits (docs/physics.md
 * "Time stepping"). It comes to rest within a few steps because friction is kept against a slipping
 * point's slip (docs/physics.md "Resting contact"); a friction that is not hops on forever, gaining
 * ~1.5e-4 J per rock.
 *
 *   cc -O2 -std=c99 -ffp-contract=off -Ilibcollide/include bench/repro/hopping_block.c build/libcollide.a -lm \
 *      -o /tmp/hopping_block && /tmp/hopping_block [vx vy omega angle y] [steps 600]
 * Prints per step (the first 9, then every 30th): impacts, energy minus the start's, pose, velocity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "collide/collide.h"

int main(int argc, char **argv)
{
    double vx = argc > 1 ? atof(argv[1]) : 0.0050645411367954349;
    double vy = argc > 2 ? atof(argv[2]) : 0.012807217399986076;
    double omega = argc > 3 ? atof(argv[3]) : 0.034056703829182994;
    double angle = argc > 4 ? atof(argv[4]) : 1.5707997254196675;
    double y = argc > 5 ? atof(argv[5]) : 0.5000039247682968;
    int steps = argc > 6 ? atoi(argv[6]) : 600, k;
    lc_world_def d = lc_default_world_def();
    lc_body_def b = lc_default_body_def();
    lc_vec2 c[4];
    lc_body_id floor_id, block;
    lc_state_view v;
    lc_energy en;
    char msg[256];
    double e0;
    lc_world *w;
    d.gravity.y = -9.8;
    w = lc_world_create(&d, msg, sizeof msg);
    if (w == NULL) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    lc_make_rectangle(20.0, 1.0, c);
    b.vertices = c;
    b.vertex_count = 4;
    b.position.y = -0.5;
    b.type = LC_BODY_STATIC;
    b.elasticity = 0.8;
    b.friction = 0.5;
    if (lc_world_add_body(w, &b, &floor_id) != LC_OK) goto fail;
    b = lc_default_body_def();
    lc_make_rectangle(1.0, 0.5, c);
    b.vertices = c;
    b.vertex_count = 4;
    b.position.y = y;
    b.angle = angle;
    b.elasticity = 0.8;
    b.friction = 0.5;
    b.velocity.x = vx;
    b.velocity.y = vy;
    b.angular_velocity = omega;
    if (lc_world_add_body(w, &b, &block) != LC_OK) goto fail;
    lc_world_get_energy(w, &en);
    e0 = en.total;
    for (k = 1; k <= steps; k++) {
        lc_counters last;
        if (lc_world_step(w, 1.0 / 60.0) != LC_OK) goto fail;
        lc_world_get_counters(w, &last, NULL);
        lc_world_get_state(w, &v);
        lc_world_get_energy(w, &en);
        if (k < 10 || k % 30 == 0)
            printf("step %d: impacts %llu, E-E0 %.3e J, x %.5f y %.7f angle %.6f, v (%.3g, %.3g) omega %.3g\n", k,
                   (unsigned long long)last.collisions, en.total - e0, v.state[6], v.state[7], v.state[8],
                   v.state[9], v.state[10], v.state[11]);
    }
    lc_world_destroy(w);
    return 0;
fail:
    fprintf(stderr, "%s\n", lc_world_last_error(w));
    lc_world_destroy(w);
    return 1;
}
