/* Oracle tests of the builder and the queries: every result is compared with
   a brute-force answer computed here from a dense grid, independently of the
   library's own logic (raster-order subtree contents, sorting, rank). */
#include "test.h"
#include "voxdag.h"
#include "count_alloc.h"

// -- Scenes on a dense grid

typedef struct scene {
    uint32_t levels, n; /* n = 2^levels */
    uint8_t *full;      /* n^3, index x + n*(y + n*z) */
    uint8_t *rgb;       /* 3 per grid cell */
} scene;

static size_t cell(const scene *s, uint32_t x, uint32_t y, uint32_t z) {
    return (size_t)x + (size_t)s->n * ((size_t)y + (size_t)s->n * z);
}

static scene scene_new(uint32_t levels, uint64_t seed) {
    scene s;
    size_t i, cells;
    s.levels = levels;
    s.n = 1u << levels;
    cells = (size_t)s.n * s.n * s.n;
    s.full = (uint8_t *)calloc(cells, 1);
    s.rgb = (uint8_t *)malloc(cells * 3);
    for (i = 0; i < cells * 3; i++) s.rgb[i] = (uint8_t)test_rand(&seed);
    return s;
}

static void scene_free(scene *s) {
    free(s->full);
    free(s->rgb);
}

enum { SC_EMPTY, SC_ONE, SC_FULL, SC_NOISE_SPARSE, SC_NOISE_DENSE, SC_SPHERE, SC_PLANE,
       SC_HEIGHT, SC_MIRRORED_BLOB, SC_CORNERS, SC_TRANSFORMED_BLOB, SC_COUNT };
static const char *const scene_names[SC_COUNT] = {"empty", "one voxel", "full", "sparse noise",
    "dense noise", "sphere", "tilted plane", "heightfield", "mirrored blob", "corners", "transformed blob"};

/* The 48 symmetries of a cube of side SIZE applied to point V: axis a moves
   to axis perm[a] (the permutations enumerated here), then axes in M flip. */
static void cube_image(uint32_t size, unsigned t, const uint32_t v[3], uint32_t out[3]) {
    static unsigned perm[6][3], n = 0;
    unsigned a, b, c;
    if (!n) /* the permutations in lexicographic order, once */
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++)
                for (c = 0; c < 3; c++)
                    if (a != b && b != c && a != c) perm[n][0] = a, perm[n][1] = b, perm[n][2] = c, n++;
    for (a = 0; a < 3; a++) out[perm[t / 8][a]] = v[a];
    for (a = 0; a < 3; a++)
        if (t >> a & 1) out[a] = size - 1 - out[a];
}

static scene make_scene(int kind, uint32_t levels, uint64_t seed) {
    scene s = scene_new(levels, seed);
    uint32_t n = s.n, x, y, z;
    uint64_t r = seed * 7919 + 17;
    size_t i, cells = (size_t)n * n * n;
    switch (kind) {
    case SC_EMPTY: break;
    case SC_ONE: s.full[cell(&s, test_rand_below(&r, n), test_rand_below(&r, n), test_rand_below(&r, n))] = 1; break;
    case SC_FULL: memset(s.full, 1, cells); break;
    case SC_NOISE_SPARSE:
        for (i = 0; i < cells / 50 + 1; i++) s.full[test_rand(&r) % cells] = 1;
        break;
    case SC_NOISE_DENSE:
        for (i = 0; i < cells; i++) s.full[i] = (test_rand(&r) & 1) != 0;
        break;
    case SC_SPHERE: {
        double c = n / 2.0 - 0.3, rad = n * 0.37;
        for (z = 0; z < n; z++)
            for (y = 0; y < n; y++)
                for (x = 0; x < n; x++) {
                    double dx = x + 0.5 - c, dy = y + 0.5 - c, dz = z + 0.5 - c;
                    double d = dx * dx + dy * dy + dz * dz;
                    s.full[cell(&s, x, y, z)] = d <= rad * rad && d >= (rad - 1.5) * (rad - 1.5);
                }
        break;
    }
    case SC_PLANE:
        for (z = 0; z < n; z++)
            for (y = 0; y < n; y++)
                for (x = 0; x < n; x++) s.full[cell(&s, x, y, z)] = (x + 2 * y + 3 * z) / 3 == n / 2;
        break;
    case SC_HEIGHT:
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                uint32_t h = (uint32_t)(n / 3 + (n / 5) * ((x * 7 + y * 3) % 11) / 11 + ((x ^ y) & 1));
                for (z = 0; z <= h && z < n; z++) s.full[cell(&s, x, y, z)] = 1;
            }
        break;
    case SC_MIRRORED_BLOB: {
        /* a random blob in the lower octant, reflected into all 8 octants */
        uint32_t h = n / 2, m;
        for (i = 0; i < (size_t)h * h * h / 12 + 1; i++) {
            uint32_t bx = test_rand_below(&r, h), by = test_rand_below(&r, h), bz = test_rand_below(&r, h);
            for (m = 0; m < 8; m++)
                s.full[cell(&s, m & 1 ? n - 1 - bx : bx, m & 2 ? n - 1 - by : by, m & 4 ? n - 1 - bz : bz)] = 1;
        }
        break;
    }
    case SC_CORNERS:
        for (i = 0; i < 8; i++) s.full[cell(&s, i & 1 ? n - 1 : 0, i & 2 ? n - 1 : 0, i & 4 ? n - 1 : 0)] = 1;
        break;
    case SC_TRANSFORMED_BLOB: {
        /* a random blob copied into 48 of the 64 cells of side n/4, each under
           another of the 48 cube symmetries */
        uint32_t q = n / 4, v[3], w[3];
        unsigned t;
        if (!q) break;
        for (i = 0; i < (size_t)q * q * q / 16 + 1; i++) {
            v[0] = test_rand_below(&r, q), v[1] = test_rand_below(&r, q), v[2] = test_rand_below(&r, q);
            for (t = 0; t < 48; t++) {
                cube_image(q, t, v, w);
                s.full[cell(&s, (t & 3) * q + w[0], (t >> 2 & 3) * q + w[1], (t >> 4) * q + w[2])] = 1;
            }
        }
        break;
    }
    }
    return s;
}

/* The full voxels as coordinate triples in raster order, with colours. */
static size_t scene_voxels(const scene *s, uint32_t **xyz, uint8_t **rgb) {
    size_t count = 0, k = 0, i;
    uint32_t x, y, z;
    for (i = 0; i < (size_t)s->n * s->n * s->n; i++) count += s->full[i];
    *xyz = (uint32_t *)malloc(3 * count * sizeof **xyz + 1);
    *rgb = (uint8_t *)malloc(3 * count + 1);
    for (z = 0; z < s->n; z++)
        for (y = 0; y < s->n; y++)
            for (x = 0; x < s->n; x++) {
                size_t c = cell(s, x, y, z);
                if (!s->full[c]) continue;
                (*xyz)[3 * k] = x;
                (*xyz)[3 * k + 1] = y;
                (*xyz)[3 * k + 2] = z;
                memcpy(*rgb + 3 * k, s->rgb + 3 * c, 3);
                k++;
            }
    return count;
}

