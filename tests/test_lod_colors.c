/* Level-of-detail colours (voxdag_cell_color, FORMAT.md LOD_COLORS) against
   brute force: on random dense scenes, every non-empty cell of every level
   has its exact mean computed here from the voxels; voxdag_cell_color must
   give it rounded to RGB8 for cells of at most 64 voxels and, with raw
   colours, for every cell; within 0.02 (RGB distance / 255) of it with
   voxcolor colours. Corrupt sections are refused, and the option turns the
   section off. */
#include "test.h"
#include "voxcolor.h"
#include "voxdag.h"
#include "rscene.h"
#include "golden.h"
#include "count_alloc.h"

#include <math.h>

// -- Brute force: per-level sums of the voxels' colours

typedef struct cell_sums {
    uint32_t levels;
    uint64_t *sum[VOXDAG_MAX_LEVELS + 1]; /* 5 per cell: R, G, B sums, the voxel count, the first index */
} cell_sums;

/* Sums the colours that D gives each full voxel of S into every level's cells. */
static void sums_make(cell_sums *c, const rscene *s, const voxdag *d) {
    uint32_t q, x, y, z, n = s->n;
    memset(c, 0, sizeof *c);
    c->levels = s->levels;
    for (q = 0; q <= s->levels; q++) {
        size_t i, cells = (size_t)1 << (3 * q);
        c->sum[q] = (uint64_t *)calloc(5 * cells, sizeof(uint64_t));
        for (i = 0; c->sum[q] && i < cells; i++) c->sum[q][5 * i + 4] = UINT64_MAX;
    }
    for (z = 0; z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                uint8_t rgb[3];
                if (!s->occ[s->levels][rcell(n, x, y, z)]) continue;
                CHECK(voxdag_color(d, s->rank[rcell(n, x, y, z)], rgb) == 1);
                for (q = 0; q <= s->levels; q++) {
                    uint32_t sh = s->levels - q;
                    uint64_t *e = c->sum[q] + 5 * rcell(1u << q, x >> sh, y >> sh, z >> sh);
                    uint64_t rank = s->rank[rcell(n, x, y, z)];
                    e[0] += rgb[0], e[1] += rgb[1], e[2] += rgb[2], e[3]++;
                    if (rank < e[4]) e[4] = rank;
                }
            }
}

static void sums_free(cell_sums *c) {
    uint32_t q;
    for (q = 0; q <= c->levels; q++) free(c->sum[q]);
}

static double rgb_dist(const uint8_t a[3], const double b[3]) {
    double dr = a[0] - b[0], dg = a[1] - b[1], db = a[2] - b[2];
    return sqrt(dr * dr + dg * dg + db * db) / 255.0;
}

typedef struct lod_stats {
    uint64_t cells, large, exact_large; /* cells checked, of them n > 64, and those exact */
    double worst;                       /* largest distance to the exact mean */
} lod_stats;

/* Checks voxdag_cell_color and voxdag_cell_count on every cell of every
   level of D against C (the count at a point inside the cell).
   EXACT: every cell must be the rounded mean (raw colours); else cells of
   n > 64 need only be within 0.02. */
