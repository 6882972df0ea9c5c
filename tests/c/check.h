/* check.h - a tiny assertion helper for the libcollide C tests (header only, C99).
 *
 * Usage:
 *     #include "check.h"
 *     int main(void) {
 *         CHECK(x > 0, "x must be positive, got %g", x);
 *         CHECK_NEAR(f, 4.905, 1e-12, "normal force");
 *         return CHECK_SUMMARY("test_name");
 *     }
 *
 * CHECK(cond, fmt, ...)          - counts a check; on failure prints file:line, the condition and the
 *                                  printf-style message (a format string is required; use "%s", "" if
 *                                  there is nothing to add).
 * CHECK_NEAR(a, b, tol, what)    - |a - b| <= tol (NaN never passes); on failure prints expected (b),
 *                                  actual (a), |difference| and tolerance.
 * CHECK_REL(a, b, rtol, what)    - |a - b| <= rtol * max(|a|, |b|, 1e-300).
 * CHECK_SUMMARY(name)            - prints "name: N checks, F failed" and evaluates to the process exit
 *                                  code (0 if everything passed, 1 otherwise). Also returns 1 if no
 *                                  check ran at all (a test that asserts nothing is a broken test).
 * check_failures(), check_count()- current counters.
 *
 * All helpers are static inline (unused ones do not warn).
 * The counters are static variables of the header (one copy per test executable, i.e. per
 * translation unit that includes this file); tests are single-threaded.
 */
#ifndef LC_TESTS_CHECK_H
#define LC_TESTS_CHECK_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static int check_n_checks_ = 0;
static int check_n_failed_ = 0;

static inline int check_count(void) { return check_n_checks_; }
static inline int check_failures(void) { return check_n_failed_; }

#if defined(__GNUC__)
#define CHECK_PRINTF_ATTR_ __attribute__((format(printf, 5, 6)))
#else
#define CHECK_PRINTF_ATTR_
#endif

/* Returns cond (so CHECK can be used in an if). */
static inline int check_impl_(int cond, const char *file, int line, const char *expr, const char *fmt, ...)
    CHECK_PRINTF_ATTR_;
static inline int check_impl_(int cond, const char *file, int line, const char *expr, const char *fmt, ...)
{
    va_list ap;
    check_n_checks_++;
    if (cond) return 1;
    check_n_failed_++;
    fprintf(stderr, "FAIL %s:%d: CHECK(%s): ", file, line, expr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    fflush(stderr);
    return 0;
}

static inline int check_near_impl_(double actual, double expected, double tol, const char *what,
                            const char *file, int line, const char *aexpr, const char *bexpr)
{
    double diff = fabs(actual - expected);
    int ok = (diff <= tol); /* false for NaN */
    check_n_checks_++;
    if (ok) return 1;
    check_n_failed_++;
    fprintf(stderr,
            "FAIL %s:%d: CHECK_NEAR(%s, %s) %s: expected %.17g, actual %.17g, |diff| %.3e > tolerance %.3e\n",
            file, line, aexpr, bexpr, what ? what : "", expected, actual, diff, tol);
    fflush(stderr);
    return 0;
}

static inline int check_rel_impl_(double actual, double expected, double rtol, const char *what,
                           const char *file, int line, const char *aexpr, const char *bexpr)
{
    double scale = fabs(actual) > fabs(expected) ? fabs(actual) : fabs(expected);
    double diff = fabs(actual - expected);
    int ok;
    if (scale < 1e-300) scale = 1e-300;
    ok = (diff <= rtol * scale);
    check_n_checks_++;
    if (ok) return 1;
    check_n_failed_++;
    fprintf(stderr,
            "FAIL %s:%d: CHECK_REL(%s, %s) %s: expected %.17g, actual %.17g, rel diff %.3e > rel tolerance %.3e\n",
            file, line, aexpr, bexpr, what ? what : "", expected, actual, diff / scale, rtol);
    fflush(stderr);
    return 0;
}

static inline int check_summary_impl_(const char *name)
{
    if (check_n_checks_ == 0) {
        printf("%s: no checks ran -> FAILED\n", name);
        return 1;
    }
    printf("%s: %d checks, %d failed -> %s\n", name, check_n_checks_, check_n_failed_,
           check_n_failed_ ? "FAILED" : "OK");
    fflush(stdout);
    return check_n_failed_ ? 1 : 0;
}

#define CHECK(cond, ...) check_impl_((cond) ? 1 : 0, __FILE__, __LINE__, #cond, __VA_ARGS__)
#define CHECK_NEAR(a, b, tol, what) \
    check_near_impl_((double)(a), (double)(b), (double)(tol), (what), __FILE__, __LINE__, #a, #b)
#define CHECK_REL(a, b, rtol, what) \
    check_rel_impl_((double)(a), (double)(b), (double)(rtol), (what), __FILE__, __LINE__, #a, #b)
#define CHECK_SUMMARY(name) check_summary_impl_(name)

#endif /* LC_TESTS_CHECK_H */
