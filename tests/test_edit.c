/* The editor against a brute-force model: a dense grid of full flags and
   colours, indexed by Morton code, with a snapshot per edit for undo and
   redo. After every edit the editor's voxels, indices, colours, lookups and
   rays must match the model, and its commit must be the very bytes the
   builder makes of the model's voxels with the same options. */
#include "voxcolor.h"
#include "voxdag.h"
#include "test.h"
#include "count_alloc.h"

#define WHITE 0xFFFFFFu

typedef struct model {
    uint32_t levels, n;  /* n = 2^levels per axis */
    size_t cells;
    uint8_t *full;       /* per Morton code */
    uint32_t *rgb;       /* 0xRRGGBB per Morton code */
} model;

/* A state per applied edit, for undo and redo. */
typedef struct history {
    model *state;
    size_t done, kept, cap;
} history;

static void model_init(model *m, uint32_t levels) {
    m->levels = levels;
    m->n = 1u << levels;
    m->cells = (size_t)1 << 3 * levels;
    m->full = (uint8_t *)calloc(m->cells, 1);
    m->rgb = (uint32_t *)calloc(m->cells, sizeof *m->rgb);
}

static void model_copy(model *dst, const model *src) {
    model_init(dst, src->levels);
    memcpy(dst->full, src->full, src->cells);
    memcpy(dst->rgb, src->rgb, src->cells * sizeof *src->rgb);
}

static void model_free(model *m) {
    free(m->full);
    free(m->rgb);
}

static uint32_t pack(const uint8_t c[3]) { return (uint32_t)c[0] << 16 | (uint32_t)c[1] << 8 | c[2]; }

static void brush_at(void *user, uint32_t x, uint32_t y, uint32_t z, uint8_t rgb[3]) {
    uint32_t salt = *(const uint32_t *)user;
    rgb[0] = (uint8_t)(x * 7 + y + salt);
    rgb[1] = (uint8_t)(y * 13 + z);
    rgb[2] = (uint8_t)(z * 5 + x + salt * 3);
}

static int in_grid(const model *m, int64_t v) { return v >= 0 && v < (int64_t)m->n; }

static int in_shape(const voxdag_shape *s, int64_t x, int64_t y, int64_t z) {
    if (s->kind == VOXDAG_SHAPE_BOX)
        return x >= s->lo[0] && x < s->hi[0] && y >= s->lo[1] && y < s->hi[1] && z >= s->lo[2] && z < s->hi[2];
    {
        int64_t dx = 2 * x + 1 - 2 * s->center[0], dy = 2 * y + 1 - 2 * s->center[1];
        int64_t dz = 2 * z + 1 - 2 * s->center[2];
        return dx * dx + dy * dy + dz * dz <= 4 * s->radius * s->radius;
    }
}

static uint32_t brush_color(const voxdag_brush *b, uint32_t x, uint32_t y, uint32_t z) {
    uint8_t c[3];
    if (!b->fn) return pack(b->rgb);
    b->fn(b->user, x, y, z, c);
    return pack(c);
}

enum { OP_FILL, OP_CARVE, OP_PAINT };

static void model_shape(model *m, int op, const voxdag_shape *s, const voxdag_brush *b) {
    uint32_t x, y, z;
    for (z = 0; z < m->n; z++)
        for (y = 0; y < m->n; y++)
            for (x = 0; x < m->n; x++) {
                size_t c = (size_t)voxdag_morton_encode(x, y, z);
                if (!in_shape(s, x, y, z)) continue;
                if (op == OP_CARVE) m->full[c] = 0;
                if (op == OP_PAINT && m->full[c]) m->rgb[c] = brush_color(b, x, y, z);
                if (op == OP_FILL) {
                    if (b) m->rgb[c] = brush_color(b, x, y, z);
                    else if (!m->full[c]) m->rgb[c] = WHITE;
                    m->full[c] = 1;
                }
            }
}