static void check_cells(const voxdag *d, const cell_sums *c, int exact, lod_stats *st) {
    uint32_t q, levels = c->levels;
    for (q = 0; q <= levels; q++) {
        uint32_t side = 1u << q, x, y, z, sh = levels - q;
        { /* voxdag_cell_count_many over the level's cells in a shuffled order, with points
             outside the grid among them */
            size_t n = (size_t)side * side * side, i, bad = 0;
            uint32_t *xyz = (uint32_t *)malloc(3 * sizeof(uint32_t) * (n + 2));
            uint64_t *count = (uint64_t *)malloc(sizeof(uint64_t) * (n + 2)), *first = (uint64_t *)malloc(sizeof(uint64_t) * (n + 2));
            uint64_t sum = 0, got;
            uint32_t rng = 12345u + q;
            if (!xyz || !count || !first) {
                CHECK(0);
            } else {
                for (i = 0; i < n + 2; i++) {
                    size_t j = i < n ? i : 0;
                    uint32_t inside = (uint32_t)(j * 2654435761u) & ((1u << sh) - 1);
                    xyz[3 * i] = ((uint32_t)(j % side) << sh) + inside;
                    xyz[3 * i + 1] = ((uint32_t)(j / side % side) << sh) + (inside >> 1);
                    xyz[3 * i + 2] = ((uint32_t)(j / side / side) << sh);
                    if (i == n) xyz[3 * i] = 1u << levels; /* outside */
                    if (i == n + 1) xyz[3 * i + 2] = UINT32_MAX;
                }
                for (i = n; i > 1; i--) { /* shuffle the cells (not the two outside points) */
                    size_t j;
                    uint32_t t[3];
                    rng = rng * 1664525u + 1013904223u;
                    j = (size_t)(rng >> 8) % i;
                    memcpy(t, xyz + 3 * (i - 1), sizeof t), memcpy(xyz + 3 * (i - 1), xyz + 3 * j, sizeof t);
                    memcpy(xyz + 3 * j, t, sizeof t);
                }
                got = voxdag_cell_count_many(d, q, xyz, n + 2, count, first);
                for (i = 0; i < n + 2; i++) {
                    const uint64_t *e;
                    if (i >= n) {
                        bad += count[i] != 0;
                        continue;
                    }
                    e = c->sum[q] + 5 * rcell(side, xyz[3 * i] >> sh, xyz[3 * i + 1] >> sh, xyz[3 * i + 2] >> sh);
                    bad += count[i] != e[3] || (e[3] && first[i] != e[4]);
                    sum += e[3];
                }
                CHECK_MSG(bad == 0 && got == sum, "voxdag_cell_count_many level %u: %zu of %zu cells wrong", q, bad,
                          n + 2);
            }
            free(xyz), free(count), free(first);
        }
        for (z = 0; z < side; z++)
            for (y = 0; y < side; y++)
                for (x = 0; x < side; x++) {
                    const uint64_t *e = c->sum[q] + 5 * rcell(side, x, y, z);
                    uint32_t inside = (x * 7 + y * 3 + z) & ((1u << sh) - 1);
                    uint64_t first = 12345;
                    voxdag_hit hit;
                    uint8_t got[3] = {0, 0, 0}, want[3];
                    double mean[3];
                    unsigned k;
                    int r;
                    memset(&hit, 0, sizeof hit);
                    hit.level = q;
                    hit.xyz[0] = x << sh, hit.xyz[1] = y << sh, hit.xyz[2] = z << sh;
                    r = voxdag_cell_color(d, &hit, got);
                    CHECK_MSG(voxdag_cell_count(d, q, hit.xyz[0] + inside, hit.xyz[1], hit.xyz[2] + inside, &first) ==
                                      e[3] && first == (e[3] ? e[4] : 12345),
                              "voxdag_cell_count level %u (%u %u %u)", q, x, y, z);
                    if (!e[3]) {
                        CHECK_MSG(r == 0, "empty cell level %u (%u %u %u): %d", q, x, y, z, r);
                        continue;
                    }
                    CHECK_MSG(r == 1, "cell level %u (%u %u %u): %d", q, x, y, z, r);
                    for (k = 0; k < 3; k++) {
                        mean[k] = (double)e[k] / (double)e[3];
                        want[k] = (uint8_t)((e[k] + e[3] / 2) / e[3]);
                    }
                    st->cells++;
                    if (rgb_dist(got, mean) > st->worst) st->worst = rgb_dist(got, mean);
                    if (e[3] > 64) {
                        st->large++;
                        st->exact_large += !memcmp(got, want, 3);
                    }
                    if (exact || e[3] <= 64)
                        CHECK_MSG(!memcmp(got, want, 3), "level %u (%u %u %u), n %llu: got %u %u %u, want %u %u %u",
                                  q, x, y, z, (unsigned long long)e[3], got[0], got[1], got[2], want[0], want[1],
                                  want[2]);
                    else
                        CHECK_MSG(rgb_dist(got, mean) <= 0.02, "level %u (%u %u %u), n %llu: %.4f from the mean", q,
                                  x, y, z, (unsigned long long)e[3], rgb_dist(got, mean));
                }
    }
}

/* D with every voxel recoloured by a pattern that varies inside cells (so
   that means differ from first voxels), as KIND: raw, or voxcolor at 0.02. */
static voxdag *recolored(const voxdag *d, const rscene *s, voxdag_color_kind kind, const voxdag_build_opts *opts) {
    uint32_t n = s->n, x, y, z;
    voxdag_info info;
    uint8_t *rgb;
    voxdag *out = NULL;
    voxdag_get_info(d, &info);
    rgb = (uint8_t *)malloc(3 * (size_t)info.voxels + 3);
    for (z = 0; z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                uint64_t i;
                if (!s->occ[s->levels][rcell(n, x, y, z)]) continue;
                i = s->rank[rcell(n, x, y, z)];
                rgb[3 * i] = (uint8_t)(x * 255 / (n - 1));
                rgb[3 * i + 1] = (uint8_t)((x ^ y ^ z) * 37 + (y & 4 ? 90 : 0));
                rgb[3 * i + 2] = (uint8_t)(z * 255 / (n - 1) ^ ((x + y) & 1) * 255);
            }
    if (kind == VOXDAG_COLORS_RGB8) {
        CHECK(voxdag_with_colors_opts(d, kind, rgb, 3 * (size_t)info.voxels, opts, &out, NULL) == VOXDAG_OK);
    } else {
        voxcolor_encode_opts vo;
        size_t cap = voxcolor_encode_bound((size_t)info.voxels), len;
        uint8_t *buf = (uint8_t *)malloc(cap);
        memset(&vo, 0, sizeof vo);
        vo.max_error = 0.02;
        len = voxcolor_encode(buf, cap, rgb, (size_t)info.voxels, &vo, NULL);
        CHECK(len > 0);
        CHECK(voxdag_with_colors_opts(d, kind, buf, len, opts, &out, NULL) == VOXDAG_OK);
        free(buf);
    }
    free(rgb);
    return out;
}

