/* Tests of voxcolor.h. Expected values come from brute force or from a small
   reference reader written from FORMAT.md, never from the codec itself. */
#include "test.h"
#include "voxcolor.h"

#include <math.h>

// -- Test data

enum { KIND_RANDOM, KIND_SMOOTH, KIND_NOISY, KIND_TEXTURE, KIND_FLAT, KIND_COUNT };
static const char *const kind_names[KIND_COUNT] = {"random", "smooth", "noisy", "texture", "flat"};

static uint8_t clamp8(double v) { return (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5); }

/* Colour arrays of N colours: uniform noise; gradients; gradients with noise;
   a texture-like image (patches of shaded colour with grain and edges, read
   along a 2D Morton curve like a voxelized surface); runs of flat colours. */
static uint8_t *make_colors(int kind, size_t n, uint64_t seed) {
    uint8_t *c = (uint8_t *)malloc(3 * n + 1);
    uint64_t s = seed;
    size_t i;
    for (i = 0; i < n; i++) {
        uint8_t *p = c + 3 * i;
        double t = (double)i, g = (double)test_rand_below(&s, 17) - 8;
        uint32_t x = 0, y = 0, k;
        switch (kind) {
        case KIND_RANDOM:
            for (k = 0; k < 3; k++) p[k] = (uint8_t)test_rand(&s);
            break;
        case KIND_SMOOTH:
            p[0] = clamp8(128 + 120 * sin(t * 0.002));
            p[1] = clamp8(128 + 100 * sin(t * 0.0031 + 1));
            p[2] = clamp8(128 + 90 * cos(t * 0.0017));
            break;
        case KIND_NOISY:
            p[0] = clamp8(128 + 100 * sin(t * 0.01) + g);
            p[1] = clamp8(100 + 60 * sin(t * 0.013) + g * 0.5);
            p[2] = clamp8(90 + 50 * cos(t * 0.007) - g);
            break;
        case KIND_TEXTURE: {
            double patch, shade;
            for (k = 0; k < 20; k++) { /* 2D Morton position of i */
                x |= (uint32_t)((i >> (2 * k)) & 1) << k;
                y |= (uint32_t)((i >> (2 * k + 1)) & 1) << k;
            }
            patch = (double)(((x / 24) * 7 + (y / 16) * 13) % 5);
            shade = 0.6 + 0.4 * sin(x * 0.05) * cos(y * 0.07);
            p[0] = clamp8((60 + 40 * patch) * shade + g);
            p[1] = clamp8((90 + 25 * patch) * shade + g * 0.7);
            p[2] = clamp8((40 + 30 * (4 - patch)) * shade + g * 0.4);
            break;
        }
        default:
            p[0] = (uint8_t)(i / 300 * 37);
            p[1] = (uint8_t)(i / 300 * 91);
            p[2] = (uint8_t)(i / 700 * 53);
            break;
        }
    }
    return c;
}

static size_t encode_new(const uint8_t *rgb, size_t n, const voxcolor_encode_opts *o,
                         uint8_t **out) {
    size_t cap = voxcolor_encode_bound(n), size;
    *out = (uint8_t *)malloc(cap);
    size = voxcolor_encode(*out, cap, rgb, n, o, NULL);
    return size;
}

static double rgb_error(const uint8_t *a, const uint8_t *b) {
    double s = 0;
    int k;
    for (k = 0; k < 3; k++) s += ((double)a[k] - b[k]) * ((double)a[k] - b[k]);
    return sqrt(s) / 255.0;
}

// -- Reference reader (written from FORMAT.md)

static uint64_t ref_le(const uint8_t *p, int n) {
    uint64_t v = 0;
    while (n--) v = v << 8 | p[n];
    return v;
}

static uint32_t ref_bits(const uint8_t *data, uint64_t *pos, int n) {
    uint32_t v = 0;
    int k;
    for (k = 0; k < n; k++, (*pos)++) v |= (uint32_t)((data[*pos / 8] >> (*pos % 8)) & 1) << k;
    return v;
}

static void ref_endpoint(const uint8_t *data, uint64_t *pos, int prec, int out[3]) {
    if (prec) {
        int k;
        for (k = 0; k < 3; k++) out[k] = (int)ref_bits(data, pos, 8);
    } else {
        int r = (int)ref_bits(data, pos, 5), g = (int)ref_bits(data, pos, 6);
        int b = (int)ref_bits(data, pos, 5);
        out[0] = r << 3 | r >> 2;
        out[1] = g << 2 | g >> 4;
        out[2] = b << 3 | b >> 2;
    }
}

/* Decodes a whole valid stream block by block into OUT; returns the number
   of blocks per mode in MODES[0..5] and of blocks with endpoints per
   precision in PRECISIONS[0..1] (RGB565, RGB888); both may be NULL. */
static void ref_decode(const uint8_t *s, uint8_t *out, size_t modes[6], size_t precisions[2]) {
    int ps = s[6], wide = s[7] & 1, ib = ps > 8 ? 2 : 1;
    uint64_t count = ref_le(s + 8, 8), pages = count ? ((count - 1) >> ps) + 1 : 0;
    const uint8_t *data = s + 24 + pages * (wide ? 8 : 4);
    uint64_t page, i = 0;
    for (page = 0; page < pages; page++) {
        const uint8_t *p = data + ref_le(s + 24 + page * (wide ? 8 : 4), wide ? 8 : 4);
        uint32_t blocks = (uint32_t)ref_le(p, ib) + 1, groups = (blocks - 1) / 8 + 1, block, first = 0;
        const uint8_t *group_ends = p + ib, *block_ends = group_ends + groups * ib;
        const uint8_t *nibbles = block_ends + (blocks - groups) * ib;
        const uint8_t *checkpoints = nibbles + (blocks + 1) / 2;
        uint64_t payload0 = 8 * (uint64_t)(checkpoints + 2 * (groups - 1) - data), pos = payload0;
        for (block = 0; block < blocks; block++) {
            int mode, prec, nibble = nibbles[block / 2] >> (4 * (block % 2)) & 15;
            uint32_t len, j, g = block / 8, last;
            int e0[3], e1[3], k;
            if (block && block % 8 == 0) /* a checkpoint: this block's payload offset */
                CHECK(ref_le(checkpoints + 2 * (g - 1), 2) == pos - payload0);
            /* The last block of a group has its last colour in the group
               ends, the others in the block ends. */
            if (block % 8 == 7 || block == blocks - 1) last = (uint32_t)ref_le(group_ends + g * ib, ib);
            else last = (uint32_t)ref_le(block_ends + (7 * g + block % 8) * ib, ib);
            mode = nibble & 7;
            prec = nibble >> 3;
            len = last + 1 - first;
            first += len;
            if (modes) modes[mode]++;
            if (precisions && mode != 5) precisions[prec]++;
            if (mode == 5) {
                for (j = 0; j < len; j++, i++)
                    for (k = 0; k < 3; k++) out[3 * i + k] = (uint8_t)ref_bits(data, &pos, 8);
                continue;
            }
            ref_endpoint(data, &pos, prec, e0);
            if (mode) ref_endpoint(data, &pos, prec, e1);
            for (j = 0; j < len; j++, i++) {
                int w = 0, steps = (1 << mode) - 1;
                if (mode) {
                    double q = ref_bits(data, &pos, mode);
                    w = (int)floor(64.0 * q / steps + 0.5);
                }
                for (k = 0; k < 3; k++)
                    out[3 * i + k] = (uint8_t)(mode ? (e0[k] * (64 - w) + e1[k] * w + 32) >> 6 : e0[k]);
            }
        }
    }
}

