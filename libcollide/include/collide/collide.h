/* libcollide: an event-accurate 2D rigid-body collision engine.
 * Functions of the public API. Every function that can fail returns lc_status and leaves the
 * world unchanged on failure; lc_world_last_error() then tells why in words. */
#ifndef COLLIDE_COLLIDE_H
#define COLLIDE_COLLIDE_H

#include <stddef.h>
#include <stdint.h>
#include "collide/math.h"
#include "collide/types.h"
#include "collide/query.h"   /* queries: bodies at a point or in a box, ray casts, distance of two bodies */

#ifdef __cplusplus
extern "C" {
#endif

/* ---- defaults and helpers ------------------------------------------------------------ */

/* Default world settings (gravity (0,-9.81) m/s^2, RK4, serial impacts, root-finder TOI). */
lc_world_def lc_default_world_def(void);
/* Default body: dynamic, 1 kg, elasticity 1, friction 0, no vertices yet. */
lc_body_def lc_default_body_def(void);
/* Default spring: stiffness 3 N/m, damping 0, rest length 0, anchored to the world. */
lc_spring_def lc_default_spring_def(void);
/* Fills out[4] with a w x h rectangle (m) centred on the local origin, counter-clockwise. */
lc_status lc_make_rectangle(double width, double height, lc_vec2 out[4]);
/* Short fixed text naming a status code. */
const char *lc_status_string(lc_status status);
/* Library version as "major.minor.patch". */
const char *lc_version(void);

/* ---- world ----------------------------------------------------------------------------- */

/* Creates a world; on failure returns NULL and writes the reason into errbuf (may be NULL). */
lc_world *lc_world_create(const lc_world_def *def, char *errbuf, size_t errbuf_len);
/* Frees a world and everything in it; NULL is allowed. */
void lc_world_destroy(lc_world *world);
/* The message of the last failed call on this world ("" after a success). */
const char *lc_world_last_error(const lc_world *world);
/* Copies the current settings. */
lc_status lc_world_get_def(const lc_world *world, lc_world_def *out);
/* Replaces all settings at once after validating every field. */
lc_status lc_world_set_def(lc_world *world, const lc_world_def *def);
/* Sets gravity (m/s^2). */
lc_status lc_world_set_gravity(lc_world *world, lc_vec2 gravity);
/* Sets linear damping k (N*s/m) and the rotation ratio r (m^2): force -k*v, torque -k*r*omega. */
lc_status lc_world_set_damping(lc_world *world, double damping, double rotation_ratio);
/* Sets the elasticity of every body present, as the seed's control does. */
lc_status lc_world_set_elasticity(lc_world *world, double elasticity);
/* Simulated time (s). */
double lc_world_get_time(const lc_world *world);
/* Advances the world by dt seconds (0 < dt <= 1). Impacts inside the step are handled at their
 * time of impact and the step is completed; on a non-finite result the step is undone. */
lc_status lc_world_step(lc_world *world, double dt);

/* ---- bodies ------------------------------------------------------------------------------- */

/* Adds a body; its id is written to out_id (required). */
lc_status lc_world_add_body(lc_world *world, const lc_body_def *def, lc_body_id *out_id);
/* Adds four static walls (thickness m) whose inner faces bound [xmin,xmax] x [ymin,ymax];
 * ids in the order bottom, right, top, left (out_ids may be NULL). */
lc_status lc_world_add_walls(lc_world *world, double xmin, double ymin, double xmax, double ymax,
                             double thickness, double elasticity, lc_body_id out_ids[4]);
/* Removes a body, its thrusters and every spring attached to it. */
lc_status lc_world_remove_body(lc_world *world, lc_body_id id);
/* Number of bodies, static ones included. */
int lc_world_body_count(const lc_world *world);
/* Row of a body in the state arrays, or -1 if unknown. */
int lc_world_body_index(const lc_world *world, lc_body_id id);
/* Zero-copy view of all body states; see lc_state_view for lifetime. */
lc_status lc_world_get_state(const lc_world *world, lc_state_view *out);
/* Overwrites all dynamic states from count x 6 doubles in lc_state_view order (static rows ignored). */
lc_status lc_world_set_state(lc_world *world, const double *state, int count);
/* Sets a body's centre-of-mass position (m) and angle (rad). */
lc_status lc_body_set_pose(lc_world *world, lc_body_id id, lc_vec2 center, double angle);
/* Sets a body's centre-of-mass velocity (m/s) and angular velocity (rad/s). */
lc_status lc_body_set_velocity(lc_world *world, lc_body_id id, lc_vec2 velocity, double angular_velocity);
/* Sets a dynamic body's mass (kg, > 0); the inertia scales with it. */
lc_status lc_body_set_mass(lc_world *world, lc_body_id id, double mass);
/* Sets a body's elasticity [0,1] and friction coefficient [0,10]. */
lc_status lc_body_set_material(lc_world *world, lc_body_id id, double elasticity, double friction);
/* Sets a constant external force (N, world frame, at the centre of mass) and torque (N*m). */
lc_status lc_body_set_external(lc_world *world, lc_body_id id, lc_vec2 force, double torque);
/* Number of vertices of a body. */
int lc_body_vertex_count(const lc_world *world, lc_body_id id);
/* Writes a body's vertices relative to its centre of mass, body frame (m), into out[capacity].
 * Like every getter on a const world, a failure still records its reason for lc_world_last_error(). */
lc_status lc_body_get_local_vertices(const lc_world *world, lc_body_id id, lc_vec2 *out, int capacity);
/* Writes a body's vertices in world coordinates (m) into out[capacity]. */
lc_status lc_body_get_world_vertices(const lc_world *world, lc_body_id id, lc_vec2 *out, int capacity);
/* Offset (m, body frame) from the body's local-frame origin to its centre of mass. */
lc_status lc_body_get_center_offset(const lc_world *world, lc_body_id id, lc_vec2 *out);

/* ---- thrusters -------------------------------------------------------------------------- */

/* Adds a thruster to a dynamic body; its index on that body goes to out_index (may be NULL). */
lc_status lc_body_add_thruster(lc_world *world, lc_body_id id, const lc_thruster_def *def, int *out_index);
/* Adds the seed's four keyboard thrusters sized for a w x h block (see docs): 0 = left (S/J),
 * 1 = right (F/L), 2 = up (E/I), 3 = down (D/K); side thrusters act above the centre and turn it. */
lc_status lc_body_add_default_thrusters(lc_world *world, lc_body_id id, double thrust, int *out_first_index);
/* Sets a thruster's level in [0, 1] (0 = off, 1 = full magnitude). */
lc_status lc_body_set_thruster_level(lc_world *world, lc_body_id id, int index, double level);
/* Sets every thruster of a body at once from a bit mask (bit i on = level 1, off = 0). */
lc_status lc_body_set_thruster_mask(lc_world *world, lc_body_id id, uint32_t mask);
/* Number of thrusters on a body (-1 for an unknown body). */
int lc_body_thruster_count(const lc_world *world, lc_body_id id);

/* ---- springs ------------------------------------------------------------------------------- */

/* Creates a spring; its id goes to out_id. */
lc_status lc_world_add_spring(lc_world *world, const lc_spring_def *def, lc_spring_id *out_id);
/* Removes a spring. */
lc_status lc_world_remove_spring(lc_world *world, lc_spring_id id);
/* Moves a world-anchored spring's target point (m, world); the mouse. */
lc_status lc_spring_set_target(lc_world *world, lc_spring_id id, lc_vec2 target);
/* Changes stiffness (N/m), damping (N*s/m) and rest length (m). */
lc_status lc_spring_set_params(lc_world *world, lc_spring_id id, double stiffness, double damping, double rest_length);
/* Reads a spring's definition back. */
lc_status lc_spring_get_def(const lc_world *world, lc_spring_id id, lc_spring_def *out);
/* World positions (m) of the spring's two ends. */
lc_status lc_spring_get_endpoints(const lc_world *world, lc_spring_id id, lc_vec2 *a, lc_vec2 *b);
/* Number of springs. */
int lc_world_spring_count(const lc_world *world);

/* ---- results ------------------------------------------------------------------------------ */

/* Contacts of the last step: its impacts and the resting contacts at its end. Valid until the next step. */
lc_status lc_world_get_contacts(const lc_world *world, const lc_contact **out, int *out_count);
/* Energy and momentum of the current state. */
lc_status lc_world_get_energy(const lc_world *world, lc_energy *out);
/* Measure wall time per pipeline stage into the counters' time_* fields (on = 1) or not (0, the default:
 * the clock reads cost ~2 x 25 ns per stage entry, ~5-15 % of a 20-block step). */
lc_status lc_world_set_stage_timing(lc_world *world, int on);
/* Counters of the last step (last may be NULL) and since creation (total may be NULL). */
lc_status lc_world_get_counters(const lc_world *world, lc_counters *last, lc_counters *total);
/* 64-bit FNV-1a hash of time and every body's state bits, for determinism checks. */
uint64_t lc_world_state_hash(const lc_world *world);

#ifdef __cplusplus
}
#endif

#endif /* COLLIDE_COLLIDE_H */
