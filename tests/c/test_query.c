/* test_query: the queries of collide/query.h against analytic answers. Axis-aligned shapes at
 * representable coordinates must come out exact (tolerance 0); rotated ones within a few ulps of the
 * coordinates (1e-14 m on scenes of ~10 m). Then consistency between the queries on a random scene, that
 * queries leave the world (and the steps after them) unchanged, and bad input: the specific status, a
 * message naming the argument, the world and the outputs untouched. */
#include <ctype.h>
#include "check.h"
#include "scenes.h"

#define TOL 1e-14

static lc_world *zero_g_world(void)
{
    lc_world_def d = sc_def_zero_g();
    return sc_world(&d);
}

/* a 2 x 2 box (dynamic, 1 kg) centred on (x, y) turned by angle */
static lc_body_id box2(lc_world *w, double x, double y, double angle)
{
    return sc_box(w, 2.0, 2.0, x, y, angle, 0.0, 0.0, 0.0, 1.0, 1.0);
}

/* the diamond |x| + |y| <= 1 around (x, y): world vertices exact at angle 0 */
static lc_body_id diamond(lc_world *w, double x, double y)
{
    static const lc_vec2 v[4] = {{1.0, 0.0}, {0.0, 1.0}, {-1.0, 0.0}, {0.0, -1.0}};
    return sc_poly(w, v, 4, x, y, 0.0, 1.0);
}

