/* Queries on the current poses (collide/query.h): bodies at a point or sharing a point with a box, ray
 * casts, and the overlap and distance of two bodies. The geometry is on each body's world vertices as
 * lc_body_get_world_vertices gives them (counter-clockwise, as polygon.c stores them), closed polygons
 * throughout; the bodies' cached bounding boxes (broad_phase.c), which bound those vertices exactly,
 * pass over the bodies that cannot answer before any polygon is looked at. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "world.h"

typedef struct polygon {
    int count;
    lc_vec2 v[LC_MAX_POLYGON_VERTICES];
} polygon;

static void world_polygon(const lc_world *w, int row, polygon *p)
{
    p->count = w->shape[row].count;
    lc_body_get_world_vertices(w, w->ids[row], p->v, LC_MAX_POLYGON_VERTICES);
}

static lc_vec2 edge_of(const polygon *p, int k) { return lc_sub(p->v[(k + 1) % p->count], p->v[k]); }

/* Outward unit normal of edge k (as lc_shape_build computes them). */
static lc_vec2 edge_normal(const polygon *p, int k)
{
    lc_vec2 e = edge_of(p, k);
    double len = sqrt(lc_dot(e, e));
    return lc_v(e.y / len, -e.x / len);
}

/* Body row's bounding box at the current state: x0, y0, x1, y1 (the broad phase's, from its cache). */
static void body_bounds(const lc_world *w, int row, double box[4])
{
    lc_swept_box((lc_world *)w, w->state, w->state, row, 0.0, box);
}

static int boxes_overlap(const double a[4], const double b[4])
{
    return a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3];
}

static int skipped(const lc_world *w, const lc_query_filter *f, int row)
{
    return f != NULL && ((f->skip_static && w->is_static[row]) || w->ids[row] == f->skip_body);
}

/* ---- argument checks (w is not NULL) ---------------------------------------------------------- */

static lc_status check_filter(lc_world *w, const lc_query_filter *f)
{
    if (f != NULL && f->skip_static != 0 && f->skip_static != 1)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "filter skip_static is 0 or 1, not %d", f->skip_static);
    return LC_OK;
}

static lc_status check_output(lc_world *w, const void *out, int capacity, const int *out_count)
{
    if (out_count == NULL) return lc_fail(w, LC_ERR_NULL, "out_count is NULL");
    if (capacity < 0) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "capacity = %d is negative", capacity);
    if (out == NULL && capacity > 0) return lc_fail(w, LC_ERR_NULL, "out is NULL but capacity is %d", capacity);
    return LC_OK;
}

/* A ray's ends (named start_name, end_name in messages) finite and within range, and apart; what: how a
 * message names the ray. */
static lc_status check_segment(lc_world *w, lc_vec2 start, lc_vec2 end, const char *start_name, const char *end_name,
                               const char *what)
{
    LC_TRY(lc_check_vec(w, start, 1e9, start_name));
    LC_TRY(lc_check_vec(w, end, 1e9, end_name));
    if (start.x == end.x && start.y == end.y)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "%s has zero length (start = end = (%g, %g))", what, start.x, start.y);
    return LC_OK;
}

static lc_status check_ray(lc_world *w, lc_vec2 start, lc_vec2 end, const lc_query_filter *f)
{
    LC_TRY(check_segment(w, start, end, "start", "end", "the ray"));
    return check_filter(w, f);
}

/* ---- bodies at a point, in a box -------------------------------------------------------------- */

/* 1 if polygon p and the box (x0, y0, x1, y1) share a point: no edge of p has the whole box outside
 * its line (the box's own axes are the bounding boxes' test, done before). */
static int polygon_meets_box(const polygon *p, const double box[4])
{
    int k, i;
    for (k = 0; k < p->count; ++k) {
        lc_vec2 e = edge_of(p, k);
        double most = -INFINITY;
        for (i = 0; i < 4; ++i) {
            lc_vec2 corner = lc_v(box[i & 1 ? 2 : 0], box[i & 2 ? 3 : 1]);
            double inside = lc_cross(e, lc_sub(corner, p->v[k]));   /* >= 0: on the inner side */
            if (inside > most) most = inside;
        }
        if (most < 0.0) return 0;
    }
    return 1;
}