// -- Round trips and the error bound

/* Encodes, validates, decodes with get, get_range and the reference reader,
   and checks all agree and every colour is within MAX_ERROR. */
static void check_roundtrip(const uint8_t *rgb, size_t n, const voxcolor_encode_opts *o,
                            const char *what) {
    uint8_t *s, *a = (uint8_t *)malloc(3 * n + 3), *b = (uint8_t *)malloc(3 * n + 3);
    uint8_t *r = (uint8_t *)malloc(3 * n + 3);
    size_t size = encode_new(rgb, n, o, &s), i, bad = 0, differ = 0;
    voxcolor_view v;
    double worst = 0, bound = o ? o->max_error : 0;
    CHECK_MSG(size > 0, "%s", what);
    CHECK_MSG(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK, "%s", what);
    CHECK(v.count == n);
    voxcolor_view_get_range(&v, 0, n, a);
    ref_decode(s, r, NULL, NULL);
    for (i = 0; i < n; i++) {
        double e = rgb_error(rgb + 3 * i, a + 3 * i);
        voxcolor_view_get(&v, i, b + 3 * i);
        if (memcmp(a + 3 * i, b + 3 * i, 3) || memcmp(a + 3 * i, r + 3 * i, 3)) differ++;
        if (e > worst) worst = e;
        if (o && o->metric == VOXCOLOR_METRIC_CIELAB) continue;
        if (e > bound + 1e-12) bad++;
    }
    CHECK_MSG(bad == 0, "%s: %zu colours over %g (worst %g)", what, bad, bound, worst);
    CHECK_MSG(differ == 0, "%s: get, get_range and reference reader differ at %zu", what, differ);
    /* Batched lookups of scattered indices equal single lookups. */
    if (n) {
        uint64_t *idx = (uint64_t *)malloc(n * sizeof *idx), seed = 3;
        for (i = 0; i < n; i++) idx[i] = test_rand_below(&seed, (uint32_t)n);
        voxcolor_view_get_many(&v, idx, n, a);
        for (i = 0; i < n; i++)
            if (memcmp(a + 3 * i, b + 3 * idx[i], 3)) break;
        CHECK_MSG(i == n, "%s: get_many differs at %zu", what, i);
        free(idx);
    }
    /* Ranges starting and ending anywhere equal single lookups. */
    for (i = 0; i < 40 && n; i++) {
        size_t first = (i * 7919) % n, len = (i * 104729) % (n - first) + 1;
        voxcolor_view_get_range(&v, first, len, a);
        CHECK_MSG(memcmp(a, b + 3 * first, 3 * len) == 0, "%s: range %zu+%zu", what, first, len);
    }
    free(s);
    free(a);
    free(b);
    free(r);
}

static void test_error_bound(void) {
    static const double bounds[] = {0, 0.005, 0.01, 0.025, 0.05, 0.1, 0.3, 2};
    int kind;
    size_t k;
    for (kind = 0; kind < KIND_COUNT; kind++) {
        uint8_t *c = make_colors(kind, 20000, 42 + (uint64_t)kind);
        for (k = 0; k < sizeof bounds / sizeof bounds[0]; k++) {
            voxcolor_encode_opts o;
            char what[64];
            memset(&o, 0, sizeof o);
            o.max_error = bounds[k];
            snprintf(what, sizeof what, "%s e_t=%g", kind_names[kind], bounds[k]);
            check_roundtrip(c, 20000, &o, what);
        }
        free(c);
    }
}

/* Weight widths and page sizes change the stream, never the guarantee. */
static void test_options(void) {
    uint8_t *c = make_colors(KIND_TEXTURE, 9000, 7);
    uint32_t bits, shift;
    for (bits = 0; bits <= 4; bits++)
        for (shift = 4; shift <= 10; shift += 3) {
            voxcolor_encode_opts o;
            uint8_t *s;
            size_t modes[6] = {0}, size, m;
            uint8_t *d = (uint8_t *)malloc(3 * 9000);
            char what[64];
            memset(&o, 0, sizeof o);
            o.max_error = 0.03;
            o.weight_bits = bits;
            o.page_shift = shift;
            snprintf(what, sizeof what, "bits=%u shift=%u", bits, shift);
            check_roundtrip(c, 9000, &o, what);
            size = encode_new(c, 9000, &o, &s);
            CHECK(size > 0 && s[6] == shift);
            ref_decode(s, d, modes, NULL);
            for (m = 1; m <= 4; m++)
                if (bits && m != bits) CHECK_MSG(modes[m] == 0, "%s: mode %zu used", what, m);
            free(s);
            free(d);
        }
    free(c);
}

/* Every page shift, at counts around page boundaries (a page that ends
   short), with one block per page or many, decoded from a buffer of exactly
   the stream's size (AddressSanitizer watches its end) by every lookup call,
   against the reference reader. */
static void test_page_boundaries_exact_size(void) {
    static const int kinds[] = {KIND_RANDOM, KIND_FLAT, KIND_SMOOTH};
    static const double bounds[] = {0, 0.05};
    uint32_t shift;
    size_t k, b, m, i;
    for (shift = 4; shift <= 10; shift++)
        for (k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
            for (b = 0; b < sizeof bounds / sizeof bounds[0]; b++)
                for (m = 1; m <= 3; m++) {
                    size_t page = (size_t)1 << shift, counts[4], c;
                    counts[0] = m * page - 1, counts[1] = m * page, counts[2] = m * page + 1;
                    counts[3] = m == 1 ? 1 : (m - 1) * page + 2;
                    for (c = 0; c < 4; c++) {
                        size_t n = counts[c], size;
                        uint8_t *src = make_colors(kinds[k], n, 30 + n), *s, *exact, *want, *got;
                        uint64_t *backwards = (uint64_t *)malloc(n * sizeof *backwards);
                        voxcolor_encode_opts o;
                        voxcolor_view v;
                        int ok = 1;
                        memset(&o, 0, sizeof o);
                        o.max_error = bounds[b];
                        o.page_shift = shift;
                        size = encode_new(src, n, &o, &s);
                        exact = (uint8_t *)malloc(size);
                        memcpy(exact, s, size);
                        want = (uint8_t *)malloc(3 * n);
                        got = (uint8_t *)malloc(3 * n);
                        ref_decode(exact, want, NULL, NULL);
                        CHECK(voxcolor_view_init(&v, exact, size, NULL) == VOXCOLOR_OK);
                        for (i = 0; i < n && ok; i++) {
                            voxcolor_view_get(&v, i, got + 3 * i);
                            ok = memcmp(got + 3 * i, want + 3 * i, 3) == 0;
                        }
                        for (i = 0; i < n; i++) backwards[i] = n - 1 - i;
                        voxcolor_view_get_many(&v, backwards, n, got);
                        for (i = 0; i < n && ok; i++) ok = memcmp(got + 3 * i, want + 3 * (n - 1 - i), 3) == 0;
                        voxcolor_view_get_range(&v, 0, n, got);
                        ok = ok && memcmp(got, want, 3 * n) == 0;
                        if (bounds[b] == 0) ok = ok && memcmp(want, src, 3 * n) == 0;
                        CHECK_MSG(ok, "shift %u %s e_t=%g n=%zu", shift, kind_names[kinds[k]], bounds[b], n);
                        free(src), free(s), free(exact), free(want), free(got), free(backwards);
                    }
                }
}

static void test_lossless(void) {
    int kind;
    for (kind = 0; kind < KIND_COUNT; kind++) {
        uint8_t *c = make_colors(kind, 5000, 3), *s, *d = (uint8_t *)malloc(3 * 5000);
        size_t size = encode_new(c, 5000, NULL, &s);
        voxcolor_view v;
        CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK);
        voxcolor_view_get_range(&v, 0, 5000, d);
        CHECK_MSG(memcmp(c, d, 3 * 5000) == 0, "%s not exact", kind_names[kind]);
        free(c);
        free(s);
        free(d);
    }
}

