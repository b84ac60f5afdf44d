/* The editor's brute-force model, shared by tests/test_edit.c and
   tests/fuzz_edit.c: a dense grid of full flags and colours indexed by
   Morton code, a state per applied edit for undo and redo, random
   operations applied to both (from any source of numbers: a generator or
   the fuzzer's bytes), and the comparison of everything the editor answers
   with the model, the commit with a fresh build of the model's voxels. */
#ifndef VOXDAG_EDIT_MODEL_H
#define VOXDAG_EDIT_MODEL_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Where random numbers come from. */
typedef struct edit_src {
    uint64_t (*next)(void *user);
    void *user;
} edit_src;

static uint64_t src_next(edit_src *s) { return s->next(s->user); }
static uint32_t src_below(edit_src *s, uint32_t n) { return (uint32_t)(src_next(s) % n); }

#define WHITE 0xFFFFFFu

typedef struct model {
    uint32_t levels, n;  /* n = 2^levels per axis */
    size_t cells;
    uint8_t *full;       /* per Morton code */
    uint32_t *rgb;       /* 0xRRGGBB per Morton code */
} model;

/* A state per applied edit, for undo and redo: [0, kept) kept, DONE the
   current one. */
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
   fresh build (the same bytes) and rays against the fresh build's. Returns
   NULL, or what differs first. FULL_CHECK looks up every cell, else 200
   taken from SRC. */
static const char *edit_compare(voxdag_editor *ed, const model *m, voxdag_symmetry sym, int colors,
                                const double *bounds, edit_src *src, int full_check) {
    seen s;
    uint64_t *rank = (uint64_t *)malloc((m->cells + 1) * sizeof *rank);
    voxdag *built, *mine = NULL;
    const char *why = NULL;
    size_t c, k;
    rank[0] = 0;
    for (c = 0; c < m->cells; c++) rank[c + 1] = rank[c] + m->full[c];
    memset(&s, 0, sizeof s);
    s.m = m;
    if (voxdag_editor_voxels(ed) != rank[m->cells]) why = "voxel count";
    else if (voxdag_editor_for_each_voxel(ed, seen_voxel, &s) != rank[m->cells] || s.bad || s.count != rank[m->cells])
        why = "for_each_voxel: voxels or indices";
    for (k = 0; !why && k < (full_check ? m->cells : 200); k++) {
        uint64_t index = UINT64_MAX;
        uint32_t x, y, z;
        uint8_t rgb[3];
        c = full_check ? k : (size_t)(src_next(src) % m->cells);
        voxdag_morton_decode(c, &x, &y, &z);
        if (voxdag_editor_lookup(ed, x, y, z, &index) != m->full[c]) why = "lookup: full or empty";
        else if (m->full[c] && index != rank[c]) why = "lookup: voxel index";
        else if (m->full[c] && voxdag_editor_color(ed, index, rgb) != colors) why = "color: has one or not";
        else if (m->full[c] && colors && pack(rgb) != m->rgb[c]) why = "color: the wrong colour";
    }
    if (!why && voxdag_editor_lookup(ed, m->n, 0, 0, NULL) != 0) why = "lookup outside the grid";
    built = model_build(m, sym, colors, bounds);
    if (!why && !built) why = "the model's build failed";
    if (!why && voxdag_editor_commit(ed, &mine, NULL) != VOXDAG_OK) why = "commit failed";
    if (!why) {
        size_t a, b;
        const void *pa = voxdag_image(built, &a), *pb = voxdag_image(mine, &b);
        if (a != b || memcmp(pa, pb, a)) why = "commit: not the builder's bytes";
        for (k = 0; !why && k < 20; k++) { /* rays: the editor's against the fresh build's */
            voxdag_ray ray;
            voxdag_ray_opts ro;
            voxdag_hit h1, h2;
            int r1, r2, a2;
            memset(&ray, 0, sizeof ray);
            memset(&ro, 0, sizeof ro);
            ro.want_index = 1;
            for (a2 = 0; a2 < 3; a2++) {
                ray.origin[a2] = (double)(src_next(src) % (4 * m->n)) / 2 - m->n / 2.0;
                ray.dir[a2] = (double)((int)(src_next(src) % 9) - 4);
            }
            memset(&h1, 0, sizeof h1);
            memset(&h2, 0, sizeof h2);
            r1 = voxdag_editor_raycast(ed, &ray, &ro, &h1);
            r2 = voxdag_raycast(built, &ray, &ro, &h2);
            if (r1 != r2 || (r1 == 1 && memcmp(&h1, &h2, sizeof h1))) why = "raycast";
            else if (voxdag_editor_occluded(ed, &ray, NULL) != voxdag_occluded(built, &ray)) why = "occluded";
        }
    }
    voxdag_free(built);
    voxdag_free(mine);
    free(rank);
    return why;
}

