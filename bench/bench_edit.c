/* Editing speed (voxdag_editor), one thread, on scenes built by bench/edit.sh.
     bench_edit [--quick] NAME=FILE.vdag ...
   A file without colours is given colours from position (r, g, b = x, y, z
   mod 256) in one set edit on an empty editor; a file with colours opens
   with them (voxcolor decoded). For each scene, markdown on stdout:
   - edits: carving and filling spheres of radius 16, 64 and 256 voxels and
     painting boxes of edge 32, 128 and 512, each centred on a voxel of the
     scene (a fixed sample), each timed alone and then undone, so every edit
     meets the scene as loaded: the median time per edit and the edited
     voxels per second, edited voxels being those whose state or colour the
     edit sets (a fill: the shape's voxels inside the grid; a carve or a
     paint: the full voxels in the shape, counted by an untimed carve);
   - after 1,000 random edits (all kinds, sizes 1..64, undo and redo among
     them): their time, the commit's, the committed file against a fresh
     voxdag_builder run on the same voxels and colours (the bytes must be the
     same), the node counts, and the editor's memory against the file's size.
   Progress on stderr. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"

#include "bench/scenes.h"

#define SAMPLES 4096

static uint64_t rng_state = 88172645463325252ull;
static uint64_t rng(void) { /* xorshift64 */
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static void color_from_position(void *user, uint32_t x, uint32_t y, uint32_t z, uint8_t rgb[3]) {
    (void)user;
    rgb[0] = (uint8_t)x, rgb[1] = (uint8_t)y, rgb[2] = (uint8_t)z;
}

static void check(voxdag_status s, const voxdag_error *e, const char *what) {
    if (s == VOXDAG_OK) return;
    fprintf(stderr, "bench_edit: %s: %s\n", what, e->message);
    exit(1);
}

// -- The scene's voxels: every one (to recolour a colourless file) and a sample of centres

typedef struct voxel_list {
    uint32_t *xyz;
    size_t n, cap, stride; /* stride > 0: keep every stride-th voxel only */
    uint64_t seen;
} voxel_list;

static int list_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    voxel_list *l = (voxel_list *)user;
    (void)index;
    if (l->stride && l->seen++ % l->stride) return 0;
    if (l->n == l->cap) return 1;
    l->xyz[3 * l->n] = x, l->xyz[3 * l->n + 1] = y, l->xyz[3 * l->n + 2] = z;
    l->n++;
    return 0;
}

/* Opens an editor on DAG; a DAG without colours gets colours from position. */
static voxdag_editor *open_editor(const voxdag *dag, double *seconds) {
    voxdag_info info;
    voxdag_editor *ed;
    voxdag_error e;
    double t = bench_now();
    voxdag_get_info(dag, &info);
    if (info.colors_decodable) {
        check(voxdag_editor_create(dag, NULL, &ed, &e), &e, "opening the editor");
    } else {
        voxdag_editor_opts o;
        voxel_list all;
        uint8_t *rgb;
        size_t i;
        memset(&o, 0, sizeof o);
        o.levels = info.levels, o.symmetry = info.symmetry, o.colors = 1;
        memset(&all, 0, sizeof all);
        all.cap = (size_t)info.voxels;
        all.xyz = (uint32_t *)bench_xmalloc(3 * all.cap * sizeof *all.xyz + 1);
        voxdag_for_each_voxel(dag, list_voxel, &all);
        rgb = (uint8_t *)bench_xmalloc(3 * all.n + 1);
        for (i = 0; i < all.n; i++) color_from_position(NULL, all.xyz[3 * i], all.xyz[3 * i + 1], all.xyz[3 * i + 2], rgb + 3 * i);
        check(voxdag_editor_create(NULL, &o, &ed, &e), &e, "opening the editor");
        check(voxdag_editor_set(ed, all.xyz, rgb, all.n, &e), &e, "setting the voxels");
        check(voxdag_editor_forget_history(ed, &e), &e, "forgetting the history");
        free(all.xyz);
        free(rgb);
    }
    *seconds = bench_now() - t;
    return ed;
}

// -- Shapes and the voxels they hold inside the grid

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : v > hi ? hi : v; }

