/* Internal layout of lc_world, shared by the engine's source files. Not installed. */
#ifndef LC_WORLD_INTERNAL_H
#define LC_WORLD_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <string.h>
#include "collide/collide.h"
#include "lcp.h"

#define LC_STATE_SIZE 6
enum { SX = 0, SY = 1, SA = 2, SVX = 3, SVY = 4, SW = 5 };

typedef struct lc_thruster {
    lc_vec2 point;      /* body frame, relative to the centre of mass */
    lc_vec2 direction;  /* body frame, unit */
    double magnitude;
    double level;
} lc_thruster;

/* Shape of one body; vertices are relative to the centre of mass. The vertices and normals live in a
 * block of their own (lc_shape_keep), not in arrays of the polygon limit: at 64 vertices a row took 2 KB,
 * and the hot loops that read a box's four corners for every body (its bounding box, the vertex-in-body
 * tests) then touched a new page per body; 20 000 bodies in free flight took ~30 % longer per step. */
typedef struct lc_shape {
    int count;
    int block_skip;                       /* bytes from the kept block's allocation to v (lc_shape_keep) */
    lc_vec2 *v;                           /* count vertices, counter-clockwise */
    lc_vec2 *n;                           /* outward unit normal of edge v[i] -> v[i+1] (same block as v) */
    lc_vec2 center_offset;                /* local-frame origin -> centre of mass, body frame */
    double radius;                        /* max |v[i]| */
    double min_edge;                      /* length of the shortest edge */
    double area;
    double unit_inertia;                  /* the polygon's (uniform density) moment about the centre of mass
                                             per unit mass, m^2 */
    double inertia_per_mass;              /* the body's inertia over its mass, m^2: unit_inertia, or a given
                                             inertia's (lc_body_set_mass keeps it) */
} lc_shape;

/* A body's vertices, as its shape has them (v points into the shape's block). */
typedef struct lc_outline {
    const lc_vec2 *v;
    int count;
} lc_outline;

typedef struct lc_spring_rec {
    lc_spring_id id;
    lc_spring_def def;   /* body points stored as given (local-origin frame) */
} lc_spring_rec;

/* A vertex of body row a against edge `edge` of body row b: a touch (resting contact or impact point). */
typedef struct lc_touch {
    int a, b, vertex, edge;
    double elasticity, friction;
    lc_vec2 p, n, ra, rb;  /* world point, edge normal, offsets from the two centres of mass */
    double gap, vn;
    double value;          /* force (resting) or accumulated impulse (impact) */
    double vn_pre;         /* normal velocity before the event (impacts) */
    double target_vn;      /* impacts: normal velocity the point must reach or exceed */
    double tangent;        /* accumulated friction impulse (impacts) */
} lc_touch;

typedef struct lc_buf {  /* growable scratch array */
    void *p;
    size_t cap;          /* bytes */
} lc_buf;

/* One angle a body was seen at: its cosine and sine, and the box about the centre of mass of the
 * body's vertices turned by it (min x, min y, max x, max y; NaN until the broad phase asks for it:
 * broad_phase.c). Seven doubles and a pad: an entry fills one cache line. */
typedef struct lc_trig_entry {
    double angle, c, s, ext[4];
    double pad;
} lc_trig_entry;

/* The last two angles a body was seen at, the newer first (lc_body_trig_entry). w->trig's rows start
 * on a cache line (LC_TRIG_ALIGN, body.c), so a lookup that finds the newer angle reads one line: a
 * step looks up every body several times, and 20 000 bodies' caches do not fit a 2 MiB cache. */
typedef struct lc_trig {
    lc_trig_entry e[2];
} lc_trig;
#define LC_TRIG_ALIGN 64

struct lc_world {
    lc_world_def def;
    double time;
    char error[256];
    int stage_timing;        /* lc_world_set_stage_timing: fill the counters' time_* fields */
    double step_t0;          /* stage clock at the start of the current step */

