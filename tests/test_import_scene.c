/* Game-scene importer tests (.spm, .ac): files written here from random
   scenes round-trip to the scene the test expects (axes turned to z up,
   AC3D transforms applied, polygons triangulated), textures are found where
   the formats put them, and broken files (cut at every length, patched
   bytes, bad counts, indices out of range, NaN) fail with one-line messages. */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include "examples/import.h"

#include <math.h>
#include <stdarg.h>
#include <sys/stat.h>
#include <unistd.h>

#include "import_test.h"

// -- Helpers

static void put_f32(bytes *b, float f) {
    uint32_t u;
    memcpy(&u, &f, 4);
    put_uint(b, u, 4, 0);
}

/* Half-precision bits of V, a multiple of 1/256 with |V| < 64 (exact). */
static uint16_t half_of(double v) {
    uint16_t sign = v < 0 ? 0x8000 : 0;
    int e;
    double m;
    if (v == 0) return sign;
    m = frexp(fabs(v), &e); /* fabs(v) = m 2^e, m in [0.5, 1) */
    return (uint16_t)(sign | (uint16_t)((e + 14) << 10) | (uint16_t)((m * 2 - 1) * 1024));
}

static double rand_eighths(uint64_t *seed, int range) {
    return ((double)test_rand_below(seed, (uint32_t)(16 * range)) - 8.0 * range) / 8.0;
}

// -- .spm

enum { SPM_MAX_V = 300, SPM_MAX_T = 400 };

/* A random SPM scene and what importing it must give. Animated ("skinned")
   files add joints and weights to each vertex and armatures after the
   meshes; the import is their bind pose, the positions as stored. */
typedef struct spm_case {
    unsigned flags, nbuf, nmat;
    int skinned;
    unsigned narm, joints[3], keys[3]; /* armatures: joints and keyframes of each */
    unsigned vc[3], ic[3], mid[3];
    const char *tex1[3], *tex2[3];
    size_t nv, nt;
    double pos[3 * SPM_MAX_V][3];   /* expected, z up */
    float uv[3 * SPM_MAX_V][2];
    uint8_t rgb[3 * SPM_MAX_V][3];
    uint32_t tri[3 * SPM_MAX_T][3]; /* expected, global */
    int32_t tmat[3 * SPM_MAX_T];
} spm_case;

/* The armatures of T (after the meshes of an animated file): names, joint
   transforms, parents (-1 or a joint of the same armature), keyframes. */
static void write_spm_armatures(bytes *b, const spm_case *t, uint64_t *seed) {
    unsigned a, j, k, f;
    put_uint(b, t->narm, 1, 0);
    put_uint(b, 20, 2, 0);
    for (a = 0; a < t->narm; a++) {
        unsigned n = t->joints[a];
        put_uint(b, n - test_rand_below(seed, 2) * (n > 1), 2, 0); /* joints used <= n */
        put_uint(b, n, 2, 0);
        for (j = 0; j < n; j++) putf(b, "%cBone.%03u", 8, j);
        for (j = 0; j < 10 * n; j++) put_f32(b, (float)rand_eighths(seed, 4));
        for (j = 0; j < n; j++) put_uint(b, j == 0 ? 0xffff : test_rand_below(seed, n), 2, 0);
        put_uint(b, t->keys[a], 2, 0);
        for (k = 0; k < t->keys[a]; k++) {
            put_uint(b, 5 * k, 2, 0);
            for (f = 0; f < 10 * n; f++) put_f32(b, (float)rand_eighths(seed, 4));
        }
    }
}

static void write_spm(bytes *b, spm_case *t, uint64_t *seed) {
    unsigned i, k, buf, njoints = 0;
    for (i = 0; t->skinned && i < t->narm; i++) njoints += t->joints[i];
    put(b, "SP", 2);
    put_uint(b, 1 << 3 | (t->skinned ? 1 : 2), 1, 0);
    put_uint(b, t->flags, 1, 0);
    for (i = 0; i < 6; i++) put_f32(b, (float)i);
    put_uint(b, t->nmat, 2, 0);
    for (i = 0; i < t->nmat; i++) {
        put_uint(b, strlen(t->tex1[i]), 1, 0);
        put(b, t->tex1[i], strlen(t->tex1[i]));
        put_uint(b, strlen(t->tex2[i]), 1, 0);
        put(b, t->tex2[i], strlen(t->tex2[i]));
    }
    put_uint(b, 2, 2, 0); /* two meshes: buffer 0, then the rest */
    t->nv = t->nt = 0;
    for (buf = 0; buf < t->nbuf; buf++) {
        unsigned vc = t->vc[buf], tc = t->ic[buf] / 3, mid = t->mid[buf];
        int tex1 = t->tex1[mid][0] != 0, tex2 = tex1 && t->tex2[mid][0] != 0;
        size_t base = t->nv;
        if (buf < 2) put_uint(b, buf == 0 ? 1 : t->nbuf - 1, 2, 0);
        put_uint(b, vc, 4, 0);
        put_uint(b, 3 * tc, 4, 0);
        put_uint(b, mid, 2, 0);
        for (i = 0; i < vc; i++) {
            double *p = t->pos[t->nv], x = rand_eighths(seed, 100), y = rand_eighths(seed, 100),
                   z = rand_eighths(seed, 100);
            put_f32(b, (float)x);
            put_f32(b, (float)y);
            put_f32(b, (float)z);
            p[0] = x, p[1] = z, p[2] = y;
            if (t->flags & 1) put_uint(b, test_rand(seed), 4, 0);
            if (t->flags & 2) {
                if (test_rand_below(seed, 3) == 0) {
                    put_uint(b, 128, 1, 0);
                    memset(t->rgb[t->nv], 255, 3);
                } else {
                    put_uint(b, test_rand_below(seed, 2) ? 0 : 200, 1, 0);
                    for (k = 0; k < 3; k++) t->rgb[t->nv][k] = (uint8_t)test_rand_below(seed, 256);
                    put(b, t->rgb[t->nv], 3);
                }
            }
            t->uv[t->nv][0] = t->uv[t->nv][1] = 0;
            if (tex1) {
                for (k = 0; k < 2; k++) {
                    t->uv[t->nv][k] = (float)(((double)test_rand_below(seed, 4096) - 2048) / 256.0);
                    put_uint(b, half_of(t->uv[t->nv][k]), 2, 0);
                }
                if (tex2) put_uint(b, test_rand(seed), 4, 0);
                if (t->flags & 4) put_uint(b, test_rand(seed), 4, 0);
            }
            if (t->skinned) { /* joints -1 or any of all armatures, weights any halves */
                for (k = 0; k < 4; k++) put_uint(b, njoints ? test_rand_below(seed, njoints + 1) - 1 : 0xffff, 2, 0);
                for (k = 0; k < 4; k++) put_uint(b, test_rand(seed), 2, 0);
            }
            t->nv++;
        }
        for (i = 0; i < tc; i++) {
            for (k = 0; k < 3; k++) {
                uint32_t idx = test_rand_below(seed, vc);
                t->tri[t->nt][k] = (uint32_t)base + idx;
                put_uint(b, idx, vc > 255 ? 2 : 1, 0);
            }
            t->tmat[t->nt++] = (int32_t)mid;
        }
    }
    if (t->skinned) write_spm_armatures(b, t, seed);
}

