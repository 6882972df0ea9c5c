/* test_determinism: the same inputs give bit-identical results (exact equality of
 * lc_world_state_hash, a hash of the time and every state bit), and worlds are independent:
 * stepping two worlds interleaved gives each exactly the hashes it has when stepped alone.
 * The scene uses everything that carries state or branches: walls, six blocks with fixed-seed
 * random velocities, gravity, e = 0.7, damping, a spring between two blocks, a mouse spring,
 * thrusters firing, resting contacts on the floor. No tolerance: equality is the requirement. */
#include "check.h"
#include "scenes.h"

#define NSTEPS 300

static lc_world *build(uint64_t seed) { return sc_driven_blocks(lc_default_world_def(), seed, 1, NULL); }

static void run_alone(uint64_t seed, uint64_t *h)
{
    lc_world *w = build(seed);
    int k;
    if (!w) return;
    for (k = 0; k < NSTEPS; k++) {
        sc_step_n(w, 0.01, 1);
        h[k] = lc_world_state_hash(w);
    }
    lc_world_destroy(w);
}

static int first_difference(const uint64_t *a, const uint64_t *b)
{
    int k;
    for (k = 0; k < NSTEPS; k++) if (a[k] != b[k]) return k;
    return -1;
}

int main(void)
{
    static uint64_t h1[NSTEPS], h2[NSTEPS], hA[NSTEPS], hB[NSTEPS], hC[NSTEPS], hX[NSTEPS];
    lc_world *a, *b, *c;
    int k, changes = 0, diff;
    lc_counters tot;

    run_alone(7u, h1);
    run_alone(7u, h2);
    diff = first_difference(h1, h2);
    CHECK(diff < 0, "same scene twice: hashes differ first at step %d", diff);
    for (k = 1; k < NSTEPS; k++) changes += h1[k] != h1[k - 1];
    CHECK(changes == NSTEPS - 1, "the hash changes every step (time advances): %d of %d", changes, NSTEPS - 1);

    /* two identical worlds and one different one, stepped interleaved */
    run_alone(99u, hX);
    CHECK(first_difference(h1, hX) == 0, "%s", "a different scene has a different hash");
    a = build(7u);
    b = build(7u);
    c = build(99u);
    if (a && b && c) {
        for (k = 0; k < NSTEPS; k++) {
            sc_step_n(a, 0.01, 1);
            sc_step_n(c, 0.01, 1);
            sc_step_n(b, 0.01, 1);
            hA[k] = lc_world_state_hash(a);
            hB[k] = lc_world_state_hash(b);
            hC[k] = lc_world_state_hash(c);
        }
        lc_world_get_counters(a, NULL, &tot);
        printf("determinism scene: %llu collisions, %llu contact solves, %llu resting contacts in %d steps\n",
               (unsigned long long)tot.collisions, (unsigned long long)tot.contact_solves,
               (unsigned long long)tot.resting_contacts, NSTEPS);
        CHECK(tot.collisions > 0, "%s", "the scene exercises collisions");
        diff = first_difference(hA, h1);
        CHECK(diff < 0, "interleaved world A differs from A alone first at step %d", diff);
        diff = first_difference(hB, h1);
        CHECK(diff < 0, "interleaved world B differs from A alone first at step %d", diff);
        diff = first_difference(hC, hX);
        CHECK(diff < 0, "interleaved world C differs from C alone first at step %d", diff);
    }
    lc_world_destroy(a);
    lc_world_destroy(b);
    lc_world_destroy(c);
    return CHECK_SUMMARY("test_determinism");
}