// -- Brute-force node counts: distinct subtree contents per level

static size_t key_bytes_global;
static int key_cmp(const void *a, const void *b) { return memcmp(a, b, key_bytes_global); }

/* The full voxels of the cell of size SIZE at (cx,cy,cz), relative to the
   cell, 3 coordinates each. Returns their number. */
static size_t cell_voxels(const scene *s, uint32_t size, uint32_t cx, uint32_t cy, uint32_t cz, uint32_t *v) {
    uint32_t x, y, z;
    size_t n = 0;
    for (z = 0; z < size; z++)
        for (y = 0; y < size; y++)
            for (x = 0; x < size; x++)
                if (s->full[cell(s, cx * size + x, cy * size + y, cz * size + z)])
                    v[3 * n] = x, v[3 * n + 1] = y, v[3 * n + 2] = z, n++;
    return n;
}

/* The image of N voxels V of a cube of side SIZE under symmetry T
   (cube_image), as raster-order bits: its sorted voxel list as a bit set. */
static void cell_key(uint32_t size, const uint32_t *v, size_t n, unsigned t, uint8_t *key) {
    size_t i;
    memset(key, 0, (size_t)size * size * size / 8);
    for (i = 0; i < n; i++) {
        uint32_t w[3];
        size_t bit;
        cube_image(size, t, v + 3 * i, w);
        bit = (size_t)w[0] + (size_t)size * ((size_t)w[1] + (size_t)size * w[2]);
        key[bit >> 3] |= (uint8_t)(1u << (bit & 7));
    }
}

/* Counts per level 0..L-2 of: nonempty cells (SVO) and distinct contents up
   to each group (index G: 0 none, 1 the 8 reflections, 2 all 48 symmetries):
   a cell's class is the smallest key over the group's images. */
static void brute_counts(const scene *s, uint64_t *svo, uint64_t groups[3][VOXDAG_LEVEL_CAPACITY]) {
    uint32_t l;
    unsigned g;
    for (l = 0; l + 1 < s->levels; l++) {
        uint32_t size = s->n >> l, cells = 1u << l, cx, cy, cz;
        size_t kb = (size_t)size * size * size / 8, count = 0, i;
        uint8_t *keys[3], *tmp = (uint8_t *)malloc(kb);
        uint32_t *v = (uint32_t *)malloc(3 * sizeof *v * (size_t)size * size * size);
        for (g = 0; g < 3; g++) keys[g] = (uint8_t *)malloc(kb * (size_t)cells * cells * cells);
        for (cz = 0; cz < cells; cz++)
            for (cy = 0; cy < cells; cy++)
                for (cx = 0; cx < cells; cx++) {
                    size_t nv = cell_voxels(s, size, cx, cy, cz, v);
                    unsigned t;
                    if (!nv) continue;
                    cell_key(size, v, nv, 0, keys[0] + count * kb);
                    memcpy(keys[1] + count * kb, keys[0] + count * kb, kb);
                    for (t = 1; t < 48; t++) {
                        uint8_t *best = keys[t < 8 ? 1 : 2] + count * kb;
                        if (t == 8) memcpy(keys[2] + count * kb, keys[1] + count * kb, kb);
                        cell_key(size, v, nv, t, tmp);
                        if (memcmp(tmp, best, kb) < 0) memcpy(best, tmp, kb);
                    }
                    count++;
                }
        key_bytes_global = kb;
        svo[l] = count;
        for (g = 0; g < 3; g++) {
            qsort(keys[g], count, kb, key_cmp);
            groups[g][l] = 0;
            for (i = 0; i < count; i++)
                if (i == 0 || memcmp(keys[g] + i * kb, keys[g] + (i - 1) * kb, kb)) groups[g][l]++;
            free(keys[g]);
        }
        free(v);
        free(tmp);
    }
}

// -- Building helpers

static voxdag *build(const scene *s, voxdag_symmetry symmetry, uint32_t threads, int compare, voxdag_build_stats *stats) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    uint32_t *xyz;
    uint8_t *rgb;
    size_t n = scene_voxels(s, &xyz, &rgb);
    memset(&o, 0, sizeof o);
    o.levels = s->levels;
    o.symmetry = symmetry;
    o.colors = 1;
    o.threads = threads;
    o.compare_structures = compare;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add(b, xyz, rgb, n, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, stats, NULL) == VOXDAG_OK);
    free(xyz);
    free(rgb);
    return d;
}

typedef struct morton_voxel {
    uint64_t code;
    size_t cell;
} morton_voxel;

static int morton_cmp(const void *a, const void *b) {
    uint64_t x = ((const morton_voxel *)a)->code, y = ((const morton_voxel *)b)->code;
    return x < y ? -1 : x > y;
}

/* Morton code computed bit by bit (independent of voxdag_morton_encode). */
static uint64_t slow_morton(uint32_t x, uint32_t y, uint32_t z, uint32_t levels) {
    uint64_t c = 0;
    uint32_t l;
    for (l = levels; l-- > 0;) c = c << 3 | (x >> l & 1) | (y >> l & 1) << 1 | (z >> l & 1) << 2;
    return c;
}

/* Full voxels sorted by Morton code: position = expected voxel index. */
static size_t sorted_voxels(const scene *s, morton_voxel **out) {
    size_t count = 0, cells = (size_t)s->n * s->n * s->n, i;
    uint32_t x, y, z;
    for (i = 0; i < cells; i++) count += s->full[i];
    *out = (morton_voxel *)malloc(count * sizeof **out + 1);
    count = 0;
    for (z = 0; z < s->n; z++)
        for (y = 0; y < s->n; y++)
            for (x = 0; x < s->n; x++)
                if (s->full[cell(s, x, y, z)]) {
                    (*out)[count].code = slow_morton(x, y, z, s->levels);
                    (*out)[count].cell = cell(s, x, y, z);
                    count++;
                }
    qsort(*out, count, sizeof **out, morton_cmp);
    return count;
}

typedef struct export_check {
    const scene *s;
    const morton_voxel *sorted;
    size_t count, seen;
    int bad;
} export_check;

static int export_cb(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    export_check *e = (export_check *)user;
    if (index != e->seen || e->seen >= e->count || e->sorted[e->seen].cell != cell(e->s, x, y, z)) e->bad++;
    e->seen++;
    return 0;
}

