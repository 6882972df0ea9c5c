/* test_api_errors: every call validates its input. For each bad input: the specific lc_status,
 * lc_world_last_error() non-empty and naming the offending field or parameter (case-insensitive
 * substring), and the world unchanged: same lc_world_state_hash (time + all state bits), same body,
 * spring and thruster counts, same settings. After a successful call the message is "".
 * Exact checks (no tolerance): validation is logic, not arithmetic. */
#include <stddef.h>
#include <ctype.h>
#include "check.h"
#include "scenes.h"

typedef struct snap {
    uint64_t hash;
    int bodies, springs, thrusters;
    lc_world_def def;
} snap;

static lc_body_id g_dyn, g_static, g_dyn2; /* bodies of the test world */
static lc_spring_id g_spring;
static const lc_body_id BAD_BODY = 987654u;
static const lc_spring_id BAD_SPRING = 987654u;

static snap take(const lc_world *w)
{
    snap s;
    memset(&s, 0, sizeof s);
    s.hash = lc_world_state_hash(w);
    s.bodies = lc_world_body_count(w);
    s.springs = lc_world_spring_count(w);
    s.thrusters = lc_body_thruster_count(w, g_dyn);
    lc_world_get_def(w, &s.def);
    return s;
}

static int def_equal(const lc_world_def *a, const lc_world_def *b)
{
    return a->gravity.x == b->gravity.x && a->gravity.y == b->gravity.y &&
           a->zero_energy_level == b->zero_energy_level && a->damping == b->damping &&
           a->damping_rotation_ratio == b->damping_rotation_ratio && a->integrator == b->integrator &&
           a->impact_mode == b->impact_mode && a->toi_method == b->toi_method &&
           a->toi_time_tolerance == b->toi_time_tolerance && a->toi_distance_tolerance == b->toi_distance_tolerance &&
           a->toi_max_iterations == b->toi_max_iterations && a->contact_gap == b->contact_gap &&
           a->contact_distance == b->contact_distance && a->resting_speed == b->resting_speed &&
           a->restitution_threshold == b->restitution_threshold &&
           a->stabilization == b->stabilization && a->elasticity_rule == b->elasticity_rule &&
           a->friction_rule == b->friction_rule && a->max_events_per_step == b->max_events_per_step &&
           a->max_serial_iterations == b->max_serial_iterations && a->lcp_exact_max == b->lcp_exact_max &&
           a->lcp_max_iterations == b->lcp_max_iterations && a->lcp_tolerance == b->lcp_tolerance &&
           a->broadphase == b->broadphase && a->broadphase_threshold == b->broadphase_threshold;
}

static int contains_ci(const char *hay, const char *needle)
{
    size_t n = strlen(needle), i, k;
    if (!hay) return 0;
    for (i = 0; hay[i]; i++) {
        for (k = 0; k < n && hay[i + k]; k++)
            if (tolower((unsigned char)hay[i + k]) != tolower((unsigned char)needle[k])) break;
        if (k == n) return 1;
    }
    return n == 0;
}

/* field: a substring the message must contain (alternatives separated by '|'), NULL = any text */
static int mentions(const char *msg, const char *field)
{
    char buf[128];
    const char *p = field;
    if (!field) return 1;
    while (*p) {
        size_t n = strcspn(p, "|");
        if (n >= sizeof buf) n = sizeof buf - 1;
        memcpy(buf, p, n);
        buf[n] = '\0';
        if (contains_ci(msg, buf)) return 1;
        p += n;
        if (*p == '|') p++;
    }
    return 0;
}

static void expect_impl(lc_world *w, snap before, lc_status got, lc_status want, const char *field, const char *call,
                        int line)
{
    const char *msg = lc_world_last_error(w);
    snap after = take(w);
    CHECK(got == want, "line %d: %s returned %s, expected %s (message: \"%s\")", line, call, lc_status_string(got),
          lc_status_string(want), msg ? msg : "(null)");
    CHECK(msg != NULL && msg[0] != '\0', "line %d: %s: last_error is empty", line, call);
    CHECK(mentions(msg, field), "line %d: %s: message \"%s\" does not mention \"%s\"", line, call, msg ? msg : "",
          field ? field : "");
    CHECK(after.hash == before.hash, "line %d: %s changed the state hash", line, call);
    CHECK(after.bodies == before.bodies && after.springs == before.springs && after.thrusters == before.thrusters,
          "line %d: %s changed counts: bodies %d->%d springs %d->%d thrusters %d->%d", line, call, before.bodies,
          after.bodies, before.springs, after.springs, before.thrusters, after.thrusters);
    CHECK(def_equal(&before.def, &after.def), "line %d: %s changed the settings", line, call);
}