static uint64_t shape_voxels(const voxdag_shape *s, int64_t n) {
    uint64_t count = 0;
    int64_t y, z, x0, x1;
    if (s->kind == VOXDAG_SHAPE_BOX) {
        uint64_t v = 1;
        int a;
        for (a = 0; a < 3; a++) {
            int64_t lo = clamp64(s->lo[a], 0, n), hi = clamp64(s->hi[a], 0, n);
            v *= hi > lo ? (uint64_t)(hi - lo) : 0;
        }
        return v;
    }
    /* sphere: rows along x of (2x+1-2cx)^2 <= 4r^2 - dy - dz */
    for (z = clamp64(s->center[2] - s->radius - 1, 0, n); z < clamp64(s->center[2] + s->radius + 1, 0, n); z++)
        for (y = clamp64(s->center[1] - s->radius - 1, 0, n); y < clamp64(s->center[1] + s->radius + 1, 0, n); y++) {
            int64_t dz = 2 * z + 1 - 2 * s->center[2], dy = 2 * y + 1 - 2 * s->center[1];
            int64_t rest = 4 * s->radius * s->radius - dy * dy - dz * dz;
            if (rest < 0) continue;
            x0 = x1 = 0;
            for (x0 = s->center[0] - s->radius - 1; x0 <= s->center[0]; x0++) {
                int64_t dx = 2 * x0 + 1 - 2 * s->center[0];
                if (dx * dx <= rest) break;
            }
            x1 = 2 * s->center[0] - x0; /* the row is symmetric about the centre */
            x0 = clamp64(x0, 0, n), x1 = clamp64(x1, 0, n);
            if (x1 > x0) count += (uint64_t)(x1 - x0);
        }
    return count;
}

static void shape_at(voxdag_shape *s, voxdag_shape_kind kind, const uint32_t *c, int64_t size) {
    int a;
    memset(s, 0, sizeof *s);
    s->kind = kind;
    for (a = 0; a < 3; a++) {
        s->center[a] = c[a];
        s->lo[a] = (int64_t)c[a] - size / 2, s->hi[a] = s->lo[a] + size;
    }
    s->radius = size;
}

// -- The edits table

typedef enum edit_kind { CARVE, FILL, FILL_POSITION, PAINT, EDIT_KINDS } edit_kind;
static const char *const edit_names[EDIT_KINDS] = {"carve sphere", "fill sphere, one colour",
                                                   "fill sphere, colour from position", "paint box"};

static voxdag_status apply(voxdag_editor *ed, edit_kind k, const voxdag_shape *s, voxdag_error *e) {
    voxdag_brush b;
    memset(&b, 0, sizeof b);
    b.rgb[0] = 200, b.rgb[1] = 60, b.rgb[2] = 30;
    if (k == FILL_POSITION) b.fn = color_from_position;
    switch (k) {
    case CARVE: return voxdag_editor_carve(ed, s, e);
    case FILL:
    case FILL_POSITION: return voxdag_editor_fill(ed, s, &b, e);
    default: return voxdag_editor_paint(ed, s, &b, e);
    }
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void edits_table(voxdag_editor *ed, const char *name, const voxel_list *centres, int64_t n, int quick) {
    static const int64_t radii[3] = {16, 64, 256};
    edit_kind k;
    int r;
    printf("| scene | edit | size | edits | ms per edit (median) | voxels in the shape (mean) | edited voxels (mean) "
           "| M edited voxels/s |\n");
    printf("|---|---|---:|---:|---:|---:|---:|---:|\n");
    for (k = CARVE; k < EDIT_KINDS; k++)
        for (r = 0; r < 3; r++) {
            int runs = quick ? 3 : radii[r] == 256 ? 5 : 15, i;
            double ms[15], shape = 0, edited = 0;
            int64_t size = k == PAINT ? 2 * radii[r] : radii[r];
            for (i = 0; i < runs; i++) {
                voxdag_shape s;
                voxdag_error e;
                uint64_t before = voxdag_editor_voxels(ed), full;
                double t;
                shape_at(&s, k == PAINT ? VOXDAG_SHAPE_BOX : VOXDAG_SHAPE_SPHERE,
                         centres->xyz + 3 * (rng() % centres->n), size);
                t = bench_now();
                check(apply(ed, k, &s, &e), &e, edit_names[k]);
                ms[i] = 1e3 * (bench_now() - t);
                voxdag_editor_undo(ed);
                /* the full voxels in the shape, by carving it (untimed) */
                check(voxdag_editor_carve(ed, &s, &e), &e, "counting");
                full = before - voxdag_editor_voxels(ed);
                voxdag_editor_undo(ed);
                shape += (double)shape_voxels(&s, n);
                edited += k == CARVE || k == PAINT ? (double)full : (double)shape_voxels(&s, n);
            }
            qsort(ms, (size_t)runs, sizeof *ms, cmp_double);
            shape /= runs, edited /= runs;
            printf("| %s | %s | %s %lld | %d | %.2f | %.0f | %.0f | %.1f |\n", name, edit_names[k],
                   k == PAINT ? "edge" : "radius", (long long)size, runs, ms[runs / 2], shape, edited,
                   edited / (ms[runs / 2] * 1e-3) / 1e6);
            fflush(stdout);
        }
    printf("\n");
}

// -- 1,000 random edits, the commit, and a fresh build of the result

typedef struct builder_feed {
    const voxdag_editor *ed;
    voxdag_builder *b;
    uint32_t xyz[3 * 4096];
    uint8_t rgb[3 * 4096];
    size_t n;
    voxdag_error e;
} builder_feed;

static void feed_flush(builder_feed *f) {
    check(voxdag_builder_add(f->b, f->xyz, f->rgb, f->n, &f->e), &f->e, "building afresh");
    f->n = 0;
}

static int feed_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    builder_feed *f = (builder_feed *)user;
    f->xyz[3 * f->n] = x, f->xyz[3 * f->n + 1] = y, f->xyz[3 * f->n + 2] = z;
    voxdag_editor_color(f->ed, index, f->rgb + 3 * f->n);
    if (++f->n == 4096) feed_flush(f);
    return 0;
}