/* Every query of D against the dense grid and the sorted voxel list. */
static void check_queries(const scene *s, const voxdag *d, const char *what) {
    morton_voxel *sorted;
    size_t count = sorted_voxels(s, &sorted), i, cells = (size_t)s->n * s->n * s->n;
    size_t step = cells > 300000 ? 7 : 1, bad_lookup = 0, bad_index = 0, bad_color = 0;
    uint64_t *rank = (uint64_t *)malloc(cells * sizeof *rank);
    voxdag_info info;
    export_check e;
    uint32_t x, y, z;
    for (i = 0; i < count; i++) rank[sorted[i].cell] = i;
    voxdag_get_info(d, &info);
    CHECK_MSG(info.voxels == count, "%s: %llu voxels, expected %llu", what,
              (unsigned long long)info.voxels, (unsigned long long)count);
    for (i = 0; i < cells; i += step) {
        uint64_t index = UINT64_MAX;
        uint8_t c[3];
        int hit;
        x = (uint32_t)(i % s->n);
        y = (uint32_t)(i / s->n % s->n);
        z = (uint32_t)(i / s->n / s->n);
        hit = voxdag_lookup(d, x, y, z, &index);
        if (hit != s->full[i]) bad_lookup++;
        if (!hit) continue;
        if (index != rank[i]) bad_index++;
        if (!voxdag_color(d, index, c) || memcmp(c, s->rgb + 3 * i, 3)) bad_color++;
    }
    /* every full voxel, when the sweep above was sampled */
    for (i = 0; step > 1 && i < count; i++) {
        uint64_t index = UINT64_MAX;
        size_t c = sorted[i].cell;
        if (!voxdag_lookup(d, (uint32_t)(c % s->n), (uint32_t)(c / s->n % s->n), (uint32_t)(c / s->n / s->n), &index) ||
            index != i)
            bad_index++;
    }
    CHECK_MSG(!bad_lookup && !bad_index && !bad_color, "%s: %zu lookups, %zu indices, %zu colours wrong", what,
              bad_lookup, bad_index, bad_color);
    CHECK(voxdag_lookup(d, s->n, 0, 0, NULL) == 0);
    CHECK(voxdag_lookup(d, 0, 0, UINT32_MAX, NULL) == 0);
    e.s = s;
    e.sorted = sorted;
    e.count = count;
    e.seen = 0;
    e.bad = 0;
    CHECK(voxdag_for_each_voxel(d, export_cb, &e) == count);
    CHECK_MSG(!e.bad && e.seen == count, "%s: export differs from the Morton-sorted voxels", what);
    free(rank);
    free(sorted);
}

/* G: the build's group (0 none, 1 reflections, 2 full). */
static void check_counts(const scene *s, const voxdag_build_stats *st, unsigned g, const uint64_t *svo,
                         uint64_t groups[3][VOXDAG_LEVEL_CAPACITY], const char *what) {
    uint32_t l;
    for (l = 0; l + 1 < s->levels; l++) {
        CHECK_MSG(st->nodes[l] == groups[g][l], "%s level %u: %llu nodes, brute force %llu", what, l,
                  (unsigned long long)st->nodes[l], (unsigned long long)groups[g][l]);
        CHECK_MSG(st->svo_nodes[l] == svo[l], "%s level %u: %llu SVO nodes, brute force %llu", what, l,
                  (unsigned long long)st->svo_nodes[l], (unsigned long long)svo[l]);
        CHECK(st->svdag_nodes[l] == groups[0][l]);
        CHECK_MSG(st->reflect_nodes[l] == groups[1][l], "%s level %u: %llu reflection nodes, brute force %llu", what,
                  l, (unsigned long long)st->reflect_nodes[l], (unsigned long long)groups[1][l]);
        CHECK_MSG(st->full_nodes[l] == groups[2][l], "%s level %u: %llu full-group nodes, brute force %llu", what, l,
                  (unsigned long long)st->full_nodes[l], (unsigned long long)groups[2][l]);
    }
}

// -- Test cases

/* Every scene kind at L = 2..6, the larger ones at L = 7 and 8: node counts
   per level equal brute-force distinct contents, with and without symmetry;
   every query agrees with the grid. */
static int oracle_wanted(int kind, uint32_t levels) {
    if (levels <= 6) return 1;
    if (levels == 7)
        return kind == SC_SPHERE || kind == SC_MIRRORED_BLOB || kind == SC_HEIGHT || kind == SC_NOISE_SPARSE ||
               kind == SC_TRANSFORMED_BLOB;
    return kind == SC_MIRRORED_BLOB || kind == SC_TRANSFORMED_BLOB;
}

static void test_oracle_scenes(void) {
    uint32_t levels;
    int kind;
    for (levels = 2; levels <= 8; levels++)
        for (kind = 0; kind < SC_COUNT; kind++) {
            static const char *const group_names[3] = {"none", "reflect", "full"};
            uint64_t svo[VOXDAG_LEVEL_CAPACITY], groups[3][VOXDAG_LEVEL_CAPACITY];
            scene s;
            unsigned g;
            if (!oracle_wanted(kind, levels)) continue;
            s = make_scene(kind, levels, 1000 + levels * 31 + (uint64_t)kind);
            brute_counts(&s, svo, groups);
            for (g = 0; g < 3; g++) {
                voxdag_build_stats st;
                char what[96];
                voxdag *d = build(&s, (voxdag_symmetry)(VOXDAG_SYMMETRY_NONE + g), 1 + (levels & 1), 1, &st);
                snprintf(what, sizeof what, "%s L=%u %s", scene_names[kind], levels, group_names[g]);
                if (!d) continue;
                check_counts(&s, &st, g, svo, groups, what);
                check_queries(&s, d, what);
                voxdag_free(d);
            }
            scene_free(&s);
        }
}

/* The mirrored blob must merge across octants: the root's 8 children are one
   node with symmetry on. */
static void test_mirrored_blob_merges(void) {
    scene s = make_scene(SC_MIRRORED_BLOB, 6, 77);
    voxdag_build_stats st;
    voxdag *d = build(&s, VOXDAG_SYMMETRY_REFLECT, 1, 1, &st);
    CHECK(st.nodes[1] == 1);
    CHECK(st.svdag_nodes[1] == 8);
    voxdag_free(d);
    scene_free(&s);
}

/* The same voxels give byte-identical files whatever the order of input,
   the chunking and the thread count. */
