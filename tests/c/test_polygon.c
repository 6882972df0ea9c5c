/* test_polygon: centre of mass and moment of inertia computed from the polygon's area (uniform
 * density) against hand-computed values, for both windings, an offset local frame and a rotated pose.
 *
 * Reference values (per unit mass, about the centre of mass), from the area formulas
 *   A = 1/2 sum c_i, c_i = x_i y_{i+1} - x_{i+1} y_i,  C = sum (p_i + p_{i+1}) c_i / (6A),
 *   J_origin = 1/12 sum c_i (x_i^2 + x_i x_{i+1} + x_{i+1}^2 + y_i^2 + y_i y_{i+1} + y_{i+1}^2),
 *   I/m = J_origin/A - |C|^2, evaluated by hand in exact fractions:
 *   - rectangle 2 x 1 with corners (1,2)..(3,3): C = (2, 5/2), I/m = (2^2 + 1^2)/12 = 5/12
 *   - right triangle (0,0), (3,0), (0,3): C = (1, 1), I/m = (a^2+b^2+c^2)/36 = (9+9+18)/36 = 1
 *   - convex pentagon (0,0), (4,0), (5,2), (2,4), (-1,2): A = 16, C = (2, 5/3), I/m = 101/36
 * Tolerance 1e-12 relative: the formulas are a few dozen floating-point operations on O(1..25)
 * numbers, so round-off is ~1e-15 relative; 1e-12 leaves a wide margin yet catches any wrong
 * formula (a bounding-box guess is off by > 1 %). */
#include "check.h"
#include "scenes.h"

typedef struct poly_case {
    const char *name;
    lc_vec2 v[5];
    int n;
    double cx, cy, i_per_m;
} poly_case;

static void check_case(const poly_case *pc, int reversed)
{
    const double m = 2.5, angle = 0.7, px = 1.25, py = -0.5;
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_vec2 v[5], off, loc[5];
    lc_body_id id;
    const double *s;
    double c = cos(angle), sn = sin(angle);
    int i, k;
    char what[128];
    if (!w) return;
    for (i = 0; i < pc->n; i++) v[i] = pc->v[reversed ? pc->n - 1 - i : i];
    id = sc_poly(w, v, pc->n, px, py, angle, m);

    snprintf(what, sizeof what, "%s%s centre offset x", pc->name, reversed ? " (clockwise)" : "");
    CHECK(lc_body_get_center_offset(w, id, &off) == LC_OK, "%s", "get_center_offset");
    CHECK_REL(off.x, pc->cx, 1e-12, what);
    snprintf(what, sizeof what, "%s%s centre offset y", pc->name, reversed ? " (clockwise)" : "");
    CHECK_REL(off.y, pc->cy, 1e-12, what);

    snprintf(what, sizeof what, "%s%s inertia", pc->name, reversed ? " (clockwise)" : "");
    CHECK_REL(sc_inertia(w, id), m * pc->i_per_m, 1e-12, what);
    CHECK_REL(sc_mass(w, id), m, 1e-15, "mass as given");

    /* The state holds the centre of mass: position + R(angle) * offset (positions O(3) m,
     * round-off ~1e-15, tolerance 1e-12 m). */
    s = sc_row(w, id);
    CHECK_NEAR(s[0], px + c * pc->cx - sn * pc->cy, 1e-12, "centre of mass x in the world");
    CHECK_NEAR(s[1], py + sn * pc->cx + c * pc->cy, 1e-12, "centre of mass y in the world");
    CHECK_NEAR(s[2], angle, 1e-15, "angle");

    /* Local vertices are the given ones relative to the centre of mass (same set, any order). */
    CHECK(lc_body_vertex_count(w, id) == pc->n, "%s vertex count %d", pc->name, lc_body_vertex_count(w, id));
    CHECK(lc_body_get_local_vertices(w, id, loc, pc->n) == LC_OK, "%s", "get_local_vertices");
    for (i = 0; i < pc->n; i++) {
        double best = INFINITY;
        for (k = 0; k < pc->n; k++) {
            double dx = loc[k].x - (pc->v[i].x - pc->cx), dy = loc[k].y - (pc->v[i].y - pc->cy);
            double dd = sqrt(dx * dx + dy * dy);
            if (dd < best) best = dd;
        }
        CHECK(best <= 1e-12, "%s local vertex %d not found (closest %.3e m)", pc->name, i, best);
    }

    /* The inertia scales with the mass (lc_body_set_mass). */
    CHECK(lc_body_set_mass(w, id, 4.0 * m) == LC_OK, "%s", "set_mass");
    CHECK_REL(sc_inertia(w, id), 4.0 * m * pc->i_per_m, 1e-12, "inertia after set_mass");
    lc_world_destroy(w);
}

int main(void)
{
    const poly_case cases[3] = {
        {"rectangle 2x1", {{1, 2}, {3, 2}, {3, 3}, {1, 3}, {0, 0}}, 4, 2.0, 2.5, 5.0 / 12.0},
        {"triangle", {{0, 0}, {3, 0}, {0, 3}, {0, 0}, {0, 0}}, 3, 1.0, 1.0, 1.0},
        {"pentagon", {{0, 0}, {4, 0}, {5, 2}, {2, 4}, {-1, 2}}, 5, 2.0, 5.0 / 3.0, 101.0 / 36.0},
    };
    int i;
    lc_vec2 r[4];
    for (i = 0; i < 3; i++) {
        check_case(&cases[i], 0);
        check_case(&cases[i], 1);
    }
    /* lc_make_rectangle: a w x h rectangle centred on the origin, counter-clockwise (exact numbers). */
    CHECK(lc_make_rectangle(2.0, 1.0, r) == LC_OK, "%s", "make_rectangle");
    {
        double area2 = 0.0, sx = 0.0, sy = 0.0;
        for (i = 0; i < 4; i++) {
            area2 += r[i].x * r[(i + 1) % 4].y - r[(i + 1) % 4].x * r[i].y;
            sx += r[i].x;
            sy += r[i].y;
            CHECK(fabs(r[i].x) == 1.0 && fabs(r[i].y) == 0.5, "rectangle corner %d = (%g, %g)", i, r[i].x, r[i].y);
        }
        CHECK(area2 == 4.0, "rectangle is counter-clockwise with area 2 (2*signed area %g)", area2);
        CHECK(sx == 0.0 && sy == 0.0, "rectangle centred (%g, %g)", sx, sy);
    }
    return CHECK_SUMMARY("test_polygon");
}
