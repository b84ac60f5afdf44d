/* The editor against a brute-force model (tests/edit_model.h): after every
   edit, undo and redo of random sequences the editor's voxels, indices,
   colours, lookups and rays must match the model, and its commit must be
   the very bytes the builder makes of the model's voxels with the same
   options; allocation failures leave nothing half-applied. L = 2..8 use
   the dense model; L = 9 and 10 a sparse one (sorted voxels), with small
   shapes near voxels and grid borders. */
#include "voxcolor.h"
#include "voxdag.h"
#include "test.h"
#include "count_alloc.h"
#include "edit_model.h"

static uint64_t next_rand(void *user) { return test_rand((uint64_t *)user); }

/* One random sequence: a random scene, then EDITS random edits, undos and
   redos, each checked. */
static void run_sequence(uint64_t seed, uint32_t levels, voxdag_symmetry sym, int colors, int voxcolor,
                         int edits, int full_check) {
    uint64_t rng = seed;
    edit_src src;
    history h;
    model start_model, *cur;
    voxdag *start;
    voxdag_editor *ed = NULL;
    double bounds[6] = {-1, -2, -3, 5, 6, 7};
    const double *bp = seed & 1 ? bounds : NULL;
    uint32_t salt = (uint32_t)seed;
    const char *why = NULL;
    int e = 0, wrong = 0;
    size_t c;
    src.next = next_rand;
    src.user = &rng;
    model_init(&start_model, levels);
    history_init(&h, &start_model);
    cur = &h.state[0];
    for (c = 0; c < cur->cells; c++) /* a random start: noise, denser in places */
        if (test_rand(&rng) % 8 < (c >> (3 * levels - 3)) % 4) cur->full[c] = 1, cur->rgb[c] = (uint32_t)test_rand(&rng) & 0xFFFFFF;
    if (!colors) memset(cur->rgb, 0, cur->cells * sizeof *cur->rgb);
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
    if (ed) {
        why = edit_compare(ed, cur, sym, colors, bp, &src, full_check);
        for (e = 1; e <= edits && !why && !wrong; e++) {
            voxdag_status st = edit_step(ed, &h, colors, &src, &salt, &wrong);
            if (st != VOXDAG_OK) why = voxdag_status_string(st);
            else if (wrong) why = "undo or redo";
            else why = edit_compare(ed, &h.state[h.done], sym, colors, bp, &src, full_check);
        }
    }
    if (ed && !why) { /* forgetting the history keeps the scene, frees blocks, ends undo */
        uint64_t held = voxdag_editor_memory(ed);
        model now;
        model_copy(&now, &h.state[h.done]);
        if (voxdag_editor_forget_history(ed, NULL) != VOXDAG_OK) why = "forget_history failed";
        else if (voxdag_editor_memory(ed) > held || voxdag_editor_undo(ed) || voxdag_editor_redo(ed))
            why = "forget_history: memory or history";
        else why = edit_compare(ed, &now, sym, colors, bp, &src, full_check);
        if (!why) { /* and edits go on as before */
            history_free(&h);
            history_init(&h, &now);
            for (e = 0; e < 4 && !why && !wrong; e++) {
                voxdag_status st = edit_step(ed, &h, colors, &src, &salt, &wrong);
                if (st != VOXDAG_OK) why = voxdag_status_string(st);
                else if (wrong) why = "undo or redo after forget_history";
                else why = edit_compare(ed, &h.state[h.done], sym, colors, bp, &src, full_check);
            }
        } else {
            model_free(&now);
        }
    }
    CHECK_MSG(!why, "seed %llu L %u symmetry %d colours %d/%d: %s after step %d", (unsigned long long)seed, levels,
              (int)sym, colors, voxcolor, why, e - 1);
    voxdag_editor_free(ed);
    history_free(&h);
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

// -- L = 9 and 10: a sparse model (sorted voxels), small shapes anywhere

/* A scene as its voxels sorted by Morton code, with colours. */
typedef struct sparse {
    uint64_t *code;
    uint32_t *rgb;
    size_t n, cap;
} sparse;

static void sparse_push(sparse *s, uint64_t code, uint32_t rgb) {
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->code = (uint64_t *)realloc(s->code, s->cap * sizeof *s->code);
        s->rgb = (uint32_t *)realloc(s->rgb, s->cap * sizeof *s->rgb);
    }
    s->code[s->n] = code;
    s->rgb[s->n++] = rgb;
}

