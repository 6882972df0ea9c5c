/* test_end_touches.c - the touches the end-of-step projection found are reused by the next step's first
 * gather only while nothing has changed (event_touches.c, kept_end_touches). A stale reuse would hand the step
 * touches with the old materials or the old bodies; each case below would then fail its physics check.
 * g = 9.81, dt = 1/60 s, a 1 m x 0.5 m, 1 kg box resting on a static floor.
 *  - reuse happens (the event regime's, so that regime is set): in a resting scene each step runs one
 *    whole-world broadphase for its islands and one for its trial (brute_force_steps = 2); the
 *    projection's search takes the trial's pairs (broad_phase_kept.c), and the resting set
 *    at its start searches nothing: one candidate pair each for the islands, the trial and the
 *    projection (broadphase_pairs = 3, 4 without the reuse, whose search would find the pair again);
 *  - friction set after a step counts at once: a resting box with mu 0 -> 1 under a 2 N push stays
 *    put (static friction can give up to 9.81 N). With the old touches (mu 0) it would reach 2/60 m/s
 *    = 3.3e-2 m/s in the first step. Bound 1e-9 m/s: the small groups' force tolerance is 9e-11
 *    m/s^2 (contact_forces.c), 1.5e-12 m/s over a step. This also checks the friction alternation's
 *    extrapolation (solve_with_friction): when the push begins, each round of normal and friction
 *    solves cuts the change only by ~0.375, and the 8 rounds without it left the box slipping
 *    5.4e-7 m/s in the first step;
 *  - a body removed and another added (same row count, same row) after a step: the new box, mid-air
 *    at rest, falls freely in its first step: y = y0 - g dt^2/2 exactly up to round-off (RK4 is exact
 *    for constant acceleration; 1e-12 m). The old box's floor touches on its row would hold it up;
 *  - a pose set after a step: the box lifted 1 m falls freely, as above. */
#include "check.h"
#include "scenes.h"

#define G 9.81
#define DT (1.0 / 60.0)

static lc_vec2 v2(double x, double y)
{
    lc_vec2 r;
    r.x = x;
    r.y = y;
    return r;
}

static lc_world *resting_box(lc_body_id *box, lc_regime regime)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    d.gravity = v2(0.0, -G);
    d.regime = regime;
    w = sc_world(&d);
    if (!w) return NULL;
    /* the floor has friction 1, the box 0: the pair's is their geometric mean, 0 until the box's is set */
    CHECK(lc_body_set_material(w, sc_static_box(w, 20.0, 1.0, 0.0, -0.5, 0.0), 0.0, 1.0) == LC_OK, "%s",
          lc_world_last_error(w));
    *box = sc_box(w, 1.0, 0.5, 0.0, 0.25, 0.0, 0, 0, 0, 1.0, 0.0);
    sc_step_n(w, DT, 30);   /* settled: the faces held at the contact gap */
    return w;
}

static void reuse_happens(void)
{
    lc_body_id box;
    lc_world *w = resting_box(&box, LC_REGIME_EVENT);
    lc_counters last;
    if (!w) return;
    sc_step_n(w, DT, 1);
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.brute_force_steps == 2,
          "a resting step ran %llu whole-world broadphases (2 expected: islands, trial)",
          (unsigned long long)last.brute_force_steps);
    CHECK(last.broadphase_pairs == 3,
          "a resting step's searches found %llu candidate pairs (3 expected: islands, trial, projection)",
          (unsigned long long)last.broadphase_pairs);
    CHECK(last.collisions == 0 && last.contact_solves > 0, "%s", "the box rests on the floor");
    lc_world_destroy(w);
}

static void friction_counts_at_once(void)
{
    lc_body_id box;
    lc_world *w = resting_box(&box, LC_REGIME_AUTO);
    lc_vec2 push = {2.0, 0.0};
    if (!w) return;
    CHECK(lc_body_set_material(w, box, 0.0, 1.0) == LC_OK, "%s", lc_world_last_error(w));
    CHECK(lc_body_set_external(w, box, push, 0.0) == LC_OK, "%s", lc_world_last_error(w));
    sc_step_n(w, DT, 1);
    CHECK_NEAR(sc_row(w, box)[3], 0.0, 1e-9, "vx of a box that static friction holds");
    sc_step_n(w, DT, 10);
    CHECK_NEAR(sc_row(w, box)[3], 0.0, 1e-9, "vx after 10 more steps");
    lc_world_destroy(w);
}

static void free_fall_step(lc_world *w, lc_body_id id, const char *what)
{
    double y0 = sc_row(w, id)[1];
    sc_step_n(w, DT, 1);
    CHECK_NEAR(sc_row(w, id)[1], y0 - 0.5 * G * DT * DT, 1e-12, what);
    CHECK_NEAR(sc_row(w, id)[4], -G * DT, 1e-12, what);
}

static void new_body_in_the_row(void)
{
    lc_body_id box, other;
    lc_world *w = resting_box(&box, LC_REGIME_AUTO);
    if (!w) return;
    CHECK(lc_world_remove_body(w, box) == LC_OK, "%s", lc_world_last_error(w));
    other = sc_box(w, 1.0, 0.5, 3.0, 5.0, 0.0, 0, 0, 0, 1.0, 0.0);
    CHECK(lc_world_body_index(w, other) == 1, "%s", "the new box takes the removed box's row");
    free_fall_step(w, other, "a new box mid-air falls freely");
    lc_world_destroy(w);
}

static void pose_set_after_a_step(void)
{
    lc_body_id box;
    lc_world *w = resting_box(&box, LC_REGIME_AUTO);
    lc_vec2 up = {0.0, 1.25};
    if (!w) return;
    CHECK(lc_body_set_pose(w, box, up, 0.0) == LC_OK, "%s", lc_world_last_error(w));
    CHECK(lc_body_set_velocity(w, box, v2(0.0, 0.0), 0.0) == LC_OK, "%s", lc_world_last_error(w));
    free_fall_step(w, box, "a lifted box falls freely");
    lc_world_destroy(w);
}

int main(void)
{
    reuse_happens();
    friction_counts_at_once();
    new_body_in_the_row();
    pose_set_after_a_step();
    return CHECK_SUMMARY("test_end_touches");
}