/* CIE76 delta E with libm, as the CIELAB metric defines it. */
static void lab_of(const uint8_t c[3], double lab[3]) {
    double l[3], X, Y, Z, fx, fy, fz;
    int k;
    for (k = 0; k < 3; k++) {
        double v = c[k] / 255.0;
        l[k] = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
    }
    X = (0.4124564 * l[0] + 0.3575761 * l[1] + 0.1804375 * l[2]) / 0.95047;
    Y = 0.2126729 * l[0] + 0.7151522 * l[1] + 0.0721750 * l[2];
    Z = (0.0193339 * l[0] + 0.1191920 * l[1] + 0.9503041 * l[2]) / 1.08883;
#define LABF(t) ((t) > 216.0 / 24389.0 ? cbrt(t) : (t) * 841.0 / 108.0 + 4.0 / 29.0)
    fx = LABF(X);
    fy = LABF(Y);
    fz = LABF(Z);
#undef LABF
    lab[0] = 116 * fy - 16;
    lab[1] = 500 * (fx - fy);
    lab[2] = 200 * (fy - fz);
}

static void test_cielab(void) {
    static const double bounds[] = {0.5, 2, 5};
    uint8_t *c = make_colors(KIND_NOISY, 6000, 11), *d = (uint8_t *)malloc(3 * 6000), *s;
    size_t k, i;
    for (k = 0; k < 3; k++) {
        voxcolor_encode_opts o;
        voxcolor_view v;
        size_t size, bad = 0;
        memset(&o, 0, sizeof o);
        o.max_error = bounds[k];
        o.metric = VOXCOLOR_METRIC_CIELAB;
        size = encode_new(c, 6000, &o, &s);
        CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK);
        voxcolor_view_get_range(&v, 0, 6000, d);
        for (i = 0; i < 6000; i++) {
            double a[3], b[3];
            lab_of(c + 3 * i, a);
            lab_of(d + 3 * i, b);
            if (sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2])) > bounds[k] + 1e-9)
                bad++;
        }
        CHECK_MSG(bad == 0, "%zu colours over delta E %g", bad, bounds[k]);
        free(s);
    }
    free(c);
    free(d);
}

/* Real colours: images (binary PPM) read along a 2D Morton curve, from
   $VOXCOLOR_TEST_IMAGES (comma-separated) or, when bench/color_fetch.sh has
   run, a few of bench/data/color/ppm. Skipped when there are none. */
static uint8_t *load_ppm_morton(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    unsigned w, h, maxval;
    uint8_t *img, *out;
    uint64_t i, end;
    *n = 0;
    if (!f) return NULL;
    if (fscanf(f, "P6 %u %u %u", &w, &h, &maxval) != 3 || maxval != 255 || fgetc(f) == EOF ||
        (uint64_t)w * h > (1u << 24)) {
        fclose(f);
        return NULL;
    }
    img = (uint8_t *)malloc(3 * (size_t)w * h);
    out = (uint8_t *)malloc(3 * (size_t)w * h);
    if (fread(img, 3, (size_t)w * h, f) != (size_t)w * h) {
        free(img), free(out), fclose(f);
        return NULL;
    }
    fclose(f);
    end = voxcolor_morton2d_encode(w - 1, h - 1) + 1;
    for (i = 0; i < end; i++) {
        uint32_t x, y;
        voxcolor_morton2d_decode(i, &x, &y);
        if (x < w && y < h) memcpy(out + 3 * (*n)++, img + 3 * ((size_t)y * w + x), 3);
    }
    free(img);
    return out;
}

static void test_real_images(void) {
    static const char *const fallback[] = {
        "bench/data/color/ppm/terrain_rock02.ppm", "bench/data/color/ppm/terrain_grass01.ppm",
        "bench/data/color/ppm/terrain_snow01.ppm", "bench/data/color/ppm/skybox.ppm"};
    static const double bounds[] = {0, 0.01, 0.025, 0.05, 0.1};
    const char *env = getenv("VOXCOLOR_TEST_IMAGES");
    char list[4096], *path;
    size_t used = 0, k, f;
    if (env) {
        snprintf(list, sizeof list, "%s", env);
        path = strtok(list, ",");
    } else {
        path = NULL;
    }
    for (f = 0; env ? path != NULL : f < 4; f++) {
        const char *p = env ? path : fallback[f];
        size_t n;
        uint8_t *c = load_ppm_morton(p, &n);
        if (c) {
            used++;
            if (n > (1u << 17)) n = 1u << 17; /* keeps the sanitized run short */
            for (k = 0; k < sizeof bounds / sizeof bounds[0]; k++) {
                voxcolor_encode_opts o;
                char what[256];
                memset(&o, 0, sizeof o);
                o.max_error = bounds[k];
                snprintf(what, sizeof what, "%s e_t=%g", p, bounds[k]);
                check_roundtrip(c, n, &o, what);
            }
            free(c);
        } else if (env) {
            CHECK_MSG(0, "cannot read %s", p);
        }
        if (env) path = strtok(NULL, ",");
    }
    if (!used) fprintf(stderr, "  no real images (run bench/color_fetch.sh bench/data/color): skipped\n");
}

// -- Sizes and buffers

static void test_bound_and_small_buffers(void) {
    size_t n, cap, size, need;
    uint8_t *c = make_colors(KIND_RANDOM, 3000, 5), *s;
    /* Random colours at every count up to 600: worst case for the bound. */
    for (n = 0; n <= 600; n += 1 + n / 16) {
        uint32_t shift;
        for (shift = 4; shift <= 10; shift += 6) {
            voxcolor_encode_opts o;
            memset(&o, 0, sizeof o);
            o.page_shift = shift;
            cap = voxcolor_encode_bound(n);
            s = (uint8_t *)malloc(cap);
            size = voxcolor_encode(s, cap, c, n, &o, NULL);
            CHECK_MSG(size > 0 && size <= cap, "n=%zu size=%zu cap=%zu", n, size, cap);
            free(s);
        }
    }
    CHECK(voxcolor_encode_bound((size_t)-1) == 0);
    /* Exact-size buffers: each too small size returns 0 without writing past
       it (AddressSanitizer watches the allocation). */
    need = encode_new(c, 200, NULL, &s);
    free(s);
    for (cap = 0; cap < need; cap += 1 + cap / 8) {
        uint8_t *b = (uint8_t *)malloc(cap ? cap : 1);
        CHECK(voxcolor_encode(cap ? b : NULL, cap, c, 200, NULL, NULL) == 0);
        free(b);
    }
    free(c);
}

static void test_deterministic(void) {
    uint8_t *c = make_colors(KIND_TEXTURE, 7000, 9), *a, *b;
    voxcolor_encode_opts o;
    size_t sa, sb;
    memset(&o, 0, sizeof o);
    o.max_error = 0.04;
    sa = encode_new(c, 7000, &o, &a);
    sb = encode_new(c, 7000, &o, &b);
    CHECK(sa == sb && memcmp(a, b, sa) == 0);
    free(a);
    free(b);
    free(c);
}

// -- The format, byte by byte

/* Three equal colours, lossless: one single-colour block with RGB888
   endpoint. Every byte follows from FORMAT.md. */
