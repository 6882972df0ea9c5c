/* libcollide: value types, definition structs and enums of the public API.
 * Units are SI throughout: m, kg, s, rad, N, N*m, J. Angles are counter-clockwise. */
#ifndef COLLIDE_TYPES_H
#define COLLIDE_TYPES_H

#include <stdint.h>
#include "collide/math.h"

/* Opaque simulation world. Separate worlds share nothing. */
typedef struct lc_world lc_world;

/* Stable body handle; never reused inside one world. */
typedef uint32_t lc_body_id;
/* Stable spring handle; never reused inside one world. */
typedef uint32_t lc_spring_id;

/* body_b of a spring anchored to a fixed world point rather than a body. */
#define LC_WORLD_ANCHOR 0xFFFFFFFFu
/* Most vertices a polygon may have. */
#define LC_MAX_POLYGON_VERTICES 64
/* Most thrusters one body may carry. */
#define LC_MAX_THRUSTERS 16

/* Result of every call that can fail. The world is unchanged when a call fails. */
typedef enum lc_status {
    LC_OK = 0,
    LC_ERR_NULL = 1,            /* a required pointer was NULL */
    LC_ERR_NOT_FINITE = 2,      /* a NaN or infinite number was given */
    LC_ERR_OUT_OF_RANGE = 3,    /* a number outside its documented range */
    LC_ERR_BAD_POLYGON = 4,     /* too few/many vertices, degenerate, non-convex or self-intersecting */
    LC_ERR_UNKNOWN_BODY = 5,    /* no body with that id in this world */
    LC_ERR_UNKNOWN_SPRING = 6,  /* no spring with that id in this world */
    LC_ERR_UNKNOWN_THRUSTER = 7,/* thruster index out of range for that body */
    LC_ERR_STATIC_BODY = 8,     /* the operation needs a dynamic body */
    LC_ERR_NO_MEMORY = 9,       /* allocation failed */
    LC_ERR_NUMERIC = 10,        /* a step produced a non-finite state; the step was undone */
    LC_ERR_BAD_ENUM = 11,       /* an enum field holds an unknown value */
    LC_ERR_BAD_SNAPSHOT = 12,   /* a snapshot (lc_world_load) that is truncated, corrupt or of another format */
    LC_ERR_CALLBACK = 13        /* a user callback failed or gave a non-finite value (a step: undone) */
} lc_status;

/* Free-flight integrator; the value is its order of accuracy. */
typedef enum lc_integrator {
    LC_INTEGRATOR_EULER = 1,    /* explicit Euler, order 1 (for teaching and order tests) */
    LC_INTEGRATOR_MIDPOINT = 2, /* explicit midpoint, order 2 */
    LC_INTEGRATOR_RK4 = 4       /* classic Runge-Kutta, order 4 (default) */
} lc_integrator;

/* How simultaneous impacts are resolved. */
typedef enum lc_impact_mode {
    LC_IMPACT_SERIAL = 0,       /* one touching body pair at a time, most negative first, until none approaches (default) */
    LC_IMPACT_SIMULTANEOUS = 1  /* all impacts in one complementarity problem */
} lc_impact_mode;

/* How the time of impact is found once a step has penetrated. */
typedef enum lc_toi_method {
    LC_TOI_ROOT_FINDER = 0,     /* bracketed root finder on the gap function (default) */
    LC_TOI_BINARY_SEARCH = 1    /* bisection on the time of impact */
} lc_toi_method;

/* Broadphase pair finding. */
typedef enum lc_broadphase {
    LC_BROADPHASE_AUTO = 0,        /* brute force below broadphase_threshold bodies, sort-and-sweep above,
                                      the grid from 4096 bodies (its search costs the same per body
                                      at any count; a sweep's grows as sqrt(n) in a square world) */
    LC_BROADPHASE_BRUTE_FORCE = 1,
    LC_BROADPHASE_SORT_AND_SWEEP = 2,
    LC_BROADPHASE_GRID = 3         /* pairs from a uniform grid of the boxes */
} lc_broadphase;

