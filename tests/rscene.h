/* Random dense scenes with their occupancy pyramid and voxel ranks, and
   random rays, for the ray-casting oracles (tests/test_raytrace.c against a
   flat DDA, tests/test_gpu.c against voxdag_raycast). */
#ifndef VOXDAG_TEST_RSCENE_H
#define VOXDAG_TEST_RSCENE_H

#include <math.h>
#include <stdlib.h>

#include "test.h"
#include "voxdag.h"

// -- Dense scenes and their occupancy pyramid

typedef struct rscene {
    uint32_t levels, n;
    uint8_t *occ[VOXDAG_MAX_LEVELS + 1]; /* occ[q]: 2^q cells per axis, 1 = not empty */
    uint64_t *rank;                      /* voxel index of each full voxel */
} rscene;

static inline size_t rcell(uint32_t n, uint32_t x, uint32_t y, uint32_t z) {
    return (size_t)x + (size_t)n * ((size_t)y + (size_t)n * z);
}

enum { RS_EMPTY, RS_ONE, RS_FULL, RS_SPARSE, RS_DENSE, RS_SPHERE, RS_PLANE, RS_BLOB, RS_CHECKER, RS_COUNT };

static inline int rscene_voxel(int kind, uint32_t n, uint32_t x, uint32_t y, uint32_t z, uint64_t *r,
                        const uint32_t one[3]) {
    double c = n / 2.0 - 0.3, rad = n * 0.4, dx = x + 0.5 - c, dy = y + 0.5 - c, dz = z + 0.5 - c;
    double d2 = dx * dx + dy * dy + dz * dz;
    uint32_t h = n / 2, mx = x < h ? x : n - 1 - x, my = y < h ? y : n - 1 - y, mz = z < h ? z : n - 1 - z;
    switch (kind) {
    case RS_ONE: return x == one[0] && y == one[1] && z == one[2];
    case RS_FULL: return 1;
    case RS_SPARSE: return test_rand(r) % 23 == 0;
    case RS_DENSE: return (test_rand(r) & 3) != 0;
    case RS_SPHERE: return d2 <= rad * rad && d2 >= (rad - 1.7) * (rad - 1.7);
    case RS_PLANE: return (x + 2 * y + 3 * z) / 3 == n / 2;
    case RS_BLOB: /* reflected into all 8 octants: many mirrored subtrees */
        return (mx * 7 + my * 13 + mz * 5 + mx * my) % 5 == 0 || mx + my + mz < n / 4;
    case RS_CHECKER: return ((x ^ y ^ z) & 1) && (x / 4 + y / 4 + z / 4) % 3 != 0;
    default: return 0;
    }
}

/* Builds a scene into a dense pyramid and a DAG under symmetry group G
   (0 none, 1 reflections, 2 all 48). */
static inline voxdag *rscene_make(rscene *s, int kind, uint32_t levels, int symmetric, uint64_t seed) {
    uint32_t n = 1u << levels, x, y, z, q, one[3];
    uint64_t r = seed, count = 0, m, cells = (uint64_t)n * n * n;
    uint32_t *xyz = (uint32_t *)malloc(3 * cells * sizeof(uint32_t));
    uint8_t *rgb = (uint8_t *)malloc(3 * cells);
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    memset(s, 0, sizeof *s);
    s->levels = levels;
    s->n = n;
    for (q = 0; q <= levels; q++) s->occ[q] = (uint8_t *)calloc((size_t)1 << (3 * q), 1);
    s->rank = (uint64_t *)calloc(cells, sizeof(uint64_t));
    for (q = 0; q < 3; q++) one[q] = test_rand_below(&r, n);
    for (z = 0; z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                if (!rscene_voxel(kind, n, x, y, z, &r, one)) continue;
                for (q = 0; q <= levels; q++) {
                    uint32_t sh = levels - q;
                    s->occ[q][rcell(1u << q, x >> sh, y >> sh, z >> sh)] = 1;
                }
                xyz[3 * count] = x, xyz[3 * count + 1] = y, xyz[3 * count + 2] = z;
                rgb[3 * count] = (uint8_t)x, rgb[3 * count + 1] = (uint8_t)y, rgb[3 * count + 2] = (uint8_t)z;
                count++;
            }
    /* Morton rank: walk every cell in Morton order (bit-by-bit decode here). */
    for (m = 0, count = 0; m < cells; m++) {
        uint32_t c[3] = {0, 0, 0}, bit;
        for (bit = 0; bit < 3 * levels; bit++) c[bit % 3] |= (uint32_t)(m >> bit & 1) << (bit / 3);
        if (s->occ[levels][rcell(n, c[0], c[1], c[2])]) s->rank[rcell(n, c[0], c[1], c[2])] = count++;
    }
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.symmetry = (voxdag_symmetry)(VOXDAG_SYMMETRY_NONE + symmetric);
    o.colors = 1;
    CHECK(voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_add(b, xyz, rgb, count, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    free(xyz);
    free(rgb);
    return d;
}

static inline void rscene_free(rscene *s) {
    uint32_t q;
    for (q = 0; q <= s->levels; q++) free(s->occ[q]);
    free(s->rank);
}

// -- Rays

static inline double rand_unit(uint64_t *r) { return (double)(test_rand(r) >> 11) / 9007199254740992.0; }

/* A float in [lo, hi) (rays come from float text in the tool). */
static inline double rand_in(uint64_t *r, double lo, double hi) { return (float)(lo + (hi - lo) * rand_unit(r)); }

static inline voxdag_ray make_ray(uint64_t *r, uint32_t n) {
    voxdag_ray ray;
    uint32_t b, kind = test_rand_below(r, 6);
    double target[3];
    memset(&ray, 0, sizeof ray);
    ray.t_max = HUGE_VAL;
    for (b = 0; b < 3; b++) {
        ray.origin[b] = rand_in(r, 0, n);
        ray.dir[b] = rand_in(r, -1, 1);
        target[b] = rand_in(r, 0, n);
    }
    switch (kind) {
    case 0: break; /* inside, random direction */
    case 1:        /* outside, aimed at the grid */
        for (b = 0; b < 3; b++) ray.origin[b] = rand_in(r, -(double)n, 2.0 * n);
        for (b = 0; b < 3; b++) ray.dir[b] = target[b] - ray.origin[b];
        break;
    case 2: /* axis-parallel: one or two zero components, origin often on a face plane */
        for (b = 0; b < 3; b++) {
            if (test_rand_below(r, 3) == 0) ray.origin[b] = test_rand_below(r, n + 1);
            if (test_rand_below(r, 3) == 0) ray.origin[b] = -ray.origin[b] - 1;
        }
        ray.dir[test_rand_below(r, 3)] = 0;
        if (test_rand(r) & 1) ray.dir[test_rand_below(r, 3)] = 0;
        break;
    case 3: /* through edges and corners: lattice origin, small integer direction */
    case 4:
        for (b = 0; b < 3; b++) {
            ray.origin[b] = (double)test_rand_below(r, n + 5) - 2;
            ray.dir[b] = (double)test_rand_below(r, 5) - 2;
            if (kind == 4 && b == 0) ray.origin[b] += 0.5;
        }
        break;
    case 5: /* a window [t_min, t_max] inside the grid */
        ray.t_min = rand_in(r, 0, n / 2.0);
        ray.t_max = ray.t_min + rand_in(r, 0, (double)n);
        break;
    }
    return ray;
}

#endif
