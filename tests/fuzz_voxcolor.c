/* Fuzz target for voxcolor.h. The first input byte selects what the rest is:
     bit 7 clear: an untrusted stream. It is validated; when accepted, every
       colour (up to a cap) is decoded singly and by ranges, which must agree.
     bit 7 set: RGB8 colours to encode with options from bits 0..6 (error
       bound, metric, weight width; bit 6 set: the next byte picks the page
       shift, 4..10 or the default; the effort from the colour count). The
       stream must validate and every decoded colour, looked up singly, in a
       batch and by range from a copy of the stream's exact size, must be
       within the bound; the encoder on 2..4 threads into a buffer of the
       exact size, and the streaming encoder (on those threads too), fed in
       chunks of a size taken from the input, must make the same bytes.
   Any violation aborts.

   Built with -DFUZZ_LIBFUZZER and -fsanitize=fuzzer this is a libFuzzer
   target (make fuzz-voxcolor). Otherwise main() replays the files and
   folders given on the command line (make test replays the committed
   corpus tests/data/fuzz/voxcolor) and prints "N passed, N failed". */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#include "fuzz_require.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FUZZ_MAX_DECODE 65536

static void fuzz_decode(const uint8_t *data, size_t size) {
    voxcolor_view v;
    voxcolor_error err;
    voxcolor_status st;
    uint8_t *all, one[3];
    size_t n, i;
    memset(&err, 0xa5, sizeof err);
    st = voxcolor_view_init(&v, data, size, &err);
    require(err.status == st && err.message != NULL, "error report differs from the status");
    if (st != VOXCOLOR_OK) {
        require(v.count == 0 && v.data == NULL, "rejected view not cleared");
        require(err.byte_offset <= size, "error offset past the stream");
        return;
    }
    n = v.count < FUZZ_MAX_DECODE ? (size_t)v.count : FUZZ_MAX_DECODE;
    all = (uint8_t *)malloc(3 * n + 3);
    voxcolor_view_get_range(&v, 0, n, all);
    for (i = 0; i < n; i++) {
        voxcolor_view_get(&v, i, one);
        require(memcmp(one, all + 3 * i, 3) == 0, "get and get_range differ");
    }
    /* Batched lookups, backwards. */
    {
        uint64_t *idx = (uint64_t *)calloc(n + 1, sizeof *idx);
        uint8_t *many = (uint8_t *)malloc(3 * n + 3);
        for (i = 0; i < n; i++) idx[i] = n - 1 - i;
        voxcolor_view_get_many(&v, idx, n, many);
        for (i = 0; i < n; i++)
            require(memcmp(many + 3 * i, all + 3 * (n - 1 - i), 3) == 0, "get_many differs");
        free(idx);
        free(many);
    }
    /* The end of long streams too. */
    if (v.count > n) {
        voxcolor_view_get_range(&v, v.count - n, n, all);
        voxcolor_view_get(&v, v.count - 1, one);
        require(memcmp(one, all + 3 * (n - 1), 3) == 0, "last colour differs");
    }
    free(all);
}

static void lab_of(const uint8_t c[3], double lab[3]) {
    double l[3], f[3], xyz[3];
    int k;
    for (k = 0; k < 3; k++) {
        double s = c[k] / 255.0;
        l[k] = s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
    }
    xyz[0] = (0.4124564 * l[0] + 0.3575761 * l[1] + 0.1804375 * l[2]) / 0.95047;
    xyz[1] = 0.2126729 * l[0] + 0.7151522 * l[1] + 0.0721750 * l[2];
    xyz[2] = (0.0193339 * l[0] + 0.1191920 * l[1] + 0.9503041 * l[2]) / 1.08883;
    for (k = 0; k < 3; k++)
        f[k] = xyz[k] > 216.0 / 24389.0 ? cbrt(xyz[k]) : xyz[k] * 841.0 / 108.0 + 4.0 / 29.0;
    lab[0] = 116 * f[1] - 16;
    lab[1] = 500 * (f[0] - f[1]);
    lab[2] = 200 * (f[1] - f[2]);
}

static double distance(const uint8_t *a, const uint8_t *b, int lab) {
    double x[3], y[3], s = 0;
    int k;
    for (k = 0; k < 3; k++) x[k] = a[k], y[k] = b[k];
    if (lab) lab_of(a, x), lab_of(b, y);
    for (k = 0; k < 3; k++) s += (x[k] - y[k]) * (x[k] - y[k]);
    return lab ? sqrt(s) : sqrt(s) / 255.0;
}

/* The streaming encoder's target: a buffer of the one-shot size. */
typedef struct fuzz_sink {
    uint8_t *p;
    size_t size;
} fuzz_sink;