static void random_spm(spm_case *t, uint64_t *seed) {
    static const char *const names[] = {"", "a.png", "b.jpg"};
    unsigned i;
    t->flags = test_rand_below(seed, 8);
    t->nmat = 1 + test_rand_below(seed, 3);
    for (i = 0; i < t->nmat; i++) {
        t->tex1[i] = names[test_rand_below(seed, 3)];
        t->tex2[i] = names[test_rand_below(seed, 3)];
    }
    t->nbuf = 2 + test_rand_below(seed, 2);
    for (i = 0; i < t->nbuf; i++) {
        t->vc[i] = 1 + test_rand_below(seed, i == 1 ? SPM_MAX_V : 20); /* buffer 1 may need u16 indices */
        t->ic[i] = 3 * test_rand_below(seed, i == 1 ? SPM_MAX_T : 8);
        t->mid[i] = test_rand_below(seed, t->nmat);
    }
    t->ic[0] = 3 * (1 + t->ic[0] / 3); /* at least one triangle */
    t->skinned = (int)test_rand_below(seed, 2);
    t->narm = t->skinned ? test_rand_below(seed, 4) : 0;
    for (i = 0; i < t->narm; i++) {
        t->joints[i] = 1 + test_rand_below(seed, 5);
        t->keys[i] = test_rand_below(seed, 4);
    }
}

static void check_spm(const vdag_scene *s, const spm_case *t) {
    size_t i;
    int any_tex = 0;
    for (i = 0; i < t->nmat; i++) any_tex |= t->tex1[i][0] != 0;
    CHECK(s->vertex_count == t->nv && s->triangle_count == t->nt && s->material_count == t->nmat);
    CHECK((s->uv != NULL) == any_tex && (s->vertex_rgb != NULL) == ((t->flags & 2) != 0));
    if (s->vertex_count != t->nv || s->triangle_count != t->nt) return;
    for (i = 0; i < t->nv; i++) {
        CHECK(s->positions[3 * i] == t->pos[i][0] && s->positions[3 * i + 1] == t->pos[i][1] &&
              s->positions[3 * i + 2] == t->pos[i][2]);
        if (s->uv) CHECK(s->uv[2 * i] == t->uv[i][0] && s->uv[2 * i + 1] == t->uv[i][1]);
        if (s->vertex_rgb) CHECK(!memcmp(s->vertex_rgb + 3 * i, t->rgb[i], 3));
    }
    for (i = 0; i < t->nt; i++) {
        CHECK(!memcmp(s->indices + 3 * i, t->tri[i], sizeof t->tri[i]));
        CHECK(s->triangle_material[i] == t->tmat[i]);
    }
    for (i = 0; i < t->nmat; i++)
        CHECK(s->materials[i].image == -1 && s->materials[i].rgb[0] == 255 && s->materials[i].rgb[2] == 255);
}

/* Random files, static and animated: animated ones import in their bind
   pose, the positions as stored (joints, weights and armatures unused). */
static void test_spm_roundtrip(void) {
    static spm_case t;
    uint64_t seed = 61;
    int round, animated = 0;
    for (round = 0; round < 40; round++) {
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        random_spm(&t, &seed);
        write_spm(&b, &t, &seed);
        animated += t.skinned;
        if (!import("spm", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "round %d: %s", round, err);
        } else {
            check_spm(&s, &t);
            vdag_scene_free(&s);
        }
        free(b.p);
    }
    CHECK(animated >= 10 && animated <= 30);
}

/* A small file with every optional field, cut and patched everywhere. */
static void test_spm_sweep(void) {
    static spm_case t;
    uint64_t seed = 7;
    bytes b = {NULL, 0, 0};
    memset(&t, 0, sizeof t);
    t.flags = 7;
    t.nmat = 2;
    t.tex1[0] = "t.png", t.tex2[0] = "u.png", t.tex1[1] = "", t.tex2[1] = "";
    t.nbuf = 2;
    t.vc[0] = 3, t.ic[0] = 3, t.mid[0] = 0;
    t.vc[1] = 4, t.ic[1] = 6, t.mid[1] = 1;
    write_spm(&b, &t, &seed);
    sweep("spm", &b, 1);
    free(b.p);
}

