/* The embedding API: the CRC-32C against a bitwise reference, loads that
   skip checksums (still structurally validated, queries safe on every
   patched byte), world-space mapping against the affine map computed here,
   colours in one call on voxcolor sections against an independent decode,
   and the brick feed against the same voxels added one by one. */

/* This unit carries its own static copy of the implementation (for the CRC),
   compiled after voxcolor.h's declarations so that voxdag_color decodes
   voxcolor streams (voxcolor's implementation is in tests/impl.c). */
#include "voxcolor.h"
#include "static_impl.h"

#include <math.h>

#include "golden.h"
#include "test.h"

// -- Helpers

/* Random voxels (distinct or not) in a 2^levels grid, with colours. */
typedef struct vox_set {
    uint32_t levels;
    size_t n;
    uint32_t *xyz;
    uint8_t *rgb;
} vox_set;

static vox_set random_voxels(uint32_t levels, size_t n, uint64_t seed) {
    vox_set s;
    uint64_t r = seed;
    size_t i;
    s.levels = levels;
    s.n = n;
    s.xyz = (uint32_t *)malloc(3 * n * sizeof *s.xyz);
    s.rgb = (uint8_t *)malloc(3 * n);
    for (i = 0; i < n; i++) {
        int k;
        /* clustered: a few dense blobs plus noise, so bricks hold several voxels */
        uint32_t c = (uint32_t)(test_rand(&r) % 4), side = 1u << levels;
        for (k = 0; k < 3; k++) {
            uint32_t centre = (side / 5) * (c + 1);
            uint32_t v = i % 7 == 0 ? test_rand_below(&r, side) : centre + test_rand_below(&r, side / 8 + 1);
            s.xyz[3 * i + k] = v % side;
        }
        for (k = 0; k < 3; k++) s.rgb[3 * i + k] = (uint8_t)(s.xyz[3 * i + k] * 7 + (uint32_t)k * 40 + (i % 5));
    }
    return s;
}

static void free_voxels(vox_set *s) {
    free(s->xyz);
    free(s->rgb);
}

/* Builds S (voxels added one call each when ONE_BY_ONE, else at once). */
static voxdag *build_voxels(const vox_set *s, int colors, const double *bounds, int one_by_one) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    size_t i;
    memset(&o, 0, sizeof o);
    o.levels = s->levels;
    o.colors = colors;
    o.bounds = bounds;
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK) return NULL;
    if (one_by_one) {
        for (i = 0; i < s->n; i++) CHECK(voxdag_builder_add(b, s->xyz + 3 * i, s->rgb + 3 * i, 1, NULL) == VOXDAG_OK);
    } else {
        CHECK(voxdag_builder_add(b, s->xyz, s->rgb, s->n, NULL) == VOXDAG_OK);
    }
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    return d;
}

static int same_image(const voxdag *a, const voxdag *b) {
    size_t na, nb;
    const void *pa = voxdag_image(a, &na), *pb = voxdag_image(b, &nb);
    return a && b && na == nb && !memcmp(pa, pb, na);
}

// -- CRC-32C

static void test_crc32c(void) {
    uint8_t *buf = (uint8_t *)malloc((1u << 20) + 8);
    uint64_t r = 11;
    size_t i, n, off, bad = 0;
    static const char check[] = "123456789";
    for (i = 0; i < (1u << 20) + 8; i++) buf[i] = (uint8_t)test_rand(&r);
    /* The standard check value of CRC-32C. */
    CHECK(voxdagi_crc32c((const uint8_t *)check, 9) == 0xE3069283u);
    CHECK(golden_crc32c((const uint8_t *)check, 9) == 0xE3069283u);
    for (i = 0; i < 256; i++) { /* the constant byte table: the register after byte i, bit by bit */
        uint32_t x = (uint32_t)i;
        int k;
        for (k = 0; k < 8; k++) x = x >> 1 ^ (x & 1 ? 0x82F63B78u : 0);
        if (voxdagi_crc_t0[i] != x) bad++;
    }
    CHECK_MSG(bad == 0, "%zu entries of the CRC byte table differ", bad);
    for (off = 0; off < 8; off++)
        for (n = 0; n <= 600; n++)
            if (voxdagi_crc32c(buf + off, n) != golden_crc32c(buf + off, n)) bad++;
    CHECK_MSG(bad == 0, "%zu of 4808 buffers differ from the bitwise CRC", bad);
    for (i = 0; i < 4; i++) {
        n = (size_t)test_rand_below(&r, 1u << 20) + 1;
        off = (size_t)test_rand_below(&r, 8);
        CHECK(voxdagi_crc32c(buf + off, n) == golden_crc32c(buf + off, n));
    }
    free(buf);
}