    /* bodies, dense rows in insertion order */
    int count, capacity;
    lc_body_id *ids;
    double *state;          /* count x 6 */
    double *mass, *inertia, *inv_mass, *inv_inertia;
    uint8_t *is_static;
    double *elasticity, *friction;
    lc_vec2 *ext_force;
    double *ext_torque;
    lc_shape *shape;
    double *radius;          /* shape[row].radius again, by row: the whole-world passes that need only it
                                (broad_phase.c's bound boxes) read a double per body, not a shape row */
    lc_outline *outline;     /* shape[row]'s vertices again, by row, for the same reason (the boxes at each
                                body's new angle) */
    lc_trig *trig;           /* per body; a cache, so written through even a const lc_world * */
    void *trig_block;        /* the allocation trig lies in (trig starts on a cache line in it) */
    lc_thruster (*thrusters)[LC_MAX_THRUSTERS];
    int *thruster_count;
    uint8_t *rests_dissipative; /* touched a pair with e < 1 at the end of the last step (regime.c) */

    lc_body_id next_body_id;
    int *id_to_row;          /* indexed by id, -1 = removed */
    size_t id_map_cap;

    lc_spring_rec *springs;
    int spring_count, spring_cap;
    lc_spring_id next_spring_id;

    lc_contact *contacts;    /* results of the last step */
    int contact_count, contact_cap;

    lc_counters last, total;

    /* The state each part of the engine keeps: buffers that grow to the largest problem seen and what it
     * remembers from one step or solve to the next, each owned by its file, created and destroyed with
     * the world (world.c). */
    struct lc_step_state *step_state;               /* step.c */
    struct lc_islands *islands;                     /* islands.c */
    struct lc_event_regime *event;                  /* event_regime.c */
    struct lc_contact_regime *contact;              /* contact_regime.c */
    struct lc_broad_phase_state *broad_phase;       /* broad_phase.c */
    struct lc_integrator_state *integrator;         /* integrator.c */
    struct lc_contact_forces_state *contact_forces; /* contact_forces.c */
    struct lc_impulse_state *impulse;               /* impulse.c */
    struct lc_sparse_lcp_state *sparse_lcp;         /* sparse_lcp.c */
    struct lc_static_load_state *static_load;       /* static_load.c */
    struct lc_sleep *sleep;                         /* sleep.c */
    struct lc_events *events;                       /* events.c: the impact event stream */
    struct lc_force_callback *force_callback;       /* force_callback.c */
    /* the dense solver's workspace (lcp.c), shared by the dense solves of contact_forces.c, impulse.c and
     * event_projection.c: scratch that no solve holds past its return */
    lc_lcp_workspace *lcp;
    /* regime.c's whole-world touch search (lc_regime_refresh): its pairs and touches */
    lc_buf b_pairs, b_touch;

    /* read by several files */
    unsigned long edits;          /* bumped by every API call that changes bodies, their states or materials:
                                     a search kept from the last step holds only while it is unchanged */
    unsigned long regime_edits;   /* `edits` when rests_dissipative last described the state (regime.c, step.c) */
    unsigned long api_changes;    /* bumped by every API call that changes anything a step reads (bodies,
                                     states, materials, forces, thrusters, springs, settings): sleep.c wakes
                                     every body when it moved */
    double step_dt;               /* dt of the step in progress (the stabilisation's time scale: integrator.c,
                                     contact_forces.c) */
    /* dynamic rows the broad phase and the event regime leave out of every pair while the event regime
     * advances the other islands (step.c sets it, broad_phase.c and event_touches.c read it; the broad
     * phase's interface is shared with regime.c and islands.c, which never set it) */
    const uint8_t *excluded;
};

/* ---- scratch memory ---- */
void *lc_buf_get(lc_buf *b, size_t bytes);   /* NULL on allocation failure */
void lc_buf_free(lc_buf *b);

/* ---- errors ---- */
lc_status lc_fail(lc_world *w, lc_status s, const char *fmt, ...);

/* ---- the API's argument checks (world.c, body.c, thruster.c, spring.c) ---- */
/* Each returns lc_fail's status from the calling API function when the check fails. */
#define LC_CHECK_FINITE(w, val, name) \
    do { if (!isfinite(val)) return lc_fail((w), LC_ERR_NOT_FINITE, "%s is not finite (%g)", (name), (double)(val)); } while (0)
