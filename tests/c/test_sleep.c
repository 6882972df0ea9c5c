/* test_sleep: islands at rest stop being advanced (lc_world_def.allow_sleep, sleep.h), and anything that
 * reaches them wakes them. dt = 1/60 s, g = 9.81, a static ground 60 m x 1 m with its top at y = 0, a
 * base-10 frictional pyramid (55 boxes of 1 m, 1 kg, e 0, mu 0.5: sc_pyramid).
 *  (1) the pyramid, built at rest, falls asleep within sleep_time plus a few steps (all 55 bodies);
 *      asleep, a step advances no island (contact_islands 0, no contact sweep), the bodies do not move
 *      at all over 2 s (their states are bit-for-bit the same), their velocities are exactly 0, and the
 *      step still reports their resting contacts: the ground's forces carry the 55 boxes' weight to 1e-9
 *      relative (the contact regime's tolerance on ~1e3 N);
 *  (2) a 5 kg box dropped onto it from 8 m above its top (in flight while the pyramid sleeps) wakes it
 *      when its swept bounds reach the pyramid (islands_woken > 0, every body awake in that step), the
 *      impact is resolved (no overlap over 1e-9 m at any step end, the allowance of the contact
 *      regime's projection) and everything comes to rest and sleeps again;
 *  (3) an API change wakes everything: a velocity set on one sleeping box leaves no body asleep after
 *      the next step;
 *  (4) a body whose thruster fires never sleeps;
 *  (5) a world that never rests takes the same steps with sleep on and off (state hashes equal after
 *      600 steps of six blocks flying at e = 1 without gravity), and a pile settling takes the same
 *      steps until the first body falls asleep. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "scenes.h"

#define DT (1.0 / 60.0)
#define BASE 10
#define NBOX (BASE * (BASE + 1) / 2)

static lc_vec2 vec(double x, double y)
{
    lc_vec2 v;
    v.x = x;
    v.y = y;
    return v;
}

static lc_world *pyramid_world(int sleep, lc_body_id *ids, lc_body_id *ground)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    d.allow_sleep = sleep;
    w = sc_world(&d);
    if (!w) return NULL;
    *ground = sc_static_box(w, 60.0, 1.0, 0.0, -0.5, 0.0);
    lc_body_set_material(w, *ground, 0.0, 0.5);
    sc_pyramid(w, BASE, 0.5, ids);
    return w;
}

static double ground_force(const lc_world *w, lc_body_id ground)
{
    const lc_contact *cs;
    int n = sc_contacts(w, &cs), i;
    double f = 0.0;
    for (i = 0; i < n; ++i)
        if (cs[i].kind == LC_CONTACT_RESTING && (cs[i].body_a == ground || cs[i].body_b == ground))
            f += cs[i].force * fabs(cs[i].normal.y);
    return f;
}

/* the deepest overlap among the pyramid's boxes and between them and the dropped box */
static double worst_overlap(const lc_world *w, const lc_body_id *ids, int n, lc_body_id extra)
{
    double worst = 0.0;
    int i, j;
    for (i = 0; i < n; ++i) {
        for (j = i + 1; j < n; ++j) worst = fmax(worst, -sc_separation(w, ids[i], ids[j]));
        worst = fmax(worst, -sc_separation(w, ids[i], extra));
    }
    return worst;
}