static void test_lod_colors_oracle(void) {
    static const int kinds[] = {RS_ONE, RS_FULL, RS_SPARSE, RS_DENSE, RS_SPHERE, RS_PLANE, RS_BLOB, RS_CHECKER};
    lod_stats raw, vc;
    uint32_t levels;
    size_t k;
    memset(&raw, 0, sizeof raw);
    memset(&vc, 0, sizeof vc);
    for (levels = 2; levels <= 6; levels++)
        for (k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
            int sym = (int)((levels + k) % 3);
            rscene s;
            voxdag *d = rscene_make(&s, kinds[k], levels, sym, 0x10D0 + 31 * levels + k), *r, *v;
            voxdag_info info;
            cell_sums c;
            if (!d) continue;
            voxdag_get_info(d, &info);
            /* the builder's file: colours (x, y, z), raw, with the section when it can help */
            CHECK((info.lod_color_bytes > 0) == (levels >= 3 && info.voxels > 64));
            sums_make(&c, &s, d);
            check_cells(d, &c, 1, &raw);
            sums_free(&c);
            if (info.voxels) {
                r = recolored(d, &s, VOXDAG_COLORS_RGB8, NULL);
                v = recolored(d, &s, VOXDAG_COLORS_VOXCOLOR, NULL);
                if (r && v) {
                    sums_make(&c, &s, r);
                    check_cells(r, &c, 1, &raw);
                    sums_free(&c);
                    sums_make(&c, &s, v); /* the exact mean of the decoded voxcolor colours */
                    check_cells(v, &c, 0, &vc);
                    sums_free(&c);
                }
                voxdag_free(r);
                voxdag_free(v);
            }
            voxdag_free(d);
            rscene_free(&s);
        }
    CHECK(raw.large > 1000 && raw.exact_large == raw.large);
    CHECK(vc.large > 1000 && vc.worst <= 0.02);
    printf("  lod colours: raw %llu cells (%llu of n > 64), worst %.4f; voxcolor %llu cells (%llu of n > 64, "
           "%llu exact), worst %.4f\n",
           (unsigned long long)raw.cells, (unsigned long long)raw.large, raw.worst, (unsigned long long)vc.cells,
           (unsigned long long)vc.large, (unsigned long long)vc.exact_large, vc.worst);
}

/* Ray hits at level of detail give the colour of the cell they stopped at,
   whatever want_index. */
static void test_lod_colors_hits(void) {
    rscene s;
    voxdag *d = rscene_make(&s, RS_SPHERE, 6, 2, 0x1D0C);
    cell_sums c;
    uint64_t r = 77, hits = 0, coarse = 0;
    unsigned i;
    if (!d) return;
    sums_make(&c, &s, d);
    for (i = 0; i < 4000; i++) {
        voxdag_ray ray = make_ray(&r, s.n);
        voxdag_ray_opts o;
        voxdag_hit hit;
        memset(&o, 0, sizeof o);
        o.want_index = (int)(i & 1);
        o.lod_factor = 0.02 * (double)(1 + i % 16);
        o.lod_pixels = 1.0;
        if (voxdag_raycast(d, &ray, &o, &hit) > 0) {
            uint32_t sh = s.levels - hit.level;
            const uint64_t *e = c.sum[hit.level] + 5 * rcell(1u << hit.level, hit.xyz[0] >> sh, hit.xyz[1] >> sh,
                                                              hit.xyz[2] >> sh);
            uint8_t got[3], want[3];
            unsigned k;
            CHECK(e[3] > 0);
            for (k = 0; k < 3; k++) want[k] = (uint8_t)((e[k] + e[3] / 2) / e[3]);
            CHECK(voxdag_cell_color(d, &hit, got) == 1 && !memcmp(got, want, 3));
            hits++;
            coarse += e[3] > 64;
        }
    }
    CHECK_MSG(hits > 500 && coarse > 10, "%llu hits, %llu of n > 64", (unsigned long long)hits, (unsigned long long)coarse);
    sums_free(&c);
    voxdag_free(d);
    rscene_free(&s);
}

// -- The option, and files without the section

