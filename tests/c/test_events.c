/* test_events: the impact event stream (lc_world_get_events) reports every collision of every step
 * taken exactly once, with the numbers of the step's LC_CONTACT_COLLISION contacts, however many steps
 * pass between two reads; past lc_world_def.event_capacity the oldest go and are counted exactly; an
 * undone step reports nothing; bad arguments are refused and change nothing; two runs report the same
 * events. The reference is the step's own contacts, polled after every step (lc_world_get_contacts):
 * equality is exact, the two are the same numbers. */
#include <stdlib.h>
#include "check.h"
#include "scenes.h"

/* A growable list of events. */
typedef struct evlist {
    lc_impact_event *e;
    int n, cap;
} evlist;

static void ev_push(evlist *l, const lc_impact_event *e)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 256;
        lc_impact_event *p = realloc(l->e, (size_t)cap * sizeof *p);
        if (p == NULL) {
            CHECK(0, "%s", "out of memory in the test");
            return;
        }
        l->e = p;
        l->cap = cap;
    }
    l->e[l->n++] = *e;
}

/* The last step's collisions, as events (kind: unknown to the contacts, left -1). */
static void poll_collisions(const lc_world *w, evlist *l)
{
    const lc_contact *c;
    int n = sc_contacts(w, &c), i;
    for (i = 0; i < n; ++i) {
        lc_impact_event e;
        if (c[i].kind != LC_CONTACT_COLLISION) continue;
        memset(&e, 0, sizeof e);
        e.time = c[i].time;
        e.body_a = c[i].body_a;
        e.body_b = c[i].body_b;
        e.point = c[i].point;
        e.normal = c[i].normal;
        e.gap = c[i].gap;
        e.normal_impulse = c[i].impulse;
        e.tangent_impulse = c[i].tangent_impulse;
        e.approach_speed = -c[i].normal_velocity;
        e.kind = (lc_impact_kind)-1;
        ev_push(l, &e);
    }
}

/* Every unread event into l; returns the drops reported. */
static uint64_t read_all(lc_world *w, evlist *l)
{
    lc_impact_event buf[64];
    uint64_t dropped = 0, d;
    int n;
    do {
        lc_status s = lc_world_get_events(w, buf, 64, &n, &d);
        CHECK(s == LC_OK, "lc_world_get_events -> %s: %s", lc_status_string(s), lc_world_last_error(w));
        if (s != LC_OK) return dropped;
        dropped += d;
        for (int i = 0; i < n; ++i) ev_push(l, &buf[i]);
    } while (n == 64);
    return dropped;
}

static int same_event(const lc_impact_event *a, const lc_impact_event *b, int with_kind)
{
    return a->time == b->time && a->body_a == b->body_a && a->body_b == b->body_b && a->point.x == b->point.x &&
           a->point.y == b->point.y && a->normal.x == b->normal.x && a->normal.y == b->normal.y &&
           a->gap == b->gap && a->normal_impulse == b->normal_impulse && a->tangent_impulse == b->tangent_impulse &&
           a->approach_speed == b->approach_speed && (!with_kind || a->kind == b->kind);
}

/* 1 if the lists hold the same events in the same order (the first difference is a failed CHECK). */
static int same_lists(const evlist *a, const evlist *b, int with_kind, const char *what)
{
    int i;
    if (!CHECK(a->n == b->n, "%s: %d events against %d", what, a->n, b->n)) return 0;
    for (i = 0; i < a->n; ++i)
        if (!CHECK(same_event(&a->e[i], &b->e[i], with_kind), "%s: event %d differs (t %.17g vs %.17g, bodies %u-%u vs %u-%u)",
                   what, i, a->e[i].time, b->e[i].time, (unsigned)a->e[i].body_a, (unsigned)a->e[i].body_b,
                   (unsigned)b->e[i].body_a, (unsigned)b->e[i].body_b))
            return 0;
    return 1;
}

/* The driven seed blocks (scenes.h) without the mouse spring: walls and blocks at e = 0.7, random
 * velocities, gravity, damping, a spring, thrusters; its islands go through both regimes. */
static lc_world *seed_scene(int event_capacity)
{
    lc_world_def d = lc_default_world_def();
    d.event_capacity = event_capacity;
    return sc_driven_blocks(d, 7, 0, NULL);
}

/* A pyramid of base 7 (e 0, friction 0.5) on a floor, and a box (e 0.3) dropped on it at 5 m/s: the
 * contact regime's impacts. */
static lc_world *pile_scene(void)
{
    lc_world *w = sc_world(NULL);
    lc_body_id ids[28];
    if (!w) return NULL;
    sc_static_box(w, 40.0, 1.0, 0.0, -0.5, 0.0);
    sc_pyramid(w, 7, 0.5, ids);
    sc_box(w, 1.0, 1.0, 0.3, 9.0, 0.2, 0.0, -5.0, 0.0, 1.0, 0.3);
    return w;
}

