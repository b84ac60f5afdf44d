/* Benchmark scenes shared by bench_build.c and bench_geometry.c: voxel lists
   (x, y, z as uint32) loaded from the fetched data (bench/fetch.sh) or
   generated, plus timing and small helpers. Include after voxdag.h.

   Scenes:
   - vox:  a MagicaVoxel file through the vdag importer, voxels as stored.
   - inr:  an INRIMAGE label volume (8-bit), voxels with label != 0 on the
           image's own index grid (no correction of the anisotropic spacing).
           At a finer level the solid is scaled by 2^k and only its shell is
           kept: a fine voxel is kept when it lies on a face of its coarse
           voxel whose 6-neighbour across that face is empty.
   - mesh: a triangle mesh through the vdag importer, scaled uniformly so its
           longest side spans the grid, voxelized by the library
           (voxdag_builder_add_mesh: a voxel is full when a triangle
           touches its closed box).
   - terrain: a generated heightfield (value noise, 4 octaves), each column
           filled from its lowest 4-neighbour height up to its own height, so
           the surface is closed. */
#ifndef BENCH_SCENES_H
#define BENCH_SCENES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "examples/import.h"

#if defined(__GNUC__) || defined(__clang__)
#define BENCH_UNUSED __attribute__((unused))
#else
#define BENCH_UNUSED
#endif

typedef struct bscene {
    char name[64];
    char input[192]; /* how the voxels were made */
    uint32_t levels;
    size_t n;
    uint32_t *xyz; /* 3 per voxel, distinct, Morton order */
} bscene;

BENCH_UNUSED static double bench_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

BENCH_UNUSED static void *bench_xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "bench: out of memory (%zu bytes)\n", n);
        exit(1);
    }
    return p;
}

BENCH_UNUSED static void bscene_free(bscene *s) {
    free(s->xyz);
    memset(s, 0, sizeof *s);
}

// -- Morton-code sets: sort + unique

BENCH_UNUSED static void bench_sort_codes(uint64_t *c, size_t n) { /* LSD radix, 8-bit digits */
    uint64_t *t = (uint64_t *)bench_xmalloc(n * sizeof *t), *a = c, *b = t, *x;
    uint64_t maxv = 0;
    unsigned shift;
    size_t i;
    for (i = 0; i < n; i++)
        if (c[i] > maxv) maxv = c[i];
    for (shift = 0; shift < 64 && (maxv >> shift); shift += 8) {
        size_t cnt[256] = {0}, sum = 0, k;
        for (i = 0; i < n; i++) cnt[(a[i] >> shift) & 255]++;
        for (k = 0; k < 256; k++) { size_t v = cnt[k]; cnt[k] = sum; sum += v; }
        for (i = 0; i < n; i++) b[cnt[(a[i] >> shift) & 255]++] = a[i];
        x = a; a = b; b = x;
    }
    if (a != c) memcpy(c, a, n * sizeof *c);
    free(t);
}

BENCH_UNUSED static size_t bench_unique(uint64_t *c, size_t n) {
    size_t i, w = 0;
    for (i = 0; i < n; i++)
        if (!w || c[w - 1] != c[i]) c[w++] = c[i];
    return w;
}

/* Fills S from N Morton codes (sorted and deduplicated here; freed). */
BENCH_UNUSED static void bscene_from_codes(bscene *s, uint64_t *c, size_t n) {
    size_t i;
    bench_sort_codes(c, n);
    n = bench_unique(c, n);
    s->n = n;
    s->xyz = (uint32_t *)bench_xmalloc(3 * n * sizeof *s->xyz);
    for (i = 0; i < n; i++) voxdag_morton_decode(c[i], &s->xyz[3 * i], &s->xyz[3 * i + 1], &s->xyz[3 * i + 2]);
    free(c);
}

// -- MagicaVoxel through the importer