static void test_golden(void) {
    static const uint8_t rgb[9] = {0x12, 0x34, 0x56, 0x12, 0x34, 0x56, 0x12, 0x34, 0x56};
    static const uint8_t expect[] = {
        'V', 'X', 'C', '1', 3, 0, 8, 0,   /* magic, version 3, page shift 8, flags */
        3, 0, 0, 0, 0, 0, 0, 0,           /* 3 colours */
        14, 0, 0, 0, 0, 0, 0, 0,          /* 14 bytes of block data */
        0, 0, 0, 0,                       /* page 0 starts at byte 0 */
        /* blocks - 1 = 0; group 0 ends at colour 2; no other block ends;
           nibble: mode 0, RGB888 (8); no checkpoints (one group); payload
           R G B. */
        0x00, 0x02, 0x08, 0x12, 0x34, 0x56,
        0, 0, 0, 0, 0, 0, 0, 0, /* closing zero bytes */
    };
    uint8_t buf[128];
    size_t size = voxcolor_encode(buf, sizeof buf, rgb, 3, NULL, NULL);
    CHECK(size == sizeof expect);
    CHECK(size == sizeof expect && memcmp(buf, expect, size) == 0);
    CHECK(VOXCOLOR_OFF_COUNT == 8 && VOXCOLOR_OFF_DATA_SIZE == 16 && VOXCOLOR_HEADER_SIZE == 24);
}

/* Appends the low N bits of V at bit *POS of BUF (zeroed), LSB first. */
static void put_bits(uint8_t *buf, unsigned *pos, uint64_t v, unsigned n) {
    unsigned k;
    for (k = 0; k < n; k++, (*pos)++) buf[*pos / 8] |= (uint8_t)(((v >> k) & 1) << (*pos % 8));
}

/* A stream of 5 colours in one page of 16 assembled by hand from FORMAT.md:
   an interpolated RGB565 block of 3 colours and a raw block of 2 (one group,
   so no checkpoints). The arguments break it in one place. Returns the
   stream size. */
static size_t handmade(uint8_t *s, unsigned mode1, unsigned raw_precision, unsigned length1,
                       unsigned extra_bytes, unsigned table_entry) {
    uint8_t *data = s + 28;
    unsigned pos = 0, k;
    memset(s, 0, 64);
    memcpy(s, "VXC1", 4);
    s[4] = 3;                             /* format version */
    s[6] = 4;                             /* pages of 16 colours */
    s[8] = 5;                             /* 5 colours */
    s[24] = (uint8_t)table_entry;         /* page 0 starts at data byte 0 */
    put_bits(data, &pos, 2 - 1, 8); /* 2 blocks */
    /* Last colours: of group 0 (its last block: 4), then of block 0. */
    put_bits(data, &pos, 4, 8);
    put_bits(data, &pos, length1 - 1, 8);
    /* Nibbles: mode 2, RGB565; mode 5 (raw). */
    put_bits(data, &pos, mode1 | 0 << 3 | (5 | raw_precision << 3) << 4, 8);
    /* e0 = (31,0,0), e1 = (0,63,31); weights 0 2 3 */
    put_bits(data, &pos, 31 | 0 << 5 | 0 << 11, 16);
    put_bits(data, &pos, 0 | 63 << 5 | 31 << 11, 16);
    for (k = 0; k < 3; k++) put_bits(data, &pos, k ? k + 1 : 0, mode1); /* 2 bits if valid */
    /* Raw colours (3,2,1) and (0xfd,0xfe,0xff). */
    put_bits(data, &pos, 0x010203, 24);
    put_bits(data, &pos, 0xfffefd, 24);
    if (mode1 == 2) CHECK(pos == 118); /* 15 bytes */
    s[16] = (uint8_t)((pos + 7) / 8 + 8 + extra_bytes); /* then 8 zero bytes */
    return 28 + s[16];
}

static void test_handmade_stream(void) {
    uint8_t s[64], out[3 * 5];
    voxcolor_view v;
    size_t size = handmade(s, 2, 0, 3, 0, 0);
    CHECK(size == 24 + 4 + 15 + 8);
    unsigned m;
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK);
    voxcolor_view_get_range(&v, 0, 5, out);
    CHECK(out[0] == 255 && out[1] == 0 && out[2] == 0);
    /* weight 2 of 2 bits = round(64 * 2 / 3) = 43: (e0 * 21 + e1 * 43 + 32) >> 6 */
    CHECK(out[3] == 84 && out[4] == 171 && out[5] == 171);
    CHECK(out[6] == 0 && out[7] == 255 && out[8] == 255);
    CHECK(out[9] == 3 && out[10] == 2 && out[11] == 1);
    CHECK(out[12] == 0xfd && out[13] == 0xfe && out[14] == 0xff);
    /* Each defect alone is rejected. */
    for (m = 6; m < 8; m++) {
        size = handmade(s, m, 0, 3, 0, 0);
        CHECK_MSG(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT, "mode %u", m);
    }
    size = handmade(s, 2, 1, 3, 0, 0);
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 4, 0, 0); /* blocks of 4 and 1: payloads do not match */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 6, 0, 0); /* last colours 5 then 4: not growing */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 5, 0, 0); /* last colours 4 and 4 */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 3, 1, 0); /* 9 closing bytes */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 3, 0, 1); /* page table points past the start */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 3, 0, 0);
    s[28 + 14] |= 0x80; /* a padding bit */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
    size = handmade(s, 2, 0, 3, 0, 0);
    s[size - 1] = 1; /* a closing byte */
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_ERR_CORRUPT);
}

// -- Untrusted input

static void decode_all(const voxcolor_view *v) {
    uint8_t *a = (uint8_t *)malloc(3 * (size_t)v->count + 3), b[3];
    size_t i;
    voxcolor_view_get_range(v, 0, (size_t)v->count, a);
    for (i = 0; i < v->count; i++) {
        voxcolor_view_get(v, i, b);
        if (memcmp(a + 3 * i, b, 3)) {
            CHECK_MSG(0, "range and single decode differ at %zu", i);
            break;
        }
    }
    free(a);
}

/* Every truncation is rejected; every byte patched (+1, -1, 0, 0xff, each
   bit; under --full every value) is rejected or decodes in bounds. */
static void test_mutations(void) {
    uint8_t *c = make_colors(KIND_TEXTURE, 700, 13), *s;
    static const double bounds[] = {0, 0.02, 0.08};
    size_t k;
    for (k = 0; k < 3; k++) {
        voxcolor_encode_opts o;
        size_t size, cut, i, accepted = 0;
        memset(&o, 0, sizeof o);
        o.max_error = bounds[k];
        o.page_shift = 6;
        size = encode_new(c, 700, &o, &s);
        for (cut = 0; cut < size; cut++) {
            uint8_t *t = (uint8_t *)malloc(cut ? cut : 1);
            voxcolor_view v;
            memcpy(t, s, cut);
            CHECK_MSG(voxcolor_view_init(&v, cut ? t : NULL, cut, NULL) != VOXCOLOR_OK, "cut %zu", cut);
            free(t);
        }
        {
            uint8_t *t = (uint8_t *)malloc(size + 1);
            voxcolor_view v;
            memcpy(t, s, size);
            t[size] = 0;
            CHECK(voxcolor_view_init(&v, t, size + 1, NULL) == VOXCOLOR_ERR_TRAILING);
            free(t);
        }
        for (i = 0; i < size; i++) {
            static const int patch[] = {1, -1, 0x100, 0x1ff, -2};
            uint8_t *t = (uint8_t *)malloc(size);
            int p;
            for (p = 0; p < (test_full ? 256 : 5 + 8); p++) {
                voxcolor_view v;
                memcpy(t, s, size);
                if (test_full) t[i] = (uint8_t)p;
                else if (p >= 5) t[i] ^= (uint8_t)(1u << (p - 5));
                else if (patch[p] == 0x100) t[i] = 0;
                else if (patch[p] == 0x1ff) t[i] = 0xff;
                else t[i] = (uint8_t)(t[i] + patch[p]);
                if (memcmp(t, s, size) == 0) continue;
                if (voxcolor_view_init(&v, t, size, NULL) == VOXCOLOR_OK) {
                    accepted++;
                    decode_all(&v);
                }
            }
            free(t);
        }
        /* Colour bits are free to change, so some patches must be accepted. */
        CHECK(accepted > 0);
        free(s);
    }
    free(c);
}