static int fuzz_write(void *user, uint64_t offset, const void *bytes, size_t size) {
    fuzz_sink *k = (fuzz_sink *)user;
    require(offset <= k->size && size <= k->size - offset, "streamed past the one-shot size");
    memcpy(k->p + offset, bytes, size);
    return 1;
}

static void fuzz_stream(const uint8_t *rgb, size_t n, const voxcolor_encode_opts *o,
                        const uint8_t *expect, size_t size) {
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    size_t chunk = n ? rgb[0] % 300 + 1 : 1, at;
    fuzz_sink k;
    k.p = (uint8_t *)malloc(size);
    k.size = size;
    require(voxcolor_encoder_init(enc, n, o, fuzz_write, &k, NULL) == VOXCOLOR_OK, "encoder_init");
    for (at = 0; at < n; at += chunk)
        require(voxcolor_encoder_push(enc, rgb + 3 * at, n - at < chunk ? n - at : chunk) == VOXCOLOR_OK,
                "push");
    require(voxcolor_encoder_finish(enc, NULL) == size && memcmp(k.p, expect, size) == 0,
            "streamed and one-shot streams differ");
    free(k.p);
    free(enc);
}

static void fuzz_roundtrip(unsigned sel, const uint8_t *rgb, size_t size) {
    static const double bounds[8] = {0, 0.004, 0.01, 0.02, 0.04, 0.08, 0.2, 1.0};
    voxcolor_encode_opts o;
    voxcolor_view v;
    size_t n, cap, len, i;
    uint8_t *s, *d, *exact, *one;
    uint64_t *backwards;
    uint32_t page_shift = 0;
    if ((sel >> 6) & 1 && size) { /* 0 (the default), 4..10 */
        page_shift = rgb[0] % 8 ? 3 + rgb[0] % 8 : 0;
        rgb++, size--;
    }
    n = size / 3;
    cap = voxcolor_encode_bound(n);
    s = (uint8_t *)malloc(cap);
    d = (uint8_t *)malloc(3 * n + 3);
    memset(&o, 0, sizeof o);
    o.max_error = bounds[sel & 7];
    o.metric = (sel >> 3) & 1 ? VOXCOLOR_METRIC_CIELAB : VOXCOLOR_METRIC_RGB;
    if (o.metric == VOXCOLOR_METRIC_CIELAB) o.max_error *= 20; /* delta E units */
    o.weight_bits = ((sel >> 4) & 3) == 3 ? 0 : (sel >> 4) & 3;
    o.page_shift = page_shift;
    o.effort = n & 1 ? VOXCOLOR_EFFORT_FAST : VOXCOLOR_EFFORT_SMALLEST;
    len = voxcolor_encode(s, cap, rgb, n, &o, NULL);
    require(len > 0 && len <= cap, "encode failed");
    /* Threads change nothing; neither does a buffer of the exact size. */
    {
        uint8_t *t = (uint8_t *)malloc(len);
        o.threads = 2 + (uint32_t)(n >> 1) % 3;
        require(voxcolor_encode(t, len, rgb, n, &o, NULL) == len && memcmp(t, s, len) == 0,
                "threads change the stream");
        free(t);
    }
    fuzz_stream(rgb, n, &o, s, len);
    /* Decoded from a copy of the exact size: a read past the stream is out
       of bounds. */
    exact = (uint8_t *)malloc(len);
    memcpy(exact, s, len);
    require(voxcolor_view_init(&v, exact, len, NULL) == VOXCOLOR_OK, "own stream rejected");
    require(v.count == n, "count");
    voxcolor_view_get_range(&v, 0, n, d);
    for (i = 0; i < n; i++)
        require(distance(rgb + 3 * i, d + 3 * i, o.metric == VOXCOLOR_METRIC_CIELAB) <=
                    o.max_error + 1e-9,
                "colour over the error bound");
    one = (uint8_t *)malloc(3 * n + 3);
    backwards = (uint64_t *)malloc(n * sizeof *backwards + 1);
    for (i = 0; i < n; i++) {
        voxcolor_view_get(&v, i, one);
        require(memcmp(one, d + 3 * i, 3) == 0, "get and get_range differ");
        backwards[i] = n - 1 - i;
    }
    voxcolor_view_get_many(&v, backwards, n, one);
    for (i = 0; i < n; i++) require(memcmp(one + 3 * i, d + 3 * (n - 1 - i), 3) == 0, "get_many differs");
    free(backwards);
    free(one);
    free(exact);
    free(s);
    free(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    if (data[0] & 0x80) fuzz_roundtrip(data[0], data + 1, size - 1);
    else fuzz_decode(data + 1, size - 1);
    return 0;
}

#ifndef FUZZ_LIBFUZZER
#include "fuzz_replay.h"
#endif
