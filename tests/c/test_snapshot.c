/* test_snapshot: lc_world_save / lc_world_load / lc_world_create_from_snapshot.
 *
 * Bit-identical continuation: a world saved after step k and loaded (into a new world, into the world
 * it came from after it went on, into an unrelated world) steps on with the same lc_world_state_hash at
 * every later step as the uninterrupted run, and ends with the same snapshot bytes (so every kept state
 * is the same too), in every regime: the seed scene (event and contact regime, springs, a mouse spring,
 * thrusters, damping), perfectly elastic blocks (the event regime alone), resting blocks forced into the
 * event regime (its warm start and kept end touches), a pile in the contact regime (warm-start cache,
 * kept touches, the sparse solver's norm estimates, sort-and-sweep), a pile with sleep on (sleeping
 * islands, rest timers), and a world with removed bodies and springs (gaps in the ids). Fresh worlds
 * have none of the caches a snapshot leaves out (trig and boxes, the sort order), so the continuation
 * also shows that leaving them out changes no bit.
 *
 * Corrupt input: every truncation, every flipped byte (the checksum), flipped bytes with the checksum
 * made right again (the loader's own checks), another format version and bad arguments are refused with
 * LC_ERR_BAD_SNAPSHOT (or the argument's status) and a message, and leave the world's snapshot bytes as
 * they were. No tolerance anywhere: equality is the requirement. */
#include <stdlib.h>
#include "check.h"
#include "scenes.h"
#include "snapshot_checksum.h"

/* ---- helpers ---------------------------------------------------------------------------------- */

typedef struct blob {
    unsigned char *p;
    size_t n;
} blob;

static blob save(const lc_world *w)
{
    blob b = {NULL, 0};
    size_t n = 0, m = 0;
    lc_status s = lc_world_save(w, NULL, 0, &n);
    CHECK(s == LC_OK && n > 32, "size query -> %s (%zu bytes): %s", lc_status_string(s), n, lc_world_last_error(w));
    b.p = malloc(n);
    if (b.p == NULL) return b;
    s = lc_world_save(w, b.p, n, &m);
    CHECK(s == LC_OK && m == n, "save -> %s (%zu of %zu bytes): %s", lc_status_string(s), m, n, lc_world_last_error(w));
    b.n = m;
    return b;
}

static int same_blob(blob a, blob b) { return a.n == b.n && memcmp(a.p, b.p, a.n) == 0; }

typedef lc_world *(*builder)(void);

/* ---- scenes ------------------------------------------------------------------------------------ */

static lc_world *seed_scene(void)
{
    lc_body_id b[6];
    lc_vec2 push;
    lc_world *w = sc_driven_blocks(lc_default_world_def(), 11, 1, b);
    if (!w) return NULL;
    push.x = 0.3;
    push.y = 0.0;
    CHECK(lc_body_set_external(w, b[5], push, 0.05) == LC_OK, "%s", "external force");
    return w;
}

/* Perfectly elastic blocks without gravity: every step is one event pass. */
static lc_world *elastic_scene(void)
{
    lc_world_def d = sc_def_zero_g();
    lc_world *w = sc_world(&d);
    sc_rng rng;
    int i;
    if (!w) return NULL;
    rng.s = 3;
    lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 1.0, NULL);
    for (i = 0; i < 8; i++)
        sc_box(w, 0.8, 0.5 + 0.1 * i, -4.5 + 1.3 * i, sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -1.0, 1.0),
               sc_uniform(&rng, -5.0, 5.0), sc_uniform(&rng, -5.0, 5.0), sc_uniform(&rng, -2.0, 2.0), 1.0, 1.0);
    return w;
}

/* Blocks falling onto the floor and onto each other at e = 0.3, every island in the event regime: its
 * resting contacts, warm start and kept end touches. */
static lc_world *event_resting_scene(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    int i;
    d.regime = LC_REGIME_EVENT;
    w = sc_world(&d);
    if (!w) return NULL;
    lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 0.3, NULL);
    for (i = 0; i < 4; i++) sc_box(w, 1.5, 0.6, -3.0 + 2.0 * i, -5.0 + 1.5 * i, 0.05 * i, 0.5, 0.0, 0.0, 1.0, 0.3);
    return w;
}

/* A pyramid of base 8 on a floor (37 bodies: sort-and-sweep) with a box dropped on it, friction 0.5,
 * e 0: the contact regime. */