static void test_rejects_garbage(void) {
    uint8_t *c = make_colors(KIND_NOISY, 300, 2), *s, buf[256];
    size_t size = encode_new(c, 300, NULL, &s), i, n;
    uint64_t r = 99;
    voxcolor_view v;
#define WITH(off, val, expect)                                             \
    do {                                                                   \
        uint8_t *t = (uint8_t *)malloc(size);                              \
        memcpy(t, s, size);                                                \
        t[off] = (uint8_t)(val);                                           \
        CHECK(voxcolor_view_init(&v, t, size, NULL) == (expect));                \
        free(t);                                                           \
    } while (0)
    WITH(0, 'W', VOXCOLOR_ERR_BAD_MAGIC);
    WITH(4, 1, VOXCOLOR_ERR_VERSION); /* the previous layout */
    WITH(5, 1, VOXCOLOR_ERR_VERSION);
    WITH(6, 3, VOXCOLOR_ERR_CORRUPT);
    WITH(6, 11, VOXCOLOR_ERR_CORRUPT);
    WITH(7, 2, VOXCOLOR_ERR_CORRUPT);
    WITH(15, 0x80, VOXCOLOR_ERR_TRUNCATED); /* 2^63 colours */
    WITH(23, 0x80, VOXCOLOR_ERR_TRUNCATED); /* 2^63 data bytes */
#undef WITH
    CHECK(voxcolor_view_init(&v, NULL, 0, NULL) == VOXCOLOR_ERR_TRUNCATED);
    CHECK(v.count == 0 && v.data == NULL);
    /* Random bytes behind a plausible header. */
    for (i = 0; i < 3000; i++) {
        size_t k, pages;
        uint64_t count = test_rand_below(&r, 60);
        n = 24 + test_rand_below(&r, 200);
        for (k = 0; k < n; k++) buf[k] = (uint8_t)test_rand(&r);
        memcpy(buf, "VXC1\2\0", 6);
        buf[6] = (uint8_t)(4 + test_rand_below(&r, 3));
        buf[7] = 0;
        pages = count ? (size_t)((count - 1) >> buf[6]) + 1 : 0;
        for (k = 0; k < 8; k++) buf[8 + k] = (uint8_t)(count >> (8 * k));
        if (n < 24 + 4 * pages) continue;
        for (k = 0; k < 8; k++) buf[16 + k] = (uint8_t)((n - 24 - 4 * pages) >> (8 * k));
        if (voxcolor_view_init(&v, buf, n, NULL) == VOXCOLOR_OK) decode_all(&v);
    }
    for (i = 0; i < VOXCOLOR_STATUS_COUNT; i++)
        CHECK(strlen(voxcolor_status_string((voxcolor_status)i)) > 0);
    CHECK(voxcolor_version() == VOXCOLOR_VERSION);
    free(s);
    free(c);
}

/* A stream rewritten with 8-byte page table entries decodes the same. */
static void test_wide_table(void) {
    uint8_t *c = make_colors(KIND_SMOOTH, 1000, 4), *s, *t, *a = (uint8_t *)malloc(3000),
            *b = (uint8_t *)malloc(3000);
    voxcolor_encode_opts o;
    voxcolor_view v;
    size_t size, pages = (1000 + 255) / 256, i;
    memset(&o, 0, sizeof o);
    o.max_error = 0.02;
    size = encode_new(c, 1000, &o, &s);
    t = (uint8_t *)malloc(size + 4 * pages);
    memcpy(t, s, 24);
    t[7] = 1;
    for (i = 0; i < pages; i++) {
        memset(t + 24 + 8 * i, 0, 8);
        memcpy(t + 24 + 8 * i, s + 24 + 4 * i, 4);
    }
    memcpy(t + 24 + 8 * pages, s + 24 + 4 * pages, size - 24 - 4 * pages);
    CHECK(voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK);
    voxcolor_view_get_range(&v, 0, 1000, a);
    CHECK(voxcolor_view_init(&v, t, size + 4 * pages, NULL) == VOXCOLOR_OK && v.wide == 1);
    voxcolor_view_get_range(&v, 0, 1000, b);
    CHECK(memcmp(a, b, 3000) == 0);
    free(s);
    free(t);
    free(a);
    free(b);
    free(c);
}

// -- Streaming encoder

/* A growing stream: bytes placed where the encoder says, each byte written
   exactly once, block data in order, the header last. FAIL_AT > 0 makes that
   call (1-based) fail. */
typedef struct sink {
    uint8_t *bytes, *written;
    size_t cap, calls, fail_at, overlaps, data_end, disorder;
    uint64_t data_offset;
    int header_seen;
} sink;

static int sink_write(void *user, uint64_t offset, const void *bytes, size_t size) {
    sink *k = (sink *)user;
    size_t i;
    if (++k->calls == k->fail_at) return 0;
    if (offset + size > k->cap) {
        size_t cap = 2 * (size_t)(offset + size);
        k->bytes = (uint8_t *)realloc(k->bytes, cap);
        k->written = (uint8_t *)realloc(k->written, cap);
        memset(k->written + k->cap, 0, cap - k->cap);
        k->cap = cap;
    }
    memcpy(k->bytes + offset, bytes, size);
    for (i = 0; i < size; i++) k->overlaps += k->written[offset + i]++ != 0;
    if (k->header_seen) k->disorder++;
    if (offset == 0) k->header_seen = 1;
    if (offset >= k->data_offset) {
        if (offset != k->data_end) k->disorder++;
        k->data_end = (size_t)(offset + size);
    }
    return 1;
}

/* Streams N colours in chunks of CHUNK (0: random sizes) into *K. */
static uint64_t stream_encode(const uint8_t *rgb, size_t n, const voxcolor_encode_opts *o,
                              size_t chunk, sink *k) {
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    uint64_t seed = n + chunk, size;
    size_t at = 0;
    memset(k, 0, sizeof *k);
    voxcolor_encoder_init(enc, n, o, sink_write, k, NULL);
    k->data_offset = k->data_end = (size_t)voxcolor_encoder_data_offset(enc);
    while (at < n) {
        size_t m = chunk ? chunk : test_rand_below(&seed, 700);
        if (m > n - at) m = n - at;
        if (voxcolor_encoder_push(enc, rgb + 3 * at, m) != VOXCOLOR_OK) break;
        at += m;
    }
    size = voxcolor_encoder_finish(enc, NULL);
    free(enc);
    return size;
}

/* Streamed in chunks of any size, the stream is the one-shot encoder's, byte
   for byte; the writes tile it. */
