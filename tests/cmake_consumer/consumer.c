/* Drops a block on the floor through the installed library and checks it bounced, and that the
 * installed generated collide/version.h names the library's version (exit 0 on success). */
#include <stdio.h>
#include <string.h>
#include "collide/collide.h"
#include "collide/version.h"

int main(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = lc_world_create(&d, NULL, 0);
    lc_vec2 v[4];
    lc_body_def b = lc_default_body_def();
    lc_body_id id;
    lc_state_view s;
    int i;
    if (strcmp(lc_version(), LC_VERSION_STRING) != 0) {
        printf("lc_version() %s != LC_VERSION_STRING %s\n", lc_version(), LC_VERSION_STRING);
        return 1;
    }
    if (w == NULL) return 1;
    lc_make_rectangle(1.0, 1.0, v);
    b.vertices = v;
    b.vertex_count = 4;
    b.position.y = 2.0;
    if (lc_world_add_walls(w, -5, 0, 5, 10, 1, 1, NULL) != LC_OK || lc_world_add_body(w, &b, &id) != LC_OK) return 1;
    for (i = 0; i < 100; ++i)
        if (lc_world_step(w, 0.01) != LC_OK) return 1;
    lc_world_get_state(w, &s);
    printf("libcollide %s: block at y = %.6f m, vy = %.6f m/s after 1 s\n", lc_version(), s.state[4 * 6 + 1], s.state[4 * 6 + 4]);
    /* falling 1.5 m takes 0.553 s; with e = 1 it is on the way up at t = 1 s */
    i = s.state[4 * 6 + 4] > 0.0 && s.state[4 * 6 + 1] > 0.5;
    lc_world_destroy(w);
    return i ? 0 : 1;
}
