/* vdag build --verify-colors (examples/check_colors.c): the streaming check
   against brute force (each colour decoded alone, its distance computed
   here), on a lossy stream of more than one slice, with the encoder's bound
   and a too-tight one (also split in jobs), on a corrupted stream and on a
   short raw file. */
#include "test.h"
#include "examples/check_colors.h"

#include <math.h>

/* Colours that vary smoothly with a little noise, so that blocks interpolate. */
static uint8_t *check_colors_input(size_t n, uint64_t seed) {
    uint8_t *rgb = (uint8_t *)malloc(3 * n);
    size_t i;
    for (i = 0; rgb && i < n; i++) {
        int k;
        for (k = 0; k < 3; k++)
            rgb[3 * i + k] = (uint8_t)((i / (97 + 13 * k) * (k + 3) + test_rand_below(&seed, 9)) & 0xFF);
    }
    return rgb;
}

static FILE *check_colors_raw(const uint8_t *rgb, size_t n) {
    FILE *f = tmpfile();
    if (f && fwrite(rgb, 3, n, f) != n) {
        fclose(f);
        return NULL;
    }
    if (f) rewind(f);
    return f;
}

/* Brute force: the largest error, its first colour, and the colours over BOUND. */
static void check_colors_oracle(const voxcolor_view *v, const uint8_t *rgb, double bound, vdag_color_check *o) {
    uint64_t i;
    o->max_error = 0;
    o->worst = 0;
    o->over = 0;
    o->first_over = UINT64_MAX;
    for (i = 0; i < v->count; i++) {
        uint8_t c[3];
        double d;
        voxcolor_view_get(v, i, c);
        d = sqrt(((double)c[0] - rgb[3 * i]) * ((double)c[0] - rgb[3 * i]) +
                 ((double)c[1] - rgb[3 * i + 1]) * ((double)c[1] - rgb[3 * i + 1]) +
                 ((double)c[2] - rgb[3 * i + 2]) * ((double)c[2] - rgb[3 * i + 2])) / 255.0;
        if (d > o->max_error) o->max_error = d, o->worst = i;
        if (d > bound) {
            if (!o->over) o->first_over = i;
            o->over++;
        }
    }
}

static int check_colors_same(const vdag_color_check *a, const vdag_color_check *b) {
    return fabs(a->max_error - b->max_error) < 1e-12 && a->worst == b->worst && a->over == b->over &&
           a->first_over == b->first_over;
}

static uint8_t *check_colors_encode(const uint8_t *rgb, size_t n, double e, size_t *size) {
    voxcolor_encode_opts o;
    size_t cap = voxcolor_encode_bound(n);
    uint8_t *s = (uint8_t *)malloc(cap);
    memset(&o, 0, sizeof o);
    o.max_error = e;
    o.effort = VOXCOLOR_EFFORT_FAST;
    *size = s ? voxcolor_encode(s, cap, rgb, n, &o, NULL) : 0;
    return s;
}

/* A RUN hook for vdag_check_colors_on: the jobs on the calling thread, last first. */
static void check_colors_backwards(void *user, void (*job)(void *job_user, uint32_t index), void *job_user,
                                   uint32_t count) {
    (void)user;
    while (count > 0) job(job_user, --count);
}

static void test_check_colors_bound(void) {
    const size_t n = ((size_t)1 << 20) + 777; /* two slices */
    uint8_t *rgb = check_colors_input(n, 1), *s;
    size_t size;
    voxcolor_view v;
    vdag_color_check got, want;
    double bounds[2];
    int b;
    FILE *f;
    CHECK(rgb != NULL);
    if (!rgb) return;
    s = check_colors_encode(rgb, n, 0.05, &size);
    CHECK(size > 0 && voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK);
    f = check_colors_raw(rgb, n);
    CHECK(f != NULL);
    bounds[0] = 0.05;
    bounds[1] = 0;
    for (b = 0; f && size && b < 2; b++) {
        check_colors_oracle(&v, rgb, b ? bounds[1] : bounds[0], &want);
        /* The too-tight bound: just under the largest error of the stream. */
        if (!b) bounds[1] = want.max_error * 0.999;
        rewind(f);
        CHECK(vdag_check_colors(&v, f, bounds[b], &got));
        CHECK_MSG(check_colors_same(&got, &want), "bound %g: max %g at %llu, %llu over from %llu; brute force %g at %llu, %llu from %llu",
                  bounds[b], got.max_error, (unsigned long long)got.worst, (unsigned long long)got.over,
                  (unsigned long long)got.first_over, want.max_error, (unsigned long long)want.worst,
                  (unsigned long long)want.over, (unsigned long long)want.first_over);
        CHECK(b ? got.over > 0 : got.over == 0 && got.max_error > 0.02);
        { /* the same in 2, 3 and 7 jobs */
            static const uint32_t threads[] = {2, 3, 7};
            size_t t;
            for (t = 0; t < sizeof threads / sizeof threads[0]; t++) {
                vdag_color_check par;
                rewind(f);
                CHECK(vdag_check_colors_on(&v, f, bounds[b], check_colors_backwards, NULL, threads[t], &par));
                CHECK_MSG(check_colors_same(&par, &want), "bound %g, %u jobs: max %g at %llu, %llu over from %llu",
                          bounds[b], threads[t], par.max_error, (unsigned long long)par.worst,
                          (unsigned long long)par.over, (unsigned long long)par.first_over);
            }
        }
    }
    if (f) fclose(f);
    free(s);
    free(rgb);
}

static void test_check_colors_corrupt(void) {
    const size_t n = 5000;
    uint8_t *rgb = check_colors_input(n, 2), *s;
    size_t size, at;
    voxcolor_view v;
    vdag_color_check got, want;
    FILE *f = NULL;
    int tried = 0;
    CHECK(rgb != NULL);
    if (!rgb) return;
    s = check_colors_encode(rgb, n, 0, &size);
    CHECK(size > 100);
    /* A lossless stream with one payload byte changed, found from the end:
       it still validates but decodes some colour wrong. */
    memset(&want, 0, sizeof want);
    for (at = size; at-- > size - 100 && !want.over;) {
        s[at] ^= 0x5A;
        if (voxcolor_view_init(&v, s, size, NULL) == VOXCOLOR_OK) {
            tried = 1;
            check_colors_oracle(&v, rgb, 0, &want);
        }
        if (!want.over) s[at] ^= 0x5A;
    }
    CHECK(tried && want.over > 0);
    if (want.over) f = check_colors_raw(rgb, n);
    if (f) {
        CHECK(vdag_check_colors(&v, f, 0, &got));
        CHECK(check_colors_same(&got, &want));
        /* A raw file one colour short cannot be compared. */
        fclose(f);
        f = check_colors_raw(rgb, n - 1);
        CHECK(f && !vdag_check_colors(&v, f, 0, &got));
    }
    if (f) fclose(f);
    free(s);
    free(rgb);
}

const test_case test_check_colors_cases[] = {
    {"check_colors/every colour against brute force, e_t and a too-tight bound", test_check_colors_bound},
    {"check_colors/a corrupted stream and a short raw file", test_check_colors_corrupt},
    {NULL, NULL},
};