/* The bodies sharing a point with the box [lower, upper] (a point: lower = upper, both named `lower_name`
 * and `upper_name` in the messages). */
static lc_status query_box(const lc_world *world, lc_vec2 lower, lc_vec2 upper, const char *lower_name,
                           const char *upper_name, const lc_query_filter *f, lc_body_id *out, int capacity,
                           int *out_count)
{
    lc_world *w = (lc_world *)world;
    double box[4];
    int row, count = 0;
    if (w == NULL) return LC_ERR_NULL;
    LC_TRY(check_output(w, out, capacity, out_count));
    LC_TRY(lc_check_vec(w, lower, 1e9, lower_name));
    LC_TRY(lc_check_vec(w, upper, 1e9, upper_name));
    if (lower.x > upper.x || lower.y > upper.y)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "box lower (%g, %g) exceeds upper (%g, %g)", lower.x, lower.y,
                       upper.x, upper.y);
    LC_TRY(check_filter(w, f));
    box[0] = lower.x;
    box[1] = lower.y;
    box[2] = upper.x;
    box[3] = upper.y;
    for (row = 0; row < w->count; ++row) {
        double bounds[4];
        polygon p;
        if (skipped(w, f, row)) continue;
        body_bounds(w, row, bounds);
        if (!boxes_overlap(bounds, box)) continue;
        world_polygon(w, row, &p);
        if (!polygon_meets_box(&p, box)) continue;
        if (count < capacity) out[count] = w->ids[row];
        count++;
    }
    *out_count = count;
    return LC_OK;
}

lc_status lc_world_query_point(const lc_world *world, lc_vec2 point, const lc_query_filter *filter,
                               lc_body_id *out, int capacity, int *out_count)
{
    return query_box(world, point, point, "point", "point", filter, out, capacity, out_count);
}

lc_status lc_world_query_box(const lc_world *world, lc_vec2 lower, lc_vec2 upper, const lc_query_filter *filter,
                             lc_body_id *out, int capacity, int *out_count)
{
    return query_box(world, lower, upper, "lower", "upper", filter, out, capacity, out_count);
}

/* ---- ray casts -------------------------------------------------------------------------------- */

/* Where the segment start + t d, t in [0, 1], first meets polygon p (Cyrus-Beck clipping against each
 * edge's half-plane): 1 and hit's point, normal and fraction, or 0. */
static int ray_polygon(const polygon *p, lc_vec2 start, lc_vec2 d, lc_ray_hit *hit)
{
    double t_in = -INFINITY, t_out = 1.0, facing = 0.0, t;
    int k, entry = -1;
    for (k = 0; k < p->count; ++k) {
        lc_vec2 e = edge_of(p, k);
        double s = lc_cross(e, lc_sub(start, p->v[k]));   /* >= 0: start on the inner side of the edge's line */
        double r = lc_cross(e, d);                         /* > 0: the ray crosses that line inwards */
        if (r > 0.0) {
            double f = r / sqrt(lc_dot(e, e));             /* |d| times the cosine of the incidence */
            t = -s / r;
            if (t > t_in || (t == t_in && f > facing)) {
                t_in = t;
                entry = k;
                facing = f;
            }
        } else if (r < 0.0) {
            t = -s / r;
            if (t < t_out) t_out = t;
        } else if (s < 0.0) {
            return 0;                                      /* along the line, outside it */
        }
    }
    t = t_in > 0.0 ? t_in : 0.0;
    if (!(t <= t_out)) return 0;
    hit->fraction = t;
    hit->point = t == 0.0 ? start : lc_add(start, lc_scale(d, t));
    if (entry >= 0 && t_in >= 0.0) {
        hit->normal = edge_normal(p, entry);
    } else {
        double len = hypot(d.x, d.y);                      /* started inside, or on it going out or along */
        hit->normal = lc_v(-d.x / len, -d.y / len);
    }
    return 1;
}

/* 1 if x comes before y along the ray (equal fractions: the lower id, i.e. the body added first). */
static int hit_before(const lc_ray_hit *x, const lc_ray_hit *y)
{
    return x->fraction < y->fraction || (x->fraction == y->fraction && x->body < y->body);
}

