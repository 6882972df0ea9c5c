/* Convex polygons: validation and mass properties computed from the area (uniform density), about the
 * centroid or about a given centre of mass. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"

static const double LC_PI = 3.14159265358979323846;

lc_status lc_shape_build(lc_shape *out, lc_vec2 *store, const lc_vec2 *v, int count, const lc_vec2 *center, char *why,
                         size_t why_len)
{
    lc_vec2 p[LC_MAX_POLYGON_VERTICES];
    double area2 = 0.0, cx = 0.0, cy = 0.0, scale = 0.0, j = 0.0, ox, oy;
    int i, sign = 0;
    if (v == NULL) {
        snprintf(why, why_len, "vertices is NULL");
        return LC_ERR_NULL;
    }
    if (count < 3 || count > LC_MAX_POLYGON_VERTICES) {
        snprintf(why, why_len, "vertex_count %d is outside [3, %d]", count, LC_MAX_POLYGON_VERTICES);
        return LC_ERR_BAD_POLYGON;
    }
    for (i = 0; i < count; ++i) {
        if (!isfinite(v[i].x) || !isfinite(v[i].y)) {
            snprintf(why, why_len, "vertex %d is not finite", i);
            return LC_ERR_NOT_FINITE;
        }
        if (fabs(v[i].x) > 1e6 || fabs(v[i].y) > 1e6) {
            snprintf(why, why_len, "vertex %d is farther than 1e6 m from the local origin", i);
            return LC_ERR_OUT_OF_RANGE;
        }
        p[i] = v[i];
        scale = fmax(scale, fmax(fabs(v[i].x), fabs(v[i].y)));
    }
    for (i = 0; i < count; ++i) area2 += lc_cross(p[i], p[(i + 1) % count]);
    /* Accept either winding; store counter-clockwise so edge normals point outward. */
    if (area2 < 0.0) {
        for (i = 0; i < count / 2; ++i) {
            lc_vec2 t = p[i];
            p[i] = p[count - 1 - i];
            p[count - 1 - i] = t;
        }
        area2 = -area2;
    }
    /* Degenerate: zero area relative to the polygon's size (collinear or repeated points). */
    if (!(area2 > 1e-12 * scale * scale) || scale == 0.0) {
        snprintf(why, why_len, "polygon is degenerate (area %.3g m^2)", area2 / 2.0);
        return LC_ERR_BAD_POLYGON;
    }
    {
        double turning = 0.0;
        for (i = 0; i < count; ++i) {
            lc_vec2 e0 = lc_sub(p[(i + 1) % count], p[i]);
            lc_vec2 e1 = lc_sub(p[(i + 2) % count], p[(i + 1) % count]);
            double l0 = sqrt(lc_dot(e0, e0)), l1 = sqrt(lc_dot(e1, e1));
            double c;
            if (l0 <= 1e-9 * scale || l1 <= 1e-9 * scale) {
                snprintf(why, why_len, "vertices %d and %d coincide", (i + 1) % count,
                         l0 <= 1e-9 * scale ? i : (i + 2) % count);
                return LC_ERR_BAD_POLYGON;
            }
            c = lc_cross(e0, e1) / (l0 * l1);
            if (c <= 1e-9) {
                snprintf(why, why_len, c > -1e-9 ? "vertex %d is collinear with its neighbours"
                                                 : "polygon is not convex at vertex %d",
                         (i + 1) % count);
                return LC_ERR_BAD_POLYGON;
            }
            if (sign == 0) sign = 1;
            turning += atan2(lc_cross(e0, e1), lc_dot(e0, e1));
        }
        /* A star polygon turns left everywhere but winds more than once. */
        if (fabs(turning - 2.0 * LC_PI) > 1e-6) {
            snprintf(why, why_len, "polygon is self-intersecting (winds %.2f times)", turning / (2.0 * LC_PI));
            return LC_ERR_BAD_POLYGON;
        }
    }
    /* Centroid and polar moment of a uniform polygon from its triangle fan about the origin. */
    for (i = 0; i < count; ++i) {
        lc_vec2 a = p[i], b = p[(i + 1) % count];
        double c = lc_cross(a, b);
        cx += (a.x + b.x) * c;
        cy += (a.y + b.y) * c;
    }
    cx /= 3.0 * area2;
    cy /= 3.0 * area2;
    ox = cx;
    oy = cy;
    if (center != NULL) {
        /* A given centre of mass: the body's mass lies in its (convex) polygon, so its centre does too;
         * points on the boundary are accepted to a rounding of the polygon's size. */
        if (!isfinite(center->x) || !isfinite(center->y)) {
            snprintf(why, why_len, "center_of_mass is not finite (%g, %g)", center->x, center->y);
            return LC_ERR_NOT_FINITE;
        }
        for (i = 0; i < count; ++i) {
            lc_vec2 e = lc_sub(p[(i + 1) % count], p[i]);
            double inside = lc_cross(e, lc_sub(*center, p[i])) / sqrt(lc_dot(e, e));
            if (inside < -1e-12 * scale) {
                snprintf(why, why_len, "center_of_mass (%g, %g) is outside the polygon (%.3g m beyond its edge %d); "
                         "a body's mass lies inside its polygon", center->x, center->y, -inside, i);
                return LC_ERR_OUT_OF_RANGE;
            }
        }
        ox = center->x;
        oy = center->y;
    }
    memset(out, 0, sizeof *out);
    out->count = count;
    out->v = store;
    out->n = store + count;
    out->center_offset = lc_v(ox, oy);
    out->area = area2 / 2.0;
    for (i = 0; i < count; ++i) out->v[i] = lc_v(p[i].x - ox, p[i].y - oy);
    out->min_edge = HUGE_VAL;
    for (i = 0; i < count; ++i) {
        lc_vec2 a = out->v[i], b = out->v[(i + 1) % count];
        lc_vec2 e = lc_sub(b, a);
        double len = sqrt(lc_dot(e, e));
        double c = lc_cross(a, b);
        out->n[i] = lc_v(e.y / len, -e.x / len);
        /* second moment of the triangle (0, a, b) about the centre of mass, the origin, per unit area */
        j += c * (lc_dot(a, a) + lc_dot(a, b) + lc_dot(b, b));
        out->radius = fmax(out->radius, sqrt(lc_dot(a, a)));
        out->min_edge = fmin(out->min_edge, len);
    }
    out->unit_inertia = (j / 12.0) / out->area;
    out->inertia_per_mass = out->unit_inertia;
    (void)sign;
    return LC_OK;
}