static void test_determinism(void) {
    int kind;
    for (kind = 0; kind < SC_COUNT; kind++) {
        scene s = make_scene(kind, 7, 4242 + (uint64_t)kind);
        uint32_t *xyz;
        uint8_t *rgb;
        size_t n = scene_voxels(&s, &xyz, &rgb), i, size0, size1;
        voxdag *ref = build(&s, VOXDAG_SYMMETRY_DEFAULT, 1, 0, NULL);
        const void *img0 = voxdag_image(ref, &size0);
        uint32_t threads;
        uint64_t seed = 99;
        for (threads = 1; threads <= 4; threads++) {
            voxdag_build_opts o;
            voxdag_builder *b;
            voxdag *d = NULL;
            memset(&o, 0, sizeof o);
            o.levels = 7;
            o.colors = 1;
            o.threads = threads;
            /* shuffled input, added in pieces, with a duplicate of every 5th voxel */
            for (i = n; i > 1; i--) {
                size_t j = test_rand(&seed) % i;
                uint32_t t[3];
                uint8_t c[3];
                memcpy(t, xyz + 3 * (i - 1), sizeof t);
                memcpy(xyz + 3 * (i - 1), xyz + 3 * j, sizeof t);
                memcpy(xyz + 3 * j, t, sizeof t);
                memcpy(c, rgb + 3 * (i - 1), 3);
                memcpy(rgb + 3 * (i - 1), rgb + 3 * j, 3);
                memcpy(rgb + 3 * j, c, 3);
            }
            CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
            for (i = 0; i < n; i += 1000) {
                size_t k = n - i < 1000 ? n - i : 1000;
                CHECK(voxdag_builder_add(b, xyz + 3 * i, rgb + 3 * i, k, NULL) == VOXDAG_OK);
            }
            for (i = 0; i < n; i += 5) CHECK(voxdag_builder_add(b, xyz + 3 * i, rgb + 3 * i, 1, NULL) == VOXDAG_OK);
            CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
            if (d) {
                const void *img1 = voxdag_image(d, &size1);
                CHECK_MSG(size0 == size1 && !memcmp(img0, img1, size0), "%s: image differs with %u threads",
                          scene_names[kind], threads);
            }
            voxdag_free(d);
        }
        voxdag_free(ref);
        free(xyz);
        free(rgb);
        scene_free(&s);
    }
}

// -- Thread pools

/* A host thread pool that runs every job on the calling thread: at once in
   RUN, last first (IMMEDIATE), or in WAIT in a scrambled order. It counts
   batches and jobs and flags a second RUN before the WAIT of the first. */
typedef struct host_pool {
    int immediate;
    voxdag_job_fn job;
    void *job_user;
    uint32_t count;
    int open;
    size_t runs, jobs, misuse;
    uint64_t seed;
} host_pool;

static void host_run(void *user, voxdag_job_fn job, void *job_user, uint32_t count) {
    host_pool *h = (host_pool *)user;
    uint32_t i;
    h->misuse += h->open;
    h->open = 1;
    h->runs++;
    h->jobs += count;
    h->job = job, h->job_user = job_user, h->count = count;
    if (h->immediate)
        for (i = count; i-- > 0;) job(job_user, i);
}

static void host_wait(void *user) {
    host_pool *h = (host_pool *)user;
    uint32_t order[256], i;
    h->misuse += !h->open;
    h->open = 0;
    if (h->immediate) return;
    if (h->count > 256) {
        h->misuse++;
        return;
    }
    for (i = 0; i < h->count; i++) order[i] = i;
    for (i = h->count; i > 1; i--) { /* Fisher-Yates */
        uint32_t j = test_rand_below(&h->seed, i), t = order[i - 1];
        order[i - 1] = order[j];
        order[j] = t;
    }
    for (i = 0; i < h->count; i++) h->job(h->job_user, order[i]);
}

/* The threads that ran a mesh's colour callback, by kernel thread id
   (Linux: ids are not reused soon, so threads made per round would show). */
#if defined(__linux__) && defined(__GNUC__)
#include <sys/syscall.h>
long syscall(long number, ...);
#define POOL_TIDS 64
static long pool_tid[POOL_TIDS];
static void pool_note_thread(void) {
    long me = syscall(SYS_gettid);
    unsigned i;
    for (i = 0; i < POOL_TIDS; i++) {
        long seen = __sync_val_compare_and_swap(&pool_tid[i], 0, me);
        if (seen == 0 || seen == me) return;
    }
}
static void pool_reset_threads(void) { memset(pool_tid, 0, sizeof pool_tid); }
static unsigned pool_thread_count(void) {
    unsigned i = 0;
    while (i < POOL_TIDS && pool_tid[i]) i++;
    return i;
}
#else
static void pool_note_thread(void) {}
static void pool_reset_threads(void) {}
static unsigned pool_thread_count(void) { return 0; }
#endif

static void pool_mesh_color(void *user, size_t tri, const double bary[3], uint8_t rgb[3]) {
    (void)user;
    pool_note_thread();
    rgb[0] = (uint8_t)(tri * 37);
    rgb[1] = (uint8_t)(bary[0] * 255);
    rgb[2] = (uint8_t)(bary[1] * 255);
}

/* Builds, with colours and the other structures compared: VOXELS from the
   scene (shuffled, in two adds), else a mesh of random triangles in chunks
   of 8^3. POOL may be NULL. */
static voxdag *pool_build(const scene *s, int voxels, uint32_t threads, host_pool *pool) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    memset(&o, 0, sizeof o);
    o.levels = s->levels;
    o.colors = 1;
    o.compare_structures = 1;
    o.threads = threads;
    o.chunk_levels = 3;
    if (pool) {
        o.thread_pool.run = host_run;
        o.thread_pool.wait = host_wait;
        o.thread_pool.user = pool;
    }
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    if (!b) return NULL;
    if (voxels) {
        uint32_t *xyz;
        uint8_t *rgb;
        size_t n = scene_voxels(s, &xyz, &rgb), i, half = n / 3;
        uint64_t seed = 5;
        for (i = n; i > 1; i--) {
            size_t j = test_rand(&seed) % i, k;
            for (k = 0; k < 3; k++) {
                uint32_t t = xyz[3 * (i - 1) + k];
                uint8_t c = rgb[3 * (i - 1) + k];
                xyz[3 * (i - 1) + k] = xyz[3 * j + k], xyz[3 * j + k] = t;
                rgb[3 * (i - 1) + k] = rgb[3 * j + k], rgb[3 * j + k] = c;
            }
        }
        CHECK(voxdag_builder_add(b, xyz, rgb, half, NULL) == VOXDAG_OK);
        CHECK(voxdag_builder_add(b, xyz + 3 * half, rgb + 3 * half, n - half, NULL) == VOXDAG_OK);
        free(xyz);
        free(rgb);
    } else {
        double pos[3 * 60];
        uint32_t idx[3 * 20], i;
        uint64_t seed = 77;
        voxdag_mesh m;
        for (i = 0; i < 3 * 60; i++) pos[i] = (double)(test_rand(&seed) % 4096) / 4096.0 * s->n;
        for (i = 0; i < 3 * 20; i++) idx[i] = i;
        memset(&m, 0, sizeof m);
        m.positions = pos, m.vertex_count = 60, m.indices = idx, m.triangle_count = 20;
        m.color = pool_mesh_color;
        CHECK(voxdag_builder_add_mesh(b, &m, NULL) == VOXDAG_OK);
    }
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    return d;
}

/* The same bytes on 1 thread, on 2 and 4 threads of the built-in pool and on
   host pools that run the jobs in reverse inside RUN or scrambled inside
   WAIT; the host pool gets batches of several jobs, one at a time; the
   built-in pool reuses its workers (no more threads than asked for, over
   all the rounds of a mesh). A pool with RUN but no WAIT is refused. */