// -- Loads that skip checksums

/* The offset and size of section TYPE in a valid image. */
static void section_at(uint8_t *img, size_t size, uint32_t type, uint64_t *off, uint64_t *sz) {
    const uint8_t *e = golden_section(img, size, type);
    *off = e ? golden_le(e + 8, 8) : 0;
    *sz = e ? golden_le(e + 16, 8) : 0;
}

static int count_fn(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    (void)x, (void)y, (void)z, (void)index;
    ++*(uint64_t *)user;
    return 0;
}

/* Queries on a loaded DAG: every voxel visited once, lookups, a few rays. */
static int exercise(const voxdag *d) {
    voxdag_info info;
    uint64_t seen = 0, idx;
    uint8_t c[3];
    uint32_t k;
    voxdag_get_info(d, &info);
    voxdag_for_each_voxel(d, count_fn, &seen);
    for (k = 0; k < 64; k++) {
        voxdag_ray ray;
        voxdag_hit hit;
        voxdag_ray_opts o;
        memset(&ray, 0, sizeof ray);
        memset(&o, 0, sizeof o);
        o.want_index = 1;
        ray.origin[0] = -1;
        ray.origin[1] = (double)(k % 8) * (double)(1u << info.levels) / 8 + 0.5;
        ray.origin[2] = (double)(k / 8) * (double)(1u << info.levels) / 8 + 0.5;
        ray.dir[0] = 1;
        ray.dir[1] = 0.01 * k;
        ray.dir[2] = -0.003 * k;
        if (voxdag_raycast(d, &ray, &o, &hit) > 0) voxdag_color(d, hit.index, c);
        voxdag_occluded(d, &ray);
        voxdag_lookup(d, k, k / 2, k / 3, &idx);
    }
    return seen == info.voxels;
}

static void test_skip_checksums(void) {
    vox_set s = random_voxels(6, 3000, 5);
    voxdag *d = build_voxels(&s, 1, NULL, 0), *e = NULL;
    voxdag_load_opts lo;
    voxdag_error err;
    const uint8_t *img;
    uint8_t *copy;
    size_t size, i;
    uint64_t off, sz, loaded = 0, rejected = 0;
    uint8_t c[3];
    img = (const uint8_t *)voxdag_image(d, &size);
    copy = (uint8_t *)malloc(size);
    memset(&lo, 0, sizeof lo);
    lo.skip_checksums = 1;

    /* A colour byte changed: the default load refuses it, the trusting one
       loads it and returns the changed colour. */
    memcpy(copy, img, size);
    section_at(copy, size, VOXDAG_SECTION_COLORS_RGB8, &off, &sz);
    CHECK(sz == 3 * 3000 || sz > 0);
    copy[off + 4] ^= 0x5A;
    CHECK(voxdag_load_memory(copy, size, NULL, &e, &err) == VOXDAG_ERR_CHECKSUM && !e);
    CHECK(voxdag_load_memory(copy, size, &lo, &e, &err) == VOXDAG_OK && e);
    CHECK(e && voxdag_color(e, 1, c) && c[1] == (uint8_t)(img[off + 4] ^ 0x5A));
    voxdag_free(e);

    /* Structure is still validated: an empty brick (checksum fixed or not). */
    memcpy(copy, img, size);
    section_at(copy, size, VOXDAG_SECTION_BRICKS, &off, &sz);
    memset(copy + off, 0, 8);
    CHECK(voxdag_load_memory(copy, size, &lo, &e, &err) == VOXDAG_ERR_CORRUPT && !e);
    /* and the header's and section table's checksums always are. */
    memcpy(copy, img, size);
    copy[VOXDAG_FILE_OFF_VOXEL_BOX] ^= 1;
    CHECK(voxdag_load_memory(copy, size, &lo, &e, &err) == VOXDAG_ERR_CHECKSUM && !e);

    /* Every byte of a colourless file's sections patched: the trusting load
       either refuses it or gives a DAG whose every query runs safely
       (sanitizers watch). */
    voxdag_free(d);
    free_voxels(&s);
    s = random_voxels(5, 700, 6);
    d = build_voxels(&s, 0, NULL, 0);
    img = (const uint8_t *)voxdag_image(d, &size);
    free(copy);
    copy = (uint8_t *)malloc(size);
    for (i = VOXDAG_FILE_HEADER_SIZE; i < size; i++) {
        int k;
        for (k = 0; k < test_patch_count(); k++) {
            memcpy(copy, img, size);
            copy[i] = test_patch(img[i], k);
            if (copy[i] == img[i]) continue;
            if (voxdag_load_memory(copy, size, &lo, &e, NULL) == VOXDAG_OK) {
                loaded++;
                CHECK(exercise(e));
                voxdag_free(e);
            } else {
                rejected++;
                CHECK(!e);
            }
        }
    }
    CHECK(loaded > 0 && rejected > 0);
    free(copy);
    voxdag_free(d);
    free_voxels(&s);
}

