#include "test.h"
#include "voxdag.h"

static void test_version(void) { CHECK(VOXDAG_VERSION_MAJOR == 0); }

const test_case test_core_cases[] = {
    {"core/version", test_version},
    {NULL, NULL},
};
