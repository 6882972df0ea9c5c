/* Wall time per pipeline stage (lc_counters time_*), for finding where a scene's time goes. Off by
 * default: each stage entry then costs one predictable branch instead of two clock reads. */
#define _POSIX_C_SOURCE 199309L
#include <time.h>
#include "world.h"

/* A monotonic clock: stages last microseconds, and the vDSO's CLOCK_MONOTONIC costs ~25 ns where a
 * CPU-time clock is a system call (~0.3 us, more than a small scene's whole stage). */
double lc_stage_clock(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0) return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

lc_status lc_world_set_stage_timing(lc_world *w, int on)
{
    if (w == NULL) return LC_ERR_NULL;
    if (on != 0 && on != 1) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "stage timing is 0 (off) or 1 (on), not %d", on);
    w->stage_timing = on;
    w->error[0] = '\0';
    return LC_OK;
}

lc_status lc_world_get_stage_timing(const lc_world *w, int *out)
{
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    *out = w->stage_timing;
    return LC_OK;
}