/* An animated ("skinned") file, as SuperTuxKart's karts are: two armatures
   with keyframes, cut and patched everywhere. */
static void test_spm_skinned_sweep(void) {
    static spm_case t;
    uint64_t seed = 9;
    bytes b = {NULL, 0, 0};
    memset(&t, 0, sizeof t);
    t.flags = 3;
    t.nmat = 1;
    t.tex1[0] = "t.png", t.tex2[0] = "";
    t.nbuf = 2;
    t.vc[0] = 3, t.ic[0] = 3, t.mid[0] = 0;
    t.vc[1] = 3, t.ic[1] = 3, t.mid[1] = 0;
    t.skinned = 1;
    t.narm = 2;
    t.joints[0] = 2, t.keys[0] = 1;
    t.joints[1] = 1, t.keys[1] = 0;
    write_spm(&b, &t, &seed);
    sweep("spm", &b, 1);
    free(b.p);
}

static void spm_header(bytes *b, unsigned kind, unsigned flags, const char *tex) {
    int i;
    put(b, "SP", 2);
    put_uint(b, 1 << 3 | kind, 1, 0);
    put_uint(b, flags, 1, 0);
    for (i = 0; i < 6; i++) put_f32(b, 0);
    put_uint(b, 1, 2, 0);
    put_uint(b, strlen(tex), 1, 0);
    put(b, tex, strlen(tex));
    put_uint(b, 0, 1, 0);
}

/* One mesh, one buffer: VC vertices at (I, 0, 0), then the indices. */
static void spm_buffer(bytes *b, uint32_t vc, uint32_t ic, unsigned mid, const uint32_t *idx, size_t n) {
    uint32_t i;
    put_uint(b, 1, 2, 0);
    put_uint(b, 1, 2, 0);
    put_uint(b, vc, 4, 0);
    put_uint(b, ic, 4, 0);
    put_uint(b, mid, 2, 0);
    for (i = 0; i < vc && i < 16; i++) {
        put_f32(b, (float)i);
        put_f32(b, 0);
        put_f32(b, 0);
    }
    for (i = 0; i < n; i++) put_uint(b, idx[i], 1, 0);
}

/* An animated file: one buffer of 3 vertices naming joint JOINT, then one
   armature of N joints used of USED, joint 1's parent PARENT (when N > 1),
   KEYS keyframes, and TAIL bytes of keyframes cut off (negative: extra
   bytes after the armature). */
static void spm_skinned(bytes *b, int joint, unsigned used, unsigned n, unsigned parent, unsigned keys, int tail) {
    static const uint32_t tri[3] = {0, 1, 2};
    size_t i;
    b->n = 0;
    spm_header(b, 1, 0, "");
    put_uint(b, 1, 2, 0);
    put_uint(b, 1, 2, 0);
    put_uint(b, 3, 4, 0);
    put_uint(b, 3, 4, 0);
    put_uint(b, 0, 2, 0);
    for (i = 0; i < 3; i++) {
        put_f32(b, (float)i), put_f32(b, 0), put_f32(b, 0);
        put_uint(b, (uint64_t)(int64_t)(i == 2 ? joint : 0), 2, 0);
        put_uint(b, 0xffff, 2, 0), put_uint(b, 0xffff, 2, 0), put_uint(b, 0xffff, 2, 0);
        put_uint(b, 0x3c00, 2, 0), put_uint(b, 0, 2, 0), put_uint(b, 0, 2, 0), put_uint(b, 0, 2, 0);
    }
    for (i = 0; i < 3; i++) put_uint(b, tri[i], 1, 0);
    put_uint(b, 1, 1, 0);
    put_uint(b, 0, 2, 0);
    put_uint(b, used, 2, 0);
    put_uint(b, n, 2, 0);
    for (i = 0; i < n; i++) putf(b, "%cj%u", 2, (unsigned)i % 10);
    for (i = 0; i < 10 * n; i++) put_f32(b, 0);
    for (i = 0; i < n; i++) put_uint(b, i == 1 ? parent : 0xffff, 2, 0);
    put_uint(b, keys, 2, 0);
    for (i = 0; i < keys * (2 + 40 * (size_t)n); i++) put_uint(b, 0, 1, 0);
    if (tail > 0) b->n -= (size_t)tail;
    for (; tail < 0; tail++) put_uint(b, 0, 1, 0);
}