#define LC_CHECK_RANGE(w, val, lo, hi, name) \
    do { LC_CHECK_FINITE(w, val, name); \
         if ((val) < (lo) || (val) > (hi)) return lc_fail((w), LC_ERR_OUT_OF_RANGE, "%s = %g is outside [%g, %g]", (name), (double)(val), (double)(lo), (double)(hi)); } while (0)
#define LC_CHECK_IRANGE(w, val, lo, hi, name) \
    do { if ((val) < (lo) || (val) > (hi)) return lc_fail((w), LC_ERR_OUT_OF_RANGE, "%s = %d is outside [%d, %d]", (name), (int)(val), (int)(lo), (int)(hi)); } while (0)
/* row = the row of body `id`, or return LC_ERR_NULL or LC_ERR_UNKNOWN_BODY; LC_GET_DYNAMIC_ROW also
 * returns LC_ERR_STATIC_BODY for a static body. */
#define LC_GET_ROW(w, id, row) \
    do { if ((w) == NULL) return LC_ERR_NULL; (row) = lc_world_body_index((w), (id)); \
         if ((row) < 0) return lc_fail((w), LC_ERR_UNKNOWN_BODY, "no body with id %u", (unsigned)(id)); } while (0)
#define LC_GET_DYNAMIC_ROW(w, id, row) \
    do { LC_GET_ROW(w, id, row); if ((w)->is_static[row]) return lc_fail((w), LC_ERR_STATIC_BODY, "body %u is static", (unsigned)(id)); } while (0)
/* row = the row of body `id` for a reader on a const world: LC_ERR_NULL for a NULL world, or for a NULL
 * output (outputs_ok == 0; the message names `what`), LC_ERR_UNKNOWN_BODY; like any failed call, a
 * failure records its message for lc_world_last_error (body.c). */
lc_status lc_read_row(const lc_world *w, lc_body_id id, int outputs_ok, const char *what, int *row);
/* Returns expr's status from the calling function unless it is LC_OK. */
#define LC_TRY(expr) do { lc_status s_ = (expr); if (s_ != LC_OK) return s_; } while (0)
/* LC_CHECK_RANGE of both components of v over [-limit, limit], named "<name>.x" and "<name>.y". */
lc_status lc_check_vec(lc_world *w, lc_vec2 v, double limit, const char *name);
/* The success of an API call that changed something a step reads: clears the message, and sleeping
 * bodies wake (sleep.c reads api_changes). */
static inline lc_status lc_changed(lc_world *w)
{
    w->api_changes++;
    w->error[0] = '\0';
    return LC_OK;
}

/* ---- body.c ---- */
/* Room for `bodies` rows and for body id `id` in the id map (-1 for ids not given). 1, or 0 without
 * memory. */
int lc_world_reserve(lc_world *w, int bodies, lc_body_id id);

/* ---- spring.c ---- */
/* Drops the springs attached to body `id` (lc_world_remove_body). */
void lc_remove_springs_of(lc_world *w, lc_body_id id);

/* ---- polygon.c ---- */
/* Validates a polygon and builds its shape about `center` (local frame; NULL: the centroid), which must
 * lie in the polygon, its vertices and normals in store (2 x LC_MAX_POLYGON_VERTICES vectors, the
 * caller's until lc_shape_keep). On failure returns the status and writes the reason into why. */
lc_status lc_shape_build(lc_shape *out, lc_vec2 *store, const lc_vec2 *v, int count, const lc_vec2 *center, char *why,
                         size_t why_len);
/* Gives a shape a block of its own for count vertices and normals, copying those v and n point to when
 * they are set (a built shape's store); 0, or -1 without memory (the shape unchanged). The block starts
 * on a cache line (LC_SHAPE_ALIGN): a box's four vertices are then one line, which the broad phase reads
 * for each body at each new angle. */
#define LC_SHAPE_ALIGN 64
int lc_shape_keep(lc_shape *s, int count);
/* Frees a kept shape's block. */
void lc_shape_release(lc_shape *s);