/* How two bodies' coefficients combine for a contact. */
typedef enum lc_mix_rule {
    LC_MIX_MIN = 0,       /* min(a, b) (default for elasticity) */
    LC_MIX_MAX = 1,
    LC_MIX_MEAN = 2,      /* (a + b) / 2 */
    LC_MIX_GEOMETRIC = 3  /* sqrt(a * b): default for friction */
} lc_mix_rule;

/* Drift correction added to resting contacts. */
typedef enum lc_stabilization {
    LC_STABILIZE_NONE = 0,
    LC_STABILIZE_VELOCITY = 1,               /* drive residual normal velocity to zero (default; drift is projected out) */
    LC_STABILIZE_VELOCITY_AND_DISTANCE = 2   /* ... and the gap to contact_gap by force (leaves ~contact_gap/h of speed) */
} lc_stabilization;

/* How an island (bodies that touch or may meet within a step, docs/contact_regime.md) is advanced. */
typedef enum lc_regime {
    LC_REGIME_AUTO = 0,    /* each island by what it needs (default): islands resting on a touch between
                              bodies that are not perfectly elastic (e < 1) in the contact regime, the
                              others (free flight, isolated impacts, e = 1 chains) in the event regime */
    LC_REGIME_EVENT = 1,   /* every island event by event: exact times of impact, eq. 11, contact forces */
    LC_REGIME_CONTACT = 2  /* every island by velocity-level time stepping of contact impulses */
} lc_regime;

typedef enum lc_body_type {
    LC_BODY_DYNAMIC = 0,
    LC_BODY_STATIC = 1    /* infinite mass and inertia, never moves */
} lc_body_type;

/* World settings. Start from lc_default_world_def(). */
typedef struct lc_world_def {
    lc_vec2 gravity;               /* m/s^2, default (0, -9.81) */
    double zero_energy_level;      /* m, height of zero gravitational potential, default 0 */
    double damping;                /* N*s/m, force -k*v at the centre of mass, >= 0, default 0 */
    double damping_rotation_ratio; /* m^2, torque -k*r*omega, >= 0, default 0.1 */
    lc_integrator integrator;      /* default LC_INTEGRATOR_RK4 */
    lc_impact_mode impact_mode;    /* default LC_IMPACT_SERIAL */
    lc_toi_method toi_method;      /* default LC_TOI_ROOT_FINDER */
    double toi_time_tolerance;     /* s, time-of-impact accuracy, [1e-15, 1e-2], default 1e-10 */
    double toi_distance_tolerance; /* m, gap accuracy at impact, [1e-15, 1e-2], default 1e-10 */
    int toi_max_iterations;        /* per search, [4, 1000], default 100 */
    double contact_gap;            /* m, gap at which impacts are handled and resting contacts are held, [1e-12, 1e-2], default 1e-7 */
    double contact_distance;       /* m, gap below which bodies touch, > contact_gap, <= 1, default 1e-5 */
    double resting_speed;          /* m/s, approach speed below which a touch is resting, not an impact, [0, 10], default 1e-4 */
    double restitution_threshold;  /* m/s, approach speed below which an impact does not bounce (pairs with e < 1), [0, 10], default 1e-2 */
    lc_stabilization stabilization;/* default LC_STABILIZE_VELOCITY */
    lc_mix_rule elasticity_rule;   /* default LC_MIX_MIN */
    lc_mix_rule friction_rule;     /* default LC_MIX_GEOMETRIC */
    int max_events_per_step;       /* impacts handled in one step before the rest are resolved inelastically, [1, 1e6], default 10000 */
    int max_serial_iterations;     /* serial-mode passes per event before one simultaneous inelastic pass, [1, 1e6], default 1000 */
    int lcp_exact_max;             /* contact problems up to this size are solved exactly (pivoting), larger iteratively, [0, 4096], default 128 */
    int lcp_max_iterations;        /* iterative solver sweeps, [1, 1e6], default 200 */
    double lcp_tolerance;          /* relative residual for the iterative solver, [0, 1], default 1e-10 */
    lc_broadphase broadphase;      /* default LC_BROADPHASE_AUTO */
    int broadphase_threshold;      /* body count at which AUTO switches from brute force, [2, 1e6], default 32 */
    lc_regime regime;              /* default LC_REGIME_AUTO */
    int contact_iterations;        /* contact regime: most solver sweeps per solve of 64 points or more (a
                                      smaller one may take proportionally more), [1, 1e6], default 30 */
    double contact_tolerance;      /* contact regime: m/s, a solve stops at a sweep that changes no point's
                                      velocity by more than this, [0, 1], default 1e-10 */
    int allow_sleep;               /* 1: islands at rest are not advanced until something reaches them
                                      (docs/contact_regime.md, "Sleep"), default 0 */
    double sleep_time;             /* s a body must rest before its island may sleep, (0, 1e6], default 0.5 */
    double sleep_speed;            /* m/s, a body rests while its centre and its farthest point move slower
                                      than this, [0, 10], default 1e-4 */
    int event_capacity;            /* most unread impact events kept for lc_world_get_events, [0, 1e6], default
                                      4096; past it the oldest go (counted); 0: none are kept */
} lc_world_def;

