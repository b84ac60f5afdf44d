/* Scene importer tests: each format round-trips files written here from
   random scenes (the expected scene is what the test generated), and broken
   files (cut at every length, patched bytes, huge counts, NaN, indices out of
   range, bad headers) fail with a one-line message. */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include "examples/import.h"

#include <math.h>
#include <stdarg.h>
#include <sys/stat.h>
#include <unistd.h>

#include "import_test.h"
#include "voxdag.h"

// -- A random mesh (the expected scene of mesh round trips)

typedef struct mesh {
    size_t nv, npoly;
    double pos[64][3];
    uint8_t rgb[64][3];
    float uv[64][2];
    size_t poly_size[32];
    uint32_t poly[32][6];
} mesh;

/* Coordinates are multiples of 1/8 (exact in every PLY type but integers,
   for which INTEGRAL makes them whole). */
static void random_mesh(mesh *m, uint64_t *seed, size_t nv, size_t npoly, int integral) {
    size_t i, j;
    m->nv = nv;
    m->npoly = npoly;
    for (i = 0; i < nv; i++) {
        for (j = 0; j < 3; j++) {
            m->pos[i][j] = ((double)test_rand_below(seed, 2001) - 1000) / (integral ? 1 : 8);
            m->rgb[i][j] = (uint8_t)test_rand_below(seed, 256);
        }
        m->uv[i][0] = (float)test_rand_below(seed, 64) / 16;
        m->uv[i][1] = (float)test_rand_below(seed, 64) / 16;
    }
    for (i = 0; i < npoly; i++) {
        m->poly_size[i] = 3 + test_rand_below(seed, 4);
        for (j = 0; j < m->poly_size[i]; j++) m->poly[i][j] = test_rand_below(seed, (uint32_t)nv);
    }
}

/* Triangle T of the fan triangulation of M's polygons, as vertex numbers
   (the triangles the STL writers write). */
static size_t fan(const mesh *m, uint32_t tris[][3]) {
    size_t i, j, n = 0;
    for (i = 0; i < m->npoly; i++)
        for (j = 1; j + 1 < m->poly_size[i]; j++) {
            tris[n][0] = m->poly[i][0];
            tris[n][1] = m->poly[i][j];
            tris[n][2] = m->poly[i][j + 1];
            n++;
        }
    return n;
}

/* 1 if scene vertex GOT of S has the position (and colour, texture
   coordinates when asked) of M's vertex WANT. */
static int same_vertex(const vdag_scene *s, size_t got, const mesh *m, uint32_t want, int rgb, int uv) {
    size_t a;
    for (a = 0; a < 3; a++)
        if (s->positions[3 * got + a] != m->pos[want][a] || (rgb && s->vertex_rgb[3 * got + a] != m->rgb[want][a]))
            return 0;
    return !uv || (s->uv[2 * got] == m->uv[want][0] && s->uv[2 * got + 1] == m->uv[want][1]);
}

/* Checks that S holds a triangulation of each of M's polygons in turn:
   poly_size - 2 triangles whose corners are corners of the polygon (by
   position, and colours and texture coordinates when asked), distinct and
   in the polygon's cyclic order (the importers fan convex polygons and clip
   ears off concave ones; these random polygons are either). */
static void check_mesh(const vdag_scene *s, const mesh *m, int rgb, int uv) {
    size_t n = 0, t = 0, i, k;
    for (i = 0; i < m->npoly; i++) n += m->poly_size[i] - 2;
    CHECK(s->point_count == 0);
    CHECK((s->vertex_rgb != NULL) == rgb);
    CHECK((s->uv != NULL) == uv);
    CHECK_MSG(s->triangle_count == n, "%zu triangles, expected %zu", s->triangle_count, n);
    if (s->triangle_count != n) return;
    for (i = 0; i < m->npoly; i++) {
        size_t np = m->poly_size[i], j0, j1, j2, tt;
        for (tt = 0; tt + 2 < np; tt++, t++) {
            const uint32_t *g = &s->indices[3 * t];
            int found = 0;
            for (k = 0; k < 3; k++) CHECK(g[k] < s->vertex_count);
            if (g[0] >= s->vertex_count || g[1] >= s->vertex_count || g[2] >= s->vertex_count) return;
            for (j0 = 0; j0 < np && !found; j0++)
                for (j1 = 1; j1 < np && !found; j1++)
                    for (j2 = j1 + 1; j2 < np && !found; j2++)
                        found = same_vertex(s, g[0], m, m->poly[i][j0], rgb, uv) &&
                                same_vertex(s, g[1], m, m->poly[i][(j0 + j1) % np], rgb, uv) &&
                                same_vertex(s, g[2], m, m->poly[i][(j0 + j2) % np], rgb, uv);
            CHECK_MSG(found, "polygon %zu triangle %zu: not three corners in order", i, tt);
        }
    }
}