static void test_lod_colors_option(void) {
    rscene s;
    voxdag *d = rscene_make(&s, RS_DENSE, 6, 1, 0x0FF), *off, *none, *plain = NULL;
    voxdag_build_opts o;
    voxdag_info info;
    cell_sums c;
    uint32_t q, side, x, y, z;
    const void *img;
    size_t size;
    if (!d) return;
    memset(&o, 0, sizeof o);
    o.no_lod_colors = 1;
    off = recolored(d, &s, VOXDAG_COLORS_RGB8, &o);
    voxdag_get_info(off, &info);
    CHECK(info.lod_color_bytes == 0 && info.color_bytes > 0);
    /* without the section: exact for n <= 64, the first voxel for larger cells */
    sums_make(&c, &s, off);
    for (q = 0; q + 2 < s.levels; q++) {
        side = 1u << q;
        for (z = 0; z < side; z++)
            for (y = 0; y < side; y++)
                for (x = 0; x < side; x++) {
                    uint32_t sh = s.levels - q, fx, fy, fz, first = UINT32_MAX;
                    voxdag_hit hit;
                    uint8_t got[3], want[3];
                    uint64_t idx;
                    memset(&hit, 0, sizeof hit);
                    hit.level = q;
                    hit.xyz[0] = x << sh, hit.xyz[1] = y << sh, hit.xyz[2] = z << sh;
                    if (!c.sum[q][5 * rcell(side, x, y, z) + 3]) continue;
                    /* the cell's first voxel in Morton order: the lowest rank in it */
                    for (fz = 0; fz < 1u << sh; fz++)
                        for (fy = 0; fy < 1u << sh; fy++)
                            for (fx = 0; fx < 1u << sh; fx++) {
                                size_t at = rcell(s.n, hit.xyz[0] + fx, hit.xyz[1] + fy, hit.xyz[2] + fz);
                                if (s.occ[s.levels][at] && s.rank[at] < first) first = (uint32_t)s.rank[at];
                            }
                    idx = first;
                    CHECK(voxdag_color(off, idx, want) == 1);
                    CHECK(voxdag_cell_color(off, &hit, got) == 1 && !memcmp(got, want, 3));
                }
    }
    sums_free(&c);
    /* a file without colours has no section; removing colours removes it */
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_NONE, NULL, 0, &none, NULL) == VOXDAG_OK);
    voxdag_get_info(none, &info);
    CHECK(info.lod_color_bytes == 0 && info.color_kind == VOXDAG_COLORS_NONE);
    {
        voxdag_hit hit;
        uint8_t rgb[3];
        memset(&hit, 0, sizeof hit);
        CHECK(voxdag_cell_color(none, &hit, rgb) == 0);
        CHECK(voxdag_cell_color(NULL, &hit, rgb) == 0 && voxdag_cell_color(d, NULL, rgb) == 0 &&
              voxdag_cell_color(d, &hit, NULL) == 0);
        hit.level = s.levels + 1;
        CHECK(voxdag_cell_color(d, &hit, rgb) == 0);
        hit.level = 1, hit.xyz[0] = s.n;
        CHECK(voxdag_cell_color(d, &hit, rgb) == 0);
        /* counts need no colours; outside the grid, past level L or NULL: 0 */
        CHECK(voxdag_cell_count(none, 0, 0, 0, 0, NULL) == voxdag_cell_count(d, 0, 0, 0, 0, NULL));
        CHECK(voxdag_cell_count(d, 0, 0, 0, 0, NULL) == info.voxels || info.voxels == 0);
        CHECK(voxdag_cell_count(d, 1, s.n, 0, 0, NULL) == 0 && voxdag_cell_count(d, 0, 0, UINT32_MAX, 0, NULL) == 0);
        CHECK(voxdag_cell_count(d, s.levels + 1, 0, 0, 0, NULL) == 0 && voxdag_cell_count(NULL, 0, 0, 0, 0, NULL) == 0);
    }
    /* the builder with the option writes the file it wrote before the section */
    {
        voxdag_builder *b;
        uint32_t *xyz = (uint32_t *)malloc(3 * sizeof(uint32_t) << 18);
        uint8_t *rgb = (uint8_t *)malloc((size_t)3 << 18);
        size_t count = 0, dsize;
        const void *dimg;
        for (z = 0; z < s.n; z++)
            for (y = 0; y < s.n; y++)
                for (x = 0; x < s.n; x++)
                    if (s.occ[s.levels][rcell(s.n, x, y, z)]) {
                        xyz[3 * count] = x, xyz[3 * count + 1] = y, xyz[3 * count + 2] = z;
                        rgb[3 * count] = (uint8_t)x, rgb[3 * count + 1] = (uint8_t)y, rgb[3 * count + 2] = (uint8_t)z;
                        count++;
                    }
        memset(&o, 0, sizeof o);
        o.levels = s.levels;
        o.symmetry = VOXDAG_SYMMETRY_REFLECT;
        o.colors = 1;
        o.no_lod_colors = 1;
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        CHECK(voxdag_builder_add(b, xyz, rgb, count, NULL) == VOXDAG_OK);
        CHECK(voxdag_builder_finish(b, &plain, NULL, NULL) == VOXDAG_OK);
        voxdag_get_info(plain, &info);
        CHECK(info.lod_color_bytes == 0);
        /* the default build is this file with the section voxdag_with_colors adds */
        {
            voxdag *again = NULL;
            const void *pc;
            size_t pn;
            CHECK(voxdag_colors(plain, &pc, &pn) == VOXDAG_COLORS_RGB8);
            CHECK(voxdag_with_colors(plain, VOXDAG_COLORS_RGB8, pc, pn, &again, NULL) == VOXDAG_OK);
            img = voxdag_image(again, &size);
            dimg = voxdag_image(d, &dsize);
            CHECK(size == dsize && !memcmp(img, dimg, size));
            voxdag_free(again);
        }
        free(xyz);
        free(rgb);
    }
    voxdag_free(plain);
    voxdag_free(none);
    voxdag_free(off);
    voxdag_free(d);
    rscene_free(&s);
}

