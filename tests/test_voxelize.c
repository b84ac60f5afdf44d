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

/* -- Solid voxelization against an independent inside test: the winding
   number of each voxel centre summed from the solid angles of the triangles
   (in double, exact enough at centres that no triangle's surface voxel
   holds, which are half a voxel from the surface), on generated closed
   meshes; surface voxels come from the surface build of the same mesh. */

#include <math.h>
#include <time.h>

typedef struct gen_mesh {
    double *pos;
    uint32_t *idx;
    size_t verts, tris, vcap, tcap;
} gen_mesh;

static uint32_t gen_vertex(gen_mesh *m, double x, double y, double z) {
    if (m->verts == m->vcap) {
        m->vcap = m->vcap ? 2 * m->vcap : 64;
        m->pos = (double *)realloc(m->pos, 3 * m->vcap * sizeof *m->pos);
    }
    m->pos[3 * m->verts] = x;
    m->pos[3 * m->verts + 1] = y;
    m->pos[3 * m->verts + 2] = z;
    return (uint32_t)m->verts++;
}

/* Triangle (a, b, c), or (a, c, b) when FLIP. */
static void gen_tri(gen_mesh *m, uint32_t a, uint32_t b, uint32_t c, int flip) {
    if (m->tris == m->tcap) {
        m->tcap = m->tcap ? 2 * m->tcap : 64;
        m->idx = (uint32_t *)realloc(m->idx, 3 * m->tcap * sizeof *m->idx);
    }
    m->idx[3 * m->tris] = a;
    m->idx[3 * m->tris + 1] = flip ? c : b;
    m->idx[3 * m->tris + 2] = flip ? b : c;
    m->tris++;
}

