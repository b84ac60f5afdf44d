/* The GPU kernel (examples/shaders/vdag_kernel.*, on voxdag_gpu.h) compiled
   from GLSL and from HLSL and run on the machine's Vulkan device (lavapipe
   where there is no GPU), against its own C build (examples/gpu.c's
   emulation) bit for bit, and against the library: on the golden files and
   dense scenes of every symmetry group, with private children, both colour
   kinds and L = 2..7, rays (random, along axes, through edges and corners,
   windows, level of detail), shadow rays, lookups with indices and colours,
   cells of every level with their counts and mean colours (files with and
   without level-of-detail colours; the same bits as voxdag_cell_count and
   voxdag_cell_color), and pictures (with level-of-detail cells lit as
   their voxels' staircase). An answer that differs from the library's exact one must
   be a counted near-tie (tests/gpu_oracle.h). When Vulkan cannot be opened
   this fails, unless VOXDAG_TEST_SKIP lists "gpu". Prints "N passed, N failed". */
#include "test.h"
#include "voxdag.h"
#include "voxcolor.h"
#include "rscene.h"
#include "golden.h"
#include "gpu_oracle.h"
#include "examples/gpu.h"

int test_current_failed, test_full;
const char *test_data_dir(void) { return "tests/data"; }

typedef struct vk_stats {
    uint64_t rays, hits, lod_hits, near_ties, occluded, lookups, cells, full_cells, slot_cells, pixels, runs, beam_blocks;
} vk_stats;

/* Runs W on the device and on the emulation; 1 when both ran and gave the
   same words (the device's are left in OUT). */
static int run_both(vdag_gpu *gpu, vdag_gpu *emu, const vdag_gpu_work *w, const uint32_t *in, size_t in_words,
                    uint32_t *out, size_t out_words, const char *what) {
    uint32_t *ref = (uint32_t *)malloc(4 * out_words);
    char err[256] = "";
    size_t i;
    int ok = ref != NULL;
    memset(out, 0xAB, 4 * out_words);
    if (ok && vdag_gpu_run(gpu, w, in, in_words, out, out_words, 1, NULL, err, sizeof err)) {
        fprintf(stderr, "  %s: %s\n", what, err);
        ok = 0;
    }
    if (ok && vdag_gpu_run(emu, w, in, in_words, ref, out_words, 1, NULL, err, sizeof err)) ok = 0;
    for (i = 0; ok && i < out_words; i++)
        if (out[i] != ref[i]) {
            fprintf(stderr, "  %s: word %zu is %08x on the device, %08x in C\n", what, i, out[i], ref[i]);
            ok = 0;
        }
    free(ref);
    return ok;
}

static void put_ray(uint32_t *w, const voxdag_ray *ray, double lod, uint32_t flags) {
    voxdag_gpu_ray g = gpu_ray(ray, lod, 0);
    memcpy(w, &g.ox, 4), memcpy(w + 1, &g.oy, 4), memcpy(w + 2, &g.oz, 4);
    memcpy(w + 3, &g.dx, 4), memcpy(w + 4, &g.dy, 4), memcpy(w + 5, &g.dz, 4);
    memcpy(w + 6, &g.t_min, 4), memcpy(w + 7, &g.t_max, 4), memcpy(w + 8, &g.lod, 4);
    w[9] = flags;
}

static voxdag_gpu_hit get_hit(const uint32_t *w) {
    voxdag_gpu_hit h;
    h.hit = w[0], memcpy(&h.t, w + 1, 4), h.x = w[2], h.y = w[3], h.z = w[4];
    h.nx = (int32_t)w[5], h.ny = (int32_t)w[6], h.nz = (int32_t)w[7], h.level = w[8];
    h.index_lo = w[9], h.index_hi = w[10];
    return h;
}

/* Whether ray I of check_file's list has VOXDAG_GPU_T_MAX_EXCLUSIVE. */
#define EXCLUSIVE(i) ((i) / 2 % 4 == 3)