static voxdag *fresh_build(const voxdag_editor *ed, const voxdag_info *info) {
    static builder_feed f;
    voxdag_build_opts o;
    voxdag *d;
    memset(&o, 0, sizeof o);
    o.levels = info->levels, o.symmetry = info->symmetry, o.colors = 1;
    if (info->has_bounds) o.bounds = info->bounds;
    f.ed = ed, f.n = 0;
    check(voxdag_builder_create(&o, &f.b, &f.e), &f.e, "building afresh");
    voxdag_editor_for_each_voxel(ed, feed_voxel, &f);
    feed_flush(&f);
    check(voxdag_builder_finish(f.b, &d, NULL, &f.e), &f.e, "building afresh"); /* frees the builder */
    return d;
}

static void random_edit(voxdag_editor *ed, const voxel_list *centres) {
    voxdag_shape s;
    voxdag_error e;
    voxdag_brush b;
    int64_t size = (int64_t)1 << (rng() % 7); /* 1..64 */
    unsigned kind = (unsigned)(rng() % 10);
    memset(&b, 0, sizeof b);
    b.rgb[0] = (uint8_t)rng(), b.rgb[1] = (uint8_t)rng(), b.rgb[2] = (uint8_t)rng();
    if (rng() % 2) b.fn = color_from_position;
    shape_at(&s, rng() % 2 ? VOXDAG_SHAPE_BOX : VOXDAG_SHAPE_SPHERE, centres->xyz + 3 * (rng() % centres->n),
             size);
    switch (kind) {
    case 0: case 1: case 2: check(voxdag_editor_carve(ed, &s, &e), &e, "carving"); break;
    case 3: case 4: case 5: check(voxdag_editor_fill(ed, &s, &b, &e), &e, "filling"); break;
    case 6: case 7: check(voxdag_editor_paint(ed, &s, &b, &e), &e, "painting"); break;
    case 8: {
        const uint32_t *d = centres->xyz + 3 * (rng() % centres->n);
        int64_t off[3];
        int a;
        for (a = 0; a < 3; a++) off[a] = (int64_t)d[a] - s.lo[a];
        check(voxdag_editor_copy(ed, s.lo, s.hi, off, &e), &e, "copying");
        break;
    }
    default:
        if (voxdag_editor_undo(ed) && rng() % 2) voxdag_editor_redo(ed);
    }
}

/* What opening cost: time, memory, and a commit of the scene as opened. */
typedef struct open_cost {
    double seconds, commit_seconds;
    uint64_t memory;
    size_t commit_bytes;
} open_cost;

