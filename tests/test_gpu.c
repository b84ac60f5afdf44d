/* voxdag_gpu.h in its C mode, against the library and brute force: the 48
   symmetries against FORMAT.md's definitions, lookups and indices against a
   dense grid and the Morton rank, colours against voxdag_color, and rays
   against voxdag_raycast / voxdag_occluded. The header traces in float32
   where the library is exact in double, so a ray may differ at a near-tie:
   an answer that differs is accepted only when the exact answer of a ray
   moved by a few float32 roundings at the grid's scale (EPS below) is the
   same, and such answers are counted and bounded. The same rays run on
   Vulkan in tests/test_gpu_vk.c, against this C build bit for bit. Cells
   (voxdag_gpu_cell) and their colours (voxdag_gpu_cell_color) are
   integers: they equal voxdag_cell_count and voxdag_cell_color exactly. */
#include "test.h"
#include "voxdag.h"
#include "voxcolor.h"
#include "voxdag_gpu.h"
#include "rscene.h"
#include "golden.h"
#include "gpu_oracle.h"
#include "examples/shaders/vdag_kernel.h"

#include <math.h>

// -- The 48 symmetries, by FORMAT.md's words

static void ref_perm(unsigned p, unsigned perm[3]) { /* lexicographic */
    static const unsigned table[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    memcpy(perm, table[p], sizeof table[p]);
}

static unsigned ref_act(unsigned t, unsigned i) {
    unsigned perm[3], a, r = 0;
    ref_perm(t >> 3, perm);
    for (a = 0; a < 3; a++) r |= (i >> a & 1) << perm[a];
    return r ^ (t & 7);
}

static void test_gpu_transforms(void) {
    unsigned a, b, i, w, x;
    uint64_t r = 0x6E0;
    for (a = 0; a < 48; a++) {
        unsigned inv = voxdag_gpui_inverse(a);
        for (i = 0; i < 8; i++) {
            CHECK(voxdag_gpui_act(a, i) == ref_act(a, i));
            CHECK(ref_act(inv, ref_act(a, i)) == i);
        }
        for (b = 0; b < 48; b++) {
            unsigned c = voxdag_gpui_compose(a, b);
            for (i = 0; i < 8; i++) CHECK(ref_act(c, i) == ref_act(a, ref_act(b, i)));
        }
        /* octant sets: world bit w is stored bit MI(w) */
        for (x = 0; x < 256; x++) {
            unsigned got = voxdag_gpui_bytes_to_world(x * 0x01010101u, a), want = 0;
            for (w = 0; w < 8; w++) want |= (x >> ref_act(a, w) & 1) << w;
            CHECK(got == want * 0x01010101u);
        }
        /* brick masks: both coordinate-bit triples */
        for (i = 0; i < 64; i++) {
            uint64_t m = test_rand(&r) & test_rand(&r), want = 0, got;
            voxdag_gpui_mask gm;
            unsigned p;
            if (i < 6) m = 1ull << test_rand_below(&r, 64);
            gm.lo = (uint32_t)m, gm.hi = (uint32_t)(m >> 32);
            gm = voxdag_gpui_brick_to_world(gm, a);
            got = (uint64_t)gm.hi << 32 | gm.lo;
            for (p = 0; p < 64; p++) want |= (m >> (ref_act(a, p & 7) | ref_act(a, p >> 3) << 3) & 1) << p;
            CHECK(got == want);
        }
    }
}

// -- Queries of one loaded file

typedef struct gpu_stats {
    uint64_t rays, hits, lod_hits, near_ties, lookups, colors, private_levels, lod_hit_colors;
    double worst_t; /* largest |t - exact t| * |dir|, grid units */
} gpu_stats;

static voxdag_gpu_buf gpu_buffer(const voxdag *d) {
    voxdag_gpu_buf buf;
    size_t size;
    buf.bytes = (const unsigned char *)voxdag_image(d, &size);
    buf.size = size;
    return buf;
}

/* One ray, with and without level of detail, and as a shadow query. */
static uint32_t packed_rgb(const uint8_t rgb[3]) {
    return (uint32_t)rgb[0] | (uint32_t)rgb[1] << 8 | (uint32_t)rgb[2] << 16;
}

static void check_ray(const voxdag *d, voxdag_gpu_buf buf, voxdag_gpu_file f, const voxdag_ray *ray, double lod,
                      gpu_stats *st) {
    voxdag_info info;
    voxdag_gpu_hit g = voxdag_gpu_raycast(buf, f, gpu_ray(ray, lod, 1));
    double m = fmax(fabs(ray->dir[0]), fmax(fabs(ray->dir[1]), fabs(ray->dir[2]))), eps;
    voxdag_get_info(d, &info);
    eps = near_tie_eps(info.levels, ray->origin);
    st->rays++;
    st->hits += g.hit;
    st->lod_hits += g.hit && g.level < info.levels;
    if (same_answer(d, ray, lod, &g)) {
        if (g.hit) {
            voxdag_ray_opts o;
            voxdag_hit h;
            memset(&o, 0, sizeof o);
            o.lod_factor = lod, o.lod_pixels = lod > 0 ? 1 : 0;
            voxdag_raycast(d, ray, &o, &h);
            st->worst_t = fmax(st->worst_t, fabs(g.t - h.t) * m);
            CHECK_MSG(fabs(g.t - h.t) * m <= eps, "t %.9g, exact %.17g", g.t, h.t);
            if (g.level < info.levels) { /* the cell's colour, as voxdag_cell_color gives the exact hit */
                uint8_t rgb[3];
                uint32_t got = voxdag_gpu_cell_color(buf, f, g);
                if (voxdag_cell_color(d, &h, rgb) == 1) CHECK(got == packed_rgb(rgb));
                else CHECK(got == VOXDAG_GPU_NO_COLOR);
                st->lod_hit_colors++;
            }
        }
    } else {
        int tie = near_tie(d, ray, lod, &g, eps);
        st->near_ties++;
        CHECK_MSG(tie, "ray (%.9g %.9g %.9g) dir (%.9g %.9g %.9g) t [%.9g %.9g] lod %g: gpu hit %u (%u %u %u) "
                  "level %u normal (%d %d %d)", ray->origin[0], ray->origin[1], ray->origin[2], ray->dir[0],
                  ray->dir[1], ray->dir[2], ray->t_min, ray->t_max, lod, g.hit, g.x, g.y, g.z, g.level, g.nx, g.ny,
                  g.nz);
    }
    { /* any hit, with the same level of detail */
        voxdag_ray_opts o;
        unsigned occ = voxdag_gpu_occluded(buf, f, gpu_ray(ray, lod, 0));
        memset(&o, 0, sizeof o);
        o.lod_factor = lod, o.lod_pixels = lod > 0 ? 1 : 0;
        CHECK(occ == g.hit);
        if (occ != (unsigned)voxdag_occluded_opts(d, ray, &o)) CHECK(near_tie(d, ray, lod, &g, eps));
        if (lod == 0) CHECK(occ == (unsigned)voxdag_occluded(d, ray) || near_tie(d, ray, 0, &g, eps));
    }
    if (g.hit) { /* t_max_exclusive: a range ending where the hit cell begins meets nothing; just past, the
                    hit (exactly so on the GPU; the exact tracer's t differs by rounding: near-ties by
                    construction, not counted) */
        voxdag_gpu_ray x = gpu_ray(ray, lod, 1);
        voxdag_ray exact = *ray;
        voxdag_gpu_hit e;
        x.flags |= VOXDAG_GPU_T_MAX_EXCLUSIVE;
        x.t_max = g.t;
        e = voxdag_gpu_raycast(buf, f, x);
        CHECK(e.hit == 0 && voxdag_gpu_occluded(buf, f, x) == 0);
        exact.t_max = g.t;
        if (!same_answer_opts(d, &exact, lod, 1, &e)) CHECK(near_tie_opts(d, &exact, lod, 1, &e, eps));
        x.t_max = nextafterf(g.t, 1e30f);
        if (x.t_max >= (float)ldexp(1, -64)) { /* (below, t_max is 0: an empty range) */
            e = voxdag_gpu_raycast(buf, f, x);
            CHECK(e.hit && e.t == g.t && e.x == g.x && e.y == g.y && e.z == g.z && e.level == g.level);
            exact.t_max = x.t_max;
            if (!same_answer_opts(d, &exact, lod, 1, &e)) CHECK(near_tie_opts(d, &exact, lod, 1, &e, eps));
        }
    }
}

static void check_file(const voxdag *d, const rscene *s, uint64_t seed, uint32_t rays, gpu_stats *st) {
    voxdag_gpu_buf buf = gpu_buffer(d);
    voxdag_gpu_file f = voxdag_gpu_open(buf, 0);
    voxdag_info info;
    uint64_t r = seed, i, n;
    uint32_t l;
    voxdag_get_info(d, &info);
    CHECK(f.levels == info.levels && ((uint64_t)f.voxels_hi << 32 | f.voxels_lo) == info.voxels);
    CHECK(f.color_kind == (uint32_t)info.color_kind);
    for (l = 0; l + 2 < info.levels; l++) st->private_levels += voxdag_gpui_level_at(buf, f, l).private_children;
    /* lookups: every cell of small grids, else a sample, against the dense grid */
    n = (uint64_t)1 << (3 * info.levels);
    for (i = 0; i < (n <= 32768 ? n : 32768); i++) {
        uint32_t x, y, z;
        voxdag_gpu_lookup_result g;
        uint64_t want_index = 0;
        int want;
        if (n <= 32768) voxdag_morton_decode(i, &x, &y, &z);
        else x = test_rand_below(&r, 1u << info.levels), y = test_rand_below(&r, 1u << info.levels), z = test_rand_below(&r, 1u << info.levels);
        g = voxdag_gpu_lookup(buf, f, x, y, z);
        want = s ? s->occ[info.levels][rcell(s->n, x, y, z)] : voxdag_lookup(d, x, y, z, &want_index);
        if (s && want) want_index = s->rank[rcell(s->n, x, y, z)];
        st->lookups++;
        CHECK_MSG((int)g.found == want, "(%u %u %u): found %u, want %d", x, y, z, g.found, want);
        if (want) CHECK(((uint64_t)g.index_hi << 32 | g.index_lo) == want_index);
    }
    CHECK(voxdag_gpu_lookup(buf, f, 1u << info.levels, 0, 0).found == 0);
    /* colours: every index */
    for (i = 0; i < info.voxels && i < 200000; i++) {
        uint8_t want[3];
        uint32_t got = voxdag_gpu_color(buf, f, (uint32_t)i, (uint32_t)(i >> 32));
        st->colors++;
        if (voxdag_color(d, i, want))
            CHECK_MSG(got == packed_rgb(want),
                      "colour %llu: %06x, want %02x%02x%02x", (unsigned long long)i, got, want[2], want[1], want[0]);
        else
            CHECK(got == VOXDAG_GPU_NO_COLOR);
    }
    /* rays, with and without level of detail */
    for (i = 0; i < rays; i++) {
        voxdag_ray ray = float_ray(&r, 1u << info.levels);
        check_ray(d, buf, f, &ray, 0, st);
        if (info.levels > 2) check_ray(d, buf, f, &ray, (float)rand_in(&r, 0.01, 0.6), st);
    }
}

static void report(const char *what, const gpu_stats *st) {
    fprintf(stderr, "  %s: %llu rays (%llu hits, %llu LOD hits, %llu of them coloured as cells), %llu near-ties, "
            "worst t error %.3g voxel; %llu lookups, %llu colours; %llu levels with private children\n", what,
            (unsigned long long)st->rays, (unsigned long long)st->hits, (unsigned long long)st->lod_hits,
            (unsigned long long)st->lod_hit_colors, (unsigned long long)st->near_ties, st->worst_t,
            (unsigned long long)st->lookups, (unsigned long long)st->colors, (unsigned long long)st->private_levels);
}

static void test_gpu_scenes(void) {
    gpu_stats st;
    uint32_t levels;
    int kind, sym;
    memset(&st, 0, sizeof st);
    for (levels = 2; levels <= 7; levels++)
        for (kind = 0; kind < RS_COUNT; kind++)
            for (sym = 0; sym < 3; sym++) {
                rscene s;
                uint64_t seed = 0x69B0 + (uint64_t)kind * 1000 + levels * 10 + (uint64_t)sym;
                voxdag *d = rscene_make(&s, kind, levels, sym, seed);
                if (d) {
                    check_file(d, &s, seed, 150, &st);
                    if ((kind + levels + (unsigned)sym) % 3 == 0) { /* voxcolor: lossless, lossy, both index widths */
                        voxdag *v = with_voxcolor(d, (kind & 1) ? 0.0 : 0.08, levels & 1 ? 10 : 4 + levels);
                        if (v) check_file(v, &s, seed + 1, 20, &st);
                        voxdag_free(v);
                    }
                }
                voxdag_free(d);
                rscene_free(&s);
            }
    report("dense scenes, L = 2..7", &st);
    CHECK(st.rays > 40000 && st.hits > st.rays / 4 && st.lod_hits > 1000);
    CHECK(st.private_levels > 20);
    CHECK(st.near_ties * 200 <= st.rays); /* at most 0.5 % */
}

// -- Cells and their colours

typedef struct cell_stats {
    uint64_t cells, full, large, slots, files, files_with_slots;
} cell_stats;

/* Every level's cells of D (all of them below 4096 a level, else a
   sample), each asked at a random point inside it: voxdag_gpu_cell against
   voxdag_cell_count, voxdag_gpu_cell_color against voxdag_cell_color. */
static void check_cells(const voxdag *d, uint64_t seed, cell_stats *st) {
    voxdag_gpu_buf buf = gpu_buffer(d);
    voxdag_gpu_file f = voxdag_gpu_open(buf, 0);
    voxdag_gpu_hit gh;
    voxdag_info info;
    uint64_t r = seed;
    uint32_t q;
    voxdag_get_info(d, &info);
    CHECK(f.lod_kind == (info.lod_color_bytes ? (uint32_t)info.color_kind : VOXDAG_GPU_COLORS_NONE));
    if (f.lod_kind != VOXDAG_GPU_COLORS_NONE) /* as the writers fill it */
        CHECK(f.lod_first == 0 && f.lod_levels + 2 == info.levels &&
              ((uint64_t)f.lod_per_level_hi << 32 | f.lod_per_level_lo) == (info.voxels + 63) / 64);
    st->files++, st->files_with_slots += f.lod_kind != VOXDAG_GPU_COLORS_NONE;
    memset(&gh, 0, sizeof gh);
    for (q = 0; q <= info.levels; q++) {
        uint64_t cells = (uint64_t)1 << (3 * q), i;
        uint32_t side = 1u << (info.levels - q);
        for (i = 0; i < (cells <= 4096 ? cells : 4096); i++) {
            uint32_t c[3], p[3], k, got;
            uint64_t first = 0, n;
            voxdag_gpu_cell_result g;
            voxdag_hit h;
            uint8_t rgb[3];
            int rc;
            if (cells <= 4096) voxdag_morton_decode(i, &c[0], &c[1], &c[2]);
            else for (k = 0; k < 3; k++) c[k] = test_rand_below(&r, 1u << q);
            for (k = 0; k < 3; k++) p[k] = c[k] * side + test_rand_below(&r, side);
            n = voxdag_cell_count(d, q, p[0], p[1], p[2], &first);
            g = voxdag_gpu_cell(buf, f, q, p[0], p[1], p[2]);
            CHECK_MSG(((uint64_t)g.count_hi << 32 | g.count_lo) == n && ((uint64_t)g.first_hi << 32 | g.first_lo) == first,
                      "level %u (%u %u %u): count %u first %u, want %llu %llu", q, p[0], p[1], p[2], g.count_lo,
                      g.first_lo, (unsigned long long)n, (unsigned long long)first);
            memset(&h, 0, sizeof h);
            h.level = q, h.xyz[0] = p[0], h.xyz[1] = p[1], h.xyz[2] = p[2];
            gh.hit = 1, gh.level = q, gh.x = p[0], gh.y = p[1], gh.z = p[2];
            rc = voxdag_cell_color(d, &h, rgb);
            got = voxdag_gpu_cell_color(buf, f, gh);
            CHECK_MSG(rc == 1 ? got == packed_rgb(rgb) : rc == 0 && got == VOXDAG_GPU_NO_COLOR,
                      "level %u (%u %u %u), n %llu: colour %06x, want %d %02x%02x%02x", q, p[0], p[1], p[2],
                      (unsigned long long)n, got, rc, rgb[2], rgb[1], rgb[0]);
            st->cells++, st->full += n > 0, st->large += n > 64;
            st->slots += n > 64 && f.lod_kind != VOXDAG_GPU_COLORS_NONE && info.color_kind != VOXDAG_COLORS_NONE;
        }
    }
    /* outside the grid, past level L, a miss */
    CHECK(voxdag_gpu_cell(buf, f, info.levels + 1, 0, 0, 0).count_lo == 0);
    CHECK(voxdag_gpu_cell(buf, f, 0, 1u << info.levels, 0, 0).count_lo == 0);
    gh.hit = 0, gh.level = 0, gh.x = 0, gh.y = 0, gh.z = 0;
    CHECK(voxdag_gpu_cell_color(buf, f, gh) == VOXDAG_GPU_NO_COLOR);
}

/* Random scenes, L = 2..7, every symmetry group: raw colours and voxcolor
   ones (lossless and lossy), each with its level-of-detail colours and
   without them; the golden files; and a file written before the section. */
static void test_gpu_cells(void) {
    cell_stats st;
    uint32_t levels;
    int kind, k;
    memset(&st, 0, sizeof st);
    for (levels = 2; levels <= 7; levels++)
        for (kind = 0; kind < RS_COUNT; kind++) {
            rscene s;
            uint64_t seed = 0xCE11 + (uint64_t)kind * 100 + levels;
            voxdag *d = rscene_make(&s, kind, levels, (int)(levels + (uint32_t)kind) % 3, seed);
            voxdag *v = d ? with_voxcolor(d, kind & 1 ? 0.0 : 0.05, levels & 1 ? 10 : 4 + levels) : NULL;
            for (k = 0; d && v && k < 4; k++) {
                const voxdag *src = k & 1 ? v : d;
                voxdag *bare = NULL;
                if (k < 2) {
                    check_cells(src, seed + (uint64_t)k, &st);
                } else { /* the same colours without the section */
                    bare = without_lod_colors(src);
                    if (bare) check_cells(bare, seed + (uint64_t)k, &st);
                    voxdag_free(bare);
                }
            }
            voxdag_free(v);
            voxdag_free(d);
            rscene_free(&s);
        }
    for (k = 0; k < GOLDEN_COUNT; k++) {
        voxdag *d = NULL;
        CHECK(golden_build(k, NULL, &d) == VOXDAG_OK);
        if (d) check_cells(d, 0xCE0 + (uint64_t)k, &st);
        voxdag_free(d);
    }
    {
        char path[4096];
        voxdag *d = NULL;
        snprintf(path, sizeof path, "%s/lod/mirrored_blob_l5_before_lod.vdag", test_data_dir());
        CHECK(voxdag_load_file(path, NULL, &d, NULL) == VOXDAG_OK);
        if (d) check_cells(d, 0xCE1, &st);
        voxdag_free(d);
    }
    fprintf(stderr, "  %llu files (%llu with level-of-detail colours): %llu cells of every level (%llu full, %llu of "
            "more than 64 voxels, %llu of them read from a slot)\n", (unsigned long long)st.files,
            (unsigned long long)st.files_with_slots, (unsigned long long)st.cells, (unsigned long long)st.full,
            (unsigned long long)st.large, (unsigned long long)st.slots);
    CHECK(st.files_with_slots > 50 && st.slots > 1000 && st.full > 10000);
}

/* The golden files, and one placed at an offset inside a larger buffer. */
static void test_gpu_golden(void) {
    gpu_stats st;
    int k;
    memset(&st, 0, sizeof st);
    for (k = 0; k < GOLDEN_COUNT; k++) {
        voxdag *d = NULL;
        CHECK(golden_build(k, NULL, &d) == VOXDAG_OK);
        if (!d) continue;
        check_file(d, NULL, 0x601D + (uint64_t)k, 300, &st);
        {
            size_t size;
            const uint8_t *img = (const uint8_t *)voxdag_image(d, &size);
            uint8_t *big = (uint8_t *)calloc(size + 24, 1);
            voxdag_gpu_buf a = gpu_buffer(d), b;
            voxdag_gpu_file fa = voxdag_gpu_open(a, 0), fb;
            uint64_t r = 7;
            int i;
            memcpy(big + 16, img, size);
            b.bytes = big, b.size = size + 24;
            fb = voxdag_gpu_open(b, 16);
            for (i = 0; i < 200; i++) {
                voxdag_ray ray = float_ray(&r, 1u << fa.levels);
                voxdag_gpu_ray g = gpu_ray(&ray, 0, 1);
                voxdag_gpu_hit ha, hb;
                ha = voxdag_gpu_raycast(a, fa, g), hb = voxdag_gpu_raycast(b, fb, g);
                CHECK(!memcmp(&ha, &hb, sizeof ha));
            }
            free(big);
        }
        voxdag_free(d);
    }
    report("golden files", &st);
}

/* Larger grids from the voxelizer (a sphere shell and a box), L = 9 and 11,
   against the library's own queries. */
static void test_gpu_large(void) {
    gpu_stats st;
    uint32_t levels;
    memset(&st, 0, sizeof st);
    for (levels = 9; levels <= 11; levels += 2) {
        voxdag_build_opts o;
        voxdag_builder *b;
        voxdag *d = NULL, *v;
        uint32_t n = 1u << levels, *xyz, k = 0, i;
        uint8_t *rgb;
        uint64_t r = levels;
        size_t cap = 400000;
        xyz = (uint32_t *)malloc(cap * 3 * sizeof *xyz), rgb = (uint8_t *)malloc(cap * 3);
        while (k < cap) { /* points on a sphere and on the faces of a box */
            double u = rand_unit(&r) * 2 - 1, phi = rand_unit(&r) * 6.283185307179586, c = n * 0.45, rad = n * 0.3;
            double p[3];
            p[0] = c + rad * sqrt(1 - u * u) * cos(phi), p[1] = c + rad * sqrt(1 - u * u) * sin(phi), p[2] = c + rad * u;
            if (k & 1) {
                p[0] = n * (0.6 + 0.3 * rand_unit(&r)), p[1] = n * (0.1 + 0.2 * rand_unit(&r));
                p[2] = (r & 1) ? n * 0.7 : n * 0.9;
            }
            for (i = 0; i < 3; i++) xyz[3 * k + i] = (uint32_t)p[i] < n ? (uint32_t)p[i] : n - 1;
            for (i = 0; i < 3; i++) rgb[3 * k + i] = (uint8_t)(xyz[3 * k + i] >> (levels - 6));
            k++;
        }
        memset(&o, 0, sizeof o);
        o.levels = levels, o.colors = 1, o.symmetry = VOXDAG_SYMMETRY_FULL;
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        CHECK(voxdag_builder_add(b, xyz, rgb, k, NULL) == VOXDAG_OK);
        CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
        free(xyz), free(rgb);
        if (!d) continue;
        check_file(d, NULL, 0xB16 + levels, 1500, &st);
        v = with_voxcolor(d, 0.02, 10);
        if (v) check_file(v, NULL, 0xB17 + levels, 100, &st);
        voxdag_free(v);
        voxdag_free(d);
    }
    report("voxelized, L = 9 and 11", &st);
    CHECK(st.near_ties * 200 <= st.rays);
}

/* The documented domain: non-finite input misses, tiny components are 0. */
static void test_gpu_domain(void) {
    voxdag *d = NULL;
    voxdag_gpu_buf buf;
    voxdag_gpu_file f;
    voxdag_gpu_ray g;
    voxdag_ray ray;
    voxdag_gpu_hit h, h0;
    float bad[4];
    int k, a;
    CHECK(golden_build(GOLDEN_MIRRORED_BLOB, NULL, &d) == VOXDAG_OK);
    if (!d) return;
    buf = gpu_buffer(d), f = voxdag_gpu_open(buf, 0);
    memset(&ray, 0, sizeof ray);
    ray.origin[0] = -3, ray.origin[1] = 10.5, ray.origin[2] = 9.25, ray.dir[0] = 1, ray.dir[1] = -0.25;
    ray.dir[2] = -0.125, ray.t_max = HUGE_VAL;
    g = gpu_ray(&ray, 0, 1);
    h0 = voxdag_gpu_raycast(buf, f, g);
    CHECK(h0.hit && same_answer(d, &ray, 0, &h0));
    g.t_max = 0; /* no limit */
    h = voxdag_gpu_raycast(buf, f, g);
    CHECK(!memcmp(&h, &h0, sizeof h));
    bad[0] = NAN, bad[1] = INFINITY, bad[2] = -INFINITY, bad[3] = 1e10f; /* beyond 2^32 */
    for (k = 0; k < 4; k++)
        for (a = 0; a < 7; a++) {
            voxdag_gpu_ray b = gpu_ray(&ray, 0, 1);
            float *field[7];
            field[0] = &b.ox, field[1] = &b.oy, field[2] = &b.oz, field[3] = &b.dx, field[4] = &b.dy, field[5] = &b.dz;
            field[6] = &b.t_min;
            *field[a] = bad[k];
            if (a == 6 && k == 2) continue; /* t_min = -inf is a valid window */
            CHECK_MSG(voxdag_gpu_raycast(buf, f, b).hit == 0 && voxdag_gpu_occluded(buf, f, b) == 0, "field %d value %g", a,
                      (double)bad[k]);
        }
    /* a direction component below 2^-64 is 0 */
    g = gpu_ray(&ray, 0, 1);
    g.dz = 1e-20f;
    ray.dir[2] = 0;
    h = voxdag_gpu_raycast(buf, f, g);
    CHECK(same_answer(d, &ray, 0, &h));
    /* bytes that are not a version-3 image: every query misses */
    {
        size_t size;
        uint8_t *copy;
        const void *img = voxdag_image(d, &size);
        voxdag_gpu_buf cb;
        copy = (uint8_t *)malloc(size);
        memcpy(copy, img, size);
        copy[8] = 4;
        cb.bytes = copy, cb.size = size;
        f = voxdag_gpu_open(cb, 0);
        CHECK(f.levels == 0 && voxdag_gpu_raycast(cb, f, gpu_ray(&ray, 0, 1)).hit == 0);
        CHECK(voxdag_gpu_lookup(cb, f, 0, 0, 0).found == 0);
        free(copy);
    }
    voxdag_free(d);
}

/* The beam pass: for random cameras (inside and outside the grid, with and
   without level of detail), every ray of an 8x8 block of a 240x160
   picture started at the block's frustum depth gives the same answer as
   from 0; the depth is often above 0 and often close to the first hit (so
   that a bound too far would show). */
static void test_gpu_beam(void) {
    uint64_t r = 0xBEA4, rays = 0, later = 0, blocks = 0, tight = 0;
    uint32_t levels;
    int kind;
    for (levels = 3; levels <= 7; levels++)
        for (kind = RS_SPARSE; kind < RS_COUNT; kind += 2) {
            rscene s;
            voxdag *d = rscene_make(&s, kind, levels, (int)(levels % 3), 0xBE0 + levels);
            voxdag_gpu_buf buf;
            voxdag_gpu_file f;
            int cam;
            if (!d) continue;
            buf = gpu_buffer(d), f = voxdag_gpu_open(buf, 0);
            for (cam = 0; cam < 6; cam++) {
                vdag_kernel_params p;
                double n = (double)(1u << levels), fd[3], rd[3], ud[3], len;
                uint32_t x, y, a, k;
                memset(&p, 0, sizeof p);
                p.width = 240, p.height = 160, p.inv_w = 1.0f / 240, p.inv_h = 1.0f / 160;
                p.lod = cam % 3 == 2 ? (float)rand_in(&r, 0.01, 0.2) : 0.0f;
                p.eye_x = (float)rand_in(&r, cam & 1 ? -n : 0, cam & 1 ? 2 * n : n);
                p.eye_y = (float)rand_in(&r, cam & 1 ? -n : 0, cam & 1 ? 2 * n : n);
                p.eye_z = (float)rand_in(&r, cam & 1 ? -n : 0, cam & 1 ? 2 * n : n);
                fd[0] = n / 2 - p.eye_x + rand_in(&r, -n / 4, n / 4), fd[1] = n / 2 - p.eye_y, fd[2] = n / 2 - p.eye_z + 0.3;
                len = sqrt(fd[0] * fd[0] + fd[1] * fd[1] + fd[2] * fd[2]);
                for (a = 0; a < 3; a++) fd[a] /= len;
                rd[0] = fd[1], rd[1] = -fd[0], rd[2] = 0, len = sqrt(rd[0] * rd[0] + rd[1] * rd[1]);
                for (a = 0; a < 3; a++) rd[a] /= len;
                ud[0] = rd[1] * fd[2] - rd[2] * fd[1], ud[1] = rd[2] * fd[0] - rd[0] * fd[2], ud[2] = rd[0] * fd[1] - rd[1] * fd[0];
                p.f_x = (float)fd[0], p.f_y = (float)fd[1], p.f_z = (float)fd[2];
                p.r_x = (float)(rd[0] * 0.7), p.r_y = (float)(rd[1] * 0.7), p.r_z = (float)(rd[2] * 0.7);
                p.u_x = (float)(ud[0] * 0.47), p.u_y = (float)(ud[1] * 0.47), p.u_z = (float)(ud[2] * 0.47);
                for (k = 0; k < 12; k++) { /* blocks of the middle, where the scene is */
                    uint32_t b = (7 + test_rand_below(&r, 6)) * 30 + 12 + test_rand_below(&r, 6);
                    float depth = voxdag_gpu_frustum_depth(buf, f, vdag_kernel_frustum(p, b)), t0 = vdag_kernel_start(f, depth);
                    blocks++, later += t0 > 0;
                    for (y = 8 * (b / 30); y < 8 * (b / 30) + 8; y++)
                        for (x = 8 * (b % 30); x < 8 * (b % 30) + 8; x++) {
                            voxdag_gpu_ray ray;
                            voxdag_gpu_hit h0, h1;
                            float sx = vdag_kernel_sx(p, x), sy = vdag_kernel_sy(p, y);
                            ray.ox = p.eye_x, ray.oy = p.eye_y, ray.oz = p.eye_z;
                            ray.dx = p.f_x + sx * p.r_x + sy * p.u_x, ray.dy = p.f_y + sx * p.r_y + sy * p.u_y;
                            ray.dz = p.f_z + sx * p.r_z + sy * p.u_z;
                            ray.t_min = 0, ray.t_max = 0, ray.lod = p.lod, ray.flags = VOXDAG_GPU_WANT_INDEX;
                            h0 = voxdag_gpu_raycast(buf, f, ray);
                            ray.t_min = t0;
                            h1 = voxdag_gpu_raycast(buf, f, ray);
                            rays++;
                            tight += h0.hit && h0.t < t0 * 1.05f;
                            CHECK_MSG(!memcmp(&h0, &h1, sizeof h0), "L=%u kind %d camera %d block %u pixel (%u %u): hit %u t %g "
                                      "from 0, hit %u t %g from the beam's %g", levels, kind, cam, b, x, y, h0.hit, (double)h0.t,
                                      h1.hit, (double)h1.t, (double)t0);
                        }
                }
            }
            voxdag_free(d);
            rscene_free(&s);
        }
    fprintf(stderr, "  %llu rays in %llu blocks, %llu blocks starting after 0, %llu hits within 5 %% of their start\n",
            (unsigned long long)rays, (unsigned long long)blocks, (unsigned long long)later, (unsigned long long)tight);
    CHECK(later * 4 > blocks && tight > 100);
}

const test_case test_gpu_cases[] = {
    {"gpu/transforms: the 48 symmetries as FORMAT.md defines them", test_gpu_transforms},
    {"gpu/scenes: lookups, colours and rays against brute force and the library", test_gpu_scenes},
    {"gpu/cells: cells and their colours against voxdag_cell_count and voxdag_cell_color", test_gpu_cells},
    {"gpu/golden: the golden files, at offset 0 and inside a larger buffer", test_gpu_golden},
    {"gpu/large: voxelized scenes at L = 9 and 11", test_gpu_large},
    {"gpu/domain: non-finite and tiny inputs", test_gpu_domain},
    {"gpu/beam: rays started at their block's frustum depth answer as from 0", test_gpu_beam},
    {NULL, NULL},
};