#define EXPECT(w, call, status, field)                                    \
    do {                                                                  \
        snap b4_ = take(w);                                               \
        lc_status st_ = (call);                                           \
        expect_impl((w), b4_, st_, (status), (field), #call, __LINE__);   \
    } while (0)

#define EXPECT_OK(w, call)                                                                                   \
    do {                                                                                                     \
        lc_status st_ = (call);                                                                              \
        CHECK(st_ == LC_OK, "line %d: %s -> %s: %s", __LINE__, #call, lc_status_string(st_), lc_world_last_error(w)); \
        CHECK(lc_world_last_error(w) != NULL && lc_world_last_error(w)[0] == '\0',                           \
              "line %d: last_error after a success must be \"\", got \"%s\"", __LINE__, lc_world_last_error(w)); \
    } while (0)

static double bad_values[3]; /* NaN, +inf, -inf (set in main) */

/* ---- world settings --------------------------------------------------------------------------- */

typedef struct dfield { size_t off; const char *name; } dfield;

static void world_def_errors(lc_world *w)
{
    const dfield dfs[] = {
        {offsetof(lc_world_def, gravity) + offsetof(lc_vec2, x), "gravity"},
        {offsetof(lc_world_def, gravity) + offsetof(lc_vec2, y), "gravity"},
        {offsetof(lc_world_def, zero_energy_level), "zero_energy_level"},
        {offsetof(lc_world_def, damping), "damping"},
        {offsetof(lc_world_def, damping_rotation_ratio), "damping_rotation_ratio"},
        {offsetof(lc_world_def, toi_time_tolerance), "toi_time_tolerance"},
        {offsetof(lc_world_def, toi_distance_tolerance), "toi_distance_tolerance"},
        {offsetof(lc_world_def, contact_gap), "contact_gap"},
        {offsetof(lc_world_def, contact_distance), "contact_distance"},
        {offsetof(lc_world_def, resting_speed), "resting_speed"},
        {offsetof(lc_world_def, restitution_threshold), "restitution_threshold"},
        {offsetof(lc_world_def, lcp_tolerance), "lcp_tolerance"},
    };
    const struct { size_t off; const char *name; double v; } ranges[] = {
        {offsetof(lc_world_def, damping), "damping", -1.0},
        {offsetof(lc_world_def, damping_rotation_ratio), "damping_rotation_ratio", -0.1},
        {offsetof(lc_world_def, toi_time_tolerance), "toi_time_tolerance", 1e-16},
        {offsetof(lc_world_def, toi_time_tolerance), "toi_time_tolerance", 0.1},
        {offsetof(lc_world_def, toi_distance_tolerance), "toi_distance_tolerance", 1e-16},
        {offsetof(lc_world_def, toi_distance_tolerance), "toi_distance_tolerance", 0.1},
        {offsetof(lc_world_def, contact_gap), "contact_gap", 1e-13},
        {offsetof(lc_world_def, contact_gap), "contact_gap", 0.02},
        {offsetof(lc_world_def, contact_distance), "contact_distance", 1e-7}, /* = contact_gap, must exceed it */
        {offsetof(lc_world_def, contact_distance), "contact_distance", 1.5},
        {offsetof(lc_world_def, resting_speed), "resting_speed", -0.1},
        {offsetof(lc_world_def, resting_speed), "resting_speed", 11.0},
        {offsetof(lc_world_def, restitution_threshold), "restitution_threshold", -0.1},
        {offsetof(lc_world_def, restitution_threshold), "restitution_threshold", 11.0},
        {offsetof(lc_world_def, lcp_tolerance), "lcp_tolerance", -0.1},
        {offsetof(lc_world_def, lcp_tolerance), "lcp_tolerance", 1.5},
    };
    const struct { size_t off; const char *name; int v; } iranges[] = {
        {offsetof(lc_world_def, toi_max_iterations), "toi_max_iterations", 3},
        {offsetof(lc_world_def, toi_max_iterations), "toi_max_iterations", 1001},
        {offsetof(lc_world_def, max_events_per_step), "max_events_per_step", 0},
        {offsetof(lc_world_def, max_events_per_step), "max_events_per_step", 1000001},
        {offsetof(lc_world_def, max_serial_iterations), "max_serial_iterations", 0},
        {offsetof(lc_world_def, max_serial_iterations), "max_serial_iterations", 1000001},
        {offsetof(lc_world_def, lcp_exact_max), "lcp_exact_max", -1},
        {offsetof(lc_world_def, lcp_exact_max), "lcp_exact_max", 4097},
        {offsetof(lc_world_def, lcp_max_iterations), "lcp_max_iterations", 0},
        {offsetof(lc_world_def, lcp_max_iterations), "lcp_max_iterations", 1000001},
        {offsetof(lc_world_def, broadphase_threshold), "broadphase_threshold", 1},
        {offsetof(lc_world_def, broadphase_threshold), "broadphase_threshold", 1000001},
    };
    size_t i;
    int k;
    char err[256];
    for (i = 0; i < sizeof dfs / sizeof dfs[0]; i++)
        for (k = 0; k < 3; k++) {
            lc_world_def d = lc_default_world_def();
            lc_world *w2;
            *(double *)((char *)&d + dfs[i].off) = bad_values[k];
            EXPECT(w, lc_world_set_def(w, &d), LC_ERR_NOT_FINITE, dfs[i].name);
            err[0] = '\0';
            w2 = lc_world_create(&d, err, sizeof err);
            CHECK(w2 == NULL, "lc_world_create accepted %s = %g", dfs[i].name, bad_values[k]);
            CHECK(mentions(err, dfs[i].name), "lc_world_create(%s = %g): errbuf \"%s\"", dfs[i].name, bad_values[k], err);
            lc_world_destroy(w2);
        }
    for (i = 0; i < sizeof ranges / sizeof ranges[0]; i++) {
        lc_world_def d = lc_default_world_def();
        lc_world *w2;
        *(double *)((char *)&d + ranges[i].off) = ranges[i].v;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_OUT_OF_RANGE, ranges[i].name);
        err[0] = '\0';
        w2 = lc_world_create(&d, err, sizeof err);
        CHECK(w2 == NULL && mentions(err, ranges[i].name), "lc_world_create(%s = %g): %p \"%s\"", ranges[i].name,
              ranges[i].v, (void *)w2, err);
        lc_world_destroy(w2);
    }
    for (i = 0; i < sizeof iranges / sizeof iranges[0]; i++) {
        lc_world_def d = lc_default_world_def();
        *(int *)((char *)&d + iranges[i].off) = iranges[i].v;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_OUT_OF_RANGE, iranges[i].name);
    }
    {
        lc_world_def d;
        d = lc_default_world_def(); d.integrator = (lc_integrator)3;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "integrator");
        d = lc_default_world_def(); d.integrator = (lc_integrator)0;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "integrator");
        d = lc_default_world_def(); d.impact_mode = (lc_impact_mode)2;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "impact_mode");
        d = lc_default_world_def(); d.toi_method = (lc_toi_method)2;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "toi_method");
        d = lc_default_world_def(); d.stabilization = (lc_stabilization)3;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "stabilization");
        d = lc_default_world_def(); d.elasticity_rule = (lc_mix_rule)4;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "elasticity_rule");
        d = lc_default_world_def(); d.friction_rule = (lc_mix_rule)-1;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "friction_rule");
        d = lc_default_world_def(); d.broadphase = (lc_broadphase)4;
        EXPECT(w, lc_world_set_def(w, &d), LC_ERR_BAD_ENUM, "broadphase");
        CHECK(lc_world_create(&d, NULL, 0) == NULL, "%s", "lc_world_create(bad def, errbuf NULL) returns NULL");
    }
    EXPECT(w, lc_world_set_def(w, NULL), LC_ERR_NULL, "def");
    EXPECT(w, lc_world_get_def(w, NULL), LC_ERR_NULL, NULL);
    for (k = 0; k < 3; k++) {
        lc_vec2 g = {0.0, bad_values[k]};
        EXPECT(w, lc_world_set_gravity(w, g), LC_ERR_NOT_FINITE, "gravity");
        EXPECT(w, lc_world_set_damping(w, bad_values[k], 0.1), LC_ERR_NOT_FINITE, "damping");
        EXPECT(w, lc_world_set_damping(w, 0.1, bad_values[k]), LC_ERR_NOT_FINITE, "ratio");
        EXPECT(w, lc_world_set_elasticity(w, bad_values[k]), LC_ERR_NOT_FINITE, "elasticity");
        EXPECT(w, lc_world_step(w, bad_values[k]), LC_ERR_NOT_FINITE, "dt");
    }
    EXPECT(w, lc_world_set_damping(w, -0.5, 0.1), LC_ERR_OUT_OF_RANGE, "damping");
    EXPECT(w, lc_world_set_damping(w, 0.5, -0.1), LC_ERR_OUT_OF_RANGE, "ratio");
    EXPECT(w, lc_world_set_elasticity(w, 1.5), LC_ERR_OUT_OF_RANGE, "elasticity");
    EXPECT(w, lc_world_set_elasticity(w, -0.1), LC_ERR_OUT_OF_RANGE, "elasticity");
    EXPECT(w, lc_world_step(w, 0.0), LC_ERR_OUT_OF_RANGE, "dt");
    EXPECT(w, lc_world_step(w, -0.01), LC_ERR_OUT_OF_RANGE, "dt");
    EXPECT(w, lc_world_step(w, 1.5), LC_ERR_OUT_OF_RANGE, "dt");
    EXPECT(w, lc_world_set_stage_timing(w, 2), LC_ERR_OUT_OF_RANGE, "stage timing");
    EXPECT(w, lc_world_set_stage_timing(w, -1), LC_ERR_OUT_OF_RANGE, "stage timing");
    CHECK(lc_world_set_stage_timing(NULL, 1) == LC_ERR_NULL, "%s", "lc_world_set_stage_timing(NULL) is LC_ERR_NULL");
}