static void history_table(voxdag_editor *ed, const voxdag *loaded, const char *name, const voxel_list *centres,
                          const open_cost *open, int quick) {
    voxdag_info info, ci;
    voxdag *committed, *fresh;
    voxdag_error e;
    const void *a, *b;
    size_t an, bn;
    uint64_t mem_edits, nodes[VOXDAG_LEVEL_CAPACITY], node_sum = 0;
    int i, edits = quick ? 200 : 1000;
    double t, edit_s, commit_s, build_s;
    voxdag_get_info(loaded, &info);
    t = bench_now();
    for (i = 0; i < edits; i++) random_edit(ed, centres);
    edit_s = bench_now() - t;
    mem_edits = voxdag_editor_memory(ed);
    fprintf(stderr, "bench_edit: %s: committing\n", name);
    t = bench_now();
    check(voxdag_editor_commit(ed, &committed, &e), &e, "committing");
    commit_s = bench_now() - t;
    voxdag_get_info(committed, &ci);
    fprintf(stderr, "bench_edit: %s: a fresh build of the same voxels\n", name);
    t = bench_now();
    fresh = fresh_build(ed, &ci);
    build_s = bench_now() - t;
    check(voxdag_editor_nodes(ed, nodes, &e), &e, "counting nodes");
    for (i = 0; i < VOXDAG_LEVEL_CAPACITY; i++) node_sum += nodes[i];
    a = voxdag_image(committed, &an), b = voxdag_image(fresh, &bn);
    printf("| scene | voxels | file loaded | open | editor memory | commit (raw RGB8 file) | %d random edits "
           "| memory after them | commit | voxels after | nodes after | committed file | fresh build | same bytes |\n",
           edits);
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    printf("| %s | %llu | %.1f MB | %.2f s | %.1f MB (%.2fx the loaded file, %.2fx the raw RGB8 one) "
           "| %.2f s (%.1f MB) | %.2f s (%.2f ms each) | %.1f MB | %.2f s | %llu | %llu | %.1f MB | %.2f s, %.1f MB | %s |\n\n",
           name, (unsigned long long)info.voxels, info.file_bytes / 1e6, open->seconds, open->memory / 1e6,
           (double)open->memory / (double)info.file_bytes, (double)open->memory / (double)open->commit_bytes,
           open->commit_seconds, open->commit_bytes / 1e6, edit_s, 1e3 * edit_s / edits, mem_edits / 1e6, commit_s,
           (unsigned long long)ci.voxels, (unsigned long long)node_sum, an / 1e6, build_s, bn / 1e6,
           an == bn && !memcmp(a, b, an) ? "yes" : "**no**");
    voxdag_free(committed);
    voxdag_free(fresh);
}

int main(int argc, char **argv) {
    int quick = 0, i, header = 0;
    for (i = 1; i < argc; i++) {
        const char *eq = strchr(argv[i], '=');
        voxdag *dag;
        voxdag_editor *ed;
        voxdag_error e;
        voxdag_info info;
        voxel_list centres;
        char name[64];
        open_cost open;
        voxdag *committed;
        double t;
        if (!strcmp(argv[i], "--quick")) {
            quick = 1;
            continue;
        }
        if (!eq || eq == argv[i] || (size_t)(eq - argv[i]) >= sizeof name) {
            fprintf(stderr, "usage: bench_edit [--quick] NAME=FILE.vdag ...\n");
            return 2;
        }
        memcpy(name, argv[i], (size_t)(eq - argv[i]));
        name[eq - argv[i]] = 0;
        check(voxdag_load_file(eq + 1, NULL, &dag, &e), &e, eq + 1);
        voxdag_get_info(dag, &info);
        fprintf(stderr, "bench_edit: %s: opening (%llu voxels)\n", name, (unsigned long long)info.voxels);
        ed = open_editor(dag, &open.seconds);
        open.memory = voxdag_editor_memory(ed);
        fprintf(stderr, "bench_edit: %s: committing the scene as opened\n", name);
        t = bench_now();
        check(voxdag_editor_commit(ed, &committed, &e), &e, "committing");
        open.commit_seconds = bench_now() - t;
        voxdag_image(committed, &open.commit_bytes);
        voxdag_free(committed);
        memset(&centres, 0, sizeof centres);
        centres.cap = SAMPLES;
        centres.stride = info.voxels / SAMPLES + 1;
        centres.xyz = (uint32_t *)bench_xmalloc(3 * SAMPLES * sizeof *centres.xyz);
        voxdag_for_each_voxel(dag, list_voxel, &centres);
        if (!centres.n) {
            fprintf(stderr, "bench_edit: %s: no voxels\n", name);
            return 1;
        }
        if (!header++)
            printf("Each edit centred on a voxel of the scene, timed alone, then undone (one thread; `voxdag_editor`).\n\n");
        fprintf(stderr, "bench_edit: %s: edits\n", name);
        edits_table(ed, name, &centres, (int64_t)1 << info.levels, quick);
        history_table(ed, dag, name, &centres, &open, quick);
        free(centres.xyz);
        voxdag_editor_free(ed);
        voxdag_free(dag);
    }
    return 0;
}