static void model_copy_box(model *m, const int64_t lo[3], const int64_t hi[3], const int64_t d[3]) {
    model src;
    int64_t x, y, z;
    model_copy(&src, m);
    for (z = lo[2]; z < hi[2]; z++)
        for (y = lo[1]; y < hi[1]; y++)
            for (x = lo[0]; x < hi[0]; x++) {
                size_t s, t;
                if (!in_grid(m, x) || !in_grid(m, y) || !in_grid(m, z)) continue;
                if (!in_grid(m, x + d[0]) || !in_grid(m, y + d[1]) || !in_grid(m, z + d[2])) continue;
                s = (size_t)voxdag_morton_encode((uint32_t)x, (uint32_t)y, (uint32_t)z);
                t = (size_t)voxdag_morton_encode((uint32_t)(x + d[0]), (uint32_t)(y + d[1]), (uint32_t)(z + d[2]));
                m->full[t] = src.full[s];
                m->rgb[t] = src.rgb[s];
            }
    model_free(&src);
}

/* Builds the model's voxels with the builder (colours when COLORS). */
static voxdag *model_build(const model *m, voxdag_symmetry sym, int colors, const double *bounds) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    uint32_t *xyz = (uint32_t *)malloc(3 * m->cells * sizeof *xyz);
    uint8_t *rgb = (uint8_t *)malloc(3 * m->cells);
    size_t c, k = 0;
    memset(&o, 0, sizeof o);
    o.levels = m->levels;
    o.symmetry = sym;
    o.colors = colors;
    o.bounds = bounds;
    for (c = 0; c < m->cells; c++) {
        if (!m->full[c]) continue;
        voxdag_morton_decode(c, &xyz[3 * k], &xyz[3 * k + 1], &xyz[3 * k + 2]);
        rgb[3 * k] = (uint8_t)(m->rgb[c] >> 16);
        rgb[3 * k + 1] = (uint8_t)(m->rgb[c] >> 8);
        rgb[3 * k + 2] = (uint8_t)m->rgb[c];
        k++;
    }
    if (voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK && voxdag_builder_add(b, xyz, rgb, k, NULL) == VOXDAG_OK)
        voxdag_builder_finish(b, &d, NULL, NULL);
    free(xyz);
    free(rgb);
    return d;
}

typedef struct seen {
    const model *m;
    uint64_t next_code, count;
    int bad;
} seen;

/* for_each_voxel must give the model's voxels in Morton order, indices 0, 1, ... */
static int seen_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    seen *s = (seen *)user;
    uint64_t c = voxdag_morton_encode(x, y, z);
    while (s->next_code < c && !s->m->full[s->next_code]) s->next_code++;
    if (s->next_code != c || index != s->count) s->bad = 1;
    s->next_code = c + 1;
    s->count++;
    return 0;
}

/* Everything the editor answers against the model; the commit against a
   fresh build. Returns 0 when something differs. */