/* Every query kind on one file, on TARGET's device and in C. */
static void check_file(vdag_gpu *gpu, vdag_gpu *emu, const voxdag *d, const rscene *s, uint64_t seed,
                       uint32_t nrays, vk_stats *st) {
    voxdag_info info;
    vdag_gpu_work w;
    char err[256] = "";
    uint64_t r = seed;
    uint32_t n, i, q, cells, *in, *out;
    voxdag_ray *rays;
    double *lods;
    voxdag_get_info(d, &info);
    if (vdag_gpu_load(gpu, d, err, sizeof err) || vdag_gpu_load(emu, d, err, sizeof err)) {
        fprintf(stderr, "  %s\n", err);
        CHECK(0);
        return;
    }
    n = 2 * nrays;
    rays = (voxdag_ray *)malloc(n * sizeof *rays), lods = (double *)malloc(n * sizeof *lods);
    in = (uint32_t *)malloc(10 * sizeof *in * n), out = (uint32_t *)malloc(12 * sizeof *out * n);
    for (i = 0; i < n; i++) { /* each ray twice: full detail, then with level of detail; every
                                 fourth pair in a half-open range */
        if (i % 2 == 0) rays[i] = float_ray(&r, 1u << info.levels), lods[i] = 0;
        else rays[i] = rays[i - 1], lods[i] = info.levels > 2 ? (float)rand_in(&r, 0.01, 0.6) : 0;
        put_ray(in + 10 * i, &rays[i], lods[i], VOXDAG_GPU_WANT_INDEX | (EXCLUSIVE(i) ? VOXDAG_GPU_T_MAX_EXCLUSIVE : 0u));
    }
    memset(&w, 0, sizeof w);
    w.mode = VDAG_GPU_RAYS, w.count = n;
    st->runs++;
    CHECK_MSG(run_both(gpu, emu, &w, in, 10 * (size_t)n, out, 12 * (size_t)n, "rays"), "rays: device and C differ");
    for (i = 0; i < n; i++) {
        voxdag_gpu_hit h = get_hit(out + 12 * i);
        st->rays++, st->hits += h.hit, st->lod_hits += h.hit && h.level < info.levels;
        if (!same_answer_opts(d, &rays[i], lods[i], EXCLUSIVE(i), &h)) {
            st->near_ties++;
            CHECK(near_tie_opts(d, &rays[i], lods[i], EXCLUSIVE(i), &h, near_tie_eps(info.levels, rays[i].origin)));
        }
        if (h.hit) { /* a voxel's colour, or a level-of-detail cell's mean */
            uint8_t rgb[3];
            uint64_t index = (uint64_t)h.index_hi << 32 | h.index_lo;
            uint32_t want = 0xFFFFFF;
            voxdag_hit cell;
            memset(&cell, 0, sizeof cell);
            cell.level = h.level, cell.xyz[0] = h.x, cell.xyz[1] = h.y, cell.xyz[2] = h.z;
            if (h.level == info.levels ? voxdag_color(d, index, rgb) == 1 : voxdag_cell_color(d, &cell, rgb) == 1)
                want = rgb[0] | (uint32_t)rgb[1] << 8 | (uint32_t)rgb[2] << 16;
            CHECK(out[12 * i + 11] == want);
        }
    }
    /* shadow rays: the full-detail ones */
    w.mode = VDAG_GPU_OCCLUDED;
    st->runs++;
    CHECK_MSG(run_both(gpu, emu, &w, in, 10 * (size_t)n, out, n, "occluded"), "occluded: device and C differ");
    for (i = 0; i < n; i += 2) {
        if (EXCLUSIVE(i)) continue;
        st->occluded++;
        if ((int)out[i] != voxdag_occluded(d, &rays[i])) {
            voxdag_gpu_hit h;
            memset(&h, 0, sizeof h);
            h.hit = out[i];
            st->near_ties++;
            CHECK(near_tie(d, &rays[i], 0, &h, near_tie_eps(info.levels, rays[i].origin)) || !out[i]);
        }
    }
    /* lookups: every cell of small grids, else a sample */
    cells = info.levels <= 5 ? 1u << (3 * info.levels) : 32768;
    free(in), free(out);
    in = (uint32_t *)malloc(3 * sizeof *in * cells), out = (uint32_t *)malloc(4 * sizeof *out * cells);
    for (i = 0; i < cells; i++) {
        uint32_t x, y, z;
        if (info.levels <= 5) voxdag_morton_decode(i, &x, &y, &z);
        else x = test_rand_below(&r, 1u << info.levels), y = test_rand_below(&r, 1u << info.levels), z = test_rand_below(&r, 1u << info.levels);
        in[3 * i] = x, in[3 * i + 1] = y, in[3 * i + 2] = z;
    }
    w.mode = VDAG_GPU_LOOKUPS, w.count = cells;
    st->runs++;
    CHECK_MSG(run_both(gpu, emu, &w, in, 3 * (size_t)cells, out, 4 * (size_t)cells, "lookups"), "lookups: device and C differ");
    for (i = 0; i < cells; i++) {
        uint64_t index = 0;
        int found = voxdag_lookup(d, in[3 * i], in[3 * i + 1], in[3 * i + 2], &index);
        st->lookups++;
        CHECK((int)out[4 * i] == found);
        if (s) CHECK(found == s->occ[info.levels][rcell(s->n, in[3 * i], in[3 * i + 1], in[3 * i + 2])]);
        if (found) CHECK(((uint64_t)out[4 * i + 2] << 32 | out[4 * i + 1]) == index);
    }
    /* cells of every level (all of a level below 4096, else a sample), each
       asked at a random point inside it */
    free(in), free(out);
    in = (uint32_t *)malloc(4 * sizeof *in * 4096 * (info.levels + 1));
    out = (uint32_t *)malloc(5 * sizeof *out * 4096 * (info.levels + 1));
    for (q = 0, cells = 0; q <= info.levels; q++) {
        uint32_t side = 1u << (info.levels - q), k, c[3];
        for (i = 0; i < (q <= 4 ? 1u << (3 * q) : 4096u); i++, cells++) {
            if (q <= 4) voxdag_morton_decode(i, &c[0], &c[1], &c[2]);
            else for (k = 0; k < 3; k++) c[k] = test_rand_below(&r, 1u << q);
            in[4 * cells] = q;
            for (k = 0; k < 3; k++) in[4 * cells + 1 + k] = c[k] * side + test_rand_below(&r, side);
        }
    }
    memset(&w, 0, sizeof w);
    w.mode = VDAG_GPU_CELLS, w.count = cells;
    st->runs++;
    CHECK_MSG(run_both(gpu, emu, &w, in, 4 * (size_t)cells, out, 5 * (size_t)cells, "cells"), "cells: device and C differ");
    for (i = 0; i < cells; i++) {
        uint64_t first = 0, count = voxdag_cell_count(d, in[4 * i], in[4 * i + 1], in[4 * i + 2], in[4 * i + 3], &first);
        uint32_t want = VOXDAG_GPU_NO_COLOR;
        uint8_t rgb[3];
        voxdag_hit cell;
        memset(&cell, 0, sizeof cell);
        cell.level = in[4 * i], cell.xyz[0] = in[4 * i + 1], cell.xyz[1] = in[4 * i + 2], cell.xyz[2] = in[4 * i + 3];
        if (voxdag_cell_color(d, &cell, rgb) == 1) want = rgb[0] | (uint32_t)rgb[1] << 8 | (uint32_t)rgb[2] << 16;
        st->cells++, st->full_cells += count > 0, st->slot_cells += count > 64 && info.lod_color_bytes > 0;
        CHECK(((uint64_t)out[5 * i + 1] << 32 | out[5 * i]) == count);
        CHECK(((uint64_t)out[5 * i + 3] << 32 | out[5 * i + 2]) == (count ? first : 0));
        CHECK_MSG(out[5 * i + 4] == want, "cell level %u (%u %u %u): %08x, want %08x", cell.level, cell.xyz[0],
                  cell.xyz[1], cell.xyz[2], out[5 * i + 4], want);
    }
    /* pictures with shadows and level of detail: a little, then much (cells
       lit as their staircase, shadow rays started past it) */
    memset(&w, 0, sizeof w);
    w.mode = VDAG_GPU_RENDER, w.width = 48, w.height = 32, w.count = 48 * 32, w.shadows = 1;
    w.eye[0] = -0.7f * (float)(1u << info.levels), w.eye[1] = 1.9f * (float)(1u << info.levels), w.eye[2] = 1.3f * (float)(1u << info.levels);
    /* looking about at the middle; r and u perpendicular to f and to each other, as the tool's camera */
    w.f[0] = 0.60000000f, w.f[1] = -0.64000000f, w.f[2] = -0.48000000f;
    w.r[0] = -0.51067604f, w.r[1] = -0.47875879f, w.r[2] = -0.00000000f;
    w.u[0] = 0.15429712f, w.u[1] = -0.16458359f, w.u[2] = 0.41231619f;
    w.light[0] = 0.48f, w.light[1] = 0.29f, w.light[2] = 0.77f;
    w.lod = info.levels > 4 ? 0.004f : 0, w.ambient = 0.3f, w.inv_w = 1.0f / 48, w.inv_h = 1.0f / 32;
    free(out);
    out = (uint32_t *)malloc(sizeof *out * w.count);
    st->runs++, st->pixels += w.count;
    CHECK_MSG(run_both(gpu, emu, &w, NULL, 0, out, w.count, "render"), "render: device and C differ");
    { /* the beam pass: rays started at their block's depth give the same picture, on both */
        uint32_t depths[24], beamed[48 * 32];
        vdag_gpu_work bw = w;
        int k;
        bw.mode = VDAG_GPU_BEAM, bw.count = 24;
        for (k = 0; k < 2; k++) {
            vdag_gpu *g = k ? emu : gpu;
            vdag_gpu_work rw = w;
            rw.beam_start = 1;
            CHECK(vdag_gpu_run(g, &bw, NULL, 0, depths, 24, 1, NULL, err, sizeof err) == 0);
            CHECK(vdag_gpu_run(g, &rw, depths, 24, beamed, w.count, 1, NULL, err, sizeof err) == 0);
            CHECK_MSG(!memcmp(beamed, out, sizeof beamed), "%s: the beam pass changed the picture", k ? "C" : "device");
            for (i = 0; i < 24; i++) st->beam_blocks += depths[i] != 0u; /* a depth above 0 */
        }
    }
    if (info.levels > 2) {
        w.lod = 0.03f;
        st->runs++, st->pixels += w.count;
        CHECK_MSG(run_both(gpu, emu, &w, NULL, 0, out, w.count, "render, level of detail"),
                  "render with level of detail: device and C differ");
    }
    free(in), free(out), free(rays), free(lods);
}