static void test_spm_errors(void) {
    static const uint32_t tri[3] = {0, 1, 2}, bad[3] = {0, 1, 3};
    bytes b = {NULL, 0, 0};
    float nan_f = (float)NAN;
    uint32_t u;
    expect_error_text("spm", "", "no \"SP\" header");
    expect_error_text("spm", "PS\x0a\x03", "no \"SP\" header");
    spm_header(&b, 0, 0, "");
    expect_error("spm", &b, "unknown mesh kind 0 (known: 1, animated; 2, static)");
    b.n = 0;
    spm_header(&b, 3, 0, "");
    expect_error("spm", &b, "unknown mesh kind 3");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 3, 1, tri, 3);
    expect_error("spm", &b, "material 1 of 1");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 3, 0, bad, 3);
    expect_error("spm", &b, "index 3 of 3 vertices");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 2, 0, tri, 2);
    expect_error("spm", &b, "not whole triangles");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 0xffffffffu, 3, 0, tri, 3);
    expect_error("spm", &b, "need more bytes than remain");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 0x7ffffffeu, 0, tri, 3);
    expect_error("spm", &b, "need more bytes than remain");
    b.n = 0;
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 3, 0, tri, 3);
    put_uint(&b, 0, 1, 0);
    expect_error("spm", &b, "1 bytes after the last mesh");
    b.n = 0; /* NaN position: a coordinate of the second vertex */
    spm_header(&b, 2, 0, "");
    spm_buffer(&b, 3, 3, 0, tri, 3);
    memcpy(&u, &nan_f, 4);
    memcpy(b.p + 28 + 4 + 14 + 12 + 4, &u, 4); /* header, material, buffer, vertex 0, x */
    expect_error("spm", &b, "not a finite number");
    b.n = 0; /* an infinite half texture coordinate */
    spm_header(&b, 2, 0, "t.png");
    put_uint(&b, 1, 2, 0);
    put_uint(&b, 1, 2, 0);
    put_uint(&b, 3, 4, 0);
    put_uint(&b, 3, 4, 0);
    put_uint(&b, 0, 2, 0);
    for (u = 0; u < 3; u++) {
        put_f32(&b, (float)u), put_f32(&b, 0), put_f32(&b, 0);
        put_uint(&b, u == 2 ? 0x7c00 : 0, 2, 0);
        put_uint(&b, 0, 2, 0);
    }
    put(&b, "\0\1\2", 3);
    expect_error("spm", &b, "vertex 2: not a finite number");
    b.n = 0; /* a colour byte other than 128 without its RGB */
    spm_header(&b, 2, 2, "");
    put_uint(&b, 1, 2, 0);
    put_uint(&b, 1, 2, 0);
    put_uint(&b, 1, 4, 0);
    put_uint(&b, 0, 4, 0);
    put_uint(&b, 0, 2, 0);
    put_f32(&b, 0), put_f32(&b, 0), put_f32(&b, 0);
    put_uint(&b, 7, 1, 0);
    expect_error("spm", &b, "truncated");
    /* Animated files: the armatures are checked and must end the file. */
    spm_skinned(&b, 1, 2, 2, 0, 2, 0);
    {
        vdag_scene s;
        char err[256];
        if (!import("spm", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            CHECK(s.vertex_count == 3 && s.triangle_count == 1 && s.positions[3] == 1);
            vdag_scene_free(&s);
        }
    }
    spm_skinned(&b, 2, 2, 2, 0, 2, 0);
    expect_error("spm", &b, "a vertex names joint 2 of 2 (the joints of all armatures)");
    spm_skinned(&b, -2, 2, 2, 0, 2, 0);
    expect_error("spm", &b, "mesh 0 buffer 0 vertex 2: joint -2");
    spm_skinned(&b, 1, 3, 2, 0, 2, 0);
    expect_error("spm", &b, "armature 0: 3 joints used of 2");
    spm_skinned(&b, 1, 2, 2, 2, 2, 0);
    expect_error("spm", &b, "armature 0 joint 1: parent 2 of 2 joints");
    spm_skinned(&b, 1, 2, 2, 0, 2, 1);
    expect_error("spm", &b, "armature 0: 2 keyframes of 2 joints need more bytes than remain");
    spm_skinned(&b, 1, 2, 2, 0, 0, -10);
    b.p[b.n - 12] = b.p[b.n - 11] = 0xff; /* 65535 keyframes, 10 bytes of them */
    expect_error("spm", &b, "armature 0: 65535 keyframes of 2 joints need more bytes than remain");
    spm_skinned(&b, 1, 2, 2, 0, 0, -1);
    expect_error("spm", &b, "1 bytes after the last armature");
    spm_skinned(&b, 0, 1, 1, 0, 0, 0);
    b.n -= 2 + 2 + 40 + 3 + 2 + 2; /* keyframe count, parents, transforms, name, joint counts */
    expect_error("spm", &b, "armature 0: truncated joint count");
    b.n -= 3;
    expect_error("spm", &b, "truncated armature count");
    free(b.p);
}

// -- .ac

/* An AC3D scene: a world with two kids, the second placed by rot and loc
   with a kid of its own placed again (transforms compose). Expected
   positions are computed here from the same numbers. */
typedef struct ac_case {
    double v[3][8][3];   /* per object, local vertices */
    int rot[3][9], loc[3][3];
    uint32_t poly[3][2][5]; /* per object two polygons */
    size_t poly_n[3][2];
    int mat[3][2];
} ac_case;

static void ac_place(const ac_case *t, int obj, const double in[3], double out[3]) {
    /* Objects 0 and 1 are kids of the world, object 2 a kid of object 1. */
    double p[3], q[3];
    int k, j, o;
    memcpy(p, in, sizeof p);
    for (o = obj; o >= 1; o--) { /* object 2 is inside object 1 */
        for (k = 0; k < 3; k++) {
            q[k] = t->loc[o][k];
            for (j = 0; j < 3; j++) q[k] += t->rot[o][3 * k + j] * p[j];
        }
        memcpy(p, q, sizeof p);
    }
    out[0] = p[0];
    out[1] = -p[2];
    out[2] = p[1];
}