/* ---- bodies ------------------------------------------------------------------------------------ */

static lc_body_def good_body(lc_vec2 *v)
{
    lc_body_def bd = lc_default_body_def();
    lc_make_rectangle(1.0, 1.0, v);
    bd.vertices = v;
    bd.vertex_count = 4;
    bd.position.x = 3.0;
    bd.position.y = 3.0;
    return bd;
}

static void body_def_errors(lc_world *w)
{
    const dfield dfs[] = {
        {offsetof(lc_body_def, position) + offsetof(lc_vec2, x), "position"},
        {offsetof(lc_body_def, position) + offsetof(lc_vec2, y), "position"},
        {offsetof(lc_body_def, angle), "angle"},
        {offsetof(lc_body_def, velocity) + offsetof(lc_vec2, x), "velocity"},
        {offsetof(lc_body_def, velocity) + offsetof(lc_vec2, y), "velocity"},
        {offsetof(lc_body_def, angular_velocity), "angular_velocity"},
        {offsetof(lc_body_def, mass), "mass"},
        {offsetof(lc_body_def, elasticity), "elasticity"},
        {offsetof(lc_body_def, friction), "friction"},
    };
    const lc_vec2 collinear[3] = {{0, 0}, {1, 1}, {2, 2}};
    const lc_vec2 duplicate[4] = {{0, 0}, {1, 0}, {1, 0}, {0, 1}};
    const lc_vec2 concave[5] = {{0, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}};
    const lc_vec2 bowtie[4] = {{0, 0}, {1, 1}, {1, 0}, {0, 1}};
    lc_vec2 star[5], many[LC_MAX_POLYGON_VERTICES + 1], v[4], bv[4];
    lc_body_def bd;
    lc_body_id id;
    size_t i;
    int k;
    for (k = 0; k < 5; k++) { /* pentagram: every turn has the same sign, but it crosses itself */
        double a = 2.0 * SC_PI * (2 * k % 5) / 5.0;
        star[k].x = cos(a);
        star[k].y = sin(a);
    }
    for (k = 0; k <= LC_MAX_POLYGON_VERTICES; k++) {
        double a = 2.0 * SC_PI * k / (LC_MAX_POLYGON_VERTICES + 1);
        many[k].x = cos(a);
        many[k].y = sin(a);
    }
    for (i = 0; i < sizeof dfs / sizeof dfs[0]; i++)
        for (k = 0; k < 3; k++) {
            bd = good_body(v);
            *(double *)((char *)&bd + dfs[i].off) = bad_values[k];
            EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_NOT_FINITE, dfs[i].name);
        }
    for (k = 0; k < 3; k++) {
        bd = good_body(v);
        memcpy(bv, v, sizeof bv);
        bv[2].x = bad_values[k];
        bd.vertices = bv;
        EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_NOT_FINITE, "vert");
        bd = good_body(v);
        bd.type = LC_BODY_STATIC;
        bd.position.y = bad_values[k];
        EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_NOT_FINITE, "position");
    }
    bd = good_body(v); bd.mass = 0.0;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "mass");
    bd = good_body(v); bd.mass = -1.0;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "mass");
    bd = good_body(v); bd.elasticity = -0.1;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "elasticity");
    bd = good_body(v); bd.elasticity = 1.1;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "elasticity");
    bd = good_body(v); bd.friction = -0.1;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "friction");
    bd = good_body(v); bd.friction = 10.5;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_OUT_OF_RANGE, "friction");
    bd = good_body(v); bd.type = (lc_body_type)2;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_ENUM, "type");
    bd = good_body(v); bd.vertices = NULL;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_NULL, "vert");
    /* polygons: the message must name the vertices or the polygon */
    bd = good_body(v); bd.vertex_count = 2;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = many; bd.vertex_count = LC_MAX_POLYGON_VERTICES + 1;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = collinear; bd.vertex_count = 3;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = duplicate; bd.vertex_count = 4;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = concave; bd.vertex_count = 5;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = bowtie; bd.vertex_count = 4;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    bd = good_body(v); bd.vertices = star; bd.vertex_count = 5;
    EXPECT(w, lc_world_add_body(w, &bd, &id), LC_ERR_BAD_POLYGON, "vert|polygon");
    /* NULL pointers */
    EXPECT(w, lc_world_add_body(w, NULL, &id), LC_ERR_NULL, "def");
    bd = good_body(v);
    EXPECT(w, lc_world_add_body(w, &bd, NULL), LC_ERR_NULL, "out_id|id");
    /* walls */
    EXPECT(w, lc_world_add_walls(w, 1.0, 0.0, 1.0, 5.0, 1.0, 1.0, NULL), LC_ERR_OUT_OF_RANGE, "xmax|xmin");
    EXPECT(w, lc_world_add_walls(w, 0.0, 5.0, 5.0, 0.0, 1.0, 1.0, NULL), LC_ERR_OUT_OF_RANGE, "ymax|ymin");
    EXPECT(w, lc_world_add_walls(w, 0.0, 0.0, 5.0, 5.0, 0.0, 1.0, NULL), LC_ERR_OUT_OF_RANGE, "thickness");
    EXPECT(w, lc_world_add_walls(w, 0.0, 0.0, 5.0, 5.0, 1.0, 1.5, NULL), LC_ERR_OUT_OF_RANGE, "elasticity");
    for (k = 0; k < 3; k++) {
        EXPECT(w, lc_world_add_walls(w, bad_values[k], 0.0, 5.0, 5.0, 1.0, 1.0, NULL), LC_ERR_NOT_FINITE, "xmin");
        EXPECT(w, lc_world_add_walls(w, 0.0, 0.0, 5.0, 5.0, bad_values[k], 1.0, NULL), LC_ERR_NOT_FINITE, "thickness");
    }
    /* a static body ignores its mass */
    bd = good_body(v);
    bd.type = LC_BODY_STATIC;
    bd.mass = 0.0;
    bd.position.x = 40.0;
    EXPECT_OK(w, lc_world_add_body(w, &bd, &id));
    EXPECT_OK(w, lc_world_remove_body(w, id));
}

