/* test_pile_rest: a settling pile comes to rest, and rest never holds what a force drives
 * (docs/contact_regime.md, "Settling and rest"; tunables.h LC_CONTACT_SETTLE_SPEED, LC_CONTACT_REST_SPEED).
 * Scenes:
 *  (1) 40 boxes of 0.3-0.8 m (fixed-seed sizes, angles and places), mu 0.5, e 0.3, dropped from up to
 *      6 m into a walled box 4 m wide, g = 9.81, dt 1/60, 15 s: the contact bench's mixed piles
 *      (bench/scenes.py mixed_boxes) at a size that runs in a second. Asserted at every step: LC_OK,
 *      no pair overlapping by more than 1e-6 m (the contact scenes' bound), no step gaining more than
 *      1e-9 of the total energy (nothing drives the scene). At the end: the pile rests -- over the last
 *      2 s every body's velocity is exactly 0 and no coordinate changed by a single bit, and the last
 *      step counted islands held at rest (lc_counters contact_rests).
 *  (2) a row of 20 unit boxes side by side on a frictionless floor, at rest, pushed at one end by an
 *      external force that accelerates the row at 1e-4 m/s^2: each step adds 1.7e-6 m/s, below the rest
 *      speed, so holding a driven island at rest would keep it still. Asserted: after 10 s (n = 600
 *      steps) the row has moved a t^2 / 2 = 5 mm within 2e-3 relative: the integrators' own error under
 *      a constant force is at most x += h v's a h^2 n (n + 1) / 2, (n + 1) / n - 1 = 1.7e-3 above the
 *      closed form; a row held still moves 0.
 *  (3) the same row without the force: no coordinate moves, no velocity is left.
 *  (4) the pile of (1) once still (kept_touches.h: it rested through a step at one state): its islands
 *      are not solved (no sweep in a step) and report the same resting contacts with the same forces
 *      step after step; a snapshot of it loads into a world that goes on bit for bit, still unsolved.
 *  (5) the still pile of (4) under gravity turned 20 degrees (a setting, no body touched): solved in the
 *      next step, and it moves.
 *  (6) the same pile with one more box, sliding along a frictionless shelf 9 m up from the start and
 *      falling off its end onto the pile after the pile is still (at ~15 s, ~11 m/s): nothing but the
 *      impact reaches the pile, no API call. Asserted: the impact wakes it (its bodies move and its
 *      islands are solved again), with LC_OK, no overlap above 1e-6 m and no step gaining more than
 *      1e-9 of the energy, as in (1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scenes.h"

#define PILE_BOXES 40
#define ROW_BOXES 20
/* m/s, the slide of scene (5)'s box: from x = -1.7 it leaves the shelf's end (x = -0.5) after ~12 s */
#define SHELF_SPEED 0.1

static void walls(lc_world *w, double half_width, double mu)
{
    lc_body_id id[3];
    int k;
    id[0] = sc_static_box(w, 2.0 * half_width + 2.0, 1.0, 0.0, -0.5, 0.0);
    id[1] = sc_static_box(w, 1.0, 30.0, -half_width - 0.5, 15.0, 0.0);
    id[2] = sc_static_box(w, 1.0, 30.0, half_width + 0.5, 15.0, 0.0);
    for (k = 0; k < 3; ++k) CHECK(lc_body_set_material(w, id[k], 0.3, mu) == LC_OK, "%s", "wall material");
}

/* The pile's state: every body's row (6 doubles) into s. */
static void pile_state(const lc_world *w, const lc_body_id *ids, int n, double *s)
{
    int i;
    for (i = 0; i < n; ++i) memcpy(&s[i * 6], sc_row(w, ids[i]), 6 * sizeof(double));
}

/* The pile of scene (1) in a new world, its boxes' ids into ids; with shelf, scene (5)'s shelf and the
 * box sliding on it (its id in ids[PILE_BOXES]). NULL if the world could not be made. */