static lc_world *pile_scene_def(lc_world_def d)
{
    lc_world *w = sc_world(&d);
    lc_body_id ids[36];
    if (!w) return NULL;
    sc_static_box(w, 40.0, 1.0, 0.0, -0.5, 0.0);
    sc_pyramid(w, 8, 0.5, ids);
    sc_box(w, 1.0, 1.0, 0.3, 10.0, 0.2, 0.0, -3.0, 0.0, 1.0, 0.2);
    return w;
}

static lc_world *pile_scene(void) { return pile_scene_def(lc_default_world_def()); }

static lc_world *pile_contact_scene(void)
{
    lc_world_def d = lc_default_world_def();
    d.regime = LC_REGIME_CONTACT;
    return pile_scene_def(d);
}

/* A pyramid of base 8 with sleep on (sleep_time 0.2 s) and a frictionless box sliding at 3 m/s along
 * the floor towards it from 8 m away: the pyramid falls asleep, the box reaches it and wakes it. */
static lc_world *sleep_scene(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w;
    lc_body_id ids[36];
    lc_body_id box;
    d.allow_sleep = 1;
    d.sleep_time = 0.2;
    w = sc_world(&d);
    if (!w) return NULL;
    sc_static_box(w, 40.0, 1.0, 0.0, -0.5, 0.0);
    sc_pyramid(w, 8, 0.5, ids);
    box = sc_box(w, 1.0, 1.0, 12.0, 0.5, 0.0, -3.0, 0.0, 0.0, 1.0, 0.2);
    CHECK(lc_body_set_material(w, box, 0.2, 0.0) == LC_OK, "%s", "frictionless box");
    return w;
}

/* The seed scene with bodies and springs removed and added: gaps in the body and spring ids, a body
 * added after the removals. */
static lc_world *gaps_scene(void)
{
    lc_world *w = seed_scene();
    lc_spring_def sd;
    lc_spring_id sid;
    if (!w) return NULL;
    CHECK(lc_world_remove_body(w, 6) == LC_OK, "%s", "remove body 6 and spring 1 with it");
    CHECK(lc_spring_get_def(w, 2, &sd) == LC_OK && lc_world_remove_spring(w, 2) == LC_OK, "%s", "remove spring 2");
    sc_box(w, 0.7, 0.7, 3.0, 4.0, 0.3, -1.0, 0.0, 0.5, 0.5, 0.7);
    sd.stiffness = 5.0;
    CHECK(lc_world_add_spring(w, &sd, &sid) == LC_OK && sid == 3, "%s", "spring 3");
    return w;
}

/* ---- continuation --------------------------------------------------------------------------- */

#define NMAX 400

/* Steps n times, the hash after each into h. */
static void run(lc_world *w, double dt, int n, uint64_t *h)
{
    int i;
    for (i = 0; i < n; ++i) {
        if (sc_step_n(w, dt, 1) != 1) {
            for (; i < n; ++i) h[i] = 0;
            return;
        }
        h[i] = lc_world_state_hash(w);
    }
}

static int same_hashes(const uint64_t *a, const uint64_t *b, int n, const char *what)
{
    int i;
    for (i = 0; i < n; ++i)
        if (!CHECK(a[i] == b[i], "%s: step %d after the snapshot differs", what, i + 1)) return 0;
    return 1;
}

/* Saves `build`'s world after k steps of dt and checks the three loads against the uninterrupted run of
 * n more steps. Returns the uninterrupted world's total counters over the continuation in *seen. */