static void body_call_errors(lc_world *w)
{
    lc_vec2 p = {0, 0}, out[4];
    double state[64 * 6];
    lc_state_view view;
    int k;
    lc_thruster_def td;
    td.point.x = 0; td.point.y = 0; td.direction.x = 1; td.direction.y = 0; td.magnitude = 1.0;
    /* unknown body */
    EXPECT(w, lc_world_remove_body(w, BAD_BODY), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_pose(w, BAD_BODY, p, 0.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_velocity(w, BAD_BODY, p, 0.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_mass(w, BAD_BODY, 1.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_material(w, BAD_BODY, 0.5, 0.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_external(w, BAD_BODY, p, 0.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_get_local_vertices(w, BAD_BODY, out, 4), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_get_world_vertices(w, BAD_BODY, out, 4), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_get_center_offset(w, BAD_BODY, out), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_add_thruster(w, BAD_BODY, &td, NULL), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_add_default_thrusters(w, BAD_BODY, 1.5, NULL), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_thruster_level(w, BAD_BODY, 0, 1.0), LC_ERR_UNKNOWN_BODY, "body");
    EXPECT(w, lc_body_set_thruster_mask(w, BAD_BODY, 1u), LC_ERR_UNKNOWN_BODY, "body");
    CHECK(lc_world_body_index(w, BAD_BODY) == -1, "%s", "body_index of an unknown id is -1");
    CHECK(lc_body_thruster_count(w, BAD_BODY) == -1, "%s", "thruster_count of an unknown id is -1");
    /* static body where a dynamic one is needed */
    EXPECT(w, lc_body_set_mass(w, g_static, 2.0), LC_ERR_STATIC_BODY, "static");
    EXPECT(w, lc_body_add_thruster(w, g_static, &td, NULL), LC_ERR_STATIC_BODY, "static");
    EXPECT(w, lc_body_add_default_thrusters(w, g_static, 1.5, NULL), LC_ERR_STATIC_BODY, "static");
    /* bad numbers */
    for (k = 0; k < 3; k++) {
        lc_vec2 b = {bad_values[k], 0.0};
        EXPECT(w, lc_body_set_pose(w, g_dyn, b, 0.0), LC_ERR_NOT_FINITE, "center");
        EXPECT(w, lc_body_set_pose(w, g_dyn, p, bad_values[k]), LC_ERR_NOT_FINITE, "angle");
        EXPECT(w, lc_body_set_velocity(w, g_dyn, b, 0.0), LC_ERR_NOT_FINITE, "velocity");
        EXPECT(w, lc_body_set_velocity(w, g_dyn, p, bad_values[k]), LC_ERR_NOT_FINITE, "angular_velocity");
        EXPECT(w, lc_body_set_mass(w, g_dyn, bad_values[k]), LC_ERR_NOT_FINITE, "mass");
        EXPECT(w, lc_body_set_material(w, g_dyn, bad_values[k], 0.0), LC_ERR_NOT_FINITE, "elasticity");
        EXPECT(w, lc_body_set_material(w, g_dyn, 0.5, bad_values[k]), LC_ERR_NOT_FINITE, "friction");
        EXPECT(w, lc_body_set_external(w, g_dyn, b, 0.0), LC_ERR_NOT_FINITE, "force");
        EXPECT(w, lc_body_set_external(w, g_dyn, p, bad_values[k]), LC_ERR_NOT_FINITE, "torque");
        EXPECT(w, lc_body_set_thruster_level(w, g_dyn, 0, bad_values[k]), LC_ERR_NOT_FINITE, "level");
        EXPECT(w, lc_body_add_default_thrusters(w, g_dyn2, bad_values[k], NULL), LC_ERR_NOT_FINITE, "thrust");
    }
    EXPECT(w, lc_body_set_mass(w, g_dyn, 0.0), LC_ERR_OUT_OF_RANGE, "mass");
    EXPECT(w, lc_body_set_mass(w, g_dyn, -2.0), LC_ERR_OUT_OF_RANGE, "mass");
    EXPECT(w, lc_body_set_material(w, g_dyn, 1.5, 0.0), LC_ERR_OUT_OF_RANGE, "elasticity");
    EXPECT(w, lc_body_set_material(w, g_dyn, 0.5, 11.0), LC_ERR_OUT_OF_RANGE, "friction");
    EXPECT(w, lc_body_set_thruster_level(w, g_dyn, 0, 1.5), LC_ERR_OUT_OF_RANGE, "level");
    EXPECT(w, lc_body_set_thruster_level(w, g_dyn, 0, -0.1), LC_ERR_OUT_OF_RANGE, "level");
    EXPECT(w, lc_body_get_local_vertices(w, g_dyn, out, 2), LC_ERR_OUT_OF_RANGE, "capacity");
    EXPECT(w, lc_body_get_local_vertices(w, g_dyn, NULL, 4), LC_ERR_NULL, "out");
    EXPECT(w, lc_body_get_center_offset(w, g_dyn, NULL), LC_ERR_NULL, "out");
    /* thrusters: bad index, bad mask, bad definitions, too many */
    EXPECT(w, lc_body_set_thruster_level(w, g_dyn, 4, 1.0), LC_ERR_UNKNOWN_THRUSTER, "thruster");
    EXPECT(w, lc_body_set_thruster_level(w, g_dyn, -1, 1.0), LC_ERR_UNKNOWN_THRUSTER, "thruster");
    EXPECT(w, lc_body_set_thruster_mask(w, g_dyn, 1u << 5), LC_ERR_UNKNOWN_THRUSTER, "thruster");
    for (k = 0; k < 3; k++) {
        lc_thruster_def t = td;
        t.point.x = bad_values[k];
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_NOT_FINITE, "point");
        t = td; t.point.y = bad_values[k];
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_NOT_FINITE, "point");
        t = td; t.direction.x = bad_values[k];
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_NOT_FINITE, "direction");
        t = td; t.direction.y = bad_values[k];
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_NOT_FINITE, "direction");
        t = td; t.magnitude = bad_values[k];
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_NOT_FINITE, "magnitude");
    }
    {
        lc_thruster_def t = td;
        t.direction.x = 0.0;
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_OUT_OF_RANGE, "direction");
        t = td; t.magnitude = -1.0;
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_OUT_OF_RANGE, "magnitude");
        t = td; t.magnitude = 2e9;
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &t, NULL), LC_ERR_OUT_OF_RANGE, "magnitude");
        EXPECT(w, lc_body_add_thruster(w, g_dyn, NULL, NULL), LC_ERR_NULL, "def");
        for (k = lc_body_thruster_count(w, g_dyn); k < LC_MAX_THRUSTERS; k++)
            EXPECT_OK(w, lc_body_add_thruster(w, g_dyn, &td, NULL));
        EXPECT(w, lc_body_add_thruster(w, g_dyn, &td, NULL), LC_ERR_OUT_OF_RANGE, "thruster");
    }
    /* state access */
    EXPECT(w, lc_world_get_state(w, NULL), LC_ERR_NULL, NULL);
    EXPECT(w, lc_world_set_state(w, NULL, lc_world_body_count(w)), LC_ERR_NULL, "state");
    CHECK(lc_world_get_state(w, &view) == LC_OK && view.count <= 64, "%s", "get_state");
    memcpy(state, view.state, (size_t)view.count * 6 * sizeof(double));
    EXPECT(w, lc_world_set_state(w, state, view.count + 1), LC_ERR_OUT_OF_RANGE, "state|count|rows");
    for (k = 0; k < 3; k++) {
        int row = lc_world_body_index(w, g_dyn2);
        memcpy(state, view.state, (size_t)view.count * 6 * sizeof(double));
        state[row * 6 + 4] = bad_values[k];
        EXPECT(w, lc_world_set_state(w, state, view.count), LC_ERR_NOT_FINITE, "state");
    }
    EXPECT(w, lc_world_get_energy(w, NULL), LC_ERR_NULL, NULL);
    {
        int n;
        EXPECT(w, lc_world_get_contacts(w, NULL, &n), LC_ERR_NULL, NULL);
    }
}