static void run_target(vdag_gpu_target target, const char *name) {
    vk_stats st;
    int k, kind, sym;
    uint32_t levels;
    vdag_gpu *gpu = NULL, *emu = NULL;
    voxdag *first = NULL;
    char err[256] = "";
    memset(&st, 0, sizeof st);
    CHECK(golden_build(GOLDEN_ONE_VOXEL, NULL, &first) == VOXDAG_OK);
    if (!first || vdag_gpu_open(&gpu, target, first, 1, err, sizeof err) ||
        vdag_gpu_open(&emu, VDAG_GPU_EMULATE, first, 2, err, sizeof err)) {
        fprintf(stderr, "  %s\n", err);
        CHECK(0);
        vdag_gpu_close(gpu);
        voxdag_free(first);
        return;
    }
    for (k = 0; k < GOLDEN_COUNT; k++) {
        voxdag *d = NULL;
        CHECK(golden_build(k, NULL, &d) == VOXDAG_OK);
        if (d) check_file(gpu, emu, d, NULL, 0x7A1 + (uint64_t)k, 400, &st);
        voxdag_free(d);
    }
    /* dense scenes: each symmetry group, L = 3..7, with voxcolor colours or none at level of detail */
    for (levels = 3, kind = RS_SPARSE, sym = 0; levels <= 7; levels++, kind = kind + 1 < RS_COUNT ? kind + 1 : RS_SPARSE, sym = (sym + 1) % 3) {
        rscene s;
        voxdag *d = rscene_make(&s, kind, levels, sym, 0x7B0 + levels);
        if (d) {
            check_file(gpu, emu, d, &s, 0x7C0 + levels, 1000, &st);
            { /* odd L: voxcolor colours; even: the raw ones without level-of-detail colours */
                voxdag *v = levels % 2 ? with_voxcolor(d, levels == 5 ? 0.0 : 0.06, levels == 5 ? 10 : 6) : without_lod_colors(d);
                if (v) check_file(gpu, emu, v, &s, 0x7D0 + levels, 300, &st);
                voxdag_free(v);
            }
        }
        voxdag_free(d);
        rscene_free(&s);
    }
    fprintf(stderr, "  %s: %llu runs; %llu rays (%llu hits, %llu LOD hits), %llu shadow rays, %llu near-ties; "
            "%llu lookups; %llu cells (%llu full, %llu read from a level-of-detail slot); %llu pixels; "
            "%llu beam blocks starting later\n", name, (unsigned long long)st.runs, (unsigned long long)st.rays,
            (unsigned long long)st.hits, (unsigned long long)st.lod_hits, (unsigned long long)st.occluded,
            (unsigned long long)st.near_ties, (unsigned long long)st.lookups, (unsigned long long)st.cells,
            (unsigned long long)st.full_cells, (unsigned long long)st.slot_cells, (unsigned long long)st.pixels,
            (unsigned long long)st.beam_blocks);
    CHECK(st.hits > 1000 && st.lod_hits > 100 && st.near_ties * 200 <= st.rays && st.beam_blocks > 100);
    CHECK(st.full_cells > 5000 && st.slot_cells > 500);
    vdag_gpu_close(gpu);
    vdag_gpu_close(emu);
    voxdag_free(first);
}