/* ---- small vector helpers ---- */
static inline lc_vec2 lc_v(double x, double y) { lc_vec2 r; r.x = x; r.y = y; return r; }
static inline lc_vec2 lc_add(lc_vec2 a, lc_vec2 b) { return lc_v(a.x + b.x, a.y + b.y); }
static inline lc_vec2 lc_sub(lc_vec2 a, lc_vec2 b) { return lc_v(a.x - b.x, a.y - b.y); }
static inline lc_vec2 lc_scale(lc_vec2 a, double s) { return lc_v(a.x * s, a.y * s); }
static inline double lc_dot(lc_vec2 a, lc_vec2 b) { return a.x * b.x + a.y * b.y; }
static inline double lc_cross(lc_vec2 a, lc_vec2 b) { return a.x * b.y - a.y * b.x; }
/* omega x r for a scalar angular velocity */
static inline lc_vec2 lc_wcross(double w, lc_vec2 r) { return lc_v(-w * r.y, w * r.x); }
static inline lc_vec2 lc_rot(double c, double s, lc_vec2 a) { return lc_v(c * a.x - s * a.y, s * a.x + c * a.y); }
static inline lc_vec2 lc_rot_inv(double c, double s, lc_vec2 a) { return lc_v(c * a.x + s * a.y, -s * a.x + c * a.y); }
/* 1 if marked[row] != 0 for one of rows[0..n). */
static inline int lc_any_marked(const uint8_t *marked, const int *rows, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (marked[rows[i]]) return 1;
    return 0;
}

/* ---- forces.c: accelerations from applied (non-contact) forces ---- */
/* For rows[0..n): acc[row*3 + 0..2] = (ax, ay, alpha) from gravity, damping, thrusters, springs, external
 * force and the force callback. Returns 0, or -1 when the force callback failed in this step (the rows'
 * accelerations are then NaN; lc_force_callback_failure says why). */
int lc_applied_accelerations(lc_world *w, const double *state, const int *rows, int n, double *acc);
/* 1 if a body's applied forces are constant over time (so it may be advanced in closed form). */
int lc_body_forces_constant(const lc_world *w, int row);
/* 1 if any of body `row`'s thrusters fires (level != 0). */
int lc_body_thrusting(const lc_world *w, int row);
/* 1 if something outside the contacts drives body `row`: an external force or torque, a thruster, or the
 * force callback (a non-zero force or torque on it in the step in progress). */
int lc_body_driven(const lc_world *w, int row);

/* ---- force_callback.c: the user's force law (collide/force.h) ---- */
typedef struct lc_force_callback lc_force_callback;
lc_force_callback *lc_force_callback_create(void);
void lc_force_callback_destroy(lc_force_callback *fc);
/* 1 when a force callback is set. */
int lc_force_callback_on(const lc_world *w);
/* At the start of a step: forgets the last step's failure and the forces recorded per row. 0, or -1 without
 * memory. */
int lc_force_callback_begin_step(lc_world *w);
/* Evaluates the callback at `state` for the dynamic rows among rows[0..n): *forces points at count x 3
 * doubles (fx, fy, torque per row; only those rows are meaningful). Records the largest force and torque
 * each row received in the step. Returns 0, or -1 when the callback failed now or earlier in the step. */
int lc_force_callback_eval(lc_world *w, const double *state, const int *rows, int n, const double **forces);
/* The largest |force| (N) and |torque| (N*m) the callback put on body `row` in the step in progress. */
void lc_force_callback_peak(const lc_world *w, int row, double *force, double *torque);
/* Why the step in progress cannot go on (the callback failed, or its buffers found no memory; *status
 * gets LC_ERR_CALLBACK or LC_ERR_NO_MEMORY), or NULL. */
const char *lc_force_callback_failure(const lc_world *w, lc_status *status);
/* The callback's potential energy (J) at `state`, 0 without a potential. LC_OK, or LC_ERR_CALLBACK with
 * the message recorded on w. */
lc_status lc_force_callback_potential(const lc_world *w, const double *state, double *out);