static void spring_errors(lc_world *w)
{
    lc_spring_def sd = lc_default_spring_def(), s;
    lc_spring_id id;
    lc_vec2 a, b;
    int k;
    sd.body_a = g_dyn;
    sd.body_b = LC_WORLD_ANCHOR;
    s = sd; s.body_a = BAD_BODY;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_UNKNOWN_BODY, "body");
    s = sd; s.body_b = BAD_BODY;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_UNKNOWN_BODY, "body");
    s = sd; s.body_a = g_static;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_STATIC_BODY, "static");
    for (k = 0; k < 3; k++) {
        s = sd; s.point_a.x = bad_values[k];
        EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_NOT_FINITE, "point_a");
        s = sd; s.point_b.y = bad_values[k];
        EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_NOT_FINITE, "point_b");
        s = sd; s.stiffness = bad_values[k];
        EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_NOT_FINITE, "stiffness");
        s = sd; s.damping = bad_values[k];
        EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_NOT_FINITE, "damping");
        s = sd; s.rest_length = bad_values[k];
        EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_NOT_FINITE, "rest_length");
        a.x = bad_values[k]; a.y = 0;
        EXPECT(w, lc_spring_set_target(w, g_spring, a), LC_ERR_NOT_FINITE, "target");
        EXPECT(w, lc_spring_set_params(w, g_spring, bad_values[k], 0, 0), LC_ERR_NOT_FINITE, "stiffness");
        EXPECT(w, lc_spring_set_params(w, g_spring, 3, bad_values[k], 0), LC_ERR_NOT_FINITE, "damping");
        EXPECT(w, lc_spring_set_params(w, g_spring, 3, 0, bad_values[k]), LC_ERR_NOT_FINITE, "rest_length");
    }
    s = sd; s.stiffness = -1.0;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_OUT_OF_RANGE, "stiffness");
    s = sd; s.stiffness = 2e9;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_OUT_OF_RANGE, "stiffness");
    s = sd; s.damping = -1.0;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_OUT_OF_RANGE, "damping");
    s = sd; s.rest_length = -1.0;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_OUT_OF_RANGE, "rest_length");
    s = sd; s.rest_length = 2e6;
    EXPECT(w, lc_world_add_spring(w, &s, &id), LC_ERR_OUT_OF_RANGE, "rest_length");
    EXPECT(w, lc_spring_set_params(w, g_spring, -3, 0, 0), LC_ERR_OUT_OF_RANGE, "stiffness");
    EXPECT(w, lc_spring_set_params(w, g_spring, 3, -1, 0), LC_ERR_OUT_OF_RANGE, "damping");
    EXPECT(w, lc_spring_set_params(w, g_spring, 3, 0, -1), LC_ERR_OUT_OF_RANGE, "rest_length");
    EXPECT(w, lc_world_add_spring(w, NULL, &id), LC_ERR_NULL, "def");
    /* unknown spring */
    a.x = a.y = 0;
    EXPECT(w, lc_world_remove_spring(w, BAD_SPRING), LC_ERR_UNKNOWN_SPRING, "spring");
    EXPECT(w, lc_spring_set_target(w, BAD_SPRING, a), LC_ERR_UNKNOWN_SPRING, "spring");
    EXPECT(w, lc_spring_set_params(w, BAD_SPRING, 3, 0, 0), LC_ERR_UNKNOWN_SPRING, "spring");
    EXPECT(w, lc_spring_get_def(w, BAD_SPRING, &s), LC_ERR_UNKNOWN_SPRING, "spring");
    EXPECT(w, lc_spring_get_endpoints(w, BAD_SPRING, &a, &b), LC_ERR_UNKNOWN_SPRING, "spring");
    EXPECT(w, lc_spring_get_def(w, g_spring, NULL), LC_ERR_NULL, NULL);
}