static void random_shape(edit_src *rng, const model *m, voxdag_shape *s) {
    int64_t span = 2 * (int64_t)m->n, a;
    memset(s, 0, sizeof *s);
    s->kind = src_next(rng) & 1 ? VOXDAG_SHAPE_SPHERE : VOXDAG_SHAPE_BOX;
    for (a = 0; a < 3; a++) {
        s->lo[a] = (int64_t)(src_next(rng) % (uint64_t)span) - (int64_t)m->n / 2;
        s->hi[a] = s->lo[a] + (int64_t)(src_next(rng) % (uint64_t)(m->n + 2)) - 1;
        s->center[a] = (int64_t)(src_next(rng) % (uint64_t)span) - (int64_t)m->n / 2;
    }
    s->radius = (int64_t)(src_next(rng) % (m->n + 1));
    if (src_next(rng) % 8 == 0) { /* the whole grid and beyond */
        for (a = 0; a < 3; a++) s->lo[a] = -1, s->hi[a] = m->n + 1;
    }
}


/* One random operation from SRC (an edit, an undo or a redo) on the editor
   and on the model's history H. Returns the edit's status: when it is not
   VOXDAG_OK the model is left as it was (a failed edit changes nothing).
   Sets *WRONG when undo or redo answered wrongly. SALT seeds the brush
   callback. */
static voxdag_status edit_step(voxdag_editor *ed, history *h, int colors, edit_src *rng, uint32_t *salt,
                               int *wrong) {
    uint32_t kind = src_below(rng, 12);
    model next;
    voxdag_status st = VOXDAG_OK;
    voxdag_brush brush;
    voxdag_shape s;
    model *cur = &h->state[h->done];
    if (kind == 10 || kind == 11) { /* undo, redo */
        int did = kind == 10 ? voxdag_editor_undo(ed) : voxdag_editor_redo(ed);
        if (did != (kind == 10 ? h->done > 0 : h->done + 1 < h->kept)) *wrong = 1;
        if (did) h->done += kind == 10 ? (size_t)-1 : 1;
    } else {
        model_copy(&next, cur);
        memset(&brush, 0, sizeof brush);
        brush.rgb[0] = (uint8_t)src_next(rng);
        brush.rgb[1] = (uint8_t)src_next(rng);
        brush.rgb[2] = (uint8_t)src_next(rng);
        if (src_next(rng) & 1) brush.fn = brush_at, brush.user = salt;
        random_shape(rng, cur, &s);
        if (kind <= 3) { /* voxel lists */
            uint32_t xyz[3 * 24];
            uint8_t rgb[3 * 24];
            size_t n = src_below(rng, 24), i;
            int with_rgb = src_next(rng) & 1;
            for (i = 0; i < n; i++) {
                size_t cc;
                if (i && src_next(rng) % 4 == 0) { /* a repeat */
                    memcpy(xyz + 3 * i, xyz + 3 * (i - 1), 3 * sizeof *xyz);
                } else {
                    xyz[3 * i] = src_below(rng, cur->n);
                    xyz[3 * i + 1] = src_below(rng, cur->n);
                    xyz[3 * i + 2] = src_below(rng, cur->n);
                }
                rgb[3 * i] = (uint8_t)src_next(rng);
                rgb[3 * i + 1] = (uint8_t)src_next(rng);
                rgb[3 * i + 2] = (uint8_t)src_next(rng);
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
            int plain = src_next(rng) % 3 == 0;
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
            for (a = 0; a < 3; a++) d[a] = (int64_t)src_below(rng, 2 * cur->n) - (int64_t)cur->n;
            model_copy_box(&next, s.lo, s.hi, d);
            st = voxdag_editor_copy(ed, s.lo, s.hi, d, NULL);
        }
        if (st != VOXDAG_OK) {
            model_free(&next);
            return st;
        }
        if (!colors) memset(next.rgb, 0, next.cells * sizeof *next.rgb);
        while (h->kept > h->done + 1) model_free(&h->state[--h->kept]);
        if (h->done + 1 == h->cap) {
            h->cap *= 2;
            h->state = (model *)realloc(h->state, h->cap * sizeof *h->state);
        }
        h->state[++h->done] = next;
        h->kept = h->done + 1;
    }
    return st;
}

/* A history whose one state is START (taken over). */
static void history_init(history *h, const model *start) {
    h->cap = 16;
    h->state = (model *)calloc(h->cap, sizeof *h->state);
    h->state[0] = *start;
    h->done = 0;
    h->kept = 1;
}

static void history_free(history *h) {
    size_t i;
    for (i = 0; i < h->kept; i++) model_free(&h->state[i]);
    free(h->state);
}

#endif
