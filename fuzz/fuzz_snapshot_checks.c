/* fuzz_snapshot_checks: the save/load round trip of the fuzz_step harness (fuzz_snapshot_checks.h). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_fail.h"
#include "fuzz_snapshot_checks.h"
#include "snapshot_checksum.h" /* libcollide/src: the checksum the loader checks */

/* Copies with a flipped byte loaded per input (each a full load attempt); over a run's many inputs and
 * snapshots they reach every part of the payload. */
#define FZ_SNAPSHOT_FLIPS 12u

/* A load of the n bytes at p into w: refused with a message and the world's snapshot (was) unchanged,
 * or accepted, after which the world goes back to was. */
static void fz_load_or_refuse(lc_world *w, const uint8_t *p, size_t n, const uint8_t *was, size_t was_n)
{
    uint64_t h = lc_world_state_hash(w);
    lc_status s = lc_world_load(w, p, n);
    if (s == LC_OK) {
        if (lc_world_load(w, was, was_n) != LC_OK) fz_fail("the world's own snapshot does not load", lc_world_last_error(w));
        return;
    }
    if (lc_world_last_error(w)[0] == '\0') fz_fail("a refused snapshot left no message", NULL);
    if (lc_world_state_hash(w) != h) fz_fail("a refused snapshot changed the world", lc_world_last_error(w));
    {
        size_t m = 0;
        uint8_t *now = malloc(was_n);
        if (now == NULL) return;
        if (lc_world_save(w, now, was_n, &m) != LC_OK || m != was_n || memcmp(now, was, was_n) != 0)
            fz_fail("a refused snapshot changed the world's snapshot", NULL);
        free(now);
    }
}

void fz_check_snapshot(lc_world *w)
{
    size_t n = 0, m = 0, i;
    const size_t header = LC_SNAPSHOT_HEADER_BYTES;
    uint8_t *b, *again, *bad;
    lc_world *x;
    char err[256];
    uint64_t h;
    if (lc_world_save(w, NULL, 0, &n) != LC_OK) fz_fail("the snapshot's size query failed", lc_world_last_error(w));
    b = malloc(n);
    again = malloc(n);
    bad = malloc(n);
    if (b == NULL || again == NULL || bad == NULL) fz_fail("out of memory in the harness", NULL);
    if (lc_world_save(w, b, n, &m) != LC_OK || m != n) fz_fail("lc_world_save failed", lc_world_last_error(w));
    x = lc_world_create_from_snapshot(b, n, err, sizeof err);
    if (x == NULL) fz_fail("the world's snapshot does not load", err);
    if (lc_world_state_hash(x) != lc_world_state_hash(w)) fz_fail("a loaded snapshot has another state", NULL);
    if (lc_world_save(x, again, n, &m) != LC_OK || m != n || memcmp(again, b, n) != 0)
        fz_fail("a loaded snapshot saves other bytes", NULL);
    lc_world_destroy(x);
    /* which bytes to flip and where to cut: from the snapshot's own bytes, so no input is consumed */
    h = lc_fnv1a64(LC_FNV1A64_BASIS, b, n);
    for (i = 0; i < FZ_SNAPSHOT_FLIPS; ++i) {
        size_t at = header + (size_t)((h + i * 7919u) % (n - header));
        memcpy(bad, b, n);
        bad[at] ^= (uint8_t)(1u << ((h >> i) & 7u));
        lc_snapshot_set_checksum(bad, n);
        fz_load_or_refuse(w, bad, n, b, n);
    }
    fz_load_or_refuse(w, b, n - 1 - (size_t)(h % (n - 1)), b, n);
    free(b);
    free(again);
    free(bad);
}
