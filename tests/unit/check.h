/* check.h: the smallest test harness for qcs's C unit tests.
 *
 * Every check prints one line, "ok NAME" or "FAIL NAME: why", which
 * tests/run-all.sh counts; a test program exits 1 if any check failed.
 * State is per program (one translation unit per test binary). */
#ifndef QCS_CHECK_H
#define QCS_CHECK_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int check_failed_count;
static const char *check_prefix = "unit";

#define CHECK(name, cond) do {                                              \
    if (cond) printf("ok %s: %s\n", check_prefix, (name));                  \
    else { printf("FAIL %s: %s (%s:%d: %s)\n", check_prefix, (name),        \
                  __FILE__, __LINE__, #cond); check_failed_count++; }       \
  } while (0)

/* |got - want| <= tol, printing both on failure. */
#define CHECK_NEAR(name, got, want, tol) do {                               \
    double g_ = (got), w_ = (want), t_ = (tol);                             \
    if (fabs(g_ - w_) <= t_) printf("ok %s: %s\n", check_prefix, (name));   \
    else { printf("FAIL %s: %s: got %.17g want %.17g (tol %g) (%s:%d)\n",   \
                  check_prefix, (name), g_, w_, t_, __FILE__, __LINE__);    \
           check_failed_count++; }                                          \
  } while (0)

#define CHECK_DONE() return check_failed_count ? 1 : 0
#endif