static void gen_free(gen_mesh *m) {
    free(m->pos);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* An axis-aligned box, outward (or inward with FLIP); SPLIT gives each face
   its own vertices (a mesh closed only by positions). */
static void gen_box(gen_mesh *m, const double lo[3], const double hi[3], int flip, int split) {
    static const int face[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    uint32_t v[8];
    int f, k;
    for (k = 0; k < 8 && !split; k++) v[k] = gen_vertex(m, k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
    for (f = 0; f < 6; f++) {
        uint32_t q[4];
        for (k = 0; k < 4; k++) {
            int c = face[f][k];
            q[k] = split ? gen_vertex(m, c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]) : v[c];
        }
        gen_tri(m, q[0], q[1], q[2], flip);
        gen_tri(m, q[0], q[2], q[3], flip);
    }
}

/* A UV sphere (one vertex per pole), outward unless FLIP. */
static void gen_sphere(gen_mesh *m, const double c[3], double r, int slices, int stacks, int flip) {
    const double pi = 3.14159265358979323846;
    uint32_t base, south, north;
    int i, j;
    south = gen_vertex(m, c[0], c[1], c[2] - r);
    base = (uint32_t)m->verts;
    for (j = 1; j < stacks; j++)
        for (i = 0; i < slices; i++) {
            double th = pi * j / stacks - pi / 2, ph = 2 * pi * i / slices + 0.1;
            gen_vertex(m, c[0] + r * cos(th) * cos(ph), c[1] + r * cos(th) * sin(ph), c[2] + r * sin(th));
        }
    north = gen_vertex(m, c[0], c[1], c[2] + r);
    for (i = 0; i < slices; i++) {
        uint32_t a = base + (uint32_t)i, b = base + (uint32_t)((i + 1) % slices);
        uint32_t top = base + (uint32_t)((stacks - 2) * slices);
        gen_tri(m, south, b, a, flip);
        gen_tri(m, north, top + (uint32_t)i, top + (uint32_t)((i + 1) % slices), flip);
        for (j = 0; j + 2 < stacks; j++) {
            uint32_t a0 = a + (uint32_t)(j * slices), b0 = b + (uint32_t)(j * slices);
            gen_tri(m, a0, b0, b0 + (uint32_t)slices, flip);
            gen_tri(m, a0, b0 + (uint32_t)slices, a0 + (uint32_t)slices, flip);
        }
    }
}

static void gen_torus(gen_mesh *m, const double c[3], double big, double small, int nu, int nv) {
    const double pi = 3.14159265358979323846;
    uint32_t base = (uint32_t)m->verts;
    int i, j;
    for (i = 0; i < nu; i++)
        for (j = 0; j < nv; j++) {
            double u = 2 * pi * i / nu, v = 2 * pi * j / nv, rr = big + small * cos(v);
            gen_vertex(m, c[0] + rr * cos(u), c[1] + rr * sin(u), c[2] + small * sin(v));
        }
    for (i = 0; i < nu; i++)
        for (j = 0; j < nv; j++) {
            uint32_t a = base + (uint32_t)(i * nv + j), b = base + (uint32_t)(((i + 1) % nu) * nv + j);
            uint32_t a1 = base + (uint32_t)(i * nv + (j + 1) % nv), b1 = base + (uint32_t)(((i + 1) % nu) * nv + (j + 1) % nv);
            gen_tri(m, a, b, b1, 0);
            gen_tri(m, a, b1, a1, 0);
        }
}

/* A concave star prism: K points of radius R (inner radius R / 3) about
   (cx, cy), from z0 to z1; caps fanned from the centre. */
static void gen_star(gen_mesh *m, double cx, double cy, double r, int k, double z0, double z1) {
    const double pi = 3.14159265358979323846;
    uint32_t c0 = gen_vertex(m, cx, cy, z0), c1 = gen_vertex(m, cx, cy, z1), base = (uint32_t)m->verts;
    int i, n = 2 * k;
    for (i = 0; i < n; i++) {
        double a = pi * i / k, rr = i & 1 ? r / 3 : r;
        gen_vertex(m, cx + rr * cos(a), cy + rr * sin(a), z0);
        gen_vertex(m, cx + rr * cos(a), cy + rr * sin(a), z1);
    }
    for (i = 0; i < n; i++) {
        uint32_t a0 = base + (uint32_t)(2 * i), a1 = a0 + 1, b0 = base + (uint32_t)(2 * ((i + 1) % n)), b1 = b0 + 1;
        gen_tri(m, c0, b0, a0, 0);
        gen_tri(m, c1, a1, b1, 0);
        gen_tri(m, a0, b0, b1, 0);
        gen_tri(m, a0, b1, a1, 0);
    }
}

/* An octahedron about (cx, cy, cz) with vertices at distance D: on voxel
   centres when all are half-integers, so columns run through its vertices
   and along its edges. */
static void gen_octahedron(gen_mesh *m, double cx, double cy, double cz, double d) {
    uint32_t v[6];
    int f;
    v[0] = gen_vertex(m, cx + d, cy, cz);
    v[1] = gen_vertex(m, cx - d, cy, cz);
    v[2] = gen_vertex(m, cx, cy + d, cz);
    v[3] = gen_vertex(m, cx, cy - d, cz);
    v[4] = gen_vertex(m, cx, cy, cz + d);
    v[5] = gen_vertex(m, cx, cy, cz - d);
    for (f = 0; f < 8; f++) { /* face (sx, sy, sz): counter-clockwise seen from outside */
        uint32_t x = v[f & 1], y = v[2 + (f >> 1 & 1)], z = v[4 + (f >> 2 & 1)];
        int odd = (f & 1) ^ (f >> 1 & 1) ^ (f >> 2 & 1);
        gen_tri(m, x, y, z, odd);
    }
}

/* The winding number at P: the triangles' solid angles over 4 pi
   (van Oosterom and Strackee). */
static double solid_winding(const gen_mesh *m, const double p[3]) {
    const double pi = 3.14159265358979323846;
    double sum = 0;
    size_t t;
    for (t = 0; t < m->tris; t++) {
        double a[3], b[3], c[3], la, lb, lc, num, den;
        int k;
        for (k = 0; k < 3; k++) {
            a[k] = m->pos[3 * m->idx[3 * t] + k] - p[k];
            b[k] = m->pos[3 * m->idx[3 * t + 1] + k] - p[k];
            c[k] = m->pos[3 * m->idx[3 * t + 2] + k] - p[k];
        }
        la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        num = a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
        den = la * lb * lc + (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * lc + (b[0] * c[0] + b[1] * c[1] + b[2] * c[2]) * la +
              (c[0] * a[0] + c[1] * a[1] + c[2] * a[2]) * lb;
        sum += 2 * atan2(num, den);
    }
    return sum / (4 * pi);
}

static voxdag *solid_build(const gen_mesh *g, uint32_t levels, uint32_t chunk_levels, uint32_t threads, int solid,
                           int colors, voxdag_status *status) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_mesh mesh;
    voxdag_status s;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.chunk_levels = chunk_levels;
    o.threads = threads;
    o.colors = colors;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = g->pos;
    mesh.vertex_count = g->verts;
    mesh.indices = g->idx;
    mesh.triangle_count = g->tris;
    mesh.color = tri_color;
    mesh.solid = solid;
    s = voxdag_builder_create(&o, &b, NULL);
    if (s == VOXDAG_OK && (s = voxdag_builder_add_mesh(b, &mesh, NULL)) != VOXDAG_OK) voxdag_builder_free(b);
    if (s == VOXDAG_OK) s = voxdag_builder_finish(b, &d, NULL, NULL);
    if (status) *status = s;
    return d;
}

/* Builds G solid at 2^LEVELS under a few chunk sizes and thread counts (the
   same bytes) and checks every voxel: full iff a surface voxel or a centre
   with a nonzero winding number. Returns the voxels inside but not on the
   surface. */
static uint64_t check_solid(const char *name, const gen_mesh *g, uint32_t levels) {
    uint32_t n = 1u << levels, x, y, z;
    voxdag_status s;
    voxdag *surf = solid_build(g, levels, 0, 1, 0, 0, NULL), *d = solid_build(g, levels, 3, 1, 1, 1, &s), *other;
    uint64_t inside = 0, bad = 0, missing_surface = 0;
    size_t size0, size1;
    const void *img;
    CHECK_MSG(s == VOXDAG_OK && surf && d, "%s: %s", name, voxdag_status_string(s));
    if (!surf || !d) {
        voxdag_free(surf);
        voxdag_free(d);
        return 0;
    }
    img = voxdag_image(d, &size0);
    other = solid_build(g, levels, 2, THREADS, 1, 1, NULL);
    CHECK_MSG(other && voxdag_image(other, &size1) && size0 == size1 && !memcmp(img, voxdag_image(other, &size1), size0),
              "%s: chunks of 2^2 on %d threads give other bytes", name, THREADS);
    voxdag_free(other);
    other = solid_build(g, levels, 8, THREADS, 1, 1, NULL);
    CHECK_MSG(other && voxdag_image(other, &size1) && size0 == size1 && !memcmp(img, voxdag_image(other, &size1), size0),
              "%s: chunks of 2^8 on %d threads give other bytes", name, THREADS);
    voxdag_free(other);
    for (z = 0; z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                int on = voxdag_lookup(surf, x, y, z, NULL), got = voxdag_lookup(d, x, y, z, NULL), want = on;
                if (!on) {
                    double p[3], w;
                    p[0] = x + 0.5;
                    p[1] = y + 0.5;
                    p[2] = z + 0.5;
                    w = solid_winding(g, p);
                    CHECK_MSG(fabs(w - floor(w + 0.5)) < 1e-6, "%s: winding %g at a centre off the surface", name, w);
                    want = fabs(w) > 0.5;
                    inside += (uint64_t)want;
                }
                if (on && !got) missing_surface++;
                if (got != want && bad++ < 3)
                    fprintf(stderr, "  %s: voxel %u %u %u is %d, want %d\n", name, x, y, z, got, want);
            }
    if (getenv("SOLID_VERBOSE")) fprintf(stderr, "  %s: %llu inside\n", name, (unsigned long long)inside);
    CHECK_MSG(bad == 0 && missing_surface == 0, "%s at 2^%u: %llu voxels wrong, %llu surface voxels missing", name, levels,
              (unsigned long long)bad, (unsigned long long)missing_surface);
    voxdag_free(surf);
    voxdag_free(d);
    return inside;
}

static void test_solid_shapes(void) {
    gen_mesh g;
    double lo[3], hi[3], c[3];
    memset(&g, 0, sizeof g);
    lo[0] = 3.25, lo[1] = 4.5, lo[2] = 2; /* faces on voxel faces and centres */
    hi[0] = 20.5, hi[1] = 17, hi[2] = 25.75;
    gen_box(&g, lo, hi, 0, 0);
    CHECK(check_solid("box", &g, 5) > 3000);
    gen_free(&g);
    gen_box(&g, lo, hi, 1, 1); /* inside out, faces with their own vertices */
    CHECK(check_solid("box inside out, split faces", &g, 5) > 3000);
    gen_free(&g);
    c[0] = 15.3, c[1] = 16.1, c[2] = 14.7;
    gen_sphere(&g, c, 12.2, 24, 12, 0);
    CHECK(check_solid("sphere", &g, 5) > 5000);
    gen_free(&g);
    c[0] = 15.5, c[1] = 16.5, c[2] = 16; /* poles on a column */
    gen_sphere(&g, c, 12.5, 16, 8, 0);
    gen_sphere(&g, c, 7.5, 12, 6, 1); /* a hollow ball */
    CHECK(check_solid("hollow ball", &g, 5) > 3000);
    gen_free(&g);
    gen_torus(&g, c, 9.5, 4.2, 32, 16);
    CHECK(check_solid("torus", &g, 5) > 1500);
    gen_free(&g);
    gen_star(&g, 15.5, 16.5, 14, 5, 3.5, 27.5);
    CHECK(check_solid("star prism", &g, 5) > 1000);
    gen_free(&g);
    gen_octahedron(&g, 15.5, 16.5, 14.5, 11);
    gen_octahedron(&g, 20.5, 16.5, 14.5, 8); /* overlapping: filled once */
    CHECK(check_solid("octahedra on centres", &g, 5) > 500);
    gen_free(&g);
    lo[0] = -40, lo[1] = -40, lo[2] = 10; /* beyond the grid but in x and y */
    hi[0] = 90, hi[1] = 70, hi[2] = 1e6;
    gen_box(&g, lo, hi, 0, 0);
    CHECK(check_solid("box over the grid", &g, 4) > 0);
    gen_free(&g);
    lo[0] = -3000.25, lo[1] = -2500, lo[2] = 5.5; /* edges past 2^31 fixed-point units: 128-bit products */
    hi[0] = 4100, hi[1] = 3000.75, hi[2] = 11;
    gen_box(&g, lo, hi, 0, 0);
    c[0] = 8.5, c[1] = 7.5, c[2] = 8.5;
    gen_octahedron(&g, c[0], c[1], c[2], 6); /* vertices on centres, inside the slab: winding 2 */
    CHECK(check_solid("wide slab", &g, 4) > 0);
    gen_free(&g);
    lo[0] = -1e13, lo[1] = -3e12, lo[2] = -1e14; /* vertices past +-2^40 voxels: clamped there */
    hi[0] = 2e13, hi[1] = 1e15, hi[2] = 9.5;
    gen_box(&g, lo, hi, 1, 0);
    CHECK(check_solid("huge box, inside out", &g, 4) == 16 * 16 * 9);
    gen_free(&g);
}

/* Interior voxels take the colour of the nearest crossing above: under a
   box's top face (triangles 10 and 11 of gen_box), the top's colour. */
static void test_solid_colors(void) {
    gen_mesh g;
    double lo[3] = {2.5, 3.5, 1.5}, hi[3] = {13.5, 12.5, 14.5};
    uint32_t x, y, z;
    size_t bad = 0, inner = 0;
    voxdag *d, *surf;
    memset(&g, 0, sizeof g);
    gen_box(&g, lo, hi, 0, 0);
    d = solid_build(&g, 4, 2, 1, 1, 1, NULL);
    surf = solid_build(&g, 4, 2, 1, 0, 0, NULL);
    for (z = 0; d && surf && z < 16; z++)
        for (y = 0; y < 16; y++)
            for (x = 0; x < 16; x++) {
                uint64_t i;
                uint8_t rgb[3];
                if (!voxdag_lookup(d, x, y, z, &i) || voxdag_lookup(surf, x, y, z, NULL)) continue;
                inner++;
                voxdag_color(d, i, rgb);
                if (rgb[0] != 10 && rgb[0] != 11) bad++;
            }
    CHECK_MSG(d && surf && inner == 10 * 8 * 12 && bad == 0, "%zu inside voxels, %zu with another colour", inner, bad);
    voxdag_free(d);
    voxdag_free(surf);
    gen_free(&g);
}

static int keep_none(void *user, size_t tri, const double bary[3]) {
    (void)user;
    (void)tri;
    (void)bary;
    return 0;
}

/* keep cuts surface voxels only: with a keep that cuts everything, a sphere
   (no centre on its surface) gives exactly the centres inside. */
static void test_solid_keep(void) {
    gen_mesh g;
    double c[3] = {15.3, 16.1, 14.7};
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_mesh mesh;
    uint32_t x, y, z;
    size_t bad = 0, inside = 0;
    memset(&g, 0, sizeof g);
    gen_sphere(&g, c, 12.2, 24, 12, 0);
    memset(&o, 0, sizeof o);
    o.levels = 5;
    o.chunk_levels = 3;
    o.threads = THREADS;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = g.pos;
    mesh.vertex_count = g.verts;
    mesh.indices = g.idx;
    mesh.triangle_count = g.tris;
    mesh.keep = keep_none;
    mesh.solid = 1;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    for (z = 0; d && z < 32; z++)
        for (y = 0; y < 32; y++)
            for (x = 0; x < 32; x++) {
                double p[3];
                int want;
                p[0] = x + 0.5;
                p[1] = y + 0.5;
                p[2] = z + 0.5;
                want = fabs(solid_winding(&g, p)) > 0.5;
                inside += (size_t)want;
                bad += (size_t)(voxdag_lookup(d, x, y, z, NULL) != want);
            }
    CHECK_MSG(d && bad == 0 && inside > 5000, "%zu voxels wrong of %zu inside", bad, inside);
    voxdag_free(d);
    gen_free(&g);
}

/* A mesh with a hole is reported, not filled; voxdag_mesh_open_edges counts
   its open edges. */
static void test_solid_open(void) {
    gen_mesh g;
    double lo[3] = {2, 2, 2}, hi[3] = {9, 9, 9};
    voxdag_mesh mesh;
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag_error err;
    uint64_t open = 0, first = 0;
    memset(&g, 0, sizeof g);
    gen_box(&g, lo, hi, 0, 1);
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = g.pos;
    mesh.vertex_count = g.verts;
    mesh.indices = g.idx;
    mesh.triangle_count = g.tris;
    CHECK(voxdag_mesh_open_edges(&mesh, NULL, &open, &first, &err) == VOXDAG_OK && open == 0 && first == UINT64_MAX);
    mesh.triangle_count = 10; /* without the last face */
    CHECK(voxdag_mesh_open_edges(&mesh, NULL, &open, &first, &err) == VOXDAG_OK && open == 4 && first == 1);
    mesh.solid = 1;
    memset(&o, 0, sizeof o);
    o.levels = 4;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_ERR_NOT_CLOSED && err.node == 1);
    CHECK(strcmp(voxdag_status_string(VOXDAG_ERR_NOT_CLOSED), "mesh not closed") == 0);
    mesh.triangle_count = 12; /* the builder is still usable */
    CHECK(voxdag_builder_add_mesh(b, &mesh, &err) == VOXDAG_OK);
    voxdag_builder_free(b);
    g.idx[3 * 11 + 2] = g.idx[3 * 11 + 1]; /* a face twice the same way */
    gen_tri(&g, 0, 1, 2, 0);
    gen_tri(&g, 0, 1, 2, 0);
    mesh.indices = g.idx;
    mesh.triangle_count = 14;
    CHECK(voxdag_mesh_open_edges(&mesh, NULL, &open, &first, &err) == VOXDAG_OK && open == 3 + 3 && first == 0);
    gen_free(&g);
}

/* A solid build under growing max_memory: a limit error until enough,
   then the bytes of the unlimited build; nothing leaks (sanitizers). */
static void test_solid_memory_limit(void) {
    gen_mesh g;
    double c[3] = {15.5, 16.5, 16};
    voxdag *ref, *d;
    size_t size0, size1;
    uint64_t limit;
    int passed = 0;
    memset(&g, 0, sizeof g);
    gen_sphere(&g, c, 12.5, 16, 8, 0);
    ref = solid_build(&g, 5, 3, 2, 1, 1, NULL);
    CHECK(ref != NULL);
    for (limit = 1024; ref && limit < (1u << 26) && !passed; limit += limit / 3) {
        voxdag_build_opts o;
        voxdag_builder *b = NULL;
        voxdag_mesh mesh;
        voxdag_error err;
        voxdag_status s;
        memset(&o, 0, sizeof o);
        o.levels = 5;
        o.chunk_levels = 3;
        o.threads = 2;
        o.colors = 1;
        o.max_memory = limit;
        memset(&mesh, 0, sizeof mesh);
        mesh.positions = g.pos;
        mesh.vertex_count = g.verts;
        mesh.indices = g.idx;
        mesh.triangle_count = g.tris;
        mesh.color = tri_color;
        mesh.solid = 1;
        d = NULL;
        s = voxdag_builder_create(&o, &b, &err);
        if (s == VOXDAG_OK && (s = voxdag_builder_add_mesh(b, &mesh, &err)) != VOXDAG_OK) voxdag_builder_free(b);
        if (s == VOXDAG_OK) s = voxdag_builder_finish(b, &d, NULL, &err);
        CHECK_MSG(s == VOXDAG_OK || s == VOXDAG_ERR_LIMIT, "max_memory %llu: %s", (unsigned long long)limit,
                  voxdag_status_string(s));
        if (d) {
            const void *img = voxdag_image(ref, &size0);
            CHECK(voxdag_image(d, &size1) && size0 == size1 && !memcmp(img, voxdag_image(d, &size1), size0));
            passed = 1;
        }
        voxdag_free(d);
    }
    CHECK(passed);
    voxdag_free(ref);
    gen_free(&g);
}

/* A sphere of radius 250 at 2^9: voxels near the ball's volume, time and
   memory (printed). */
static void test_solid_sphere(void) {
    gen_mesh g;
    double c[3] = {256.3, 255.7, 256.1};
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_mesh mesh;
    voxdag_build_stats st;
    voxdag_info info;
    clock_t t0 = clock();
    memset(&g, 0, sizeof g);
    gen_sphere(&g, c, 250, 128, 64, 0);
    memset(&o, 0, sizeof o);
    o.levels = 9;
    o.threads = THREADS;
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = g.pos;
    mesh.vertex_count = g.verts;
    mesh.indices = g.idx;
    mesh.triangle_count = g.tris;
    mesh.solid = 1;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &mesh, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, &st, NULL) == VOXDAG_OK);
    if (d) {
        double v = 4.0 / 3 * 3.14159265358979323846 * 250 * 250 * 250;
        voxdag_get_info(d, &info);
        fprintf(stderr, "  solid sphere r=250 at 2^9, %zu triangles: %llu voxels (ball %.0f), peak %.1f MB, %.2f s cpu\n",
                g.tris, (unsigned long long)info.voxels, v, (double)st.peak_memory / 1e6,
                (double)(clock() - t0) / CLOCKS_PER_SEC);
        CHECK(info.voxels > (uint64_t)(0.99 * v) && info.voxels < (uint64_t)(1.02 * v));
        CHECK(voxdag_lookup(d, 256, 256, 256, NULL) && voxdag_lookup(d, 50, 256, 256, NULL) &&
              !voxdag_lookup(d, 50, 50, 50, NULL));
        CHECK(st.peak_memory < 100000000);
    }
    voxdag_free(d);
    gen_free(&g);
}