BENCH_UNUSED static int bscene_vox(bscene *s, const char *path, const char *name) {
    vdag_scene sc;
    char err[256];
    uint32_t maxc = 0, L = 2;
    uint64_t *c;
    size_t i;
    memset(s, 0, sizeof *s);
    memset(&sc, 0, sizeof sc);
    if (!vdag_import_file(path, NULL, &sc, err, sizeof err)) {
        fprintf(stderr, "bench: %s: %s\n", path, err);
        return 0;
    }
    for (i = 0; i < 3 * sc.point_count; i++)
        if (sc.points[i] > maxc) maxc = (uint32_t)sc.points[i];
    while ((1u << L) <= maxc) L++;
    c = (uint64_t *)bench_xmalloc((sc.point_count ? sc.point_count : 1) * sizeof *c);
    for (i = 0; i < sc.point_count; i++)
        c[i] = voxdag_morton_encode((uint32_t)sc.points[3 * i], (uint32_t)sc.points[3 * i + 1],
                                    (uint32_t)sc.points[3 * i + 2]);
    s->levels = L;
    snprintf(s->name, sizeof s->name, "%s", name);
    snprintf(s->input, sizeof s->input, "%.100s: %zu voxels as stored", path, sc.point_count);
    bscene_from_codes(s, c, sc.point_count);
    vdag_scene_free(&sc);
    return 1;
}

// -- INRIMAGE label volume

typedef struct bench_grid {
    uint32_t dim[3];
    uint8_t *full; /* dim[0]*dim[1]*dim[2], x fastest */
} bench_grid;

BENCH_UNUSED static int bench_grid_at(const bench_grid *g, long x, long y, long z) {
    if (x < 0 || y < 0 || z < 0 || x >= (long)g->dim[0] || y >= (long)g->dim[1] || z >= (long)g->dim[2]) return 0;
    return g->full[((size_t)z * g->dim[1] + (size_t)y) * g->dim[0] + (size_t)x];
}

BENCH_UNUSED static int bench_read_inr(const char *path, bench_grid *g) {
    FILE *f = fopen(path, "rb");
    char head[257], *p;
    size_t n, i;
    int vdim = 1;
    memset(g, 0, sizeof *g);
    if (!f || fread(head, 1, 256, f) != 256) {
        fprintf(stderr, "bench: cannot read %s\n", path);
        if (f) fclose(f);
        return 0;
    }
    head[256] = 0;
    if (strncmp(head, "#INRIMAGE-4#{", 13) || !strstr(head, "##}") ||
        !(p = strstr(head, "XDIM=")) || sscanf(p, "XDIM=%u", &g->dim[0]) != 1 ||
        !(p = strstr(head, "YDIM=")) || sscanf(p, "YDIM=%u", &g->dim[1]) != 1 ||
        !(p = strstr(head, "ZDIM=")) || sscanf(p, "ZDIM=%u", &g->dim[2]) != 1 ||
        !strstr(head, "PIXSIZE=8 bits") || ((p = strstr(head, "VDIM=")) && sscanf(p, "VDIM=%d", &vdim) == 1 && vdim != 1) ||
        g->dim[0] - 1 >= 4096 || g->dim[1] - 1 >= 4096 || g->dim[2] - 1 >= 4096) {
        fprintf(stderr, "bench: %s: not an 8-bit INRIMAGE with a 256-byte header\n", path);
        fclose(f);
        return 0;
    }
    n = (size_t)g->dim[0] * g->dim[1] * g->dim[2];
    g->full = (uint8_t *)bench_xmalloc(n);
    if (fread(g->full, 1, n, f) != n) {
        fprintf(stderr, "bench: %s: truncated\n", path);
        fclose(f);
        free(g->full);
        return 0;
    }
    fclose(f);
    for (i = 0; i < n; i++) g->full[i] = g->full[i] != 0;
    return 1;
}