static int cmp_hit(const void *x, const void *y)
{
    return hit_before(x, y) ? -1 : hit_before(y, x) ? 1 : 0;
}

/* Calls fn with the hit of each body the segment from start to end meets, in row order. */
typedef void (*hit_fn)(const lc_ray_hit *hit, void *ctx);

/* The box (x0, y0, x1, y1) around the segment from a to b. */
static void segment_box(lc_vec2 a, lc_vec2 b, double box[4])
{
    box[0] = fmin(a.x, b.x);
    box[1] = fmin(a.y, b.y);
    box[2] = fmax(a.x, b.x);
    box[3] = fmax(a.y, b.y);
}

/* The ray from start along d against the body of row (its box: bounds; the ray's: span); fn on a hit. */
static void cast_row(const lc_world *w, int row, const double bounds[4], const double span[4], lc_vec2 start,
                     lc_vec2 d, hit_fn fn, void *ctx)
{
    polygon p;
    lc_ray_hit hit;
    if (!boxes_overlap(bounds, span)) return;
    world_polygon(w, row, &p);
    if (!ray_polygon(&p, start, d, &hit)) return;
    hit.body = w->ids[row];
    fn(&hit, ctx);
}

static void cast(const lc_world *w, lc_vec2 start, lc_vec2 end, const lc_query_filter *f, hit_fn fn, void *ctx)
{
    lc_vec2 d = lc_sub(end, start);
    double span[4];
    int row;
    segment_box(start, end, span);
    for (row = 0; row < w->count; ++row) {
        double bounds[4];
        if (skipped(w, f, row)) continue;
        body_bounds(w, row, bounds);
        cast_row(w, row, bounds, span, start, d, fn, ctx);
    }
}

typedef struct first_hit {
    lc_ray_hit best;
    int found;
} first_hit;

static void keep_first(const lc_ray_hit *hit, void *ctx)
{
    first_hit *fh = ctx;
    if (!fh->found || hit_before(hit, &fh->best)) fh->best = *hit;
    fh->found = 1;
}

lc_status lc_world_ray_cast(const lc_world *world, lc_vec2 start, lc_vec2 end, const lc_query_filter *filter,
                            lc_ray_hit *hit, int *out_hit)
{
    lc_world *w = (lc_world *)world;
    first_hit fh;
    if (w == NULL) return LC_ERR_NULL;
    if (hit == NULL || out_hit == NULL) return lc_fail(w, LC_ERR_NULL, "hit or out_hit is NULL");
    LC_TRY(check_ray(w, start, end, filter));
    fh.found = 0;
    cast(world, start, end, filter, keep_first, &fh);
    if (fh.found) *hit = fh.best;
    *out_hit = fh.found;
    return LC_OK;
}

/* The `capacity` first hits so far in out[0..min(count, capacity)), a max-heap by hit_before. */
typedef struct all_hits {
    lc_ray_hit *out;
    int capacity, count;
} all_hits;

static void keep_all(const lc_ray_hit *hit, void *ctx)
{
    all_hits *ah = ctx;
    lc_ray_hit *h = ah->out;
    int n = ah->count < ah->capacity ? ah->count : ah->capacity, i = 0;
    ah->count++;
    if (n < ah->capacity) {
        for (i = n; i > 0 && hit_before(&h[(i - 1) / 2], hit); i = (i - 1) / 2) h[i] = h[(i - 1) / 2];
        h[i] = *hit;
        return;
    }
    if (n == 0 || !hit_before(hit, &h[0])) return;
    for (;;) {   /* the last of the kept hits gives way: sift the new one down from the top */
        int c = 2 * i + 1;
        if (c >= n) break;
        if (c + 1 < n && hit_before(&h[c], &h[c + 1])) c++;
        if (!hit_before(hit, &h[c])) break;
        h[i] = h[c];
        i = c;
    }
    h[i] = *hit;
}

