/* test_ray_batch: lc_world_ray_cast_batch against lc_world_ray_cast, ray by ray, bit for bit (hit or not,
 * body, point, normal, fraction) on a random scene of turned boxes with random rays, long ones crossing
 * the scene, short ones, rays starting inside bodies, with and without a filter; a laser fan inside four
 * walls against the analytic ranges (axis-aligned walls at representable coordinates: exact); and bad
 * input: the specific status, a message naming the ray's index, nothing written. */
#include <string.h>
#include "check.h"
#include "scenes.h"

#define NBODIES 60
#define NRAYS 2000

static lc_vec2 V(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

static int same_hit(const lc_ray_hit *a, const lc_ray_hit *b)
{
    return a->body == b->body && memcmp(&a->point, &b->point, sizeof a->point) == 0
        && memcmp(&a->normal, &b->normal, sizeof a->normal) == 0
        && memcmp(&a->fraction, &b->fraction, sizeof a->fraction) == 0;
}

static void batch_equals_single_casts(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    static lc_vec2 starts[NRAYS], ends[NRAYS];
    static lc_ray_hit hits[NRAYS];
    static int found[NRAYS];
    lc_body_id ids[NBODIES];
    lc_query_filter filters[3];
    sc_rng rng = {12345};
    int i, f, nhit = 0, nmiss = 0, ninside = 0;
    for (i = 0; i < NBODIES; ++i)
        ids[i] = sc_box(w, sc_uniform(&rng, 0.2, 1.5), sc_uniform(&rng, 0.2, 1.5), sc_uniform(&rng, -10, 10),
                        sc_uniform(&rng, -10, 10), sc_uniform(&rng, -3, 3), 0, 0, 0, 1, 1);
    sc_static_box(w, 30, 1, 0, -11, 1);
    for (i = 0; i < NRAYS; ++i) {
        double len = i % 3 == 0 ? 30.0 : sc_uniform(&rng, 0.01, 3.0), a = sc_uniform(&rng, -3.2, 3.2);
        starts[i] = V(sc_uniform(&rng, -11, 11), sc_uniform(&rng, -11, 11));
        ends[i] = V(starts[i].x + len * cos(a), starts[i].y + len * sin(a));
    }
    filters[0].skip_static = 0;
    filters[0].skip_body = 0;
    filters[1].skip_static = 1;
    filters[1].skip_body = ids[7];
    for (f = 0; f < 3; ++f) {
        const lc_query_filter *flt = f == 2 ? NULL : &filters[f];
        lc_status s = lc_world_ray_cast_batch(w, starts, ends, NRAYS, flt, hits, found);
        CHECK(s == LC_OK, "batch -> %s: %s", lc_status_string(s), lc_world_last_error(w));
        for (i = 0; i < NRAYS; ++i) {
            lc_ray_hit one;
            int got = -1;
            s = lc_world_ray_cast(w, starts[i], ends[i], flt, &one, &got);
            CHECK(s == LC_OK, "ray_cast %d -> %s", i, lc_status_string(s));
            CHECK(found[i] == got, "filter %d ray %d: batch found %d, single %d", f, i, found[i], got);
            if (got == 1) {
                CHECK(same_hit(&hits[i], &one), "filter %d ray %d: batch hit differs from the single cast", f, i);
                nhit++;
                ninside += one.fraction == 0.0;
            } else {
                nmiss++;
            }
        }
    }
    /* the scene covers every case: hits, misses and rays that start inside a body */
    CHECK(nhit > 500 && nmiss > 500 && ninside > 10, "hits %d, misses %d, starting inside %d", nhit, nmiss,
          ninside);
    lc_world_destroy(w);
}

/* A scanner at (x0, y0) inside walls whose inner faces bound [-4, 6] x [-2, 3]: 360 rays of 20 m, each
 * ending on a wall at an exactly computable range where the direction is axis-aligned. */
static void fan_inside_walls(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_vec2 starts[4], ends[4];
    lc_ray_hit hits[4];
    int found[4], i;
    const double x0 = 1.0, y0 = 0.5;
    const double want[4] = {5.0, 2.5, 5.0, 2.5};  /* +x, +y, -x, -y */
    const double nx[4] = {-1, 0, 1, 0}, ny[4] = {0, -1, 0, 1};
    lc_status s = lc_world_add_walls(w, -4, -2, 6, 3, 1.0, 1.0, NULL);
    CHECK(s == LC_OK, "walls -> %s", lc_status_string(s));
    for (i = 0; i < 4; ++i) {
        starts[i] = V(x0, y0);
        ends[i] = V(x0 + (i == 0 ? 20.0 : i == 2 ? -20.0 : 0.0), y0 + (i == 1 ? 20.0 : i == 3 ? -20.0 : 0.0));
    }
    s = lc_world_ray_cast_batch(w, starts, ends, 4, NULL, hits, found);
    CHECK(s == LC_OK, "batch -> %s", lc_status_string(s));
    for (i = 0; i < 4; ++i) {
        double dx = hits[i].point.x - x0, dy = hits[i].point.y - y0;
        CHECK(found[i] == 1, "ray %d found %d", i, found[i]);
        CHECK(sqrt(dx * dx + dy * dy) == want[i], "ray %d range %.17g, expected %g", i, sqrt(dx * dx + dy * dy),
              want[i]);
        CHECK(hits[i].fraction * 20.0 == want[i], "ray %d fraction %.17g", i, hits[i].fraction);
        CHECK(hits[i].normal.x == nx[i] && hits[i].normal.y == ny[i], "ray %d normal (%g, %g)", i,
              hits[i].normal.x, hits[i].normal.y);
    }
    lc_world_destroy(w);
}

static void bad_input(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_vec2 starts[3], ends[3];
    lc_ray_hit hits[3];
    int found[3] = {7, 7, 7}, i;
    lc_query_filter bad_filter = {2, 0};
    lc_status s;
    sc_box(w, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1);
    for (i = 0; i < 3; ++i) {
        starts[i] = V(-5, 0.1 * i);
        ends[i] = V(5, 0.1 * i);
    }
    memset(hits, 0xab, sizeof hits);

    s = lc_world_ray_cast_batch(NULL, starts, ends, 3, NULL, hits, found);
    CHECK(s == LC_ERR_NULL, "NULL world -> %s", lc_status_string(s));
    s = lc_world_ray_cast_batch(w, starts, ends, -1, NULL, hits, found);
    CHECK(s == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "count"), "count -1 -> %s: %s",
          lc_status_string(s), lc_world_last_error(w));
    s = lc_world_ray_cast_batch(w, starts, NULL, 3, NULL, hits, found);
    CHECK(s == LC_ERR_NULL && strstr(lc_world_last_error(w), "NULL"), "NULL ends -> %s", lc_status_string(s));
    s = lc_world_ray_cast_batch(w, starts, ends, 3, NULL, hits, NULL);
    CHECK(s == LC_ERR_NULL, "NULL out_found -> %s", lc_status_string(s));
    s = lc_world_ray_cast_batch(w, starts, ends, 3, &bad_filter, hits, found);
    CHECK(s == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "skip_static"), "bad filter -> %s: %s",
          lc_status_string(s), lc_world_last_error(w));
    ends[2].y = NAN;
    s = lc_world_ray_cast_batch(w, starts, ends, 3, NULL, hits, found);
    CHECK(s == LC_ERR_NOT_FINITE && strstr(lc_world_last_error(w), "ends[2]"), "NaN in ray 2 -> %s: %s",
          lc_status_string(s), lc_world_last_error(w));
    ends[2] = V(5, 0.2);
    starts[1] = V(2e9, 0);
    s = lc_world_ray_cast_batch(w, starts, ends, 3, NULL, hits, found);
    CHECK(s == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "starts[1]"), "far start -> %s: %s",
          lc_status_string(s), lc_world_last_error(w));
    starts[1] = ends[1];
    s = lc_world_ray_cast_batch(w, starts, ends, 3, NULL, hits, found);
    CHECK(s == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "ray 1"), "zero-length ray 1 -> %s: %s",
          lc_status_string(s), lc_world_last_error(w));
    /* a failed call wrote nothing: the rays before the bad one were not cast either */
    for (i = 0; i < 3; ++i) {
        unsigned char raw[sizeof hits[0]];
        memset(raw, 0xab, sizeof raw);
        CHECK(found[i] == 7 && memcmp(&hits[i], raw, sizeof raw) == 0, "output %d written by a failed call", i);
    }
    /* zero rays: nothing to do, NULL arrays allowed */
    s = lc_world_ray_cast_batch(w, NULL, NULL, 0, NULL, NULL, NULL);
    CHECK(s == LC_OK, "count 0 -> %s", lc_status_string(s));
    lc_world_destroy(w);
}

int main(void)
{
    batch_equals_single_casts();
    fan_inside_walls();
    bad_input();
    return CHECK_SUMMARY("test_ray_batch");
}
