/* test_touch_refresh.c - lc_touch_refresh (narrow_phase.c), which a pile sub-step's projection uses to take
 * the flow's own points to their new positions without a search (contact_projection.c): a vertex-edge
 * touch is kept where the search would keep a point, with its gap at the new state.
 * A unit box a (vertex 0 its lower left corner) against a static 2 m x 1 m box b centred at the origin
 * (edge 1 its right side, edge 2 its top, normals out of b); contact_distance 1e-5 m.
 *  - vertex 1e-4 m inside b under the top, 0.5 m from the right side: kept, gap -1e-4 m against the top;
 *  - vertex inside b 3e-5 m from the right side and 1e-4 m under the top: kept, and the touch takes the
 *    edge the vertex is least deep behind (the right side), gap -3e-5 m, normal +x (the vertex-in-body
 *    test's answer; the top's normal would push it 1e-4 m up instead);
 *  - vertex 1e-3 m right of b and 1e-4 m under the top's line: beside b, not in it: dropped (its gap against
 *    the top, -1e-4 m, is no overlap);
 *  - vertex 2e-6 m above the top, over it: kept, gap 2e-6 m;
 *  - vertex 2e-6 m above the top's line and 2e-5 m past its end (beyond contact_distance): dropped, as the
 *    search drops a vertex that passes the edge's end;
 *  - the same 5e-6 m past the end (within contact_distance): kept.
 * Gaps to 1e-12 m: coordinates of order 1 m, a few operations of round-off. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "world.h"

#define TOL 1e-12

static lc_vec2 v2(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

/* a at angle 0 with its lower left corner (vertex 0) at (x, y) */
static void place_corner(lc_world *w, int row, double x, double y)
{
    double *s = &w->state[row * 6];
    s[SX] = x + 0.5;
    s[SY] = y + 0.5;
    s[SA] = 0.0;
}

static int refresh(lc_world *w, int a, int b, int edge, lc_touch *t)
{
    memset(t, 0, sizeof *t);
    t->a = a;
    t->b = b;
    t->vertex = 0;
    t->edge = edge;
    return lc_touch_refresh(w, w->state, t, w->def.contact_distance);
}

int main(void)
{
    lc_world_def d = lc_default_world_def();
    lc_body_def bd = lc_default_body_def();
    lc_vec2 unit[4], slab[4];
    lc_world *w;
    lc_body_id ia, ib;
    lc_touch t;
    int kept;
    unit[0] = v2(-0.5, -0.5); unit[1] = v2(0.5, -0.5); unit[2] = v2(0.5, 0.5); unit[3] = v2(-0.5, 0.5);
    slab[0] = v2(-1.0, -0.5); slab[1] = v2(1.0, -0.5); slab[2] = v2(1.0, 0.5); slab[3] = v2(-1.0, 0.5);
    d.gravity = v2(0.0, 0.0);
    d.contact_distance = 1e-5;
    w = lc_world_create(&d, NULL, 0);
    CHECK(w != NULL, "%s", "world created");
    if (w == NULL) return CHECK_SUMMARY("test_touch_refresh");
    bd.vertices = unit;
    bd.vertex_count = 4;
    bd.position = v2(0.0, 3.0);
    CHECK(lc_world_add_body(w, &bd, &ia) == LC_OK, "%s", "box a added");
    bd.vertices = slab;
    bd.position = v2(0.0, 0.0);
    bd.type = LC_BODY_STATIC;
    CHECK(lc_world_add_body(w, &bd, &ib) == LC_OK, "%s", "slab b added");
    CHECK(w->count == 2, "two rows (%d)", w->count);

    place_corner(w, 0, 0.5, 0.5 - 1e-4);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(kept && t.edge == 2 && fabs(t.gap + 1e-4) < TOL,
          "inside under the top: kept (%d) against the top (edge %d), gap %.17g", kept, t.edge, t.gap);

    place_corner(w, 0, 1.0 - 3e-5, 0.5 - 1e-4);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(kept && t.edge == 1 && fabs(t.gap + 3e-5) < TOL && fabs(t.n.x - 1.0) < TOL && fabs(t.n.y) < TOL,
          "inside near the side: kept (%d) against the side (edge %d), gap %.17g, normal (%g, %g)", kept, t.edge,
          t.gap, t.n.x, t.n.y);

    place_corner(w, 0, 1.0 + 1e-3, 0.5 - 1e-4);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(!kept, "beside b under the top's line: dropped (%d, gap %.3g against edge %d)", kept, t.gap, t.edge);

    place_corner(w, 0, 0.5, 0.5 + 2e-6);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(kept && t.edge == 2 && fabs(t.gap - 2e-6) < TOL, "over the top: kept (%d), gap %.17g", kept, t.gap);

    place_corner(w, 0, 1.0 + 2e-5, 0.5 + 2e-6);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(!kept, "past the top's end by 2 contact distances: dropped (%d)", kept);

    place_corner(w, 0, 1.0 + 5e-6, 0.5 + 2e-6);
    kept = refresh(w, 0, 1, 2, &t);
    CHECK(kept && fabs(t.gap - 2e-6) < TOL, "past the top's end within contact_distance: kept (%d), gap %.17g", kept,
          t.gap);

    lc_world_destroy(w);
    return CHECK_SUMMARY("test_touch_refresh");
}
