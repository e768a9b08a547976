/* test.h - a zero-dependency test harness for this project's tests.

   Each test program lists its cases in a table and hands it to test_main():

       static void test_something(void) { CHECK_NEAR(1.0, compute(), 1e-12); }
       static const test_case cases[] = { TEST(test_something) };
       int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }

   Run `./prog` for every case, `./prog substring` for the cases whose name contains
   it. A failing check prints file:line, the expression, the expected and the actual
   value, and the case goes on (so one run shows every failure). Every case prints
   PASS or FAIL; the last line is `RESULT <passed> <failed>` (counted in cases), which
   the Makefile sums across the build matrix. The exit status is 1 if any case failed.

   Written in the common subset of C99 and C++ so the same test file builds as both. */
#ifndef TEST_H
#define TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct test_case {
    const char *name;
    void (*fn)(void);
} test_case;

#define TEST(fn) { #fn, fn }
#define TEST_MAIN(argc, argv, cases) \
    test_main((argc), (argv), (cases), (int)(sizeof(cases) / sizeof((cases)[0])))

/* Failed checks in the current case. Tests are single-threaded programs, so a file-
   scope counter is fine here (the library itself keeps no global state). */
static int test__failed_checks;

static inline void test__fail_header(const char *file, int line, const char *what)
{
    fprintf(stderr, "%s:%d: check failed: %s\n", file, line, what);
    test__failed_checks++;
}

static inline void test__check(int ok, const char *file, int line, const char *expr)
{
    if (!ok) test__fail_header(file, line, expr);
}

static inline void test__check_int(long long expected, long long actual, const char *file, int line,
                            const char *expr)
{
    if (expected != actual) {
        test__fail_header(file, line, expr);
        fprintf(stderr, "    expected %lld, actual %lld\n", expected, actual);
    }
}

/* |expected - actual| <= tol; a NaN on either side always fails. */
static inline void test__check_near(double expected, double actual, double tol, const char *file,
                             int line, const char *expr)
{
    double diff = fabs(expected - actual);
    if (!(diff <= tol)) {
        test__fail_header(file, line, expr);
        fprintf(stderr, "    expected %.17g, actual %.17g, |diff| %.3g > tol %.3g\n", expected,
                actual, diff, tol);
    }
}

/* |expected - actual| <= rel * |expected|. */
static inline void test__check_rel(double expected, double actual, double rel, const char *file, int line,
                            const char *expr)
{
    double diff = fabs(expected - actual);
    if (!(diff <= rel * fabs(expected))) {
        test__fail_header(file, line, expr);
        fprintf(stderr, "    expected %.17g, actual %.17g, relative error %.3g > %.3g\n", expected,
                actual, expected != 0.0 ? diff / fabs(expected) : diff, rel);
    }
}

#define CHECK(cond) test__check(!!(cond), __FILE__, __LINE__, #cond)
#define CHECK_INT(expected, actual) \
    test__check_int((long long)(expected), (long long)(actual), __FILE__, __LINE__, \
                    "CHECK_INT(" #expected ", " #actual ")")
#define CHECK_NEAR(expected, actual, tol) \
    test__check_near((double)(expected), (double)(actual), (double)(tol), __FILE__, __LINE__, \
                     "CHECK_NEAR(" #expected ", " #actual ")")
#define CHECK_REL(expected, actual, rel) \
    test__check_rel((double)(expected), (double)(actual), (double)(rel), __FILE__, __LINE__, \
                    "CHECK_REL(" #expected ", " #actual ")")

/* Ends the current case early when a precondition for the rest of it failed. */
#define REQUIRE(cond) \
    do { \
        if (!(cond)) { \
            test__fail_header(__FILE__, __LINE__, "REQUIRE(" #cond ")"); \
            return; \
        } \
    } while (0)

/* True when the build asked for the reduced sizes (g++, clang and sanitizer builds, see
   the Makefile):
   heavy convergence studies shrink, every assertion stays. */
#ifdef TEST_QUICK
#define TEST_IS_QUICK 1
#else
#define TEST_IS_QUICK 0
#endif

static int test_main(int argc, char **argv, const test_case *cases, int count)
{
    const char *filter = argc > 1 ? argv[1] : NULL;
    int passed = 0, failed = 0, i;
    for (i = 0; i < count; i++) {
        if (filter && !strstr(cases[i].name, filter)) continue;
        clock_t start = clock();
        double seconds;
        test__failed_checks = 0;
        cases[i].fn();
        seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
        if (test__failed_checks == 0) {
            passed++;
            printf("PASS %s (%.2f s)\n", cases[i].name, seconds);
        } else {
            failed++;
            printf("FAIL %s (%d checks, %.2f s)\n", cases[i].name, test__failed_checks, seconds);
        }
        fflush(stdout);
    }
    printf("RESULT %d %d\n", passed, failed);
    return failed ? 1 : 0;
}

#endif /* TEST_H */
