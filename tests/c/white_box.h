/* white_box.h - helpers for the C tests that look inside the library (include after check.h and the
 * library's internal world.h; header only, C99, static inline).
 *
 *   wb_all_touches(w, buf)   - every touch between two bodies at the world's state (gap <
 *                              contact_distance), into buf from 0; returns the count (0 on failure,
 *                              which is a failed CHECK)
 */
#ifndef LC_TESTS_WHITE_BOX_H
#define LC_TESTS_WHITE_BOX_H

#include "check.h"
#include "world.h"

static inline int wb_all_touches(lc_world *w, lc_buf *buf)
{
    int a, b, n = 0;
    for (a = 0; a < w->count; ++a)
        for (b = a + 1; b < w->count; ++b) {
            n = lc_collect_touches(w, w->state, a, b, w->def.contact_distance, buf, n);
            CHECK(n >= 0, "%s", "lc_collect_touches failed");
            if (n < 0) return 0;
        }
    return n;
}

#endif /* LC_TESTS_WHITE_BOX_H */
