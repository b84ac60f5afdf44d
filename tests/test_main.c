/* The test runner: every suite registers its cases here. Usage:
   test [--full] [FILTER...]  runs the cases whose name contains a FILTER; --full
   makes the sweeps exhaustive (test.h). Built with TEST_PORTABLE (the
   foreign targets of tests/matrix.sh), it holds the library's suites only:
   no importers, no images, no tool. */
#include "test.h"

#include <time.h>

int test_current_failed;
int test_full;

extern const test_case test_core_cases[];
extern const test_case test_voxcolor_cases[];
extern const test_case test_format_cases[];
extern const test_case test_voxelize_cases[];
extern const test_case test_raytrace_cases[];
extern const test_case test_gpu_cases[];
extern const test_case test_no_voxcolor_cases[];
extern const test_case test_lod_colors_cases[];
extern const test_case test_edit_cases[];
#ifndef TEST_PORTABLE
extern const test_case test_import_cases[];
extern const test_case test_import_scene_cases[];
extern const test_case test_image_cases[];
extern const test_case test_api_cases[];
extern const test_case test_check_colors_cases[];
#endif

static const test_case *const suites[] = {
    test_core_cases,
    test_voxcolor_cases,
#ifndef TEST_PORTABLE
    test_import_cases,
    test_import_scene_cases,
#endif
    test_format_cases,
    test_voxelize_cases,
    test_raytrace_cases,
    test_gpu_cases,
    test_no_voxcolor_cases,
    test_lod_colors_cases,
    test_edit_cases,
#ifndef TEST_PORTABLE
    test_image_cases,
    test_api_cases,
    test_check_colors_cases,
#endif
};

const char *test_data_dir(void) {
    const char *d = getenv("VOXDAG_TEST_DATA");
    return d ? d : "tests/data";
}

int main(int argc, char **argv) {
    int passed = 0, failed = 0, first, i;
    size_t s;
    test_full = argc > 1 && !strcmp(argv[1], "--full");
    first = 1 + test_full;
    for (s = 0; s < sizeof suites / sizeof suites[0]; s++) {
        const test_case *t;
        for (t = suites[s]; t->name; t++) {
            for (i = first; i < argc && !strstr(t->name, argv[i]); i++) continue;
            if (first < argc && i == argc) continue;
            clock_t start = clock();
            test_current_failed = 0;
            fprintf(stderr, "[ RUN ] %s\n", t->name);
            t->fn();
            if (clock() - start > CLOCKS_PER_SEC) /* where the suite's time goes */
                fprintf(stderr, "[ CPU ] %s: %.1f s\n", t->name, (double)(clock() - start) / CLOCKS_PER_SEC);
            if (test_current_failed) {
                fprintf(stderr, "[FAIL ] %s (%d checks failed)\n", t->name, test_current_failed);
                failed++;
            } else {
                passed++;
            }
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