// -- World space

static void test_world_space(void) {
    static const double bounds[6] = {-3.5, 10.0, 0.25, 4.5, 26.0, 0.75}; /* 8 x 16 x 0.5: not cubic */
    vox_set s = random_voxels(6, 4000, 9);
    voxdag *d = build_voxels(&s, 0, bounds, 0), *plain = build_voxels(&s, 0, NULL, 0);
    const double N = 64;
    uint64_t r = 3;
    int i, k, hits = 0;
    double w[3], g[3], back[3];
    voxdag_ray wr, gr;
    CHECK(d && plain);
    /* Points: the affine map, and round trips. */
    for (i = 0; i < 2000; i++) {
        double want[3];
        for (k = 0; k < 3; k++) {
            double u = (double)(test_rand(&r) >> 11) / 9007199254740992.0 * 1.4 - 0.2; /* a bit outside too */
            w[k] = bounds[k] + u * (bounds[k + 3] - bounds[k]);
            want[k] = (w[k] - bounds[k]) * N / (bounds[k + 3] - bounds[k]);
        }
        CHECK(voxdag_world_to_grid(d, w, g) == VOXDAG_OK);
        for (k = 0; k < 3; k++) CHECK_MSG(fabs(g[k] - want[k]) <= 1e-12 * N, "axis %d: %.17g vs %.17g", k, g[k], want[k]);
        CHECK(voxdag_grid_to_world(d, g, back) == VOXDAG_OK);
        for (k = 0; k < 3; k++)
            CHECK(fabs(back[k] - w[k]) <= 1e-12 * (fabs(bounds[k]) + fabs(bounds[k + 3])));
        /* grid -> world -> grid, in place */
        for (k = 0; k < 3; k++) back[k] = g[k];
        CHECK(voxdag_grid_to_world(d, back, back) == VOXDAG_OK && voxdag_world_to_grid(d, back, back) == VOXDAG_OK);
        for (k = 0; k < 3; k++) CHECK(fabs(back[k] - g[k]) <= 1e-12 * N);
        /* Without bounds, world space is grid space. */
        CHECK(voxdag_world_to_grid(plain, w, back) == VOXDAG_OK && !memcmp(back, w, sizeof w));
        CHECK(voxdag_grid_to_world(plain, w, back) == VOXDAG_OK && !memcmp(back, w, sizeof w));
    }
    /* Corners: the grid's world box maps to 0 and 2^L exactly. */
    CHECK(voxdag_world_to_grid(d, bounds, g) == VOXDAG_OK && g[0] == 0 && g[1] == 0 && g[2] == 0);
    CHECK(voxdag_world_to_grid(d, bounds + 3, g) == VOXDAG_OK && g[0] == N && g[1] == N && g[2] == N);

    /* Rays: the world ray mapped by the library hits what the same ray,
       mapped here, hits in grid space; the hit's t is a world-space
       parameter whose point lies on the hit voxel. */
    for (i = 0; i < 3000; i++) {
        voxdag_hit hw, hg;
        int a, b;
        memset(&wr, 0, sizeof wr);
        for (k = 0; k < 3; k++) {
            double u = (double)(test_rand(&r) >> 11) / 9007199254740992.0;
            wr.origin[k] = bounds[k] + (u * 1.6 - 0.3) * (bounds[k + 3] - bounds[k]);
        }
        if (i % 4) { /* towards a voxel's centre (most of these hit), else anywhere */
            const uint32_t *v = s.xyz + 3 * test_rand_below(&r, (uint32_t)s.n);
            for (k = 0; k < 3; k++)
                wr.dir[k] = bounds[k] + (v[k] + 0.5) * (bounds[k + 3] - bounds[k]) / N - wr.origin[k];
        } else {
            for (k = 0; k < 3; k++)
                wr.dir[k] = ((double)(test_rand(&r) >> 11) / 9007199254740992.0 - 0.5) * (bounds[k + 3] - bounds[k]);
        }
        wr.t_max = i % 3 ? 0 : 2.5;
        CHECK(voxdag_world_ray(d, &wr, &gr) == VOXDAG_OK);
        CHECK(gr.t_min == wr.t_min && gr.t_max == wr.t_max);
        for (k = 0; k < 3; k++) {
            CHECK(fabs(gr.origin[k] - (wr.origin[k] - bounds[k]) * N / (bounds[k + 3] - bounds[k])) <= 1e-12 * N);
            CHECK(fabs(gr.dir[k] - wr.dir[k] * N / (bounds[k + 3] - bounds[k])) <= 1e-12 * fabs(gr.dir[k]) + 1e-300);
        }
        {
            voxdag_ray oracle = wr;
            for (k = 0; k < 3; k++) {
                oracle.origin[k] = (wr.origin[k] - bounds[k]) * N / (bounds[k + 3] - bounds[k]);
                oracle.dir[k] = wr.dir[k] * N / (bounds[k + 3] - bounds[k]);
            }
            a = voxdag_raycast(d, &gr, NULL, &hw);
            b = voxdag_raycast(plain, &oracle, NULL, &hg);
        }
        CHECK(a == b);
        if (a > 0 && b > 0) {
            hits++;
            /* the same voxel unless the ray grazes an edge (rounding may then pick a neighbour) */
            if (memcmp(hw.xyz, hg.xyz, sizeof hw.xyz)) {
                for (k = 0; k < 3; k++) CHECK((hw.xyz[k] > hg.xyz[k] ? hw.xyz[k] - hg.xyz[k] : hg.xyz[k] - hw.xyz[k]) <= 1);
                CHECK(fabs(hw.t - hg.t) <= 1e-9 * (1 + fabs(hg.t)));
            }
            for (k = 0; k < 3; k++) {
                double p = wr.origin[k] + hw.t * wr.dir[k], cell = (bounds[k + 3] - bounds[k]) / N;
                double lo = bounds[k] + hw.xyz[k] * cell, hi = lo + cell;
                CHECK_MSG(p >= lo - 1e-9 * (bounds[k + 3] - bounds[k]) && p <= hi + 1e-9 * (bounds[k + 3] - bounds[k]),
                          "axis %d: %.17g not in [%.17g, %.17g]", k, p, lo, hi);
            }
        }
    }
    CHECK_MSG(hits > 1000, "%d hits", hits);
    CHECK(voxdag_world_to_grid(NULL, w, g) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_world_to_grid(d, NULL, g) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_grid_to_world(d, g, NULL) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_world_ray(d, NULL, &gr) == VOXDAG_ERR_INVALID_ARGUMENT);
    voxdag_free(d);
    voxdag_free(plain);
    free_voxels(&s);
}