/* ---- narrow_phase.c ---- */
/* Geometry of a vertex/edge touch at `state`; fills p, n, ra, rb, gap, vn. */
void lc_touch_update(const lc_world *w, const double *state, lc_touch *t);
/* The touch at `state` (lc_touch_update) if its vertex is a contact there: 1 if the vertex is inside body b
 * (the touch then takes the edge the vertex is least deep behind), or outside and over its edge (grown
 * by extent at each end for a vertex within extent of its line), as lc_collect_touches_within keeps a
 * point; 0 if outside and not over it, or behind its line beside the body. */
int lc_touch_refresh(const lc_world *w, const double *state, lc_touch *t, double extent);
/* Appends touches between rows a and b with gap < max_gap (both directions), reduced to a manifold.
 * Returns the new count or -1 on allocation failure. */
int lc_collect_touches(const lc_world *w, const double *state, int a, int b, double max_gap,
                       lc_buf *buf, int count);
/* The same with the edges' extent grown by `extent` instead of max_gap, and only for vertices within
 * `extent` of the edge's line: a speculative search far beyond contact_distance must not take a vertex
 * passing just beyond the end of an edge (over a seam between two slabs) for one that will hit it. */
int lc_collect_touches_within(const lc_world *w, const double *state, int a, int b, double max_gap, double extent,
                              lc_buf *buf, int count);
/* Crossing found between two states: vertex of row a entered edge of row b. Its time of impact lies
 * in [t_lo, t_hi] from the interval's start: outside at t_lo, known to be inside by t_hi. Once
 * searched: toi, that time from the start of the event regime's step (< 0: none found), clear_to, a
 * time from the interval's start before which it has none, and by_pair, 1 when toi is the pair's first
 * touch by its separation rather than the vertex's. */
typedef struct lc_crossing {
    int a, b, vertex, edge;
    double t_lo, t_hi, toi, clear_to;
    int by_pair;
} lc_crossing;
/* Appends crossings of the pair (a, b) between state0 and state1. Returns new count or -1. */
int lc_find_crossings(const lc_world *w, const double *s0, const double *s1, int a, int b,
                      lc_buf *buf, int count);
/* Largest separation of two bodies over the faces of both (< 0: overlapping), the separating axis test. */
double lc_pair_separation(const lc_world *w, const double *state, int a, int b);
/* The same, with the face it is measured along: edge `edge` of row `ref` (a or b). */
double lc_pair_separation_axis(const lc_world *w, const double *state, int a, int b, int *ref, int *edge);
/* Signed distance of vertex of a from the line of edge of b at state. */
double lc_vertex_edge_gap(const lc_world *w, const double *state, int a, int vertex, int b, int edge);

/* ---- broad_phase.c ---- */
typedef struct lc_broad_phase_state lc_broad_phase_state;
lc_broad_phase_state *lc_broad_phase_state_create(void);
void lc_broad_phase_state_destroy(lc_broad_phase_state *bp);
/* Candidate pairs (a < b by row, not both static) whose boxes, swept from s0 to s1 (s1 may equal s0) and
 * grown by margin, overlap. Writes pairs as int[2] into buf; returns count or -1. */
int lc_broad_phase(lc_world *w, const double *s0, const double *s1, double margin, lc_buf *buf);
/* Largest gap (m) between two bodies' axis-aligned bounding boxes along x or y at a state: a lower
 * bound of their distance that, unlike the bounding circles, stays tight for a block over a long
 * floor or beside a wall (boxes from the per-body cache). */
double lc_bounds_gap(const lc_world *w, const double *state, int a, int b);
/* Body row's box over the interval grown by margin (x0, y0, x1, y1), as the pair searches take it: its
 * end poses' boxes, or its bounding circle's where it turns more than LC_MAX_TRIAL_ROTATION. */
void lc_swept_box(lc_world *w, const double *s0, const double *s1, int row, double margin, double out[4]);
/* Body row's end poses' boxes, joined and grown by margin (the caller allows for the turn between). */
void lc_end_poses_box(lc_world *w, const double *s0, const double *s1, int row, double margin, double out[4]);
/* Candidate pairs, as lc_broad_phase, of given boxes (4 doubles per row: x0, y0, x1, y1). */
int lc_broad_phase_boxes(lc_world *w, const double *boxes4, lc_buf *buf);
/* The same, restricted to pairs with at least one of the nlist bodies in list (marked[row] != 0). */
int lc_broad_phase_of(lc_world *w, const double *s0, const double *s1, double margin, const uint8_t *marked,
                      const int *list, int nlist, lc_buf *buf);