/* A body. Start from lc_default_body_def(). Vertices are in the body's local frame; the centre of
 * mass and moment of inertia are computed from the polygon (uniform density) unless given. A body's
 * mass lies inside its polygon (the polygon is all that collides), so a given centre of mass must lie
 * in the polygon and a given inertia cannot exceed mass * r^2, r the farthest vertex from it. */
typedef struct lc_body_def {
    lc_body_type type;             /* default LC_BODY_DYNAMIC */
    const lc_vec2 *vertices;       /* m, local frame, convex, either winding, 3..LC_MAX_POLYGON_VERTICES */
    int vertex_count;
    lc_vec2 position;              /* m, world position of the local frame's origin */
    double angle;                  /* rad, rotation of the local frame */
    lc_vec2 velocity;              /* m/s, of the centre of mass */
    double angular_velocity;       /* rad/s */
    double mass;                   /* kg, > 0 for dynamic bodies, ignored for static, default 1 */
    double elasticity;             /* coefficient of restitution, [0, 1], default 1 */
    double friction;               /* Coulomb coefficient, [0, 10], default 0 */
    double inertia;                /* kg*m^2 about the centre of mass, (0, mass * r^2] with r the farthest
                                      vertex from the centre of mass; 0 (default): the polygon's (uniform
                                      density) about the centre of mass; ignored for static bodies */
    int custom_center_of_mass;     /* 1: the centre of mass is center_of_mass; 0 (default): the polygon's
                                      centroid, and center_of_mass is ignored */
    lc_vec2 center_of_mass;        /* m, local frame, inside the polygon or on its boundary (static bodies
                                      too: the state is that point's) */
} lc_body_def;

/* A thruster fixed to a body: a force of magnitude*level along direction, applied at point. */
typedef struct lc_thruster_def {
    lc_vec2 point;      /* m, body frame relative to the body's local origin */
    lc_vec2 direction;  /* body frame, normalised on creation, non-zero */
    double magnitude;   /* N at level 1, [0, 1e9] */
} lc_thruster_def;

/* A spring from a point on body_a to a point on body_b or to a fixed world point. */
typedef struct lc_spring_def {
    lc_body_id body_a;  /* must be a dynamic body */
    lc_vec2 point_a;    /* m, body_a local frame */
    lc_body_id body_b;  /* a body, or LC_WORLD_ANCHOR */
    lc_vec2 point_b;    /* m, body_b local frame, or world frame when body_b is LC_WORLD_ANCHOR */
    double stiffness;   /* N/m, [0, 1e9], default 3 (a mouse spring's) */
    double damping;     /* N*s/m on the relative velocity of the two points, [0, 1e9], default 0 */
    double rest_length; /* m, [0, 1e6], default 0 */
} lc_spring_def;

/* Read-only view of every body's state, contiguous and in body order (the order bodies were added,
 * removals close the gap). Valid until the next call that adds or removes a body. */