/* Voxels of G scaled by 2^K: all of them (K = 0), or the shell (K > 0). */
BENCH_UNUSED static void bscene_grid(bscene *s, const bench_grid *g, unsigned k, const char *name, const char *path) {
    uint32_t maxd = g->dim[0], L = 2, S = 1u << k;
    size_t cells = 0, cap = 0, n = 0;
    uint64_t *c = NULL;
    long x, y, z;
    memset(s, 0, sizeof *s);
    if (g->dim[1] > maxd) maxd = g->dim[1];
    if (g->dim[2] > maxd) maxd = g->dim[2];
    while ((1u << L) < (maxd << k)) L++;
    for (z = 0; z < (long)g->dim[2]; z++)
        for (y = 0; y < (long)g->dim[1]; y++)
            for (x = 0; x < (long)g->dim[0]; x++) {
                int open[6];
                uint32_t a, b, d;
                if (!bench_grid_at(g, x, y, z)) continue;
                cells++;
                if (!k) {
                    if (n == cap) { cap = cap ? 2 * cap : 1 << 20; c = (uint64_t *)realloc(c, cap * sizeof *c); if (!c) exit(1); }
                    c[n++] = voxdag_morton_encode((uint32_t)x, (uint32_t)y, (uint32_t)z);
                    continue;
                }
                open[0] = !bench_grid_at(g, x - 1, y, z); open[1] = !bench_grid_at(g, x + 1, y, z);
                open[2] = !bench_grid_at(g, x, y - 1, z); open[3] = !bench_grid_at(g, x, y + 1, z);
                open[4] = !bench_grid_at(g, x, y, z - 1); open[5] = !bench_grid_at(g, x, y, z + 1);
                if (!(open[0] | open[1] | open[2] | open[3] | open[4] | open[5])) continue;
                for (d = 0; d < S; d++)
                    for (b = 0; b < S; b++) {
                        int edge_db = d == 0 || d == S - 1 || b == 0 || b == S - 1;
                        for (a = 0; a < S; a = edge_db || a == S - 1 ? a + 1 : S - 1) {
                            int keep = (a == 0 && open[0]) || (a == S - 1 && open[1]) || (b == 0 && open[2]) ||
                                       (b == S - 1 && open[3]) || (d == 0 && open[4]) || (d == S - 1 && open[5]);
                            if (!keep) continue;
                            if (n == cap) { cap = cap ? 2 * cap : 1 << 20; c = (uint64_t *)realloc(c, cap * sizeof *c); if (!c) exit(1); }
                            c[n++] = voxdag_morton_encode(((uint32_t)x << k) + a, ((uint32_t)y << k) + b,
                                                          ((uint32_t)z << k) + d);
                        }
                    }
            }
    s->levels = L;
    snprintf(s->name, sizeof s->name, "%s", name);
    if (!k)
        snprintf(s->input, sizeof s->input, "%s: %ux%ux%u labels, %zu voxels with label != 0", path,
                 g->dim[0], g->dim[1], g->dim[2], cells);
    else
        snprintf(s->input, sizeof s->input, "%s: label != 0 scaled by %u, shell only", path, S);
    bscene_from_codes(s, c, n);
}

/* The voxel scenes the build and geometry benches share: tree.vox, then the
   liver CT grid and its shells scaled by 2^1..2^SHELLS, at SCENES (room for
   2 + SHELLS). Returns how many loaded. */
BENCH_UNUSED static size_t bscene_voxel_scenes(bscene *scenes, const char *dir, unsigned shells) {
    char path[512];
    bench_grid liver;
    size_t ns = 0;
    unsigned k;
    snprintf(path, sizeof path, "%s/tree.vox", dir);
    if (bscene_vox(&scenes[ns], path, "tree.vox")) ns++;
    snprintf(path, sizeof path, "%s/liver.inr", dir);
    if (bench_read_inr(path, &liver)) {
        for (k = 0; k <= shells; k++) {
            char name[64];
            snprintf(name, sizeof name, k ? "liver shell x%u" : "liver", 1u << k);
            bscene_grid(&scenes[ns++], &liver, k, name, "liver.inr");
        }
        free(liver.full);
    }
    return ns;
}

// -- Triangle meshes through the importer, voxelized by the library

/* Triangles fitted into the 2^L grid by their bounding box (one uniform
   scale), as `vdag build` does. */
typedef struct bmesh {
    double *pos; /* 3 per vertex, grid units */
    uint32_t *idx;
    size_t verts, tris;
} bmesh;

