/* fuzz_snapshot_checks: the save/load round trip that ends every fuzz_step input (fuzz_step.c).
 *
 * Invariants checked (a violation calls fz_fail, fuzz_fail.h):
 *  - the world's snapshot (lc_world_save) loads into a new world (lc_world_create_from_snapshot) with
 *    the same state hash, and that world saves the same bytes;
 *  - copies with a payload byte flipped and the checksum made right again (lc_snapshot_set_checksum,
 *    so that the loader's own checks are what stands), and a copy cut short, are either refused by
 *    lc_world_load with a message and the world's state hash and snapshot bytes unchanged, or load
 *    (after which the world loads its own snapshot back).
 * The flipped bytes and the cut are chosen from a hash of the snapshot, not from the input's bytes, so
 * these checks consume no input and every corpus input decodes the same with or without them. */
#ifndef FZ_FUZZ_SNAPSHOT_CHECKS_H
#define FZ_FUZZ_SNAPSHOT_CHECKS_H

#include "collide/collide.h"

/* Runs the checks above on w; w ends in the state it started in. */
void fz_check_snapshot(lc_world *w);

#endif
