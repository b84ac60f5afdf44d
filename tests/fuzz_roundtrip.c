/* Fuzz target for the build -> save -> load round trip. The input is a small
   voxel scene with its options:
     byte 0    bits 0-4  levels: 2 + value % 20 (2..21)
               bit 5     symmetry none; else reflections when bits 0-4
                         are >= 20, all 48 symmetries below
               bit 6     colours (RGB8 per voxel)
               bit 7     two threads (and the result must equal a one-thread
                         build byte for byte)
     byte 1    bits 0-2  colours saved as a voxcolor stream with error bound
                         BOUNDS[value] (0: kept as RGB8)
               bits 3-4  adding: 0 all at once; 1 in Morton order, flushed
                         every P voxels; 2 like 1, and after each flush a
                         voxel that precedes the flushed ones must be refused
                         with VOXDAG_ERR_ORDER; 3 one call per voxel
               bit 5     the allocator fails at call P * 4 + (byte 1 >> 6)
               bits 6-7  with bit 5 clear: a limit checked exactly (0 none,
                         1 max_nodes, 2 max_levels, 3 max_input_bytes): the
                         load passes at the file's value and fails below it
     byte 2    P
     then      voxels: x, y, z (1 byte each up to 8 levels, else 3 bytes,
               reduced modulo 2^levels), then r, g, b with colours.
   A brute-force oracle built from the same bytes (the distinct voxels sorted
   by Morton code, the colour added last) must agree with the loaded DAG:
   the voxel count, every voxel's lookup and index (its Morton rank), its
   colour (exact, or within the bound as decoded from the voxcolor stream),
   lookups next to every voxel, and voxdag_for_each_voxel. Every allocation
   goes through a counting allocator that holds zero bytes at the end. Any
   violation aborts.

   Built with -DFUZZ_LIBFUZZER and -fsanitize=fuzzer this is a libFuzzer
   target (make fuzz-roundtrip). Otherwise main() replays the files and
   folders given on the command line (make test replays
   tests/data/fuzz/roundtrip) and prints "N passed, N failed". */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#include "count_alloc.h"
#include "fuzz_require.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Allocation failure sweeps of the replay main (fuzz_replay.h). */
#define FUZZ_ALLOC_SWEEP
static long fuzz_fail_at = -1, fuzz_alloc_calls;

// -- The scene and its oracle

typedef struct voxel {
    uint64_t morton;
    size_t order; /* position in the input, so that the last colour wins */
    uint8_t rgb[3];
} voxel;

typedef struct scene {
    uint32_t levels;
    int colors, threads;
    voxdag_symmetry symmetry;
    unsigned bound, adding, fail, limit, p;
    size_t n;         /* voxels as added, in input order */
    uint32_t *xyz;
    uint8_t *rgb;
    size_t distinct;  /* the oracle: distinct voxels sorted by Morton code */
    voxel *sorted;
} scene;

static int by_morton(const void *a, const void *b) {
    const voxel *u = (const voxel *)a, *v = (const voxel *)b;
    if (u->morton != v->morton) return u->morton < v->morton ? -1 : 1;
    return u->order < v->order ? -1 : u->order > v->order;
}

static void scene_read(scene *s, const uint8_t *data, size_t size) {
    size_t cb, rec, i, w;
    uint32_t mask;
    memset(s, 0, sizeof *s);
    s->levels = 2 + (data[0] & 31) % 20;
    s->symmetry = data[0] >> 5 & 1 ? VOXDAG_SYMMETRY_NONE
                  : (data[0] & 31) >= 20 ? VOXDAG_SYMMETRY_REFLECT : VOXDAG_SYMMETRY_FULL;
    s->colors = data[0] >> 6 & 1;
    s->threads = data[0] >> 7 ? 2 : 1;
    s->bound = data[1] & 7;
    s->adding = data[1] >> 3 & 3;
    s->fail = data[1] >> 5 & 1;
    s->limit = data[1] >> 6;
    s->p = data[2];
    mask = (1u << s->levels) - 1;
    cb = s->levels <= 8 ? 1 : 3;
    rec = 3 * cb + (s->colors ? 3 : 0);
    s->n = (size - 3) / rec;
    s->xyz = (uint32_t *)malloc(3 * s->n * sizeof *s->xyz + 1);
    s->rgb = (uint8_t *)malloc(3 * s->n + 1);
    s->sorted = (voxel *)malloc(s->n * sizeof *s->sorted + 1);
    for (i = 0; i < s->n; i++) {
        const uint8_t *r = data + 3 + i * rec;
        unsigned k;
        for (k = 0; k < 3; k++) {
            const uint8_t *c = r + k * cb;
            s->xyz[3 * i + k] = (cb == 1 ? c[0] : (uint32_t)c[0] | (uint32_t)c[1] << 8 | (uint32_t)c[2] << 16) & mask;
            s->rgb[3 * i + k] = s->colors ? r[3 * cb + k] : 0;
        }
        s->sorted[i].morton = voxdag_morton_encode(s->xyz[3 * i], s->xyz[3 * i + 1], s->xyz[3 * i + 2]);
        s->sorted[i].order = i;
        memcpy(s->sorted[i].rgb, s->rgb + 3 * i, 3);
    }
    if (s->n) qsort(s->sorted, s->n, sizeof *s->sorted, by_morton);
    for (i = w = 0; i < s->n; i++) { /* keep the last of equal codes */
        if (w && s->sorted[w - 1].morton == s->sorted[i].morton) w--;
        s->sorted[w++] = s->sorted[i];
    }
    s->distinct = w;
}