typedef struct lc_state_view {
    int count;
    const lc_body_id *ids;   /* ids[i] is the id of row i */
    const double *state;     /* count x 6 doubles: x, y (centre of mass, m), angle (rad), vx, vy (m/s), omega (rad/s) */
    const double *mass;      /* kg, 0 for static bodies */
    const double *inertia;   /* kg*m^2 about the centre of mass, 0 for static bodies */
    const uint8_t *is_static;/* 1 for static bodies */
} lc_state_view;

typedef enum lc_contact_kind {
    LC_CONTACT_COLLISION = 0, /* an impact handled during the last step */
    LC_CONTACT_RESTING = 1    /* a resting contact held by a contact force at the end of the last step */
} lc_contact_kind;

/* One contact point. body_a owns the vertex, body_b the edge; normal points out of body_b. */
typedef struct lc_contact {
    lc_body_id body_a;
    lc_body_id body_b;
    lc_vec2 point;            /* m, world */
    lc_vec2 normal;           /* unit, world */
    double gap;               /* m, separation along normal at that instant */
    double normal_velocity;   /* m/s, relative normal velocity before the impact (collisions) or now (resting) */
    double impulse;           /* N*s, normal impulse (collisions), 0 for resting */
    double tangent_impulse;   /* N*s, friction impulse (collisions) */
    double force;             /* N, normal contact force (resting), 0 for collisions */
    double time;              /* s, world time of the impact or of the reading */
    lc_contact_kind kind;
} lc_contact;

/* Which regime resolved an impact (docs/contact_regime.md). */
typedef enum lc_impact_kind {
    LC_IMPACT_EVENT = 0,   /* the event regime: at the impact's own time, by eq. 11 */
    LC_IMPACT_CONTACT = 1  /* the contact regime: at the start of the (sub-)step in which the point closed
                              faster than resting_speed */
} lc_impact_kind;

/* One impact of the event stream (lc_world_get_events): a contact point that received a collision
 * impulse. The same numbers as the step's LC_CONTACT_COLLISION contact. body_a owns the vertex, body_b
 * the edge; the normal points out of body_b. */
typedef struct lc_impact_event {
    double time;              /* s, world time of the impact */
    lc_body_id body_a;
    lc_body_id body_b;
    lc_vec2 point;            /* m, world */
    lc_vec2 normal;           /* unit, world */
    double gap;               /* m, separation along the normal when the impulse was applied */
    double normal_impulse;    /* N*s, along the normal, >= 0 */
    double tangent_impulse;   /* N*s, friction, along (-normal.y, normal.x) */
    double approach_speed;    /* m/s, the points' approach along the normal before the impact (minus the
                                 relative normal velocity); <= 0 for a point of a multi-point impact that
                                 was not approaching itself */
    lc_impact_kind kind;
} lc_impact_event;

/* Energy split into translational, rotational, gravitational, spring and force-callback parts, plus
 * momentum. */
typedef struct lc_energy {
    double translational;    /* J, sum of m|v|^2/2 */
    double rotational;       /* J, sum of I*omega^2/2 */
    double gravitational;    /* J, sum of m*g*(height above zero_energy_level) along -gravity */
    double spring;           /* J, sum of k*stretch^2/2 */
    double callback;         /* J, the force callback's potential (lc_potential_fn); 0 without one */
    double total;            /* J */
    lc_vec2 linear_momentum; /* kg*m/s */
    double angular_momentum; /* kg*m^2/s, about the world origin */
} lc_energy;