int lc_shape_keep(lc_shape *s, int count)
{
    unsigned char *raw = malloc((size_t)(count > 0 ? 2 * count : 1) * sizeof(lc_vec2) + LC_SHAPE_ALIGN - 1);
    size_t skip;
    lc_vec2 *block;
    if (raw == NULL) return -1;
    skip = (LC_SHAPE_ALIGN - (size_t)((uintptr_t)raw % LC_SHAPE_ALIGN)) % LC_SHAPE_ALIGN;
    block = (lc_vec2 *)(void *)(raw + skip);
    if (s->v != NULL) memcpy(block, s->v, (size_t)count * sizeof *block);
    if (s->n != NULL) memcpy(block + count, s->n, (size_t)count * sizeof *block);
    s->v = block;
    s->n = block + count;
    s->block_skip = (int)skip;
    return 0;
}

void lc_shape_release(lc_shape *s)
{
    if (s->v != NULL) free((unsigned char *)s->v - s->block_skip);
    s->v = s->n = NULL;
}

lc_status lc_make_rectangle(double width, double height, lc_vec2 out[4])
{
    if (out == NULL) return LC_ERR_NULL;
    if (!isfinite(width) || !isfinite(height)) return LC_ERR_NOT_FINITE;
    if (!(width > 0.0) || !(height > 0.0) || width > 1e6 || height > 1e6) return LC_ERR_OUT_OF_RANGE;
    out[0] = lc_v(-width / 2, -height / 2);
    out[1] = lc_v(width / 2, -height / 2);
    out[2] = lc_v(width / 2, height / 2);
    out[3] = lc_v(-width / 2, height / 2);
    return LC_OK;
}
