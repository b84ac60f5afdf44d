/* A counting allocator for the tests and fuzz targets: fails at call FAIL_AT
   (never when negative), tracks bytes held and their peak, and flags a free
   whose size differs from the allocation's. Include it after voxdag.h. */
#ifndef VOXDAG_COUNT_ALLOC_H
#define VOXDAG_COUNT_ALLOC_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct count_alloc {
    long calls, fail_at;
    uint64_t held, peak;
    int bad_free; /* a free with the wrong size, or of more than was held */
} count_alloc;

static void *ca_alloc(void *user, size_t size) {
    count_alloc *a = (count_alloc *)user;
    unsigned char *p;
    if (a->fail_at >= 0 && a->calls++ == a->fail_at) return NULL;
    p = (unsigned char *)malloc(size + 16);
    if (!p) return NULL;
    memcpy(p, &size, sizeof size);
    a->held += size;
    if (a->held > a->peak) a->peak = a->held;
    return p + 16;
}

static void ca_free(void *user, void *ptr, size_t size) {
    count_alloc *a = (count_alloc *)user;
    size_t stored;
    memcpy(&stored, (unsigned char *)ptr - 16, sizeof stored);
    if (stored != size || a->held < size) a->bad_free = 1;
    a->held -= size;
    free((unsigned char *)ptr - 16);
}

/* Resets A to fail at call FAIL_AT (-1: never) and returns it as a
   voxdag_allocator. */
static voxdag_allocator ca_start(count_alloc *a, long fail_at) {
    voxdag_allocator r;
    memset(a, 0, sizeof *a);
    a->fail_at = fail_at;
    r.alloc = ca_alloc;
    r.free = ca_free;
    r.user = a;
    return r;
}

#endif