static lc_world *pile_scene(lc_body_id *ids, int shelf)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    sc_rng rng = {7};
    int i;
    d.gravity.y = -9.81;
    w = sc_world(&d);
    if (!w) return NULL;
    walls(w, 2.0, 0.5);
    for (i = 0; i < PILE_BOXES; ++i) {
        double bw = sc_uniform(&rng, 0.3, 0.8), bh = sc_uniform(&rng, 0.3, 0.8);
        double x = sc_uniform(&rng, -1.5, 1.5), y = 1.0 + 0.15 * i, a = sc_uniform(&rng, 0.0, SC_PI);
        ids[i] = sc_box(w, bw, bh, x, y, a, 0.0, 0.0, 0.0, bw * bh * 4.0, 0.3);
        CHECK(lc_body_set_material(w, ids[i], 0.3, 0.5) == LC_OK, "%s", "box material");
    }
    if (shelf) {
        lc_body_id id = sc_static_box(w, 1.5, 0.2, -1.25, 8.9, 0.0);
        CHECK(lc_body_set_material(w, id, 0.0, 0.0) == LC_OK, "%s", "shelf material");
        ids[PILE_BOXES] = sc_box(w, 0.5, 0.5, -1.7, 9.25, 0.0, SHELF_SPEED, 0.0, 0.0, 1.0, 0.0);
        CHECK(lc_body_set_material(w, ids[PILE_BOXES], 0.3, 0.5) == LC_OK, "%s", "sliding box material");
    }
    return w;
}

/* Steps w n times at dt; asserts every step's status, energy gain (<= 1e-9 of the total) and deepest
 * overlap among ids[0..nids) (<= 1e-6 m), into *worst_gain and *deepest. Returns the steps taken. */
static int checked_steps(lc_world *w, const lc_body_id *ids, int nids, double dt, int n, double *worst_gain,
                         double *deepest)
{
    double e_prev = sc_energy(w).total;
    int i, j, k;
    for (k = 0; k < n; ++k) {
        double e;
        if (sc_step_n(w, dt, 1) != 1) break;
        e = sc_energy(w).total;
        *worst_gain = fmax(*worst_gain, (e - e_prev) / fabs(e_prev));
        e_prev = e;
        for (i = 0; i < nids; ++i)
            for (j = i + 1; j < nids; ++j) *deepest = fmax(*deepest, -sc_separation(w, ids[i], ids[j]));
    }
    return k;
}

static void pile_comes_to_rest(void)
{
    lc_world *w;
    lc_body_id ids[PILE_BOXES];
    double rest_start[PILE_BOXES * 6], now[PILE_BOXES * 6], worst_gain = -INFINITY, deepest = 0.0;
    const double dt = 1.0 / 60.0, seconds = 15.0;
    int i, j, k, steps = (int)(seconds / dt + 0.5), rest_from = steps - 120, moved = 0, moving = 0;
    lc_counters last;
    w = pile_scene(ids, 0);
    if (!w) return;
    k = checked_steps(w, ids, PILE_BOXES, dt, rest_from, &worst_gain, &deepest);
    pile_state(w, ids, PILE_BOXES, rest_start);
    for (; k < steps; ++k) {
        if (checked_steps(w, ids, PILE_BOXES, dt, 1, &worst_gain, &deepest) != 1) break;
        pile_state(w, ids, PILE_BOXES, now);
        for (i = 0; i < PILE_BOXES; ++i) {
            for (j = 0; j < 3; ++j) moved += now[i * 6 + j] != rest_start[i * 6 + j];
            for (j = 3; j < 6; ++j) moving += now[i * 6 + j] != 0.0;
        }
    }
    CHECK(k == steps, "the pile ran its %d steps (%d)", steps, k);
    CHECK(worst_gain <= 1e-9, "no step gained more than 1e-9 of the energy (worst %.3g)", worst_gain);
    CHECK(deepest <= 1e-6, "no pair overlapped by more than 1e-6 m (deepest %.3g m)", deepest);
    CHECK(moved == 0, "over the last 2 s no coordinate of the pile changed (%d changes)", moved);
    CHECK(moving == 0, "over the last 2 s every velocity was exactly 0 (%d nonzero values)", moving);
    CHECK(lc_world_get_counters(w, &last, NULL) == LC_OK, "%s", "counters");
    CHECK(last.contact_rests > 0, "the last step held islands at rest (%llu)", (unsigned long long)last.contact_rests);
    printf("pile of %d boxes: worst step gain %.3g, deepest overlap %.3g m, islands held at rest in the last step "
           "%llu\n", PILE_BOXES, worst_gain, deepest, (unsigned long long)last.contact_rests);
    lc_world_destroy(w);
}