static void random_ac(ac_case *t, uint64_t *seed) {
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int o, i, k;
    for (o = 0; o < 3; o++) {
        const int *pm = perms[test_rand_below(seed, 6)];
        memset(t->rot[o], 0, sizeof t->rot[o]);
        for (k = 0; k < 3; k++) {
            t->rot[o][3 * k + pm[k]] = test_rand_below(seed, 2) ? 1 : -1;
            t->loc[o][k] = (int)test_rand_below(seed, 21) - 10;
        }
        for (i = 0; i < 8; i++)
            for (k = 0; k < 3; k++) t->v[o][i][k] = rand_eighths(seed, 10);
        for (i = 0; i < 2; i++) {
            t->poly_n[o][i] = 3 + test_rand_below(seed, 3);
            for (k = 0; k < (int)t->poly_n[o][i]; k++) t->poly[o][i][k] = test_rand_below(seed, 8);
            t->mat[o][i] = (int)test_rand_below(seed, 2);
        }
    }
}

static void write_ac_object(bytes *b, const ac_case *t, int o) {
    int i, k;
    putf(b, "OBJECT poly\nname \"part %d\"\ndata 12\nline1\n#line2\n\n", o);
    if (o > 0) {
        putf(b, "rot");
        for (k = 0; k < 9; k++) putf(b, " %d", t->rot[o][k]);
        putf(b, "\nloc %d %d %d\n", t->loc[o][0], t->loc[o][1], t->loc[o][2]);
    }
    putf(b, "crease 45.0\nnumvert 8\n");
    for (i = 0; i < 8; i++) putf(b, "%g %g %g\n", t->v[o][i][0], t->v[o][i][1], t->v[o][i][2]);
    putf(b, "numsurf 3\nSURF 0x22\nmat 0\nrefs 2\n0 0 0\n1 0 0\n");
    for (i = 0; i < 2; i++) {
        putf(b, "SURF 0x%d0\nmat %d\nrefs %zu\n", i + 1, t->mat[o][i], t->poly_n[o][i]);
        for (k = 0; k < (int)t->poly_n[o][i]; k++) putf(b, "%u 0.5 0.25\n", t->poly[o][i][k]);
    }
}

static void write_ac(bytes *b, const ac_case *t) {
    putf(b, "AC3Db\nMATERIAL \"red # one\" rgb 1 0 0  amb 0.2 0.2 0.2  emis 0 0 0  spec 0 0 0  shi 10  trans 0\n");
    putf(b, "MATERIAL \"\" rgb 0.2 0.4 1 amb 1 1 1 emis 0 0 0 spec 0 0 0 shi 0 trans 0\n");
    putf(b, "OBJECT world\nkids 2\n");
    write_ac_object(b, t, 0);
    putf(b, "kids 0\n");
    write_ac_object(b, t, 1);
    putf(b, "kids 1\n");
    write_ac_object(b, t, 2);
    putf(b, "kids 0\n");
}

static void test_ac_roundtrip(void) {
    ac_case t;
    uint64_t seed = 5;
    int round;
    for (round = 0; round < 30; round++) {
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256];
        size_t nv = 0, nt = 0, o, i, k;
        int first_mat = -1;
        random_ac(&t, &seed);
        write_ac(&b, &t);
        if (!import("ac", &b, &s, err, sizeof err)) {
            CHECK_MSG(0, "round %d: %s", round, err);
            free(b.p);
            continue;
        }
        CHECK(s.uv == NULL && s.image_count == 0);
        for (o = 0; o < 3; o++)
            for (i = 0; i < 2; i++) {
                size_t n = t.poly_n[o][i];
                int32_t want_mat;
                if (first_mat < 0) first_mat = t.mat[o][i];
                want_mat = t.mat[o][i] == first_mat ? 0 : 1; /* materials numbered by first use */
                for (k = 0; k < n && nv + k < s.vertex_count; k++) {
                    double want[3];
                    ac_place(&t, (int)o, t.v[o][t.poly[o][i][k]], want);
                    CHECK_MSG(s.positions[3 * (nv + k)] == want[0] && s.positions[3 * (nv + k) + 1] == want[1] &&
                                  s.positions[3 * (nv + k) + 2] == want[2],
                              "object %zu corner %zu", o, k);
                }
                for (k = 1; k + 1 < n && nt < s.triangle_count; k++, nt++) { /* corners of the polygon, in order */
                    const uint32_t *g = &s.indices[3 * nt];
                    size_t c0 = g[0] - nv, c1 = g[1] - nv, c2 = g[2] - nv;
                    CHECK(g[0] >= nv && g[1] >= nv && g[2] >= nv && c0 < n && c1 < n && c2 < n && c0 != c1 &&
                          c1 != c2 && c0 != c2 && (c1 + n - c0) % n + (c2 + n - c1) % n + (c0 + n - c2) % n == n);
                    CHECK(s.triangle_material[nt] == want_mat);
                }
                nv += n;
            }
        CHECK(s.vertex_count == nv && s.triangle_count == nt);
        CHECK(s.material_count >= 1 && s.material_count <= 2);
        for (i = 0; i < s.material_count; i++) {
            int m = (int)i == 0 ? first_mat : 1 - first_mat;
            static const uint8_t want[2][3] = {{255, 0, 0}, {51, 102, 255}};
            CHECK(!memcmp(s.materials[i].rgb, want[m], 3) && s.materials[i].image == -1);
        }
        vdag_scene_free(&s);
        free(b.p);
    }
}

static void test_ac_sweep(void) {
    ac_case t;
    uint64_t seed = 3;
    bytes b = {NULL, 0, 0};
    random_ac(&t, &seed);
    write_ac(&b, &t);
    sweep("ac", &b, 0);
    free(b.p);
}

/* "subdiv N" with N > 0 warns, once per file, that the objects are imported
   as their control meshes; subdiv 0 says nothing, and the mesh is the same. */
