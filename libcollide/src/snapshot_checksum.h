/* The checksum of a world snapshot (snapshot.c; layout in docs/events_and_snapshots.md): FNV-1a 64 of
 * the payload, stored little-endian in header bytes 24..31. One definition for the library (save and
 * load), the fuzz harness and the C tests, which corrupt a snapshot on purpose and make its checksum
 * right again so that the loader's own checks are what refuses it. An internal header: not installed,
 * not part of the public API.
 *
 * The offset basis is 1469598103934665603, not the published FNV-1a 64 basis 14695981039346656037
 * (one digit shorter). It is part of the snapshot format and of every lc_world_state_hash value, so it
 * stays; test_snapshot's checksum_pinned fails if it changes. */
#ifndef LC_SNAPSHOT_CHECKSUM_H
#define LC_SNAPSHOT_CHECKSUM_H

#include <stddef.h>
#include <stdint.h>

#define LC_FNV1A64_BASIS 1469598103934665603ULL
/* Bytes of a snapshot's header; the payload follows. */
#define LC_SNAPSHOT_HEADER_BYTES 32u
/* Where the header keeps the payload's checksum (8 bytes, little-endian). */
#define LC_SNAPSHOT_CHECKSUM_AT 24u

/* FNV-1a 64 of p[0 .. n) continued from h (LC_FNV1A64_BASIS to start); chaining calls hashes the
 * concatenation, which is how lc_world_state_hash covers time, state and ids. */
uint64_t lc_fnv1a64(uint64_t h, const void *p, size_t n);

/* The checksum of the `size`-byte snapshot at p: FNV-1a 64 of its payload, bytes
 * [LC_SNAPSHOT_HEADER_BYTES, size). size is at least LC_SNAPSHOT_HEADER_BYTES. */
uint64_t lc_snapshot_checksum(const uint8_t *p, size_t size);

/* Writes lc_snapshot_checksum(p, size) into the header (bytes 24..31, little-endian). */
void lc_snapshot_set_checksum(uint8_t *p, size_t size);

#endif