// -- Colours in one call

static void test_color_voxcolor(void) {
    vox_set s = random_voxels(6, 5000, 21);
    voxdag *d = build_voxels(&s, 1, NULL, 0), *v = NULL, *loaded = NULL, *bad = NULL;
    voxdag_info info;
    voxcolor_encode_opts eo;
    voxcolor_view view;
    voxdag_error err;
    uint8_t *raw, *stream, c[3], want[3];
    size_t cap, len, i, size;
    double bound;
    int pass;
    voxdag_get_info(d, &info);
    raw = (uint8_t *)malloc(3 * (size_t)info.voxels);
    for (i = 0; i < info.voxels; i++) CHECK(voxdag_color(d, i, raw + 3 * i));
    cap = voxcolor_encode_bound((size_t)info.voxels);
    stream = (uint8_t *)malloc(cap);
    for (pass = 0; pass < 2; pass++) {
        const void *img;
        memset(&eo, 0, sizeof eo);
        eo.max_error = bound = pass ? 0.05 : 0;
        len = voxcolor_encode(stream, cap, raw, (size_t)info.voxels, &eo, NULL);
        CHECK(len > 0);
        CHECK(voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, stream, len, &v, &err) == VOXDAG_OK);
        img = voxdag_image(v, &size);
        CHECK(voxdag_load_memory(img, size, NULL, &loaded, &err) == VOXDAG_OK);
        {
            voxdag_info li; /* voxcolor.h came first: decodable (tests/test_no_voxcolor.c: not) */
            voxdag_get_info(loaded, &li);
            CHECK(li.color_kind == VOXDAG_COLORS_VOXCOLOR && li.colors_decodable == 1);
        }
        /* The oracle: the stream decoded by its own view, and the original colours. */
        CHECK(voxcolor_view_init(&view, stream, len, NULL) == VOXCOLOR_OK);
        for (i = 0; i < info.voxels; i++) {
            int k;
            double dist = 0;
            voxcolor_view_get(&view, i, want);
            CHECK(voxdag_color(loaded, i, c) == 1 && !memcmp(c, want, 3));
            for (k = 0; k < 3; k++) dist += ((double)c[k] - raw[3 * i + k]) * ((double)c[k] - raw[3 * i + k]);
            CHECK(sqrt(dist) / 255 <= bound + 1e-9);
        }
        CHECK(voxdag_color(loaded, info.voxels, c) == 0);
        /* From a ray hit, in one call. */
        {
            voxdag_ray ray;
            voxdag_ray_opts o;
            voxdag_hit hit;
            uint64_t idx;
            memset(&ray, 0, sizeof ray);
            memset(&o, 0, sizeof o);
            o.want_index = 1;
            ray.origin[0] = s.xyz[0] + 0.5, ray.origin[1] = s.xyz[1] + 0.5, ray.origin[2] = -3;
            ray.dir[2] = 1;
            CHECK(voxdag_raycast(loaded, &ray, &o, &hit) == 1);
            CHECK(voxdag_lookup(loaded, hit.xyz[0], hit.xyz[1], hit.xyz[2], &idx) && idx == hit.index);
            voxcolor_view_get(&view, idx, want);
            CHECK(voxdag_color(loaded, hit.index, c) == 1 && !memcmp(c, want, 3));
        }
        voxdag_free(loaded);
        voxdag_free(v);
        loaded = v = NULL;
    }
    /* A stream that does not validate, or holds another count, is refused. */
    stream[0] ^= 0xFF;
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, stream, len, &bad, &err) == VOXDAG_ERR_CORRUPT && !bad);
    stream[0] ^= 0xFF;
    len = voxcolor_encode(stream, cap, raw, (size_t)info.voxels - 1, NULL, NULL);
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, stream, len, &bad, &err) == VOXDAG_ERR_CORRUPT && !bad);
    /* NULL arguments. */
    CHECK(voxdag_color(NULL, 0, c) == 0 && voxdag_color(d, 0, NULL) == 0);
    free(raw);
    free(stream);
    voxdag_free(d);
    free_voxels(&s);
}