/* Without gravity, a 0.5 m box at 40 m/s hits a 1 m box at rest, which the rest of the 50 ms step
 * carries into a third 1 m box beyond the reach its island was built with: the step is taken again
 * (lc_counters.island_retries). */
static lc_world *chain_scene(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    if (!w) return NULL;
    sc_box(w, 0.5, 0.5, -3.0, 0.0, 0.0, 40.0, 0.0, 0.0, 1.0, 0.9);
    sc_box(w, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.9);
    sc_box(w, 1.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.9);
    return w;
}

/* Steps n times at dt, reading the stream every `every` steps; the stream must equal the collisions
 * polled after each step. Counts the events of each kind into kinds[2]. */
static void stream_matches_polling(lc_world *w, double dt, int n, int every, int kinds[2], const char *what,
                                   int least)
{
    evlist polled = {0}, stream = {0};
    int k, i;
    for (k = 0; k < n; ++k) {
        if (sc_step_n(w, dt, 1) != 1) break;
        poll_collisions(w, &polled);
        if ((k + 1) % every == 0)
            CHECK(read_all(w, &stream) == 0, "%s: nothing dropped at the default capacity", what);
    }
    CHECK(read_all(w, &stream) == 0, "%s: nothing dropped at the default capacity", what);
    CHECK(polled.n >= least, "%s: the scene has impacts to report (%d)", what, polled.n);
    same_lists(&polled, &stream, 0, what);
    for (i = 0; i < stream.n; ++i) {
        CHECK(stream.e[i].kind == LC_IMPACT_EVENT || stream.e[i].kind == LC_IMPACT_CONTACT, "%s: kind %d", what,
              (int)stream.e[i].kind);
        if (stream.e[i].kind == LC_IMPACT_EVENT || stream.e[i].kind == LC_IMPACT_CONTACT) kinds[stream.e[i].kind]++;
        CHECK(stream.e[i].normal_impulse > 0.0, "%s: event %d has a positive impulse (%g)", what, i,
              stream.e[i].normal_impulse);
        CHECK(i == 0 || stream.e[i].time >= stream.e[i - 1].time, "%s: event %d in time order", what, i);
    }
    free(polled.e);
    free(stream.e);
}

/* 1 kHz steps read at 100 Hz (the node's rates): no impact lost or repeated, in each regime. */
static void no_impact_lost(void)
{
    int kinds[2] = {0, 0}, pile[2] = {0, 0}, base;
    lc_world *w = seed_scene(4096);
    lc_counters total;
    if (w) {
        stream_matches_polling(w, 0.001, 3000, 10, kinds, "seed scene, 1 kHz read at 100 Hz", 20);
        lc_world_destroy(w);
    }
    CHECK(kinds[LC_IMPACT_EVENT] > 0, "the seed scene reports event-regime impacts (%d)", kinds[LC_IMPACT_EVENT]);
    w = pile_scene();
    if (w) {
        stream_matches_polling(w, 0.001, 1500, 10, pile, "pile, 1 kHz read at 100 Hz", 20);
        lc_world_destroy(w);
    }
    /* island steps solved again: the first solve's impacts must not be reported twice. A box dropped on
     * a pyramid (tests/c/test_drop_family.c) leaves, at a few steps of some bases, an overlap or a gain
     * the precise retry removes: the first base from 8 up whose drop has them */
    total.contact_precise_retries = 0;
    for (base = 8; base <= 16 && total.contact_precise_retries == 0; ++base) {
        w = sc_drop_on_pyramid(base);
        if (w == NULL) break;
        stream_matches_polling(w, 1.0 / 60.0, 300, 10, pile, "pile solved again", 20);
        lc_world_get_counters(w, NULL, &total);
        lc_world_destroy(w);
    }
    CHECK(total.contact_precise_retries > 0, "a pile's island steps were solved again (%llu, bases 8-%d)",
          (unsigned long long)total.contact_precise_retries, base - 1);
    CHECK(pile[LC_IMPACT_CONTACT] > 0, "the pile reports contact-regime impacts (%d)", pile[LC_IMPACT_CONTACT]);
    /* a step taken again: the first try's impacts must not be reported twice */
    w = chain_scene();
    if (w) {
        int chain[2] = {0, 0};
        stream_matches_polling(w, 0.05, 10, 3, chain, "a chain whose step is taken again", 3);
        lc_world_get_counters(w, NULL, &total);
        CHECK(total.island_retries > 0, "the chain's step was taken again (%llu)", (unsigned long long)total.island_retries);
        lc_world_destroy(w);
    }
    /* a step of 10 ms read after every step, and after every 37 */
    w = seed_scene(4096);
    if (w) {
        stream_matches_polling(w, 0.01, 400, 1, kinds, "seed scene, read every step", 20);
        lc_world_destroy(w);
    }
    w = seed_scene(4096);
    if (w) {
        stream_matches_polling(w, 0.01, 400, 37, kinds, "seed scene, read every 37 steps", 20);
        lc_world_destroy(w);
    }
}