static lc_vec2 V(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

static int ray(lc_world *w, lc_vec2 a, lc_vec2 b, const lc_query_filter *f, lc_ray_hit *hit)
{
    int found = -1;
    lc_status s = lc_world_ray_cast(w, a, b, f, hit, &found);
    CHECK(s == LC_OK, "ray_cast -> %s: %s", lc_status_string(s), lc_world_last_error(w));
    return found;
}

static void check_hit(const lc_ray_hit *h, lc_body_id body, double fraction, double px, double py, double nx,
                      double ny, double tol, const char *what)
{
    CHECK(h->body == body, "%s: body %u, expected %u", what, (unsigned)h->body, (unsigned)body);
    CHECK_NEAR(h->fraction, fraction, tol, what);
    CHECK_NEAR(h->point.x, px, tol, what);
    CHECK_NEAR(h->point.y, py, tol, what);
    CHECK_NEAR(h->normal.x, nx, tol, what);
    CHECK_NEAR(h->normal.y, ny, tol, what);
}

/* ---- rays against one box -------------------------------------------------------------------- */

static void rays_against_a_box(void)
{
    lc_world *w = zero_g_world();
    lc_body_id b = box2(w, 0.0, 0.0, 0.0);
    lc_ray_hit h;
    const double phis[] = {0.0, 0.3, 1.0, -2.0, SC_PI / 6.0, 2.5};
    const double alphas[] = {0.0, 0.2, -0.6, 0.7};
    size_t i, j;

    /* head on, exact */
    CHECK(ray(w, V(-5, 0), V(5, 0), NULL, &h) == 1, "%s", "head-on ray missed");
    check_hit(&h, b, 0.4, -1.0, 0.0, -1.0, 0.0, 0.0, "head on");
    CHECK(ray(w, V(5, 0.5), V(-5, 0.5), NULL, &h) == 1, "%s", "ray from the right missed");
    check_hit(&h, b, 0.4, 1.0, 0.5, 1.0, 0.0, 0.0, "from the right");
    CHECK(ray(w, V(0.25, -9), V(0.25, 7), NULL, &h) == 1, "%s", "ray from below missed");
    check_hit(&h, b, 0.5, 0.25, -1.0, 0.0, -1.0, 0.0, "from below");
    /* slanted: d = (10, 1.2) crosses x = -1 at t = 0.4, y = 0.48 */
    CHECK(ray(w, V(-5, 0), V(5, 1.2), NULL, &h) == 1, "%s", "slanted ray missed");
    check_hit(&h, b, 0.4, -1.0, 0.48, -1.0, 0.0, 1e-15, "slanted");
    /* too short, beyond, and past the box */
    CHECK(ray(w, V(-5, 0), V(-1.5, 0), NULL, &h) == 0, "%s", "a ray ending before the box hit it");
    CHECK(ray(w, V(3, 0), V(5, 0), NULL, &h) == 0, "%s", "a ray beyond the box hit it");
    CHECK(ray(w, V(-5, 1.5), V(5, 1.5), NULL, &h) == 0, "%s", "a ray passing above hit");
    /* ending exactly on the face: fraction 1 */
    CHECK(ray(w, V(-3, 0), V(-1, 0), NULL, &h) == 1, "%s", "a ray ending on the face missed");
    check_hit(&h, b, 1.0, -1.0, 0.0, -1.0, 0.0, 0.0, "ending on the face");
    /* through a corner at 45 degrees: a tie between two faces facing it alike, the first (bottom) */
    CHECK(ray(w, V(-5, -5), V(5, 5), NULL, &h) == 1, "%s", "diagonal ray missed");
    check_hit(&h, b, 0.4, -1.0, -1.0, 0.0, -1.0, 0.0, "through the corner");
    lc_world_destroy(w);

    /* the box turned by phi, a ray through its centre at alpha to the normal of the face it enters:
     * it reaches that face h / cos(alpha) before the centre (h = 1) */
    for (i = 0; i < sizeof phis / sizeof phis[0]; ++i)
        for (j = 0; j < sizeof alphas / sizeof alphas[0]; ++j) {
            double phi = phis[i], al = alphas[j], D = 10.0;
            double ux = cos(phi + al), uy = sin(phi + al), cx = 0.7, cy = -1.3;
            double s = D - 1.0 / cos(al);
            char what[64];
            w = zero_g_world();
            b = box2(w, cx, cy, phi);
            snprintf(what, sizeof what, "phi %g alpha %g", phi, al);
            CHECK(ray(w, V(cx - D * ux, cy - D * uy), V(cx + D * ux, cy + D * uy), NULL, &h) == 1, "%s missed", what);
            check_hit(&h, b, s / (2.0 * D), cx - D * ux + s * ux, cy - D * uy + s * uy, -cos(phi), -sin(phi), TOL,
                      what);
            lc_world_destroy(w);
        }
}

static void rays_starting_inside_or_on(void)
{
    lc_world *w = zero_g_world();
    lc_body_id b = box2(w, 0.0, 0.0, 0.0), far = box2(w, 10.0, 0.0, 0.0);
    lc_ray_hit h, all[4];
    int n = -1;
    /* inside: fraction 0 at the start, normal against the ray */
    CHECK(ray(w, V(0.2, 0.3), V(3.2, 4.3), NULL, &h) == 1, "%s", "a ray from inside missed");
    check_hit(&h, b, 0.0, 0.2, 0.3, -0.6, -0.8, 1e-16, "inside");
    /* on the left face going in: the face's normal */
    CHECK(ray(w, V(-1, 0.5), V(5, 0.5), NULL, &h) == 1, "%s", "a ray from the face missed");
    check_hit(&h, b, 0.0, -1.0, 0.5, -1.0, 0.0, 0.0, "on the face, going in");
    /* on the right face going out: still a hit at 0 (closed polygons), normal against the ray */
    CHECK(ray(w, V(1, 0), V(5, 3), NULL, &h) == 1, "%s", "a ray leaving from the face missed");
    check_hit(&h, b, 0.0, 1.0, 0.0, -0.8, -0.6, 1e-16, "on the face, going out");
    /* from inside through the far box: both, in order; the far one entered at x = 9 */
    CHECK(lc_world_ray_cast_all(w, V(0, 0), V(20, 0), NULL, all, 4, &n) == LC_OK && n == 2, "all: %d hits", n);
    if (n == 2) {
        check_hit(&all[0], b, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, "all, inside");
        check_hit(&all[1], far, 0.45, 9.0, 0.0, -1.0, 0.0, 0.0, "all, far box");
    }
    /* the caster left out by the filter: the far box first */
    {
        lc_query_filter f;
        f.skip_static = 0;
        f.skip_body = b;
        CHECK(ray(w, V(0, 0), V(20, 0), &f, &h) == 1, "%s", "filtered ray missed");
        check_hit(&h, far, 0.45, 9.0, 0.0, -1.0, 0.0, 0.0, "skipping the caster");
    }
    lc_world_destroy(w);
}

static void rays_parallel_and_grazing(void)
{
    lc_world *w = zero_g_world();
    lc_body_id b = box2(w, 0.0, 0.0, 0.0), d;
    lc_ray_hit h;
    const double r2 = 1.0 / sqrt(2.0);
    /* along the line of the top face: meets the box at its top-left corner, entering the left face */
    CHECK(ray(w, V(-5, 1), V(5, 1), NULL, &h) == 1, "%s", "a ray along the top face missed");
    check_hit(&h, b, 0.4, -1.0, 1.0, -1.0, 0.0, 0.0, "along the top face");
    /* parallel to it just outside: nothing; just inside: the left face */
    CHECK(ray(w, V(-5, 1 + 0x1p-40), V(5, 1 + 0x1p-40), NULL, &h) == 0, "%s", "a ray above the top face hit");
    CHECK(ray(w, V(-5, 1 - 0x1p-40), V(5, 1 - 0x1p-40), NULL, &h) == 1, "%s", "a ray below the top face missed");
    check_hit(&h, b, 0.4, -1.0, 1 - 0x1p-40, -1.0, 0.0, 0.0, "just below the top face");
    /* along the top face from its middle: starts on the body, fraction 0 */
    CHECK(ray(w, V(0, 1), V(5, 1), NULL, &h) == 1, "%s", "a ray along the face from on it missed");
    check_hit(&h, b, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, "along the face from on it");
    lc_world_destroy(w);

    w = zero_g_world();
    d = diamond(w, 0.0, 0.0);
    /* grazing the top vertex (0, 1): a hit at that point only, through the upper-left edge */
    CHECK(ray(w, V(-3, 1), V(3, 1), NULL, &h) == 1, "%s", "a ray grazing the vertex missed");
    check_hit(&h, d, 0.5, 0.0, 1.0, -r2, r2, 1e-16, "grazing the top vertex");
    CHECK(ray(w, V(-3, 1 + 1e-12), V(3, 1 + 1e-12), NULL, &h) == 0, "%s", "a ray above the vertex hit");
    /* into the left vertex (-1, 0) going up-right: the lower-left face faces it more squarely */
    CHECK(ray(w, V(-4, -1), V(2, 1), NULL, &h) == 1, "%s", "a ray into the left vertex missed");
    check_hit(&h, d, 0.5, -1.0, 0.0, -r2, -r2, 1e-16, "into the left vertex");
    /* into it head on: both faces alike, the first in vertex order (upper-left) */
    CHECK(ray(w, V(-3, 0), V(3, 0), NULL, &h) == 1, "%s", "a ray into the left vertex head on missed");
    check_hit(&h, d, 1.0 / 3.0, -1.0, 0.0, -r2, r2, 1e-16, "into the left vertex head on");
    lc_world_destroy(w);
}

static void ray_cast_all_sorted(void)
{
    lc_world *w = zero_g_world();
    lc_body_id ids[5], st;
    lc_ray_hit hits[8], h;
    lc_query_filter f;
    int i, n = -1;
    /* five boxes along x, added right to left so row order is not ray order */
    for (i = 0; i < 5; ++i) ids[i] = box2(w, 12.0 - 3.0 * i, 0.0, 0.0);   /* x = 12, 9, 6, 3, 0 */
    st = sc_static_box(w, 2.0, 2.0, 0.0, 10.0, 1.0);                      /* off the ray */
    CHECK(lc_world_ray_cast_all(w, V(-2, 0), V(18, 0), NULL, hits, 8, &n) == LC_OK, "%s", lc_world_last_error(w));
    CHECK(n == 5, "%d hits, expected 5", n);
    for (i = 0; i < 5 && i < n; ++i) {
        double x = 3.0 * i - 1.0;   /* faces at -1, 2, 5, 8, 11 */
        char what[32];
        snprintf(what, sizeof what, "hit %d", i);
        check_hit(&hits[i], ids[4 - i], (x + 2.0) / 20.0, x, 0.0, -1.0, 0.0, TOL, what);
    }
    /* a smaller buffer gets the nearest ones, sorted, and the total */
    for (i = 0; i < 8; ++i) hits[i].body = 0;
    CHECK(lc_world_ray_cast_all(w, V(-2, 0), V(18, 0), NULL, hits, 2, &n) == LC_OK && n == 5, "capacity 2: n = %d", n);
    CHECK(hits[0].body == ids[4] && hits[1].body == ids[3] && hits[2].body == 0, "capacity 2: %u %u %u",
          (unsigned)hits[0].body, (unsigned)hits[1].body, (unsigned)hits[2].body);
    /* the same from the other end (reverse order of the heap's arrivals) */
    CHECK(lc_world_ray_cast_all(w, V(18, 0), V(-2, 0), NULL, hits, 3, &n) == LC_OK && n == 5, "reverse: n = %d", n);
    CHECK(hits[0].body == ids[0] && hits[1].body == ids[1] && hits[2].body == ids[2], "reverse: %u %u %u",
          (unsigned)hits[0].body, (unsigned)hits[1].body, (unsigned)hits[2].body);
    CHECK(hits[0].fraction < hits[1].fraction && hits[1].fraction < hits[2].fraction, "%s", "reverse: unsorted");
    /* counting only */
    CHECK(lc_world_ray_cast_all(w, V(-2, 0), V(18, 0), NULL, NULL, 0, &n) == LC_OK && n == 5, "count only: %d", n);
    /* the first hit is the nearest, whatever the row order */
    CHECK(ray(w, V(18, 0), V(-2, 0), NULL, &h) == 1 && h.body == ids[0], "first hit %u", (unsigned)h.body);
    /* filters: the static box is hit by a vertical ray unless static bodies are skipped */
    f.skip_static = 0;
    f.skip_body = 0;
    CHECK(lc_world_ray_cast_all(w, V(0, -5), V(0, 15), &f, hits, 8, &n) == LC_OK && n == 2, "vertical: %d", n);
    if (n == 2) CHECK(hits[0].body == ids[4] && hits[1].body == st, "%s", "vertical order");
    f.skip_static = 1;
    CHECK(lc_world_ray_cast_all(w, V(0, -5), V(0, 15), &f, hits, 8, &n) == LC_OK && n == 1, "no static: %d", n);
    f.skip_body = ids[4];
    CHECK(lc_world_ray_cast_all(w, V(0, -5), V(0, 15), &f, hits, 8, &n) == LC_OK && n == 0, "none: %d", n);
    lc_world_destroy(w);

    /* equal fractions: the body added first first */
    w = zero_g_world();
    ids[0] = box2(w, 0.0, 0.5, 0.0);
    ids[1] = box2(w, 0.0, -0.5, 0.0);
    CHECK(lc_world_ray_cast_all(w, V(5, 0), V(-5, 0), NULL, hits, 8, &n) == LC_OK && n == 2, "ties: %d", n);
    if (n == 2)
        CHECK(hits[0].body == ids[0] && hits[1].body == ids[1] && hits[0].fraction == 0.4 && hits[1].fraction == 0.4,
              "ties: %u %.17g, %u %.17g", (unsigned)hits[0].body, hits[0].fraction, (unsigned)hits[1].body,
              hits[1].fraction);
    CHECK(ray(w, V(5, 0), V(-5, 0), NULL, &h) == 1 && h.body == ids[0], "tie, first hit %u", (unsigned)h.body);
    lc_world_destroy(w);
}

/* ---- points and boxes ------------------------------------------------------------------------- */

static int query_point(lc_world *w, double x, double y, const lc_query_filter *f, lc_body_id *out, int cap)
{
    int n = -1;
    lc_status s = lc_world_query_point(w, V(x, y), f, out, cap, &n);
    CHECK(s == LC_OK, "query_point -> %s: %s", lc_status_string(s), lc_world_last_error(w));
    return n;
}

static int query_box(lc_world *w, double x0, double y0, double x1, double y1, lc_body_id *out, int cap)
{
    int n = -1;
    lc_status s = lc_world_query_box(w, V(x0, y0), V(x1, y1), NULL, out, cap, &n);
    CHECK(s == LC_OK, "query_box -> %s: %s", lc_status_string(s), lc_world_last_error(w));
    return n;
}

static void points(void)
{
    lc_world *w = zero_g_world();
    lc_body_id a = box2(w, 2.0, 3.0, 0.0), b = sc_static_box(w, 2.0, 2.0, 4.0, 3.0, 1.0), d = diamond(w, -5.0, 0.0);
    lc_body_id out[4] = {0, 0, 0, 0};
    lc_query_filter f;
    CHECK(query_point(w, 2.0, 3.0, NULL, out, 4) == 1 && out[0] == a, "%s", "centre");
    CHECK(query_point(w, 1.0, 3.5, NULL, out, 4) == 1 && out[0] == a, "%s", "on the left edge");
    CHECK(query_point(w, 1.0 - 0x1p-40, 3.5, NULL, out, 4) == 0, "%s", "just outside the left edge");
    CHECK(query_point(w, 1.0, 4.0, NULL, out, 4) == 1 && out[0] == a, "%s", "on a corner");
    /* the edge the two boxes share (x = 3): both, in row order; with room for one, the first and the count */
    CHECK(query_point(w, 3.0, 2.5, NULL, out, 4) == 2 && out[0] == a && out[1] == b, "%s", "shared edge");
    out[0] = out[1] = 0;
    CHECK(query_point(w, 3.0, 2.5, NULL, out, 1) == 2 && out[0] == a && out[1] == 0, "%s", "capacity 1");
    CHECK(query_point(w, 3.0, 2.5, NULL, NULL, 0) == 2, "%s", "count only");
    f.skip_static = 1;
    f.skip_body = 0;
    CHECK(query_point(w, 3.0, 2.5, &f, out, 4) == 1 && out[0] == a, "%s", "skipping static");
    f.skip_static = 0;
    f.skip_body = a;
    CHECK(query_point(w, 3.0, 2.5, &f, out, 4) == 1 && out[0] == b, "%s", "skipping a");
    f.skip_body = 987654u;   /* no such body: leaves out nothing */
    CHECK(query_point(w, 3.0, 2.5, &f, out, 4) == 2, "%s", "skipping no body");
    /* the diamond: its bounding box holds (-4.4, 0.6) but the polygon does not; its edge holds (-4.5, 0.5) */
    CHECK(query_point(w, -4.4, 0.6, NULL, out, 4) == 0, "%s", "in the diamond's bounding box only");
    CHECK(query_point(w, -4.5, 0.5, NULL, out, 4) == 1 && out[0] == d, "%s", "on the diamond's edge");
    CHECK(query_point(w, 0.0, 0.0, NULL, out, 4) == 0, "%s", "empty space");
    /* the current pose counts: moved, the box is found where it went and no longer where it was */
    CHECK(lc_body_set_pose(w, a, V(20.0, 0.0), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    CHECK(query_point(w, 2.0, 3.0, NULL, out, 4) == 0, "%s", "old place");
    CHECK(query_point(w, 20.5, -0.5, NULL, out, 4) == 1 && out[0] == a, "%s", "new place");
    /* after a removal (rows shift) */
    CHECK(lc_world_remove_body(w, b) == LC_OK, "%s", lc_world_last_error(w));
    CHECK(query_point(w, -5.0, 0.0, NULL, out, 4) == 1 && out[0] == d, "%s", "after a removal");
    CHECK(query_point(w, 4.0, 3.0, NULL, out, 4) == 0, "%s", "the removed body");
    lc_world_destroy(w);
}

static void boxes(void)
{
    lc_world *w = zero_g_world();
    lc_body_id a = box2(w, 0.0, 0.0, 0.0), d = diamond(w, 5.0, 0.0), r = box2(w, 0.0, 6.0, SC_PI / 4.0);
    lc_body_id out[4];
    /* overlapping the box, touching its face, just apart */
    CHECK(query_box(w, 0.5, 0.5, 3.0, 3.0, out, 4) == 1 && out[0] == a, "%s", "overlapping a corner");
    CHECK(query_box(w, 1.0, -0.1, 2.0, 0.1, out, 4) == 1 && out[0] == a, "%s", "touching the right face");
    CHECK(query_box(w, 1.0 + 0x1p-40, -0.1, 2.0, 0.1, out, 4) == 0, "%s", "just right of the box");
    /* inside the box, around everything, of zero size */
    CHECK(query_box(w, -0.1, -0.1, 0.1, 0.1, out, 4) == 1 && out[0] == a, "%s", "inside");
    CHECK(query_box(w, -10, -10, 10, 10, out, 4) == 3 && out[0] == a && out[1] == d && out[2] == r, "%s", "all");
    CHECK(query_box(w, 0.3, 0.3, 0.3, 0.3, out, 4) == 1 && out[0] == a, "%s", "zero size");
    /* the diamond's corner regions: inside its bounding box, outside the polygon; touching its edge */
    CHECK(query_box(w, 5.6, 0.6, 6.0, 1.0, out, 4) == 0, "%s", "beside the diamond's edge");
    CHECK(query_box(w, 5.5, 0.5, 6.0, 1.0, out, 4) == 1 && out[0] == d, "%s", "touching the diamond's edge");
    /* a thin box across the diamond's top vertex: no corner of it inside, still overlapping */
    CHECK(query_box(w, 4.9, 0.95, 5.1, 2.0, out, 4) == 1 && out[0] == d, "%s", "across the diamond's vertex");
    /* the turned box (corners at (0, 6 +- sqrt 2) and (+-sqrt 2, 6)): near its corner region */
    CHECK(query_box(w, 0.8, 6.8, 2.0, 8.0, out, 4) == 0, "%s", "beside the turned box");
    CHECK(query_box(w, 0.6, 6.6, 2.0, 8.0, out, 4) == 1 && out[0] == r, "%s", "into the turned box");
    lc_world_destroy(w);
}

/* ---- two bodies ------------------------------------------------------------------------------- */

static lc_distance_result distance(lc_world *w, lc_body_id a, lc_body_id b)
{
    lc_distance_result r;
    int overlap = -1;
    lc_status s;
    memset(&r, 0, sizeof r);
    s = lc_body_distance(w, a, b, &r);
    CHECK(s == LC_OK, "distance -> %s: %s", lc_status_string(s), lc_world_last_error(w));
    s = lc_body_overlap(w, a, b, &overlap);
    CHECK(s == LC_OK && overlap == (r.distance <= 0.0), "overlap %d with distance %.17g", overlap, r.distance);
    /* the documented relation point_b - point_a = distance * normal, a unit normal */
    CHECK_NEAR(r.point_b.x - r.point_a.x, r.distance * r.normal.x, 1e-14, "point_b - point_a, x");
    CHECK_NEAR(r.point_b.y - r.point_a.y, r.distance * r.normal.y, 1e-14, "point_b - point_a, y");
    CHECK_NEAR(hypot(r.normal.x, r.normal.y), 1.0, 1e-15, "|normal|");
    return r;
}

static void check_distance(lc_distance_result r, double dist, double nx, double ny, double tol, const char *what)
{
    CHECK_NEAR(r.distance, dist, tol, what);
    CHECK_NEAR(r.normal.x, nx, tol, what);
    CHECK_NEAR(r.normal.y, ny, tol, what);
}

static void distances(void)
{
    lc_world *w = zero_g_world();
    lc_body_id a = box2(w, 0.0, 0.0, 0.0), b = box2(w, 3.5, 0.0, 0.0);
    lc_distance_result r;
    const double phis[] = {0.0, 0.4, -1.1, 2.0};
    size_t i;
    int overlap;
    /* face to face, 1.5 apart */
    r = distance(w, a, b);
    check_distance(r, 1.5, 1.0, 0.0, 0.0, "face to face");
    CHECK(r.point_a.x == 1.0 && r.point_b.x == 2.5 && fabs(r.point_a.y) <= 1.0, "points (%g, %g) (%g, %g)",
          r.point_a.x, r.point_a.y, r.point_b.x, r.point_b.y);
    /* the other way round */
    r = distance(w, b, a);
    check_distance(r, 1.5, -1.0, 0.0, 0.0, "face to face, b to a");
    /* corner to corner: (1, 1) to (3, 4) */
    CHECK(lc_body_set_pose(w, b, V(4.0, 5.0), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    check_distance(r, sqrt(13.0), 2.0 / sqrt(13.0), 3.0 / sqrt(13.0), 1e-15, "corner to corner");
    CHECK(r.point_a.x == 1.0 && r.point_a.y == 1.0 && r.point_b.x == 3.0 && r.point_b.y == 4.0, "%s", "corners");
    /* corner of a turned box to a face: b at 45 degrees, its left corner sqrt 2 left of its centre */
    CHECK(lc_body_set_pose(w, b, V(1.0 + 0.25 + sqrt(2.0), 0.0), SC_PI / 4.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    check_distance(r, 0.25, 1.0, 0.0, TOL, "corner to face");
    CHECK_NEAR(r.point_b.x, 1.25, TOL, "corner");
    CHECK_NEAR(r.point_b.y, 0.0, TOL, "corner");
    CHECK_NEAR(r.point_a.x, 1.0, TOL, "face");
    /* touching face to face: 0, overlapping */
    CHECK(lc_body_set_pose(w, b, V(2.0, 0.5), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    CHECK(r.distance == 0.0 && !signbit(r.distance), "touching: %.17g", r.distance);
    CHECK(lc_body_overlap(w, a, b, &overlap) == LC_OK && overlap == 1, "%s", "touching overlaps");
    /* touching corner to corner */
    CHECK(lc_body_set_pose(w, b, V(2.0, 2.0), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    CHECK(r.distance == 0.0, "corners touching: %.17g", r.distance);
    CHECK(r.point_a.x == 1.0 && r.point_a.y == 1.0 && r.point_b.x == 1.0 && r.point_b.y == 1.0, "%s", "the corner");
    /* just apart */
    CHECK(lc_body_set_pose(w, b, V(2.0 + 0x1p-40, 0.5), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    CHECK(r.distance == 0x1p-40, "just apart: %.17g", r.distance);
    CHECK(lc_body_overlap(w, a, b, &overlap) == LC_OK && overlap == 0, "%s", "just apart overlaps");
    /* overlapping by 0.5 along x (1.8 along y): distance -0.5, out along +x */
    CHECK(lc_body_set_pose(w, b, V(1.5, 0.2), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    r = distance(w, a, b);
    check_distance(r, -0.5, 1.0, 0.0, 0.0, "overlapping");
    CHECK(r.point_a.x == 1.0 && r.point_b.x == 0.5, "overlap points x %g %g", r.point_a.x, r.point_b.x);
    /* a small box deep inside: the shortest way out is 0.65 to the right */
    CHECK(lc_world_remove_body(w, b) == LC_OK, "%s", lc_world_last_error(w));
    b = sc_box(w, 0.5, 0.5, 0.6, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0);
    r = distance(w, a, b);
    check_distance(r, -0.65, 1.0, 0.0, 1e-15, "inside");
    r = distance(w, b, a);
    check_distance(r, -0.65, -1.0, 0.0, 1e-15, "inside, b to a");
    lc_world_destroy(w);

    /* both turned by phi, b beside a along a's face normal: face to face gap g, then overlapping by 0.3 */
    for (i = 0; i < sizeof phis / sizeof phis[0]; ++i) {
        double phi = phis[i], c = cos(phi), s = sin(phi), g;
        for (g = 0.75; g > -0.5; g -= 1.05) {
            char what[64];
            w = zero_g_world();
            a = box2(w, 1.0, -2.0, phi);
            b = box2(w, 1.0 + (2.0 + g) * c, -2.0 + (2.0 + g) * s, phi);
            snprintf(what, sizeof what, "phi %g gap %g", phi, g);
            r = distance(w, a, b);
            check_distance(r, g, c, s, TOL, what);
            lc_world_destroy(w);
        }
    }
}

/* ---- consistency on a random scene, and queries change nothing ------------------------------------ */

/* n boxes, one in seven static: anywhere (overlaps included) or one per cell of a 4 m grid (apart) */
static void random_scene(lc_world *w, sc_rng *rng, int n, int grid)
{
    int i;
    for (i = 0; i < n; ++i) {
        double x = sc_uniform(rng, -20, 20), y = sc_uniform(rng, -20, 20), a = sc_uniform(rng, -3, 3);
        double wd = sc_uniform(rng, 0.3, grid ? 2.0 : 3.0), ht = sc_uniform(rng, 0.3, grid ? 2.0 : 3.0);
        if (grid) {
            x = 4.0 * (i % 12) - 22.0;
            y = 4.0 * (i / 12) - 22.0;
        }
        if (i % 7 == 0)
            sc_static_box_rotated(w, wd, ht, x, y, a, 1.0);
        else
            sc_box(w, wd, ht, x, y, a, sc_uniform(rng, -1, 1), sc_uniform(rng, -1, 1), sc_uniform(rng, -1, 1), 1.0, 1.0);
    }
}

static int same_hit(const lc_ray_hit *x, const lc_ray_hit *y)
{
    return x->body == y->body && x->fraction == y->fraction && x->point.x == y->point.x && x->point.y == y->point.y &&
           x->normal.x == y->normal.x && x->normal.y == y->normal.y;
}

/* k random queries of every kind on w; returns the number of disagreements between them and adds the
 * number of points found in a body to *inside */
static int random_queries(lc_world *w, sc_rng *rng, int k, int *inside)
{
    static lc_body_id found[200];
    static lc_ray_hit hits[200];
    lc_ray_hit first;
    int bad = 0, i, j, n, nf, got;
    for (; k > 0; --k) {
        lc_vec2 p = V(sc_uniform(rng, -22, 22), sc_uniform(rng, -22, 22));
        lc_vec2 q = V(sc_uniform(rng, -40, 40), sc_uniform(rng, -40, 40));
        lc_world_query_point(w, p, NULL, found, 200, &nf);
        lc_world_ray_cast_all(w, p, q, NULL, hits, 200, &n);
        *inside += nf > 0;
        /* the bodies a ray from p meets at fraction 0 are those holding p */
        for (i = 0, j = 0; i < n && hits[i].fraction == 0.0; ++i) {
            int in = 0, m;
            for (m = 0; m < nf; ++m) in |= found[m] == hits[i].body;
            j++;
            bad += !in;
        }
        bad += j != nf;
        for (i = 1; i < n; ++i) bad += hits[i - 1].fraction > hits[i].fraction;
        lc_world_ray_cast(w, p, q, NULL, &first, &got);
        bad += got != (n > 0) || (got && !same_hit(&first, &hits[0]));
        lc_world_query_box(w, p, V(p.x + 3.0, p.y + 1.0), NULL, found, 200, &n);
        bad += n < nf;   /* the box holds p */
    }
    return bad;
}

static void consistency(void)
{
    lc_world_def def = sc_def_zero_g();
    lc_world *w, *twin;
    sc_rng rng = {12345u};
    lc_body_id ids[200];
    lc_state_view v;
    int i, j, bad_pair = 0, inside = 0, overlapping = 0;
    w = sc_world(&def);
    random_scene(w, &rng, 150, 0);
    CHECK(random_queries(w, &rng, 300, &inside) == 0, "%s", "the queries disagree on a random scene");
    CHECK(inside > 20, "only %d of 300 points in a body: the scene tests little", inside);
    /* pairs: overlap agrees with the sign of the distance, and the distance with scenes.h's SAT */
    lc_world_get_state(w, &v);
    for (i = 0; i < v.count; ++i) ids[i] = v.ids[i];
    for (i = 0; i < 150; ++i)
        for (j = i + 1; j < 150; j += 7) {
            lc_distance_result r;
            int ov;
            double sat = sc_separation(w, ids[i], ids[j]);
            lc_body_distance(w, ids[i], ids[j], &r);
            lc_body_overlap(w, ids[i], ids[j], &ov);
            overlapping += ov;
            bad_pair += ov != (r.distance <= 0.0) || (r.distance > 0.0) != (sat > 0.0) ||
                        (sat > 0.0 && r.distance < sat - 1e-12) || (sat <= 0.0 && fabs(r.distance - sat) > 1e-12);
        }
    CHECK(bad_pair == 0, "%d pairs with inconsistent distance, overlap and separation", bad_pair);
    CHECK(overlapping > 5, "only %d overlapping pairs: the scene tests little", overlapping);
    lc_world_destroy(w);

    /* queries change nothing: same hash, and the same steps after them as a twin never queried */
    def.broadphase = LC_BROADPHASE_SORT_AND_SWEEP;
    w = sc_world(&def);
    twin = sc_world(&def);
    rng.s = 777u;
    random_scene(w, &rng, 150, 1);
    rng.s = 777u;
    random_scene(twin, &rng, 150, 1);
    for (i = 0; i < 3; ++i) {
        random_queries(w, &rng, 50, &inside);
        CHECK(lc_world_state_hash(w) == lc_world_state_hash(twin), "%s", "queries changed the state");
        sc_step_n(w, 0.01, 10);
        sc_step_n(twin, 0.01, 10);
    }
    CHECK(lc_world_state_hash(w) == lc_world_state_hash(twin), "%s", "queries changed the steps after them");
    lc_world_destroy(w);
    lc_world_destroy(twin);
}

/* ---- bad input -------------------------------------------------------------------------------- */

static int mentions(const char *msg, const char *word)
{
    size_t n = strlen(word), i, k;
    for (i = 0; msg[i]; i++) {
        for (k = 0; k < n && msg[i + k]; k++)
            if (tolower((unsigned char)msg[i + k]) != tolower((unsigned char)word[k])) break;
        if (k == n) return 1;
    }
    return 0;
}

static void expect_impl(lc_world *w, uint64_t hash, int count, lc_status got, lc_status want, const char *word,
                        int out_before, int out_after, const char *call, int line)
{
    const char *msg = lc_world_last_error(w);
    CHECK(got == want, "line %d: %s returned %s, expected %s (\"%s\")", line, call, lc_status_string(got),
          lc_status_string(want), msg);
    CHECK(msg[0] != '\0' && mentions(msg, word), "line %d: %s: message \"%s\" does not mention \"%s\"", line, call,
          msg, word);
    CHECK(lc_world_state_hash(w) == hash && lc_world_body_count(w) == count, "line %d: %s changed the world", line,
          call);
    CHECK(out_before == out_after, "line %d: %s wrote its output on failure", line, call);
}

/* out: the int output the call must leave alone (set to -7 before it) */
#define EXPECT(call, status, word)                                                                          \
    do {                                                                                                    \
        uint64_t h_ = lc_world_state_hash(w);                                                               \
        int c_ = lc_world_body_count(w);                                                                    \
        lc_status s_;                                                                                       \
        out = -7;                                                                                           \
        clear_error(w);                                                                                   \
        s_ = (call);                                                                                        \
        expect_impl(w, h_, c_, s_, (status), (word), -7, out, #call, __LINE__);                            \
    } while (0)

/* a successful call that changes something, so that each EXPECT starts from an empty message */
static void clear_error(lc_world *w) { lc_world_set_stage_timing(w, 0); }

static void bad_input(void)
{
    lc_world *w = zero_g_world();
    lc_body_id a = box2(w, 0.0, 0.0, 0.0), b = box2(w, 5.0, 0.0, 0.0), ids[4];
    lc_ray_hit hits[4];
    lc_distance_result r;
    lc_query_filter f;
    const double bad[] = {NAN, INFINITY, -INFINITY, 2e9};
    int out, k;
    f.skip_static = 2;
    f.skip_body = 0;
    /* NULL world: LC_ERR_NULL, nothing to write the reason to */
    CHECK(lc_world_query_point(NULL, V(0, 0), NULL, ids, 4, &out) == LC_ERR_NULL, "%s", "NULL world, point");
    CHECK(lc_world_query_box(NULL, V(0, 0), V(1, 1), NULL, ids, 4, &out) == LC_ERR_NULL, "%s", "NULL world, box");
    CHECK(lc_world_ray_cast(NULL, V(0, 0), V(1, 1), NULL, hits, &out) == LC_ERR_NULL, "%s", "NULL world, ray");
    CHECK(lc_world_ray_cast_all(NULL, V(0, 0), V(1, 1), NULL, hits, 4, &out) == LC_ERR_NULL, "%s", "NULL world, all");
    CHECK(lc_body_overlap(NULL, a, b, &out) == LC_ERR_NULL, "%s", "NULL world, overlap");
    CHECK(lc_body_distance(NULL, a, b, &r) == LC_ERR_NULL, "%s", "NULL world, distance");
    /* NULL outputs, capacities */
    EXPECT(lc_world_query_point(w, V(0, 0), NULL, ids, 4, NULL), LC_ERR_NULL, "out_count");
    EXPECT(lc_world_query_point(w, V(0, 0), NULL, NULL, 4, &out), LC_ERR_NULL, "out");
    EXPECT(lc_world_query_point(w, V(0, 0), NULL, ids, -1, &out), LC_ERR_OUT_OF_RANGE, "capacity");
    EXPECT(lc_world_query_box(w, V(0, 0), V(1, 1), NULL, ids, -5, &out), LC_ERR_OUT_OF_RANGE, "capacity");
    EXPECT(lc_world_query_box(w, V(0, 0), V(1, 1), NULL, NULL, 1, &out), LC_ERR_NULL, "out");
    EXPECT(lc_world_ray_cast(w, V(0, 0), V(1, 1), NULL, NULL, &out), LC_ERR_NULL, "hit");
    EXPECT(lc_world_ray_cast(w, V(0, 0), V(1, 1), NULL, hits, NULL), LC_ERR_NULL, "out_hit");
    EXPECT(lc_world_ray_cast_all(w, V(0, 0), V(1, 1), NULL, hits, -1, &out), LC_ERR_OUT_OF_RANGE, "capacity");
    EXPECT(lc_world_ray_cast_all(w, V(0, 0), V(1, 1), NULL, NULL, 3, &out), LC_ERR_NULL, "out");
    EXPECT(lc_world_ray_cast_all(w, V(0, 0), V(1, 1), NULL, hits, 4, NULL), LC_ERR_NULL, "out_count");
    EXPECT(lc_body_overlap(w, a, b, NULL), LC_ERR_NULL, "out_overlap");
    EXPECT(lc_body_distance(w, a, b, NULL), LC_ERR_NULL, "out");
    /* non-finite and out-of-range coordinates */
    for (k = 0; k < 4; ++k) {
        lc_status want = k < 3 ? LC_ERR_NOT_FINITE : LC_ERR_OUT_OF_RANGE;
        double x = bad[k];
        EXPECT(lc_world_query_point(w, V(x, 0), NULL, ids, 4, &out), want, "point.x");
        EXPECT(lc_world_query_point(w, V(0, x), NULL, ids, 4, &out), want, "point.y");
        EXPECT(lc_world_query_box(w, V(x, 0), V(1, 1), NULL, ids, 4, &out), want, "lower.x");
        EXPECT(lc_world_query_box(w, V(0, 0), V(1, x), NULL, ids, 4, &out), want, "upper.y");
        EXPECT(lc_world_ray_cast(w, V(x, 0), V(1, 1), NULL, hits, &out), want, "start.x");
        EXPECT(lc_world_ray_cast(w, V(0, 0), V(1, x), NULL, hits, &out), want, "end.y");
        EXPECT(lc_world_ray_cast_all(w, V(0, x), V(1, 1), NULL, hits, 4, &out), want, "start.y");
        EXPECT(lc_world_ray_cast_all(w, V(0, 0), V(x, 1), NULL, hits, 4, &out), want, "end.x");
    }
    /* zero-length rays, an upside-down box, a bad filter flag */
    EXPECT(lc_world_ray_cast(w, V(0.5, 0.5), V(0.5, 0.5), NULL, hits, &out), LC_ERR_OUT_OF_RANGE, "zero length");
    EXPECT(lc_world_ray_cast_all(w, V(3, 3), V(3, 3), NULL, hits, 4, &out), LC_ERR_OUT_OF_RANGE, "zero length");
    EXPECT(lc_world_query_box(w, V(1, 0), V(0, 1), NULL, ids, 4, &out), LC_ERR_OUT_OF_RANGE, "lower");
    EXPECT(lc_world_query_box(w, V(0, 1), V(1, 0), NULL, ids, 4, &out), LC_ERR_OUT_OF_RANGE, "upper");
    EXPECT(lc_world_query_point(w, V(0, 0), &f, ids, 4, &out), LC_ERR_OUT_OF_RANGE, "skip_static");
    EXPECT(lc_world_query_box(w, V(0, 0), V(1, 1), &f, ids, 4, &out), LC_ERR_OUT_OF_RANGE, "skip_static");
    EXPECT(lc_world_ray_cast(w, V(0, 0), V(1, 1), &f, hits, &out), LC_ERR_OUT_OF_RANGE, "skip_static");
    EXPECT(lc_world_ray_cast_all(w, V(0, 0), V(1, 1), &f, hits, 4, &out), LC_ERR_OUT_OF_RANGE, "skip_static");
    /* bodies: unknown, the same twice, removed */
    EXPECT(lc_body_overlap(w, a, 987654u, &out), LC_ERR_UNKNOWN_BODY, "987654");
    EXPECT(lc_body_overlap(w, 0, b, &out), LC_ERR_UNKNOWN_BODY, "id 0");
    EXPECT(lc_body_distance(w, 987654u, b, &r), LC_ERR_UNKNOWN_BODY, "987654");
    EXPECT(lc_body_overlap(w, a, a, &out), LC_ERR_OUT_OF_RANGE, "same body");
    EXPECT(lc_body_distance(w, b, b, &r), LC_ERR_OUT_OF_RANGE, "same body");
    CHECK(lc_world_remove_body(w, b) == LC_OK, "%s", lc_world_last_error(w));
    EXPECT(lc_body_distance(w, a, b, &r), LC_ERR_UNKNOWN_BODY, "no body");
    lc_world_destroy(w);
}

int main(void)
{
    rays_against_a_box();
    rays_starting_inside_or_on();
    rays_parallel_and_grazing();
    ray_cast_all_sorted();
    points();
    boxes();
    distances();
    consistency();
    bad_input();
    return CHECK_SUMMARY("test_query");
}