static void test_ac_subdiv_warns(void) {
    static const char *const subdiv[] = {"", "subdiv 0\n", "subdiv 2\n"};
    int k;
    for (k = 0; k < 3; k++) {
        bytes b = {NULL, 0, 0};
        vdag_scene s;
        char err[256], warn[512];
        int obj;
        putf(&b, "AC3Db\nMATERIAL \"m\" rgb 1 1 1\nOBJECT world\nkids 2\n");
        for (obj = 0; obj < 2; obj++)
            putf(&b, "OBJECT poly\n%snumvert 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\nnumsurf 1\nSURF 0x10\nmat 0\nrefs 4\n"
                     "0 0 0\n1 0 0\n2 0 0\n3 0 0\nkids 0\n",
                 subdiv[k]);
        if (!import_warnings("ac", &b, &s, err, sizeof err, warn, sizeof warn)) {
            CHECK_MSG(0, "%s", err);
        } else {
            const char *w = strstr(warn, "warning: ac: 2 objects have subdiv > 0 (the first on line 6): subdivision "
                                         "surfaces are imported unsubdivided, as their control mesh");
            CHECK(s.triangle_count == 4 && s.vertex_count == 8);
            if (k < 2) CHECK_MSG(!warn[0], "subdiv %d: warned \"%s\"", k, warn);
            else CHECK_MSG(w && !strstr(w + 1, "warning"), "warned \"%s\"", warn);
            vdag_scene_free(&s);
        }
        free(b.p);
    }
    expect_error_text("ac", "AC3Db\nOBJECT poly\nsubdiv x\nkids 0\n", "line 3: bad subdiv count");
}

static void test_ac_errors(void) {
    static const char obj[] = "AC3Db\nMATERIAL \"m\" rgb 1 1 1\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\n";
    char text[512];
    int i;
    bytes b = {NULL, 0, 0};
    expect_error_text("ac", "", "no \"AC3D\" header");
    expect_error_text("ac", "ply\n", "no \"AC3D\" header");
    expect_error_text("ac", "AC3Db\nMATERIAL \"m\"\n", "MATERIAL without rgb");
    expect_error_text("ac", "AC3Db\nfoo\n", "expected MATERIAL or OBJECT");
    expect_error_text("ac", "AC3Db\nOBJECT world\nname \"w\"\n", "without kids line");
    expect_error_text("ac", "AC3Db\nOBJECT world\nkids 2\nOBJECT poly\nkids 0\n", "missing kids");
    expect_error_text("ac", "AC3Db\nOBJECT world\nkids 1\nnumvert 1\n", "expected OBJECT");
    expect_error_text("ac", "AC3Db\nOBJECT world\nkids 99999999\n", "bad kids count");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nnumvert 4000000000\n0 0 0\n", "bad numvert count");
    /* Integers past 2^64 are refused, not wrapped (2^64 + 1 would read as 1). */
    expect_error_text("ac", "AC3Db\nOBJECT poly\nnumvert 18446744073709551617\n0 0 0\nkids 0\n", "bad numvert count");
    expect_error_text("ac", "AC3Db\nOBJECT world\nkids 18446744073709551617\nOBJECT poly\nkids 0\n", "bad kids count");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nnumvert 1\n0 nan 0\nkids 0\n", "a vertex needs 3 numbers");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nnumvert 1\n0 0\nkids 0\n", "a vertex needs 3 numbers");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nrot 1 0 0 0 1 0 0 0\n", "rot needs 9 numbers");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nloc 1 inf 0\n", "loc needs 3 numbers");
    expect_error_text("ac", "AC3Db\nOBJECT poly\nloc 1e30 0 0\nnumvert 1\n1e30 0 0\nkids 0\n", "out of range once placed");
    expect_error_text("ac", "AC3Db\nOBJECT poly\ndata 100\nabc\n", "bad data length");
    expect_error_text("ac", "AC3Db\nOBJECT poly\ntexture \"a.png\nkids 0\n", "unterminated texture name");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0x0\nmat 1\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", obj);
    expect_error_text("ac", text, "material out of range");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0x0\nmat 0\nrefs 3\n0 0 0\n1 0 0\n3 0 0\nkids 0\n", obj);
    expect_error_text("ac", text, "vertex index out of range");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0x0\nrefs 3\n0 0 0\n1 nan 0\n2 0 0\nkids 0\n", obj);
    expect_error_text("ac", text, "bad texture coordinates");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0xzz\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", obj);
    expect_error_text("ac", text, "bad SURF flags");
    snprintf(text, sizeof text, "%snumsurf 2\nSURF 0x0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", obj);
    expect_error_text("ac", text, "expected SURF flags");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0x0\nrefs 3\n0 0 0\n", obj);
    expect_error_text("ac", text, "truncated refs");
    snprintf(text, sizeof text, "%snumsurf 1\nSURF 0x0\nfoo\n", obj);
    expect_error_text("ac", text, "expected mat or refs");
    /* Nesting deeper than any real file: an error, not a stack overflow. */
    putf(&b, "AC3Db\n");
    for (i = 0; i < 300; i++) putf(&b, "OBJECT group\nkids 1\n");
    expect_error("ac", &b, "nested too deep");
    free(b.p);
}

// -- Files: texture look-up

static const uint8_t scene_pixels[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 9, 8, 7};

static int sfile(const char *path, const void *data, size_t n) {
    FILE *f = fopen(path, "wb");
    size_t got;
    if (!f) return 0;
    got = fwrite(data, 1, n, f);
    return fclose(f) == 0 && got == n;
}