/* The documented defaults (types.h / collide.h doc lines), exact. */
static void defaults(void)
{
    lc_world_def d = lc_default_world_def();
    lc_body_def b = lc_default_body_def();
    lc_spring_def s = lc_default_spring_def();
    CHECK(d.gravity.x == 0.0 && d.gravity.y == -9.81, "default gravity (%g, %g)", d.gravity.x, d.gravity.y);
    CHECK(d.zero_energy_level == 0.0 && d.damping == 0.0 && d.damping_rotation_ratio == 0.1, "%s",
          "default zero level 0, damping 0, rotation ratio 0.1");
    CHECK(d.integrator == LC_INTEGRATOR_RK4 && d.impact_mode == LC_IMPACT_SERIAL && d.toi_method == LC_TOI_ROOT_FINDER,
          "%s", "default RK4, serial, root finder");
    CHECK(d.toi_time_tolerance == 1e-10 && d.toi_distance_tolerance == 1e-10 && d.toi_max_iterations == 100, "%s",
          "default TOI tolerances 1e-10 s, 1e-10 m, 100 iterations");
    CHECK(d.contact_gap == 1e-7 && d.contact_distance == 1e-5 && d.resting_speed == 1e-4 &&
              d.restitution_threshold == 1e-2, "%s",
          "default contact_gap 1e-7, contact_distance 1e-5, resting_speed 1e-4, restitution_threshold 1e-2");
    CHECK(d.stabilization == LC_STABILIZE_VELOCITY && d.elasticity_rule == LC_MIX_MIN &&
              d.friction_rule == LC_MIX_GEOMETRIC, "%s", "default stabilisation and mix rules");
    CHECK(d.max_events_per_step == 10000 && d.max_serial_iterations == 1000 && d.lcp_exact_max == 128 &&
              d.lcp_max_iterations == 200 && d.lcp_tolerance == 1e-10, "%s", "default event and LCP limits");
    CHECK(d.broadphase == LC_BROADPHASE_AUTO && d.broadphase_threshold == 32, "%s", "default broadphase AUTO, 32");
    CHECK(b.type == LC_BODY_DYNAMIC && b.mass == 1.0 && b.elasticity == 1.0 && b.friction == 0.0 && b.vertices == NULL &&
              b.vertex_count == 0, "%s", "default body: dynamic, 1 kg, e 1, friction 0, no vertices");
    CHECK(s.stiffness == 3.0 && s.damping == 0.0 && s.rest_length == 0.0 && s.body_b == LC_WORLD_ANCHOR, "%s",
          "default spring: 3 N/m, no damping, rest length 0, anchored to the world");
    CHECK(lc_version() != NULL && lc_version()[0] != '\0', "%s", "version string");
}

