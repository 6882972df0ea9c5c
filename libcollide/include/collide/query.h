/* libcollide: geometric queries on a world's current poses (bodies at a point or in a box, ray casts,
 * the distance between two bodies). Included by collide/collide.h.
 *
 * Bodies are closed convex polygons: a point on an edge is in the body, a body that only touches a box
 * or a ray overlaps it. Every answer is computed in double precision from the body's world vertices
 * (the ones lc_body_get_world_vertices gives), so a query on axis-aligned shapes at representable
 * coordinates is exact, and any other is within round-off of the analytic answer. Queries never change
 * the world; like the getters, a failure returns its status and records its reason for
 * lc_world_last_error(), a success leaves the message as it was. Results list bodies in row order (the
 * order they were added) unless said otherwise. */
#ifndef COLLIDE_QUERY_H
#define COLLIDE_QUERY_H

#include "collide/export.h"
#include "collide/math.h"
#include "collide/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which bodies a query leaves out. A NULL filter leaves out none. */
typedef struct lc_query_filter {
    int skip_static;       /* 1: static bodies are left out, 0: they are not (no other value) */
    lc_body_id skip_body;  /* a body left out (e.g. the one casting the ray); 0 = none. An id that names
                              no body leaves out nothing */
} lc_query_filter;

/* Where a ray from start to end meets a body. */
typedef struct lc_ray_hit {
    lc_body_id body;
    lc_vec2 point;    /* m, world: start + fraction * (end - start) */
    lc_vec2 normal;   /* unit, world: the outward normal of the edge the ray enters through (at a vertex,
                         of the two edges the one facing the ray more squarely, the first on a tie); for
                         a ray starting inside the body, or on its boundary without entering through
                         an edge, the ray's reversed direction */
    double fraction;  /* [0, 1] along the ray; 0 when the ray starts inside or on the body */
} lc_ray_hit;

/* How far apart two bodies are (lc_body_distance). */
typedef struct lc_distance_result {
    double distance;  /* m: > 0 apart (the Euclidean distance between the polygons), 0 touching, < 0
                         overlapping: minus the penetration depth (the shortest translation of one body
                         that leaves them touching) */
    lc_vec2 normal;   /* unit, world, from a towards b: moving b by -distance * normal leaves the pair
                         touching (apart: closer; overlapping: out) */
    lc_vec2 point_a;  /* m, world: apart or touching, a point of a closest to b; overlapping, the point
                         on a's boundary facing point_b */
    lc_vec2 point_b;  /* m, world: apart or touching, a point of b closest to a; overlapping, the point
                         of b deepest in a. Always point_b - point_a = distance * normal */
} lc_distance_result;

/* Bodies containing `point` (m, world; |x|, |y| <= 1e9), boundary included. The first min(count,
 * capacity) ids go to out[0..capacity) (out may be NULL when capacity is 0); *out_count gets the
 * number of bodies found, which may exceed capacity (call again with a larger buffer). */
LC_API lc_status lc_world_query_point(const lc_world *world, lc_vec2 point, const lc_query_filter *filter,
                                      lc_body_id *out, int capacity, int *out_count);
/* Bodies sharing at least one point with the axis-aligned box [lower.x, upper.x] x [lower.y, upper.y]
 * (m, world; lower <= upper componentwise, a box of zero width or height allowed). The exact polygon
 * test, not only the bounding boxes. Output as lc_world_query_point. */
LC_API lc_status lc_world_query_box(const lc_world *world, lc_vec2 lower, lc_vec2 upper, const lc_query_filter *filter,
                                    lc_body_id *out, int capacity, int *out_count);
/* The first body the segment from start to end (m, world, start != end) meets: *out_hit = 1 and the
 * hit in *hit, or *out_hit = 0 (hit untouched). Equal fractions go to the body added first. */
LC_API lc_status lc_world_ray_cast(const lc_world *world, lc_vec2 start, lc_vec2 end, const lc_query_filter *filter,
                                   lc_ray_hit *hit, int *out_hit);
/* Every body the segment meets, one hit each (where the ray enters it), sorted by fraction (equal
 * fractions: the body added first first). The first min(count, capacity) hits go to out (out may be NULL
 * when capacity is 0); *out_count gets the number of bodies hit, which may exceed capacity. */
LC_API lc_status lc_world_ray_cast_all(const lc_world *world, lc_vec2 start, lc_vec2 end, const lc_query_filter *filter,
                                       lc_ray_hit *out, int capacity, int *out_count);
/* The first hit of each of `count` segments (count >= 0), ray i from starts[i] to ends[i], all with one
 * filter: out_found[i] = 1 and the hit in out_hits[i] as lc_world_ray_cast gives it (bit for bit), or
 * out_found[i] = 0 and out_hits[i] untouched. Every ray is checked before any is cast: a bad one fails
 * the call (the message names its index) and nothing is written. One call for a laser scan: the bodies
 * near the rays are found once for all of them. */
LC_API lc_status lc_world_ray_cast_batch(const lc_world *world, const lc_vec2 *starts, const lc_vec2 *ends, int count,
                                         const lc_query_filter *filter, lc_ray_hit *out_hits, int *out_found);
/* 1 in *out_overlap when bodies a and b (a != b) share at least one point (touching counts), else 0. */
LC_API lc_status lc_body_overlap(const lc_world *world, lc_body_id a, lc_body_id b, int *out_overlap);
/* Distance, normal and closest points of bodies a and b (a != b); see lc_distance_result. */
LC_API lc_status lc_body_distance(const lc_world *world, lc_body_id a, lc_body_id b, lc_distance_result *out);

#ifdef __cplusplus
}
#endif

#endif /* COLLIDE_QUERY_H */