/* An OFF file (polygons fanned) fitted into [1.3, 2^LEVELS - 1.7]^3; 0 when
   it cannot be read. */
static int read_off(const char *path, uint32_t levels, gen_mesh *m) {
    FILE *f = fopen(path, "r");
    char word[16];
    unsigned long nv, nf, ne, i;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, scale, span = 0;
    int k, ok = f && fscanf(f, "%15s %lu %lu %lu", word, &nv, &nf, &ne) == 4 && !strcmp(word, "OFF");
    for (i = 0; ok && i < nv; i++) {
        double p[3];
        ok = fscanf(f, "%lf %lf %lf", &p[0], &p[1], &p[2]) == 3;
        gen_vertex(m, p[0], p[1], p[2]);
    }
    for (i = 0; ok && i < nf; i++) {
        unsigned long n, c, v0, prev, v;
        ok = fscanf(f, "%lu %lu %lu", &n, &v0, &prev) == 3 && n >= 3 && v0 < nv && prev < nv;
        for (c = 2; ok && c < n; c++) {
            ok = fscanf(f, "%lu", &v) == 1 && v < nv;
            if (ok) gen_tri(m, (uint32_t)v0, (uint32_t)prev, (uint32_t)v, 0);
            prev = v;
        }
    }
    if (f) fclose(f);
    for (i = 0; ok && i < m->verts; i++)
        for (k = 0; k < 3; k++) {
            if (m->pos[3 * i + k] < lo[k]) lo[k] = m->pos[3 * i + k];
            if (m->pos[3 * i + k] > hi[k]) hi[k] = m->pos[3 * i + k];
        }
    for (k = 0; k < 3; k++)
        if (hi[k] - lo[k] > span) span = hi[k] - lo[k];
    scale = ((double)(1u << levels) - 3) / span;
    for (i = 0; ok && i < m->verts; i++)
        for (k = 0; k < 3; k++) m->pos[3 * i + k] = 1.3 + (m->pos[3 * i + k] - lo[k]) * scale;
    return ok;
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Real closed meshes (OFF files named in VOXDAG_REAL_MESHES, e.g. CGAL's
   armadillo.off that bench/fetch.sh brings; skipped when unset) against an
   inside test along the other axis: rays towards +x from each voxel centre,
   crossings of each triangle by the orientation of its projection on the
   y-z plane, in double (a ray through an edge exactly is left to chance:
   none in these meshes). Voxels the surface touches come from the surface
   build. */
static void test_solid_real_meshes(void) {
    const char *list = getenv("VOXDAG_REAL_MESHES");
    char path[1024];
    while (list && *list) {
        const uint32_t levels = 6, n = 1u << levels;
        size_t len = strcspn(list, " ");
        gen_mesh g;
        voxdag *surf, *d;
        voxdag_status s;
        uint32_t y, z, x;
        uint64_t inside = 0, bad = 0;
        memset(&g, 0, sizeof g);
        snprintf(path, sizeof path, "%.*s", (int)len, list);
        list += len + (list[len] == ' ');
        if (!len) continue;
        CHECK_MSG(read_off(path, levels, &g), "%s: not read", path);
        surf = solid_build(&g, levels, 0, 1, 0, 0, NULL);
        d = solid_build(&g, levels, 4, THREADS, 1, 1, &s);
        if (s == VOXDAG_ERR_NOT_CLOSED) { /* reported, not filled: counted again */
            voxdag_mesh mesh;
            uint64_t open = 0;
            memset(&mesh, 0, sizeof mesh);
            mesh.positions = g.pos;
            mesh.vertex_count = g.verts;
            mesh.indices = g.idx;
            mesh.triangle_count = g.tris;
            CHECK(voxdag_mesh_open_edges(&mesh, NULL, &open, NULL, NULL) == VOXDAG_OK && open > 0);
            fprintf(stderr, "  %s: not closed, %llu open edges\n", path, (unsigned long long)open);
            voxdag_free(surf);
            gen_free(&g);
            continue;
        }
        CHECK_MSG(d && surf, "%s: %s", path, voxdag_status_string(s));
        for (z = 0; d && surf && z < n; z++)
            for (y = 0; y < n; y++) {
                double py = y + 0.5, pz = z + 0.5;
                size_t t, nh = 0, pos = 0, neg = 0;
                double hp[4096], hn[4096];
                for (t = 0; t < g.tris; t++) {
                    const double *a = g.pos + 3 * g.idx[3 * t], *b = g.pos + 3 * g.idx[3 * t + 1],
                                 *c = g.pos + 3 * g.idx[3 * t + 2];
                    double w0 = (b[1] - py) * (c[2] - pz) - (b[2] - pz) * (c[1] - py);
                    double w1 = (c[1] - py) * (a[2] - pz) - (c[2] - pz) * (a[1] - py);
                    double w2 = (a[1] - py) * (b[2] - pz) - (a[2] - pz) * (b[1] - py), sum = w0 + w1 + w2;
                    if (!((w0 > 0 && w1 > 0 && w2 > 0) || (w0 < 0 && w1 < 0 && w2 < 0))) continue;
                    if (sum > 0 && pos < 4096) hp[pos++] = (w0 * a[0] + w1 * b[0] + w2 * c[0]) / sum;
                    if (sum < 0 && neg < 4096) hn[neg++] = (w0 * a[0] + w1 * b[0] + w2 * c[0]) / sum;
                    nh++;
                }
                CHECK(pos + neg == nh);
                qsort(hp, pos, sizeof *hp, cmp_double);
                qsort(hn, neg, sizeof *hn, cmp_double);
                for (x = 0; x < n; x++) {
                    double px = x + 0.5;
                    size_t above_p = 0, above_n = 0;
                    int want, got = voxdag_lookup(d, x, y, z, NULL);
                    if (voxdag_lookup(surf, x, y, z, NULL)) {
                        if (!got) bad++;
                        continue;
                    }
                    for (t = 0; t < pos; t++) above_p += hp[t] > px;
                    for (t = 0; t < neg; t++) above_n += hn[t] > px;
                    want = above_p != above_n;
                    inside += (uint64_t)want;
                    if (want != got && bad++ < 3) fprintf(stderr, "  %s: voxel %u %u %u is %d\n", path, x, y, z, got);
                }
            }
        fprintf(stderr, "  %s: %zu triangles, %llu voxels inside off the surface at 2^%u\n", path, g.tris,
                (unsigned long long)inside, levels);
        CHECK_MSG(bad == 0 && inside > 0, "%s: %llu voxels wrong", path, (unsigned long long)bad);
        voxdag_free(surf);
        voxdag_free(d);
        gen_free(&g);
    }
}

const test_case test_voxelize_cases[] = {
    {"voxelize/random_triangles", test_random_triangles},
    {"voxelize/face_plane", test_face_plane},
    {"voxelize/keep_callback", test_keep_callback},
    {"voxelize/mesh_memory_limit", test_mesh_memory_limit},
    {"voxelize/bad_meshes", test_bad_meshes},
    {"voxelize/solid_shapes", test_solid_shapes},
    {"voxelize/solid_colors", test_solid_colors},
    {"voxelize/solid_open", test_solid_open},
    {"voxelize/solid_keep", test_solid_keep},
    {"voxelize/solid_memory_limit", test_solid_memory_limit},
    {"voxelize/solid_sphere", test_solid_sphere},
    {"voxelize/solid_real_meshes", test_solid_real_meshes},
    {NULL, NULL},
};