/* remove_body takes its springs and thrusters with it; ids are never reused. */
static void removal(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id s1, s2;
    lc_body_id a, b, c;
    if (!w) return;
    a = sc_box(w, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1);
    b = sc_box(w, 1, 1, 3, 0, 0, 0, 0, 0, 1, 1);
    sd.body_a = a;
    sd.body_b = b;
    CHECK(lc_world_add_spring(w, &sd, &s1) == LC_OK, "%s", "spring a-b");
    sd.body_a = b;
    sd.body_b = LC_WORLD_ANCHOR;
    CHECK(lc_world_add_spring(w, &sd, &s2) == LC_OK, "%s", "spring b-world");
    CHECK(lc_world_spring_count(w) == 2, "%s", "two springs");
    EXPECT_OK(w, lc_world_remove_body(w, a));
    CHECK(lc_world_spring_count(w) == 1, "removing a body removes its springs (%d left)", lc_world_spring_count(w));
    EXPECT(w, lc_spring_set_params(w, s1, 3, 0, 0), LC_ERR_UNKNOWN_SPRING, "spring");
    CHECK(lc_world_body_count(w) == 1 && lc_world_body_index(w, b) == 0, "%s", "remaining body moved to row 0");
    EXPECT(w, lc_body_set_mass(w, a, 2.0), LC_ERR_UNKNOWN_BODY, "body");
    c = sc_box(w, 1, 1, -3, 0, 0, 0, 0, 0, 1, 1);
    CHECK(c != a && c != b, "ids are not reused (%u vs %u, %u)", (unsigned)c, (unsigned)a, (unsigned)b);
    lc_world_destroy(w);
}

