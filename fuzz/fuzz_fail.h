/* fuzz_fail: how the fuzz_step harness reports a broken invariant (fuzz_step.c and the checks it calls,
 * fuzz_snapshot_checks.c). It aborts the harness, so that libFuzzer records the input and the replayer's
 * child process fails; the library itself never aborts. */
#ifndef FZ_FUZZ_FAIL_H
#define FZ_FUZZ_FAIL_H

#include <stdio.h>
#include <stdlib.h>

static inline void fz_fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_step: INVARIANT VIOLATED: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

#endif
