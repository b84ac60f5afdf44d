/* A ray-casting peer for bench_rays.c (bench_rays_nanovdb.cpp, or none). */
#ifndef BENCH_RAYS_PEER_H
#define BENCH_RAYS_PEER_H
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
typedef struct bench_peer bench_peer;
/* Builds the peer's structure over N voxels (XYZ: 3 per voxel); *BYTES: its size. */
bench_peer *bench_peer_build(const uint32_t *xyz, size_t n, size_t *bytes);
/* First active voxel along the ray; returns 1 and its coordinates, or 0. Thread-safe. */
int bench_peer_trace(const bench_peer *p, const double origin[3], const double dir[3], uint32_t ijk[3]);
void bench_peer_free(bench_peer *p);
const char *bench_peer_name(void);
#ifdef __cplusplus
}
#endif
#endif