static void test_stream_equals_oneshot(void) {
    static const size_t counts[] = {0, 1, 15, 16, 17, 255, 256, 257, 1000, 4096, 20000};
    static const size_t chunks[] = {1, 2, 255, 256, 257, 1024, 100000, 0};
    static const double bounds[] = {0, 0.025, 0.1};
    size_t c, h, b, shift;
    uint8_t *rgb = make_colors(KIND_TEXTURE, 20000, 11);
    for (c = 0; c < sizeof counts / sizeof counts[0]; c++)
        for (b = 0; b < sizeof bounds / sizeof bounds[0]; b++)
            for (shift = 4; shift <= 10; shift += 3) {
                voxcolor_encode_opts o;
                uint8_t *one;
                size_t n = counts[c], size;
                memset(&o, 0, sizeof o);
                o.max_error = bounds[b];
                o.page_shift = (uint32_t)shift;
                size = encode_new(rgb, n, &o, &one);
                for (h = 0; h < sizeof chunks / sizeof chunks[0]; h++) {
                    sink k;
                    uint64_t got = stream_encode(rgb, n, &o, chunks[h], &k);
                    size_t i, holes = 0;
                    for (i = 0; i < got; i++) holes += k.written[i] != 1;
                    CHECK_MSG(got == size && memcmp(k.bytes, one, size) == 0,
                              "n=%zu e_t=%g shift=%zu chunk=%zu: %llu vs %zu bytes", n, bounds[b],
                              shift, chunks[h], (unsigned long long)got, size);
                    CHECK_MSG(holes == 0 && k.overlaps == 0 && k.disorder == 0 && k.header_seen,
                              "n=%zu chunk=%zu: holes %zu overlaps %zu disorder %zu", n,
                              chunks[h], holes, k.overlaps, k.disorder);
                    free(k.bytes);
                    free(k.written);
                }
                free(one);
            }
    free(rgb);
}

/* A failing write stops the encoder: push and finish report it. Pushing
   fewer colours than declared fails at finish. */
static void test_stream_failures(void) {
    uint8_t *rgb = make_colors(KIND_NOISY, 30000, 12);
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    size_t calls, fail;
    sink k;
    stream_encode(rgb, 30000, NULL, 0, &k);
    calls = k.calls;
    free(k.bytes);
    free(k.written);
    CHECK(calls > 3);
    for (fail = 1; fail <= calls; fail++) {
        int ok = 1;
        memset(&k, 0, sizeof k);
        k.fail_at = fail;
        voxcolor_encoder_init(enc, 30000, NULL, sink_write, &k, NULL);
        ok &= voxcolor_encoder_push(enc, rgb, 12345) == VOXCOLOR_OK;
        ok &= voxcolor_encoder_push(enc, rgb + 3 * 12345, 30000 - 12345) == VOXCOLOR_OK;
        CHECK(ok == (k.calls < fail)); /* failed exactly when a write failed */
        CHECK_MSG(voxcolor_encoder_finish(enc, NULL) == 0, "write %zu of %zu failed", fail, calls);
        free(k.bytes);
        free(k.written);
    }
    memset(&k, 0, sizeof k);
    voxcolor_encoder_init(enc, 30000, NULL, sink_write, &k, NULL);
    CHECK(voxcolor_encoder_push(enc, rgb, 29999) == VOXCOLOR_OK);
    CHECK(voxcolor_encoder_finish(enc, NULL) == 0);
    free(k.bytes);
    free(k.written);
    /* Above 2^30 colours the page table has 8-byte entries. */
    voxcolor_encoder_init(enc, (1ull << 30) + 1, NULL, sink_write, &k, NULL);
    CHECK(voxcolor_encoder_data_offset(enc) == 24 + 8 * ((1ull << 22) + 1));
    voxcolor_encoder_init(enc, 1ull << 30, NULL, sink_write, &k, NULL);
    CHECK(voxcolor_encoder_data_offset(enc) == 24 + 4 * (1ull << 22));
    free(enc);
    free(rgb);
}

static void test_empty(void) {
    uint8_t buf[64];
    voxcolor_view v;
    size_t size = voxcolor_encode(buf, sizeof buf, NULL, 0, NULL, NULL);
    CHECK(size == 24 + 8);
    CHECK(voxcolor_view_init(&v, buf, size, NULL) == VOXCOLOR_OK && v.count == 0);
}

// -- Options and errors

/* Every out-of-range option, and every NULL pointer the calls do not allow,
   gives VOXCOLOR_ERR_INVALID_ARGUMENT with a message: from voxcolor_encode
   (nothing written to the buffer), voxcolor_encoder_init (then push and
   finish fail and nothing is written) and voxcolor_view_init. The same
   sweep runs under NDEBUG (tests/test_voxcolor_ndebug.c). */
static int count_writes(void *user, uint64_t offset, const void *bytes, size_t size) {
    (void)offset, (void)bytes, (void)size;
    ++*(size_t *)user;
    return 1;
}

