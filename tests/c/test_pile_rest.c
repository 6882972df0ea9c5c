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
 *  (3) the same row without the force: no coordinate moves, no velocity is left. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "scenes.h"

#define PILE_BOXES 40
#define ROW_BOXES 20

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

static void pile_comes_to_rest(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id ids[PILE_BOXES];
    double rest_start[PILE_BOXES * 6], now[PILE_BOXES * 6], e_prev, worst_gain = -INFINITY, deepest = 0.0;
    sc_rng rng = {7};
    const double dt = 1.0 / 60.0, seconds = 15.0;
    int i, j, k, steps = (int)(seconds / dt + 0.5), rest_from = steps - 120, moved = 0, moving = 0;
    lc_counters last;
    d.gravity.y = -9.81;
    w = sc_world(&d);
    if (!w) return;
    walls(w, 2.0, 0.5);
    for (i = 0; i < PILE_BOXES; ++i) {
        double bw = sc_uniform(&rng, 0.3, 0.8), bh = sc_uniform(&rng, 0.3, 0.8);
        double x = sc_uniform(&rng, -1.5, 1.5), y = 1.0 + 0.15 * i, a = sc_uniform(&rng, 0.0, SC_PI);
        ids[i] = sc_box(w, bw, bh, x, y, a, 0.0, 0.0, 0.0, bw * bh * 4.0, 0.3);
        CHECK(lc_body_set_material(w, ids[i], 0.3, 0.5) == LC_OK, "%s", "box material");
    }
    e_prev = sc_energy(w).total;
    for (k = 0; k < steps; ++k) {
        double e;
        if (sc_step_n(w, dt, 1) != 1) break;
        e = sc_energy(w).total;
        worst_gain = fmax(worst_gain, (e - e_prev) / fabs(e_prev));
        e_prev = e;
        for (i = 0; i < PILE_BOXES; ++i)
            for (j = i + 1; j < PILE_BOXES; ++j) deepest = fmax(deepest, -sc_separation(w, ids[i], ids[j]));
        if (k + 1 == rest_from) pile_state(w, ids, PILE_BOXES, rest_start);
        if (k + 1 > rest_from) {
            pile_state(w, ids, PILE_BOXES, now);
            for (i = 0; i < PILE_BOXES; ++i) {
                for (j = 0; j < 3; ++j) moved += now[i * 6 + j] != rest_start[i * 6 + j];
                for (j = 3; j < 6; ++j) moving += now[i * 6 + j] != 0.0;
            }
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

int main(void)
{
    pile_comes_to_rest();
    driven_row_is_never_held();
    undriven_row_stays();
    return CHECK_SUMMARY("test_pile_rest");
}
