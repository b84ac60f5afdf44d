/* Format version 2 next to the current library (bench/v2.c): the last
   version-2 voxdag.h, built from the same voxels, for side-by-side sizes and
   query and build speeds. With BENCH_NO_V2 (no git history) the builds return
   NULL and every size is 0. */
#ifndef BENCH_V2_H
#define BENCH_V2_H
#include <stddef.h>
#include <stdint.h>

typedef struct bench_v2 bench_v2;

/* A version-2 DAG of N voxels (XYZ: 3 per voxel) in 2^LEVELS; NULL on failure
   or without version 2. */
bench_v2 *bench_v2_build(const uint32_t *xyz, size_t n, uint32_t levels, unsigned threads);
/* voxdag_builder_add_mesh + finish: the triangles (3 POSITIONS per vertex in
   grid units, 3 INDICES per triangle) voxelized into 2^LEVELS in chunks of
   2^CHUNK_LEVELS voxels a side; NULL on failure or without version 2. */
bench_v2 *bench_v2_build_mesh(const double *positions, size_t vertices, const uint32_t *indices, size_t triangles,
                              uint32_t levels, uint32_t chunk_levels, unsigned threads);
void bench_v2_free(bench_v2 *d);
/* Voxels of D; 0 without version 2. */
uint64_t bench_v2_voxels(const bench_v2 *d);
/* Geometry bytes (encoded nodes and bricks); 0 without version 2. */
uint64_t bench_v2_bytes(const bench_v2 *d);
uint64_t bench_v2_geometry_bytes(const uint32_t *xyz, size_t n, uint32_t levels);
/* voxdag_raycast from ORIGIN along DIR (t in [0, inf)): returns 1 and the hit
   voxel (and its index when INDEX is not NULL), or 0. */
int bench_v2_raycast(const bench_v2 *d, const double origin[3], const double dir[3], uint32_t xyz[3], uint64_t *index);
/* voxdag_lookup. */
int bench_v2_lookup(const bench_v2 *d, uint32_t x, uint32_t y, uint32_t z, uint64_t *index);
#endif