static void sparse_copy(sparse *dst, const sparse *src) {
    size_t i;
    memset(dst, 0, sizeof *dst);
    for (i = 0; i < src->n; i++) sparse_push(dst, src->code[i], src->rgb[i]);
}

static void sparse_free(sparse *s) {
    free(s->code);
    free(s->rgb);
    memset(s, 0, sizeof *s);
}

/* The index of CODE, or -1. */
static long sparse_find(const sparse *s, uint64_t code) {
    size_t lo = 0, hi = s->n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (s->code[mid] < code) lo = mid + 1;
        else hi = mid;
    }
    return lo < s->n && s->code[lo] == code ? (long)lo : -1;
}

typedef struct code_rgb {
    uint64_t code;
    uint32_t rgb;
} code_rgb;

static int code_rgb_cmp(const void *a, const void *b) {
    uint64_t x = ((const code_rgb *)a)->code, y = ((const code_rgb *)b)->code;
    return (x > y) - (x < y);
}

/* Replaces S by the voxels of LIST (any order, distinct codes). */
static void sparse_from(sparse *s, code_rgb *list, size_t n) {
    size_t i;
    qsort(list, n, sizeof *list, code_rgb_cmp);
    s->n = 0;
    for (i = 0; i < n; i++) sparse_push(s, list[i].code, list[i].rgb);
}

/* The voxels of S after OP with SHAPE (BRUSH as voxdag_editor_fill / _paint). */
static void sparse_shape(sparse *s, uint32_t n, int op, const voxdag_shape *sh, const voxdag_brush *b) {
    code_rgb *list;
    size_t i, k = 0, room = s->n + 1;
    int64_t lo[3], hi[3], x, y, z;
    int a;
    for (a = 0; a < 3; a++) { /* the shape's box inside the grid */
        lo[a] = sh->kind == VOXDAG_SHAPE_BOX ? sh->lo[a] : sh->center[a] - sh->radius;
        hi[a] = sh->kind == VOXDAG_SHAPE_BOX ? sh->hi[a] : sh->center[a] + sh->radius + 1;
        if (lo[a] < 0) lo[a] = 0;
        if (hi[a] > (int64_t)n) hi[a] = n;
        if (hi[a] < lo[a]) hi[a] = lo[a];
    }
    if (op == OP_FILL) room += (size_t)((hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]));
    list = (code_rgb *)malloc(room * sizeof *list);
    for (i = 0; i < s->n; i++) { /* the voxels there: carved, painted or kept */
        uint32_t v[3];
        voxdag_morton_decode(s->code[i], &v[0], &v[1], &v[2]);
        if (in_shape(sh, v[0], v[1], v[2])) {
            if (op == OP_CARVE) continue;
            if (op == OP_PAINT || (op == OP_FILL && b)) {
                list[k].code = s->code[i], list[k++].rgb = brush_color(b, v[0], v[1], v[2]);
                continue;
            }
        }
        list[k].code = s->code[i], list[k++].rgb = s->rgb[i];
    }
    if (op == OP_FILL) /* the new voxels */
        for (z = lo[2]; z < hi[2]; z++)
            for (y = lo[1]; y < hi[1]; y++)
                for (x = lo[0]; x < hi[0]; x++) {
                    uint64_t c = voxdag_morton_encode((uint32_t)x, (uint32_t)y, (uint32_t)z);
                    if (!in_shape(sh, x, y, z) || sparse_find(s, c) >= 0) continue;
                    list[k].code = c;
                    list[k++].rgb = b ? brush_color(b, (uint32_t)x, (uint32_t)y, (uint32_t)z) : WHITE;
                }
    sparse_from(s, list, k);
    free(list);
}

static int box_has(const int64_t lo[3], const int64_t hi[3], const int64_t v[3], uint32_t n) {
    int a;
    for (a = 0; a < 3; a++)
        if (v[a] < lo[a] || v[a] >= hi[a] || v[a] < 0 || v[a] >= (int64_t)n) return 0;
    return 1;
}

/* voxdag_editor_copy on S: each in-grid voxel position of LO..HI, full or
   empty, written at itself + D when that lies in the grid. */
