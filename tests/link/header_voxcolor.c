/* voxcolor.h in one translation unit: the declarations alone, or with the
   implementation when the command line defines VOXCOLOR_IMPLEMENTATION.
   CHECK_CUSTOM sets VOXCOLOR_ASSERT. tests/check_all.sh compiles it in every
   configuration. */
#ifdef CHECK_CUSTOM
static unsigned long check_failed_asserts;
#define VOXCOLOR_ASSERT(x) ((x) ? (void)0 : (void)check_failed_asserts++)
#endif
#include "voxcolor.h"
#include "voxcolor.h" /* the guard makes a second inclusion harmless */

#include <string.h>

int check_header_voxcolor(voxcolor_status status);
int check_header_voxcolor(voxcolor_status status) {
    voxcolor_encode_opts opts;
    memset(&opts, 0, sizeof opts);
    opts.page_shift = VOXCOLOR_DEFAULT_PAGE_SHIFT;
#ifdef CHECK_CUSTOM
    if (check_failed_asserts) return -1;
#endif
    return (int)opts.page_shift + (int)status + VOXCOLOR_VERSION;
}

/* On Windows the implementation includes <windows.h> lean and without the
   min/max macros, and leaves neither switch defined behind it. */
#if defined(_WIN32) && (defined(min) || defined(max) || defined(WIN32_LEAN_AND_MEAN) || defined(NOMINMAX))
#error "<windows.h> leaked min/max, or its switches stayed defined"
#endif