static void continues(builder build, const char *name, double dt, int k, int n, lc_counters *seen)
{
    lc_world *w = build(), *x, *y;
    uint64_t ref[NMAX], h[NMAX], at_save;
    lc_counters before, after, last;
    blob b, end_ref, end, again;
    char err[256], what[128];
    int i;
    if (!w) return;
    sc_step_n(w, dt, k);
    b = save(w);
    at_save = lc_world_state_hash(w);
    lc_world_get_counters(w, &last, &before);
    run(w, dt, n, ref);
    lc_world_get_counters(w, NULL, &after);
    end_ref = save(w);
    memset(seen, 0, sizeof *seen);
    seen->collisions = after.collisions - before.collisions;
    seen->contact_islands = after.contact_islands - before.contact_islands;
    seen->islands = after.islands - before.islands;
    seen->contact_points = after.contact_points - before.contact_points;
    seen->sort_and_sweep_steps = after.sort_and_sweep_steps - before.sort_and_sweep_steps;
    seen->bodies_asleep = last.bodies_asleep;   /* at the save */

    /* a new world from the snapshot: the same bytes when saved again, the same steps */
    x = lc_world_create_from_snapshot(b.p, b.n, err, sizeof err);
    snprintf(what, sizeof what, "%s: a new world", name);
    if (CHECK(x != NULL, "%s: %s", what, err)) {
        again = save(x);
        CHECK(same_blob(again, b), "%s: saving the loaded world gives the snapshot's bytes", what);
        CHECK(lc_world_state_hash(x) == at_save, "%s: the state at the save", what);
        run(x, dt, n, h);
        same_hashes(ref, h, n, what);
        end = save(x);
        CHECK(same_blob(end, end_ref), "%s: the same snapshot bytes after %d more steps", what, n);
        free(end.p);
        free(again.p);
        lc_world_destroy(x);
    }
    /* into the world it came from, which went on meanwhile */
    snprintf(what, sizeof what, "%s: the world it came from", name);
    CHECK(lc_world_load(w, b.p, b.n) == LC_OK, "%s: %s", what, lc_world_last_error(w));
    CHECK(lc_world_state_hash(w) == at_save, "%s: back to the state at the save", what);
    run(w, dt, n, h);
    same_hashes(ref, h, n, what);
    /* into an unrelated world with other settings, bodies and kept state */
    y = elastic_scene();
    if (y) {
        lc_world_set_stage_timing(y, 1);
        sc_step_n(y, 0.01, 20);
        snprintf(what, sizeof what, "%s: an unrelated world", name);
        CHECK(lc_world_load(y, b.p, b.n) == LC_OK, "%s: %s", what, lc_world_last_error(y));
        run(y, dt, n, h);
        same_hashes(ref, h, n, what);
        i = 0;
        lc_world_get_stage_timing(y, &i);
        CHECK(i == 1, "%s: its stage timing setting is kept", what);
        lc_world_destroy(y);
    }
    free(b.p);
    free(end_ref.p);
    lc_world_destroy(w);
}

static void continuation(void)
{
    lc_counters seen;
    uint64_t contact_islands = 0;
    int k;
    /* the seed scene saved at several points: before any step, mid-flight, resting */
    for (k = 0; k <= 300; k += 100) {
        continues(seed_scene, "seed scene", 0.01, k, 200, &seen);
        CHECK(seen.collisions > 0, "seed scene from step %d: impacts in the continuation (%llu)", k,
              (unsigned long long)seen.collisions);
        contact_islands += seen.contact_islands;
    }
    CHECK(contact_islands > 0, "seed scene: contact islands in the continuations (%llu)", (unsigned long long)contact_islands);
    continues(elastic_scene, "elastic blocks", 0.01, 50, 300, &seen);
    CHECK(seen.collisions > 10 && seen.contact_islands == 0, "elastic blocks: event regime only (%llu impacts)",
          (unsigned long long)seen.collisions);
    continues(event_resting_scene, "resting blocks, event regime", 0.01, 40, 300, &seen);
    CHECK(seen.contact_islands == 0 && seen.collisions > 0, "resting blocks: event regime (%llu impacts)",
          (unsigned long long)seen.collisions);
    continues(pile_scene, "pile", 0.01, 60, 150, &seen);
    CHECK(seen.contact_points > 0 && seen.sort_and_sweep_steps > 0, "pile: contact regime (%llu points), sort and sweep",
          (unsigned long long)seen.contact_points);
    continues(pile_contact_scene, "pile, contact regime", 0.01, 100, 100, &seen);
    CHECK(seen.contact_points > 0, "pile, contact regime: %llu points", (unsigned long long)seen.contact_points);
    continues(sleep_scene, "pile with sleep", 0.01, 40, 250, &seen);
    CHECK(seen.bodies_asleep >= 36, "pile with sleep: bodies asleep at the save (%llu)", (unsigned long long)seen.bodies_asleep);
    continues(gaps_scene, "removed bodies and springs", 0.01, 120, 150, &seen);
}

/* The sleep scene saved while the pyramid sleeps and the box is still falling towards it. */
static void saved_asleep(void)
{
    lc_world *w = sleep_scene(), *x;
    lc_counters last;
    uint64_t ref[NMAX], h[NMAX];
    blob b;
    if (!w) return;
    sc_step_n(w, 0.01, 40);
    lc_world_get_counters(w, &last, NULL);
    CHECK(last.bodies_asleep >= 36, "the pyramid sleeps at the save (%llu asleep)", (unsigned long long)last.bodies_asleep);
    b = save(w);
    run(w, 0.01, 300, ref);
    x = lc_world_create_from_snapshot(b.p, b.n, NULL, 0);
    if (CHECK(x != NULL, "%s", "load")) {
        run(x, 0.01, 300, h);
        same_hashes(ref, h, 300, "saved asleep");
        lc_world_get_counters(x, &last, NULL);
        CHECK(last.bodies_asleep == 0, "the box woke the pyramid after the load (%llu asleep)",
              (unsigned long long)last.bodies_asleep);
        lc_world_destroy(x);
    }
    free(b.p);
    lc_world_destroy(w);
}