static void sparse_copy_box(sparse *s, uint32_t n, const int64_t lo[3], const int64_t hi[3], const int64_t d[3]) {
    code_rgb *list = (code_rgb *)malloc((2 * s->n + 1) * sizeof *list);
    size_t i, k = 0;
    int a;
    for (i = 0; i < s->n; i++) {
        uint32_t u[3];
        int64_t v[3], from[3], to[3];
        voxdag_morton_decode(s->code[i], &u[0], &u[1], &u[2]);
        for (a = 0; a < 3; a++) v[a] = u[a], from[a] = v[a] - d[a], to[a] = v[a] + d[a];
        if (!box_has(lo, hi, from, n)) list[k].code = s->code[i], list[k++].rgb = s->rgb[i]; /* not overwritten */
        if (box_has(lo, hi, v, n) && to[0] >= 0 && to[1] >= 0 && to[2] >= 0 &&
            to[0] < (int64_t)n && to[1] < (int64_t)n && to[2] < (int64_t)n) {
            list[k].code = voxdag_morton_encode((uint32_t)to[0], (uint32_t)to[1], (uint32_t)to[2]);
            list[k++].rgb = s->rgb[i];
        }
    }
    sparse_from(s, list, k);
    free(list);
}

static voxdag *sparse_build(const sparse *s, uint32_t levels, voxdag_symmetry sym, int colors) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    uint32_t *xyz = (uint32_t *)malloc((3 * s->n + 1) * sizeof *xyz);
    uint8_t *rgb = (uint8_t *)malloc(3 * s->n + 1);
    size_t i;
    memset(&o, 0, sizeof o);
    o.levels = levels, o.symmetry = sym, o.colors = colors;
    for (i = 0; i < s->n; i++) {
        voxdag_morton_decode(s->code[i], &xyz[3 * i], &xyz[3 * i + 1], &xyz[3 * i + 2]);
        rgb[3 * i] = (uint8_t)(s->rgb[i] >> 16), rgb[3 * i + 1] = (uint8_t)(s->rgb[i] >> 8);
        rgb[3 * i + 2] = (uint8_t)s->rgb[i];
    }
    if (voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK && voxdag_builder_add(b, xyz, rgb, s->n, NULL) == VOXDAG_OK)
        voxdag_builder_finish(b, &d, NULL, NULL);
    free(xyz);
    free(rgb);
    return d;
}

typedef struct sparse_seen {
    const sparse *s;
    const voxdag_editor *ed;
    int colors;
    uint64_t count;
    int bad;
} sparse_seen;

static int sparse_seen_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    sparse_seen *v = (sparse_seen *)user;
    uint8_t rgb[3];
    if (index != v->count || index >= v->s->n || v->s->code[index] != voxdag_morton_encode(x, y, z) ||
        voxdag_editor_color(v->ed, index, rgb) != v->colors || (v->colors && pack(rgb) != v->s->rgb[index]))
        v->bad = 1;
    v->count++;
    return v->bad;
}

/* The editor against S: count, every voxel with its index and colour in
   order, lookups near the voxels; with COMMIT, the commit against a fresh
   build. */
static const char *sparse_compare(voxdag_editor *ed, const sparse *s, uint32_t levels, voxdag_symmetry sym,
                                  int colors, uint64_t *rng, int commit) {
    sparse_seen v;
    voxdag *built, *mine = NULL;
    const char *why = NULL;
    int k;
    memset(&v, 0, sizeof v);
    v.s = s, v.ed = ed, v.colors = colors;
    if (voxdag_editor_voxels(ed) != s->n) return "voxel count";
    voxdag_editor_for_each_voxel(ed, sparse_seen_voxel, &v);
    if (v.bad || v.count != s->n) return "for_each_voxel: voxels, indices or colours";
    for (k = 0; k < 400 && !why; k++) { /* near a voxel, or anywhere */
        uint32_t p[3];
        uint64_t index = UINT64_MAX, c;
        long at;
        int a;
        if (s->n && k % 2) {
            voxdag_morton_decode(s->code[test_rand(rng) % s->n], &p[0], &p[1], &p[2]);
            for (a = 0; a < 3; a++) p[a] = (p[a] + test_rand_below(rng, 3) + (1u << levels) - 1) % (1u << levels);
        } else {
            for (a = 0; a < 3; a++) p[a] = test_rand_below(rng, 1u << levels);
        }
        c = voxdag_morton_encode(p[0], p[1], p[2]);
        at = sparse_find(s, c);
        if (voxdag_editor_lookup(ed, p[0], p[1], p[2], &index) != (at >= 0)) why = "lookup: full or empty";
        else if (at >= 0 && index != (uint64_t)at) why = "lookup: voxel index";
    }
    if (why || !commit) return why;
    built = sparse_build(s, levels, sym, colors);
    if (!why && (!built || voxdag_editor_commit(ed, &mine, NULL) != VOXDAG_OK)) why = "build or commit failed";
    if (!why) {
        size_t a, b;
        const void *pa = voxdag_image(built, &a), *pb = voxdag_image(mine, &b);
        if (a != b || memcmp(pa, pb, a)) why = "commit: not the builder's bytes";
    }
    voxdag_free(built);
    voxdag_free(mine);
    return why;
}