static int check_state(voxdag_editor *ed, const model *m, voxdag_symmetry sym, int colors,
                       const double *bounds, uint64_t *rng, int full_check) {
    seen s;
    uint64_t *rank = (uint64_t *)malloc((m->cells + 1) * sizeof *rank);
    voxdag *built, *mine = NULL;
    size_t c, k;
    int before = test_current_failed;
    rank[0] = 0;
    for (c = 0; c < m->cells; c++) rank[c + 1] = rank[c] + m->full[c];
    CHECK(voxdag_editor_voxels(ed) == rank[m->cells]);
    memset(&s, 0, sizeof s);
    s.m = m;
    CHECK(voxdag_editor_for_each_voxel(ed, seen_voxel, &s) == rank[m->cells]);
    CHECK(!s.bad && s.count == rank[m->cells]);
    for (k = 0; k < (full_check ? m->cells : 200); k++) {
        uint64_t index = UINT64_MAX;
        uint32_t x, y, z;
        c = full_check ? k : (size_t)(test_rand(rng) % m->cells);
        voxdag_morton_decode(c, &x, &y, &z);
        CHECK(voxdag_editor_lookup(ed, x, y, z, &index) == m->full[c]);
        if (m->full[c]) {
            uint8_t rgb[3];
            CHECK(index == rank[c]);
            CHECK(voxdag_editor_color(ed, index, rgb) == colors);
            if (colors) CHECK_MSG(pack(rgb) == m->rgb[c], "colour of (%u %u %u): %06x, not %06x", x, y, z, pack(rgb), m->rgb[c]);
        }
    }
    CHECK(voxdag_editor_lookup(ed, m->n, 0, 0, NULL) == 0);
    built = model_build(m, sym, colors, bounds);
    CHECK(built != NULL);
    CHECK(voxdag_editor_commit(ed, &mine, NULL) == VOXDAG_OK);
    if (built && mine) {
        size_t a, b;
        const void *pa = voxdag_image(built, &a), *pb = voxdag_image(mine, &b);
        CHECK_MSG(a == b && !memcmp(pa, pb, a), "commit is not the builder's bytes (%zu vs %zu bytes)", b, a);
        for (k = 0; k < 20; k++) { /* rays: the editor's against the fresh build's */
            voxdag_ray ray;
            voxdag_ray_opts ro;
            voxdag_hit h1, h2;
            int r1, r2, a2;
            memset(&ray, 0, sizeof ray);
            memset(&ro, 0, sizeof ro);
            ro.want_index = 1;
            for (a2 = 0; a2 < 3; a2++) {
                ray.origin[a2] = (double)(test_rand(rng) % (4 * m->n)) / 2 - m->n / 2.0;
                ray.dir[a2] = (double)((int)(test_rand(rng) % 9) - 4);
            }
            memset(&h1, 0, sizeof h1);
            memset(&h2, 0, sizeof h2);
            r1 = voxdag_editor_raycast(ed, &ray, &ro, &h1);
            r2 = voxdag_raycast(built, &ray, &ro, &h2);
            CHECK(r1 == r2 && (r1 != 1 || !memcmp(&h1, &h2, sizeof h1)));
            CHECK(voxdag_editor_occluded(ed, &ray, NULL) == voxdag_occluded(built, &ray));
        }
    }
    voxdag_free(built);
    voxdag_free(mine);
    free(rank);
    return test_current_failed == before;
}

static void random_shape(uint64_t *rng, const model *m, voxdag_shape *s) {
    int64_t span = 2 * (int64_t)m->n, a;
    memset(s, 0, sizeof *s);
    s->kind = test_rand(rng) & 1 ? VOXDAG_SHAPE_SPHERE : VOXDAG_SHAPE_BOX;
    for (a = 0; a < 3; a++) {
        s->lo[a] = (int64_t)(test_rand(rng) % (uint64_t)span) - (int64_t)m->n / 2;
        s->hi[a] = s->lo[a] + (int64_t)(test_rand(rng) % (uint64_t)(m->n + 2)) - 1;
        s->center[a] = (int64_t)(test_rand(rng) % (uint64_t)span) - (int64_t)m->n / 2;
    }
    s->radius = (int64_t)(test_rand(rng) % (m->n + 1));
    if (test_rand(rng) % 8 == 0) { /* the whole grid and beyond */
        for (a = 0; a < 3; a++) s->lo[a] = -1, s->hi[a] = m->n + 1;
    }
}

/* One random sequence: a random scene, then EDITS random edits, undos and
   redos, each checked. */