/* A row of ROW_BOXES unit boxes side by side on a frictionless floor, ids into ids. */
static lc_world *row_scene(lc_body_id *ids)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    int i;
    d.gravity.y = -9.81;
    d.damping = 0.0;
    w = sc_world(&d);
    if (!w) return NULL;
    walls(w, 40.0, 0.0);
    for (i = 0; i < ROW_BOXES; ++i) ids[i] = sc_box(w, 1.0, 1.0, -10.0 + i * 1.0, 0.5, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    return w;
}

static void driven_row_is_never_held(void)
{
    lc_body_id ids[ROW_BOXES];
    lc_world *w = row_scene(ids);
    const double dt = 1.0 / 60.0, a = 1e-4;
    double x0, x1, n = 600.0, closed, discrete;
    lc_vec2 f;
    if (!w) return;
    x0 = sc_row(w, ids[0])[0];
    f.x = a * ROW_BOXES;
    f.y = 0.0;
    CHECK(lc_body_set_external(w, ids[0], f, 0.0) == LC_OK, "%s", "external force");
    CHECK(sc_step_n(w, dt, (int)n) == (int)n, "%s", "the driven row's 10 s");
    x1 = sc_row(w, ids[0])[0];
    closed = 0.5 * a * (n * dt) * (n * dt);
    discrete = a * dt * dt * n * (n + 1.0) / 2.0;
    CHECK(fabs((x1 - x0) - closed) <= 2e-3 * closed, "the pushed row moved %.9g m, a t^2 / 2 = %.9g m", x1 - x0, closed);
    printf("row pushed at %g m/s^2: moved %.9g m in 10 s (a t^2 / 2 = %.9g, x += h v: %.9g)\n", a, x1 - x0, closed,
           discrete);
    lc_world_destroy(w);
}

static void undriven_row_stays(void)
{
    lc_body_id ids[ROW_BOXES];
    lc_world *w = row_scene(ids);
    double start[ROW_BOXES * 6], now[ROW_BOXES * 6];
    int i, changed = 0;
    if (!w) return;
    pile_state(w, ids, ROW_BOXES, start);
    CHECK(sc_step_n(w, 1.0 / 60.0, 600) == 600, "%s", "the row's 10 s");
    pile_state(w, ids, ROW_BOXES, now);
    for (i = 0; i < ROW_BOXES * 6; ++i) changed += now[i] != start[i];
    CHECK(changed == 0, "the resting row kept every coordinate and velocity (%d changed)", changed);
    lc_world_destroy(w);
}

/* Whether two contact lists are the same, field for field but the reading's time. */
static int same_contacts(const lc_contact *a, int na, const lc_contact *b, int nb)
{
    int i;
    if (na != nb) return 0;
    for (i = 0; i < na; ++i) {
        lc_contact x = a[i], y = b[i];
        x.time = y.time = 0.0;
        if (memcmp(&x, &y, sizeof x) != 0) return 0;
    }
    return 1;
}