/* ---- bad input ---------------------------------------------------------------------------------- */

/* A failed load: the status, a message (holding `says`), and the world's own snapshot unchanged. */
static void refused(lc_world *w, const blob *was, const void *p, size_t n, lc_status want, const char *what,
                    const char *says)
{
    lc_status s = lc_world_load(w, p, n);
    blob now;
    if (!CHECK(s == want, "%s: %s (want %s): %s", what, lc_status_string(s), lc_status_string(want), lc_world_last_error(w)))
        return;
    CHECK(lc_world_last_error(w)[0] != '\0' && strstr(lc_world_last_error(w), says) != NULL, "%s: the message says '%s': %s",
          what, says, lc_world_last_error(w));
    now = save(w);
    CHECK(same_blob(now, *was), "%s: the world is unchanged", what);
    free(now.p);
}

static void corrupt_input(void)
{
    lc_world *src = gaps_scene(), *w = elastic_scene();
    blob b, was;
    unsigned char *c;
    size_t i;
    int accepted = 0, refused_fixed = 0;
    char err[256];
    if (!src || !w) return;
    sc_step_n(src, 0.01, 150);
    sc_step_n(w, 0.01, 10);
    b = save(src);
    was = save(w);
    c = malloc(b.n);
    if (c == NULL) return;
    /* every truncation */
    for (i = 0; i < b.n; ++i) {
        lc_status s = lc_world_load(w, b.p, i);
        if (!CHECK(s == LC_ERR_BAD_SNAPSHOT, "truncated to %zu of %zu bytes: %s", i, b.n, lc_status_string(s))) break;
    }
    refused(w, &was, b.p, b.n - 1, LC_ERR_BAD_SNAPSHOT, "truncated by one byte", "truncated");
    /* every flipped byte: the checksum (or the header) refuses it */
    for (i = 0; i < b.n; ++i) {
        lc_status s;
        memcpy(c, b.p, b.n);
        c[i] ^= 0x5A;
        s = lc_world_load(w, c, b.n);
        if (!CHECK(s == LC_ERR_BAD_SNAPSHOT, "byte %zu flipped: %s", i, lc_status_string(s))) break;
    }
    refused(w, &was, c, b.n, LC_ERR_BAD_SNAPSHOT, "the last byte flipped", "checksum");
    /* flipped bytes with the checksum made right: the loader's own checks refuse what would break the
     * world; what they let through is a world that steps (a different number) */
    for (i = 32; i < b.n; ++i) {
        lc_status s;
        memcpy(c, b.p, b.n);
        c[i] ^= (unsigned char)(0x80u >> (i % 8));
        lc_snapshot_set_checksum(c, b.n);
        s = lc_world_load(w, c, b.n);
        if (s == LC_OK) {
            accepted++;
            lc_world_step(w, 0.01);
            CHECK(lc_world_load(w, was.p, was.n) == LC_OK, "%s", "back to the saved world");
        } else {
            refused_fixed++;
            if (!CHECK(s == LC_ERR_BAD_SNAPSHOT && lc_world_last_error(w)[0] != '\0', "byte %zu flipped, checksum fixed: %s",
                       i, lc_status_string(s)))
                break;
        }
    }
    CHECK(refused_fixed > 50 && accepted > 50, "the loader's checks refused %d of the fixed-up flips and let %d through",
          refused_fixed, accepted);
    {
        blob now = save(w);
        CHECK(same_blob(now, was), "%s", "the world is the saved one again");
        free(now.p);
    }
    /* another format version, a reserved field set, trailing bytes */
    memcpy(c, b.p, b.n);
    c[8] = 1;
    refused(w, &was, c, b.n, LC_ERR_BAD_SNAPSHOT, "format version 1", "format");
    memcpy(c, b.p, b.n);
    c[8] = 3;
    refused(w, &was, c, b.n, LC_ERR_BAD_SNAPSHOT, "format version 3", "format");
    memcpy(c, b.p, b.n);
    c[12] = 1;
    refused(w, &was, c, b.n, LC_ERR_BAD_SNAPSHOT, "reserved field set", "format");
    {
        unsigned char *longer = malloc(b.n + 1);
        if (longer) {
            memcpy(longer, b.p, b.n);
            longer[b.n] = 0;
            refused(w, &was, longer, b.n + 1, LC_ERR_BAD_SNAPSHOT, "a byte more than the header says", "truncated");
            longer[16] = (unsigned char)(longer[16] + 1);   /* the payload size follows, the checksum does not */
            lc_snapshot_set_checksum(longer, b.n + 1);
            refused(w, &was, longer, b.n + 1, LC_ERR_BAD_SNAPSHOT, "a trailing byte", "follow");
            free(longer);
        }
    }
    /* bad arguments */
    {
        size_t m = 0;
        unsigned char small[16];
        CHECK(lc_world_save(NULL, NULL, 0, &m) == LC_ERR_NULL, "%s", "save of NULL");
        CHECK(lc_world_save(w, NULL, 0, NULL) == LC_ERR_NULL && strstr(lc_world_last_error(w), "out_size"), "save without "
              "out_size: %s", lc_world_last_error(w));
        CHECK(lc_world_save(w, small, sizeof small, &m) == LC_ERR_OUT_OF_RANGE && m == was.n,
              "a small buffer: %zu bytes needed (%zu): %s", m, was.n, lc_world_last_error(w));
        CHECK(lc_world_load(NULL, b.p, b.n) == LC_ERR_NULL, "%s", "load into NULL");
        refused(w, &was, NULL, b.n, LC_ERR_NULL, "load from NULL", "NULL");
        CHECK(lc_world_create_from_snapshot(NULL, 5, err, sizeof err) == NULL && err[0] != '\0', "create from NULL: %s", err);
        CHECK(lc_world_create_from_snapshot(b.p, 10, err, sizeof err) == NULL && strstr(err, "snapshot"), "create from 10 "
              "bytes: %s", err);
        CHECK(lc_world_create_from_snapshot(b.p, b.n - 3, NULL, 0) == NULL, "%s", "no error buffer");
    }
    free(c);
    free(b.p);
    free(was.p);
    lc_world_destroy(src);
    lc_world_destroy(w);
}