/* A point P near something: a voxel of S, a grid border, or anywhere. */
static void sparse_near(const sparse *s, uint32_t n, uint64_t *rng, int64_t p[3]) {
    uint32_t v[3];
    int a, mode = (int)test_rand_below(rng, 4) / 2 + 1; /* 1, 1, 2, 2 ... */
    if (test_rand(rng) & 1) mode = 0;                     /* ... or 0, half the time */
    if (mode == 0 && s->n) voxdag_morton_decode(s->code[test_rand(rng) % s->n], &v[0], &v[1], &v[2]);
    for (a = 0; a < 3; a++) {
        if (mode == 0 && s->n) p[a] = (int64_t)v[a] + (int64_t)test_rand_below(rng, 17) - 8;
        else if (mode == 1 && test_rand(rng) % 3) p[a] = (test_rand(rng) & 1 ? (int64_t)n : 0) + (int64_t)test_rand_below(rng, 21) - 10;
        else p[a] = test_rand_below(rng, n);
    }
}

/* voxdag_editor_set / _clear of one voxel on S (RGB < 0: no colour given). */
static void sparse_set(sparse *s, uint64_t code, long rgb, int full) {
    long at = sparse_find(s, code);
    size_t i;
    if (at >= 0 && !full) { /* clear */
        memmove(s->code + at, s->code + at + 1, (s->n - (size_t)at - 1) * sizeof *s->code);
        memmove(s->rgb + at, s->rgb + at + 1, (s->n - (size_t)at - 1) * sizeof *s->rgb);
        s->n--;
    } else if (at >= 0) {
        if (rgb >= 0) s->rgb[at] = (uint32_t)rgb;
    } else if (full) {
        sparse_push(s, code, rgb >= 0 ? (uint32_t)rgb : WHITE);
        for (i = s->n - 1; i > 0 && s->code[i - 1] > code; i--) { /* into its place */
            uint64_t c = s->code[i];
            uint32_t r = s->rgb[i];
            s->code[i] = s->code[i - 1], s->rgb[i] = s->rgb[i - 1];
            s->code[i - 1] = c, s->rgb[i - 1] = r;
        }
    }
}

/* One random sequence of EDITS operations at L = LEVELS (9, 10) from an
   empty scene: fills, carves, paints, copies, voxel lists, undo and redo,
   with shapes of up to 24 voxels near voxels and grid borders, each checked
   against the sparse model. */