static void scene_free(scene *s) {
    free(s->xyz);
    free(s->rgb);
    free(s->sorted);
}

/* Oracle rank of a voxel, or -1 when it is empty. */
static long oracle_find(const scene *s, uint64_t morton) {
    size_t lo = 0, hi = s->distinct;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->sorted[mid].morton < morton) lo = mid + 1;
        else hi = mid;
    }
    return lo < s->distinct && s->sorted[lo].morton == morton ? (long)lo : -1;
}

// -- Build

/* Adds the scene the way byte 1 says; returns the first error. */
static voxdag_status add_all(const scene *s, voxdag_builder *b) {
    voxdag_status st = VOXDAG_OK;
    size_t i, step = s->p ? s->p : 1;
    uint32_t xyz[3];
    if (s->adding == 0) return voxdag_builder_add(b, s->xyz, s->rgb, s->n, NULL);
    if (s->adding == 3) {
        for (i = 0; i < s->n && st == VOXDAG_OK; i++)
            st = voxdag_builder_add(b, s->xyz + 3 * i, s->rgb + 3 * i, 1, NULL);
        return st;
    }
    /* Morton order, in flushed chunks (the sorted oracle order, with every
       repeat in input order, so the colour added last still wins). */
    {
        voxel *all = (voxel *)malloc(s->n * sizeof *all + 1);
        for (i = 0; i < s->n; i++) {
            all[i].morton = voxdag_morton_encode(s->xyz[3 * i], s->xyz[3 * i + 1], s->xyz[3 * i + 2]);
            all[i].order = i;
            memcpy(all[i].rgb, s->rgb + 3 * i, 3);
        }
        if (s->n) qsort(all, s->n, sizeof *all, by_morton);
        for (i = 0; i < s->n && st == VOXDAG_OK; i++) {
            voxdag_morton_decode(all[i].morton, xyz, xyz + 1, xyz + 2);
            st = voxdag_builder_add(b, xyz, all[i].rgb, 1, NULL);
            if (st != VOXDAG_OK || (i + 1) % step) continue;
            st = voxdag_builder_flush(b, NULL);
            if (st == VOXDAG_OK && s->adding == 2 && all[0].morton < all[i].morton) {
                voxdag_morton_decode(all[0].morton, xyz, xyz + 1, xyz + 2);
                require(voxdag_builder_add(b, xyz, all[0].rgb, 1, NULL) == VOXDAG_ERR_ORDER,
                        "a voxel before the flushed ones accepted");
            }
        }
        free(all);
    }
    return st;
}

static voxdag_status build(const scene *s, unsigned threads, const voxdag_allocator *a, voxdag **out) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag_status st;
    memset(&o, 0, sizeof o);
    o.levels = s->levels;
    o.symmetry = s->symmetry == VOXDAG_SYMMETRY_FULL ? VOXDAG_SYMMETRY_DEFAULT : s->symmetry;
    o.colors = s->colors;
    o.threads = threads;
    o.allocator = *a;
    *out = NULL;
    st = voxdag_builder_create(&o, &b, NULL);
    if (st != VOXDAG_OK) return st;
    st = add_all(s, b);
    if (st != VOXDAG_OK) {
        voxdag_builder_free(b);
        return st;
    }
    return voxdag_builder_finish(b, out, NULL, NULL);
}

/* The colours as a voxcolor stream (allocated with A), stored in a copy of
   *D that replaces it. */
