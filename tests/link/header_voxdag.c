/* voxdag.h in one translation unit: the declarations alone, or with the
   implementation when the command line defines VOXDAG_IMPLEMENTATION.
   CHECK_CUSTOM sets every configuration macro to a custom value;
   CHECK_MALLOC_ONLY / CHECK_FREE_ONLY define one allocator macro, which must
   stop the compilation. tests/check_all.sh compiles it in every
   configuration. */
#if defined(CHECK_CUSTOM) || defined(CHECK_MALLOC_ONLY) || defined(CHECK_FREE_ONLY)
#include <stdlib.h>
#endif
#ifdef CHECK_CUSTOM
static unsigned long check_failed_asserts;
static void *check_malloc(size_t size) { return malloc(size); }
static void check_free(void *p) { free(p); }
#define VOXDAG_MALLOC(sz) check_malloc(sz)
#define VOXDAG_FREE(p) check_free(p)
#define VOXDAG_ASSERT(x) ((x) ? (void)0 : (void)check_failed_asserts++)
#define VOXDAG_MAX_LEVELS 12
#endif
#ifdef CHECK_MALLOC_ONLY
#define VOXDAG_MALLOC(sz) malloc(sz)
#endif
#ifdef CHECK_FREE_ONLY
#define VOXDAG_FREE(p) free(p)
#endif
#include "voxdag.h"
#include "voxdag.h" /* the guard makes a second inclusion harmless */

#include <string.h>

int check_header_voxdag(voxdag_status status);
int check_header_voxdag(voxdag_status status) {
    voxdag_build_opts opts;
    memset(&opts, 0, sizeof opts);
    opts.levels = VOXDAG_MAX_LEVELS;
#ifdef CHECK_CUSTOM
    if (check_failed_asserts) return -1;
#endif
    return (int)opts.levels + (int)status + VOXDAG_VERSION;
}

/* On Windows the implementation includes <windows.h> lean and without the
   min/max macros, and leaves neither switch defined behind it. */
#if defined(_WIN32) && (defined(min) || defined(max) || defined(WIN32_LEAN_AND_MEAN) || defined(NOMINMAX))
#error "<windows.h> leaked min/max, or its switches stayed defined"
#endif
