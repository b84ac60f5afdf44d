/* voxcolor.h's option and argument checks in a release build: compiled with
   -DNDEBUG (asserts gone) under AddressSanitizer and UndefinedBehaviorSanitizer
   (make test). Every options field is swept over valid and invalid values;
   what is valid is decided here from the documentation of
   voxcolor_encode_opts, not by the library. A valid set must encode a stream
   that validates and keeps the bound; an invalid one must fail with
   VOXCOLOR_ERR_INVALID_ARGUMENT and a message, write nothing and touch no
   memory outside the buffers. NULL pointers likewise. Prints
   "N passed, N failed". */
#ifndef NDEBUG
#error "tests/test_voxcolor_ndebug.c is built with -DNDEBUG"
#endif
#define _DEFAULT_SOURCE /* mmap's MAP_ANONYMOUS under -std=c99 */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tally.h"

#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#include <unistd.h>
/* Streams of every page shift decoded in place from memory that ends where
   the stream ends, followed by a page that cannot be read: any read past the
   end faults (in this release build as in the user's, sanitizers or not). */
static void guard_page_reads(void) {
    static const size_t extra[] = {0, 1, 2, 3, 17};
    size_t pagesize = (size_t)sysconf(_SC_PAGESIZE), n, i, e;
    uint32_t shift;
    for (shift = 4; shift <= 10; shift++)
        for (e = 0; e < sizeof extra / sizeof extra[0]; e++) {
            voxcolor_encode_opts o;
            voxcolor_view v;
            uint8_t *rgb, *s, *map, *at, *one, *all;
            uint64_t *idx;
            size_t cap, size, span;
            int ok = 1;
            n = ((size_t)1 << shift) + extra[e];
            rgb = (uint8_t *)malloc(3 * n);
            one = (uint8_t *)malloc(3 * n);
            all = (uint8_t *)malloc(3 * n);
            idx = (uint64_t *)malloc(n * sizeof *idx);
            for (i = 0; i < 3 * n; i++) rgb[i] = (uint8_t)(i * 131 ^ i >> 2);
            for (i = 0; i < n; i++) idx[i] = n - 1 - i;
            memset(&o, 0, sizeof o);
            o.page_shift = shift;
            cap = voxcolor_encode_bound(n);
            s = (uint8_t *)malloc(cap);
            size = voxcolor_encode(s, cap, rgb, n, &o, NULL);
            span = (size + pagesize - 1) / pagesize * pagesize;
            map = (uint8_t *)mmap(NULL, span + pagesize, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
            if (map == MAP_FAILED || mprotect(map + span, pagesize, PROT_NONE)) {
                check(0, "guard page mapped", shift);
                continue;
            }
            at = map + span - size;
            memcpy(at, s, size);
            if (size == 0 || voxcolor_view_init(&v, at, size, NULL) != VOXCOLOR_OK) ok = 0;
            for (i = 0; ok && i < n; i++) voxcolor_view_get(&v, i, one + 3 * i);
            if (ok) voxcolor_view_get_many(&v, idx, n, all);
            for (i = 0; ok && i < n; i++) ok = memcmp(all + 3 * i, rgb + 3 * (n - 1 - i), 3) == 0;
            if (ok) voxcolor_view_get_range(&v, 0, n, all);
            check(ok && memcmp(one, rgb, 3 * n) == 0 && memcmp(all, rgb, 3 * n) == 0,
                  "lossless stream decoded up to a guard page", shift * 100 + e);
            munmap(map, span + pagesize);
            free(rgb), free(one), free(all), free(idx), free(s);
        }
}
#else
static void guard_page_reads(void) {}
#endif

static int no_writes(void *user, uint64_t offset, const void *bytes, size_t size) {
    (void)offset, (void)bytes, (void)size;
    ++*(unsigned long *)user;
    return 1;
}

/* The documented ranges. */
static int valid(const voxcolor_encode_opts *o) {
    return o->zero_begin == 0 && o->zero_end == 0 && o->max_error >= 0 && !isnan(o->max_error) &&
           (o->metric == VOXCOLOR_METRIC_RGB || o->metric == VOXCOLOR_METRIC_CIELAB) && o->weight_bits <= 4 &&
           (o->page_shift == 0 || (o->page_shift >= 4 && o->page_shift <= 10)) &&
           (o->effort == VOXCOLOR_EFFORT_SMALLEST || o->effort == VOXCOLOR_EFFORT_FAST);
}

int main(void) {
    static const double errors[] = {0, 0.03, 1e300, -0.0, -1e-300, -0.5};
    static const uint32_t shifts[] = {0, 1, 3, 4, 8, 10, 11, 31, 32, 63, 64, 99, 0xffffffffu};
    static const uint32_t bits[] = {0, 3, 4, 5, 8, 0x80000000u};
    static const int32_t metrics[] = {0, 1, 2, -1, 0x7fffffff};
    static const int32_t efforts[] = {0, 1, 2, -1};
    static const uint32_t guards[] = {0, 1, 0xa5a5a5a5u};
    enum { N = 600 };
    uint8_t rgb[3 * N], *buf, *dec = (uint8_t *)malloc(3 * N);
    size_t cap = voxcolor_encode_bound(N), i, e, s, b, m, f, g, count = 0;
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    voxcolor_error err;
    voxcolor_view v;
    unsigned long writes;
    uint64_t r = 7;
    buf = (uint8_t *)malloc(cap);
    for (i = 0; i < 3 * N; i++) {
        r = r * 6364136223846793005ull + 1442695040888963407ull;
        rgb[i] = (uint8_t)((i / 3 % 64) * 3 + (r >> 60)); /* gradients with noise */
    }
    for (e = 0; e < sizeof errors / sizeof errors[0] + 3; e++)
        for (s = 0; s < sizeof shifts / sizeof shifts[0]; s++)
            for (b = 0; b < sizeof bits / sizeof bits[0]; b++)
                for (m = 0; m < sizeof metrics / sizeof metrics[0]; m++)
                    for (f = 0; f < sizeof efforts / sizeof efforts[0]; f++)
                        for (g = 0; g < 3; g++, count++) {
                            voxcolor_encode_opts o;
                            size_t size, k;
                            int ok;
                            /* Sparse: the full product is large; every value of every field
                               still meets the others' valid values. */
                            if ((s && b && (m || f)) || (g && (s || b || m || f))) continue;
                            memset(&o, 0, sizeof o);
                            o.max_error = e == 6 ? NAN : e == 7 ? -INFINITY : e == 8 ? INFINITY : errors[e];
                            o.page_shift = shifts[s];
                            o.weight_bits = bits[b];
                            o.metric = (voxcolor_metric)metrics[m];
                            o.effort = (voxcolor_effort)efforts[f];
                            o.zero_begin = g == 1 ? guards[1 + (count & 1)] : 0;
                            o.zero_end = g == 2 ? guards[1 + (count & 1)] : 0;
                            o.threads = (uint32_t)(count % 3);
                            memset(buf, 0xa5, cap);
                            memset(&err, 0, sizeof err);
                            size = voxcolor_encode(buf, cap, rgb, N, &o, &err);
                            if (!valid(&o)) {
                                for (k = 0; k < cap && buf[k] == 0xa5; k++) continue;
                                check(size == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT && err.message &&
                                          k == cap,
                                      "invalid options rejected, nothing written", count);
                                writes = 0;
                                check(voxcolor_encoder_init(enc, N, &o, no_writes, &writes, NULL) ==
                                              VOXCOLOR_ERR_INVALID_ARGUMENT &&
                                          voxcolor_encoder_push(enc, rgb, N) != VOXCOLOR_OK &&
                                          voxcolor_encoder_finish(enc, NULL) == 0 && writes == 0,
                                      "invalid options rejected by the streaming encoder", count);
                                continue;
                            }
                            ok = size > 0 && err.status == VOXCOLOR_OK &&
                                 voxcolor_view_init(&v, buf, size, NULL) == VOXCOLOR_OK && v.count == N;
                            if (ok && o.metric == VOXCOLOR_METRIC_RGB) {
                                voxcolor_view_get_range(&v, 0, N, dec);
                                for (k = 0; ok && k < N; k++) {
                                    double d = 0;
                                    int c;
                                    for (c = 0; c < 3; c++)
                                        d += ((double)dec[3 * k + c] - rgb[3 * k + c]) *
                                             ((double)dec[3 * k + c] - rgb[3 * k + c]);
                                    ok = sqrt(d) / 255 <= o.max_error + 1e-12;
                                }
                            }
                            check(ok, "valid options encode within the bound", count);
                        }
    /* NULL pointers and counts out of range. */
    check(voxcolor_encode(NULL, cap, rgb, N, NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT,
          "NULL dst", 0);
    check(voxcolor_encode(buf, cap, NULL, N, NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT,
          "NULL colours", 0);
    check(voxcolor_encoder_init(NULL, N, NULL, no_writes, &writes, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT,
          "NULL encoder", 0);
    check(voxcolor_encoder_init(enc, N, NULL, NULL, NULL, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT, "NULL write", 0);
    check(voxcolor_encoder_push(NULL, rgb, N) == VOXCOLOR_ERR_INVALID_ARGUMENT, "push on NULL", 0);
    check(voxcolor_encoder_finish(NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT, "finish NULL", 0);
    writes = 0;
    check(voxcolor_encoder_init(enc, N, NULL, no_writes, &writes, NULL) == VOXCOLOR_OK &&
              voxcolor_encoder_push(enc, NULL, 3) == VOXCOLOR_ERR_INVALID_ARGUMENT &&
              voxcolor_encoder_finish(enc, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT,
          "push NULL colours", 0);
    check(voxcolor_encoder_init(enc, N, NULL, no_writes, &writes, NULL) == VOXCOLOR_OK &&
              voxcolor_encoder_push(enc, rgb, N) == VOXCOLOR_OK &&
              voxcolor_encoder_push(enc, rgb, 1) == VOXCOLOR_ERR_INVALID_ARGUMENT,
          "push past the count", 0);
    guard_page_reads();
    check(voxcolor_view_init(NULL, buf, cap, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT, "NULL view", 0);
    check(voxcolor_view_init(&v, NULL, 100, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT, "NULL stream", 0);
    free(buf);
    free(dec);
    free(enc);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
