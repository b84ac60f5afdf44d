/* The fuzz targets' check: a violated property prints what was violated,
   with the target's file and line, and aborts, which libFuzzer and the
   replay main (fuzz_replay.h) both report. */
#ifndef VOXDAG_FUZZ_REQUIRE_H
#define VOXDAG_FUZZ_REQUIRE_H

#include <stdio.h>
#include <stdlib.h>

#define require(ok, what) fuzz_require((ok), (what), __FILE__, __LINE__)

static void fuzz_require(int ok, const char *what, const char *file, int line) {
    if (!ok) {
        fprintf(stderr, "%s:%d: %s\n", file, line, what);
        abort();
    }
}

#endif
