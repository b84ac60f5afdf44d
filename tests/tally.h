/* Pass/fail counting for the standalone release-build tests
   (tests/test_*_ndebug.c), which print "N passed, N failed". */
#ifndef VOXDAG_TEST_TALLY_H
#define VOXDAG_TEST_TALLY_H
#include <stdio.h>

static int passed, failed;

/* Counts OK; the first failures are printed with WHAT and case number K. */
static void check(int ok, const char *what, unsigned long long k) {
    if (ok) {
        passed++;
    } else {
        failed++;
        if (failed < 20) fprintf(stderr, "FAIL %s (case %llu)\n", what, k);
    }
}
#endif