// -- Corrupt sections

/* Loads SIZE bytes of IMG (resealed first when RESEAL); returns the status. */
static voxdag_status load(uint8_t *img, size_t size, int reseal, voxdag_error *err) {
    voxdag *d = NULL;
    voxdag_status st;
    if (reseal) golden_reseal(img, size);
    st = voxdag_load_memory(img, size, NULL, &d, err);
    voxdag_free(d);
    return st;
}

/* Corrupt level-of-detail sections of the file D (its section is the last
   one): every header byte patched, the section shortened and lengthened,
   its kind changed, the colour section taken away, and every truncation. */
static void check_corrupt(const voxdag *d) {
    size_t size, cut, i;
    const uint8_t *src = (const uint8_t *)voxdag_image(d, &size);
    uint8_t *img = (uint8_t *)malloc(size + 64), *e;
    uint64_t off, sz;
    voxdag_error err;
    int k;
    memcpy(img, src, size);
    e = golden_section(img, size, VOXDAG_SECTION_LOD_COLORS);
    CHECK(e != NULL);
    if (!e) {
        free(img);
        return;
    }
    off = golden_le(e + 8, 8), sz = golden_le(e + 16, 8);
    CHECK(off + sz == size);              /* the last section here (no bounds) */
    CHECK(golden_le(e + 4, 4) == 1);      /* optional: older readers skip it */
    CHECK(load(img, size, 1, &err) == VOXDAG_OK);
    for (i = 0; i < VOXDAG_FILE_LOD_HEADER_SIZE; i++)
        for (k = 0; k < test_patch_count(); k++) {
            uint8_t was = img[off + i], v = test_patch(was, k);
            if (v == was) continue;
            img[off + i] = v;
            CHECK_MSG(load(img, size, 1, &err) == VOXDAG_ERR_CORRUPT, "header byte %u patched to %u loads", (unsigned)i,
                      v);
            img[off + i] = was;
        }
    /* the section shorter or longer by 8 bytes (the file with it) */
    for (k = -1; k <= 1; k += 2) {
        uint64_t nsz = k < 0 ? sz - 8 : sz + 8;
        size_t nsize = k < 0 ? size - 8 : size + 8;
        memcpy(img, src, size);
        memset(img + size, 0, 64);
        golden_put_le(e + 16, nsz, 8);
        golden_put_le(img + GOLDEN_OFF_FILE_SIZE, nsize, 8);
        CHECK_MSG(load(img, nsize, 1, &err) == VOXDAG_ERR_CORRUPT && strstr(err.message, "level-of-detail"),
                  "section %+d bytes: %s", 8 * k, err.message);
    }
    /* the other kind */
    memcpy(img, src, size);
    img[off] = (uint8_t)(img[off] == VOXDAG_COLORS_RGB8 ? VOXDAG_COLORS_VOXCOLOR : VOXDAG_COLORS_RGB8);
    CHECK(load(img, size, 1, &err) == VOXDAG_ERR_CORRUPT);
    /* no colour section: the colours made an unknown optional section */
    memcpy(img, src, size);
    for (i = 0; i < golden_le(img + GOLDEN_OFF_SECTION_COUNT, 4); i++) {
        uint8_t *c = img + GOLDEN_HEADER_SIZE + i * GOLDEN_SECTION_ENTRY_SIZE;
        uint64_t t = golden_le(c, 4);
        if (t == VOXDAG_SECTION_COLORS_RGB8 || t == VOXDAG_SECTION_COLORS_VOXCOLOR) {
            golden_put_le(c, 99, 4);
            golden_put_le(c + 4, 1, 4);
        }
    }
    CHECK_MSG(load(img, size, 1, &err) == VOXDAG_ERR_CORRUPT && strstr(err.message, "level-of-detail"), "%s",
              err.message);
    /* a slot byte changed: still a valid file (checksums aside) */
    memcpy(img, src, size);
    img[size - 9] ^= 1;
    CHECK(load(img, size, 0, &err) == VOXDAG_ERR_CHECKSUM);
    /* every truncation, as an exact-size copy */
    for (cut = 0; cut < size; cut += cut < off ? 1 + (off - cut) / 64 : 1) {
        uint8_t *t = (uint8_t *)malloc(cut + 1);
        memcpy(t, src, cut);
        CHECK_MSG(load(t, cut, 0, &err) != VOXDAG_OK, "truncated at %u loads", (unsigned)cut);
        free(t);
    }
    free(img);
}

static void test_lod_colors_corrupt(void) {
    rscene s;
    voxdag *d = rscene_make(&s, RS_BLOB, 5, 2, 0xC0), *v;
    if (!d) return;
    check_corrupt(d);
    v = recolored(d, &s, VOXDAG_COLORS_VOXCOLOR, NULL);
    if (v) check_corrupt(v);
    voxdag_free(v);
    voxdag_free(d);
    rscene_free(&s);
}