static void run_sparse_sequence(uint64_t seed, uint32_t levels, voxdag_symmetry sym, int colors, int edits) {
    uint64_t rng = seed;
    uint32_t n = 1u << levels, salt = (uint32_t)seed;
    sparse *state = (sparse *)calloc((size_t)edits + 1, sizeof *state);
    size_t done = 0, kept = 1, i;
    voxdag_editor_opts o;
    voxdag_editor *ed = NULL;
    const char *why = NULL;
    int e = 0;
    memset(&o, 0, sizeof o);
    o.levels = levels, o.symmetry = sym, o.colors = colors;
    CHECK(voxdag_editor_create(NULL, &o, &ed, NULL) == VOXDAG_OK);
    for (e = 1; ed && !why && e <= edits; e++) {
        uint32_t kind = test_rand_below(&rng, 10), xyz[3 * 16];
        uint8_t rgb[3 * 16];
        voxdag_shape sh;
        voxdag_brush brush;
        const voxdag_brush *fill_brush;
        sparse next;
        voxdag_status st = VOXDAG_OK;
        int a, k, count;
        if (kind == 9) { /* undo or redo */
            if (test_rand(&rng) & 1) {
                if (voxdag_editor_undo(ed) != (done > 0)) why = "undo";
                else if (done) done--;
            } else {
                if (voxdag_editor_redo(ed) != (done + 1 < kept)) why = "redo";
                else if (done + 1 < kept) done++;
            }
            if (!why) why = sparse_compare(ed, &state[done], levels, sym, colors, &rng, e == edits);
            continue;
        }
        memset(&sh, 0, sizeof sh);
        memset(&brush, 0, sizeof brush);
        brush.rgb[0] = (uint8_t)test_rand(&rng), brush.rgb[1] = (uint8_t)test_rand(&rng);
        brush.rgb[2] = (uint8_t)test_rand(&rng);
        if (test_rand(&rng) & 1) brush.fn = brush_at, brush.user = &salt;
        fill_brush = test_rand(&rng) % 3 ? &brush : NULL;
        salt++;
        sh.kind = test_rand(&rng) & 1 ? VOXDAG_SHAPE_SPHERE : VOXDAG_SHAPE_BOX;
        sh.radius = test_rand_below(&rng, 25);
        sparse_near(&state[done], n, &rng, sh.center);
        for (a = 0; a < 3; a++) {
            sh.lo[a] = sh.center[a] - test_rand_below(&rng, 24);
            sh.hi[a] = sh.center[a] + test_rand_below(&rng, 24);
        }
        sparse_copy(&next, &state[done]);
        if (kind < 3) {
            st = voxdag_editor_fill(ed, &sh, fill_brush, NULL);
            sparse_shape(&next, n, OP_FILL, &sh, fill_brush);
        } else if (kind < 5) {
            st = voxdag_editor_carve(ed, &sh, NULL);
            sparse_shape(&next, n, OP_CARVE, &sh, NULL);
        } else if (kind < 7) {
            st = voxdag_editor_paint(ed, &sh, &brush, NULL);
            sparse_shape(&next, n, OP_PAINT, &sh, &brush);
        } else if (kind == 7) {
            int64_t d[3];
            sparse_near(&state[done], n, &rng, d);
            for (a = 0; a < 3; a++) d[a] -= sh.lo[a];
            st = voxdag_editor_copy(ed, sh.lo, sh.hi, d, NULL);
            sparse_copy_box(&next, n, sh.lo, sh.hi, d);
        } else { /* a voxel list, repeats included */
            int full = test_rand(&rng) & 1, with_rgb = test_rand(&rng) & 1;
            count = 1 + (int)test_rand_below(&rng, 16);
            for (k = 0; k < count; k++) {
                int64_t v[3];
                sparse_near(&state[done], n, &rng, v);
                for (a = 0; a < 3; a++) xyz[3 * k + a] = (uint32_t)(v[a] < 0 ? 0 : v[a] >= (int64_t)n ? n - 1 : v[a]);
                if (k && test_rand(&rng) % 4 == 0) memcpy(xyz + 3 * k, xyz + 3 * (k - 1), 3 * sizeof *xyz);
                for (a = 0; a < 3; a++) rgb[3 * k + a] = (uint8_t)test_rand(&rng);
                sparse_set(&next, voxdag_morton_encode(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]),
                           with_rgb ? (long)pack(rgb + 3 * k) : -1, full);
            }
            st = full ? voxdag_editor_set(ed, xyz, with_rgb ? rgb : NULL, (size_t)count, NULL)
                      : voxdag_editor_clear(ed, xyz, (size_t)count, NULL);
        }
        if (st != VOXDAG_OK) {
            why = voxdag_status_string(st);
            sparse_free(&next);
            break;
        }
        while (kept > done + 1) sparse_free(&state[--kept]); /* the edits that could be redone */
        state[++done] = next;
        kept = done + 1;
        why = sparse_compare(ed, &state[done], levels, sym, colors, &rng, e % 4 == 0 || e == edits);
    }
    CHECK_MSG(!why, "seed %llu L %u symmetry %d colours %d: %s after step %d", (unsigned long long)seed, levels,
              (int)sym, colors, why, e - 1);
    voxdag_editor_free(ed);
    for (i = 0; i < kept; i++) sparse_free(&state[i]);
    free(state);
}

