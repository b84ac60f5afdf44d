/* The NanoVDB peer of bench_rays.c: the same voxels as active values of a
   NanoVDB float grid, primary rays through NanoVDB's own hierarchical DDA
   (nanovdb::firstActive). Built only when NanoVDB's headers are installed. */
#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/HDDA.h>
#include <nanovdb/util/Ray.h>

#include "bench_rays_peer.h"

struct bench_peer {
    nanovdb::GridHandle<nanovdb::HostBuffer> handle;
};

extern "C" bench_peer *bench_peer_build(const uint32_t *xyz, size_t n, size_t *bytes) {
    nanovdb::GridBuilder<float> builder(0.0f);
    auto acc = builder.getAccessor();
    for (size_t i = 0; i < n; i++)
        acc.setValue(nanovdb::Coord((int)xyz[3 * i], (int)xyz[3 * i + 1], (int)xyz[3 * i + 2]), 1.0f);
    bench_peer *p = new bench_peer;
    p->handle = builder.getHandle<>();
    *bytes = p->handle.size();
    return p;
}

extern "C" int bench_peer_trace(const bench_peer *p, const double origin[3], const double dir[3], uint32_t ijk[3]) {
    const nanovdb::FloatGrid *grid = p->handle.grid<float>();
    auto acc = grid->getAccessor();
    nanovdb::Ray<float> ray(nanovdb::Vec3f((float)origin[0], (float)origin[1], (float)origin[2]),
                            nanovdb::Vec3f((float)dir[0], (float)dir[1], (float)dir[2]));
    nanovdb::Coord c;
    float t;
    if (!nanovdb::firstActive(ray, acc, c, t)) return 0;
    ijk[0] = (uint32_t)c[0], ijk[1] = (uint32_t)c[1], ijk[2] = (uint32_t)c[2];
    return 1;
}

extern "C" void bench_peer_free(bench_peer *p) { delete p; }

#define BENCH_STR2(x) #x
#define BENCH_STR(x) BENCH_STR2(x)
extern "C" const char *bench_peer_name(void) {
    return "NanoVDB " BENCH_STR(NANOVDB_MAJOR_VERSION_NUMBER) "." BENCH_STR(NANOVDB_MINOR_VERSION_NUMBER) "." BENCH_STR(
        NANOVDB_PATCH_VERSION_NUMBER) " firstActive (float grid)";
}