static void test_thread_pool(void) {
    scene s = make_scene(SC_NOISE_DENSE, 7, 31);
    int voxels;
    for (voxels = 0; voxels < 2; voxels++) {
        voxdag *ref = pool_build(&s, voxels, 1, NULL);
        size_t size0 = 0, size1;
        const void *img0 = ref ? voxdag_image(ref, &size0) : NULL;
        int variant;
        for (variant = 0; variant < 4; variant++) {
            host_pool h;
            voxdag *d;
            uint32_t threads = variant == 0 ? 2 : 4;
            memset(&h, 0, sizeof h);
            h.immediate = variant == 2;
            h.seed = 11 + (uint64_t)variant;
            pool_reset_threads();
            d = pool_build(&s, voxels, threads, variant >= 2 ? &h : NULL);
            if (d) {
                const void *img1 = voxdag_image(d, &size1);
                CHECK_MSG(size0 == size1 && !memcmp(img0, img1, size0), "%s, variant %d: image differs",
                          voxels ? "voxels" : "mesh", variant);
            }
            if (variant >= 2)
                CHECK_MSG(h.runs > 0 && h.jobs >= 2 * h.runs && !h.misuse && !h.open,
                          "%s: %zu runs, %zu jobs, %zu misuses", voxels ? "voxels" : "mesh", h.runs, h.jobs,
                          h.misuse);
            if (!voxels && variant < 2)
                CHECK_MSG(pool_thread_count() <= threads, "mesh on %u threads ran on %u", threads,
                          pool_thread_count());
            if (!voxels && variant >= 2)
                CHECK_MSG(pool_thread_count() <= 1, "a host pool on the calling thread: %u threads",
                          pool_thread_count());
            voxdag_free(d);
        }
        voxdag_free(ref);
    }
    {
        voxdag_build_opts o;
        voxdag_builder *b = NULL;
        voxdag_error e;
        memset(&o, 0, sizeof o);
        o.thread_pool.run = host_run;
        CHECK(voxdag_builder_create(&o, &b, &e) == VOXDAG_ERR_INVALID_ARGUMENT && !b);
    }
    scene_free(&s);
}

/* Voxels added in any order are sorted on the builder's threads: a flush
   of shuffled voxels on a host pool of 3 threads runs each pass of the
   radix sort (2 for L = 7: 21 bits, 11 a pass) as two batches of 3 jobs
   (count, then move), and the file is the one thread's. */
static void test_parallel_sort(void) {
    scene s = make_scene(SC_NOISE_DENSE, 7, 41);
    uint32_t *xyz;
    uint8_t *rgb;
    size_t n = scene_voxels(&s, &xyz, &rgb), i, size[2] = {0, 0};
    uint64_t seed = 9;
    voxdag *d[2] = {NULL, NULL};
    int k;
    CHECK(n >= 1u << 16); /* enough for the parallel sort */
    for (i = n; i > 1; i--) {
        size_t j = test_rand(&seed) % i, c;
        for (c = 0; c < 3; c++) {
            uint32_t t = xyz[3 * (i - 1) + c];
            uint8_t v = rgb[3 * (i - 1) + c];
            xyz[3 * (i - 1) + c] = xyz[3 * j + c], xyz[3 * j + c] = t;
            rgb[3 * (i - 1) + c] = rgb[3 * j + c], rgb[3 * j + c] = v;
        }
    }
    for (k = 0; k < 2; k++) {
        voxdag_build_opts o;
        voxdag_builder *b = NULL;
        host_pool h;
        size_t runs, jobs;
        memset(&o, 0, sizeof o);
        memset(&h, 0, sizeof h);
        h.seed = 3;
        o.levels = 7;
        o.colors = 1;
        o.threads = k ? 3 : 1;
        o.thread_pool.run = host_run;
        o.thread_pool.wait = host_wait;
        o.thread_pool.user = &h;
        CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
        if (!b) continue;
        CHECK(voxdag_builder_add(b, xyz, rgb, n, NULL) == VOXDAG_OK);
        runs = h.runs, jobs = h.jobs;
        CHECK(voxdag_builder_flush(b, NULL) == VOXDAG_OK);
        if (k) CHECK_MSG(h.runs - runs >= 4 && h.jobs - jobs >= 12, "the flush ran %zu batches, %zu jobs",
                         h.runs - runs, h.jobs - jobs);
        CHECK(!h.misuse && !h.open);
        CHECK(voxdag_builder_finish(b, &d[k], NULL, NULL) == VOXDAG_OK);
        if (d[k]) voxdag_image(d[k], &size[k]);
    }
    CHECK(d[0] && d[1] && size[0] == size[1] &&
          !memcmp(voxdag_image(d[0], NULL), voxdag_image(d[1], NULL), size[0]));
    voxdag_free(d[0]);
    voxdag_free(d[1]);
    free(xyz);
    free(rgb);
    scene_free(&s);
}

/* Streaming: Morton-ordered chunks flushed one by one (subtrees of 16^3) give
   the same file as one batch; a voxel before a flushed one is refused. */
static void test_streaming_chunks(void) {
    scene s = make_scene(SC_SPHERE, 7, 5);
    morton_voxel *sorted;
    size_t count = sorted_voxels(&s, &sorted), i, size0, size1;
    voxdag *ref = build(&s, VOXDAG_SYMMETRY_DEFAULT, 2, 0, NULL), *d = NULL;
    voxdag_build_opts o;
    voxdag_builder *b;
    uint32_t xyz[3];
    voxdag_error err;
    memset(&o, 0, sizeof o);
    o.levels = 7;
    o.colors = 1;
    o.threads = 2;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    for (i = 0; i < count; i++) {
        size_t c = sorted[i].cell;
        xyz[0] = (uint32_t)(c % s.n);
        xyz[1] = (uint32_t)(c / s.n % s.n);
        xyz[2] = (uint32_t)(c / s.n / s.n);
        CHECK(voxdag_builder_add(b, xyz, s.rgb + 3 * c, 1, NULL) == VOXDAG_OK);
        if (i + 1 < count && sorted[i].code >> 12 != sorted[i + 1].code >> 12) CHECK(voxdag_builder_flush(b, NULL) == VOXDAG_OK);
    }
    /* the first voxel again precedes the flushed ones */
    xyz[0] = (uint32_t)(sorted[0].cell % s.n);
    xyz[1] = (uint32_t)(sorted[0].cell / s.n % s.n);
    xyz[2] = (uint32_t)(sorted[0].cell / s.n / s.n);
    CHECK(voxdag_builder_add(b, xyz, s.rgb, 1, &err) == VOXDAG_ERR_ORDER && err.status == VOXDAG_ERR_ORDER);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    if (d) {
        const void *a = voxdag_image(ref, &size0), *c = voxdag_image(d, &size1);
        CHECK(size0 == size1 && !memcmp(a, c, size0));
    }
    voxdag_free(d);
    voxdag_free(ref);
    free(sorted);
    scene_free(&s);
}

/* A colour sink gets the colours in voxel-index order, also when a flush
   starts by repeating the last voxel with a new colour: attaching them to the
   sink's colourless DAG gives the file built without a sink. A failing sink
   fails the build. */