/* L = 9 and 10: every group, with and without colours. */
static void test_edit_sequences_deep(void) {
    uint64_t seed = 5000;
    uint32_t levels;
    int g;
    for (levels = 9; levels <= 10; levels++)
        for (g = 0; g < 3; g++) run_sparse_sequence(seed++, levels, groups[g], g != 1, 30);
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
    int64_t lo[3] = {0, 0, 0}, hi[3] = {4, 4, 4}, away[3] = {0, (int64_t)1 << 29, 0};
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
    CHECK(voxdag_editor_copy(ed, lo, hi, away, &err) == VOXDAG_ERR_COORDINATE);
    CHECK(voxdag_editor_undo(ed) == 0 && voxdag_editor_redo(ed) == 0);
    CHECK(voxdag_editor_set(ed, xyz, NULL, 1, &err) == VOXDAG_OK && voxdag_editor_voxels(ed) == 1);
    {
        uint8_t rgb[3] = {1, 2, 3};
        CHECK(voxdag_editor_color(ed, 0, rgb) == 0 && rgb[0] == 1); /* no colours: nothing written */
    }
    voxdag_editor_free(ed);
    voxdag_editor_free(NULL);
    /* a limit: the edit that needs more fails whole, and the scene stays */
    o.levels = 8;
    o.colors = 1;
    o.max_memory = 1 << 20;
    CHECK(voxdag_editor_create(NULL, &o, &ed, &err) == VOXDAG_OK);
    s.kind = VOXDAG_SHAPE_SPHERE;
    s.center[0] = s.center[1] = s.center[2] = 40;
    s.radius = 3;
    CHECK(voxdag_editor_fill(ed, &s, NULL, &err) == VOXDAG_OK && voxdag_editor_voxels(ed) == 136);
    s.radius = 100;
    CHECK(voxdag_editor_fill(ed, &s, NULL, &err) == VOXDAG_ERR_LIMIT);
    CHECK(voxdag_editor_voxels(ed) == 136 && voxdag_editor_memory(ed) <= o.max_memory);
    CHECK(voxdag_editor_undo(ed) == 1 && voxdag_editor_undo(ed) == 0);
    voxdag_editor_free(ed);
    CHECK(voxdag_editor_undo(NULL) == 0 && voxdag_editor_lookup(NULL, 0, 0, 0, NULL) == 0);
}

/* Sharing does not decay: after edits, the unique nodes the editor reaches
   per level are the canonical counts of the final voxels (the builder's),
   and carving a hole and filling it back gives the first scene's counts. */
/* An edit after an undo reuses the colour blocks of the edit it discards:
   fill, undo, fill again ... holds no more memory after the second round
   than after the tenth (it grew by the fill's blocks every round before). */
static void test_edit_memory_reused(void) {
    voxdag_editor_opts o;
    voxdag_editor *ed = NULL;
    voxdag_shape s;
    voxdag_brush b;
    uint64_t second = 0;
    int round;
    memset(&o, 0, sizeof o);
    o.levels = 7;
    o.colors = 1;
    memset(&s, 0, sizeof s);
    s.kind = VOXDAG_SHAPE_SPHERE;
    s.center[0] = s.center[1] = s.center[2] = 64;
    s.radius = 40;
    memset(&b, 0, sizeof b);
    b.rgb[0] = 7;
    CHECK(voxdag_editor_create(NULL, &o, &ed, NULL) == VOXDAG_OK);
    for (round = 1; ed && round <= 10; round++) {
        CHECK(voxdag_editor_fill(ed, &s, &b, NULL) == VOXDAG_OK);
        CHECK(voxdag_editor_undo(ed) == 1);
        if (round == 2) second = voxdag_editor_memory(ed);
    }
    CHECK_MSG(voxdag_editor_memory(ed) == second, "memory after 10 rounds %llu, after 2 %llu",
              (unsigned long long)voxdag_editor_memory(ed), (unsigned long long)second);
    voxdag_editor_free(ed);
}

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
    {"edit sequences L = 9 and 10", test_edit_sequences_deep},
    {"edit allocation failures", test_edit_alloc_failures},
    {"edit errors", test_edit_errors},
    {"edit sharing", test_edit_sharing},
    {"edit memory reused after undo", test_edit_memory_reused},
    {NULL, NULL},
};