/* Work counters; lc_world_get_counters gives those of the last step and the cumulative ones. */
typedef struct lc_counters {
    uint64_t steps;
    uint64_t force_evaluations;       /* right-hand-side evaluations of the ODE */
    uint64_t analytic_advances;       /* body advances done in closed form (no integrator) */
    uint64_t broadphase_pairs;        /* candidate pairs the broadphase produced */
    uint64_t brute_force_steps;       /* detections done by brute force */
    uint64_t sort_and_sweep_steps;    /* detections done by sort-and-sweep */
    uint64_t grid_steps;              /* detections done by the grid */
    uint64_t collisions;              /* impact events (one per time of impact) */
    uint64_t impulses;                /* contact points that received a collision impulse */
    uint64_t toi_searches;            /* time-of-impact searches */
    uint64_t toi_iterations;          /* their gap-function evaluations */
    uint64_t serial_iterations;       /* serial-mode passes */
    uint64_t inelastic_fallbacks;     /* events closed by the inelastic simultaneous pass */
    uint64_t resting_contacts;        /* resting contact points in contact solves */
    uint64_t contact_solves;          /* complementarity solves for contact forces */
    uint64_t contact_solve_iterations;/* pivots, or products of the response matrix (large groups), in those solves */
    uint64_t solver_work;             /* response-matrix entries visited by all complementarity solves (contact
                                         forces, impulses, projection): m^2 per pivot or sweep of a dense solve of
                                         m rows, 12 m per product of a sparse one (6 entries a row, read twice);
                                         what a step's solves cost, capped at 1e9 per body of the world */
    uint64_t impulse_solves;          /* complementarity solves for impulses */
    uint64_t position_projections;    /* end-of-step corrections of points found inside another body */
    uint64_t quiet_advances;          /* RK4 intervals of resting bodies taken with two force evaluations */
    uint64_t islands;                 /* islands advanced (docs/contact_regime.md) */
    uint64_t island_retries;          /* steps taken again with islands grown to where the bodies went */
    uint64_t contact_islands;         /* of those, advanced in the contact regime */
    uint64_t contact_points;          /* contact points in the contact regime's solves */
    uint64_t contact_sweeps;          /* Gauss-Seidel sweeps of those solves */
    uint64_t contact_exact_solves;    /* of those solves, taken exactly (few points: active sets or pivoting) */
    uint64_t contact_cuts;            /* contact-regime steps cut at a located stick-slip or arrival */
    uint64_t contact_precise_retries; /* contact-regime island steps taken again with converged solves */
    uint64_t energy_clamps;           /* contact-regime island steps whose energy gain was taken back from
                                         the island's kinetic energy */
    uint64_t contact_rests;           /* contact-regime island sub-steps held at rest (a settling pile whose
                                         answer moved no point faster than the rest speed, 1e-5 m/s, or a
                                         step no try could take of an island at rest to 1e-4 m/s), and
                                         steps of still islands, not solved */
    uint64_t contact_unresolved;      /* contact-regime steps of islands too large for the event regime kept
                                         with an overlap or an energy gain above the engine's allowance
                                         (docs/contact_regime.md, "Guarantees") */
    double max_unresolved_overlap;    /* m, deepest overlap such a step left */
    double max_unresolved_energy;     /* J, largest energy gain such a step kept */
    uint64_t bodies_asleep;           /* bodies asleep at the end of the step (last; the total sums them) */
    uint64_t islands_woken;           /* islands of sleeping bodies woken by an awake body reaching them */
    double max_contact_residual;      /* m/s, largest residual of a contact-regime solve (its stopping rule) */
    double max_lcp_residual;          /* largest residual of an iterative contact-force solve: relative for
                                         groups up to lcp_exact_max, m/s^2 of relative acceleration above */
    /* s of wall time per pipeline stage, measured only while lc_world_set_stage_timing is on (else 0).
     * The first six and time_contact_regime do not overlap and sum to at most time_step;
     * time_contact_forces lies inside time_integration and time_toi_search (the integrator solves the
     * contact forces). */
    double time_step;                 /* the whole lc_world_step */
    double time_detection;            /* broadphase, touches, crossings, swept checks */
    double time_integration;          /* advancing the world over trial intervals and to event times */
    double time_toi_search;           /* time-of-impact searches (their own integrations included) */
    double time_impulses;             /* impulse solves of impacts */
    double time_projection;           /* end-of-step position projection */
    double time_contact_forces;       /* resting-contact force solves, wherever they ran */
    double time_contact_regime;       /* contact-regime island steps, all their stages (disjoint from the
                                         six above) */
} lc_counters;

#endif /* COLLIDE_TYPES_H */