lc_status lc_world_ray_cast_all(const lc_world *world, lc_vec2 start, lc_vec2 end, const lc_query_filter *filter,
                                lc_ray_hit *out, int capacity, int *out_count)
{
    lc_world *w = (lc_world *)world;
    all_hits ah;
    if (w == NULL) return LC_ERR_NULL;
    LC_TRY(check_output(w, out, capacity, out_count));
    LC_TRY(check_ray(w, start, end, filter));
    ah.out = out;
    ah.capacity = capacity;
    ah.count = 0;
    cast(world, start, end, filter, keep_all, &ah);
    if (ah.count > 1 && capacity > 1)
        qsort(out, (size_t)(ah.count < capacity ? ah.count : capacity), sizeof *out, cmp_hit);
    *out_count = ah.count;
    return LC_OK;
}

/* ---- many rays at once ------------------------------------------------------------------------ */

/* Ray i of a batch checked as lc_world_ray_cast checks its ray, the message naming the index. */
static lc_status check_batch_ray(lc_world *w, const lc_vec2 *starts, const lc_vec2 *ends, int i)
{
    char start_name[32], end_name[32], what[32];
    snprintf(start_name, sizeof start_name, "starts[%d]", i);
    snprintf(end_name, sizeof end_name, "ends[%d]", i);
    snprintf(what, sizeof what, "ray %d", i);
    return check_segment(w, starts[i], ends[i], start_name, end_name, what);
}

static void extend_box(double box[4], lc_vec2 p)
{
    box[0] = fmin(box[0], p.x);
    box[1] = fmin(box[1], p.y);
    box[2] = fmax(box[2], p.x);
    box[3] = fmax(box[3], p.y);
}

lc_status lc_world_ray_cast_batch(const lc_world *world, const lc_vec2 *starts, const lc_vec2 *ends, int count,
                                  const lc_query_filter *filter, lc_ray_hit *out_hits, int *out_found)
{
    lc_world *w = (lc_world *)world;
    double all[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    double *bounds;
    int *rows, nrows = 0, i, k;
    if (w == NULL) return LC_ERR_NULL;
    if (count < 0) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "count = %d is negative", count);
    if (count > 0 && (starts == NULL || ends == NULL || out_hits == NULL || out_found == NULL))
        return lc_fail(w, LC_ERR_NULL, "starts, ends, out_hits or out_found is NULL with count %d", count);
    LC_TRY(check_filter(w, filter));
    for (i = 0; i < count; ++i) {
        LC_TRY(check_batch_ray(w, starts, ends, i));
        extend_box(all, starts[i]);
        extend_box(all, ends[i]);
    }
    if (count == 0) return LC_OK;
    /* The bodies whose box meets the box around every ray, found once: each ray then looks at those
     * only (a scanner's rays span a few metres of a large world). Same rows in the same order as
     * cast() visits, so each ray's answer is lc_world_ray_cast's, bit for bit. */
    rows = malloc((size_t)(w->count > 0 ? w->count : 1) * sizeof *rows);
    bounds = malloc((size_t)(w->count > 0 ? w->count : 1) * 4 * sizeof *bounds);
    if (rows == NULL || bounds == NULL) {
        free(rows);
        free(bounds);
        return lc_fail(w, LC_ERR_NO_MEMORY, "out of memory for a batch of %d rays over %d bodies", count, w->count);
    }
    for (k = 0; k < w->count; ++k) {
        if (skipped(w, filter, k)) continue;
        body_bounds(w, k, bounds + 4 * nrows);
        if (boxes_overlap(bounds + 4 * nrows, all)) rows[nrows++] = k;
    }
    for (i = 0; i < count; ++i) {
        lc_vec2 d = lc_sub(ends[i], starts[i]);
        double span[4];
        first_hit fh;
        segment_box(starts[i], ends[i], span);
        fh.found = 0;
        for (k = 0; k < nrows; ++k) cast_row(w, rows[k], bounds + 4 * k, span, starts[i], d, keep_first, &fh);
        out_found[i] = fh.found;
        if (fh.found) out_hits[i] = fh.best;
    }
    free(rows);
    free(bounds);
    return LC_OK;
}

/* ---- two bodies ------------------------------------------------------------------------------- */

/* Rows of two different bodies. */
static lc_status pair_rows(lc_world *w, lc_body_id a, lc_body_id b, int *ra, int *rb)
{
    LC_GET_ROW(w, a, *ra);
    LC_GET_ROW(w, b, *rb);
    if (a == b) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body a and body b are the same body (%u)", (unsigned)a);
    return LC_OK;
}