/* A file written before the section (the coloured golden scene as it was):
   it loads, and gains or loses the section as the only change. */
static uint8_t *read_all(const char *name, size_t *size) {
    char path[4096];
    FILE *f;
    long n;
    uint8_t *p = NULL;
    snprintf(path, sizeof path, "%s/%s", test_data_dir(), name);
    f = fopen(path, "rb");
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0) {
        p = (uint8_t *)malloc((size_t)n);
        if (fread(p, 1, (size_t)n, f) != (size_t)n) free(p), p = NULL;
        *size = (size_t)n;
    }
    fclose(f);
    return p;
}

static void test_lod_colors_older_file(void) {
    size_t old_size = 0, new_size = 0, a_size, b_size, pn;
    uint8_t *old = read_all("lod/mirrored_blob_l5_before_lod.vdag", &old_size);
    uint8_t *cur = read_all("golden/mirrored_blob_l5.vdag", &new_size);
    voxdag *o = NULL, *c = NULL, *added = NULL, *dropped = NULL;
    voxdag_build_opts opts;
    voxdag_info info;
    const void *pc, *a, *b;
    CHECK(old && cur);
    if (!old || !cur) goto done;
    CHECK(voxdag_load_memory(old, old_size, NULL, &o, NULL) == VOXDAG_OK);
    CHECK(voxdag_load_memory(cur, new_size, NULL, &c, NULL) == VOXDAG_OK);
    if (!o || !c) goto done;
    voxdag_get_info(o, &info);
    CHECK(info.lod_color_bytes == 0 && info.color_kind == VOXDAG_COLORS_RGB8);
    voxdag_get_info(c, &info);
    CHECK(info.lod_color_bytes > 0);
    CHECK(voxdag_colors(o, &pc, &pn) == VOXDAG_COLORS_RGB8);
    CHECK(voxdag_with_colors(o, VOXDAG_COLORS_RGB8, pc, pn, &added, NULL) == VOXDAG_OK);
    memset(&opts, 0, sizeof opts);
    opts.no_lod_colors = 1;
    CHECK(voxdag_with_colors_opts(c, VOXDAG_COLORS_RGB8, pc, pn, &opts, &dropped, NULL) == VOXDAG_OK);
    a = voxdag_image(added, &a_size);
    b = voxdag_image(dropped, &b_size);
    CHECK(a_size == new_size && !memcmp(a, cur, new_size));
    CHECK(b_size == old_size && !memcmp(b, old, old_size));
    { /* the root (192 voxels) without the section: its first voxel's colour; with it: the mean */
        voxdag_hit hit;
        uint8_t first[3], got[3], mean[3];
        uint64_t sum[3] = {0, 0, 0}, i;
        unsigned k;
        voxdag_get_info(o, &info);
        for (i = 0; i < info.voxels; i++) {
            CHECK(voxdag_color(o, i, got) == 1);
            for (k = 0; k < 3; k++) sum[k] += got[k];
        }
        for (k = 0; k < 3; k++) mean[k] = (uint8_t)((sum[k] + info.voxels / 2) / info.voxels);
        memset(&hit, 0, sizeof hit);
        CHECK(voxdag_color(o, 0, first) == 1);
        CHECK(voxdag_cell_color(o, &hit, got) == 1 && !memcmp(got, first, 3));
        CHECK(voxdag_cell_color(c, &hit, got) == 1 && !memcmp(got, mean, 3));
    }
done:
    voxdag_free(added);
    voxdag_free(dropped);
    voxdag_free(o);
    voxdag_free(c);
    free(old);
    free(cur);
}

/* A host pool (voxdag_thread_pool) that runs a batch's jobs last first in
   its WAIT, and counts the jobs. */
typedef struct lod_pool {
    voxdag_job_fn job;
    void *job_user;
    uint32_t count;
    size_t jobs;
} lod_pool;

static void lod_pool_run(void *user, voxdag_job_fn job, void *job_user, uint32_t count) {
    lod_pool *p = (lod_pool *)user;
    p->job = job, p->job_user = job_user, p->count = count;
}

static void lod_pool_wait(void *user) {
    lod_pool *p = (lod_pool *)user;
    uint32_t i;
    for (i = p->count; i-- > 0;) p->job(p->job_user, i);
    p->jobs += p->count;
    p->count = 0;
}

/* Options for VARIANT 0..3: 2, 3 or 4 threads of the built-in pool, or 3
   jobs a batch on the host pool P. */
static void lod_variant(int variant, voxdag_build_opts *o, lod_pool *p) {
    memset(o, 0, sizeof *o);
    memset(p, 0, sizeof *p);
    o->threads = variant < 3 ? (uint32_t)variant + 2 : 3;
    if (variant == 3) {
        o->thread_pool.run = lod_pool_run;
        o->thread_pool.wait = lod_pool_wait;
        o->thread_pool.user = p;
    }
}

