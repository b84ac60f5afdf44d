/* Colour codec benchmark (make bench-color): voxcolor.h against the
   reimplemented baselines of bench/color_baselines.h on the same colour
   arrays, in one run. Prints markdown tables shaped like Dolonius et al.
   2017, Tables 2-4: size (% of 24-bit), global MSE, PSNR, largest error,
   encode speed, random and coherent lookup speed.

   Usage: bench_color [--max N] [--quick] [--threads-only] [--peers SCRIPT] NAME=IMAGE.ppm[,...] ...
   Each image (binary PPM, as bench/color_fetch.sh makes them) is read along
   a 2D Morton curve, as a voxelized surface's colours would be, and the
   images of one NAME are concatenated into one colour array. Speeds are per
   core: single-threaded, in CPU time, but in the first table of each set:
   the encoder on 1 and 2 threads, default and fast effort (per CPU-second
   and per wall second, with the previous encoder's sizes; --threads-only
   prints only that table). With --peers, the array is also mapped
   to a 2D Morton image (voxcolor_to_image) and run through external image
   codecs by SCRIPT (bench/color_peers.sh); their decoded output is mapped
   back and measured like ours. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, popen */
#define VOXCOLOR_IMPLEMENTATION
#include "../voxcolor.h"
#include "color_baselines.h"
#include "color_previous.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double wall_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double cpu_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// -- Inputs

/* Appends the pixels of a binary PPM to *RGB along a Morton curve. */
static int load_ppm(const char *path, uint8_t **rgb, size_t *n, size_t *cap) {
    FILE *f = fopen(path, "rb");
    unsigned w, h, maxval;
    uint8_t *img;
    uint64_t i, size;
    if (!f) return 0;
    if (fscanf(f, "P6 %u %u %u", &w, &h, &maxval) != 3 || maxval != 255 || fgetc(f) == EOF) {
        fclose(f);
        return 0;
    }
    img = (uint8_t *)malloc(3 * (size_t)w * h);
    if (!img || fread(img, 3, (size_t)w * h, f) != (size_t)w * h) {
        free(img);
        fclose(f);
        return 0;
    }
    fclose(f);
    if (*n + (size_t)w * h > *cap) {
        *cap = 2 * (*n + (size_t)w * h);
        *rgb = (uint8_t *)realloc(*rgb, 3 * *cap);
    }
    /* Every pixel once, in Morton order of its position. */
    size = voxcolor_morton2d_encode(w - 1, h - 1) + 1;
    for (i = 0; i < size; i++) {
        uint32_t x, y;
        voxcolor_morton2d_decode(i, &x, &y);
        if (x < w && y < h) memcpy(*rgb + 3 * (*n)++, img + 3 * ((size_t)y * w + x), 3);
    }
    free(img);
    return 1;
}

// -- Measurements

typedef struct result {
    const char *method;
    char setting[48];
    uint64_t bits;
    double mse, psnr, max_error, encode_rate, random_rate, coherent_rate;
    double batch_rate; /* voxcolor_view_get_many; 0 for the baselines */
} result;

typedef void (*get_fn)(const void *codec, size_t i, uint8_t out[3]);

static void get_ours(const void *codec, size_t i, uint8_t out[3]) {
    voxcolor_view_get((const voxcolor_view *)codec, i, out);
}

static void get_baseline(const void *codec, size_t i, uint8_t out[3]) {
    color_codec_get((const color_codec *)codec, i, out);
}

static size_t *random_indices(size_t n, size_t count) {
    size_t *idx = (size_t *)malloc(count * sizeof *idx), i;
    uint64_t s = 0x9e3779b97f4a7c15ull;
    for (i = 0; i < count; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        idx[i] = (size_t)(s % n);
    }
    return idx;
}