static void run_sequence(uint64_t seed, uint32_t levels, voxdag_symmetry sym, int colors, int voxcolor,
                         int edits, int full_check) {
    uint64_t rng = seed;
    history h;
    model *cur;
    voxdag *start;
    voxdag_editor *ed = NULL;
    double bounds[6] = {-1, -2, -3, 5, 6, 7};
    const double *bp = seed & 1 ? bounds : NULL;
    uint32_t salt = (uint32_t)seed;
    int e, failed_at = -1;
    size_t c;
    memset(&h, 0, sizeof h);
    h.cap = (size_t)edits + 1;
    h.state = (model *)calloc(h.cap, sizeof *h.state);
    h.kept = 1;
    model_init(&h.state[0], levels);
    cur = &h.state[0];
    for (c = 0; c < cur->cells; c++) /* a random start: noise, denser in places */
        if (test_rand(&rng) % 8 < (c >> (3 * levels - 3)) % 4) cur->full[c] = 1, cur->rgb[c] = (uint32_t)test_rand(&rng) & 0xFFFFFF;
    start = model_build(cur, sym, colors, bp);
    if (colors && voxcolor) { /* the colours as a voxcolor stream: the model takes the decoded ones */
        const void *raw;
        size_t size, cap, len;
        uint8_t *stream;
        voxcolor_encode_opts o;
        voxdag *v = NULL;
        voxdag_colors(start, &raw, &size);
        cap = voxcolor_encode_bound(size / 3);
        stream = (uint8_t *)malloc(cap);
        memset(&o, 0, sizeof o);
        o.max_error = 0.05;
        len = voxcolor_encode(stream, cap, (const uint8_t *)raw, size / 3, &o, NULL);
        CHECK(len > 0 && voxdag_with_colors(start, VOXDAG_COLORS_VOXCOLOR, stream, len, &v, NULL) == VOXDAG_OK);
        free(stream);
        voxdag_free(start);
        start = v;
        for (c = 0; c < cur->cells; c++) {
            uint32_t x, y, z;
            uint64_t index;
            uint8_t rgb[3];
            voxdag_morton_decode(c, &x, &y, &z);
            if (cur->full[c] && voxdag_lookup(start, x, y, z, &index) && voxdag_color(start, index, rgb) == 1)
                cur->rgb[c] = pack(rgb);
        }
    }
    CHECK(voxdag_editor_create(start, NULL, &ed, NULL) == VOXDAG_OK);
    voxdag_free(start);
    if (!ed) return;
    if (!check_state(ed, cur, sym, colors, bp, &rng, full_check)) failed_at = 0;
    for (e = 0; e < edits && failed_at < 0; e++) {
        uint32_t kind = test_rand_below(&rng, 12);
        model next;
        voxdag_status st = VOXDAG_OK;
        voxdag_brush brush;
        voxdag_shape s;
        cur = &h.state[h.done];
        if (kind == 10 || kind == 11) { /* undo, redo */
            int did = kind == 10 ? voxdag_editor_undo(ed) : voxdag_editor_redo(ed);
            CHECK(did == (kind == 10 ? h.done > 0 : h.done + 1 < h.kept));
            if (did) h.done += kind == 10 ? (size_t)-1 : 1;
        } else {
            model_copy(&next, cur);
            memset(&brush, 0, sizeof brush);
            brush.rgb[0] = (uint8_t)test_rand(&rng);
            brush.rgb[1] = (uint8_t)test_rand(&rng);
            brush.rgb[2] = (uint8_t)test_rand(&rng);
            if (test_rand(&rng) & 1) brush.fn = brush_at, brush.user = &salt;
            random_shape(&rng, cur, &s);
            if (kind <= 3) { /* voxel lists */
                uint32_t xyz[3 * 24];
                uint8_t rgb[3 * 24];
                size_t n = test_rand_below(&rng, 24), i;
                int with_rgb = test_rand(&rng) & 1;
                for (i = 0; i < n; i++) {
                    size_t cc;
                    if (i && test_rand(&rng) % 4 == 0) { /* a repeat */
                        memcpy(xyz + 3 * i, xyz + 3 * (i - 1), 3 * sizeof *xyz);
                    } else {
                        xyz[3 * i] = test_rand_below(&rng, cur->n);
                        xyz[3 * i + 1] = test_rand_below(&rng, cur->n);
                        xyz[3 * i + 2] = test_rand_below(&rng, cur->n);
                    }
                    rgb[3 * i] = (uint8_t)test_rand(&rng);
                    rgb[3 * i + 1] = (uint8_t)test_rand(&rng);
                    rgb[3 * i + 2] = (uint8_t)test_rand(&rng);
                    cc = (size_t)voxdag_morton_encode(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                    if (kind <= 1) {
                        if (with_rgb) next.rgb[cc] = pack(rgb + 3 * i);
                        else if (!next.full[cc]) next.rgb[cc] = WHITE;
                        next.full[cc] = 1;
                    } else {
                        next.full[cc] = 0;
                    }
                }
                st = kind <= 1 ? voxdag_editor_set(ed, xyz, with_rgb ? rgb : NULL, n, NULL)
                               : voxdag_editor_clear(ed, xyz, n, NULL);
            } else if (kind <= 5) {
                int plain = test_rand(&rng) % 3 == 0;
                model_shape(&next, OP_FILL, &s, plain ? NULL : &brush);
                st = voxdag_editor_fill(ed, &s, plain ? NULL : &brush, NULL);
            } else if (kind <= 7) {
                model_shape(&next, OP_CARVE, &s, NULL);
                st = voxdag_editor_carve(ed, &s, NULL);
            } else if (kind == 8) {
                model_shape(&next, OP_PAINT, &s, &brush);
                st = voxdag_editor_paint(ed, &s, &brush, NULL);
            } else {
                int64_t d[3];
                unsigned a;
                for (a = 0; a < 3; a++) d[a] = (int64_t)test_rand_below(&rng, 2 * cur->n) - (int64_t)cur->n;
                model_copy_box(&next, s.lo, s.hi, d);
                st = voxdag_editor_copy(ed, s.lo, s.hi, d, NULL);
            }
            CHECK_MSG(st == VOXDAG_OK, "edit %d (kind %u) failed: %s", e, kind, voxdag_status_string(st));
            if (!colors) memset(next.rgb, 0, next.cells * sizeof *next.rgb);
            while (h.kept > h.done + 1) model_free(&h.state[--h.kept]);
            h.state[++h.done] = next;
            h.kept = h.done + 1;
        }
        if (!check_state(ed, &h.state[h.done], sym, colors, bp, &rng, full_check)) failed_at = e + 1;
    }
    CHECK_MSG(failed_at < 0, "seed %llu L %u symmetry %d colours %d/%d: differs after step %d",
              (unsigned long long)seed, levels, (int)sym, colors, voxcolor, failed_at);
    voxdag_editor_free(ed);
    for (c = 0; c < h.kept; c++) model_free(&h.state[c]);
    free(h.state);
}

static const voxdag_symmetry groups[3] = {VOXDAG_SYMMETRY_NONE, VOXDAG_SYMMETRY_REFLECT, VOXDAG_SYMMETRY_FULL};

/* Small grids, long sequences, every cell checked after every edit. */
static void test_edit_sequences_small(void) {
    uint64_t seed = 1;
    uint32_t levels;
    int g, kind;
    for (levels = 2; levels <= 5; levels++)
        for (g = 0; g < 3; g++)
            for (kind = 0; kind < 3; kind++) /* no colours, raw, voxcolor */
                run_sequence(seed++ * 7919 + levels, levels, groups[g], kind > 0, kind == 2, levels <= 3 ? 60 : 30, 1);
}

/* Larger grids, shorter sequences, sampled lookups. */
static void test_edit_sequences_large(void) {
    uint64_t seed = 1000;
    uint32_t levels;
    int g;
    for (levels = 6; levels <= 7; levels++)
        for (g = 0; g < 3; g++)
            run_sequence(seed++, levels, groups[g], g != 1, levels == 7, levels == 6 ? 12 : 6, 0);
    run_sequence(seed, 8, VOXDAG_SYMMETRY_FULL, 1, 0, 3, 0);
}

/* A failed edit (every allocation in turn fails) changes nothing: the scene
   and the commit stay as they were, and the edit then works. Nothing leaks. */
static void test_edit_alloc_failures(void) {
    long fail_at;
    int done = 0;
    for (fail_at = 0; !done && fail_at < 100000; fail_at++) {
        count_alloc ca;
        voxdag_editor_opts o;
        voxdag_editor *ed = NULL;
        voxdag *before = NULL, *after = NULL;
        voxdag_shape s;
        voxdag_brush b;
        uint32_t xyz[6] = {1, 2, 3, 30, 31, 0};
        voxdag_status st;
        memset(&o, 0, sizeof o);
        o.levels = 5;
        o.colors = 1;
        o.allocator = ca_start(&ca, -1);
        CHECK(voxdag_editor_create(NULL, &o, &ed, NULL) == VOXDAG_OK);
        memset(&s, 0, sizeof s);
        memset(&b, 0, sizeof b);
        s.kind = VOXDAG_SHAPE_SPHERE;
        s.center[0] = s.center[1] = s.center[2] = 10;
        s.radius = 7;
        b.rgb[0] = 200;
        CHECK(voxdag_editor_fill(ed, &s, &b, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_commit(ed, &before, NULL) == VOXDAG_OK);
        ca.fail_at = ca.calls + fail_at; /* the next edit's allocation FAIL_AT fails */
        s.center[0] = 20;
        b.rgb[1] = 100;
        switch (fail_at % 3) {
        case 0: st = voxdag_editor_fill(ed, &s, &b, NULL); break;
        case 1: st = voxdag_editor_set(ed, xyz, NULL, 2, NULL); break;
        default: {
            int64_t lo[3] = {0, 0, 0}, hi[3] = {16, 16, 16}, d[3] = {9, 9, 9};
            st = voxdag_editor_copy(ed, lo, hi, d, NULL);
        }
        }
        done = st == VOXDAG_OK && ca.calls <= ca.fail_at;
        ca.fail_at = -1;
        if (st != VOXDAG_OK) {
            size_t a, c;
            CHECK(st == VOXDAG_ERR_OUT_OF_MEMORY);
            CHECK(voxdag_editor_commit(ed, &after, NULL) == VOXDAG_OK);
            if (before && after) {
                const void *pa = voxdag_image(before, &a), *pc = voxdag_image(after, &c);
                CHECK_MSG(a == c && !memcmp(pa, pc, a), "a failed edit (allocation %ld) changed the scene", fail_at);
            }
            CHECK(voxdag_editor_undo(ed) == 1 && voxdag_editor_voxels(ed) == 0);
            CHECK(voxdag_editor_redo(ed) == 1 && voxdag_editor_redo(ed) == 0);
        }
        voxdag_free(before);
        voxdag_free(after);
        voxdag_editor_free(ed);
        CHECK(ca.held == 0 && !ca.bad_free);
    }
    CHECK(done);
}

/* Bad calls get errors and change nothing. */
static void test_edit_errors(void) {
    voxdag_editor_opts o;
    voxdag_editor *ed = NULL;
    voxdag_error err;
    voxdag_shape s;
    uint32_t xyz[6] = {1, 1, 1, 0, 16, 0};
    int64_t lo[3] = {0, 0, 0}, hi[3] = {4, 4, 4}, far[3] = {0, (int64_t)1 << 29, 0};
    memset(&o, 0, sizeof o);
    o.zero_end = 1;
    CHECK(voxdag_editor_create(NULL, &o, &ed, &err) == VOXDAG_ERR_INVALID_ARGUMENT && !ed);
    o.zero_end = 0;
    o.levels = 22;
    CHECK(voxdag_editor_create(NULL, &o, &ed, &err) == VOXDAG_ERR_LIMIT);
    o.levels = 4;
    CHECK(voxdag_editor_create(NULL, &o, &ed, &err) == VOXDAG_OK);
    CHECK(voxdag_editor_set(ed, xyz, NULL, 2, &err) == VOXDAG_ERR_COORDINATE && err.node == 1);
    CHECK(voxdag_editor_voxels(ed) == 0 && voxdag_editor_undo(ed) == 0);
    memset(&s, 0, sizeof s);
    s.kind = VOXDAG_SHAPE_SPHERE;
    s.radius = -1;
    CHECK(voxdag_editor_fill(ed, &s, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    s.radius = 2;
    s.center[2] = -((int64_t)1 << 29);
    CHECK(voxdag_editor_carve(ed, &s, &err) == VOXDAG_ERR_COORDINATE);
    s.kind = (voxdag_shape_kind)7;
    CHECK(voxdag_editor_fill(ed, &s, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_editor_paint(ed, &s, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_editor_copy(ed, lo, hi, far, &err) == VOXDAG_ERR_COORDINATE);
    CHECK(voxdag_editor_undo(ed) == 0 && voxdag_editor_redo(ed) == 0);
    CHECK(voxdag_editor_set(ed, xyz, NULL, 1, &err) == VOXDAG_OK && voxdag_editor_voxels(ed) == 1);
    {
        uint8_t rgb[3] = {1, 2, 3};
        CHECK(voxdag_editor_color(ed, 0, rgb) == 0 && rgb[0] == 1); /* no colours: nothing written */
    }
    voxdag_editor_free(ed);
    voxdag_editor_free(NULL);
    CHECK(voxdag_editor_undo(NULL) == 0 && voxdag_editor_lookup(NULL, 0, 0, 0, NULL) == 0);
}

/* Sharing does not decay: after edits, the unique nodes the editor reaches
   per level are the canonical counts of the final voxels (the builder's),
   and carving a hole and filling it back gives the first scene's counts. */
static void test_edit_sharing(void) {
    int g;
    for (g = 0; g < 3; g++) {
        voxdag_editor_opts o;
        voxdag_editor *ed = NULL;
        voxdag *a = NULL, *b = NULL;
        voxdag_info ia, ib;
        voxdag_shape s;
        uint64_t na[VOXDAG_LEVEL_CAPACITY], nb[VOXDAG_LEVEL_CAPACITY];
        uint32_t l;
        memset(&o, 0, sizeof o);
        o.levels = 7;
        o.symmetry = groups[g];
        CHECK(voxdag_editor_create(NULL, &o, &ed, NULL) == VOXDAG_OK);
        memset(&s, 0, sizeof s);
        s.kind = VOXDAG_SHAPE_SPHERE;
        s.center[0] = s.center[1] = s.center[2] = 64;
        s.radius = 40;
        CHECK(voxdag_editor_fill(ed, &s, NULL, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_nodes(ed, na, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_commit(ed, &a, NULL) == VOXDAG_OK);
        s.kind = VOXDAG_SHAPE_BOX;
        s.lo[0] = 10, s.lo[1] = 20, s.lo[2] = 30;
        s.hi[0] = 90, s.hi[1] = 70, s.hi[2] = 99;
        CHECK(voxdag_editor_carve(ed, &s, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_commit(ed, &b, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_nodes(ed, nb, NULL) == VOXDAG_OK);
        voxdag_get_info(a, &ia);
        voxdag_get_info(b, &ib);
        for (l = 0; l + 1 < o.levels; l++) CHECK(na[l] == ia.nodes[l] && nb[l] == ib.nodes[l]);
        CHECK(ia.nodes[o.levels - 2] != ib.nodes[o.levels - 2]);
        CHECK(voxdag_editor_undo(ed) == 1);
        CHECK(voxdag_editor_nodes(ed, nb, NULL) == VOXDAG_OK && !memcmp(na, nb, sizeof na));
        CHECK(voxdag_editor_redo(ed) == 1);
        s.kind = VOXDAG_SHAPE_SPHERE;
        CHECK(voxdag_editor_fill(ed, &s, NULL, NULL) == VOXDAG_OK); /* the hole filled back */
        CHECK(voxdag_editor_nodes(ed, nb, NULL) == VOXDAG_OK && !memcmp(na, nb, sizeof na));
        voxdag_free(a);
        voxdag_free(b);
        voxdag_editor_free(ed);
    }
}

const test_case test_edit_cases[] = {
    {"edit sequences small grids", test_edit_sequences_small},
    {"edit sequences large grids", test_edit_sequences_large},
    {"edit allocation failures", test_edit_alloc_failures},
    {"edit errors", test_edit_errors},
    {"edit sharing", test_edit_sharing},
    {NULL, NULL},
};