/* The event regime's trial interval in a grid (reach_grid.h): where each of rows[0..nrows) (advanced from
 * s0 over h to s1 under constant accelerations, no touch) and each static body can be until the
 * interval ends. While tracked, lc_broad_phase_of and lc_broad_phase_near visit only what is near, for
 * states between s0 and s1. 0, or -1 without memory (then untracked). */
int lc_broad_phase_track(lc_world *w, const double *s0, const double *s1, double h, const int *rows, int nrows,
                         double margin);
/* Rows rows[0..nrows) now go from s0 over h to s1 (an impact changed their paths). 0, or -1 (untracked). */
int lc_broad_phase_retrack(lc_world *w, const double *s0, const double *s1, double h, const int *rows, int nrows,
                           double margin);
void lc_broad_phase_untrack(lc_world *w);
/* The tracked rows whose reach meets box4 (x0, y0, x1, y1), in ascending row order, into *out: their
 * count, -1 without memory, or -2 when nothing is tracked. */
int lc_broad_phase_near(lc_world *w, const double box4[4], const int **out);

/* ---- response.c ---- */
/* Change of relative velocity along di at touch ti per unit impulse along dj at touch tj (J M^-1 J^T). */
double lc_response_dir(const lc_world *w, const lc_touch *ti, lc_vec2 di, const lc_touch *tj, lc_vec2 dj);
/* The n x n matrix of normal responses (delta normal velocity at i per unit normal impulse at j). */
void lc_response_matrix(const lc_world *w, const lc_touch *t, int n, double *A);
/* Adds push/m and (r x push)/I to body a's three entries at dst[row * stride] and subtracts them from
 * body b's: velocities (dst = state + 3, stride 6), accelerations (stride 3) or positions (stride 6). */
void lc_touch_apply(const lc_world *w, const lc_touch *t, lc_vec2 push, double *dst, int stride);
/* Relative motion along d at touch t produced by per-body changes acc[row * 3 + 0..2] (the inverse of
 * lc_touch_apply with stride 3). */
double lc_response_push(const lc_world *w, const lc_touch *t, lc_vec2 d, const double *acc);
/* out = A x between rows of t[0..m): x pushes along each touch's normal (from_tangent = 0) or tangent,
 * out is read back along the normal (to_tangent = 0) or tangent; A is never formed, O(m + bodies).
 * body: scratch of count x 3 doubles (overwritten). */
void lc_response_rows(const lc_world *w, const lc_touch *t, int m, int from_tangent, const double *x,
                      int to_tangent, double *body, double *out);
/* Tangent of a contact normal (the direction of friction rows and tangent impulses). */
static inline lc_vec2 lc_tangent_of(lc_vec2 n) { return lc_v(-n.y, n.x); }

/* ---- sparse_lcp.c ---- */
typedef struct lc_sparse_lcp_state lc_sparse_lcp_state;
lc_sparse_lcp_state *lc_sparse_lcp_state_create(void);
void lc_sparse_lcp_state_destroy(lc_sparse_lcp_state *sp);
/* MPRGP on min 1/2 x'Ax + b'x, lo <= x <= hi, with A = J M^-1 J' of the touches' normal (or, with
 * tangent != 0, tangent) rows, never formed. x: start and answer. Returns products of A used (-1: no
 * memory); *violation = largest entry of the projected gradient (units of b). A solve that diverges
 * (round-off past its matrix's scale) stops with the best iterate it kept. */
int lc_sparse_lcp(lc_world *w, const lc_touch *t, int m, int tangent, const double *b, const double *lo,
                  const double *hi, double *x, double tol, int max_products, double *violation);