// -- The brick feed

/* The voxels of S as bricks: (key, mask) pairs in Morton order, and their
   colours brick by brick in mask order (the last colour of a repeated voxel). */
static size_t to_bricks(const vox_set *s, uint64_t **bricks_out, uint8_t **rgb_out, size_t *voxels) {
    uint32_t side = 1u << s->levels;
    uint8_t *grid = (uint8_t *)calloc((size_t)side * side * side, 4); /* rgb + full */
    uint64_t *bricks = (uint64_t *)malloc(2 * s->n * sizeof *bricks);
    uint8_t *rgb = (uint8_t *)malloc(3 * s->n);
    uint64_t code, cells = (uint64_t)side * side * side;
    size_t i, nb = 0, nv = 0;
    for (i = 0; i < s->n; i++) {
        const uint32_t *p = s->xyz + 3 * i;
        uint8_t *g = grid + 4 * ((size_t)p[0] + (size_t)side * (p[1] + (size_t)side * p[2]));
        memcpy(g, s->rgb + 3 * i, 3);
        g[3] = 1;
    }
    for (code = 0; code < cells; code++) { /* every voxel in Morton order */
        uint32_t x, y, z;
        const uint8_t *g;
        voxdag_morton_decode(code, &x, &y, &z);
        g = grid + 4 * ((size_t)x + (size_t)side * (y + (size_t)side * z));
        if (!g[3]) continue;
        if (!nb || bricks[2 * nb - 2] != code >> 6) {
            bricks[2 * nb] = code >> 6;
            bricks[2 * nb + 1] = 0;
            nb++;
        }
        bricks[2 * nb - 1] |= 1ull << (code & 63);
        memcpy(rgb + 3 * nv++, g, 3);
    }
    free(grid);
    *bricks_out = bricks;
    *rgb_out = rgb;
    *voxels = nv;
    return nb;
}