/* Quality over all colours and lookup speeds. */
static void measure(result *r, const uint8_t *rgb, size_t n, const void *codec, get_fn get,
                    const size_t *idx, size_t lookups) {
    double se = 0, worst = 0, t;
    size_t i, coherent = n < 4000000 ? n : 4000000;
    unsigned sum = 0;
    for (i = 0; i < n; i++) {
        uint8_t d[3];
        int e0, e1, e2, e;
        get(codec, i, d);
        e0 = d[0] - rgb[3 * i], e1 = d[1] - rgb[3 * i + 1], e2 = d[2] - rgb[3 * i + 2];
        e = e0 * e0 + e1 * e1 + e2 * e2;
        se += e;
        if (e > worst) worst = e;
    }
    r->mse = se / (3.0 * (double)n);
    r->psnr = r->mse > 0 ? 10 * log10(255.0 * 255.0 / r->mse) : INFINITY;
    r->max_error = sqrt(worst) / 255.0;
    t = cpu_seconds();
    for (i = 0; i < lookups; i++) {
        uint8_t d[3];
        get(codec, idx[i], d);
        sum += d[0];
    }
    r->random_rate = (double)lookups / (cpu_seconds() - t);
    t = cpu_seconds();
    for (i = 0; i < coherent; i++) {
        uint8_t d[3];
        get(codec, i, d);
        sum += d[1];
    }
    r->coherent_rate = (double)coherent / (cpu_seconds() - t);
    if (sum == 1) fprintf(stderr, " "); /* keeps the loops */
}

static void print_row(const result *r, size_t n) {
    char psnr[16], batch[16];
    snprintf(psnr, sizeof psnr, isinf(r->psnr) ? "lossless" : "%.1f", r->psnr);
    snprintf(batch, sizeof batch, r->batch_rate > 0 ? "%.1f" : "-", r->batch_rate / 1e6);
    printf("| %s | %s | %.2f%% | %.2f | %s | %.4f | %.2f | %.1f | %s | %.1f |\n", r->method,
           r->setting, 100.0 * (double)r->bits / (24.0 * (double)n), r->mse, psnr, r->max_error,
           r->encode_rate / 1e6, r->random_rate / 1e6, batch, r->coherent_rate / 1e6);
    fflush(stdout);
}

static void run_ours(result *r, const uint8_t *rgb, size_t n, const voxcolor_encode_opts *o,
                     const size_t *idx, size_t lookups) {
    size_t cap = voxcolor_encode_bound(n), size;
    uint8_t *buf = (uint8_t *)malloc(cap);
    voxcolor_view v;
    double t = cpu_seconds();
    size = voxcolor_encode(buf, cap, rgb, n, o, NULL);
    r->encode_rate = (double)n / (cpu_seconds() - t);
    r->bits = 8 * (uint64_t)size;
    if (voxcolor_view_init(&v, buf, size, NULL) != VOXCOLOR_OK) {
        fprintf(stderr, "bench_color: own stream rejected\n");
        exit(1);
    }
    measure(r, rgb, n, &v, get_ours, idx, lookups);
    {
        uint64_t *wide = (uint64_t *)malloc(lookups * sizeof *wide);
        uint8_t *out = (uint8_t *)malloc(3 * lookups);
        size_t i;
        for (i = 0; i < lookups; i++) wide[i] = idx[i];
        t = cpu_seconds();
        voxcolor_view_get_many(&v, wide, lookups, out);
        r->batch_rate = (double)lookups / (cpu_seconds() - t);
        free(wide);
        free(out);
    }
    if (o->metric == VOXCOLOR_METRIC_RGB && r->max_error > o->max_error + 1e-12) {
        fprintf(stderr, "bench_color: error bound broken\n");
        exit(1);
    }
    free(buf);
}

static void run_baseline(result *r, const uint8_t *rgb, size_t n, int kind, double e, uint32_t k,
                         const size_t *idx, size_t lookups) {
    double t = cpu_seconds();
    color_codec *c = kind == 0 ? color_alg1_encode(rgb, n, e)
                     : kind == 1 ? color_hdag_encode(rgb, n, e)
                                 : color_dado_encode(rgb, n, k);
    r->encode_rate = (double)n / (cpu_seconds() - t);
    if (!c) {
        fprintf(stderr, "bench_color: out of memory\n");
        exit(1);
    }
    r->bits = color_codec_bits(c);
    r->batch_rate = 0;
    measure(r, rgb, n, c, get_baseline, idx, lookups);
    color_codec_free(c);
}

// -- Encoder threads and effort

/* The encoder at 1 and 2 threads, default and fast effort: size (next to
   the previous encoder's, and whether the bytes are the same), colours per
   CPU-second (all threads' CPU time) and per wall second, each the best of
   REPS runs, and the wall-time speed-up of 2 threads. */