lc_status lc_body_overlap(const lc_world *world, lc_body_id a, lc_body_id b, int *out_overlap)
{
    lc_world *w = (lc_world *)world;
    int ra = -1, rb = -1;
    if (w == NULL) return LC_ERR_NULL;
    if (out_overlap == NULL) return lc_fail(w, LC_ERR_NULL, "out_overlap is NULL");
    LC_TRY(pair_rows(w, a, b, &ra, &rb));
    /* the separating axis test, as lc_body_distance decides it: overlap exactly when distance <= 0 */
    *out_overlap = !(lc_pair_separation(w, w->state, ra, rb) > 0.0);
    return LC_OK;
}

/* The nearest of p's vertices to q's edges so far: *best (squared distance), at p's vertex *at_p and
 * q's point *at_q. */
static void vertices_to_edges(const polygon *p, const polygon *q, double *best, lc_vec2 *at_p, lc_vec2 *at_q)
{
    int i, k;
    for (i = 0; i < p->count; ++i)
        for (k = 0; k < q->count; ++k) {
            lc_vec2 a = q->v[k], e = edge_of(q, k), x, g;
            double t = lc_dot(lc_sub(p->v[i], a), e) / lc_dot(e, e), d2;
            x = t <= 0.0 ? a : t >= 1.0 ? q->v[(k + 1) % q->count] : lc_add(a, lc_scale(e, t));
            g = lc_sub(p->v[i], x);
            d2 = lc_dot(g, g);
            if (d2 < *best) {
                *best = d2;
                *at_p = p->v[i];
                *at_q = x;
            }
        }
}

lc_status lc_body_distance(const lc_world *world, lc_body_id a, lc_body_id b, lc_distance_result *out)
{
    lc_world *w = (lc_world *)world;
    int ra = -1, rb = -1, ref, edge;
    double sep;
    polygon pa, pb;
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail(w, LC_ERR_NULL, "out is NULL");
    LC_TRY(pair_rows(w, a, b, &ra, &rb));
    sep = lc_pair_separation_axis(w, w->state, ra, rb, &ref, &edge);
    world_polygon(w, ra, &pa);
    world_polygon(w, rb, &pb);
    if (sep > 0.0) {
        /* apart: two disjoint convex polygons are nearest at a vertex of one and an edge of the other */
        double best = INFINITY, dist;
        lc_vec2 pa_at, pb_at, g;
        vertices_to_edges(&pa, &pb, &best, &pa_at, &pb_at);
        vertices_to_edges(&pb, &pa, &best, &pb_at, &pa_at);
        g = lc_sub(pb_at, pa_at);
        dist = hypot(g.x, g.y);
        out->point_a = pa_at;
        out->point_b = pb_at;
        if (dist > 0.0) {
            out->normal = lc_scale(g, 1.0 / dist);
            out->distance = dist;
        } else {
            /* the separating axis proves them apart: never 0 for round-off in the world vertices */
            lc_vec2 n = edge_normal(ref == ra ? &pa : &pb, edge);
            out->normal = ref == ra ? n : lc_scale(n, -1.0);
            out->distance = sep;
        }
    } else {
        /* touching or overlapping: the separating axis test's least-overlap face is the shortest way
         * out; the other body's vertex deepest behind it and that vertex's image on the face */
        const polygon *rp = ref == ra ? &pa : &pb, *ip = ref == ra ? &pb : &pa;
        lc_vec2 n = edge_normal(rp, edge), deep = ip->v[0], face;
        double least = INFINITY;
        int i;
        for (i = 0; i < ip->count; ++i) {
            double h = lc_dot(n, lc_sub(ip->v[i], rp->v[edge]));
            if (h < least) {
                least = h;
                deep = ip->v[i];
            }
        }
        if (sep == 0.0) sep = 0.0;   /* no -0 */
        face = lc_sub(deep, lc_scale(n, sep));
        out->distance = sep;
        out->normal = ref == ra ? n : lc_scale(n, -1.0);
        out->point_a = ref == ra ? face : deep;
        out->point_b = ref == ra ? deep : face;
    }
    return LC_OK;
}