static voxdag_status to_voxcolor(voxdag **d, double bound, const voxdag_allocator *a) {
    voxcolor_encode_opts o;
    const void *rgb;
    size_t size, cap, len;
    uint8_t *stream;
    voxdag *e = NULL;
    voxdag_status st;
    require(voxdag_colors(*d, &rgb, &size) == VOXDAG_COLORS_RGB8, "no RGB8 colours");
    cap = voxcolor_encode_bound(size / 3);
    stream = (uint8_t *)a->alloc(a->user, cap);
    if (!stream) return VOXDAG_ERR_OUT_OF_MEMORY;
    memset(&o, 0, sizeof o);
    o.max_error = bound;
    len = voxcolor_encode(stream, cap, (const uint8_t *)rgb, size / 3, &o, NULL);
    require(len > 0, "voxcolor_encode failed");
    st = voxdag_with_colors(*d, VOXDAG_COLORS_VOXCOLOR, stream, len, &e, NULL);
    a->free(a->user, stream, cap);
    if (st == VOXDAG_OK) {
        voxdag_free(*d);
        *d = e;
    }
    return st;
}

// -- Checks on the loaded DAG

typedef struct walk {
    const scene *s;
    uint64_t visited;
} walk;

static int visit(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    walk *w = (walk *)user;
    require(index == w->visited && index < w->s->distinct, "for_each_voxel index");
    require(voxdag_morton_encode(x, y, z) == w->s->sorted[index].morton, "for_each_voxel voxel");
    w->visited++;
    return 0;
}

static void check(const scene *s, const voxdag *d, double bound) {
    voxdag_info info;
    voxcolor_view view;
    const void *payload;
    size_t size, i;
    voxdag_color_kind kind = voxdag_colors(d, &payload, &size);
    walk w;
    voxdag_get_info(d, &info);
    require(info.levels == s->levels && info.voxels == s->distinct, "levels or voxel count");
    require(info.symmetry == s->symmetry, "symmetry group");
    { /* the occupied box, from the voxels */
        uint32_t box[6] = {0, 0, 0, 0, 0, 0}, c[3], k;
        for (i = 0; i < s->distinct; i++) {
            voxdag_morton_decode(s->sorted[i].morton, c, c + 1, c + 2);
            for (k = 0; k < 3; k++) {
                if (!i || c[k] < box[k]) box[k] = c[k];
                if (!i || c[k] + 1 > box[k + 3]) box[k + 3] = c[k] + 1;
            }
        }
        require(!memcmp(box, info.voxel_box, sizeof box), "voxel box");
    }
    require(kind == (!s->colors ? VOXDAG_COLORS_NONE : s->bound ? VOXDAG_COLORS_VOXCOLOR : VOXDAG_COLORS_RGB8),
            "colour kind");
    if (kind == VOXDAG_COLORS_VOXCOLOR) {
        require(voxcolor_view_init(&view, payload, size, NULL) == VOXCOLOR_OK, "voxcolor stream rejected");
        require(view.count == s->distinct, "voxcolor count");
    }
    for (i = 0; i < s->distinct; i++) {
        uint32_t c[3], k;
        uint64_t index = UINT64_MAX;
        uint8_t rgb[3];
        voxdag_morton_decode(s->sorted[i].morton, c, c + 1, c + 2);
        require(voxdag_lookup(d, c[0], c[1], c[2], &index) == 1 && index == i, "voxel index is not its Morton rank");
        if (kind == VOXDAG_COLORS_RGB8)
            require(voxdag_color(d, i, rgb) == 1 && !memcmp(rgb, s->sorted[i].rgb, 3), "RGB8 colour");
        if (kind == VOXDAG_COLORS_VOXCOLOR) {
            double e = 0;
            voxcolor_view_get(&view, i, rgb);
            for (k = 0; k < 3; k++) e += ((double)rgb[k] - s->sorted[i].rgb[k]) * ((double)rgb[k] - s->sorted[i].rgb[k]);
            require(sqrt(e) / 255.0 <= bound + 1e-9, "colour over the error bound");
        }
        /* the six neighbours (and the grid's edge) against the oracle */
        for (k = 0; k < 6; k++) {
            uint32_t n[3] = {c[0], c[1], c[2]};
            n[k >> 1] += k & 1 ? 1u : (uint32_t)-1;
            if ((n[0] | n[1] | n[2]) >> s->levels) {
                require(voxdag_lookup(d, n[0], n[1], n[2], NULL) == 0, "a voxel outside the grid");
                continue;
            }
            index = UINT64_MAX;
            {
                long want = oracle_find(s, voxdag_morton_encode(n[0], n[1], n[2]));
                int got = voxdag_lookup(d, n[0], n[1], n[2], &index);
                require(got == (want >= 0) && (!got || index == (uint64_t)want), "neighbour lookup");
            }
        }
    }
    if (kind == VOXDAG_COLORS_RGB8) {
        uint8_t rgb[3];
        require(voxdag_color(d, s->distinct, rgb) == 0, "colour past the end");
    }
    memset(&w, 0, sizeof w);
    w.s = s;
    require(voxdag_for_each_voxel(d, visit, &w) == s->distinct && w.visited == s->distinct, "for_each_voxel count");
}