/* Whether A and B are the same file image. */
static int same_image(const voxdag *a, const voxdag *b) {
    size_t na, nb;
    const void *ia = voxdag_image(a, &na), *ib = voxdag_image(b, &nb);
    return a && b && na == nb && !memcmp(ia, ib, na);
}

/* The level-of-detail means on threads: voxdag_with_colors_opts with 2, 3
   and 4 threads of the built-in pool and on a host pool, and the builder
   with 1 and 4 threads, give the bytes of one thread, for both colour
   kinds: the dense scenes (L = 2..7) and a sphere shell at L = 10, whose
   cells are split a few levels above the ones that sum their voxels. */
static void test_lod_colors_threads(void) {
    static const int kinds[] = {RS_SPARSE, RS_SPHERE, RS_BLOB};
    uint32_t levels;
    size_t k;
    for (levels = 2; levels <= 10; levels += levels < 7 ? 1 : 3) /* 2..7, then 10 */
        for (k = 0; k < (levels <= 7 ? sizeof kinds / sizeof kinds[0] : 1); k++) {
            rscene s;
            voxdag *d = NULL, *one[2];
            int kind, variant;
            if (levels <= 7) d = rscene_make(&s, kinds[k], levels, (int)(k % 3), 0x7D0 + 17 * levels + (uint32_t)k);
            else { /* a sphere shell from voxels, on 1 and 4 threads */
                uint32_t n = 1u << levels, i, count = 0, *xyz = (uint32_t *)malloc(12 * (size_t)200000);
                uint8_t *rgb = (uint8_t *)malloc(3 * (size_t)200000);
                uint64_t r = 0x5EED + levels;
                voxdag *dt[2] = {NULL, NULL};
                unsigned t;
                for (i = 0; xyz && rgb && i < 200000; i++) {
                    double u = (double)test_rand_below(&r, 1u << 20) / (1 << 20) * 2 - 1;
                    double a = (double)test_rand_below(&r, 1u << 20) / (1 << 20) * 6.283185307179586;
                    double rad = 0.45 * n, q = sqrt(1 - u * u);
                    xyz[3 * count] = (uint32_t)(0.5 * n + rad * q * cos(a));
                    xyz[3 * count + 1] = (uint32_t)(0.5 * n + rad * q * sin(a));
                    xyz[3 * count + 2] = (uint32_t)(0.5 * n + rad * u);
                    rgb[3 * count] = (uint8_t)test_rand(&r), rgb[3 * count + 1] = (uint8_t)(xyz[3 * count] >> 2);
                    rgb[3 * count + 2] = (uint8_t)(xyz[3 * count + 2] >> 2);
                    count++;
                }
                for (t = 0; t < 2 && xyz && rgb; t++) {
                    voxdag_build_opts o;
                    voxdag_builder *b = NULL;
                    memset(&o, 0, sizeof o);
                    o.levels = levels;
                    o.colors = 1;
                    o.threads = t ? 4 : 1;
                    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
                    CHECK(voxdag_builder_add(b, xyz, rgb, count, NULL) == VOXDAG_OK);
                    CHECK(voxdag_builder_finish(b, &dt[t], NULL, NULL) == VOXDAG_OK);
                }
                CHECK_MSG(same_image(dt[0], dt[1]), "L = %u: the builder's file differs on 4 threads", levels);
                voxdag_free(dt[1]);
                d = dt[0];
                free(xyz);
                free(rgb);
                if (!d) continue;
                for (kind = 0; kind < 2; kind++) {
                    const void *pc;
                    size_t pn;
                    voxdag_color_kind ck = voxdag_colors(d, &pc, &pn);
                    voxdag *v = NULL;
                    if (kind) { /* a voxcolor copy of the colours */
                        voxcolor_encode_opts vo;
                        size_t cap = voxcolor_encode_bound(pn / 3), len;
                        uint8_t *buf = (uint8_t *)malloc(cap);
                        memset(&vo, 0, sizeof vo);
                        vo.max_error = 0.02;
                        len = buf ? voxcolor_encode(buf, cap, (const uint8_t *)pc, pn / 3, &vo, NULL) : 0;
                        CHECK(len > 0 && voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, buf, len, &v, NULL) == VOXDAG_OK);
                        free(buf);
                        if (!v) continue;
                        ck = voxdag_colors(v, &pc, &pn);
                    }
                    for (variant = 0; variant < 4; variant++) {
                        voxdag_build_opts o;
                        lod_pool p;
                        voxdag *w = NULL;
                        lod_variant(variant, &o, &p);
                        CHECK(voxdag_with_colors_opts(kind ? v : d, ck, pc, pn, &o, &w, NULL) == VOXDAG_OK);
                        CHECK_MSG(same_image(kind ? v : d, w), "L = %u, kind %d: %u threads%s differ", levels, kind,
                                  o.threads, variant == 3 ? " (host pool)" : "");
                        if (variant == 3) CHECK(p.jobs > 0);
                        voxdag_free(w);
                    }
                    voxdag_free(v);
                }
                voxdag_free(d);
                continue;
            }
            if (!d) continue;
            one[0] = recolored(d, &s, VOXDAG_COLORS_RGB8, NULL);
            one[1] = recolored(d, &s, VOXDAG_COLORS_VOXCOLOR, NULL);
            for (kind = 0; kind < 2; kind++)
                for (variant = 0; variant < 4 && one[kind]; variant++) {
                    voxdag_build_opts o;
                    lod_pool p;
                    voxdag *w;
                    lod_variant(variant, &o, &p);
                    w = recolored(d, &s, kind ? VOXDAG_COLORS_VOXCOLOR : VOXDAG_COLORS_RGB8, &o);
                    CHECK_MSG(same_image(one[kind], w), "L = %u, scene %u, kind %d: %u threads%s differ", levels,
                              (unsigned)k, kind, o.threads, variant == 3 ? " (host pool)" : "");
                    voxdag_free(w);
                }
            /* a pool with run but no wait is refused */
            if (one[0]) {
                voxdag_build_opts o;
                lod_pool p;
                const void *pc;
                size_t pn;
                voxdag *w = NULL;
                voxdag_color_kind ck = voxdag_colors(one[0], &pc, &pn);
                memset(&o, 0, sizeof o);
                o.thread_pool.run = lod_pool_run;
                o.thread_pool.user = &p;
                CHECK(voxdag_with_colors_opts(one[0], ck, pc, pn, &o, &w, NULL) == VOXDAG_ERR_INVALID_ARGUMENT && !w);
            }
            voxdag_free(one[0]);
            voxdag_free(one[1]);
            voxdag_free(d);
            rscene_free(&s);
        }
}