static void run_threads(const char *name, const uint8_t *rgb, size_t n, int reps) {
    static const double bounds[] = {0, 0.01, 0.025, 0.05, 0.1};
    size_t cap = voxcolor_encode_bound(n), k;
    uint8_t *buf = (uint8_t *)malloc(cap), *prev = (uint8_t *)malloc(cap), *first = (uint8_t *)malloc(cap);
    printf("Encoder threads and effort, %s (1 and 2 threads, default and fast effort, best of %d runs each; "
           "CPU time of all threads; the previous encoder is the one before the parallel encoder):\n\n",
           name, reps);
    printf("| e_t | effort | size (%% of 24-bit) | previous encoder | same bytes | 1 thread (M/CPU-s) "
           "| 2 threads (M/CPU-s) | 1 thread (M/s wall) | 2 threads (M/s wall) | speed-up (wall) |\n"
           "|---|---|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < sizeof bounds / sizeof bounds[0]; k++) {
        size_t psize = previous_voxcolor_encode(prev, cap, rgb, n, bounds[k]), fsize = 0;
        int effort;
        for (effort = 0; effort < 2; effort++) {
            double cpu[2] = {1e30, 1e30}, wall[2] = {1e30, 1e30};
            size_t size = 0;
            int t, r, same = 1;
            char pcol[32], scol[16];
            for (t = 0; t < 2; t++)
                for (r = 0; r < reps; r++) {
                    voxcolor_encode_opts o;
                    double c0, w0, c, w;
                    memset(&o, 0, sizeof o);
                    o.max_error = bounds[k];
                    o.effort = effort ? VOXCOLOR_EFFORT_FAST : VOXCOLOR_EFFORT_SMALLEST;
                    o.threads = (uint32_t)(t + 1);
                    c0 = cpu_seconds();
                    w0 = wall_seconds();
                    size = voxcolor_encode(buf, cap, rgb, n, &o, NULL);
                    w = wall_seconds() - w0;
                    c = cpu_seconds() - c0;
                    if (!size) {
                        fprintf(stderr, "bench_color: encode failed\n");
                        exit(1);
                    }
                    if (c < cpu[t]) cpu[t] = c;
                    if (w < wall[t]) wall[t] = w;
                    /* Every run the same bytes: threads change nothing. */
                    if (!t && !r) memcpy(first, buf, size), fsize = size;
                    else if (size != fsize || memcmp(first, buf, size)) same = -1;
                }
            if (same < 0) {
                fprintf(stderr, "bench_color: the thread count changed the stream\n");
                exit(1);
            }
            if (!psize) snprintf(pcol, sizeof pcol, "-"), snprintf(scol, sizeof scol, "-");
            else if (effort) snprintf(pcol, sizeof pcol, "%.2f%%", 100.0 * (double)psize / (3.0 * (double)n)),
                             snprintf(scol, sizeof scol, "%s", psize == size && !memcmp(prev, buf, size) ? "yes" : "no");
            else snprintf(pcol, sizeof pcol, "%.2f%%", 100.0 * (double)psize / (3.0 * (double)n)),
                 snprintf(scol, sizeof scol, "%s", psize == size && !memcmp(prev, buf, size) ? "yes" : "**no**");
            printf("| %g | %s | %.2f%% | %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f |\n", bounds[k],
                   effort ? "fast" : "default", 100.0 * (double)size / (3.0 * (double)n), pcol, scol,
                   (double)n / cpu[0] / 1e6, (double)n / cpu[1] / 1e6, (double)n / wall[0] / 1e6,
                   (double)n / wall[1] / 1e6, wall[0] / wall[1]);
            fflush(stdout);
        }
    }
    printf("\n");
    free(buf);
    free(prev);
    free(first);
}

// -- External codecs on the 2D-mapped array

static int write_ppm(const char *path, const uint8_t *img, uint32_t w, uint32_t h) {
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f) return 0;
    fprintf(f, "P6\n%u %u\n255\n", (unsigned)w, (unsigned)h);
    ok = fwrite(img, 3, (size_t)w * h, f) == (size_t)w * h;
    return fclose(f) == 0 && ok;
}

static uint8_t *read_ppm(const char *path, uint32_t *w, uint32_t *h) {
    FILE *f = fopen(path, "rb");
    unsigned ww, hh, maxval;
    uint8_t *img = NULL;
    if (!f) return NULL;
    if (fscanf(f, "P6 %u %u %u", &ww, &hh, &maxval) == 3 && maxval == 255 && fgetc(f) != EOF) {
        img = (uint8_t *)malloc(3 * (size_t)ww * hh);
        if (img && fread(img, 3, (size_t)ww * hh, f) != (size_t)ww * hh) {
            free(img);
            img = NULL;
        }
    }
    fclose(f);
    *w = ww;
    *h = hh;
    return img;
}