BENCH_UNUSED static int bmesh_load(bmesh *m, const char *path, uint32_t L) {
    vdag_scene sc;
    char err[256];
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, ext = 0, scale;
    size_t i;
    memset(m, 0, sizeof *m);
    memset(&sc, 0, sizeof sc);
    if (!vdag_import_file(path, NULL, &sc, err, sizeof err)) {
        fprintf(stderr, "bench: %s: %s\n", path, err);
        return 0;
    }
    for (i = 0; i < 3 * sc.vertex_count; i++) {
        if (sc.positions[i] < lo[i % 3]) lo[i % 3] = sc.positions[i];
        if (sc.positions[i] > hi[i % 3]) hi[i % 3] = sc.positions[i];
    }
    for (i = 0; i < 3; i++)
        if (hi[i] - lo[i] > ext) ext = hi[i] - lo[i];
    scale = ext > 0 ? (double)(1u << L) / ext : 1;
    m->verts = sc.vertex_count, m->tris = sc.triangle_count;
    m->pos = (double *)bench_xmalloc(3 * m->verts * sizeof *m->pos);
    m->idx = (uint32_t *)bench_xmalloc(3 * m->tris * sizeof *m->idx);
    for (i = 0; i < 3 * m->verts; i++) m->pos[i] = (sc.positions[i] - lo[i % 3]) * scale;
    memcpy(m->idx, sc.indices, 3 * m->tris * sizeof *m->idx);
    vdag_scene_free(&sc);
    return 1;
}

BENCH_UNUSED static void bmesh_free(bmesh *m) {
    free(m->pos);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* Voxelizes M into a DAG of 2^L with voxdag_builder_add_mesh (exact
   conservative voxelization, chunks of 2^BENCH_CHUNK_LEVELS voxels a side). */
#define BENCH_CHUNK_LEVELS 8
BENCH_UNUSED static voxdag *bmesh_voxelize(const bmesh *m, uint32_t L, unsigned threads, voxdag_build_stats *st) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag_mesh vm;
    voxdag_error e;
    voxdag *d = NULL;
    memset(&o, 0, sizeof o);
    o.levels = L;
    o.threads = threads;
    o.chunk_levels = BENCH_CHUNK_LEVELS;
    memset(&vm, 0, sizeof vm);
    vm.positions = m->pos, vm.vertex_count = m->verts, vm.indices = m->idx, vm.triangle_count = m->tris;
    if (voxdag_builder_create(&o, &b, &e) != VOXDAG_OK || voxdag_builder_add_mesh(b, &vm, &e) != VOXDAG_OK ||
        voxdag_builder_finish(b, &d, st, &e) != VOXDAG_OK) {
        fprintf(stderr, "bench: voxelizing: %s\n", e.message);
        exit(1);
    }
    return d;
}

typedef struct bench_codes {
    uint64_t *c;
    size_t n;
} bench_codes;

BENCH_UNUSED static int bench_collect(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    bench_codes *k = (bench_codes *)user;
    k->c[index] = voxdag_morton_encode(x, y, z);
    k->n++;
    return 0;
}

/* Fills S with the voxels of D. */
BENCH_UNUSED static void bscene_from_dag(bscene *s, const voxdag *d, uint32_t L) {
    voxdag_info info;
    bench_codes k;
    voxdag_get_info(d, &info);
    k.c = (uint64_t *)bench_xmalloc((info.voxels ? info.voxels : 1) * sizeof *k.c);
    k.n = 0;
    voxdag_for_each_voxel(d, bench_collect, &k);
    s->levels = L;
    bscene_from_codes(s, k.c, k.n);
}

BENCH_UNUSED static int bscene_mesh(bscene *s, const char *path, const char *name, uint32_t L) {
    bmesh m;
    voxdag *d;
    memset(s, 0, sizeof *s);
    if (!bmesh_load(&m, path, L)) return 0;
    d = bmesh_voxelize(&m, L, 1, NULL);
    bscene_from_dag(s, d, L);
    voxdag_free(d);
    snprintf(s->name, sizeof s->name, "%s", name);
    snprintf(s->input, sizeof s->input, "%.80s: %zu triangles, voxelized by voxdag_builder_add_mesh at %u^3", path,
             m.tris, 1u << L);
    bmesh_free(&m);
    return 1;
}