/* A step whose result is not finite is undone: a 1e-3 kg block on a 1e9 N/m spring stepped with
 * dt = 1 s (omega dt = 1e6: RK4 amplifies by ~(omega dt)^4 / 24 per step) overflows within a few
 * dozen steps; that step returns LC_ERR_NUMERIC with a message and leaves time and state as before. */
static void numeric_failure(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    lc_body_id a;
    lc_status st = LC_OK;
    int k;
    if (!w) return;
    a = sc_box(w, 1.0, 1.0, 1.0, 0.0, 0.0, 0, 0, 0, 1e-3, 1.0);
    sd.body_a = a;
    sd.stiffness = 1e9;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "%s", "stiff spring");
    for (k = 0; k < 200 && st == LC_OK; k++) {
        snap b4 = take(w);
        double t = lc_world_get_time(w);
        st = lc_world_step(w, 1.0);
        if (st != LC_OK) {
            expect_impl(w, b4, st, LC_ERR_NUMERIC, NULL, "lc_world_step (diverging)", __LINE__);
            CHECK(lc_world_get_time(w) == t, "%s", "time not advanced by the undone step");
            CHECK(isfinite(sc_row(w, a)[0]), "%s", "state still finite");
        }
    }
    CHECK(st == LC_ERR_NUMERIC, "a diverging integration must end in LC_ERR_NUMERIC, got %s", lc_status_string(st));
    lc_world_destroy(w);
}

int main(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_vec2 v[4], z = {0, 0};
    lc_body_def bd;
    lc_spring_def sd = lc_default_spring_def();
    lc_body_id id;
    int i, j;
    bad_values[0] = NAN;
    bad_values[1] = INFINITY;
    bad_values[2] = -INFINITY;

    /* statuses have distinct names */
    for (i = 0; i <= (int)LC_ERR_CALLBACK; i++) {
        const char *a = lc_status_string((lc_status)i);
        CHECK(a != NULL && a[0] != '\0', "status %d has a name", i);
        for (j = 0; j < i; j++)
            CHECK(a && lc_status_string((lc_status)j) && strcmp(a, lc_status_string((lc_status)j)) != 0,
                  "statuses %d and %d share a name", i, j);
    }
    CHECK(lc_status_string((lc_status)99) != NULL, "%s", "unknown status still gives a string");
    /* calls without a world */
    CHECK(lc_world_step(NULL, 0.01) == LC_ERR_NULL, "%s", "step(NULL world)");
    bd = good_body(v);
    CHECK(lc_world_add_body(NULL, &bd, &id) == LC_ERR_NULL, "%s", "add_body(NULL world)");
    CHECK(lc_make_rectangle(1.0, 1.0, NULL) == LC_ERR_NULL, "%s", "make_rectangle(out NULL)");
    CHECK(lc_make_rectangle(0.0, 1.0, v) == LC_ERR_OUT_OF_RANGE, "%s", "make_rectangle(width 0)");
    CHECK(lc_make_rectangle(1.0, -1.0, v) == LC_ERR_OUT_OF_RANGE, "%s", "make_rectangle(height < 0)");
    CHECK(lc_make_rectangle(NAN, 1.0, v) == LC_ERR_NOT_FINITE, "%s", "make_rectangle(NaN)");
    lc_world_destroy(NULL);
    defaults();
    removal();
    numeric_failure();

    /* the test world: walls, two dynamic bodies, a static one, a spring, thrusters, a few steps */
    w = sc_world(&d);
    if (!w) return CHECK_SUMMARY("test_api_errors");
    lc_world_add_walls(w, -10, -10, 10, 10, 1.0, 1.0, NULL);
    g_dyn = sc_box(w, 1.0, 2.0, -2.0, 0.0, 0.1, 1.0, 0.5, 0.2, 1.0, 1.0);
    g_dyn2 = sc_box(w, 1.0, 1.0, 2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 2.0, 1.0);
    g_static = sc_static_box(w, 1.0, 1.0, 0.0, -5.0, 1.0);
    CHECK(lc_body_add_default_thrusters(w, g_dyn, 1.5, NULL) == LC_OK, "%s", "default thrusters");
    sd.body_a = g_dyn2;
    sd.body_b = LC_WORLD_ANCHOR;
    sd.point_b.x = 3.0;
    CHECK(lc_world_add_spring(w, &sd, &g_spring) == LC_OK, "%s", "spring");
    sc_step_n(w, 0.01, 10);
    EXPECT_OK(w, lc_body_set_external(w, g_dyn2, z, 0.0));

    world_def_errors(w);
    body_def_errors(w);
    body_call_errors(w);
    spring_errors(w);
    /* the world still works after all that */
    EXPECT_OK(w, lc_world_step(w, 0.01));
    lc_world_destroy(w);
    return CHECK_SUMMARY("test_api_errors");
}
