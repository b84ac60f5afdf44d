/* Triangle voxelization against a brute-force oracle: every voxel of small
   grids tested with an exact integer separating-axis test written here
   (coordinates are multiples of 1/16, scaled to integers). */
#include "test.h"
#include "voxdag.h"

#ifndef THREADS
#define THREADS 2
#endif
#define SCALE 16 /* vertices are k / SCALE */

typedef struct itri {
    int64_t v[3][3]; /* scaled by SCALE */
} itri;

static int64_t dot3(const int64_t a[3], const int64_t b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const int64_t a[3], const int64_t b[3], int64_t out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Projections of the triangle and of the box [lo, lo+1]^3 (scaled) on AXIS
   overlap (touching included)? A zero axis never separates. */
static int overlap_on(const itri *t, const int64_t box_lo[3], const int64_t axis[3]) {
    int64_t tmin = INT64_MAX, tmax = INT64_MIN, bmin = INT64_MAX, bmax = INT64_MIN;
    int i, c;
    for (i = 0; i < 3; i++) {
        int64_t p = dot3(axis, t->v[i]);
        if (p < tmin) tmin = p;
        if (p > tmax) tmax = p;
    }
    for (c = 0; c < 8; c++) {
        int64_t corner[3], p;
        corner[0] = box_lo[0] + (c & 1 ? SCALE : 0);
        corner[1] = box_lo[1] + (c & 2 ? SCALE : 0);
        corner[2] = box_lo[2] + (c & 4 ? SCALE : 0);
        p = dot3(axis, corner);
        if (p < bmin) bmin = p;
        if (p > bmax) bmax = p;
    }
    return !(tmin > bmax || tmax < bmin);
}

static int brute_overlap(const itri *t, int x, int y, int z) {
    static const int64_t unit[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int64_t lo[3], e[3][3], n[3], axis[3];
    int i, k;
    lo[0] = (int64_t)x * SCALE;
    lo[1] = (int64_t)y * SCALE;
    lo[2] = (int64_t)z * SCALE;
    for (i = 0; i < 3; i++)
        for (k = 0; k < 3; k++) e[i][k] = t->v[(i + 1) % 3][k] - t->v[i][k];
    for (k = 0; k < 3; k++)
        if (!overlap_on(t, lo, unit[k])) return 0;
    cross3(e[0], e[1], n);
    if (!overlap_on(t, lo, n)) return 0;
    for (i = 0; i < 3; i++)
        for (k = 0; k < 3; k++) {
            cross3(e[i], unit[k], axis);
            if (!overlap_on(t, lo, axis)) return 0;
        }
    return 1;
}

typedef struct mesh_data {
    double *pos;
    uint32_t *idx;
    size_t tris;
} mesh_data;

static void tri_color(void *user, size_t tri, const double bary[3], uint8_t rgb[3]) {
    (void)user;
    (void)bary;
    rgb[0] = (uint8_t)tri;
    rgb[1] = (uint8_t)(tri >> 8);
    rgb[2] = 7;
}

/* Random triangles of a few kinds in (or partly outside) the grid. */
static void random_tris(uint64_t *r, uint32_t n, size_t count, itri *out) {
    size_t i;
    for (i = 0; i < count; i++) {
        int kind = (int)test_rand_below(r, 6), c, k;
        int64_t span = (int64_t)(n + 2) * SCALE;
        for (c = 0; c < 3; c++)
            for (k = 0; k < 3; k++) out[i].v[c][k] = (int64_t)test_rand_below(r, (uint32_t)span) - SCALE;
        if (kind == 1) /* small */
            for (c = 1; c < 3; c++)
                for (k = 0; k < 3; k++) out[i].v[c][k] = out[i].v[0][k] + (int64_t)test_rand_below(r, 2 * SCALE) - SCALE;
        if (kind == 2) /* on a voxel face plane z = integer */
            for (c = 0; c < 3; c++) out[i].v[c][2] = (out[i].v[0][2] / SCALE) * SCALE;
        if (kind == 3) /* degenerate: a segment */
            for (k = 0; k < 3; k++) out[i].v[2][k] = (out[i].v[0][k] + out[i].v[1][k]) / 2 / 2 * 2;
        if (kind == 4) /* a point */
            for (c = 1; c < 3; c++) memcpy(out[i].v[c], out[i].v[0], sizeof out[i].v[0]);
        if (kind == 5) /* a sliver along a long edge */
            for (k = 0; k < 3; k++) out[i].v[2][k] = out[i].v[0][k] + (out[i].v[1][k] - out[i].v[0][k]) / 2 + (k == 0);
    }
}

/* The same mesh through a colour sink: the sink's colours attached to its
   colourless DAG give REF's file. */
static void check_sink(const voxdag_build_opts *opts, const voxdag_mesh *mesh, const voxdag *ref) {
    voxdag_build_opts o = *opts;
    voxdag_builder *b;
    voxdag *d = NULL, *with = NULL;
    voxdag_info info;
    sink_buf sink;
    size_t size0, size1 = 0;
    const void *img0, *img1 = NULL;
    voxdag_get_info(ref, &info);
    sink.cap = (size_t)info.voxels;
    sink.rgb = (uint8_t *)malloc(3 * sink.cap + 1);
    sink.n = 0;
    o.color_sink = sink_collect;
    o.color_sink_user = &sink;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, mesh, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    CHECK(d && sink.n == sink.cap &&
          voxdag_with_colors(d, VOXDAG_COLORS_RGB8, sink.rgb, 3 * sink.n, &with, NULL) == VOXDAG_OK);
    img0 = voxdag_image(ref, &size0);
    if (with) img1 = voxdag_image(with, &size1);
    CHECK(img1 && size0 == size1 && !memcmp(img0, img1, size0));
    voxdag_free(with);
    voxdag_free(d);
    free(sink.rgb);
}

/* A cut-away pattern for the keep callback: each corner of a triangle gets
   a weight 0 or 1, and a point is kept when its weighted barycentric sum is
   at least one half (as an alpha test of interpolated vertex alphas). */
static int corner_weight(size_t tri, int corner) { return (int)((tri * 7 + (size_t)corner * 5 + tri / 3) % 3 != 0); }

static int tri_keep(void *user, size_t tri, const double bary[3]) {
    (void)user;
    return bary[0] * corner_weight(tri, 0) + bary[1] * corner_weight(tri, 1) + bary[2] * corner_weight(tri, 2) >= 0.5;
}

/* The keep rule of voxdag_builder_add_mesh for triangle T and voxel
   (x, y, z), in exact integers: the signed areas of the voxel centre's
   projection against each edge (along the normal), negative ones as 0.
   Returns 1 kept, 0 cut, -1 on a tie (exactly one half: either is right). */
static int brute_keep(const itri *t, size_t tri, int x, int y, int z) {
    int64_t e1[3], e2[3], n[3], c[3], num[3], sum = 0, kept = 0;
    int i, k;
    c[0] = (int64_t)x * SCALE + SCALE / 2;
    c[1] = (int64_t)y * SCALE + SCALE / 2;
    c[2] = (int64_t)z * SCALE + SCALE / 2;
    for (k = 0; k < 3; k++) {
        e1[k] = t->v[1][k] - t->v[0][k];
        e2[k] = t->v[2][k] - t->v[0][k];
    }
    cross3(e1, e2, n);
    for (i = 0; i < 3; i++) {
        int64_t a[3], b[3], ab[3];
        for (k = 0; k < 3; k++) {
            a[k] = t->v[(i + 1) % 3][k] - c[k];
            b[k] = t->v[(i + 2) % 3][k] - c[k];
        }
        cross3(a, b, ab);
        num[i] = dot3(n, ab) > 0 ? dot3(n, ab) : 0;
        if (dot3(n, n) == 0) num[i] = 1; /* degenerate: the centroid */
        sum += num[i];
    }
    if (sum == 0)
        for (i = 0, sum = 3; i < 3; i++) num[i] = 1;
    for (i = 0; i < 3; i++) kept += corner_weight(tri, i) * num[i];
    return 2 * kept == sum ? -1 : 2 * kept > sum;
}

static void check_voxelization_keep(uint32_t levels, uint32_t chunk_levels, size_t count, uint64_t seed, int keep) {
    uint32_t n = 1u << levels, x, y, z;
    uint64_t r = seed;
    itri *tris = (itri *)malloc(count * sizeof *tris);
    mesh_data m;
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    voxdag_mesh mesh;
    size_t i, bad = 0, bad_color = 0, full = 0, cut = 0, ties = 0;
    random_tris(&r, n, count, tris);
    m.pos = (double *)malloc(9 * count * sizeof *m.pos);
    m.idx = (uint32_t *)malloc(3 * count * sizeof *m.idx);
    for (i = 0; i < count; i++) {
        int c, k;
        for (c = 0; c < 3; c++) {
            for (k = 0; k < 3; k++) m.pos[9 * i + 3 * c + k] = (double)tris[i].v[c][k] / SCALE;
            m.idx[3 * i + c] = (uint32_t)(3 * i + c);
        }
    }
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.colors = 1;
    o.chunk_levels = chunk_levels;
    o.threads = THREADS;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = m.pos;
    mesh.vertex_count = 3 * count;
    mesh.indices = m.idx;
    mesh.triangle_count = count;
    mesh.color = tri_color;
    if (keep) mesh.keep = tri_keep;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    if (d) check_sink(&o, &mesh, d);
    for (z = 0; d && z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                size_t last = SIZE_MAX;
                uint64_t index;
                int want, tie = 0;
                for (i = 0; i < count; i++)
                    if (brute_overlap(&tris[i], (int)x, (int)y, (int)z)) {
                        int k = keep ? brute_keep(&tris[i], i, (int)x, (int)y, (int)z) : 1;
                        if (k < 0) tie = 1;
                        else if (k) last = i;
                        else cut++;
                    }
                if (tie) { /* a point at exactly one half: not decided here */
                    ties++;
                    continue;
                }
                want = last != SIZE_MAX;
                full += (size_t)want;
                if (voxdag_lookup(d, x, y, z, &index) != want) {
                    bad++;
                } else if (want) {
                    uint8_t c[3];
                    voxdag_color(d, index, c);
                    if (c[0] != (uint8_t)last || c[1] != (uint8_t)(last >> 8)) bad_color++;
                }
            }
    CHECK_MSG(bad == 0 && bad_color == 0, "L=%u chunks 2^%u keep %d: %zu voxels wrong, %zu colours wrong (of %zu full)",
              levels, chunk_levels, keep, bad, bad_color, full);
    CHECK(full > 0);
    CHECK_MSG(!keep || (cut > full / 4 && ties < full / 50), "keep: %zu cut, %zu ties, %zu full", cut, ties, full);
    voxdag_free(d);
    free(tris);
    free(m.pos);
    free(m.idx);
}

static void check_voxelization(uint32_t levels, uint32_t chunk_levels, size_t count, uint64_t seed) {
    check_voxelization_keep(levels, chunk_levels, count, seed, 0);
}

/* A keep callback cuts voxels away by the documented rule (the voxel
   centre's clamped barycentric point), and colours come from the last
   triangle that keeps a voxel. */
static void test_keep_callback(void) {
    check_voxelization_keep(4, 2, 60, 12, 1);
    check_voxelization_keep(5, 3, 80, 13, 1);
}

static void test_random_triangles(void) {
    check_voxelization(3, 0, 40, 1);
    check_voxelization(4, 2, 60, 2);
    check_voxelization(5, 3, 80, 3);
    check_voxelization(5, 2, 30, 4);
}

/* A square on the plane z = 8 fills the voxel layers z = 7 and z = 8. */
static void test_face_plane(void) {
    static const double pos[] = {2, 2, 8, 6, 2, 8, 6, 6, 8, 2, 6, 8};
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    voxdag_mesh mesh;
    voxdag_info info;
    memset(&o, 0, sizeof o);
    o.levels = 4;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = pos;
    mesh.vertex_count = 4;
    mesh.indices = idx;
    mesh.triangle_count = 2;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    voxdag_get_info(d, &info);
    CHECK(info.voxels == 2 * 6 * 6); /* x, y in 1..6 (closed boxes touch 2 and 6), z in 7..8 */
    CHECK(voxdag_lookup(d, 1, 1, 7, NULL) && voxdag_lookup(d, 6, 6, 8, NULL) && !voxdag_lookup(d, 3, 3, 9, NULL));
    voxdag_free(d);
}

/* A mesh build under max_memory: its measured peak passes, one byte less
   (or a small limit, with threads) fails as VOXDAG_ERR_LIMIT, not as out of
   memory, with a message naming max_memory; a generous limit passes. */
static voxdag_status mesh_build_limited(const voxdag_mesh *mesh, uint32_t threads, uint64_t max_memory,
                                        uint64_t *peak) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_build_stats st;
    voxdag_error err;
    voxdag_status s;
    memset(&o, 0, sizeof o);
    o.levels = 6;
    o.colors = 1;
    o.chunk_levels = 3;
    o.threads = threads;
    o.max_memory = max_memory;
    s = voxdag_builder_create(&o, &b, &err);
    if (s == VOXDAG_OK && (s = voxdag_builder_add_mesh(b, mesh, &err)) != VOXDAG_OK) voxdag_builder_free(b);
    if (s == VOXDAG_OK) s = voxdag_builder_finish(b, &d, &st, &err);
    CHECK(s == err.status && (s == VOXDAG_OK) == (d != NULL));
    if (s == VOXDAG_ERR_LIMIT) CHECK_MSG(strstr(err.message, "max_memory") != NULL, "%s", err.message);
    if (peak && d) *peak = st.peak_memory;
    voxdag_free(d);
    return s;
}

static void test_mesh_memory_limit(void) {
    static const double pos[] = {1, 1, 1, 60, 3, 5, 7, 62, 30, 50, 40, 61};
    static const uint32_t idx[] = {0, 1, 2, 1, 2, 3, 0, 2, 3};
    voxdag_mesh mesh;
    uint64_t peak = 0;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = pos;
    mesh.vertex_count = 4;
    mesh.indices = idx;
    mesh.triangle_count = 3;
    mesh.color = tri_color;
    CHECK(mesh_build_limited(&mesh, 1, 0, &peak) == VOXDAG_OK && peak > 0);
    CHECK(mesh_build_limited(&mesh, 1, peak, NULL) == VOXDAG_OK);
    CHECK(mesh_build_limited(&mesh, 1, peak - 1, NULL) == VOXDAG_ERR_LIMIT);
    CHECK(mesh_build_limited(&mesh, 2, 1 << 16, NULL) == VOXDAG_ERR_LIMIT);
    CHECK(mesh_build_limited(&mesh, 2, 1 << 30, NULL) == VOXDAG_OK);
}

static void test_bad_meshes(void) {
    static const double pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t bad_idx[] = {0, 1, 3};
    double nan_pos[9];
    static const uint32_t idx[] = {0, 1, 2};
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag_mesh mesh;
    voxdag_error err;
    uint32_t xyz[3] = {1, 1, 1};
    memset(&o, 0, sizeof o);
    o.levels = 4;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = pos;
    mesh.vertex_count = 3;
    mesh.indices = bad_idx;
    mesh.triangle_count = 1;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_ERR_INVALID_ARGUMENT && err.node == 0);
    voxdag_builder_free(b);
    memcpy(nan_pos, pos, sizeof pos);
    nan_pos[4] = 0.0 / 0.0;
    mesh.positions = nan_pos;
    mesh.indices = idx;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    voxdag_builder_free(b);
    mesh.positions = pos;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add(b, xyz, NULL, 1, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    voxdag_builder_free(b);
    o.colors = 1; /* colours need a colour callback */
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_ERR_INVALID_ARGUMENT);
    voxdag_builder_free(b);
}

const test_case test_voxelize_cases[] = {
    {"voxelize/random_triangles", test_random_triangles},
    {"voxelize/face_plane", test_face_plane},
    {"voxelize/keep_callback", test_keep_callback},
    {"voxelize/mesh_memory_limit", test_mesh_memory_limit},
    {"voxelize/bad_meshes", test_bad_meshes},
    {NULL, NULL},
};