static void test_xyz_roundtrip(void) {
    uint64_t seed = 1;
    int colours;
    for (colours = 0; colours < 2; colours++) {
        bytes b = {NULL, 0, 0};
        uint32_t v[100][6];
        vdag_scene s;
        char err[256];
        size_t i, j;
        putf(&b, "# voxels\n\n");
        for (i = 0; i < 100; i++) {
            for (j = 0; j < 6; j++) v[i][j] = test_rand_below(&seed, j < 3 ? 100000 : 256);
            putf(&b, "%s%u %u\t%u", i % 7 ? "" : "  ", v[i][0], v[i][1], v[i][2]);
            if (colours) putf(&b, " %u %u %u", v[i][3], v[i][4], v[i][5]);
            putf(&b, i % 5 ? "\n" : " # comment\r\n");
        }
        if (!import("xyz", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            CHECK(s.points_are_voxels == 1 && s.point_count == 100 && s.triangle_count == 0);
            CHECK((s.point_rgb != NULL) == colours);
            for (i = 0; i < 100 && s.point_count == 100; i++)
                for (j = 0; j < 3; j++) {
                    CHECK(s.points[3 * i + j] == v[i][j]);
                    if (colours) CHECK(s.point_rgb[3 * i + j] == v[i][3 + j]);
                }
            vdag_scene_free(&s);
        }
        sweep("xyz", &b, 0);
        free(b.p);
    }
}

static void test_xyz_errors(void) {
    expect_error_text("xyz", "1 2 -3\n", "line 1: coordinate outside");
    expect_error_text("xyz", "1 2 3\n1.5 2 x\n", "line 2: value 3 is not a finite number");
    expect_error_text("xyz", "1 2 3\n4 5 6 7 8 9\n", "line 2: 6 values, but line 1 has 3");
    expect_error_text("xyz", "1 2 3 4 5 256\n", "colour outside 0..255");
    expect_error_text("xyz", "1 2 3 4\n", "expected \"x y z\"");
    expect_error_text("xyz", "1 2 3 4 5 6 7\n", "expected \"x y z\"");
    expect_error_text("xyz", "nan 2 3\n", "value 1 is not a finite number");
    expect_error_text("xyz", "1 2.5 3\ninf 2 3\n", "line 2: value 1 is not a finite number");
    expect_error_text("xyz", "4294967296 0 0\n", "coordinate outside");
    expect_error_text("xyz", "99999999999999999999 0 0\n", "line 1: coordinate outside");
    expect_error_text("xyz", "1 2 3 0.5 0 0\n", "line 1: colour outside 0..255");
    expect_error_text("xyz", "1 2 3\n1 2 3.5 4 5 6\n", "line 2: 6 values, but line 1 has 3");
}

/* Coordinates written with a point or an exponent make a point cloud (read
   as written); the 4th-6th values are colours when every one is an integer
   0..255, else ignored (normals). Integer files stay voxel lists. */
static void test_xyz_points(void) {
    uint64_t seed = 5;
    int kind;
    for (kind = 0; kind < 3; kind++) { /* no extra values, colours, normals */
        bytes b = {NULL, 0, 0};
        double v[50][6];
        vdag_scene s;
        char err[256];
        size_t i, j;
        for (i = 0; i < 50; i++) {
            for (j = 0; j < 3; j++) v[i][j] = ((double)test_rand_below(&seed, 20001) - 10000) / 64;
            for (j = 3; j < 6; j++)
                v[i][j] = kind == 1 ? (double)test_rand_below(&seed, 256) : ((double)test_rand_below(&seed, 17) - 8) / 8;
            putf(&b, i == 7 ? "%.17g %.17g %.17ge0" : "%.17g %.17g %.17g", v[i][0], v[i][1], v[i][2]);
            if (kind == 1) putf(&b, " %d %d %d", (int)v[i][3], (int)v[i][4], (int)v[i][5]);
            if (kind == 2) putf(&b, " %.3f %.3f %.3f", v[i][3], v[i][4], v[i][5]);
            putf(&b, i % 3 ? "\n" : " # c\n");
        }
        if (!import("xyz", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            CHECK(s.points_are_voxels == 0 && s.point_count == 50 && s.triangle_count == 0);
            CHECK((s.point_rgb != NULL) == (kind == 1));
            for (i = 0; i < 50 && s.point_count == 50; i++)
                for (j = 0; j < 3; j++) {
                    CHECK(s.points[3 * i + j] == v[i][j]);
                    if (s.point_rgb) CHECK(s.point_rgb[3 * i + j] == v[i][3 + j]);
                }
            vdag_scene_free(&s);
        }
        sweep("xyz", &b, 0);
        free(b.p);
    }
    { /* one decimal point anywhere makes the whole file a point cloud */
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        putf(&b, "1 2 3\n-4 5 6\n7 8 9.0\n");
        if (!import("xyz", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            CHECK(!s.points_are_voxels && s.point_count == 3 && s.points[3] == -4 && s.points[8] == 9);
            vdag_scene_free(&s);
        }
        free(b.p);
    }
}

// -- .ply

typedef struct ply_style {
    const char *format; /* ascii, binary_little_endian, binary_big_endian */
    const char *coord, *colour, *count, *index;
} ply_style;

/* Writes value V as PLY TYPE. */
static void ply_put(bytes *b, const ply_style *st, const char *type, double v) {
    int big = !strcmp(st->format, "binary_big_endian");
    if (!strcmp(st->format, "ascii")) {
        putf(b, "%.17g ", v);
    } else if (!strcmp(type, "float")) {
        float f = (float)v;
        uint32_t u;
        memcpy(&u, &f, 4);
        put_uint(b, u, 4, big);
    } else if (!strcmp(type, "double")) {
        uint64_t u;
        memcpy(&u, &v, 8);
        put_uint(b, u, 8, big);
    } else {
        int n = !strcmp(type, "uchar") || !strcmp(type, "char") ? 1 : !strcmp(type, "ushort") || !strcmp(type, "short") ? 2 : 4;
        put_uint(b, (uint64_t)(int64_t)v, n, big);
    }
}

static void ply_newline(bytes *b, const ply_style *st) {
    if (!strcmp(st->format, "ascii")) putf(b, "\n");
}

/* M as PLY in style ST, with unknown elements and properties around the
   known ones (including lists) that the reader must skip. */
static void write_ply(bytes *b, const mesh *m, const ply_style *st, int faces) {
    size_t i, j;
    putf(b, "ply\r\nformat %s 1.0\ncomment made by the tests\n", st->format);
    putf(b, "element material 2\nproperty list uchar int junk\nproperty float shine\n");
    putf(b, "element vertex %zu\nproperty %s x\nproperty %s y\nproperty %s z\nproperty float nx\n", m->nv, st->coord,
         st->coord, st->coord);
    putf(b, "property %s red\nproperty %s green\nproperty %s blue\nproperty uchar alpha\n", st->colour, st->colour,
         st->colour);
    putf(b, "property list uchar short extra\nproperty float s\nproperty float t\n");
    if (faces)
        putf(b, "element face %zu\nproperty int flags\nproperty list %s %s vertex_indices\n"
                "property list uchar float texcoord\n",
             m->npoly, st->count, st->index);
    putf(b, "element edge 3\nproperty int a\nproperty int b\nend_header\n");
    for (i = 0; i < 2; i++) {
        ply_put(b, st, "uchar", (double)i + 1);
        for (j = 0; j <= i; j++) ply_put(b, st, "int", 7);
        ply_put(b, st, "float", 0.5);
        ply_newline(b, st);
    }
    for (i = 0; i < m->nv; i++) {
        for (j = 0; j < 3; j++) ply_put(b, st, st->coord, m->pos[i][j]);
        ply_put(b, st, "float", 1);
        for (j = 0; j < 3; j++)
            ply_put(b, st, st->colour, !strcmp(st->colour, "float") ? m->rgb[i][j] / 255.0 : m->rgb[i][j]);
        ply_put(b, st, "uchar", 255);
        ply_put(b, st, "uchar", (double)(i % 3));
        for (j = 0; j < i % 3; j++) ply_put(b, st, "short", -5);
        ply_put(b, st, "float", m->uv[i][0]);
        ply_put(b, st, "float", m->uv[i][1]);
        ply_newline(b, st);
    }
    for (i = 0; faces && i < m->npoly; i++) {
        ply_put(b, st, "int", -1);
        ply_put(b, st, st->count, (double)m->poly_size[i]);
        for (j = 0; j < m->poly_size[i]; j++) ply_put(b, st, st->index, m->poly[i][j]);
        ply_put(b, st, "uchar", 2);
        ply_put(b, st, "float", 0);
        ply_put(b, st, "float", 1);
        ply_newline(b, st);
    }
    for (i = 0; i < 3; i++) {
        ply_put(b, st, "int", 1);
        ply_put(b, st, "int", 2);
        ply_newline(b, st);
    }
}

static void test_ply_roundtrip(void) {
    static const char *const formats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    static const char *const coords[] = {"float", "double", "int", "short"};
    static const char *const colours[] = {"uchar", "float"};
    static const char *const lists[][2] = {{"uchar", "int"}, {"ushort", "uint"}, {"uint", "ushort"}, {"char", "uchar"}};
    uint64_t seed = 2;
    size_t f, c, k, l;
    for (f = 0; f < 3; f++)
        for (c = 0; c < 4; c++)
            for (k = 0; k < 2; k++)
                for (l = 0; l < 4; l++) {
                    ply_style st;
                    mesh m;
                    bytes b = {NULL, 0, 0};
                    vdag_scene s;
                    char err[256];
                    st.format = formats[f];
                    st.coord = coords[c];
                    st.colour = colours[k];
                    st.count = lists[l][0];
                    st.index = lists[l][1];
                    random_mesh(&m, &seed, 5 + test_rand_below(&seed, 40), 1 + test_rand_below(&seed, 20), c >= 2);
                    write_ply(&b, &m, &st, 1);
                    if (!import("ply", &b, &s, err, sizeof err)) {
                        CHECK_MSG(0, "%s %s %s %s: %s", st.format, st.coord, st.colour, st.count, err);
                    } else {
                        CHECK(s.vertex_count == m.nv);
                        check_mesh(&s, &m, 1, 1);
                        vdag_scene_free(&s);
                    }
                    free(b.p);
                }
}

static void test_ply_points(void) {
    ply_style st = {"binary_little_endian", "float", "uchar", "uchar", "int"};
    uint64_t seed = 3;
    mesh m;
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    size_t i, j;
    random_mesh(&m, &seed, 30, 0, 0);
    write_ply(&b, &m, &st, 0);
    if (!import("ply", &b, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.points_are_voxels == 0 && s.point_count == 30 && s.point_rgb && !s.positions && !s.uv);
        for (i = 0; i < 30 && s.point_count == 30; i++)
            for (j = 0; j < 3; j++) CHECK(s.points[3 * i + j] == m.pos[i][j] && s.point_rgb[3 * i + j] == m.rgb[i][j]);
        vdag_scene_free(&s);
    }
    free(b.p);
}

/* Cuts and patches of small files in each PLY encoding. */
static void test_ply_sweep(void) {
    static const char *const formats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    uint64_t seed = 4;
    size_t f;
    for (f = 0; f < 3; f++) {
        ply_style st = {formats[f], "float", "uchar", "uchar", "int"};
        mesh m;
        bytes b = {NULL, 0, 0};
        random_mesh(&m, &seed, 4, 2, 0);
        write_ply(&b, &m, &st, 1);
        sweep("ply", &b, f > 0); /* an ASCII number cut short is still a number */
        free(b.p);
    }
}

/* A header line with an unknown keyword (a comment without "comment", as
   some exporters write) is skipped; the rest reads as without it. */
static void test_ply_unknown_header_line(void) {
    ply_style st = {"binary_little_endian", "float", "uchar", "uchar", "int"};
    uint64_t seed = 12;
    mesh m;
    bytes b = {NULL, 0, 0}, with = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    const char *end;
    random_mesh(&m, &seed, 12, 6, 0);
    write_ply(&b, &m, &st, 1);
    end = strstr((const char *)b.p, "element vertex");
    put(&with, b.p, (size_t)(end - (const char *)b.p));
    putf(&with, "Created by an exporter 1.0\n");
    put(&with, end, b.n - (size_t)(end - (const char *)b.p));
    if (!import("ply", &with, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        check_mesh(&s, &m, 1, 1);
        vdag_scene_free(&s);
    }
    free(b.p);
    free(with.p);
}

static void test_ply_errors(void) {
    const char *head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    char text[1024];
    bytes b = {NULL, 0, 0};
    expect_error_text("ply", "plx\nformat ascii 1.0\nend_header\n", "not a PLY file");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex 1\n", "no end_header");
    expect_error_text("ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown format");
    expect_error_text("ply", "ply\nelement vertex 1\nproperty float x\nend_header\n0\n", "no format line");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "unknown property type");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n",
                      "list length type");
    expect_error_text("ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n", "property before any element");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
                      "lacks scalar x, y or z");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                             "property float z\nend_header\n",
                      "more vertices than the file holds");
    expect_error_text("ply", "ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "element NAME COUNT");
    expect_error_text("ply", "ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n",
                      "element NAME COUNT");
    expect_error_text("ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4611686018427387904\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n",
                      "more vertices than the file holds");
    snprintf(text, sizeof text, "%send_header\n0 0 0\n1 nan 0\n0 1 0\n", head);
    expect_error_text("ply", text, "vertex 1: coordinate is not finite");
    snprintf(text, sizeof text, "%send_header\n0 0 0\n1 0 0\n0 1 1e999\n", head);
    expect_error_text("ply", text, "vertex 2: coordinate is not finite");
    snprintf(text, sizeof text, "%selement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", head);
    expect_error_text("ply", text, "line 13: vertex index out of range");
    snprintf(text, sizeof text, "%selement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", head);
    expect_error_text("ply", text, "vertex index out of range");
    snprintf(text, sizeof text, "%selement face 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n", head);
    expect_error_text("ply", text, "bad list length");
    snprintf(text, sizeof text, "%selement face 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n", head);
    expect_error_text("ply", text, "file ends early");
    snprintf(text, sizeof text, "%selement face 1\nproperty int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3\n", head);
    expect_error_text("ply", text, "no vertex_indices list");
    snprintf(text, sizeof text, "%send_header\n0 0 0\n1 0 x\n0 1 0\n", head);
    expect_error_text("ply", text, "line 9: not a number");
    /* A binary NaN, and a skipped element far larger than the file. */
    putf(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n");
    put_le32(&b, 0);
    put_le32(&b, 0x7fc00000);
    put_le32(&b, 0);
    expect_error("ply", &b, "vertex 0: coordinate is not finite");
    b.n = 0;
    putf(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
             "property float z\nelement junk 4000000000000\nproperty double a\nend_header\n");
    expect_error("ply", &b, "file ends early");
    free(b.p);
}

// -- .off

static void write_off(bytes *b, const mesh *m, int coff, int counts_on_header) {
    size_t i, j;
    putf(b, "# a comment first\n%s", coff ? "COFF" : "OFF");
    putf(b, counts_on_header ? " " : "\n\n# counts\n");
    putf(b, "%zu %zu 0\n", m->nv, m->npoly);
    for (i = 0; i < m->nv; i++) {
        putf(b, "%.17g %.17g %.17g", m->pos[i][0], m->pos[i][1], m->pos[i][2]);
        if (coff && i % 2) putf(b, " %.17g %.17g %.17g 1.0", m->rgb[i][0] / 255.0, m->rgb[i][1] / 255.0, m->rgb[i][2] / 255.0);
        else if (coff) putf(b, " %u %u %u 255", m->rgb[i][0], m->rgb[i][1], m->rgb[i][2]);
        putf(b, i % 4 ? "\n" : " # vertex\n");
    }
    for (i = 0; i < m->npoly; i++) {
        putf(b, "%zu", m->poly_size[i]);
        for (j = 0; j < m->poly_size[i]; j++) putf(b, " %u", m->poly[i][j]);
        putf(b, i % 2 ? " 255 0 0\n" : "\n"); /* a face colour, ignored */
    }
}

static void test_off_roundtrip(void) {
    uint64_t seed = 5;
    int coff, header;
    for (coff = 0; coff < 2; coff++)
        for (header = 0; header < 2; header++) {
            mesh m;
            bytes b = {NULL, 0, 0};
            vdag_scene s;
            char err[256];
            random_mesh(&m, &seed, 3 + test_rand_below(&seed, 50), 1 + test_rand_below(&seed, 30), 0);
            write_off(&b, &m, coff, header);
            if (!import("off", &b, &s, err, sizeof err)) {
                CHECK_MSG(0, "%s", err);
            } else {
                check_mesh(&s, &m, coff, 0);
                vdag_scene_free(&s);
            }
            free(b.p);
        }
}

static void test_off_points_and_sweep(void) {
    uint64_t seed = 6;
    mesh m;
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    random_mesh(&m, &seed, 10, 0, 0);
    write_off(&b, &m, 1, 0);
    if (!import("off", &b, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.point_count == 10 && s.points_are_voxels == 0 && s.point_rgb && s.points[3] == m.pos[1][0]);
        vdag_scene_free(&s);
    }
    free(b.p);
    b.p = NULL;
    b.n = b.cap = 0;
    random_mesh(&m, &seed, 4, 2, 0);
    write_off(&b, &m, 1, 1);
    sweep("off", &b, 0);
    free(b.p);
}

static void test_off_errors(void) {
    expect_error_text("off", "", "empty file");
    expect_error_text("off", "PLY\n", "not an OFF file");
    expect_error_text("off", "4OFF\n1 0 0\n", "not an OFF file");
    expect_error_text("off", "OFF BINARY\n", "binary OFF");
    expect_error_text("off", "OFF\n3\n", "expected vertex and face counts");
    expect_error_text("off", "OFF\n-1 0 0\n", "expected vertex and face counts");
    expect_error_text("off", "OFF\n1000000 0 0\n0 0 0\n", "more vertices than the file holds");
    expect_error_text("off", "OFF\n2 0 0\n0 0 0\n# padding\n", "file ends after 1 of 2 vertices");
    expect_error_text("off", "OFF\n1 0 0\n0 nan 0\n", "line 3: coordinate is not finite");
    expect_error_text("off", "OFF\n1 0 0\n0 inf 0\n", "coordinate is not finite");
    expect_error_text("off", "OFF\n1 0 0\n0 0\n# padding\n", "line 3: expected x y z");
    expect_error_text("off", "COFF\n1 0 0\n0 0 0 1\n", "expected a colour");
    expect_error_text("off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: missing or out-of-range");
    expect_error_text("off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "missing or out-of-range");
    expect_error_text("off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "file ends after 1 of 2 faces");
    expect_error_text("off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n", "bad corner count");
}

// -- .obj and .mtl

/* M as OBJ: colours on odd vertices, every corner form, relative indices on
   some faces, and polygons switching between three materials. */
static void write_obj(bytes *b, const mesh *m, int32_t *material_of_poly) {
    size_t i, j;
    putf(b, "# made by the tests\nmtllib lib.mtl\no thing\n");
    for (i = 0; i < m->nv; i++) {
        putf(b, "v %.17g %.17g %.17g", m->pos[i][0], m->pos[i][1], m->pos[i][2]);
        if (i % 2) putf(b, " %.17g %.17g %.17g", m->rgb[i][0] / 255.0, m->rgb[i][1] / 255.0, m->rgb[i][2] / 255.0);
        putf(b, "\nvt %.9g %.9g\nvn 0 0 1\n", m->uv[i][0], m->uv[i][1]);
    }
    for (i = 0; i < m->npoly; i++) {
        static const char *const names[] = {"red", "green paint", "blue"};
        int32_t mat = (int32_t)(i % 4 == 3 ? 1 : i % 3);
        putf(b, "usemtl %s\nf", names[mat]);
        material_of_poly[i] = mat;
        for (j = 0; j < m->poly_size[i]; j++) {
            long v = (long)m->poly[i][j] + 1;
            if (i % 2) v -= (long)m->nv + 1; /* relative to the end */
            putf(b, j % 2 ? " %ld/%ld" : " %ld/%ld/1", v, v);
        }
        putf(b, "\ns off\n");
    }
}

static void test_obj_roundtrip(void) {
    uint64_t seed = 7;
    int round;
    for (round = 0; round < 10; round++) {
        mesh m;
        int32_t mat[32];
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        size_t i, j, t;
        random_mesh(&m, &seed, 3 + test_rand_below(&seed, 60), 1 + test_rand_below(&seed, 30), 0);
        for (i = 0; i < m.nv; i++) /* even vertices have no colour: white */
            if (i % 2 == 0) m.rgb[i][0] = m.rgb[i][1] = m.rgb[i][2] = 255;
        write_obj(&b, &m, mat);
        if (!import("obj", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            uint32_t first_use[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX}, used = 0;
            check_mesh(&s, &m, m.nv > 1, 1);
            CHECK(s.triangle_material != NULL);
            /* Materials are numbered by first use, white without a library. */
            for (i = t = 0; s.triangle_material && i < m.npoly; i++) {
                if (first_use[mat[i]] == UINT32_MAX) first_use[mat[i]] = used++;
                for (j = 2; j < m.poly_size[i]; j++, t++)
                    CHECK(t < s.triangle_count && s.triangle_material[t] == (int32_t)first_use[mat[i]]);
            }
            CHECK(s.material_count == used);
            for (i = 0; i < s.material_count; i++)
                CHECK(s.materials[i].image == -1 && s.materials[i].rgb[0] == 255 && s.materials[i].rgb[2] == 255);
            vdag_scene_free(&s);
        }
        if (round == 0) sweep("obj", &b, 0);
        free(b.p);
    }
}

static void test_obj_points(void) {
    const char *text = "v 1 2 3\nv 4 5 6 0 1 0.5\nvt 0 0\nl 1 2\nf 1 2\n";
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    put(&b, text, strlen(text));
    if (!import("obj", &b, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.point_count == 2 && s.points_are_voxels == 0 && s.points[3] == 4 && s.point_rgb);
        CHECK(s.point_rgb && s.point_rgb[0] == 255 && s.point_rgb[3] == 0 && s.point_rgb[4] == 255 && s.point_rgb[5] == 128);
        vdag_scene_free(&s);
    }
    free(b.p);
}

// -- Polygons: concave ones clipped into ears, bad ones fanned with a warning

/* A comb in the plane z = 0.5: a base [1.5, 62.5] x [1.5, 4.5] with 16 teeth
   1 wide and 4 apart up to y = 20.5; 64 corners, counter-clockwise, every
   coordinate a half-integer. Its fan from the first corner covers the gaps
   between the teeth, where two columns of voxels must stay empty. */
#define COMB_TEETH 16
#define COMB_N (4 * COMB_TEETH)
static void comb(double xy[COMB_N][2]) {
    size_t n = 0;
    int i;
    xy[n][0] = 1.5, xy[n++][1] = 1.5;
    xy[n][0] = 1.5 + 4 * (COMB_TEETH - 1) + 1, xy[n++][1] = 1.5;
    for (i = COMB_TEETH - 1; i >= 0; i--) {
        xy[n][0] = 1.5 + 4 * i + 1, xy[n++][1] = 20.5;
        xy[n][0] = 1.5 + 4 * i, xy[n++][1] = 20.5;
        if (i) {
            xy[n][0] = 1.5 + 4 * i, xy[n++][1] = 4.5;
            xy[n][0] = 1.5 + 4 * i - 3, xy[n++][1] = 4.5;
        }
    }
}

/* Even-odd test of point (X, Y) against polygon XY of N corners. */
static int inside_polygon(const double (*xy)[2], size_t n, double x, double y) {
    size_t i, j;
    int in = 0;
    for (i = 0, j = n - 1; i < n; j = i++)
        if ((xy[i][1] > y) != (xy[j][1] > y) &&
            x < xy[j][0] + (y - xy[j][1]) * (xy[i][0] - xy[j][0]) / (xy[i][1] - xy[j][1]))
            in = !in;
    return in;
}

/* Voxelizes scene S (levels 6) and compares it with the comb, brute force:
   its edges lie on half-integers, so voxel (x, y, 0) touches the comb
   exactly when one of its four quarters' centres is inside; no other voxel
   is full. */
static void check_comb_voxels(const vdag_scene *s, const double (*xy)[2], const char *what) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    voxdag_mesh vm;
    voxdag_info info;
    uint32_t x, y;
    uint64_t want = 0, wrong = 0;
    memset(&o, 0, sizeof o);
    o.levels = 6;
    memset(&vm, 0, sizeof vm);
    vm.positions = s->positions;
    vm.vertex_count = s->vertex_count;
    vm.indices = s->indices;
    vm.triangle_count = s->triangle_count;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add_mesh(b, &vm, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    if (!d) return;
    for (y = 0; y < 64; y++)
        for (x = 0; x < 64; x++) {
            int full = 0, q;
            for (q = 0; q < 4; q++) full |= inside_polygon(xy, COMB_N, x + 0.25 + 0.5 * (q & 1), y + 0.25 + 0.5 * (q >> 1));
            want += (uint64_t)full;
            wrong += (uint64_t)(full != voxdag_lookup(d, x, y, 0, NULL));
        }
    voxdag_get_info(d, &info);
    CHECK(want == 62 * 4 + 16 * 2 * 16); /* base 62 x 4, teeth 2 x 16 */
    CHECK_MSG(wrong == 0 && info.voxels == want, "%s: %llu voxels of the z = 0 layer wrong; %llu voxels, %llu expected",
              what, (unsigned long long)wrong, (unsigned long long)info.voxels, (unsigned long long)want);
    voxdag_free(d);
}

/* The comb written as one polygon in each text format that has polygons
   (.ply with its faces before and after its vertices) voxelizes as the comb:
   no voxel in the gaps between teeth, every voxel of the teeth. */
static void test_concave_polygons(void) {
    double xy[COMB_N][2];
    int fmt;
    comb(xy);
    for (fmt = 0; fmt < 5; fmt++) {
        static const char *const ext[] = {"obj", "off", "ply", "ply", "ac"};
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256], warn[512];
        size_t i;
        if (fmt == 0) {
            for (i = 0; i < COMB_N; i++) putf(&b, "v %g %g 0.5\n", xy[i][0], xy[i][1]);
            putf(&b, "f");
            for (i = 0; i < COMB_N; i++) putf(&b, " %zu", i + 1);
            putf(&b, "\n");
        } else if (fmt == 1) {
            putf(&b, "OFF\n%d 1 0\n", COMB_N);
            for (i = 0; i < COMB_N; i++) putf(&b, "%g %g 0.5\n", xy[i][0], xy[i][1]);
            putf(&b, "%d", COMB_N);
            for (i = 0; i < COMB_N; i++) putf(&b, " %zu", i);
            putf(&b, "\n");
        } else if (fmt == 2 || fmt == 3) { /* 3: the face element first */
            const char *vh = "element vertex 64\nproperty float x\nproperty float y\nproperty float z\n";
            const char *fh = "element face 1\nproperty list uchar int vertex_indices\n";
            putf(&b, "ply\nformat ascii 1.0\n%s%send_header\n", fmt == 2 ? vh : fh, fmt == 2 ? fh : vh);
            if (fmt == 2)
                for (i = 0; i < COMB_N; i++) putf(&b, "%g %g 0.5\n", xy[i][0], xy[i][1]);
            putf(&b, "%d", COMB_N);
            for (i = 0; i < COMB_N; i++) putf(&b, " %zu", i);
            putf(&b, "\n");
            if (fmt == 3)
                for (i = 0; i < COMB_N; i++) putf(&b, "%g %g 0.5\n", xy[i][0], xy[i][1]);
        } else { /* AC3D: y up, so file (x, 0.5, -y) is (x, y, 0.5) */
            putf(&b, "AC3Db\nMATERIAL \"m\" rgb 1 1 1\nOBJECT world\nkids 1\nOBJECT poly\nnumvert %d\n", COMB_N);
            for (i = 0; i < COMB_N; i++) putf(&b, "%g 0.5 %g\n", xy[i][0], -xy[i][1]);
            putf(&b, "numsurf 1\nSURF 0x10\nmat 0\nrefs %d\n", COMB_N);
            for (i = 0; i < COMB_N; i++) putf(&b, "%zu 0 0\n", i);
            putf(&b, "kids 0\n");
        }
        if (!import_warnings(ext[fmt], &b, &s, err, sizeof err, warn, sizeof warn)) {
            CHECK_MSG(0, "%s: %s", ext[fmt], err);
        } else {
            CHECK_MSG(s.triangle_count == COMB_N - 2, "%s: %zu triangles", ext[fmt], s.triangle_count);
            CHECK_MSG(!warn[0], "%s: warned \"%s\"", ext[fmt], warn);
            check_comb_voxels(&s, (const double(*)[2])xy, ext[fmt]);
            vdag_scene_free(&s);
        }
        sweep(ext[fmt], &b, 0);
        free(b.p);
    }
}

/* Convex polygons keep the fan from their first corner, also with a
   straight corner (a square with a midpoint). */
static void test_convex_polygons_fanned(void) {
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4 5\nf 5 4 3 2 1\n";
    static const uint32_t want[] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 4, 3, 2, 4, 2, 1, 4, 1, 0};
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    char err[256], warn[512];
    put(&b, obj, strlen(obj));
    if (!import_warnings("obj", &b, &s, err, sizeof err, warn, sizeof warn)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.triangle_count == 6 && !memcmp(s.indices, want, sizeof want));
        CHECK_MSG(!warn[0], "warned \"%s\"", warn);
        vdag_scene_free(&s);
    }
    free(b.p);
}

/* Self-intersecting polygons (a pentagram, a bow tie) and a degenerate one
   (all corners on a line) are fan-triangulated, with one warning per file
   that counts them; a concave polygon in the same file is still clipped. */
static void test_bad_polygons_warn(void) {
    static const char obj[] = "v 0 10 0\nv 6 -8 0\nv -9.5 3 0\nv 9.5 3 0\nv -6 -8 0\n" /* pentagram, in star order */
                              "v 0 0 1\nv 1 1 1\nv 1 0 1\nv 0 1 1\n"                   /* bow tie */
                              "v 0 0 2\nv 1 0 2\nv 2 0 2\nv 3 0 2\n"                   /* on a line */
                              "v 0 0 3\nv 4 0 3\nv 4 4 3\nv 2 1 3\nv 0 4 3\n"          /* concave: a notch */
                              "f 1 2 3 4 5\nf 6 7 8 9\nf 10 11 12 13\nf 14 15 16 17 18\n";
    static const char off[] = "OFF\n5 1 0\n0 10 0\n6 -8 0\n-9.5 3 0\n9.5 3 0\n-6 -8 0\n5 0 1 2 3 4\n";
    static const uint32_t star_fan[] = {0, 1, 2, 0, 2, 3, 0, 3, 4};
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    char err[256], warn[512];
    put(&b, obj, strlen(obj));
    if (!import_warnings("obj", &b, &s, err, sizeof err, warn, sizeof warn)) {
        CHECK_MSG(0, "%s", err);
    } else {
        const char *w = strstr(warn, "warning: obj: 3 polygons were degenerate or self-intersecting; fan-triangulated");
        CHECK_MSG(w && !strstr(w + 1, "warning"), "warned \"%s\"", warn);
        CHECK(s.triangle_count == 3 + 2 + 2 + 3);
        if (s.triangle_count == 10) {
            CHECK(!memcmp(s.indices, star_fan, sizeof star_fan));
            CHECK(s.indices[15] == 9 && s.indices[16] == 10 && s.indices[17] == 11); /* the line: its fan */
            /* The notch corner (2, 1) is no fan centre: the first corner's
               fan would cross the notch. Triangles cover area 16 - 6 = 10. */
            {
                double area = 0;
                size_t t;
                for (t = 7; t < 10; t++) {
                    const double *p0 = &s.positions[3 * s.indices[3 * t]], *p1 = &s.positions[3 * s.indices[3 * t + 1]],
                                 *p2 = &s.positions[3 * s.indices[3 * t + 2]];
                    double a = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
                    CHECK(a > 0);
                    area += fabs(a) / 2;
                }
                CHECK_MSG(area == 10, "notched polygon: area %g", area);
            }
        }
        vdag_scene_free(&s);
    }
    b.n = 0;
    put(&b, off, strlen(off));
    if (!import_warnings("off", &b, &s, err, sizeof err, warn, sizeof warn)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK_MSG(strstr(warn, "warning: off: 1 polygon was degenerate or self-intersecting; fan-triangulated") != NULL,
                  "warned \"%s\"", warn);
        CHECK(s.triangle_count == 3 && !memcmp(s.indices, star_fan, sizeof star_fan));
        vdag_scene_free(&s);
    }
    free(b.p);
}

static void test_obj_errors(void) {
    expect_error_text("obj", "v 1 2\n", "line 1: v needs x y z");
    expect_error_text("obj", "v 1 2 x\n", "line 1: not a number");
    expect_error_text("obj", "v 1 nan 3\n", "coordinate is not finite");
    expect_error_text("obj", "v 1 2 3 nan 0 0\n", "colour is NaN");
    expect_error_text("obj", "vt inf 0\n", "texture coordinate is not finite");
    expect_error_text("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "a face uses vertex 4 of 3");
    expect_error_text("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "line 4: bad face corner");
    expect_error_text("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4: bad face corner");
    expect_error_text("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", "texture coordinate 2 of 1");
    expect_error_text("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n", "bad face corner");
    expect_error_text("obj", "v 0 0 0\nf 1 1 99999999999999999999\n", "bad face corner");
    expect_error_text("mtl", "Kd 1 1 1\n", "line 1: Kd before newmtl");
    expect_error_text("mtl", "newmtl a\nKd 1 1\n", "line 2: Kd needs 1 or 3 numbers");
    expect_error_text("mtl", "newmtl a\nKd 1 nan 1\n", "Kd needs 1 or 3 numbers");
    expect_error_text("mtl", "newmtl a\nmap_Kd -s 1 1 1\n", "line 2: map_Kd has no file");
}

/* A 3x2 binary PPM, for the texture of the file test. */
static const uint8_t test_pixels[18] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30, 40, 50, 60, 70, 80, 90};

static int write_file(const char *path, const void *data, size_t n) {
    FILE *f = fopen(path, "wb");
    size_t put_n;
    if (!f) return 0;
    put_n = fwrite(data, 1, n, f);
    return fclose(f) == 0 && put_n == n;
}

/* .obj from a file: the .mtl beside it gives colours and a texture whose
   name has spaces and options before it. */
static void test_obj_file(void) {
    char dir[] = "/tmp/vdag-import-XXXXXX", path[256], sub[256], tex[256], err[512];
    const char *obj = "mtllib lib.mtl missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                      "usemtl plain\nf 1 2 3\nusemtl painted\nf 1/1 2/2 3/3\nusemtl unknown\nf 3 2 1\n";
    const char *mtl = "newmtl unused\nKd 0 0 0\nnewmtl plain\nKd 0.2 0.4 1\n"
                      "newmtl painted\nKd 0.5\nmap_Kd -s 1 1 1 -o 0.5 -bm 0.2 -clamp on tex dir\\my tex.ppm\n";
    bytes ppm = {NULL, 0, 0};
    vdag_scene s;
    vdag_image probe;
    vdag_import_limits limits;
    int decodes;
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/scene.OBJ", dir);
    CHECK(write_file(path, obj, strlen(obj)));
    snprintf(path, sizeof path, "%s/lib.mtl", dir);
    CHECK(write_file(path, mtl, strlen(mtl)));
    snprintf(sub, sizeof sub, "%s/tex dir", dir);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(tex, sizeof tex, "%s/tex dir/my tex.ppm", dir);
    putf(&ppm, "P6\n3 2\n255\n");
    put(&ppm, test_pixels, sizeof test_pixels);
    CHECK(write_file(tex, ppm.p, ppm.n));
    decodes = vdag_image_load(tex, &probe, err, sizeof err);
    if (!decodes) CHECK_MSG(strstr(err, "texture decoding not built in") != NULL, "%s", err);
    vdag_image_free(&probe);

    snprintf(path, sizeof path, "%s/scene.OBJ", dir);
    if (!vdag_import_file(path, NULL, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.triangle_count == 3 && s.material_count == 3 && s.uv != NULL);
        CHECK(s.triangle_material && s.triangle_material[0] == 0 && s.triangle_material[1] == 1 &&
              s.triangle_material[2] == 2);
        CHECK(s.materials[0].rgb[0] == 51 && s.materials[0].rgb[1] == 102 && s.materials[0].rgb[2] == 255);
        CHECK(s.materials[0].image == -1);
        CHECK(s.materials[1].rgb[0] == 128 && s.materials[1].rgb[1] == 128 && s.materials[1].rgb[2] == 128);
        CHECK(s.materials[2].rgb[0] == 255 && s.materials[2].image == -1);
        if (decodes) {
            CHECK(s.image_count == 1 && s.materials[1].image == 0);
            CHECK(s.image_count == 1 && s.images[0].width == 3 && s.images[0].height == 2 &&
                  !memcmp(s.images[0].rgb, test_pixels, sizeof test_pixels));
        } else {
            CHECK(s.image_count == 0 && s.materials[1].image == -1);
        }
        vdag_scene_free(&s);
    }
    /* Callers that keep no colours skip the texture: the material keeps Kd. */
    memset(&limits, 0, sizeof limits);
    limits.skip_textures = 1;
    if (!vdag_import_file(path, &limits, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.material_count == 3 && s.image_count == 0 && s.materials[1].image == -1);
        CHECK(s.materials[1].rgb[0] == 128 && s.uv != NULL);
        vdag_scene_free(&s);
    }
    remove(tex);
    rmdir(sub);
    snprintf(path, sizeof path, "%s/lib.mtl", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/scene.OBJ", dir);
    remove(path);
    rmdir(dir);
    free(ppm.p);
}


/* Imports file PATH with warnings on, returning what went to stderr in WARN. */
static int import_file_warnings(const char *path, vdag_scene *s, char *err, size_t err_size, char *warn,
                                size_t warn_size) {
    FILE *tmp = tmpfile();
    int saved = dup(2), ok;
    size_t n;
    warn[0] = 0;
    CHECK(tmp != NULL && saved >= 0);
    if (!tmp || saved < 0) return 0;
    fflush(stderr);
    dup2(fileno(tmp), 2);
    ok = vdag_import_file(path, NULL, s, err, err_size);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    n = fread(warn, 1, warn_size - 1, tmp);
    warn[n] = 0;
    fclose(tmp);
    return ok;
}

/* A usemtl name that no material library read defines stays white, with one
   warning per .obj naming such names (the first few): none when every name
   is defined; one line for several undefined names, or several uses. */
static void test_obj_undefined_material(void) {
    static const char *const mtl = "newmtl red\nKd 1 0 0\n";
    static const struct {
        const char *obj, *want; /* WANT: the warning's text after the file name; NULL: no warning */
    } cases[] = {
        {"mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n", NULL},
        {"mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl hull\nf 3 2 1\nusemtl hull\nf 1 3 2\n",
         ": usemtl names 1 material that no material library defines (white): \"hull\"\n"},
        {"mtllib lib.mtl gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl red\nf 3 2 1\nusemtl b\nf 1 3 2\n",
         ": usemtl names 2 materials that no material library defines (white): \"a\", \"b\"\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 3 2 1\nusemtl c\nf 1 3 2\nusemtl d\nf 2 1 3\n"
         "usemtl e\nf 2 3 1\n",
         ": usemtl names 5 materials that no material library defines (white): \"a\", \"b\", \"c\", \"d\", ... "
         "(no mtllib line)\n"},
    };
    char dir[] = "/tmp/vdag-mtlname-XXXXXX", path[256], lib[256], err[512], warn[2048];
    size_t k, i, white;
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/boat.obj", dir);
    snprintf(lib, sizeof lib, "%s/lib.mtl", dir);
    CHECK(write_file(lib, mtl, strlen(mtl)));
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        vdag_scene s;
        CHECK(write_file(path, cases[k].obj, strlen(cases[k].obj)));
        if (!import_file_warnings(path, &s, err, sizeof err, warn, sizeof warn)) {
            CHECK_MSG(0, "case %zu: %s", k, err);
            continue;
        }
        if (!cases[k].want) {
            CHECK_MSG(!warn[0], "case %zu warned \"%s\"", k, warn);
        } else { /* the warning ends the output: one line (a missing library has its own, before it) */
            const char *m = strstr(warn, "vdag: warning: ");
            while (m && strstr(m + 1, "vdag: warning: ")) m = strstr(m + 1, "vdag: warning: ");
            m = m ? strstr(m, "boat.obj: usemtl") : NULL;
            CHECK_MSG(m && !strcmp(m + strlen("boat.obj"), cases[k].want), "case %zu warned \"%s\"", k, warn);
            CHECK_MSG(strstr(warn, "usemtl") == m + strlen("boat.obj: "), "case %zu warned \"%s\"", k, warn);
        }
        for (i = white = 0; i < s.material_count; i++) /* red is red, the undefined ones white */
            white += s.materials[i].rgb[0] == 255 && s.materials[i].rgb[1] == 255 && s.materials[i].rgb[2] == 255;
        CHECK_MSG(white + (k != 3) == s.material_count, "case %zu: %zu white of %zu", k, white, s.material_count);
        vdag_scene_free(&s);
    }
    remove(path);
    remove(lib);
    rmdir(dir);
}

/* Side files (material libraries, textures) are read only when they are
   regular files of at most VDAG_IMPORT_MAX_SIDE_FILE_BYTES: a device (no
   4 GiB read of /dev/zero), a FIFO (no wait for a writer) or an oversized
   file is refused at once, with a message naming it. */
static void test_side_files(void) {
    static const char *const tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
    char dir[] = "/tmp/vdag-side-XXXXXX", path[256], fifo[256], big[256], text[512], err[512];
    vdag_scene s;
    FILE *f;
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/scene.obj", dir);
    snprintf(fifo, sizeof fifo, "%s/fifo.mtl", dir);
    CHECK(mkfifo(fifo, 0600) == 0);
    snprintf(big, sizeof big, "%s/big.mtl", dir);
    CHECK((f = fopen(big, "wb")) != NULL); /* sparse: one byte past the limit */
    if (f) CHECK(fseek(f, (long)VDAG_IMPORT_MAX_SIDE_FILE_BYTES, SEEK_SET) == 0 && fputc('\n', f) == '\n' && !fclose(f));

    snprintf(text, sizeof text, "mtllib /dev/zero\n%s", tri);
    CHECK(write_file(path, text, strlen(text)));
    CHECK(!vdag_import_file(path, NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "/dev/zero") && strstr(err, "not a regular file"), "%s", err);

    snprintf(text, sizeof text, "mtllib fifo.mtl\n%s", tri);
    CHECK(write_file(path, text, strlen(text)));
    CHECK(!vdag_import_file(path, NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "fifo.mtl") && strstr(err, "not a regular file"), "%s", err);

    snprintf(text, sizeof text, "mtllib big.mtl\n%s", tri);
    CHECK(write_file(path, text, strlen(text)));
    CHECK(!vdag_import_file(path, NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "big.mtl") && strstr(err, "larger than 268435456 bytes"), "%s", err);

    /* A texture that is a FIFO, and a material library that is a directory. */
    snprintf(text, sizeof text, "mtllib lib.mtl\n%s", tri);
    CHECK(write_file(path, text, strlen(text)));
    snprintf(text, sizeof text, "%s/lib.mtl", dir);
    CHECK(write_file(text, "newmtl m\nmap_Kd fifo.mtl\n", 25));
    CHECK(!vdag_import_file(path, NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "fifo.mtl") && strstr(err, "not a regular file"), "%s", err);
    remove(text);
    CHECK(mkdir(text, 0700) == 0);
    CHECK(!vdag_import_file(path, NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "lib.mtl") && strstr(err, "not a regular file"), "%s", err);
    rmdir(text);

    /* A library that does not exist still only gets a warning. */
    snprintf(text, sizeof text, "mtllib none.mtl\n%s", tri);
    CHECK(write_file(path, text, strlen(text)));
    {
        vdag_import_limits quiet;
        memset(&quiet, 0, sizeof quiet);
        quiet.quiet = 1;
        if (!vdag_import_file(path, &quiet, &s, err, sizeof err)) CHECK_MSG(0, "%s", err);
        else vdag_scene_free(&s);
    }
    remove(path);
    remove(fifo);
    remove(big);
    rmdir(dir);
}

/* vdag_import_limits.run for the tests: the jobs on the calling thread,
   last first. */
static void run_backwards(void *user, void (*job)(void *job_user, uint32_t index), void *job_user, uint32_t count) {
    (void)user;
    while (count > 0) job(job_user, --count);
}

/* Textures are cached by file identity: one file named under several
   spellings is decoded once and counted once against max_texture_pixels,
   the pixel budget of all textures of an import. The same with textures
   decoded in batches of 2 and 3 on the caller's threads (limits.run), and
   an undecodable texture among them keeps its material's colour. */
static void test_texture_budget(void) {
    char dir[] = "/tmp/vdag-tex-XXXXXX", path[256], lib[256], sub[256], tex[256], tex2[256], bad[256], mtl[1024],
         err[512];
    const char *obj = "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                      "usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 2/2 3/3\nusemtl c\nf 1/1 2/2 3/3\n"
                      "usemtl d\nf 1/1 2/2 3/3\n";
    bytes ppm = {NULL, 0, 0};
    vdag_import_limits lim;
    vdag_scene s;
    vdag_image probe;
    int decodes, k, v;
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/scene.obj", dir);
    CHECK(write_file(path, obj, strlen(obj)));
    snprintf(sub, sizeof sub, "%s/sub", dir);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(tex, sizeof tex, "%s/a.ppm", dir);
    snprintf(tex2, sizeof tex2, "%s/b.ppm", dir);
    putf(&ppm, "P6\n3 2\n255\n");
    put(&ppm, test_pixels, sizeof test_pixels);
    CHECK(write_file(tex, ppm.p, ppm.n) && write_file(tex2, ppm.p, ppm.n));
    decodes = vdag_image_load(tex, &probe, err, sizeof err);
    vdag_image_free(&probe);
    snprintf(lib, sizeof lib, "%s/lib.mtl", dir);
    /* a.ppm four ways: plain, "./", through "sub/..", and absolute. */
    snprintf(mtl, sizeof mtl, "newmtl a\nmap_Kd a.ppm\nnewmtl b\nmap_Kd ./a.ppm\nnewmtl c\nmap_Kd sub/../a.ppm\n"
                              "newmtl d\nmap_Kd %s\n", tex);
    CHECK(write_file(lib, mtl, strlen(mtl)));
    for (k = 0; k < 6; k++) { /* 6 pixels: within a budget of 6, not of 5 */
        v = k >> 1; /* one by one, in batches of 2, of 3 */
        memset(&lim, 0, sizeof lim);
        lim.run = run_backwards;
        lim.threads = v ? (uint32_t)v + 1 : 0;
        lim.quiet = 1;
        lim.max_texture_pixels = 6 - (uint64_t)(k & 1);
        if (!decodes) break;
        if (vdag_import_file(path, &lim, &s, err, sizeof err)) {
            CHECK(!(k & 1));
            CHECK_MSG(s.image_count == 1, "%zu images", s.image_count);
            CHECK(s.material_count == 4 && s.materials[0].image == 0 && s.materials[1].image == 0 &&
                  s.materials[2].image == 0 && s.materials[3].image == 0);
            vdag_scene_free(&s);
        } else {
            CHECK_MSG((k & 1) && strstr(err, "max_texture_pixels") && strstr(err, "--max-texture-pixels"), "%s", err);
        }
    }
    /* Two files of 6 pixels each: 12 in all. */
    snprintf(mtl, sizeof mtl, "newmtl a\nmap_Kd a.ppm\nnewmtl b\nmap_Kd b.ppm\nnewmtl c\nmap_Kd ./b.ppm\n");
    CHECK(write_file(lib, mtl, strlen(mtl)));
    for (k = 0; decodes && k < 6; k++) {
        v = k >> 1;
        memset(&lim, 0, sizeof lim);
        lim.run = run_backwards;
        lim.threads = v ? (uint32_t)v + 1 : 0;
        lim.quiet = 1;
        lim.max_texture_pixels = 12 - (uint64_t)(k & 1);
        if (vdag_import_file(path, &lim, &s, err, sizeof err)) {
            CHECK(!(k & 1) && s.image_count == 2);
            vdag_scene_free(&s);
        } else {
            CHECK_MSG((k & 1) && strstr(err, "b.ppm") && strstr(err, "max_texture_pixels (11)"), "%s", err);
        }
    }
    /* A texture that does not decode between them: its material keeps its
       colour, the others' images are numbered as they are met. */
    snprintf(mtl, sizeof mtl, "newmtl a\nmap_Kd bad.ppm\nnewmtl b\nmap_Kd b.ppm\nnewmtl c\nmap_Kd a.ppm\n"
                              "newmtl d\nmap_Kd ./b.ppm\n");
    CHECK(write_file(lib, mtl, strlen(mtl)));
    snprintf(bad, sizeof bad, "%s/bad.ppm", dir);
    CHECK(write_file(bad, "not an image", 12));
    for (v = 0; decodes && v < 4; v++) {
        memset(&lim, 0, sizeof lim);
        lim.run = run_backwards;
        lim.threads = (uint32_t)v + (v > 0);
        lim.quiet = 1;
        if (vdag_import_file(path, &lim, &s, err, sizeof err)) {
            CHECK_MSG(s.image_count == 2 && s.material_count == 4 && s.materials[0].image == -1 &&
                          s.materials[1].image == 0 && s.materials[2].image == 1 && s.materials[3].image == 0,
                      "batches of %u: %zu images, %d %d %d %d", lim.threads, s.image_count, s.materials[0].image,
                      s.materials[1].image, s.materials[2].image, s.materials[3].image);
            vdag_scene_free(&s);
        } else {
            CHECK_MSG(0, "%s", err);
        }
    }
    remove(bad);
    remove(lib);
    remove(tex);
    remove(tex2);
    remove(path);
    rmdir(sub);
    rmdir(dir);
    free(ppm.p);
}

// -- .stl

/* ASCII: one facet per polygon (more than three vertices are fanned), with
   keywords in STYLE's case, CRLF lines and a UTF-8 BOM when asked. */
static void write_stl_ascii(bytes *b, const mesh *m, int upper, int bom) {
    size_t i, j;
    if (bom) put(b, "\xEF\xBB\xBF", 3);
    putf(b, upper ? "SOLID part one\r\n" : "solid part one\n");
    for (i = 0; i < m->npoly; i++) {
        putf(b, upper ? "  FACET NORMAL 0 0 1\r\n    OUTER LOOP\r\n" : "facet normal 0 0 1\nouter loop\n");
        for (j = 0; j < m->poly_size[i]; j++) {
            const double *p = m->pos[m->poly[i][j]];
            putf(b, upper ? "      VERTEX %.9e %.9e %.9e\r\n" : "vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
        }
        putf(b, upper ? "    ENDLOOP\r\n  ENDFACET\r\n" : "endloop\nendfacet\n");
    }
    putf(b, upper ? "ENDSOLID part one\r\n" : "endsolid part one\n");
}

/* Binary: the fan triangles; HEADER fills the first bytes of the header. */
static void write_stl_binary(bytes *b, const mesh *m, const char *header) {
    uint32_t tris[32 * 4][3];
    size_t n = fan(m, tris), t, k, a;
    char head[80] = {0};
    memcpy(head, header, strlen(header));
    put(b, head, 80);
    put_le32(b, (int64_t)n);
    for (t = 0; t < n; t++) {
        float f[12];
        uint8_t raw[48];
        f[0] = f[1] = 0, f[2] = 1;
        for (k = 0; k < 3; k++)
            for (a = 0; a < 3; a++) f[3 + 3 * k + a] = (float)m->pos[tris[t][k]][a];
        for (k = 0; k < 12; k++) {
            uint32_t w;
            memcpy(&w, &f[k], 4);
            for (a = 0; a < 4; a++) raw[4 * k + a] = (uint8_t)(w >> (8 * a));
        }
        put(b, raw, 48);
        put(b, "\0\0", 2);
    }
}

static void test_stl_roundtrip(void) {
    uint64_t seed = 21;
    int style;
    for (style = 0; style < 4; style++) { /* ascii, ASCII with BOM and CRLF, binary, binary saying "solid" */
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        mesh m;
        random_mesh(&m, &seed, 20, 12, 0); /* multiples of 1/8 below 126: exact in a float */
        if (style < 2) write_stl_ascii(&b, &m, style, style);
        else write_stl_binary(&b, &m, style == 2 ? "binary STL" : "solid by a CAD exporter");
        if (!import("stl", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "style %d: %s", style, err);
        } else {
            check_mesh(&s, &m, 0, 0);
            vdag_scene_free(&s);
        }
        sweep("stl", &b, style >= 2);
        free(b.p);
    }
}

static void test_stl_errors(void) {
    bytes b = {NULL, 0, 0};
    mesh m;
    uint64_t seed = 22;
    expect_error_text("stl", "", "not an STL file");
    expect_error_text("stl", "hello", "not an STL file");
    expect_error_text("stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
                      "line 6: a facet with fewer than 3 vertices");
    expect_error_text("stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 nan 0\n",
                      "line 5: expected \"vertex x y z\" with finite numbers");
    expect_error_text("stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n"
                             "endloop\nendfacet\n",
                      "no \"endsolid\"");
    expect_error_text("stl", "solid x\nvertex 0 0 0\n", "line 2: expected \"facet\" or \"endsolid\"");
    expect_error_text("stl", "solid x\nfacet\nloop\n", "line 3: expected \"outer loop\"");
    random_mesh(&m, &seed, 8, 3, 0);
    write_stl_binary(&b, &m, "");
    b.p[80] = 200; /* more triangles than the file holds */
    expect_error("stl", &b, "binary header declares 200 triangles");
    b.p[80] = 0; /* fewer: the rest is ignored with a warning */
    {
        vdag_scene s;
        char err[256];
        vdag_import_limits quiet;
        memset(&quiet, 0, sizeof quiet);
        quiet.quiet = 1;
        CHECK(vdag_import_memory("stl", b.p, b.n, NULL, &quiet, &s, err, sizeof err) && s.triangle_count == 0);
        vdag_scene_free(&s);
    }
    b.n = 84;
    b.p[80] = 1;
    memcpy(b.p, "solid x\n", 8);
    expect_error("stl", &b, "line 2: expected \"facet\" or \"endsolid\""); /* not binary-sized: read as ASCII */
    free(b.p);
}

// -- Tolerance: byte order marks, UTF-16, short palettes, directories

/* A UTF-8 byte order mark before any text format changes nothing; UTF-16
   text is refused with a message that says so. */
static void test_text_bom(void) {
    static const struct {
        const char *ext, *text;
    } files[] = {
        {"xyz", "1 2 3 4 5 6\n7 8 9 10 11 12\n"},
        {"ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
        {"off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"},
        {"ac", "AC3D\nMATERIAL \"m\" rgb 1 0 0\nOBJECT world\nkids 1\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\n"
               "numsurf 1\nSURF 0x0\nmat 0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n"},
        {"stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
                "endsolid t\n"},
        {"mtl", "newmtl a\nKd 1 0.5 0\n"},
    };
    size_t i, j;
    for (i = 0; i < sizeof files / sizeof files[0]; i++) {
        bytes plain = {NULL, 0, 0}, bom = {NULL, 0, 0}, wide = {NULL, 0, 0};
        vdag_scene a, b;
        char err[256];
        put(&plain, files[i].text, strlen(files[i].text));
        put(&bom, "\xEF\xBB\xBF", 3);
        put(&bom, files[i].text, strlen(files[i].text));
        if (!import(files[i].ext, &plain, &a, err, sizeof err)) {
            CHECK_MSG(0, "%s: %s", files[i].ext, err);
        } else {
            if (!import(files[i].ext, &bom, &b, err, sizeof err)) {
                CHECK_MSG(0, "%s with a BOM: %s", files[i].ext, err);
            } else {
                CHECK(a.point_count == b.point_count && a.vertex_count == b.vertex_count &&
                      a.triangle_count == b.triangle_count && a.material_count == b.material_count);
                CHECK(a.triangle_count || a.point_count || a.material_count);
                for (j = 0; j < 3 * a.vertex_count && a.vertex_count == b.vertex_count; j++)
                    CHECK(a.positions[j] == b.positions[j]);
                vdag_scene_free(&b);
            }
            vdag_scene_free(&a);
        }
        /* The same text in UTF-16, little-endian with a BOM, and without one. */
        put(&wide, "\xFF\xFE", 2);
        for (j = 0; files[i].text[j]; j++) {
            put(&wide, &files[i].text[j], 1);
            put(&wide, "", 1);
        }
        if (strcmp(files[i].ext, "stl")) {
            bytes no_bom = {NULL, 0, 0};
            put(&no_bom, wide.p + 2, wide.n - 2);
            expect_error(files[i].ext, &wide, "UTF-16");
            expect_error(files[i].ext, &no_bom, "UTF-16");
            free(no_bom.p);
        }
        free(plain.p);
        free(bom.p);
        free(wide.p);
    }
}

static void test_file_errors(void) {
    vdag_scene s;
    char err[256];
    CHECK(!vdag_import_file("/nonexistent/scene.ply", NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "/nonexistent/scene.ply: cannot open") == err, "%s", err);
    CHECK(!vdag_import_file("tests/test_import.c", NULL, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "unknown format") != NULL, "%s", err);
    CHECK(!vdag_import_memory("stp", "", 0, NULL, NULL, &s, err, sizeof err));
    CHECK_MSG(!strcmp(err, "stp: unknown format (expected .xyz, .ply, .obj, .off, .stl, .vox, .mtl, .spm or .ac)"),
              "%s", err);
    CHECK(!vdag_import_file("tests", NULL, &s, err, sizeof err)); /* a directory */
    CHECK_MSG(strstr(err, "tests: is a directory") == err, "%s", err);
    CHECK(!vdag_import_memory("ply", "", 0, NULL, NULL, &s, err, 8)); /* the message is cut, not overflowed */
    CHECK(strlen(err) == 7);
    CHECK(!vdag_import_memory("ply", "", 0, NULL, NULL, &s, NULL, 0));
}

/* Limits apply to totals: each passes at the scene's own count and fails
   one below it, with a message naming it; the input cap also for files. */
static void test_limits(void) {
    static const char *const xyz = "1 2 3\n4 5 6\n7 8 9\n";
    static const char *const obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n";
    char dir[] = "/tmp/vdag-limits-XXXXXX", path[256], err[512];
    vdag_import_limits lim;
    vdag_scene s;
    int k;
    for (k = 0; k < 2; k++) { /* max_points on a point cloud */
        memset(&lim, 0, sizeof lim);
        lim.max_points = 3 - (uint64_t)k;
        CHECK(vdag_import_memory("xyz", xyz, strlen(xyz), NULL, &lim, &s, err, sizeof err) == !k);
        if (!k) vdag_scene_free(&s);
        else CHECK_MSG(strstr(err, "max_points") != NULL, "%s", err);
    }
    for (k = 0; k < 2; k++) { /* max_vertices and max_triangles on a mesh (a quad: 2 triangles) */
        memset(&lim, 0, sizeof lim);
        lim.max_vertices = 4 - (uint64_t)k;
        CHECK(vdag_import_memory("obj", obj, strlen(obj), NULL, &lim, &s, err, sizeof err) == !k);
        if (!k) vdag_scene_free(&s);
        else CHECK_MSG(strstr(err, "max_vertices") != NULL, "%s", err);
        memset(&lim, 0, sizeof lim);
        lim.max_triangles = 2 - (uint64_t)k;
        CHECK(vdag_import_memory("obj", obj, strlen(obj), NULL, &lim, &s, err, sizeof err) == !k);
        if (!k) vdag_scene_free(&s);
        else CHECK_MSG(strstr(err, "max_triangles") != NULL, "%s", err);
    }
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/points.xyz", dir);
    CHECK(write_file(path, xyz, strlen(xyz)));
    for (k = 0; k < 2; k++) { /* max_input_bytes, in memory and from a file */
        memset(&lim, 0, sizeof lim);
        lim.max_input_bytes = strlen(xyz) - (uint64_t)k;
        CHECK(vdag_import_memory("xyz", xyz, strlen(xyz), NULL, &lim, &s, err, sizeof err) == !k);
        if (!k) vdag_scene_free(&s);
        else CHECK_MSG(strstr(err, "max_input_bytes") != NULL, "%s", err);
        CHECK(vdag_import_file(path, &lim, &s, err, sizeof err) == !k);
        if (!k) vdag_scene_free(&s);
        else CHECK_MSG(strstr(err, "max_input_bytes") != NULL && !s.point_count, "%s", err);
    }
    remove(path);
    rmdir(dir);
}

// -- .vox

typedef struct vox_model {
    uint32_t size[3];
    size_t n;
    uint8_t v[40][4]; /* x, y, z, colour index */
} vox_model;

static void random_model(vox_model *m, uint64_t *seed) {
    size_t i, a;
    for (a = 0; a < 3; a++) m->size[a] = 1 + test_rand_below(seed, 12);
    m->n = 1 + test_rand_below(seed, 40);
    for (i = 0; i < m->n; i++) {
        for (a = 0; a < 3; a++) m->v[i][a] = (uint8_t)test_rand_below(seed, m->size[a]);
        m->v[i][3] = (uint8_t)(1 + test_rand_below(seed, 255));
    }
}

static void vox_chunk(bytes *b, const char *id, const bytes *content, uint32_t children) {
    put(b, id, 4);
    put_le32(b, (int64_t)content->n);
    put_le32(b, children);
    put(b, content->p, content->n);
}

static void vox_string(bytes *b, const char *s) {
    put_le32(b, (int64_t)strlen(s));
    put(b, s, strlen(s));
}

/* A DICT of N key/value pairs given as strings. */
static void vox_dict(bytes *b, int n, ...) {
    va_list ap;
    int i;
    put_le32(b, n);
    va_start(ap, n);
    for (i = 0; i < 2 * n; i++) vox_string(b, va_arg(ap, const char *));
    va_end(ap);
}

static void vox_models(bytes *b, const vox_model *models, size_t count) {
    bytes c = {NULL, 0, 0};
    size_t i, k;
    for (i = 0; i < count; i++) {
        c.n = 0;
        for (k = 0; k < 3; k++) put_le32(&c, models[i].size[k]);
        vox_chunk(b, "SIZE", &c, 0);
        c.n = 0;
        put_le32(&c, (int64_t)models[i].n);
        put(&c, models[i].v, 4 * models[i].n);
        vox_chunk(b, "XYZI", &c, 0);
    }
    free(c.p);
}

/* Wraps CHILDREN in a MAIN chunk after the file header. */
static void vox_file(bytes *file, const bytes *children, int version) {
    put(file, "VOX ", 4);
    put_le32(file, version);
    put(file, "MAIN", 4);
    put_le32(file, 0);
    put_le32(file, (int64_t)children->n);
    put(file, children->p, children->n);
}

/* An nTRN node on LAYER, HIDDEN or not. */
static void vox_transform_on(bytes *b, int32_t id, int32_t child, const char *r, const char *t, int32_t layer,
                             int hidden) {
    bytes c = {NULL, 0, 0};
    put_le32(&c, id);
    vox_dict(&c, 2, "_name", "node", "_hidden", hidden ? "1" : "0");
    put_le32(&c, child);
    put_le32(&c, -1);
    put_le32(&c, layer);
    put_le32(&c, 1);
    if (r && t) vox_dict(&c, 2, "_r", r, "_t", t);
    else if (t) vox_dict(&c, 1, "_t", t);
    else vox_dict(&c, 0);
    vox_chunk(b, "nTRN", &c, 0);
    free(c.p);
}

static void vox_transform(bytes *b, int32_t id, int32_t child, const char *r, const char *t) {
    vox_transform_on(b, id, child, r, t, 0, 0);
}

static void vox_layer(bytes *b, int32_t id, int hidden) {
    bytes c = {NULL, 0, 0};
    put_le32(&c, id);
    vox_dict(&c, 1, "_hidden", hidden ? "1" : "0");
    put_le32(&c, -1);
    vox_chunk(b, "LAYR", &c, 0);
    free(c.p);
}

static void vox_group(bytes *b, int32_t id, const int32_t *children, size_t n) {
    bytes c = {NULL, 0, 0};
    size_t i;
    put_le32(&c, id);
    vox_dict(&c, 0);
    put_le32(&c, (int64_t)n);
    for (i = 0; i < n; i++) put_le32(&c, children[i]);
    vox_chunk(b, "nGRP", &c, 0);
    free(c.p);
}

static void vox_shape(bytes *b, int32_t id, int32_t model) {
    bytes c = {NULL, 0, 0};
    put_le32(&c, id);
    vox_dict(&c, 0);
    put_le32(&c, 1);
    put_le32(&c, model);
    vox_dict(&c, 1, "_f", "0");
    vox_chunk(b, "nSHP", &c, 0);
    free(c.p);
}

/* Voxels as (x, y, z, r, g, b) rows, sorted, so sets can be compared. */
typedef struct voxel {
    int64_t p[3];
    uint8_t rgb[3];
} voxel;

static int voxel_order(const void *a, const void *b) {
    const voxel *x = (const voxel *)a, *y = (const voxel *)b;
    int i;
    for (i = 0; i < 3; i++)
        if (x->p[i] != y->p[i]) return x->p[i] < y->p[i] ? -1 : 1;
    return memcmp(x->rgb, y->rgb, 3);
}

/* Puts WANT (MagicaVoxel world coordinates, z up) into the importer's frame:
   the same axes, shifted so each axis starts at 0; then compares it with the
   scene's voxels. */
static void check_voxels(const vdag_scene *s, voxel *want, size_t n) {
    voxel *got;
    int64_t lo[3];
    size_t i, a;
    CHECK(s->points_are_voxels == 1 && s->point_rgb != NULL && s->triangle_count == 0);
    CHECK_MSG(s->point_count == n, "%zu voxels, expected %zu", s->point_count, n);
    if (s->point_count != n || !n) return;
    for (i = 0; i < n; i++) {
        for (a = 0; a < 3; a++)
            if (!i || want[i].p[a] < lo[a]) lo[a] = want[i].p[a];
    }
    got = (voxel *)calloc(n, sizeof *got);
    for (i = 0; i < n; i++) {
        for (a = 0; a < 3; a++) {
            want[i].p[a] -= lo[a];
            got[i].p[a] = (int64_t)s->points[3 * i + a];
            CHECK(s->points[3 * i + a] == (double)got[i].p[a]);
        }
        memcpy(got[i].rgb, &s->point_rgb[3 * i], 3);
    }
    qsort(want, n, sizeof *want, voxel_order);
    qsort(got, n, sizeof *got, voxel_order);
    for (i = 0; i < n; i++) CHECK(!voxel_order(&want[i], &got[i]));
    free(got);
}

/* Two models, no scene graph: voxels keep their model coordinates. */
/* Two models and no scene graph (animation frames): the first is imported,
   with a warning naming the count; vox_model picks the other; a number past
   the last is an error naming the count; a file with a scene graph refuses
   any but 0. */
static void test_vox_models(void) {
    uint64_t seed = 8;
    vox_model m[2];
    uint8_t palette[1024];
    voxel want[80];
    bytes body = {NULL, 0, 0}, file = {NULL, 0, 0}, c = {NULL, 0, 0};
    vdag_scene s;
    vdag_import_limits pick;
    char err[256], warn[512];
    size_t i, k, n;
    for (i = 0; i < sizeof palette; i++) palette[i] = (uint8_t)test_rand_below(&seed, 256);
    put_le32(&c, 2);
    vox_chunk(&body, "PACK", &c, 0);
    random_model(&m[0], &seed);
    random_model(&m[1], &seed);
    m[1].v[0][3] = 0; /* colour index 0: no voxel */
    vox_models(&body, m, 2);
    c.n = 0;
    put(&c, palette, sizeof palette);
    vox_chunk(&body, "RGBA", &c, 0);
    vox_file(&file, &body, 150);
    memset(&pick, 0, sizeof pick);
    pick.quiet = 1;
    for (i = 0; i < 2; i++) {
        for (n = k = 0; k < m[i].n; k++) {
            if (!m[i].v[k][3]) continue;
            want[n].p[0] = m[i].v[k][0];
            want[n].p[1] = m[i].v[k][1];
            want[n].p[2] = m[i].v[k][2];
            memcpy(want[n].rgb, &palette[4 * (m[i].v[k][3] - 1)], 3); /* index i is entry i - 1 */
            n++;
        }
        if (i == 0 && !import_warnings("vox", &file, &s, err, sizeof err, warn, sizeof warn)) {
            CHECK_MSG(0, "%s", err);
            continue;
        }
        pick.vox_model = (uint32_t)i;
        if (i == 1 && !vdag_import_memory("vox", file.p, file.n, NULL, &pick, &s, err, sizeof err)) {
            CHECK_MSG(0, "model 1: %s", err);
            continue;
        }
        if (i == 0)
            CHECK_MSG(strstr(warn, "warning: vox: 2 models and no scene graph (animation frames?): model 0 imported; "
                                   "--vox-model N (0..1) picks another") != NULL,
                      "warned \"%s\"", warn);
        check_voxels(&s, want, n);
        vdag_scene_free(&s);
    }
    pick.vox_model = 2;
    CHECK(!vdag_import_memory("vox", file.p, file.n, NULL, &pick, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "model 2 asked for, but the file holds 2 models (numbered from 0)") != NULL, "%s", err);
    CHECK(!s.points && !s.point_count);
    sweep("vox", &file, 1);
    /* One model: no warning; model 1 of it is an error. */
    body.n = file.n = 0;
    vox_models(&body, m, 1);
    vox_file(&file, &body, 150);
    if (!import_warnings("vox", &file, &s, err, sizeof err, warn, sizeof warn)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK_MSG(!warn[0], "warned \"%s\"", warn);
        CHECK(s.point_count == m[0].n);
        vdag_scene_free(&s);
    }
    pick.vox_model = 1;
    CHECK(!vdag_import_memory("vox", file.p, file.n, NULL, &pick, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "the file holds 1 model (numbered from 0)") != NULL, "%s", err);
    /* A scene graph places the models: picking one is refused. */
    body.n = file.n = 0;
    vox_models(&body, m, 2);
    vox_transform(&body, 0, 1, NULL, NULL);
    vox_shape(&body, 1, 1);
    vox_file(&file, &body, 150);
    pick.vox_model = 0;
    if (!vdag_import_memory("vox", file.p, file.n, NULL, &pick, &s, err, sizeof err)) CHECK_MSG(0, "%s", err);
    else vdag_scene_free(&s);
    pick.vox_model = 1;
    CHECK(!vdag_import_memory("vox", file.p, file.n, NULL, &pick, &s, err, sizeof err));
    CHECK_MSG(strstr(err, "the file has a scene graph") != NULL, "%s", err);
    free(body.p);
    free(file.p);
    free(c.p);
}

/* Without an RGBA chunk, colours come from MagicaVoxel's default palette;
   the expected values are entries of its published table. */
static void test_vox_default_palette(void) {
    static const struct {
        uint8_t index, rgb[3];
    } table[] = {
        {1, {0xff, 0xff, 0xff}},   {2, {0xff, 0xff, 0xcc}},   {7, {0xff, 0xcc, 0xff}},   {37, {0xcc, 0xff, 0xff}},
        {215, {0x00, 0x00, 0x33}}, {216, {0xee, 0x00, 0x00}}, {225, {0x11, 0x00, 0x00}}, {226, {0x00, 0xee, 0x00}},
        {236, {0x00, 0x00, 0xee}}, {246, {0xee, 0xee, 0xee}}, {255, {0x11, 0x11, 0x11}},
    };
    const size_t n = sizeof table / sizeof table[0];
    vox_model m;
    voxel want[16];
    bytes body = {NULL, 0, 0}, file = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    size_t i;
    m.size[0] = (uint32_t)n;
    m.size[1] = m.size[2] = 1;
    m.n = n;
    for (i = 0; i < n; i++) {
        m.v[i][0] = (uint8_t)i;
        m.v[i][1] = m.v[i][2] = 0;
        m.v[i][3] = table[i].index;
        want[i].p[0] = (int64_t)i;
        want[i].p[1] = want[i].p[2] = 0;
        memcpy(want[i].rgb, table[i].rgb, 3);
    }
    vox_models(&body, &m, 1);
    vox_file(&file, &body, 150);
    if (!import("vox", &file, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        check_voxels(&s, want, n);
        vdag_scene_free(&s);
    }
    free(body.p);
    free(file.p);
}

/* An RGBA chunk shorter than 1024 bytes (1020, as some tools write, or
   fewer) gives its whole entries; the missing ones are the default
   palette's (the same table as above). */
static void test_vox_short_palette(void) {
    static const size_t lengths[] = {1020, 8, 6, 0};
    size_t li;
    for (li = 0; li < sizeof lengths / sizeof lengths[0]; li++) {
        vox_model m;
        voxel want[3];
        bytes body = {NULL, 0, 0}, file = {NULL, 0, 0}, c = {NULL, 0, 0};
        vdag_import_limits quiet;
        vdag_scene s;
        char err[256];
        size_t i;
        static const uint8_t colour_index[3] = {1, 2, 255};
        static const uint8_t defaults[3][3] = {{0xff, 0xff, 0xff}, {0xff, 0xff, 0xcc}, {0x11, 0x11, 0x11}};
        memset(&quiet, 0, sizeof quiet);
        quiet.quiet = 1;
        m.size[0] = 3;
        m.size[1] = m.size[2] = 1;
        m.n = 3;
        for (i = 0; i < lengths[li]; i++) {
            uint8_t byte = (uint8_t)(i * 7 + 1);
            put(&c, &byte, 1);
        }
        for (i = 0; i < 3; i++) {
            size_t entry = (size_t)colour_index[i] - 1;
            m.v[i][0] = (uint8_t)i;
            m.v[i][1] = m.v[i][2] = 0;
            m.v[i][3] = colour_index[i];
            want[i].p[0] = (int64_t)i;
            want[i].p[1] = want[i].p[2] = 0;
            if (4 * entry + 4 <= lengths[li]) {
                size_t k;
                for (k = 0; k < 3; k++) want[i].rgb[k] = (uint8_t)((4 * entry + k) * 7 + 1);
            } else {
                memcpy(want[i].rgb, defaults[i], 3);
            }
        }
        vox_models(&body, &m, 1);
        vox_chunk(&body, "RGBA", &c, 0);
        vox_file(&file, &body, 150);
        if (!vdag_import_memory("vox", file.p, file.n, NULL, &quiet, &s, err, sizeof err)) {
            CHECK_MSG(0, "%zu-byte palette: %s", lengths[li], err);
        } else {
            check_voxels(&s, want, 3);
            vdag_scene_free(&s);
        }
        free(body.p);
        free(file.p);
        free(c.p);
    }
}

/* A rotation byte: rows 0 and 1 take their non-zero entry from columns C0
   and C1, row 2 from the third; SIGNS bits 0-2 negate rows 0-2. */
static int rotation_byte(int c0, int c1, int signs) { return c0 | c1 << 2 | signs << 4; }

/* Scene graph: root transform -> group -> three transforms -> shapes, one
   model shown twice, and two more left out: a hidden node and a node on a
   hidden layer; plus chunks the importer does not use. The expected voxel
   is floor(R_root (R (v + 1/2 - size/2) + t) + t_root), in doubles. */
static void test_vox_scene_graph(void) {
    uint64_t seed = 9;
    int round;
    for (round = 0; round < 20; round++) {
        vox_model m[2];
        int rot[4][3][3], perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
        int64_t t[4][3];
        char rs[4][8], ts[4][64];
        const int32_t group_children[5] = {2, 4, 6, 8, 10};
        const int shown[3] = {0, 1, 0};
        voxel want[120];
        bytes body = {NULL, 0, 0}, file = {NULL, 0, 0}, c = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        size_t i, k, n = 0;
        int j, a, b;
        random_model(&m[0], &seed);
        random_model(&m[1], &seed);
        for (j = 0; j < 4; j++) {
            const int *p = perm[test_rand_below(&seed, 6)];
            int signs = (int)test_rand_below(&seed, 8);
            memset(rot[j], 0, sizeof rot[j]);
            for (a = 0; a < 3; a++) rot[j][a][p[a]] = signs >> a & 1 ? -1 : 1;
            snprintf(rs[j], sizeof rs[j], "%d", rotation_byte(p[0], p[1], signs));
            for (a = 0; a < 3; a++) t[j][a] = (int64_t)test_rand_below(&seed, 200) - 100;
            snprintf(ts[j], sizeof ts[j], "%ld %ld %ld", (long)t[j][0], (long)t[j][1], (long)t[j][2]);
        }
        vox_models(&body, m, 2);
        c.n = 0;
        putf(&c, "anything");
        vox_chunk(&body, "NOTE", &c, 0);
        vox_transform(&body, 0, 1, rs[3], ts[3]);
        vox_group(&body, 1, group_children, 5);
        for (j = 0; j < 3; j++) {
            vox_transform(&body, 2 + 2 * j, 3 + 2 * j, rs[j], ts[j]);
            vox_shape(&body, 3 + 2 * j, shown[j]);
        }
        vox_transform_on(&body, 8, 9, NULL, NULL, 0, 1);
        vox_shape(&body, 9, 1);
        vox_transform_on(&body, 10, 11, NULL, NULL, 7, 0);
        vox_shape(&body, 11, 0);
        vox_layer(&body, 0, 0);
        vox_layer(&body, 7, 1);
        c.n = 0;
        putf(&c, "unknown chunk with children");
        vox_chunk(&body, "ZZZZ", &c, 12);
        c.n = 0;
        vox_chunk(&body, "ZZZY", &c, 0); /* its child */
        vox_file(&file, &body, 200);
        for (j = 0; j < 3; j++) {
            const vox_model *model = &m[shown[j]];
            for (k = 0; k < model->n; k++) {
                double local[3], mid[3], world;
                for (a = 0; a < 3; a++) local[a] = model->v[k][a] + 0.5 - model->size[a] / 2.0;
                for (a = 0; a < 3; a++) {
                    mid[a] = (double)t[j][a];
                    for (b = 0; b < 3; b++) mid[a] += rot[j][a][b] * local[b];
                }
                for (a = 0; a < 3; a++) {
                    world = (double)t[3][a];
                    for (b = 0; b < 3; b++) world += rot[3][a][b] * mid[b];
                    want[n].p[a] = (int64_t)floor(world);
                }
                for (a = 0; a < 3; a++) want[n].rgb[a] = 0; /* colours are not compared here */
                n++;
            }
        }
        if (!import("vox", &file, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            for (i = 0; i < s.point_count; i++) s.point_rgb[3 * i] = s.point_rgb[3 * i + 1] = s.point_rgb[3 * i + 2] = 0;
            check_voxels(&s, want, n);
            vdag_scene_free(&s);
        }
        if (round == 0) sweep("vox", &file, 1);
        free(body.p);
        free(file.p);
        free(c.p);
    }
}

/* A one-voxel model followed by scene graph chunks written by FILL. */
static void vox_error(void (*fill)(bytes *), const char *want) {
    vox_model m = {{2, 2, 2}, 1, {{1, 1, 1, 5}}};
    bytes body = {NULL, 0, 0}, file = {NULL, 0, 0};
    vox_models(&body, &m, 1);
    fill(&body);
    vox_file(&file, &body, 200);
    expect_error("vox", &file, want);
    free(body.p);
    free(file.p);
}

static void graph_missing_node(bytes *b) { vox_transform(b, 0, 99, NULL, NULL); }
static void graph_missing_model(bytes *b) {
    vox_transform(b, 0, 1, NULL, NULL);
    vox_shape(b, 1, 1);
}
static void graph_cycle(bytes *b) {
    const int32_t back[1] = {0};
    vox_transform(b, 0, 1, NULL, "1 1 1");
    vox_group(b, 1, back, 1);
}
static void graph_duplicate(bytes *b) {
    vox_transform(b, 0, 1, NULL, NULL);
    vox_shape(b, 0, 0);
}
static void graph_bad_rotation(bytes *b) { vox_transform(b, 0, 1, "3", "0 0 0"); }
static void graph_same_columns(bytes *b) { vox_transform(b, 0, 1, "5", "0 0 0"); }
static void graph_bad_translation(bytes *b) { vox_transform(b, 0, 1, NULL, "1 2"); }
static void graph_huge_translation(bytes *b) { vox_transform(b, 0, 1, NULL, "0 0 4294967296"); }
/* Groups 1..40, each listing the next twice: 2^40 paths to one shape. */
static void graph_explosion(bytes *b) {
    int32_t i;
    vox_transform(b, 0, 1, NULL, NULL);
    for (i = 1; i <= 40; i++) {
        int32_t next[2];
        next[0] = next[1] = i + 1;
        vox_group(b, i, next, 2);
    }
    vox_shape(b, 41, 0);
}
/* A 2x2x2 model whose XYZI chunk declares COUNT voxels but holds one. */
static void vox_raw_model(bytes *b, int64_t count, const char *xyzi) {
    bytes c = {NULL, 0, 0};
    int i;
    for (i = 0; i < 3; i++) put_le32(&c, 2);
    vox_chunk(b, "SIZE", &c, 0);
    c.n = 0;
    put_le32(&c, count);
    put(&c, xyzi, 4);
    vox_chunk(b, "XYZI", &c, 0);
    free(c.p);
}
static void graph_outside(bytes *b) { vox_raw_model(b, 1, "\x01\x02\x01\x07"); }
static void graph_xyzi_short(bytes *b) { vox_raw_model(b, 1000000000, "\x01\x01\x01\x07"); }
static void graph_xyzi_only(bytes *b) {
    bytes c = {NULL, 0, 0};
    put_le32(&c, 0);
    vox_chunk(b, "XYZI", &c, 0);
    free(c.p);
}
static void graph_bad_layer(bytes *b) {
    bytes c = {NULL, 0, 0};
    put(&c, "\0\0", 2);
    vox_chunk(b, "LAYR", &c, 0);
    free(c.p);
}
static void graph_chunk_overrun(bytes *b) {
    put(b, "nTRN", 4);
    put_le32(b, 1000);
    put_le32(b, 0);
}

static void test_vox_errors(void) {
    bytes b = {NULL, 0, 0};
    expect_error_text("vox", "VOX", "not a MagicaVoxel file");
    expect_error_text("vox", "RIFF\x96\0\0\0MAIN", "not a MagicaVoxel file");
    expect_error_text("vox", "VOX \x96\0\0\0MIAN\0\0\0\0\0\0\0\0", "no MAIN chunk");
    put(&b, "VOX \x96\0\0\0MAIN\0\0\0\0\xff\xff\xff\xff", 20);
    expect_error("vox", &b, "MAIN chunk runs past the end");
    vox_error(graph_missing_node, "missing node 99");
    vox_error(graph_missing_model, "shows missing model 1");
    vox_error(graph_cycle, "cycle");
    vox_error(graph_duplicate, "two scene graph nodes have the id 0");
    vox_error(graph_bad_rotation, "malformed nTRN chunk");
    vox_error(graph_same_columns, "malformed nTRN chunk");
    vox_error(graph_bad_translation, "malformed nTRN chunk");
    vox_error(graph_huge_translation, "malformed nTRN chunk");
    vox_error(graph_explosion, "scene graph expands to more than");
    vox_error(graph_outside, "outside its model's size");
    vox_error(graph_xyzi_only, "XYZI chunk without a SIZE chunk");
    vox_error(graph_xyzi_short, "fewer voxels than it declares");
    vox_error(graph_chunk_overrun, "chunk runs past the end of MAIN");
    vox_error(graph_bad_layer, "malformed LAYR chunk");
    free(b.p);
}


/* A scene graph that places a model many times is refused at
   max_vox_voxels before any voxel is placed: at the default budget (2^31)
   a model of 65536 empty voxels shown 2^16 times (2^32 voxels to walk),
   and a small budget on 64 copies of a 2x2x2 cube (512 voxels). */
static void test_vox_voxel_budget(void) {
    bytes body = {NULL, 0, 0}, file = {NULL, 0, 0}, c = {NULL, 0, 0};
    vox_model cube = {{2, 2, 2}, 8, {{0}}};
    int32_t children[64];
    vdag_import_limits lim;
    vdag_scene s;
    char err[256];
    int32_t i;
    int k;
    for (i = 0; i < 3; i++) put_le32(&c, i < 2 ? 256 : 1);
    vox_chunk(&body, "SIZE", &c, 0);
    c.n = 0;
    put_le32(&c, 65536);
    for (i = 0; i < 65536; i++) {
        uint8_t v[4] = {(uint8_t)i, (uint8_t)(i >> 8), 0, 0}; /* colour index 0: empty */
        put(&c, v, 4);
    }
    vox_chunk(&body, "XYZI", &c, 0);
    vox_transform(&body, 0, 1, NULL, NULL);
    for (i = 1; i <= 16; i++) {
        int32_t next[2];
        next[0] = next[1] = i + 1;
        vox_group(&body, i, next, 2);
    }
    vox_shape(&body, 17, 0);
    vox_file(&file, &body, 200);
    expect_error("vox", &file, "max_vox_voxels (2147483648)");

    body.n = file.n = 0;
    for (i = 0; i < 8; i++) {
        cube.v[i][0] = (uint8_t)(i & 1);
        cube.v[i][1] = (uint8_t)(i >> 1 & 1);
        cube.v[i][2] = (uint8_t)(i >> 2 & 1);
        cube.v[i][3] = 7;
    }
    vox_models(&body, &cube, 1);
    vox_transform(&body, 0, 1, NULL, NULL);
    for (i = 0; i < 64; i++) children[i] = 2;
    vox_group(&body, 1, children, 64);
    vox_transform(&body, 2, 3, NULL, NULL);
    vox_shape(&body, 3, 0);
    vox_file(&file, &body, 200);
    for (k = 0; k < 2; k++) {
        memset(&lim, 0, sizeof lim);
        lim.max_vox_voxels = 512 - (uint64_t)k;
        if (vdag_import_memory("vox", file.p, file.n, NULL, &lim, &s, err, sizeof err)) {
            CHECK(!k && s.point_count == 512);
            vdag_scene_free(&s);
        } else {
            CHECK_MSG(k && strstr(err, "max_vox_voxels (511)") && strstr(err, "--max-vox-voxels"), "%s", err);
        }
    }
    free(body.p);
    free(file.p);
    free(c.p);
}

/* Integers past the parser's range are refused, never wrapped at 2^64:
   2^64 + 1 would read as 1 and 2^64 as 0. */
static void test_integer_overflow(void) {
    static const char *const big[] = {"18446744073709551617", "18446744073709551616", "-18446744073709551617",
                                      "99999999999999999999", "4611686018427387905"};
    bytes body = {NULL, 0, 0}, file = {NULL, 0, 0};
    vox_model m = {{2, 2, 2}, 1, {{1, 1, 1, 5}}};
    char text[512];
    size_t i;
    for (i = 0; i < sizeof big / sizeof big[0]; i++) {
        snprintf(text, sizeof text, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf %s 2 3\n", big[i]);
        expect_error_text("obj", text, "bad face corner");
        snprintf(text, sizeof text, "ply\nformat ascii 1.0\nelement vertex %s\nproperty float x\n"
                                    "property float y\nproperty float z\nend_header\n0 0 0\n", big[i]);
        expect_error_text("ply", text, "expected \"element NAME COUNT\"");
        snprintf(text, sizeof text, "OFF\n%s 0 0\n0 0 0\n", big[i]);
        expect_error_text("off", text, "expected vertex and face counts");
        snprintf(text, sizeof text, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n%s 0 1 2\n", big[i]);
        expect_error_text("off", text, "bad corner count");
        snprintf(text, sizeof text, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 %s 1 2\n", big[i]);
        expect_error_text("off", text, "out-of-range vertex index");
        snprintf(text, sizeof text, "0 0 %s", big[i]);
        body.n = file.n = 0;
        vox_models(&body, &m, 1);
        vox_transform(&body, 0, 1, NULL, text);
        vox_shape(&body, 1, 0);
        vox_file(&file, &body, 200);
        expect_error("vox", &file, "malformed nTRN chunk");
    }
    free(body.p);
    free(file.p);
}

const test_case test_import_cases[] = {
    {"import/xyz roundtrip", test_xyz_roundtrip},
    {"import/xyz errors", test_xyz_errors},
    {"import/xyz point cloud", test_xyz_points},
    {"import/ply unknown header line", test_ply_unknown_header_line},
    {"import/stl roundtrip", test_stl_roundtrip},
    {"import/stl errors", test_stl_errors},
    {"import/text with a BOM, UTF-16 refused", test_text_bom},
    {"import/vox short palette", test_vox_short_palette},
    {"import/ply roundtrip", test_ply_roundtrip},
    {"import/ply points", test_ply_points},
    {"import/ply sweep", test_ply_sweep},
    {"import/ply errors", test_ply_errors},
    {"import/off roundtrip", test_off_roundtrip},
    {"import/off points and sweep", test_off_points_and_sweep},
    {"import/off errors", test_off_errors},
    {"import/obj roundtrip", test_obj_roundtrip},
    {"import/obj points", test_obj_points},
    {"import/obj errors", test_obj_errors},
    {"import/polygons: concave ones as they are", test_concave_polygons},
    {"import/polygons: convex ones fanned", test_convex_polygons_fanned},
    {"import/polygons: bad ones fanned with a warning", test_bad_polygons_warn},
    {"import/obj file with mtl and texture", test_obj_file},
    {"import/file errors", test_file_errors},
    {"import/limits", test_limits},
    {"import/vox models: one of several frames, picked", test_vox_models},
    {"import/vox default palette", test_vox_default_palette},
    {"import/vox scene graph", test_vox_scene_graph},
    {"import/vox errors", test_vox_errors},
    {"import/integers out of range refused", test_integer_overflow},
    {"import/obj: an undefined usemtl warns once per file", test_obj_undefined_material},
    {"import/side files: regular files only", test_side_files},
    {"import/textures by file identity, pixel budget", test_texture_budget},
    {"import/vox voxel budget", test_vox_voxel_budget},
    {NULL, NULL},
};