// -- Generated terrain

BENCH_UNUSED static double bench_lattice(uint32_t x, uint32_t z, uint32_t seed) {
    uint64_t h = ((uint64_t)x * 0x9E3779B1u) ^ ((uint64_t)z * 0x85EBCA77u) ^ ((uint64_t)seed << 40);
    h ^= h >> 29; h *= 0xBF58476D1CE4E5B9ull; h ^= h >> 32;
    return (double)(h & 0xFFFFFF) / (double)0x1000000;
}

BENCH_UNUSED static double bench_noise(double x, double z, uint32_t seed) {
    uint32_t xi = (uint32_t)x, zi = (uint32_t)z;
    double fx = x - xi, fz = z - zi;
    double a = bench_lattice(xi, zi, seed), b = bench_lattice(xi + 1, zi, seed);
    double c = bench_lattice(xi, zi + 1, seed), d = bench_lattice(xi + 1, zi + 1, seed);
    fx = fx * fx * (3 - 2 * fx);
    fz = fz * fz * (3 - 2 * fz);
    return (a + (b - a) * fx) * (1 - fz) + (c + (d - c) * fx) * fz;
}

BENCH_UNUSED static void bscene_terrain(bscene *s, uint32_t L) {
    uint32_t N = 1u << L, x, z, y;
    uint32_t *hgt = (uint32_t *)bench_xmalloc((size_t)N * N * sizeof *hgt);
    size_t n = 0, cap = 0;
    uint64_t *c = NULL;
    memset(s, 0, sizeof *s);
    for (z = 0; z < N; z++)
        for (x = 0; x < N; x++) {
            double v = 0, amp = 0.5, f = 8.0 / N;
            unsigned o;
            for (o = 0; o < 4; o++, amp *= 0.5, f *= 2) v += amp * bench_noise(x * f, z * f, o);
            hgt[(size_t)z * N + x] = (uint32_t)(N / 16 + v * (N / 3));
        }
    for (z = 0; z < N; z++)
        for (x = 0; x < N; x++) {
            uint32_t h = hgt[(size_t)z * N + x], lo = h;
            if (x && hgt[(size_t)z * N + x - 1] < lo) lo = hgt[(size_t)z * N + x - 1];
            if (x + 1 < N && hgt[(size_t)z * N + x + 1] < lo) lo = hgt[(size_t)z * N + x + 1];
            if (z && hgt[(size_t)(z - 1) * N + x] < lo) lo = hgt[(size_t)(z - 1) * N + x];
            if (z + 1 < N && hgt[(size_t)(z + 1) * N + x] < lo) lo = hgt[(size_t)(z + 1) * N + x];
            for (y = lo; y <= h; y++) {
                if (n == cap) { cap = cap ? 2 * cap : 1 << 22; c = (uint64_t *)realloc(c, cap * sizeof *c); if (!c) exit(1); }
                c[n++] = voxdag_morton_encode(x, y, z);
            }
        }
    free(hgt);
    s->levels = L;
    snprintf(s->name, sizeof s->name, "terrain");
    snprintf(s->input, sizeof s->input, "generated heightfield, 4 octaves of value noise, closed surface, %u^3", N);
    bscene_from_codes(s, c, n);
}

/* Voxels with distinct Morton codes >> 3: the octree's nodes at level L-1
   (2^3 cells), which voxdag_build_stats does not list. */
BENCH_UNUSED static uint64_t bscene_cells2(const bscene *s) {
    uint64_t prev = UINT64_MAX, n = 0;
    size_t i;
    for (i = 0; i < s->n; i++) {
        uint64_t c = voxdag_morton_encode(s->xyz[3 * i], s->xyz[3 * i + 1], s->xyz[3 * i + 2]) >> 3;
        if (c != prev) n++;
        prev = c;
    }
    return n;
}

#endif