/* Maps the array to an image, has SCRIPT compress and decode it with each
   external codec, and prints a row per codec setting: size of the compressed
   file against 24 bits per colour, and the errors of the decoded colours. */
static void run_peers(const char *script, const uint8_t *rgb, size_t n, int quick) {
    static const char *dir = "bench/out/color_peers";
    char cmd[1024], line[1024], path[256];
    uint32_t w, h;
    uint8_t *img, *back = (uint8_t *)malloc(3 * n);
    FILE *p;
    voxcolor_image_size(n, &w, &h);
    img = (uint8_t *)malloc(3 * (size_t)w * h);
    voxcolor_to_image(img, w, h, rgb, n);
    snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
    snprintf(path, sizeof path, "%s/morton.ppm", dir);
    if (system(cmd) != 0 || !write_ppm(path, img, w, h)) {
        printf("| (external codecs) | cannot write %s | | | | | | | | |\n", path);
        free(img);
        free(back);
        return;
    }
    free(img);
    snprintf(cmd, sizeof cmd, "sh %s %s %s %s", script, dir, path, quick ? "quick" : "");
    p = popen(cmd, "r");
    while (p && fgets(line, sizeof line, p)) {
        char *codec = strtok(line, "|"), *setting = strtok(NULL, "|"), *bytes = strtok(NULL, "|"),
             *file = strtok(NULL, "|\n");
        uint32_t dw, dh;
        uint8_t *dec;
        double se = 0, worst = 0, mse;
        size_t i;
        if (!codec || !setting || !bytes || !file) continue;
        if (!strcmp(bytes, "skip")) {
            printf("| %s | %s | skipped: %s | | | | | | | |\n", codec, setting, file);
            continue;
        }
        dec = read_ppm(file, &dw, &dh);
        if (!dec || dw < w || dh < h) {
            printf("| %s | %s | skipped: unreadable output | | | | | | | |\n", codec, setting);
            free(dec);
            continue;
        }
        voxcolor_from_image(back, n, dec, dw, dh);
        free(dec);
        for (i = 0; i < 3 * n; i += 3) {
            int e0 = back[i] - rgb[i], e1 = back[i + 1] - rgb[i + 1], e2 = back[i + 2] - rgb[i + 2];
            double e = e0 * e0 + e1 * e1 + e2 * e2;
            se += e;
            if (e > worst) worst = e;
        }
        mse = se / (3.0 * (double)n);
        printf("| %s | %s | %.2f%% | %.2f | ", codec, setting,
               100.0 * 8.0 * strtod(bytes, NULL) / (24.0 * (double)n), mse);
        if (mse > 0) printf("%.1f", 10 * log10(255.0 * 255.0 / mse));
        else printf("lossless");
        printf(" | %.4f | - | - | - | - |\n", sqrt(worst) / 255.0);
        fflush(stdout);
    }
    if (p) pclose(p);
    free(back);
}

static void machine(char *out, size_t size) {
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[256];
    snprintf(out, size, "unknown CPU");
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
            snprintf(out, size, "%s", strchr(line, ':') + 2);
            out[strcspn(out, "\n")] = 0;
            break;
        }
    if (f) fclose(f);
}