static void still_pile_is_not_solved(void)
{
    lc_body_id ids[PILE_BOXES];
    lc_world *w = pile_scene(ids, 0), *copy;
    const lc_contact *cs;
    lc_contact *before = NULL;
    lc_counters last;
    unsigned char *buf = NULL;
    size_t size = 0;
    char err[256];
    int k, n, nbefore = 0, still_from = -1, unsolved = 0, same = 0;
    if (!w) return;
    /* 15 s: the first step with rests and no sweep is the first still one */
    for (k = 0; k < 900 && sc_step_n(w, 1.0 / 60.0, 1) == 1; ++k) {
        lc_world_get_counters(w, &last, NULL);
        if (still_from < 0 && last.contact_rests > 0 && last.contact_sweeps == 0) still_from = k + 1;
    }
    CHECK(still_from > 0, "the pile was still before 15 s (from step %d)", still_from);
    n = sc_contacts(w, &cs);
    before = malloc((size_t)(n > 0 ? n : 1) * sizeof *before);
    if (!CHECK(before != NULL, "%s", "memory for the contacts")) {
        lc_world_destroy(w);
        return;
    }
    memcpy(before, cs, (size_t)n * sizeof *cs);
    nbefore = n;
    for (k = 0; k < 60 && sc_step_n(w, 1.0 / 60.0, 1) == 1; ++k) {
        lc_world_get_counters(w, &last, NULL);
        unsolved += last.contact_sweeps == 0 && last.contact_rests > 0;
        n = sc_contacts(w, &cs);
        same += same_contacts(before, nbefore, cs, n);
    }
    CHECK(unsolved == 60, "the still pile was not solved in %d of 60 steps", unsolved);
    CHECK(same == 60 && nbefore > 0, "it reported its %d resting contacts unchanged in %d of 60 steps", nbefore, same);
    /* a snapshot of the still pile goes on bit for bit, still */
    lc_world_save(w, NULL, 0, &size);
    buf = size > 0 ? malloc(size) : NULL;
    if (CHECK(buf != NULL && lc_world_save(w, buf, size, &size) == LC_OK, "the still pile saved (%zu bytes)", size)) {
        copy = lc_world_create_from_snapshot(buf, size, err, sizeof err);
        CHECK(copy != NULL, "the still pile's snapshot loads: %s", copy ? "" : err);
        if (copy) {
            int steps_same = 0;
            for (k = 0; k < 30; ++k) {
                sc_step_n(w, 1.0 / 60.0, 1);
                sc_step_n(copy, 1.0 / 60.0, 1);
                lc_world_get_counters(copy, &last, NULL);
                steps_same += lc_world_state_hash(w) == lc_world_state_hash(copy) && last.contact_sweeps == 0;
            }
            CHECK(steps_same == 30, "the loaded copy went on bit for bit, unsolved, in %d of 30 steps", steps_same);
            lc_world_destroy(copy);
        }
    }
    printf("pile of %d boxes still from step %d (%.2f s): %d resting contacts reported unchanged, not solved\n",
           PILE_BOXES, still_from, still_from / 60.0, nbefore);
    free(buf);
    free(before);
    lc_world_destroy(w);
}

/* A setting changes the problem without touching a body: gravity turned 20 degrees off the vertical
 * makes the still pile lean on its walls and friction, and it is solved again in the next step. */