static void pyramid_sleeps_and_wakes(void)
{
    lc_body_id ids[NBOX], box, ground;
    lc_counters last;
    lc_world *w = pyramid_world(1, ids, &ground);
    double before[NBOX * 6], overlap = 0.0, v = 0.0;
    int i, k, asleep_at = -1, woken_at = -1, all_awake_when_woken = 0, asleep_again = -1;
    lc_body_def bd = lc_default_body_def();
    lc_vec2 verts[4];
    if (!w) return;
    /* the box above, falling from rest: it lands ~1.3 s in, after the pyramid fell asleep */
    lc_make_rectangle(1.0, 1.0, verts);
    bd.vertices = verts;
    bd.vertex_count = 4;
    bd.position.x = 0.3;
    bd.position.y = BASE + 8.5;
    bd.mass = 5.0;
    bd.elasticity = 0.0;
    bd.friction = 0.5;
    box = sc_add(w, &bd, "falling box");
    for (k = 0; k < 600; ++k) {
        if (lc_world_step(w, DT) != LC_OK) break;
        lc_world_get_counters(w, &last, NULL);
        if (asleep_at < 0 && last.bodies_asleep == NBOX) {
            asleep_at = k;
            CHECK(ground_force(w, ground) > 0.0, "a sleeping pyramid's contacts are reported");
            for (i = 0; i < NBOX; ++i) memcpy(&before[i * 6], sc_row(w, ids[i]), 6 * sizeof(double));
        }
        if (asleep_at >= 0 && woken_at < 0 && k > asleep_at && last.islands_woken == 0) {
            /* asleep and not reached yet: nothing of the pyramid moves or is advanced */
            int same = 1;
            for (i = 0; i < NBOX; ++i) same &= memcmp(&before[i * 6], sc_row(w, ids[i]), 6 * sizeof(double)) == 0;
            CHECK(same, "step %d: a sleeping body's state does not change", k);
            CHECK(last.contact_sweeps == 0, "step %d: no island of the sleeping pyramid is solved (%llu sweeps)", k,
                  (unsigned long long)last.contact_sweeps);
        }
        if (woken_at < 0 && last.islands_woken > 0) {
            woken_at = k;
            all_awake_when_woken = last.bodies_asleep == 0;
        }
        if (woken_at >= 0) overlap = fmax(overlap, worst_overlap(w, ids, NBOX, box));
        if (woken_at >= 0 && asleep_again < 0 && last.bodies_asleep == NBOX + 1) asleep_again = k;
    }
    printf("pyramid: asleep at step %d, woken at %d (all awake: %d), deepest overlap after %.3g m, asleep again at %d\n",
           asleep_at, woken_at, all_awake_when_woken, overlap, asleep_again);
    CHECK(k == 600, "600 steps taken (%d)", k);
    CHECK(asleep_at >= 0 && asleep_at <= (int)(0.5 / DT) + 30, "the pyramid falls asleep within 0.5 s + 30 steps (step %d)",
          asleep_at);
    for (i = 0; i < NBOX && asleep_at >= 0; ++i) v = fmax(v, fabs(before[i * 6 + 3]) + fabs(before[i * 6 + 4]) + fabs(before[i * 6 + 5]));
    CHECK(v == 0.0, "asleep, the velocities are exactly 0 (%.3g)", v);
    CHECK(woken_at > asleep_at + 30, "the falling box wakes the pyramid when it arrives (step %d, asleep at %d)", woken_at,
          asleep_at);
    CHECK(all_awake_when_woken, "every body of the pyramid wakes with its island");
    /* the woken pyramid and the box are one island of 56 bodies: its sub-steps are pile sub-steps,
     * projected to 1e-7 m and allowed 2.5e-7 m at a step's end (contact_regime.md) */
    CHECK(overlap <= 2.5e-7, "no overlap deeper than 2.5e-7 m from the wake on (%.3g m)", overlap);
    CHECK(asleep_again > woken_at, "everything comes to rest and sleeps again (step %d)", asleep_again);
    lc_world_destroy(w);
}