/* Snapshots (snapshot.c): the ||A|| estimates kept across solves. */
struct lc_writer;
struct lc_reader;
void lc_sparse_lcp_save(const lc_sparse_lcp_state *sp, struct lc_writer *out);
void lc_sparse_lcp_load(lc_sparse_lcp_state *sp, struct lc_reader *in);

/* ---- static_load.c ---- */
typedef struct lc_static_load_state lc_static_load_state;
lc_static_load_state *lc_static_load_state_create(void);
void lc_static_load_state_destroy(lc_static_load_state *sl);
/* Starting guesses for a cold pile's sparse solves (only touches a body rests on get one; f, lam must
 * hold zeros). Each returns 0 (no gravity: no guess), or -1 on allocation failure. */
/* f[i]: N, the weight each touch carries when loads are shared among a body's supports by the lever rule. */
int lc_static_load_forces(lc_world *w, const lc_touch *t, int m, double *f);
/* The same over an island: local[row] maps its dynamic rows to 0..n-1 (static rows to -1), rows[k] back. */
int lc_static_load_forces_of(lc_world *w, const lc_touch *t, int m, const int *local, const int *rows, int n,
                             double *f);
/* lam[i]: kg*m, the projection's multipliers that lift every body by the gaps below it (deficit[i], m,
 * what touch i is short of the contact gap). */
int lc_static_load_lifts(lc_world *w, const lc_touch *t, int m, const double *deficit, double *lam);

/* ---- contact_forces.c ---- */
typedef struct lc_contact_forces_state lc_contact_forces_state;
lc_contact_forces_state *lc_contact_forces_state_create(void);
void lc_contact_forces_state_destroy(lc_contact_forces_state *cf);
/* Adds resting contact forces for touches[0..n) into acc (rows indexed), solving the contact LCP.
 * Stores each force in touches[i].value. Returns 0, or -1 on allocation failure. */
int lc_contact_forces(lc_world *w, const double *state, lc_touch *touches, int n, double *acc);

/* ---- integrator.c ---- */
typedef struct lc_integrator_state lc_integrator_state;
lc_integrator_state *lc_integrator_state_create(void);
void lc_integrator_state_destroy(lc_integrator_state *is);
/* Advances rows (dynamic bodies) from s0 by h into s1 with the world integrator, touches held as resting
 * contacts; the rows not listed are copied from s0. Returns 0, or -1 without memory or when the force
 * callback failed. */
int lc_integrate(lc_world *w, const double *s0, double h, const int *rows, int nrows,
                 lc_touch *touches, int ntouches, double *s1);
/* lc_integrate writing only the listed rows of s1 (the others keep whatever s1 held): for callers that
 * read only those rows, a pair's time-of-impact search in a 2000-body world copying 96 KB per
 * evaluation otherwise. */
int lc_integrate_rows(lc_world *w, const double *s0, double h, const int *rows, int nrows,
                      lc_touch *touches, int ntouches, double *s1);

/* ---- impulse.c ---- */
typedef struct lc_impulse_state lc_impulse_state;
lc_impulse_state *lc_impulse_state_create(void);
void lc_impulse_state_destroy(lc_impulse_state *is);
/* Resolves the impact among touches[0..n) at the current state (velocities changed in place), with
 * restitution when `elastic`, else perfectly inelastic. Returns the number of points that received an
 * impulse, or -1 on allocation failure. */
int lc_resolve_impacts(lc_world *w, double *state, lc_touch *t, int n, int elastic);
/* Approach speed (m/s) above which an impact of a pair of this elasticity bounces. */
double lc_bounce_speed(const lc_world *w, double elasticity);

/* ---- step.c ---- */
typedef struct lc_step_state lc_step_state;   /* the step's own buffers, owned by the world */
lc_step_state *lc_step_state_create(void);
void lc_step_state_destroy(lc_step_state *ss);
/* The try at the step in progress, as the regimes see it: where it began (to undo it, or to weigh its
 * energy against), and the rows an earlier try sent to the event regime. */
typedef struct lc_step_try {
    const double *start;         /* every row's state when the step began */
    double time0;                /* the world's time then */
    const uint8_t *force_event;  /* rows an earlier try of this step found the contact regime unable to keep apart */
} lc_step_try;
/* Undoes the step in progress (the state and time it began with, no contacts) and fails with s:
 * "<what>; the step was undone". */
