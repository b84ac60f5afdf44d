/* The test runner: every suite registers its cases here. Usage:
   test [--full] [FILTER]  runs the cases whose name contains FILTER; --full
   makes the sweeps exhaustive (test.h). */
#include "test.h"

int test_current_failed;
int test_full;

extern const test_case test_core_cases[];
extern const test_case test_voxcolor_cases[];
extern const test_case test_import_cases[];
extern const test_case test_import_scene_cases[];
extern const test_case test_format_cases[];
extern const test_case test_voxelize_cases[];
extern const test_case test_raytrace_cases[];
extern const test_case test_image_cases[];
extern const test_case test_check_colors_cases[];

static const test_case *const suites[] = {
    test_core_cases,
    test_voxcolor_cases,
    test_import_cases,
    test_import_scene_cases,
    test_format_cases,
    test_voxelize_cases,
    test_raytrace_cases,
    test_image_cases,
    test_check_colors_cases,
};

const char *test_data_dir(void) {
    const char *d = getenv("VOXDAG_TEST_DATA");
    return d ? d : "tests/data";
}

int main(int argc, char **argv) {
    const char *filter;
    int passed = 0, failed = 0;
    size_t s;
    test_full = argc > 1 && !strcmp(argv[1], "--full");
    filter = argc > 1 + test_full ? argv[1 + test_full] : NULL;
    for (s = 0; s < sizeof suites / sizeof suites[0]; s++) {
        const test_case *t;
        for (t = suites[s]; t->name; t++) {
            if (filter && !strstr(t->name, filter)) continue;
            test_current_failed = 0;
            fprintf(stderr, "[ RUN ] %s\n", t->name);
            t->fn();
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