static void test_invalid_options(void) {
    uint8_t *c = make_colors(KIND_TEXTURE, 1000, 21), *buf;
    size_t cap = voxcolor_encode_bound(1000), i, k;
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    voxcolor_error err;
    voxcolor_view v;
    buf = (uint8_t *)malloc(cap);
    for (i = 0;; i++) {
        voxcolor_encode_opts o;
        size_t writes = 0;
        memset(&o, 0, sizeof o);
        switch (i) {
        case 0: o.page_shift = 99; break;
        case 1: o.page_shift = 2; break;
        case 2: o.page_shift = 3; break;
        case 3: o.page_shift = 11; break;
        case 4: o.weight_bits = 5; break;
        case 5: o.weight_bits = 0xffffffffu; break;
        case 6: o.metric = (voxcolor_metric)2; break;
        case 7: o.metric = (voxcolor_metric)-1; break;
        case 8: o.max_error = -0.01; break;
        case 9: o.max_error = NAN; break;
        case 10: o.max_error = -INFINITY; break;
        case 11: o.effort = (voxcolor_effort)2; break;
        case 12: o.zero_begin = 1; break;
        case 13: o.zero_end = 0xdeadbeef; break;
        default: break;
        }
        if (i > 13) break;
        memset(buf, 0xa5, cap);
        memset(&err, 0, sizeof err);
        CHECK_MSG(voxcolor_encode(buf, cap, c, 1000, &o, &err) == 0, "option case %zu accepted", i);
        CHECK_MSG(err.status == VOXCOLOR_ERR_INVALID_ARGUMENT && err.message && *err.message, "case %zu", i);
        for (k = 0; k < cap && buf[k] == 0xa5; k++) continue;
        CHECK_MSG(k == cap, "case %zu wrote to the buffer", i);
        CHECK(voxcolor_encode(buf, cap, c, 1000, &o, NULL) == 0); /* ERR may be NULL */
        memset(&err, 0, sizeof err);
        CHECK(voxcolor_encoder_init(enc, 1000, &o, count_writes, &writes, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT);
        CHECK(err.status == VOXCOLOR_ERR_INVALID_ARGUMENT && err.message);
        CHECK(voxcolor_encoder_push(enc, c, 1000) == VOXCOLOR_ERR_INVALID_ARGUMENT);
        CHECK(voxcolor_encoder_finish(enc, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
        CHECK_MSG(writes == 0, "case %zu: the encoder wrote", i);
    }
    /* An infinite bound is valid: every colour fits. */
    {
        voxcolor_encode_opts o;
        memset(&o, 0, sizeof o);
        o.max_error = INFINITY;
        CHECK(voxcolor_encode(buf, cap, c, 1000, &o, &err) > 0 && err.status == VOXCOLOR_OK);
    }
    /* NULL pointers. */
    CHECK(voxcolor_encode(NULL, 100, c, 10, NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encode(buf, cap, NULL, 10, NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encode(buf, cap, NULL, 0, NULL, &err) == 32 && err.status == VOXCOLOR_OK);
    CHECK(voxcolor_encode(buf, 31, c, 0, NULL, &err) == 0 && err.status == VOXCOLOR_ERR_BUFFER_TOO_SMALL);
    CHECK(voxcolor_encoder_init(NULL, 10, NULL, count_writes, NULL, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encoder_init(enc, 10, NULL, NULL, NULL, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encoder_push(NULL, c, 10) == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encoder_finish(NULL, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_encoder_data_offset(NULL) == 0);
    {
        size_t writes = 0;
        CHECK(voxcolor_encoder_init(enc, 10, NULL, count_writes, &writes, &err) == VOXCOLOR_OK);
        CHECK(voxcolor_encoder_push(enc, NULL, 0) == VOXCOLOR_OK);
        CHECK(voxcolor_encoder_push(enc, NULL, 5) == VOXCOLOR_ERR_INVALID_ARGUMENT);
        CHECK(voxcolor_encoder_push(enc, c, 5) == VOXCOLOR_ERR_INVALID_ARGUMENT); /* sticky */
        CHECK(voxcolor_encoder_finish(enc, &err) == 0 && err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
        CHECK(voxcolor_encoder_init(enc, 10, NULL, count_writes, &writes, &err) == VOXCOLOR_OK);
        CHECK(voxcolor_encoder_push(enc, c, 11) == VOXCOLOR_ERR_INVALID_ARGUMENT); /* more than declared */
        CHECK(voxcolor_encoder_init(enc, 10, NULL, count_writes, &writes, &err) == VOXCOLOR_OK);
        CHECK(voxcolor_encoder_push(enc, c, 9) == VOXCOLOR_OK);
        CHECK(voxcolor_encoder_finish(enc, &err) == 0 && err.status == VOXCOLOR_ERR_INCOMPLETE);
    }
    CHECK(voxcolor_view_init(NULL, buf, 32, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT &&
          err.status == VOXCOLOR_ERR_INVALID_ARGUMENT);
    CHECK(voxcolor_view_init(&v, NULL, 32, &err) == VOXCOLOR_ERR_INVALID_ARGUMENT && v.count == 0);
    free(enc);
    free(buf);
    free(c);
}

/* A stream that fails to validate says where: offsets from FORMAT.md. */
static void test_error_offsets(void) {
    static const uint8_t rgb[9] = {0x12, 0x34, 0x56, 0x12, 0x34, 0x56, 0x12, 0x34, 0x56};
    uint8_t s[64], t[65];
    voxcolor_view v;
    voxcolor_error err;
    size_t size = voxcolor_encode(s, sizeof s, rgb, 3, NULL, &err);
    CHECK(size == 42 && err.status == VOXCOLOR_OK);
    CHECK(voxcolor_view_init(&v, s, size, &err) == VOXCOLOR_OK && err.status == VOXCOLOR_OK);
#define EXPECT(stream, n, st, off)                                                          \
    do {                                                                                    \
        memset(&err, 0, sizeof err);                                                        \
        CHECK(voxcolor_view_init(&v, stream, n, &err) == (st));                             \
        CHECK_MSG(err.status == (st) && err.message && err.byte_offset == (uint64_t)(off), \
                  "%s at %llu", err.message ? err.message : "-",                            \
                  (unsigned long long)err.byte_offset);                                     \
    } while (0)
    EXPECT(s, 20, VOXCOLOR_ERR_TRUNCATED, 20); /* the stream's end */
    EXPECT(s, size - 1, VOXCOLOR_ERR_TRUNCATED, size - 1);
    memcpy(t, s, size);
    t[size] = 0;
    EXPECT(t, size + 1, VOXCOLOR_ERR_TRAILING, size); /* the first byte after the data */
    memcpy(t, s, size);
    t[1] = 'Y';
    EXPECT(t, size, VOXCOLOR_ERR_BAD_MAGIC, 0);
    memcpy(t, s, size);
    t[4] = 4;
    EXPECT(t, size, VOXCOLOR_ERR_VERSION, 4);
    memcpy(t, s, size);
    t[6] = 99;
    EXPECT(t, size, VOXCOLOR_ERR_CORRUPT, 6);
    memcpy(t, s, size);
    t[7] = 2;
    EXPECT(t, size, VOXCOLOR_ERR_CORRUPT, 7);
    /* Block data from byte 28: block count, group end, the mode nibble at 30. */
    memcpy(t, s, size);
    t[30] = 0x0e; /* mode 6 */
    EXPECT(t, size, VOXCOLOR_ERR_CORRUPT, 30);
    memcpy(t, s, size);
    t[30] = 0x88; /* a nonzero nibble after the last block's */
    EXPECT(t, size, VOXCOLOR_ERR_CORRUPT, 30);
    memcpy(t, s, size);
    t[size - 3] = 1; /* a closing byte */
    EXPECT(t, size, VOXCOLOR_ERR_CORRUPT, size - 3);
#undef EXPECT
}

// -- Threads and effort

/* A host thread pool: runs the jobs on the calling thread, last first, and
   counts the calls and jobs. */
typedef struct host_pool {
    size_t runs, jobs;
} host_pool;

static void host_run(void *user, voxcolor_job_fn job, void *job_user, uint32_t count) {
    host_pool *p = (host_pool *)user;
    uint32_t i;
    p->runs++;
    p->jobs += count;
    for (i = count; i--;) job(job_user, i);
}

/* Any thread count, the host's pool and the built-in one, one-shot and
   streamed, give the serial encoder's bytes; so does a buffer of the exact
   size (smaller batches), and one byte less fails cleanly. */
static void test_threads_identical(void) {
    static const size_t counts[] = {0, 5, 256, 257, 3000, 70000};
    static const uint32_t threads[] = {2, 3, 8, 200};
    static const double bounds[] = {0, 0.025, 0.1};
    uint8_t *rgb = make_colors(KIND_TEXTURE, 70000, 31);
    size_t c, b, t, shift;
    for (c = 0; c < sizeof counts / sizeof counts[0]; c++)
        for (b = 0; b < sizeof bounds / sizeof bounds[0]; b++)
            for (shift = 4; shift <= 10; shift += 3) {
                voxcolor_encode_opts o;
                uint8_t *one, *par;
                size_t n = counts[c], size, cap = voxcolor_encode_bound(n), got;
                host_pool hp;
                sink k;
                voxcolor_error err;
                memset(&o, 0, sizeof o);
                o.max_error = bounds[b];
                o.page_shift = (uint32_t)shift;
                size = encode_new(rgb, n, &o, &one);
                par = (uint8_t *)malloc(cap + 1);
                for (t = 0; t < sizeof threads / sizeof threads[0]; t++) {
                    o.threads = threads[t];
                    got = voxcolor_encode(par, cap, rgb, n, &o, NULL);
                    CHECK_MSG(got == size && memcmp(par, one, size) == 0, "n=%zu e_t=%g shift=%zu threads=%u", n,
                              bounds[b], shift, threads[t]);
                }
                o.threads = 2;
                /* The exact size: the parallel scratch shrinks to what is left. */
                got = voxcolor_encode(par, size, rgb, n, &o, NULL);
                CHECK_MSG(got == size && memcmp(par, one, size) == 0, "n=%zu shift=%zu exact buffer", n, shift);
                got = voxcolor_encode(par, size - 1, rgb, n, &o, &err);
                CHECK(got == 0 && err.status == VOXCOLOR_ERR_BUFFER_TOO_SMALL);
                memset(&hp, 0, sizeof hp);
                o.threads = 0;
                o.thread_pool.run = host_run;
                o.thread_pool.user = &hp;
                got = voxcolor_encode(par, cap, rgb, n, &o, NULL);
                CHECK_MSG(got == size && memcmp(par, one, size) == 0, "n=%zu shift=%zu host pool", n, shift);
                if (n >= 3000) CHECK_MSG(hp.runs > 0 && hp.jobs >= 2 * hp.runs, "n=%zu: pool unused", n);
                /* Streamed with the host's pool and with 3 threads, in chunks. */
                got = stream_encode(rgb, n, &o, n > 1000 ? 1000 + shift : 0, &k);
                CHECK_MSG(got == size && memcmp(k.bytes, one, size) == 0 && k.disorder == 0 && k.overlaps == 0,
                          "n=%zu shift=%zu streamed, host pool", n, shift);
                free(k.bytes);
                free(k.written);
                memset(&o.thread_pool, 0, sizeof o.thread_pool);
                o.threads = 3;
                got = stream_encode(rgb, n, &o, n, &k);
                CHECK_MSG(got == size && memcmp(k.bytes, one, size) == 0 && k.disorder == 0 && k.overlaps == 0,
                          "n=%zu shift=%zu streamed, 3 threads", n, shift);
                free(k.bytes);
                free(k.written);
                free(par);
                free(one);
            }
    free(rgb);
}

/* A failing write stops a parallel streaming encoder too. */
static void test_threads_write_failure(void) {
    uint8_t *rgb = make_colors(KIND_NOISY, 200000, 12);
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    voxcolor_encode_opts o;
    voxcolor_error err;
    size_t calls, fail;
    sink k;
    memset(&o, 0, sizeof o);
    o.max_error = 0.02;
    o.threads = 2;
    stream_encode(rgb, 200000, &o, 200000, &k);
    calls = k.calls;
    free(k.bytes);
    free(k.written);
    CHECK(calls > 3);
    for (fail = 1; fail <= calls; fail++) {
        memset(&k, 0, sizeof k);
        k.fail_at = fail;
        CHECK(voxcolor_encoder_init(enc, 200000, &o, sink_write, &k, NULL) == VOXCOLOR_OK);
        voxcolor_encoder_push(enc, rgb, 200000);
        CHECK_MSG(voxcolor_encoder_finish(enc, &err) == 0 && err.status == VOXCOLOR_ERR_WRITE, "write %zu of %zu",
                  fail, calls);
        CHECK_MSG(k.calls == fail, "write %zu of %zu failed, then %zu calls", fail, calls, k.calls);
        free(k.bytes);
        free(k.written);
    }
    free(enc);
    free(rgb);
}

/* The fast effort keeps the bound, uses one endpoint precision per stream,
   and equals the default where the default tries only one. */
static void test_effort(void) {
    static const double bounds[] = {0, 0.01, 0.02, 0.025, 0.03, 0.038, 0.05, 0.1};
    uint8_t *c = make_colors(KIND_TEXTURE, 20000, 17);
    size_t k;
    for (k = 0; k < sizeof bounds / sizeof bounds[0]; k++) {
        voxcolor_encode_opts o;
        uint8_t *fast, *def, *d = (uint8_t *)malloc(3 * 20000);
        size_t sf, sd, fp[2] = {0, 0}, dp[2] = {0, 0};
        char what[64];
        memset(&o, 0, sizeof o);
        o.max_error = bounds[k];
        sd = encode_new(c, 20000, &o, &def);
        o.effort = VOXCOLOR_EFFORT_FAST;
        snprintf(what, sizeof what, "fast e_t=%g", bounds[k]);
        check_roundtrip(c, 20000, &o, what);
        sf = encode_new(c, 20000, &o, &fast);
        ref_decode(fast, d, NULL, fp);
        ref_decode(def, d, NULL, dp);
        CHECK_MSG(!fp[0] || !fp[1], "%s: both precisions", what);
        if (!dp[0] || !dp[1]) CHECK_MSG(sf == sd && memcmp(fast, def, sd) == 0, "%s differs", what);
        else CHECK_MSG(sf >= sd, "%s smaller than the default", what);
        free(fast);
        free(def);
        free(d);
    }
    free(c);
}

// -- 2D mapping

static void test_morton2d(void) {
    uint64_t count;
    uint32_t x, y, w, h;
    uint64_t r = 1;
    size_t i;
    for (i = 0; i < 1000; i++) {
        uint64_t idx = test_rand(&r) >> 2;
        voxcolor_morton2d_decode(idx, &x, &y);
        CHECK(voxcolor_morton2d_encode(x, y) == idx);
    }
    voxcolor_morton2d_decode(6, &x, &y); /* 0b110: x = 0b10... bit0 x, bit1 y */
    CHECK(x == 2 && y == 1);
    /* Image size against brute force: the rows actually visited. */
    for (count = 1; count <= 5000; count += 1 + count / 50) {
        uint32_t maxx = 0, maxy = 0;
        uint64_t k;
        for (k = 0; k < count; k++) {
            voxcolor_morton2d_decode(k, &x, &y);
            if (x > maxx) maxx = x;
            if (y > maxy) maxy = y;
        }
        voxcolor_image_size(count, &w, &h);
        CHECK_MSG(h == maxy + 1 && w > maxx && w >= h && (w & (w - 1)) == 0 && w / 2 <= maxx + 1,
                  "count %llu: %ux%u", (unsigned long long)count, w, h);
    }
    {
        uint8_t *c = make_colors(KIND_RANDOM, 777, 8), *img, *back = (uint8_t *)malloc(3 * 777);
        voxcolor_image_size(777, &w, &h);
        img = (uint8_t *)malloc(3 * (size_t)w * h);
        voxcolor_to_image(img, w, h, c, 777);
        voxcolor_from_image(back, 777, img, w, h);
        CHECK(memcmp(c, back, 3 * 777) == 0);
        voxcolor_morton2d_decode(776, &x, &y);
        CHECK(memcmp(img + 3 * ((size_t)y * w + x), c + 3 * 776, 3) == 0);
        free(c);
        free(img);
        free(back);
    }
}

const test_case test_voxcolor_cases[] = {
    {"voxcolor/error_bound", test_error_bound},
    {"voxcolor/options", test_options},
    {"voxcolor/real_images", test_real_images},
    {"voxcolor/lossless", test_lossless},
    {"voxcolor/page_boundaries_exact_size", test_page_boundaries_exact_size},
    {"voxcolor/cielab", test_cielab},
    {"voxcolor/bound_and_small_buffers", test_bound_and_small_buffers},
    {"voxcolor/deterministic", test_deterministic},
    {"voxcolor/golden", test_golden},
    {"voxcolor/handmade_stream", test_handmade_stream},
    {"voxcolor/mutations", test_mutations},
    {"voxcolor/rejects_garbage", test_rejects_garbage},
    {"voxcolor/wide_table", test_wide_table},
    {"voxcolor/stream_equals_oneshot", test_stream_equals_oneshot},
    {"voxcolor/stream_failures", test_stream_failures},
    {"voxcolor/empty", test_empty},
    {"voxcolor/morton2d", test_morton2d},
    {"voxcolor/invalid_options", test_invalid_options},
    {"voxcolor/error_offsets", test_error_offsets},
    {"voxcolor/threads_identical", test_threads_identical},
    {"voxcolor/threads_write_failure", test_threads_write_failure},
    {"voxcolor/effort", test_effort},
    {NULL, NULL},
};