static voxdag_status build_streamed(const scene *s, const morton_voxel *sorted, size_t count, sink_buf *sink,
                                    voxdag **out) {
    voxdag_build_opts o;
    voxdag_builder *b;
    size_t i;
    memset(&o, 0, sizeof o);
    o.levels = 7;
    o.colors = 1;
    o.threads = 2;
    if (sink) {
        o.color_sink = sink_collect;
        o.color_sink_user = sink;
    }
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    for (i = 0; i < count; i++) {
        size_t c = sorted[i].cell;
        uint32_t xyz[3];
        uint8_t again[3];
        xyz[0] = (uint32_t)(c % s->n);
        xyz[1] = (uint32_t)(c / s->n % s->n);
        xyz[2] = (uint32_t)(c / s->n / s->n);
        CHECK(voxdag_builder_add(b, xyz, s->rgb + 3 * c, 1, NULL) == VOXDAG_OK);
        if (i + 1 < count && sorted[i].code >> 9 != sorted[i + 1].code >> 9) {
            voxdag_status st = voxdag_builder_flush(b, NULL);
            if (st != VOXDAG_OK) {
                voxdag_builder_free(b);
                return st;
            }
            again[0] = (uint8_t)~s->rgb[3 * c]; /* the same voxel again: its colour changes */
            again[1] = (uint8_t)(i * 7);
            again[2] = 1;
            CHECK(voxdag_builder_add(b, xyz, again, 1, NULL) == VOXDAG_OK);
        }
    }
    return voxdag_builder_finish(b, out, NULL, NULL);
}

static void test_color_sink(void) {
    scene s = make_scene(SC_SPHERE, 7, 6);
    morton_voxel *sorted;
    size_t count = sorted_voxels(&s, &sorted), size0, size1;
    voxdag *ref = NULL, *d = NULL, *with = NULL;
    sink_buf sink;
    voxdag_info info;
    CHECK(build_streamed(&s, sorted, count, NULL, &ref) == VOXDAG_OK);
    sink.rgb = (uint8_t *)malloc(3 * count + 1);
    sink.n = 0;
    sink.cap = count;
    CHECK(build_streamed(&s, sorted, count, &sink, &d) == VOXDAG_OK);
    if (ref && d) {
        const void *a, *c;
        voxdag_get_info(d, &info);
        CHECK(info.voxels == count && sink.n == count && info.color_kind == VOXDAG_COLORS_NONE);
        CHECK(voxdag_with_colors(d, VOXDAG_COLORS_RGB8, sink.rgb, 3 * sink.n, &with, NULL) == VOXDAG_OK);
        a = voxdag_image(ref, &size0);
        c = with ? voxdag_image(with, &size1) : NULL;
        CHECK(c && size0 == size1 && !memcmp(a, c, size0));
    }
    sink.n = 0;
    sink.cap = count / 2;
    voxdag_free(d);
    d = NULL;
    CHECK(build_streamed(&s, sorted, count, &sink, &d) == VOXDAG_ERR_IO && !d);
    voxdag_free(with);
    voxdag_free(ref);
    free(sink.rgb);
    free(sorted);
    scene_free(&s);
}

/* Build -> image -> load (validated) -> the same answers. */
static void test_load_roundtrip(void) {
    int kind;
    for (kind = 0; kind < SC_COUNT; kind++) {
        scene s = make_scene(kind, 6, 300 + (uint64_t)kind);
        voxdag *d = build(&s, VOXDAG_SYMMETRY_DEFAULT, 1, 0, NULL), *e = NULL;
        size_t size;
        const void *img = voxdag_image(d, &size);
        voxdag_error err;
        CHECK_MSG(voxdag_load_memory(img, size, NULL, &e, &err) == VOXDAG_OK, "%s: %s at %llu", scene_names[kind],
                  err.message, (unsigned long long)err.byte_offset);
        if (e) {
            check_queries(&s, e, scene_names[kind]);
            voxdag_free(e);
        }
        voxdag_free(d);
        scene_free(&s);
    }
}

static void test_bad_arguments(void) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag_error err;
    uint32_t xyz[3] = {0, 0, 64};
    memset(&o, 0, sizeof o);
    o.levels = 1;
    CHECK(voxdag_builder_create(&o, &b, &err) == VOXDAG_ERR_LIMIT && !b);
    o.levels = VOXDAG_MAX_LEVELS + 1;
    CHECK(voxdag_builder_create(&o, &b, &err) == VOXDAG_ERR_LIMIT && !b);
    o.levels = 6;
    o.zero_end = 1;
    CHECK(voxdag_builder_create(&o, &b, &err) == VOXDAG_ERR_INVALID_ARGUMENT && !b);
    o.zero_end = 0;
    CHECK(voxdag_builder_create(&o, &b, &err) == VOXDAG_OK);
    CHECK(voxdag_builder_add(b, xyz, NULL, 1, &err) == VOXDAG_ERR_COORDINATE && err.node == 0);
    xyz[2] = 63;
    CHECK(voxdag_builder_add(b, xyz, NULL, 1, &err) == VOXDAG_OK);
    voxdag_builder_free(b);
    CHECK(strcmp(voxdag_status_string(VOXDAG_ERR_CORRUPT), "corrupt data") == 0);
    { /* a large add is checked by several threads: still the first bad voxel */
        size_t n = 300000, i;
        uint32_t *many = (uint32_t *)calloc(3 * n, sizeof *many);
        o.threads = 3;
        for (i = 0; i < 3 * n; i++) many[i] = (uint32_t)(i % 61);
        many[3 * 250000 + 1] = 64;
        many[3 * 280000] = 99;
        CHECK(voxdag_builder_create(&o, &b, &err) == VOXDAG_OK);
        CHECK(voxdag_builder_add(b, many, NULL, n, &err) == VOXDAG_ERR_COORDINATE && err.node == 250000);
        many[3 * 250000 + 1] = 1;
        many[3 * 280000] = 9;
        CHECK(voxdag_builder_add(b, many, NULL, n, &err) == VOXDAG_OK);
        voxdag_builder_free(b);
        free(many);
    }
}

// -- Allocation failure: a counting allocator that fails at call N