/* Past the capacity the oldest unread events go, counted exactly: a model queue of the polled
 * collisions, cut to the capacity after each step, is what each read returns. */
static void overflow(void)
{
    const int cap = 7;
    lc_world *w = seed_scene(cap);
    evlist model = {0}, got = {0};
    uint64_t model_dropped = 0, reported = 0, total_dropped = 0;
    int k, reads = 0;
    lc_world_def d;
    if (!w) return;
    /* 3 s: the driven blocks settle into a resting pile after about 5 s, and the reads below need
     * impacts still coming */
    for (k = 0; k < 300; ++k) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        poll_collisions(w, &model);
        if (model.n > cap) {
            int drop = model.n - cap;
            memmove(model.e, model.e + drop, (size_t)cap * sizeof *model.e);
            model.n = cap;
            model_dropped += (uint64_t)drop;
        }
        if (k % 50 == 49) {
            got.n = 0;
            reported = read_all(w, &got);
            CHECK(reported == model_dropped, "read %d: %llu dropped reported, %llu expected", reads,
                  (unsigned long long)reported, (unsigned long long)model_dropped);
            same_lists(&model, &got, 0, "the newest events, after the drops");
            total_dropped += model_dropped;
            model.n = 0;
            model_dropped = 0;
            reads++;
        }
    }
    CHECK(total_dropped > 0, "the scene overflowed a capacity of %d (%llu dropped)", cap, (unsigned long long)total_dropped);
    /* a smaller capacity drops the oldest unread ones at once; 0 drops all */
    for (k = 0; k < 100; ++k) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        poll_collisions(w, &model);
        if (model.n > cap) {
            memmove(model.e, model.e + (model.n - cap), (size_t)cap * sizeof *model.e);
            model_dropped += (uint64_t)(model.n - cap);
            model.n = cap;
        }
    }
    CHECK(model.n == cap, "the stream is full before the capacity shrinks (%d)", model.n);
    lc_world_get_def(w, &d);
    d.event_capacity = 3;
    CHECK(lc_world_set_def(w, &d) == LC_OK, "%s", "event_capacity 3");
    got.n = 0;
    reported = read_all(w, &got);
    CHECK(reported == model_dropped + (uint64_t)(cap - 3), "shrinking to 3 drops the 4 oldest (%llu reported, %llu expected)",
          (unsigned long long)reported, (unsigned long long)(model_dropped + (uint64_t)(cap - 3)));
    memmove(model.e, model.e + (cap - 3), 3 * sizeof *model.e);
    model.n = 3;
    same_lists(&model, &got, 0, "the 3 newest after the shrink");
    d.event_capacity = 0;
    CHECK(lc_world_set_def(w, &d) == LC_OK, "%s", "event_capacity 0");
    model.n = 0;
    for (k = 0; k < 50; ++k) {
        if (sc_step_n(w, 0.01, 1) != 1) break;
        poll_collisions(w, &model);
    }
    got.n = 0;
    reported = read_all(w, &got);
    CHECK(got.n == 0 && reported == (uint64_t)model.n && model.n > 0,
          "capacity 0 keeps nothing and counts every impact (%d read, %llu dropped, %d impacts)", got.n,
          (unsigned long long)reported, model.n);
    free(model.e);
    free(got.e);
    lc_world_destroy(w);
}

/* A step that is undone reports nothing: a ball crossing a walled box at 30 m/s hits walls in every
 * 1 s step, and a 1e-3 kg block on a 1e9 N/m spring (test_api_errors' numeric failure) makes a step
 * diverge within a few dozen steps; that step is undone and its impacts never reach the stream. */