static void test_brick_feed(void) {
    static const uint32_t levels[] = {2, 3, 6};
    size_t li;
    for (li = 0; li < 3; li++) {
        vox_set s = random_voxels(levels[li], levels[li] == 6 ? 6000 : 40, 30 + li);
        voxdag *one = build_voxels(&s, 1, NULL, 1), *fed = NULL;
        uint64_t *bricks, *padded;
        uint8_t *rgb;
        size_t nv, nb = to_bricks(&s, &bricks, &rgb, &nv), at = 0, rgb_at = 0, i, np = 0;
        voxdag_build_opts o;
        voxdag_builder *b;
        voxdag_error err;
        uint64_t r = 77;
        memset(&o, 0, sizeof o);
        o.levels = levels[li];
        o.colors = 1;
        /* In random pieces, with empty bricks in between. */
        padded = (uint64_t *)malloc(4 * nb * sizeof *padded);
        for (i = 0; i < nb; i++) {
            if (i % 3 == 0) {
                padded[2 * np] = test_rand(&r); /* any key: a 0 mask is skipped */
                padded[2 * np + 1] = 0;
                np++;
            }
            padded[2 * np] = bricks[2 * i];
            padded[2 * np + 1] = bricks[2 * i + 1];
            np++;
        }
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        while (at < np) {
            size_t m = 1 + test_rand_below(&r, 20), v = 0;
            if (m > np - at) m = np - at;
            for (i = at; i < at + m; i++) v += (size_t)voxdagi_popcount64(padded[2 * i + 1]);
            CHECK(voxdag_builder_add_bricks(b, padded + 2 * at, rgb + 3 * rgb_at, m, &err) == VOXDAG_OK);
            at += m;
            rgb_at += v;
        }
        CHECK(rgb_at == nv);
        CHECK(voxdag_builder_finish(b, &fed, NULL, NULL) == VOXDAG_OK);
        CHECK_MSG(same_image(one, fed), "levels %u: the brick feed's file differs", levels[li]);
        voxdag_free(fed);

        /* Errors leave the builder as it was: the same file after them. */
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        if (nb >= 2) {
            uint64_t swapped[4];
            swapped[0] = bricks[2], swapped[1] = bricks[3], swapped[2] = bricks[0], swapped[3] = bricks[1];
            CHECK(voxdag_builder_add_bricks(b, swapped, rgb, 2, &err) == VOXDAG_ERR_ORDER && err.node == 1);
        }
        {
            uint64_t outside[4];
            outside[0] = bricks[0], outside[1] = bricks[1];
            outside[2] = 1ull << (3 * (levels[li] - 2)), outside[3] = 1;
            CHECK(voxdag_builder_add_bricks(b, outside, rgb, 2, &err) == VOXDAG_ERR_COORDINATE && err.node == 1);
        }
        CHECK(voxdag_builder_add_bricks(b, NULL, rgb, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
        CHECK(voxdag_builder_add_bricks(b, bricks, NULL, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
        CHECK(voxdag_builder_add_bricks(b, bricks, rgb, nb / 2, &err) == VOXDAG_OK);
        /* a brick at or before the last one fed */
        if (nb / 2) CHECK(voxdag_builder_add_bricks(b, bricks + 2 * (nb / 2 - 1), rgb, 1, &err) == VOXDAG_ERR_ORDER);
        {
            size_t v = 0;
            for (i = 0; i < nb / 2; i++) v += (size_t)voxdagi_popcount64(bricks[2 * i + 1]);
            CHECK(voxdag_builder_add_bricks(b, bricks + 2 * (nb / 2), rgb + 3 * v, nb - nb / 2, &err) == VOXDAG_OK);
        }
        CHECK(voxdag_builder_finish(b, &fed, NULL, NULL) == VOXDAG_OK);
        CHECK(same_image(one, fed));
        voxdag_free(fed);

        /* Buffered voxels must be flushed first; then bricks may follow them. */
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        {
            uint32_t x, y, z, xyz[3];
            voxdag_morton_decode(bricks[0] << 6, &x, &y, &z);
            xyz[0] = x, xyz[1] = y, xyz[2] = z;
            CHECK(voxdag_builder_add(b, xyz, rgb, 1, NULL) == VOXDAG_OK);
            CHECK(voxdag_builder_add_bricks(b, bricks + 2, rgb, nb - 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
            CHECK(voxdag_builder_flush(b, NULL) == VOXDAG_OK);
            CHECK(nb < 2 || voxdag_builder_add_bricks(b, bricks + 2, rgb, 1, &err) != VOXDAG_ERR_INVALID_ARGUMENT);
        }
        voxdag_builder_free(b);
        free(padded);
        free(bricks);
        free(rgb);
        voxdag_free(one);
        free_voxels(&s);
    }
}

// -- The stored voxel box

/* Scenes whose voxels sit in a few small clusters anywhere in the grid (so
   that the extremes lie under transformed, shared nodes): the stored box
   must be the box of the voxels computed here, and a file whose box misses
   its voxels by one voxel on any side, or holds more, is refused (checksums
   resealed, so the box check itself must catch it). */
static void test_voxel_box_checked(void) {
    uint32_t levels, seed;
    for (levels = 2; levels <= 9; levels++)
        for (seed = 0; seed < 6; seed++) {
            vox_set s;
            uint64_t r = 100 * levels + seed;
            uint32_t side = 1u << levels, box[6] = {UINT32_MAX, UINT32_MAX, UINT32_MAX, 0, 0, 0}, k;
            size_t i, size;
            voxdag *d;
            voxdag_info info;
            uint8_t *copy;
            const uint8_t *img;
            s.levels = levels;
            s.n = 1 + test_rand_below(&r, 40);
            s.xyz = (uint32_t *)malloc(3 * s.n * sizeof *s.xyz);
            s.rgb = (uint8_t *)calloc(3 * s.n, 1);
            for (i = 0; i < s.n; i++)
                for (k = 0; k < 3; k++) {
                    uint32_t centre = i % 3 == 0 ? test_rand_below(&r, side) : (seed * 37 + k * 11) % side;
                    s.xyz[3 * i + k] = (centre + test_rand_below(&r, 3)) % side;
                }
            for (i = 0; i < s.n; i++)
                for (k = 0; k < 3; k++) {
                    if (s.xyz[3 * i + k] < box[k]) box[k] = s.xyz[3 * i + k];
                    if (s.xyz[3 * i + k] + 1 > box[k + 3]) box[k + 3] = s.xyz[3 * i + k] + 1;
                }
            d = build_voxels(&s, 0, NULL, 0);
            free_voxels(&s);
            if (!d) {
                CHECK(0);
                continue;
            }
            voxdag_get_info(d, &info);
            CHECK_MSG(!memcmp(info.voxel_box, box, sizeof box), "L=%u seed %u: box", levels, seed);
            img = (const uint8_t *)voxdag_image(d, &size);
            copy = (uint8_t *)malloc(size);
            for (k = 0; k < 6; k++) {
                int delta;
                for (delta = -1; delta <= 1; delta += 2) {
                    uint32_t v = box[k] + (uint32_t)delta;
                    voxdag *e = NULL;
                    voxdag_error err;
                    if (v > side || (k < 3 ? v >= box[k + 3] : v <= box[k - 3])) continue; /* refused anyway */
                    memcpy(copy, img, size);
                    golden_put_le(copy + VOXDAG_FILE_OFF_VOXEL_BOX + 4 * k, v, 4);
                    golden_reseal(copy, size);
                    CHECK_MSG(voxdag_load_memory(copy, size, NULL, &e, &err) == VOXDAG_ERR_CORRUPT && !e &&
                                  strstr(err.message, "voxel box") &&
                                  err.byte_offset == VOXDAG_FILE_OFF_VOXEL_BOX + 4 * k,
                              "L=%u seed %u: box field %u moved by %d accepted", levels, seed, k, delta);
                    voxdag_free(e);
                }
            }
            free(copy);
            voxdag_free(d);
        }
}


// -- Rays skip empty space at coarse levels

/* Cells at levels 1..L (L: voxels) that hold a voxel of S and that the ray
   from ORIGIN along DIR crosses inside the grid (interiors, t > 0): what a
   miss may cost, by brute force over S. */
static uint64_t full_cells_crossed(const vox_set *s, const double origin[3], const double dir[3]) {
    uint64_t count = 0, *seen = (uint64_t *)malloc(s->n * sizeof *seen);
    uint32_t q;
    for (q = 1; q <= s->levels; q++) {
        uint32_t sh = s->levels - q;
        size_t i, j, n = 0;
        for (i = 0; i < s->n; i++) {
            uint64_t key = voxdag_morton_encode(s->xyz[3 * i] >> sh, s->xyz[3 * i + 1] >> sh, s->xyz[3 * i + 2] >> sh);
            for (j = 0; j < n && seen[j] != key; j++) continue;
            if (j < n) continue;
            seen[n++] = key;
            {
                double lo = 0, hi = HUGE_VAL;
                int k;
                for (k = 0; k < 3; k++) {
                    double a = (double)((s->xyz[3 * i + k] >> sh) << sh), b = a + (double)(1u << sh), t0, t1;
                    double g = (double)(1u << s->levels);
                    if (a < 0) a = 0;
                    if (b > g) b = g;
                    if (dir[k] == 0) {
                        if (!(origin[k] > a && origin[k] < b)) lo = HUGE_VAL;
                        continue;
                    }
                    t0 = (a - origin[k]) / dir[k], t1 = (b - origin[k]) / dir[k];
                    if (t0 > t1) { double x = t0; t0 = t1; t1 = x; }
                    if (t0 > lo) lo = t0;
                    if (t1 < hi) hi = t1;
                }
                if (lo < hi) count++;
            }
        }
    }
    free(seen);
    return count;
}

/* A lattice of single voxels, one in a corner of every 4^3 brick, and rays
   between its planes (axis-aligned, both ways, and one slowly across): each
   misses, and it steps through (counted inside the traversal) at most two
   cells per full cell it crosses (by brute force) and one per level: the
   full cell, and the step past a node whose full cells are all behind the
   ray, so empty space costs nothing where it is coarse. */
static void test_miss_cost(void) {
    vox_set s;
    voxdag *d;
    uint32_t i, j, k, a, lane;
    /* The reach tables against brute force: octants W ^ F for every subset
       F of AHEAD; brick positions by their coordinate along the axis. */
    for (i = 0; i < 8; i++)
        for (j = 0; j < 8; j++) {
            unsigned want = 0, f;
            for (f = 0; f < 8; f++)
                if (!(f & ~j)) want |= 1u << (i ^ f);
            CHECK_MSG(voxdagi_reach8[i][j] == want, "reach8[%u][%u]", i, j);
        }
    for (a = 0; a < 3; a++)
        for (i = 0; i < 4; i++)
            for (k = 0; k < 3; k++) {
                uint64_t want = 0;
                unsigned p;
                for (p = 0; p < 64; p++) {
                    uint32_t v = (p >> a & 1) | (p >> (a + 3) & 1) << 1;
                    if (k == 0 ? v == i : k == 1 ? v >= i : v <= i) want |= 1ull << p;
                }
                CHECK_MSG(voxdagi_brick_reach[a][i][k] == want, "brick_reach[%u][%u][%u]", a, i, k);
            }
    s.levels = 6;
    s.n = 16 * 16 * 16;
    s.xyz = (uint32_t *)malloc(3 * s.n * sizeof *s.xyz);
    s.rgb = (uint8_t *)calloc(3 * s.n, 1);
    for (i = 0; i < 16; i++)
        for (j = 0; j < 16; j++)
            for (k = 0; k < 16; k++) {
                uint32_t *p = s.xyz + 3 * (256 * i + 16 * j + k);
                p[0] = 4 * i + (i & 1), p[1] = 4 * j + (j & 1), p[2] = 4 * k + (k & 1);
            }
    d = build_voxels(&s, 0, NULL, 0);
    if (!d) {
        CHECK(0);
        free_voxels(&s);
        return;
    }
    for (a = 0; a < 3; a++)
        for (lane = 0; lane < 8; lane++) {
            int sign;
            for (sign = -1; sign <= 1; sign += 2) {
                voxdag_ray ray;
                voxdag_hit hit;
                uint64_t steps = 0, full;
                memset(&ray, 0, sizeof ray);
                ray.origin[a] = sign > 0 ? -3.0 : 67.0;
                ray.dir[a] = sign;
                ray.origin[(a + 1) % 3] = 8.0 * lane + 2.5 + (lane & 1); /* between the lattice planes */
                ray.origin[(a + 2) % 3] = 8.0 * (7 - lane) + 3.5;
                if (lane == 7) ray.dir[(a + 1) % 3] = 0.01 * sign; /* across the lattice, slowly */
                CHECK_MSG(voxdagi_trace(d, &ray, 0, 0, 0, &hit, &steps) == 0, "axis %u lane %u: a hit", a, lane);
                full = full_cells_crossed(&s, ray.origin, ray.dir);
                CHECK_MSG(steps <= 2 * full + s.levels, "axis %u lane %u sign %d: %llu steps for %llu full cells crossed",
                          a, lane, sign, (unsigned long long)steps, (unsigned long long)full);
            }
        }
    voxdag_free(d);
    free_voxels(&s);
}

const test_case test_api_cases[] = {
    {"api/crc32c", test_crc32c},
    {"api/skip_checksums", test_skip_checksums},
    {"api/world_space", test_world_space},
    {"api/color_voxcolor", test_color_voxcolor},
    {"api/brick_feed", test_brick_feed},
    {"api/voxel_box_checked", test_voxel_box_checked},
    {"api/miss_cost", test_miss_cost},
    {NULL, NULL},
};