static void test_allocation_failures(void) {
    scene s = make_scene(SC_SPHERE, 6, 8);
    uint32_t *xyz;
    uint8_t *rgb;
    size_t n = scene_voxels(&s, &xyz, &rgb);
    long fail_at;
    int done = 0;
    for (fail_at = 0; !done && fail_at < 100000; fail_at++) {
        count_alloc ca;
        voxdag_build_opts o;
        voxdag_builder *b = NULL;
        voxdag *d = NULL;
        voxdag_status st;
        memset(&o, 0, sizeof o);
        o.levels = 6;
        o.colors = 1;
        o.threads = (fail_at & 1) + 1;
        o.allocator = ca_start(&ca, fail_at);
        st = voxdag_builder_create(&o, &b, NULL);
        if (st == VOXDAG_OK) st = voxdag_builder_add(b, xyz, rgb, n, NULL);
        if (st == VOXDAG_OK) st = voxdag_builder_finish(b, &d, NULL, NULL);
        else voxdag_builder_free(b);
        CHECK(st == VOXDAG_OK || st == VOXDAG_ERR_OUT_OF_MEMORY);
        /* a build may succeed past a failed optional allocation (a cache);
           the sweep ends when the failure is no longer reached */
        if (st == VOXDAG_OK) check_queries(&s, d, "after allocation failures");
        done = ca.calls <= fail_at;
        voxdag_free(d);
        CHECK_MSG(ca.held == 0 && !ca.bad_free, "%llu bytes held (bad free: %d) after failing allocation %ld",
                  (unsigned long long)ca.held, ca.bad_free, fail_at);
    }
    CHECK(done);
    free(xyz);
    free(rgb);
    scene_free(&s);
}

// -- Build limits: max_nodes and max_memory refuse exactly past the result's totals

static voxdag_status build_limited(const uint32_t *xyz, const uint8_t *rgb, size_t n, const voxdag_build_opts *base,
                                   uint64_t max_nodes, uint64_t max_memory, int flush, voxdag_build_stats *stats) {
    count_alloc ca;
    voxdag_build_opts o = *base;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_error err;
    voxdag_status st;
    o.max_nodes = max_nodes;
    o.max_memory = max_memory;
    o.allocator = ca_start(&ca, -1);
    st = voxdag_builder_create(&o, &b, &err);
    if (st == VOXDAG_OK) st = voxdag_builder_add(b, xyz, rgb, n, &err);
    if (st == VOXDAG_OK && flush) {
        voxdag_status fs = voxdag_builder_flush(b, &err);
        CHECK(fs == VOXDAG_OK || fs == VOXDAG_ERR_LIMIT || fs == VOXDAG_ERR_OUT_OF_MEMORY);
    }
    if (st == VOXDAG_OK) st = voxdag_builder_finish(b, &d, stats, &err);
    else voxdag_builder_free(b);
    CHECK(st == err.status && (st == VOXDAG_OK) == (d != NULL));
    if (st == VOXDAG_ERR_LIMIT) CHECK(strstr(err.message, max_memory ? "max_memory" : "max_nodes") != NULL);
    voxdag_free(d);
    CHECK(ca.held == 0 && !ca.bad_free);
    return st;
}

static void test_build_limits(void) {
    scene s = make_scene(SC_MIRRORED_BLOB, 6, 5);
    uint32_t *xyz;
    uint8_t *rgb;
    size_t n = scene_voxels(&s, &xyz, &rgb);
    voxdag_build_opts o;
    voxdag_build_stats stats;
    uint64_t nodes = 0;
    uint32_t l;
    int flush, threads;
    memset(&o, 0, sizeof o);
    o.levels = 6;
    o.colors = 1;
    CHECK(build_limited(xyz, rgb, n, &o, 0, 0, 0, &stats) == VOXDAG_OK);
    for (l = 0; l + 1 < stats.levels; l++) nodes += stats.nodes[l];
    CHECK(nodes > 1);
    for (threads = 1; threads <= 2; threads++)
        for (flush = 0; flush < 2; flush++) {
            o.threads = (uint32_t)threads;
            CHECK(build_limited(xyz, rgb, n, &o, nodes, 0, flush, NULL) == VOXDAG_OK);
            CHECK_MSG(build_limited(xyz, rgb, n, &o, nodes - 1, 0, flush, NULL) == VOXDAG_ERR_LIMIT,
                      "max_nodes, %d threads, flush %d", threads, flush);
        }
    /* max_memory: the measured peak passes, one byte less is a limit (not
       out of memory), also when the builder itself does not fit */
    o.threads = 1;
    CHECK(build_limited(xyz, rgb, n, &o, 0, stats.peak_memory, 0, NULL) == VOXDAG_OK);
    CHECK(build_limited(xyz, rgb, n, &o, 0, stats.peak_memory - 1, 0, NULL) == VOXDAG_ERR_LIMIT);
    CHECK(build_limited(xyz, rgb, n, &o, 0, stats.peak_memory - 1, 1, NULL) == VOXDAG_ERR_LIMIT);
    CHECK(build_limited(xyz, rgb, n, &o, 0, 1, 0, NULL) == VOXDAG_ERR_LIMIT);
    free(xyz);
    free(rgb);
    scene_free(&s);
}

/* Every single-byte change of a small image is rejected or, when it only
   touches ignored padding, still loads; never a crash (ASan checks). Every
   truncation is rejected. */
static void test_mutations_rejected(void) {
    scene s = make_scene(SC_MIRRORED_BLOB, 5, 21);
    voxdag *d = build(&s, VOXDAG_SYMMETRY_DEFAULT, 1, 0, NULL);
    size_t size, i;
    const uint8_t *img = (const uint8_t *)voxdag_image(d, &size);
    uint8_t *copy = (uint8_t *)malloc(size);
    int accepted = 0;
    for (i = 0; i < size; i++) {
        int k;
        for (k = 0; k < test_patch_count(); k++) {
            voxdag *e = NULL;
            uint8_t v = test_patch(img[i], k);
            if (v == img[i]) continue;
            memcpy(copy, img, size);
            copy[i] = v;
            if (voxdag_load_memory(copy, size, NULL, &e, NULL) == VOXDAG_OK) {
                accepted++;
                voxdag_free(e);
            }
        }
    }
    CHECK_MSG(accepted == 0, "%d mutated images accepted", accepted);
    for (i = 0; i < size; i++) {
        voxdag *e = NULL;
        uint8_t *cut = (uint8_t *)malloc(i + 1);
        memcpy(cut, img, i);
        CHECK(voxdag_load_memory(cut, i, NULL, &e, NULL) != VOXDAG_OK && !e);
        free(cut);
    }
    free(copy);
    voxdag_free(d);
    scene_free(&s);
}

// -- Progress reports and cancelling

/* What a build reported: every call of progress and of progress_cancel, the
   latter cancelling at its call CANCEL_AT (-1: never). */
typedef struct progress_log {
    long calls, cancel_calls, cancel_at;
    long intermediate;        /* reports with 0 < fraction < 1 */
    int bad;                  /* a fraction outside [0, 1], or decreasing in a stage */
    int cancel_seen;          /* progress and progress_cancel got the same reports */
    const char *stage;        /* of the last report */
    double fraction;
    const char *last_stage;   /* of the last cancel report */
} progress_log;

static void log_progress(void *user, const char *stage, double fraction) {
    progress_log *g = (progress_log *)user;
    if (fraction < 0 || fraction > 1 || (g->stage && !strcmp(g->stage, stage) && fraction < g->fraction &&
                                         strcmp(stage, "reduce")))
        g->bad = 1; /* "reduce" starts again at each flush */
    g->intermediate += fraction > 0 && fraction < 1;
    g->stage = stage;
    g->fraction = fraction;
    g->calls++;
}

