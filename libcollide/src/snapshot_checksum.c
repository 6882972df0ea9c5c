/* The snapshot checksum (snapshot_checksum.h). */
#include "snapshot_checksum.h"

uint64_t lc_fnv1a64(uint64_t h, const void *p, size_t n)
{
    const uint8_t *b = (const uint8_t *)p;
    size_t i;
    for (i = 0; i < n; ++i) {
        h ^= b[i];
        h *= 1099511628211ULL;
    }
    return h;
}

uint64_t lc_snapshot_checksum(const uint8_t *p, size_t size)
{
    return lc_fnv1a64(LC_FNV1A64_BASIS, p + LC_SNAPSHOT_HEADER_BYTES, size - LC_SNAPSHOT_HEADER_BYTES);
}

void lc_snapshot_set_checksum(uint8_t *p, size_t size)
{
    uint64_t h = lc_snapshot_checksum(p, size);
    int k;
    for (k = 0; k < 8; ++k) p[LC_SNAPSHOT_CHECKSUM_AT + (size_t)k] = (uint8_t)(h >> (8 * k));
}