int main(int argc, char **argv) {
    static const double ours_e[] = {0, 0.01, 0.025, 0.038, 0.05, 0.1};
    static const double base_e[] = {0.01, 0.025, 0.038, 0.05, 0.1};
    static const uint32_t dado_k[] = {0, 4096, 2048, 256};
    size_t max = 0, a, k;
    int quick = 0, threads_only = 0;
    const char *peers = NULL;
    char cpu[128];
    machine(cpu, sizeof cpu);
    printf("Machine: %s; compiler: %s; voxcolor %d.%d.%d (stream format %d). "
           "Speeds in millions per second per core (CPU time).\n\n",
           cpu, __VERSION__, VOXCOLOR_VERSION_MAJOR, VOXCOLOR_VERSION_MINOR,
           VOXCOLOR_VERSION_PATCH, VOXCOLOR_FORMAT_VERSION);
    for (a = 1; a < (size_t)argc; a++) {
        char *spec = argv[a], *files, *file;
        uint8_t *rgb = NULL;
        size_t n = 0, cap = 0, images = 0, lookups;
        size_t *idx;
        result r;
        if (!strcmp(spec, "--max") && a + 1 < (size_t)argc) {
            max = (size_t)strtoull(argv[++a], NULL, 10);
            continue;
        }
        if (!strcmp(spec, "--quick")) {
            quick = 1;
            continue;
        }
        if (!strcmp(spec, "--threads-only")) {
            threads_only = 1;
            continue;
        }
        if (!strcmp(spec, "--peers") && a + 1 < (size_t)argc) {
            peers = argv[++a];
            continue;
        }
        files = strchr(spec, '=');
        if (!files) {
            fprintf(stderr, "bench_color: expected NAME=IMAGE.ppm[,...], got %s\n", spec);
            return 1;
        }
        *files++ = 0;
        for (file = strtok(files, ","); file; file = strtok(NULL, ","), images++)
            if (!load_ppm(file, &rgb, &n, &cap)) {
                fprintf(stderr, "bench_color: cannot read %s\n", file);
                return 1;
            }
        if (max && n > max) n = max;
        lookups = 2000000;
        idx = random_indices(n, lookups);
        printf("### %s: %zu colours from %zu image%s\n\n", spec, n, images, images == 1 ? "" : "s");
        run_threads(spec, rgb, n, quick ? 1 : 3);
        if (threads_only) {
            free(idx);
            free(rgb);
            continue;
        }
        printf("| codec | setting | size (%% of 24-bit) | MSE | PSNR (dB) | max error | encode "
               "| random lookup | random, batched | coherent lookup |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n");
        for (k = 0; k < sizeof ours_e / sizeof ours_e[0]; k++) {
            voxcolor_encode_opts o;
            memset(&o, 0, sizeof o);
            o.max_error = ours_e[k];
            r.method = "voxcolor";
            snprintf(r.setting, sizeof r.setting, "e_t %g", ours_e[k]);
            run_ours(&r, rgb, n, &o, idx, lookups);
            print_row(&r, n);
        }
        {
            voxcolor_encode_opts o;
            memset(&o, 0, sizeof o);
            o.max_error = 0.05;
            o.weight_bits = 3;
            r.method = "voxcolor";
            snprintf(r.setting, sizeof r.setting, "e_t 0.05, 3-bit weights only");
            run_ours(&r, rgb, n, &o, idx, lookups);
            print_row(&r, n);
            o.weight_bits = 0;
            o.page_shift = 6;
            snprintf(r.setting, sizeof r.setting, "e_t 0.05, pages of 64");
            run_ours(&r, rgb, n, &o, idx, lookups);
            print_row(&r, n);
            o.page_shift = 0;
            o.metric = VOXCOLOR_METRIC_CIELAB;
            o.max_error = 2;
            snprintf(r.setting, sizeof r.setting, "CIELAB delta E 2");
            run_ours(&r, rgb, n, &o, idx, lookups);
            print_row(&r, n);
        }
        for (k = quick ? 1 : 0; k < sizeof base_e / sizeof base_e[0]; k++) {
            r.method = "Dolonius Alg. 1 (3-bit)";
            snprintf(r.setting, sizeof r.setting, "e_t %g", base_e[k]);
            run_baseline(&r, rgb, n, 0, base_e[k], 0, idx, lookups);
            print_row(&r, n);
        }
        for (k = 0; k < sizeof base_e / sizeof base_e[0]; k++) {
            r.method = "HashDAG 64-bit headers";
            snprintf(r.setting, sizeof r.setting, "e_t %g", base_e[k]);
            run_baseline(&r, rgb, n, 1, base_e[k], 0, idx, lookups);
            print_row(&r, n);
        }
        for (k = 0; k < sizeof dado_k / sizeof dado_k[0]; k++) {
            r.method = "Dado palettes";
            if (dado_k[k]) snprintf(r.setting, sizeof r.setting, "%u colours", (unsigned)dado_k[k]);
            else snprintf(r.setting, sizeof r.setting, "lossless");
            run_baseline(&r, rgb, n, 2, 0, dado_k[k], idx, lookups);
            print_row(&r, n);
        }
        if (peers) run_peers(peers, rgb, n, quick);
        printf("\n");
        free(idx);
        free(rgb);
    }
    return 0;
}