lc_status lc_step_undo(lc_world *w, const lc_step_try *step, lc_status s, const char *what);

/* ---- results.c ---- */
/* A new slot at the end of the step's contacts (grown as needed), or NULL without memory. */
lc_contact *lc_new_contact(lc_world *w);
/* Appends a contact of the step in progress (a touch at its current geometry). 0, or -1 without memory. */
int lc_push_contact(lc_world *w, const lc_touch *t, lc_contact_kind kind);
/* Adds a step's counters to the running totals (the max_* fields take the larger). */
void lc_counters_add(lc_counters *total, const lc_counters *last);

/* ---- time_of_impact.c ---- */
/* Time in [0, h] at which the crossing's gap reaches the contact gap; integrates the listed rows. */
double lc_time_of_impact(lc_world *w, const double *s0, double h, const lc_crossing *c,
                         const int *rows, int nrows, lc_touch *touches, int ntouches, double *scratch);
/* Time in [0, h] at which bodies a and b, separated by more than the contact gap at s0 and overlapping
 * at s0 + h, are separated by the contact gap again (bisection on their separating-axis distance), to
 * toi_time_tolerance and, beyond it, until they are at most `reach` farther apart than the contact gap
 * (INFINITY: the time tolerance only). */
double lc_pair_time_of_impact(lc_world *w, const double *s0, double h, int a, int b, const int *rows, int nrows,
                              lc_touch *touches, int ntouches, double reach, double *scratch);

/* ---- energy.c ---- */
void lc_compute_energy(const lc_world *w, const double *state, lc_energy *out);
/* 1 if the bodies under the resting touches rest[0..nrest) gained, from s0 to s1, more than their
 * kinetic energy again (contact forces do no work). mark: count bytes of zeros (left zero). */
int lc_contact_energy_blew_up(const lc_world *w, const double *s0, const double *s1, const lc_touch *rest,
                              int nrest, uint8_t *mark);
/* 1 if the step from `backup` to w->state gained far more energy than its driving forces can give. */
int lc_step_energy_blew_up(const lc_world *w, const double *backup, double dt, int started_deep);

/* Stage timing (stage_timing.c): t0 = lc_stage_begin(w); ...; lc_stage_end(w, &w->last.time_x, t0). */
double lc_stage_clock(void);
static inline double lc_stage_begin(const lc_world *w) { return w->stage_timing ? lc_stage_clock() : 0.0; }
static inline void lc_stage_end(const lc_world *w, double *field, double t0)
{
    if (w->stage_timing) *field += lc_stage_clock() - t0;
}

/* Empties a body's trig cache (NaN matches no angle). */
static inline void lc_trig_clear(lc_trig *t) { t->e[0].angle = t->e[1].angle = NAN; }

/* The trig cache's entry of body `row` at `angle`, made (cosine and sine; no box yet) when neither of
 * the last two angles is it. A step asks for the same few states' trig many times (broad phase,
 * crossings, separation, touches: it was 40 % of the seed scene's time), so the last two angles per
 * body are remembered; a match is bit-for-bit, so results do not change. */
static inline lc_trig_entry *lc_body_trig_entry(const lc_world *w, int row, double angle)
{
    lc_trig *t = &w->trig[row];
    if (memcmp(&t->e[0].angle, &angle, sizeof angle) == 0) return &t->e[0];
    if (memcmp(&t->e[1].angle, &angle, sizeof angle) == 0) return &t->e[1];
    t->e[1] = t->e[0];
    t->e[0].angle = angle;
    t->e[0].c = cos(angle);
    t->e[0].s = sin(angle);
    t->e[0].ext[0] = NAN;
    return &t->e[0];
}

/* Cosine and sine of body `row` at `angle` (the trig cache). */
static inline void lc_body_trig(const lc_world *w, int row, double angle, double *c, double *s)
{
    const lc_trig_entry *e = lc_body_trig_entry(w, row, angle);
    *c = e->c;
    *s = e->s;
}

#endif
