/* The editor against a brute-force model (tests/edit_model.h): after every
   edit, undo and redo of random sequences the editor's voxels, indices,
   colours, lookups and rays must match the model, and its commit must be
   the very bytes the builder makes of the model's voxels with the same
   options; allocation failures leave nothing half-applied. */
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