static int skip_allowed(void) {
    const char *s = getenv("VOXDAG_TEST_SKIP");
    return s && (strstr(s, "gpu") || strstr(s, "all"));
}

int main(void) {
    static const struct { vdag_gpu_target target; const char *name; } targets[2] = {
        {VDAG_GPU_GLSL, "gpu kernel compiled from GLSL"}, {VDAG_GPU_HLSL, "gpu kernel compiled from HLSL"}};
    int passed = 0, failed = 0, t;
    voxdag *d = NULL;
    vdag_gpu *probe = NULL;
    char err[256] = "";
    CHECK(golden_build(GOLDEN_ONE_VOXEL, NULL, &d) == VOXDAG_OK);
    if (vdag_gpu_open(&probe, VDAG_GPU_GLSL, d, 1, err, sizeof err)) {
        voxdag_free(d);
        if (skip_allowed()) {
            printf("SKIP gpu: %s (allowed by VOXDAG_TEST_SKIP)\n0 passed, 0 failed\n", err);
            return 0;
        }
        fprintf(stderr, "FAIL gpu: %s (tests/deps.sh installs the packages; VOXDAG_TEST_SKIP=gpu allows the skip)\n", err);
        printf("0 passed, 1 failed\n");
        return 1;
    }
    fprintf(stderr, "device: %s%s\n", vdag_gpu_device(probe), vdag_gpu_is_cpu(probe) ? " (a CPU)" : "");
    vdag_gpu_close(probe);
    voxdag_free(d);
    for (t = 0; t < 2; t++) {
        test_current_failed = 0;
        fprintf(stderr, "[ RUN ] %s\n", targets[t].name);
        run_target(targets[t].target, targets[t].name);
        if (test_current_failed) fprintf(stderr, "[FAIL ] %s (%d checks failed)\n", targets[t].name, test_current_failed), failed++;
        else passed++;
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
