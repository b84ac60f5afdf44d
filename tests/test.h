/* Minimal test harness shared by all suites: explicit registry, one line per
   failure, a closing "N passed, N failed" line. */
#ifndef VOXDAG_TEST_H
#define VOXDAG_TEST_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct test_case {
    const char *name;
    void (*fn)(void);
} test_case;

/* Set by CHECK when the running test case fails. */
extern int test_current_failed;

/* 1 under `test --full` (make test-full): sweeps patch every byte to each of
   its 255 other values instead of +1, -1, 0x00 and 0xff. */
extern int test_full;

/* The value patch K of a sweep gives byte V: K < test_patch_count(). */
static inline int test_patch_count(void) { return test_full ? 256 : 4; }
static inline uint8_t test_patch(uint8_t v, int k) {
    static const int patch[4] = {1, -1, 0, 0xFF}; /* +1, -1, set 0, set 0xff */
    return test_full ? (uint8_t)k : k < 2 ? (uint8_t)(v + patch[k]) : (uint8_t)patch[k];
}

#define CHECK(cond)                                                            \
    do {                                                                       \
        if (!(cond)) {                                                         \
            if (test_current_failed < 8)                                       \
                fprintf(stderr, "  %s:%d: CHECK failed: %s\n", __FILE__,       \
                        __LINE__, #cond);                                      \
            test_current_failed++;                                             \
        }                                                                      \
    } while (0)

#define CHECK_MSG(cond, ...)                                                   \
    do {                                                                       \
        if (!(cond)) {                                                         \
            if (test_current_failed < 8) {                                     \
                fprintf(stderr, "  %s:%d: CHECK failed: %s: ", __FILE__,       \
                        __LINE__, #cond);                                      \
                fprintf(stderr, __VA_ARGS__);                                  \
                fputc('\n', stderr);                                           \
            }                                                                  \
            test_current_failed++;                                             \
        }                                                                      \
    } while (0)

/* Deterministic generator for test data (splitmix64). */
static inline uint64_t test_rand(uint64_t *state) {
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static inline uint32_t test_rand_below(uint64_t *state, uint32_t n) {
    return (uint32_t)(test_rand(state) % n);
}

/* A builder colour sink collecting the colours it gets into RGB; a push
   past CAP colours fails (so that tests can exercise a failing sink). */
typedef struct sink_buf {
    uint8_t *rgb;
    size_t n, cap;
} sink_buf;

static inline int sink_collect(void *user, const uint8_t *rgb, size_t n) {
    sink_buf *s = (sink_buf *)user;
    if (s->n + n > s->cap) return 1;
    memcpy(s->rgb + 3 * s->n, rgb, 3 * n);
    s->n += n;
    return 0;
}

/* Path of the test data folder (tests/data), overridable by VOXDAG_TEST_DATA. */
const char *test_data_dir(void);

#endif