static void ppm(const char *path, int variant) {
    bytes b = {NULL, 0, 0};
    putf(&b, "P6\n%d 2\n255\n", 2);
    put(&b, scene_pixels, sizeof scene_pixels);
    b.p[b.n - 1] = (uint8_t)variant;
    CHECK(sfile(path, b.p, b.n));
    free(b.p);
}

/* .spm textures: beside the file, in ../../textures, in ../../library/X;
   a missing one leaves the material white. .ac: beside the file, with
   texrep and texoff applied to the coordinates. */
static void test_scene_files(void) {
    char dir[] = "/tmp/vdag-scene-XXXXXX", p[32][320], err[512];
    static spm_case t;
    static const char *const made[] = {"tracks", "tracks/t", "textures", "library", "library/lib1"};
    uint64_t seed = 11;
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    vdag_image probe;
    int decodes, i, n = 0;
    CHECK(mkdtemp(dir) != NULL);
    for (i = 0; i < 5; i++) {
        snprintf(p[n], sizeof p[n], "%s/%s", dir, made[i]);
        CHECK(mkdir(p[n++], 0700) == 0);
    }
    snprintf(p[n], sizeof p[n], "%s/tracks/t/near.ppm", dir), ppm(p[n++], 1);
    snprintf(p[n], sizeof p[n], "%s/textures/shared.ppm", dir), ppm(p[n++], 2);
    snprintf(p[n], sizeof p[n], "%s/library/lib1/lib.ppm", dir), ppm(p[n++], 3);
    decodes = vdag_image_load(p[n - 1], &probe, err, sizeof err);
    vdag_image_free(&probe);

    memset(&t, 0, sizeof t);
    t.flags = 0;
    t.nmat = 3;
    t.tex1[0] = "lib.ppm", t.tex1[1] = "near.ppm", t.tex1[2] = "missing.ppm";
    t.tex2[0] = t.tex2[1] = t.tex2[2] = "";
    t.nbuf = 3;
    for (i = 0; i < 3; i++) t.vc[i] = 3, t.ic[i] = 3, t.mid[i] = (unsigned)i;
    write_spm(&b, &t, &seed);
    snprintf(p[n], sizeof p[n], "%s/tracks/t/track.spm", dir);
    CHECK(sfile(p[n], b.p, b.n));
    if (!vdag_import_file(p[n++], NULL, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.material_count == 3 && s.triangle_count == 3 && s.uv != NULL);
        CHECK(s.materials[2].image == -1);
        if (decodes) {
            CHECK(s.image_count == 2 && s.materials[0].image == 0 && s.materials[1].image == 1);
            CHECK(s.image_count == 2 && s.images[0].rgb[11] == 3 && s.images[1].rgb[11] == 1);
        } else {
            CHECK(s.image_count == 0 && s.materials[0].image == -1);
        }
        vdag_scene_free(&s);
    }
    b.n = 0;
    t.tex1[0] = "shared.ppm";
    write_spm(&b, &t, &seed);
    snprintf(p[n], sizeof p[n], "%s/tracks/t/track2.spm", dir);
    CHECK(sfile(p[n], b.p, b.n));
    if (!vdag_import_file(p[n++], NULL, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        if (decodes) CHECK(s.image_count == 2 && s.materials[0].image == 0 && s.images[0].rgb[11] == 2);
        vdag_scene_free(&s);
    }

    b.n = 0;
    putf(&b, "AC3Db\nMATERIAL \"m\" rgb 0 1 0\nOBJECT world\nkids 2\nOBJECT poly\ntexture \"near.ppm\"\n"
              "texture \"ignored.png\"\ntexrep 2 4\ntexoff 0.5 0.25\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\n"
              "numsurf 1\nSURF 0x10\nmat 0\nrefs 3\n0 0 0\n1 1 0\n2 0.5 1\nkids 0\n"
              "OBJECT poly\ntexture empty_texture_no_mapping\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\n"
              "numsurf 1\nSURF 0x10\nmat 0\nrefs 3\n0 0 0\n1 1 0\n2 0.5 1\nkids 0\n");
    snprintf(p[n], sizeof p[n], "%s/tracks/t/model.ac", dir);
    CHECK(sfile(p[n], b.p, b.n));
    if (!vdag_import_file(p[n++], NULL, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s", err);
    } else {
        CHECK(s.triangle_count == 2 && s.material_count == (decodes ? 2u : 1u));
        CHECK(s.materials[0].rgb[1] == 255 && s.materials[s.material_count - 1].image == -1);
        if (decodes) {
            CHECK(s.uv != NULL && s.image_count == 1 && s.materials[0].image == 0);
            CHECK(s.uv && s.uv[0] == 0.5f && s.uv[1] == 0.25f && s.uv[2] == 2.5f && s.uv[3] == 0.25f &&
                  s.uv[4] == 1.5f && s.uv[5] == 4.25f);
        } else {
            CHECK(s.uv == NULL && s.materials[0].image == -1);
        }
        vdag_scene_free(&s);
    }
    free(b.p);
    while (n-- > 0) remove(p[n]); /* files, then folders, deepest first */
    rmdir(dir);
}

/* SuperTuxKart's grass shader reads vertex colours as wind weights, never
   as colours: materials drawn with it (the materials.xml beside the file
   first, then ../../textures/materials.xml; comments skipped) get white
   vertices, the texture's own colours; others keep their tint. Foliage
   with wind weights of about 0.05 came out near-black before. */
static void test_spm_wind(void) {
    static const char *const tex[] = {"leaf.png", "bark.png", "shared.png", "over.png",
                                      "commented.png", "quoted.png", "", "leaf.png.bak"};
    static const int wind[] = {1, 0, 1, 0, 0, 1, 0, 0};
    enum { NMAT = sizeof wind / sizeof wind[0] };
    static const char beside[] =
        "<?xml version=\"1.0\"?>\n<materials>\n"
        "  <!-- <material name=\"commented.png\" shader=\"grass\"/> -->\n"
        "  <material name=\"leaf.png\" shader=\"grass\" ignore=\"Y\" grass-speed=\"1.50\"/>\n"
        "  <material name=\"bark.png\" normal-map=\"a>b.png\" shader=\"alphatest\"/>\n"
        "  <material name=\"over.png\" shader=\"alphatest\"/>\n"
        "  <material\n     shader = 'grass'\n     name='quoted.png' />\n"
        "  <material name=\"leaf.png\" shader=\"solid\"/>\n"
        "</materials>\n";
    static const char shared[] =
        "<materials>\n<material name=\"shared.png\" shader=\"grass\"/>\n"
        "<material name=\"over.png\" shader=\"grass\"/>\n<material name=\"leaf.png.bak\" shader=\"grass\"\n";
    static const char *const made[] = {"tracks", "tracks/t", "textures"};
    char dir[] = "/tmp/vdag-wind-XXXXXX", p[8][320], err[512];
    vdag_import_limits quiet;
    bytes b = {NULL, 0, 0};
    vdag_scene s;
    int i, k, pass, n = 0;
    memset(&quiet, 0, sizeof quiet);
    quiet.quiet = 1; /* the textures are missing: white, with warnings */
    CHECK(mkdtemp(dir) != NULL);
    for (i = 0; i < 3; i++) {
        snprintf(p[n], sizeof p[n], "%s/%s", dir, made[i]);
        CHECK(mkdir(p[n++], 0700) == 0);
    }
    snprintf(p[n], sizeof p[n], "%s/tracks/t/materials.xml", dir);
    CHECK(sfile(p[n++], beside, strlen(beside)));
    snprintf(p[n], sizeof p[n], "%s/textures/materials.xml", dir);
    CHECK(sfile(p[n++], shared, strlen(shared)));
    put(&b, "SP", 2);
    put_uint(&b, 1 << 3 | 2, 1, 0);
    put_uint(&b, 2, 1, 0); /* vertex colours */
    for (i = 0; i < 6; i++) put_f32(&b, 0);
    put_uint(&b, NMAT, 2, 0);
    for (i = 0; i < NMAT; i++) {
        put_uint(&b, strlen(tex[i]), 1, 0);
        put(&b, tex[i], strlen(tex[i]));
        put_uint(&b, 0, 1, 0);
    }
    put_uint(&b, 1, 2, 0);
    put_uint(&b, NMAT, 2, 0);
    for (i = 0; i < NMAT; i++) { /* one buffer per material: 3 vertices of colour (i, 10 + k, 50) */
        put_uint(&b, 3, 4, 0);
        put_uint(&b, 3, 4, 0);
        put_uint(&b, (uint64_t)i, 2, 0);
        for (k = 0; k < 3; k++) {
            put_f32(&b, (float)k), put_f32(&b, (float)i), put_f32(&b, 0);
            put_uint(&b, 0, 1, 0);
            put_uint(&b, (uint64_t)i, 1, 0), put_uint(&b, 10 + (uint64_t)k, 1, 0), put_uint(&b, 50, 1, 0);
            if (tex[i][0]) put_uint(&b, 0, 4, 0); /* texture coordinates */
        }
        put(&b, "\0\1\2", 3);
    }
    snprintf(p[n], sizeof p[n], "%s/tracks/t/track.spm", dir);
    CHECK(sfile(p[n++], b.p, b.n));
    for (pass = 0; pass < 2; pass++) { /* from the file; from memory (no look-up) */
        int ok = pass == 0 ? vdag_import_file(p[n - 1], &quiet, &s, err, sizeof err)
                           : vdag_import_memory("spm", b.p, b.n, NULL, &quiet, &s, err, sizeof err);
        if (!ok) {
            CHECK_MSG(0, "%s", err);
            continue;
        }
        CHECK(s.vertex_count == 3 * NMAT && s.vertex_rgb != NULL);
        for (i = 0; i < NMAT && s.vertex_rgb && s.vertex_count == 3 * NMAT; i++)
            for (k = 0; k < 3; k++) {
                const uint8_t *got = s.vertex_rgb + 3 * (3 * (size_t)i + (size_t)k);
                uint8_t want[3];
                want[0] = (uint8_t)i, want[1] = (uint8_t)(10 + k), want[2] = 50;
                if (pass == 0 && wind[i]) memset(want, 255, 3);
                CHECK_MSG(!memcmp(got, want, 3), "pass %d material %s vertex %d: %u %u %u", pass, tex[i], k,
                          got[0], got[1], got[2]);
            }
        vdag_scene_free(&s);
    }
    free(b.p);
    while (n-- > 0) remove(p[n]); /* files, then folders, deepest first */
    rmdir(dir);
}

const test_case test_import_scene_cases[] = {
    {"import_scene/spm roundtrip", test_spm_roundtrip},
    {"import_scene/spm sweep", test_spm_sweep},
    {"import_scene/spm skinned sweep", test_spm_skinned_sweep},
    {"import_scene/spm errors", test_spm_errors},
    {"import_scene/ac roundtrip", test_ac_roundtrip},
    {"import_scene/ac sweep", test_ac_sweep},
    {"import_scene/ac errors", test_ac_errors},
    {"import_scene/ac subdiv warns", test_ac_subdiv_warns},
    {"import_scene/texture files", test_scene_files},
    {"import_scene/spm grass shader colours", test_spm_wind},
    {NULL, NULL},
};
