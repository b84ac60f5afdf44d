/* Format version 2 (the last version-2 voxdag.h, which the Makefile extracts
   from the git history into $(BUILD)/bench/v2/voxdag.h) for the benchmarks'
   side-by-side sizes, query and build speeds (bench/v2.h). Its functions stay private
   to this file (VOXDAG_STATIC), so a benchmark can link it next to the
   current voxdag.h. Without that header (no history), BENCH_NO_V2 makes every
   build fail and every size 0. */
#include "bench/v2.h"

#ifdef BENCH_NO_V2
bench_v2 *bench_v2_build(const uint32_t *xyz, size_t n, uint32_t levels, unsigned threads) {
    (void)xyz, (void)n, (void)levels, (void)threads;
    return NULL;
}
bench_v2 *bench_v2_build_mesh(const double *positions, size_t vertices, const uint32_t *indices, size_t triangles,
                              uint32_t levels, uint32_t chunk_levels, unsigned threads) {
    (void)positions, (void)vertices, (void)indices, (void)triangles, (void)levels, (void)chunk_levels, (void)threads;
    return NULL;
}
void bench_v2_free(bench_v2 *d) { (void)d; }
uint64_t bench_v2_bytes(const bench_v2 *d) {
    (void)d;
    return 0;
}
uint64_t bench_v2_voxels(const bench_v2 *d) {
    (void)d;
    return 0;
}
int bench_v2_raycast(const bench_v2 *d, const double origin[3], const double dir[3], uint32_t xyz[3], uint64_t *index) {
    (void)d, (void)origin, (void)dir, (void)xyz, (void)index;
    return 0;
}
int bench_v2_lookup(const bench_v2 *d, uint32_t x, uint32_t y, uint32_t z, uint64_t *index) {
    (void)d, (void)x, (void)y, (void)z, (void)index;
    return 0;
}
#else
#define VOXDAG_STATIC
#define VOXDAG_IMPLEMENTATION
#include "v2/voxdag.h"

/* A builder with O, given MESH (when not NULL) or the N voxels XYZ, then
   finished. */
static bench_v2 *build(const voxdag_build_opts *o, const uint32_t *xyz, size_t n, const voxdag_mesh *mesh) {
    voxdag_builder *b;
    voxdag *d = NULL;
    if (voxdag_builder_create(o, &b, NULL) != VOXDAG_OK) return NULL;
    if ((mesh ? voxdag_builder_add_mesh(b, mesh, NULL) : voxdag_builder_add(b, xyz, NULL, n, NULL)) != VOXDAG_OK) {
        voxdag_builder_free(b);
        return NULL;
    }
    if (voxdag_builder_finish(b, &d, NULL, NULL) != VOXDAG_OK) return NULL; /* frees the builder */
    return (bench_v2 *)d;
}

bench_v2 *bench_v2_build(const uint32_t *xyz, size_t n, uint32_t levels, unsigned threads) {
    voxdag_build_opts o;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.threads = threads;
    return build(&o, xyz, n, NULL);
}

bench_v2 *bench_v2_build_mesh(const double *positions, size_t vertices, const uint32_t *indices, size_t triangles,
                              uint32_t levels, uint32_t chunk_levels, unsigned threads) {
    voxdag_build_opts o;
    voxdag_mesh m;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.threads = threads;
    o.chunk_levels = chunk_levels;
    memset(&m, 0, sizeof m);
    m.positions = positions, m.vertex_count = vertices, m.indices = indices, m.triangle_count = triangles;
    return build(&o, NULL, 0, &m);
}

void bench_v2_free(bench_v2 *d) { voxdag_free((voxdag *)d); }

uint64_t bench_v2_voxels(const bench_v2 *d) {
    voxdag_info info;
    if (!d) return 0;
    voxdag_get_info((const voxdag *)d, &info);
    return info.voxels;
}

uint64_t bench_v2_bytes(const bench_v2 *d) {
    voxdag_info info;
    if (!d) return 0;
    voxdag_get_info((const voxdag *)d, &info);
    return info.node_bytes + info.brick_bytes;
}

int bench_v2_raycast(const bench_v2 *d, const double origin[3], const double dir[3], uint32_t xyz[3], uint64_t *index) {
    voxdag_ray ray;
    voxdag_ray_opts opts;
    voxdag_hit hit;
    memcpy(ray.origin, origin, sizeof ray.origin);
    memcpy(ray.dir, dir, sizeof ray.dir);
    ray.t_min = 0, ray.t_max = HUGE_VAL;
    memset(&opts, 0, sizeof opts);
    opts.want_index = index != NULL;
    if (!voxdag_raycast((const voxdag *)d, &ray, &opts, &hit)) return 0;
    memcpy(xyz, hit.xyz, sizeof hit.xyz);
    if (index) *index = hit.index;
    return 1;
}

int bench_v2_lookup(const bench_v2 *d, uint32_t x, uint32_t y, uint32_t z, uint64_t *index) {
    return voxdag_lookup((const voxdag *)d, x, y, z, index);
}
#endif

uint64_t bench_v2_geometry_bytes(const uint32_t *xyz, size_t n, uint32_t levels) {
    bench_v2 *d = bench_v2_build(xyz, n, levels, 2);
    uint64_t bytes = bench_v2_bytes(d);
    bench_v2_free(d);
    return bytes;
}
