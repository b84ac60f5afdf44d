/* Geometry bytes written by format version 2 (the last version-2 voxdag.h,
   which the Makefile extracts from the git history into
   $(BUILD)/bench/v2/voxdag.h), for the benchmarks' side-by-side sizes. Its
   functions stay private to this file (VOXDAG_STATIC), so the benchmark can
   link it next to the current voxdag.h. Without that header (no history),
   BENCH_NO_V2 makes every size 0. */
#include <stddef.h>
#include <stdint.h>

uint64_t bench_v2_geometry_bytes(const uint32_t *xyz, size_t n, uint32_t levels);

#ifdef BENCH_NO_V2
uint64_t bench_v2_geometry_bytes(const uint32_t *xyz, size_t n, uint32_t levels) {
    (void)xyz, (void)n, (void)levels;
    return 0;
}
#else
#define VOXDAG_STATIC
#define VOXDAG_IMPLEMENTATION
#include "v2/voxdag.h"

uint64_t bench_v2_geometry_bytes(const uint32_t *xyz, size_t n, uint32_t levels) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    voxdag_info info;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.threads = 2;
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK) return 0;
    if (voxdag_builder_add(b, xyz, NULL, n, NULL) != VOXDAG_OK) {
        voxdag_builder_free(b);
        return 0;
    }
    if (voxdag_builder_finish(b, &d, NULL, NULL) != VOXDAG_OK) return 0; /* frees the builder */
    voxdag_get_info(d, &info);
    voxdag_free(d);
    return info.node_bytes + info.brick_bytes;
}
#endif