/* Every allocation of voxdag_with_colors failing in turn, for both kinds,
   on one thread and on two: VOXDAG_ERR_OUT_OF_MEMORY with nothing held, or
   the same file. */
static void test_lod_colors_allocation_failures(void) {
    rscene s;
    voxdag *d = rscene_make(&s, RS_SPHERE, 5, 1, 0xA110C), *v = NULL;
    int kind;
    if (!d) return;
    v = recolored(d, &s, VOXDAG_COLORS_VOXCOLOR, NULL);
    for (kind = 0; kind < 2 && v; kind++) {
        const voxdag *src = kind ? v : d;
        const void *img, *pc, *want;
        size_t size, pn, want_size;
        count_alloc ca;
        voxdag_load_opts lo;
        voxdag *dag = NULL, *ref = NULL;
        voxdag_color_kind ck;
        long n;
        int done = 0;
        img = voxdag_image(src, &size);
        memset(&lo, 0, sizeof lo);
        lo.allocator = ca_start(&ca, -1);
        CHECK(voxdag_load_memory(img, size, &lo, &dag, NULL) == VOXDAG_OK);
        if (!dag) continue;
        ck = voxdag_colors(dag, &pc, &pn);
        CHECK(voxdag_with_colors(dag, ck, pc, pn, &ref, NULL) == VOXDAG_OK);
        want = voxdag_image(ref, &want_size);
        for (n = 0; !done && n < 2000; n++) {
            uint64_t held = ca.held;
            voxdag *out = NULL;
            voxdag_status st;
            voxdag_build_opts o;
            memset(&o, 0, sizeof o);
            o.threads = (uint32_t)(n & 1) + 1; /* the team's pool and its cells fail too */
            ca.calls = 0, ca.fail_at = n >> 1;
            st = voxdag_with_colors_opts(dag, ck, pc, pn, &o, &out, NULL);
            CHECK_MSG(st == VOXDAG_OK || (st == VOXDAG_ERR_OUT_OF_MEMORY && !out), "kind %d, allocation %ld: %d",
                      kind, n, (int)st);
            if (st == VOXDAG_OK) {
                size_t got_size;
                const void *got = voxdag_image(out, &got_size);
                CHECK(got_size == want_size && !memcmp(got, want, want_size));
                done = ca.calls <= (n >> 1) && (n & 1);
            }
            voxdag_free(out);
            CHECK_MSG(ca.held == held && !ca.bad_free, "kind %d, allocation %ld: %llu bytes left", kind, n,
                      (unsigned long long)(ca.held - held));
        }
        CHECK(done);
        ca.fail_at = -1;
        voxdag_free(ref);
        voxdag_free(dag);
        CHECK(ca.held == 0 && !ca.bad_free);
    }
    voxdag_free(v);
    voxdag_free(d);
    rscene_free(&s);
}

const test_case test_lod_colors_cases[] = {
    {"lod_colors_oracle", test_lod_colors_oracle},
    {"lod_colors_hits", test_lod_colors_hits},
    {"lod_colors_option", test_lod_colors_option},
    {"lod_colors_corrupt", test_lod_colors_corrupt},
    {"lod_colors_older_file", test_lod_colors_older_file},
    {"lod_colors_threads", test_lod_colors_threads},
    {"lod_colors_allocation_failures", test_lod_colors_allocation_failures},
    {NULL, NULL},
};