/* The layout's header as documented: magic, version 2, payload size, checksum, little-endian. */
static void header_layout(void)
{
    lc_world *w = seed_scene();
    blob b;
    uint64_t payload = 0, sum = 0;
    int k;
    if (!w) return;
    b = save(w);
    CHECK(memcmp(b.p, "LCWORLD\x1a", 8) == 0, "%s", "magic");
    CHECK(b.p[8] == 2 && b.p[9] == 0 && b.p[10] == 0 && b.p[11] == 0, "%s", "version 2, little-endian");
    for (k = 0; k < 8; ++k) {
        payload |= (uint64_t)b.p[16 + k] << (8 * k);
        sum |= (uint64_t)b.p[24 + k] << (8 * k);
    }
    CHECK(payload == b.n - 32, "payload size %llu of %zu bytes", (unsigned long long)payload, b.n);
    CHECK(sum == lc_snapshot_checksum(b.p, b.n), "%s", "checksum");
    free(b.p);
    lc_world_destroy(w);
}

/* The checksum's bits are part of the snapshot format (snapshot_checksum.h): FNV-1a 64 with this library's
 * offset basis, little-endian at bytes 24..31, over the payload only. header_layout compares a saved
 * header with lc_snapshot_checksum; this pins lc_snapshot_checksum itself to values worked out by hand
 * (python: h ^= byte; h = h * 1099511628211 % 2**64, from 1469598103934665603), so a changed hash
 * fails here instead of silently moving the format. */
static void checksum_pinned(void)
{
    unsigned char s[40];
    int k, others = 1;
    memset(s, 0xA5, 32);                  /* a header whose bytes the checksum must not read */
    memcpy(s + 32, "LCWORLD\x1a", 8);     /* a payload */
    CHECK(lc_snapshot_checksum(s, 32) == 0x14650fb0739d0383ULL, "%s", "an empty payload hashes to the offset basis");
    CHECK(lc_snapshot_checksum(s, 40) == 0x6b7ca17ec82567f4ULL, "checksum %016llx",
          (unsigned long long)lc_snapshot_checksum(s, 40));
    lc_snapshot_set_checksum(s, 40);
    for (k = 0; k < 8; ++k)
        CHECK(s[24 + k] == (unsigned char)(0x6b7ca17ec82567f4ULL >> (8 * k)), "checksum byte %d little-endian", k);
    for (k = 0; k < 24; ++k) others &= s[k] == 0xA5;
    CHECK(others && memcmp(s + 32, "LCWORLD\x1a", 8) == 0, "%s", "setting the checksum writes bytes 24..31 only");
}

int main(void)
{
    continuation();
    saved_asleep();
    corrupt_input();
    header_layout();
    checksum_pinned();
    return CHECK_SUMMARY("test_snapshot");
}