static void rest_reports_weight(void)
{
    lc_body_id ids[NBOX], ground;
    lc_counters last;
    lc_world *w = pyramid_world(1, ids, &ground);
    int k;
    if (!w) return;
    for (k = 0; k < 120; ++k) sc_step_n(w, DT, 1);
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.bodies_asleep == NBOX && last.contact_islands == 0, "asleep after 2 s: %llu bodies asleep, %llu contact islands",
          (unsigned long long)last.bodies_asleep, (unsigned long long)last.contact_islands);
    CHECK_REL(ground_force(w, ground), NBOX * 9.81, 1e-9, "the ground carries the sleeping pyramid");
    /* (3) an API change wakes everything */
    lc_body_set_velocity(w, ids[NBOX - 1], vec(0.0, 0.0), 0.0);
    sc_step_n(w, DT, 1);
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.bodies_asleep == 0 && last.contact_islands > 0, "after set_velocity every body is awake (%llu asleep)",
          (unsigned long long)last.bodies_asleep);
    lc_world_destroy(w);
}

static void thrusting_never_sleeps(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id b;
    lc_counters last;
    int first;
    d.allow_sleep = 1;
    w = sc_world(&d);
    if (!w) return;
    lc_body_set_material(w, sc_static_box(w, 60.0, 1.0, 0.0, -0.5, 0.0), 0.0, 0.9);
    b = sc_box(w, 1.0, 0.5, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    lc_body_set_material(w, b, 0.0, 0.9);
    /* a small sideways thrust that static friction holds: the body is at rest but driven */
    lc_body_add_default_thrusters(w, b, 1.0, &first);
    lc_body_set_thruster_level(w, b, first, 1.0);
    sc_step_n(w, DT, 120);
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.bodies_asleep == 0, "a body whose thruster fires does not sleep (%llu asleep)",
          (unsigned long long)last.bodies_asleep);
    lc_world_destroy(w);
}

static void same_steps_without_rest(void)
{
    lc_world *w[2];
    int s, i;
    uint64_t h[2];
    for (s = 0; s < 2; ++s) {
        lc_world_def d = sc_def_zero_g();
        d.allow_sleep = s;
        w[s] = sc_world(&d);
        if (!w[s]) return;
        lc_world_add_walls(w[s], -5.0, -5.0, 5.0, 5.0, 1.0, 1.0, NULL);
        for (i = 0; i < 6; ++i)
            sc_box(w[s], 1.0, 0.5, -3.0 + 1.2 * i, 0.3 * i - 1.0, 0.2 * i, 1.0 + 0.3 * i, -0.7 + 0.2 * i, 0.5 - 0.1 * i, 1.0,
                   1.0);
        sc_step_n(w[s], DT, 600);
        h[s] = lc_world_state_hash(w[s]);
    }
    CHECK(h[0] == h[1], "six blocks flying at e = 1: the same state with sleep off and on (%016llx, %016llx)",
          (unsigned long long)h[0], (unsigned long long)h[1]);
    lc_world_destroy(w[0]);
    lc_world_destroy(w[1]);
    /* a settling pile: the same steps until a body falls asleep */
    {
        lc_body_id ids[NBOX], ground;
        lc_world *p[2];
        lc_counters last;
        int k, equal = 1, slept = -1;
        for (s = 0; s < 2; ++s) {
            p[s] = pyramid_world(s, ids, &ground);
            if (!p[s]) return;
            lc_body_set_velocity(p[s], ids[NBOX - 1], vec(0.5, 0.0), 1.0);
        }
        for (k = 0; k < 300 && slept < 0; ++k) {
            sc_step_n(p[0], DT, 1);
            sc_step_n(p[1], DT, 1);
            lc_world_get_counters(p[1], &last, NULL);
            if (last.bodies_asleep > 0) slept = k;
            else equal &= lc_world_state_hash(p[0]) == lc_world_state_hash(p[1]);
        }
        CHECK(slept > 0 && equal, "a settling pyramid: the same states with sleep off and on until step %d", slept);
        lc_world_destroy(p[0]);
        lc_world_destroy(p[1]);
    }
}

int main(void)
{
    pyramid_sleeps_and_wakes();
    rest_reports_weight();
    thrusting_never_sleeps();
    same_steps_without_rest();
    return CHECK_SUMMARY("test_sleep");
}