static int log_cancel(void *user, const char *stage, double fraction) {
    progress_log *g = (progress_log *)user;
    if (g->stage != stage || g->fraction != fraction) g->bad = 1; /* just after progress, the same report */
    g->last_stage = stage;
    return g->cancel_calls++ == g->cancel_at;
}

enum { PROGRESS_VOXELS, PROGRESS_BRICKS, PROGRESS_MESH, PROGRESS_KINDS };

static void progress_mesh_color(void *user, size_t tri, const double bary[3], uint8_t rgb[3]) {
    (void)user, (void)bary;
    rgb[0] = rgb[1] = rgb[2] = (uint8_t)(tri * 50);
}

/* Builds one input of KIND (voxels: 300k voxels in two adds and a flush;
   bricks: 60k in one call; a mesh: two triangles in chunks of 4^3) with
   both callbacks on G and a counting allocator. Returns the first failing
   status (every call after a failure is still made), with *OUT the DAG. */
static voxdag_status progress_build(int kind, progress_log *g, count_alloc *ca, voxdag **out) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag_status st = VOXDAG_OK, s2;
    size_t i, n;
    memset(&o, 0, sizeof o);
    o.levels = kind == PROGRESS_MESH ? 6 : 9;
    o.colors = 1;
    o.threads = 1;
    o.chunk_levels = 2;
    o.allocator = ca_start(ca, -1);
    o.progress = log_progress;
    o.progress_cancel = log_cancel;
    o.progress_user = g;
    *out = NULL;
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK) return VOXDAG_ERR_INVALID_ARGUMENT;
    if (kind == PROGRESS_VOXELS) {
        uint64_t seed = 3;
        n = 300000;
        uint32_t *xyz = (uint32_t *)malloc(3 * n * sizeof *xyz);
        uint8_t *rgb = (uint8_t *)malloc(3 * n);
        for (i = 0; i < 3 * n; i++) xyz[i] = test_rand_below(&seed, 512), rgb[i] = (uint8_t)i;
        for (i = 0; i < n; i++) xyz[3 * i + 2] = xyz[3 * i + 2] / 2 + (i < n / 2 ? 0 : 256); /* z halves: Morton order */
        st = voxdag_builder_add(b, xyz, rgb, n / 2, NULL);
        s2 = voxdag_builder_flush(b, NULL);
        if (st == VOXDAG_OK) st = s2;
        s2 = voxdag_builder_add(b, xyz + 3 * (n / 2), rgb + 3 * (n / 2), n - n / 2, NULL);
        if (st == VOXDAG_OK) st = s2;
        free(xyz);
        free(rgb);
    } else if (kind == PROGRESS_BRICKS) {
        n = 60000;
        uint64_t *bricks = (uint64_t *)malloc(2 * n * sizeof *bricks);
        uint8_t *rgb = (uint8_t *)malloc(3 * n);
        for (i = 0; i < n; i++) bricks[2 * i] = 3 * i, bricks[2 * i + 1] = 1, rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = 9;
        st = voxdag_builder_add_bricks(b, bricks, rgb, n, NULL);
        free(bricks);
        free(rgb);
    } else {
        static const double pos[] = {0, 0, 5, 64, 0, 30, 64, 64, 50, 0, 64, 20};
        static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
        voxdag_mesh m;
        memset(&m, 0, sizeof m);
        m.positions = pos, m.vertex_count = 4, m.indices = idx, m.triangle_count = 2;
        m.color = progress_mesh_color;
        st = voxdag_builder_add_mesh(b, &m, NULL);
    }
    s2 = voxdag_builder_finish(b, out, NULL, NULL);
    return st == VOXDAG_OK ? s2 : st;
}

/* Every input kind reports real progress (fractions between 0 and 1, not
   just two reports at 100 %), ending with "encode" at 1; progress and
   progress_cancel see the same reports. Cancelling at each report in turn
   fails the build with VOXDAG_ERR_CANCELLED, no DAG, the builder freed by
   finish and nothing leaked; the previous void callback keeps working. */
static void test_progress_cancel(void) {
    static const char *const names[PROGRESS_KINDS] = {"voxels", "bricks", "mesh"};
    int kind;
    CHECK(strcmp(voxdag_status_string(VOXDAG_ERR_CANCELLED), "cancelled") == 0);
    for (kind = 0; kind < PROGRESS_KINDS; kind++) {
        progress_log g;
        count_alloc ca;
        voxdag *d = NULL;
        long reports, k;
        memset(&g, 0, sizeof g);
        g.cancel_at = -1;
        CHECK_MSG(progress_build(kind, &g, &ca, &d) == VOXDAG_OK && d, "%s", names[kind]);
        voxdag_free(d);
        reports = g.calls;
        CHECK_MSG(!g.bad && g.cancel_calls == reports, "%s: %ld and %ld reports", names[kind], reports, g.cancel_calls);
        CHECK_MSG(g.intermediate >= 3, "%s: %ld of %ld reports between 0 and 1", names[kind], g.intermediate, reports);
        CHECK_MSG(g.stage && !strcmp(g.stage, "encode") && g.fraction == 1.0, "%s", names[kind]);
        CHECK_MSG(ca.held == 0 && !ca.bad_free, "%s: %llu bytes held", names[kind], (unsigned long long)ca.held);
        for (k = 0; k < reports; k++) {
            voxdag_status st;
            memset(&g, 0, sizeof g);
            g.cancel_at = k;
            st = progress_build(kind, &g, &ca, &d);
            CHECK_MSG(st == VOXDAG_ERR_CANCELLED && !d, "%s, cancelled at report %ld (%s): %s", names[kind], k,
                      g.last_stage ? g.last_stage : "?", voxdag_status_string(st));
            CHECK_MSG(g.cancel_calls == k + 1, "%s: reports went on after cancelling at %ld", names[kind], k);
            CHECK_MSG(ca.held == 0 && !ca.bad_free, "%s, cancelled at report %ld: %llu bytes held", names[kind], k,
                      (unsigned long long)ca.held);
            voxdag_free(d);
        }
    }
}

const test_case test_core_cases[] = {
    {"core/oracle_scenes", test_oracle_scenes},
    {"core/mirrored_blob_merges", test_mirrored_blob_merges},
    {"core/determinism", test_determinism},
    {"core/thread_pool", test_thread_pool},
    {"core/parallel_sort", test_parallel_sort},
    {"core/streaming_chunks", test_streaming_chunks},
    {"core/color_sink", test_color_sink},
    {"core/load_roundtrip", test_load_roundtrip},
    {"core/bad_arguments", test_bad_arguments},
    {"core/allocation_failures", test_allocation_failures},
    {"core/build_limits", test_build_limits},
    {"core/mutations_rejected", test_mutations_rejected},
    {"core/progress_cancel", test_progress_cancel},
    {NULL, NULL},
};