static void undone_step(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    lc_spring_def sd = lc_default_spring_def();
    lc_spring_id sid;
    lc_status st = LC_OK;
    lc_counters last;
    evlist got = {0}, polled = {0};
    int k, n;
    uint64_t dropped;
    if (!w) return;
    lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 1.0, NULL);
    sc_box(w, 0.5, 0.5, 0.0, 0.0, 0.0, 30.0, 7.0, 0.0, 1.0, 1.0);
    sd.body_a = sc_box(w, 0.2, 0.2, 41.0, 0.0, 0.0, 0, 0, 0, 1e-3, 1.0);
    sd.stiffness = 1e9;
    sd.point_b.x = 40.0;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK, "%s", "stiff spring");
    for (k = 0; k < 200 && st == LC_OK; k++) {
        st = lc_world_step(w, 1.0);
        if (st == LC_OK) {
            poll_collisions(w, &polled);
            got.n = 0;
            read_all(w, &got);
            same_lists(&polled, &got, 0, "a step taken");
            polled.n = 0;
        }
    }
    CHECK(st == LC_ERR_NUMERIC, "the stiff spring ends in an undone step (%s)", lc_status_string(st));
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.collisions > 0, "the undone step had impacts before it failed (%llu)", (unsigned long long)last.collisions);
    CHECK(lc_world_get_events(w, NULL, 0, &n, &dropped) == LC_OK && n == 0 && dropped == 0,
          "the undone step left no event (%d unread, %llu dropped)", n, (unsigned long long)dropped);
    free(got.e);
    free(polled.e);
    lc_world_destroy(w);
}

/* Bad arguments: an error with a message, and the stream and the world unchanged. */
static void bad_arguments(void)
{
    lc_world *w = seed_scene(4096);
    lc_world_def d;
    lc_impact_event buf[4];
    int n = -5, before, after;
    uint64_t dropped, h;
    char err[256];
    if (!w) return;
    sc_step_n(w, 0.01, 100);
    CHECK(lc_world_get_events(w, NULL, 0, &before, &dropped) == LC_OK && before > 4, "unread events (%d)", before);
    h = lc_world_state_hash(w);
    CHECK(lc_world_get_events(NULL, buf, 4, &n, &dropped) == LC_ERR_NULL, "%s", "NULL world");
    CHECK(lc_world_get_events(w, buf, 4, NULL, &dropped) == LC_ERR_NULL && strstr(lc_world_last_error(w), "out_count"),
          "NULL out_count: %s", lc_world_last_error(w));
    CHECK(lc_world_get_events(w, NULL, 4, &n, &dropped) == LC_ERR_NULL && strstr(lc_world_last_error(w), "out"),
          "NULL out with a capacity: %s", lc_world_last_error(w));
    CHECK(lc_world_get_events(w, buf, -1, &n, &dropped) == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "capacity"),
          "negative capacity: %s", lc_world_last_error(w));
    CHECK(n == -5, "a refused read writes no count (%d)", n);
    lc_world_get_def(w, &d);
    d.event_capacity = -1;
    CHECK(lc_world_set_def(w, &d) == LC_ERR_OUT_OF_RANGE && strstr(lc_world_last_error(w), "event_capacity"),
          "event_capacity -1: %s", lc_world_last_error(w));
    d.event_capacity = 1000001;
    CHECK(lc_world_set_def(w, &d) == LC_ERR_OUT_OF_RANGE, "%s", "event_capacity past 1e6");
    CHECK(lc_world_create(&d, err, sizeof err) == NULL && strstr(err, "event_capacity"), "create refuses it: %s", err);
    CHECK(lc_world_get_events(w, NULL, 0, &after, &dropped) == LC_OK && after == before && dropped == 0,
          "the refused calls left the stream (%d unread of %d)", after, before);
    CHECK(lc_world_state_hash(w) == h, "%s", "and the world unchanged");
    CHECK(lc_world_get_events(w, buf, 4, &n, NULL) == LC_OK && n == 4, "a read of 4 (%d)", n);
    CHECK(lc_world_get_events(w, NULL, 0, &after, NULL) == LC_OK && after == before - 4, "leaves the rest (%d)", after);
    CHECK(lc_world_state_hash(w) == h, "%s", "reading changes no state");
    lc_world_destroy(w);
}

/* Reading does not change the run, and two runs report the same events. */
static void determinism(void)
{
    lc_world *a = seed_scene(4096), *b = seed_scene(4096);
    evlist ea = {0}, eb = {0};
    int k;
    if (!a || !b) return;
    for (k = 0; k < 500; ++k) {
        sc_step_n(a, 0.01, 1);
        sc_step_n(b, 0.01, 1);
        if (k % 3 == 0) read_all(a, &ea);   /* a reads often, b once */
        if (!CHECK(lc_world_state_hash(a) == lc_world_state_hash(b), "step %d: reading changed the run", k)) break;
    }
    read_all(a, &ea);
    read_all(b, &eb);
    CHECK(ea.n > 50, "events to compare (%d)", ea.n);
    same_lists(&ea, &eb, 1, "two runs");
    free(ea.e);
    free(eb.e);
    lc_world_destroy(a);
    lc_world_destroy(b);
}

int main(void)
{
    CHECK(lc_default_world_def().event_capacity == 4096, "%s", "default capacity");
    no_impact_lost();
    overflow();
    undone_step();
    bad_arguments();
    determinism();
    return CHECK_SUMMARY("test_events");
}