static void setting_wakes_still_pile(void)
{
    lc_body_id ids[PILE_BOXES];
    lc_world *w = pile_scene(ids, 0);
    lc_counters last;
    lc_vec2 g;
    double before[PILE_BOXES * 6], now[PILE_BOXES * 6];
    int i, moved = 0;
    if (!w) return;
    CHECK(sc_step_n(w, 1.0 / 60.0, 900) == 900, "%s", "the pile's 15 s");
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.contact_sweeps == 0 && last.contact_rests > 0, "the pile was still after 15 s (%llu sweeps)",
          (unsigned long long)last.contact_sweeps);
    pile_state(w, ids, PILE_BOXES, before);
    g.x = 9.81 * sin(20.0 * SC_PI / 180.0);
    g.y = -9.81 * cos(20.0 * SC_PI / 180.0);
    CHECK(lc_world_set_gravity(w, g) == LC_OK, "%s", "gravity turned");
    CHECK(sc_step_n(w, 1.0 / 60.0, 1) == 1, "%s", "a step under the turned gravity");
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.contact_sweeps > 0, "the pile was solved again in the step after the setting (%llu sweeps)",
          (unsigned long long)last.contact_sweeps);
    CHECK(sc_step_n(w, 1.0 / 60.0, 59) == 59, "%s", "a second under the turned gravity");
    pile_state(w, ids, PILE_BOXES, now);
    for (i = 0; i < PILE_BOXES * 6; ++i) moved += now[i] != before[i];
    CHECK(moved > 0, "the pile moved under the turned gravity (%d numbers changed)", moved);
    lc_world_destroy(w);
}

static void impact_wakes_still_pile(void)
{
    lc_body_id ids[PILE_BOXES + 1];
    lc_world *w = pile_scene(ids, 1);
    lc_counters last;
    double worst_gain = -INFINITY, deepest = 0.0, still_state[PILE_BOXES * 6], now[PILE_BOXES * 6];
    int k, i, still = 0, moved = 0, solved_after = 0;
    if (!w) return;
    pile_state(w, ids, PILE_BOXES, still_state);
    /* until the box leaves the shelf: the pile still by then (the box's own island is solved while it
     * slides, so the pile's stillness shows in its bits: unchanged over the last second, at rest) */
    for (k = 0; k < 900 && sc_row(w, ids[PILE_BOXES])[0] < -0.5; ++k) {
        if (checked_steps(w, ids, PILE_BOXES + 1, 1.0 / 60.0, 1, &worst_gain, &deepest) != 1) break;
        lc_world_get_counters(w, &last, NULL);
        pile_state(w, ids, PILE_BOXES, now);
        still = memcmp(now, still_state, sizeof now) == 0 && last.contact_rests > 0 ? still + 1 : 0;
        memcpy(still_state, now, sizeof now);
    }
    CHECK(still >= 60, "the pile was still over the second before the box left the shelf at step %d (%d steps)", k,
          still);
    for (k = 0; k < 120; ++k) {
        if (checked_steps(w, ids, PILE_BOXES + 1, 1.0 / 60.0, 1, &worst_gain, &deepest) != 1) break;
        lc_world_get_counters(w, &last, NULL);
        solved_after += last.contact_sweeps > 0;
    }
    pile_state(w, ids, PILE_BOXES, now);
    for (i = 0; i < PILE_BOXES * 6; ++i) moved += now[i] != still_state[i];
    CHECK(k == 120, "the 2 s after the fall ran (%d steps)", k);
    CHECK(moved > 0 && solved_after > 0, "the impact woke the pile: %d of its numbers changed, solved in %d steps",
          moved, solved_after);
    CHECK(sc_row(w, ids[PILE_BOXES])[1] < 8.0, "the box fell off the shelf (y %.3g m)", sc_row(w, ids[PILE_BOXES])[1]);
    CHECK(worst_gain <= 1e-9, "no step gained more than 1e-9 of the energy (worst %.3g)", worst_gain);
    CHECK(deepest <= 1e-6, "no pair overlapped by more than 1e-6 m (deepest %.3g m)", deepest);
    printf("box off the shelf onto the still pile: %d pile numbers changed, solved in %d of 120 steps, worst gain "
           "%.3g, deepest overlap %.3g m\n", moved, solved_after, worst_gain, deepest);
    lc_world_destroy(w);
}

int main(void)
{
    pile_comes_to_rest();
    driven_row_is_never_held();
    undriven_row_stays();
    still_pile_is_not_solved();
    setting_wakes_still_pile();
    impact_wakes_still_pile();
    return CHECK_SUMMARY("test_pile_rest");
}