/* The exact limit of byte 1: the load passes at the file's own value and is
   refused one below it. */
static void check_limit(const scene *s, const void *img, size_t size, const voxdag_info *info) {
    voxdag_load_opts o;
    voxdag *d = NULL;
    uint64_t nodes = 0;
    uint32_t l;
    for (l = 0; l + 1 < info->levels; l++) nodes += info->nodes[l];
    memset(&o, 0, sizeof o);
    switch (s->limit) {
    case 1: o.max_nodes = nodes; break;
    case 2: o.max_levels = info->levels; break;
    case 3: o.max_input_bytes = size; break;
    default: return;
    }
    require(voxdag_load_memory(img, size, &o, &d, NULL) == VOXDAG_OK, "load refused at its own limit");
    voxdag_free(d);
    d = NULL;
    if (o.max_nodes) o.max_nodes--;
    if (o.max_levels) o.max_levels--;
    if (o.max_input_bytes) o.max_input_bytes--;
    if (o.max_nodes || o.max_levels || o.max_input_bytes) /* 0 would mean no limit */
        require(voxdag_load_memory(img, size, &o, &d, NULL) == VOXDAG_ERR_LIMIT && !d, "load past a limit accepted");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const double bounds[8] = {0, 0, 0.004, 0.01, 0.02, 0.05, 0.1, 0.3};
    scene s;
    count_alloc ca;
    voxdag_allocator a;
    voxdag *built = NULL, *loaded = NULL;
    voxdag_load_opts o;
    voxdag_status st;
    if (size < 3) return 0;
    scene_read(&s, data, size);
    a = ca_start(&ca, fuzz_fail_at >= 0 ? fuzz_fail_at : s.fail ? 4 * (long)s.p + (data[1] >> 6) : -1);
    st = build(&s, (unsigned)s.threads, &a, &built);
    if (st == VOXDAG_OK && s.colors && s.bound) st = to_voxcolor(&built, bounds[s.bound], &a);
    if (st == VOXDAG_OK) {
        size_t img_size;
        const void *img = voxdag_image(built, &img_size);
        memset(&o, 0, sizeof o);
        o.allocator = a;
        o.copy = s.p & 1;
        st = voxdag_load_memory(img, img_size, &o, &loaded, NULL);
        if (st == VOXDAG_OK) {
            size_t size2;
            voxdag_info info;
            require(voxdag_image(loaded, &size2) != NULL && size2 == img_size, "loaded image size");
            require(!memcmp(voxdag_image(loaded, &size2), img, img_size), "loaded image differs");
            check(&s, loaded, bounds[s.bound]);
            voxdag_get_info(loaded, &info);
            if (ca.fail_at < 0) check_limit(&s, img, img_size, &info);
        }
    }
    require(st == VOXDAG_OK || (ca.fail_at >= 0 && st == VOXDAG_ERR_OUT_OF_MEMORY), "round trip failed");
    /* Threads change nothing in the file. */
    if (st == VOXDAG_OK && s.threads > 1 && !(s.colors && s.bound)) {
        voxdag_allocator plain;
        voxdag *one = NULL;
        size_t n1, n2;
        const void *i1, *i2;
        memset(&plain, 0, sizeof plain);
        require(build(&s, 1, &plain, &one) == VOXDAG_OK, "one-thread build failed");
        i1 = voxdag_image(one, &n1);
        i2 = voxdag_image(built, &n2);
        require(n1 == n2 && !memcmp(i1, i2, n2), "threads changed the file");
        voxdag_free(one);
    }
    voxdag_free(loaded);
    voxdag_free(built);
    fuzz_alloc_calls = ca.calls;
    require(ca.held == 0 && !ca.bad_free, "bytes held at the end, or a free of the wrong size");
    scene_free(&s);
    return 0;
}

#ifndef FUZZ_LIBFUZZER
#include "fuzz_replay.h"
#endif
