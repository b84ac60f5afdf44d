/* A load-and-query program built with VOXDAG_NO_BUILD (no builder, voxelizer
   or encoder compiled in): loads the .vdag file named on the command line and
   queries it. Prints "N voxels, M hits" and exits 0 when every voxel the walk
   visits is found again by lookup with the same index. */
#define VOXDAG_NO_BUILD
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"

#include <stdio.h>
#include <string.h>

static int relookup(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    uint64_t found;
    if (!voxdag_lookup((const voxdag *)user, x, y, z, &found) || found != index) return 1;
    return 0;
}

int main(int argc, char **argv) {
    voxdag *dag;
    voxdag_error err;
    voxdag_info info;
    voxdag_ray ray;
    voxdag_hit hit;
    uint64_t visited;
    unsigned k, hits = 0;
    if (argc < 2 || voxdag_load_file(argv[1], NULL, &dag, &err) != VOXDAG_OK) {
        fprintf(stderr, "load_query: %s\n", argc < 2 ? "usage: load_query FILE" : err.message);
        return 1;
    }
    voxdag_get_info(dag, &info);
    visited = voxdag_for_each_voxel(dag, relookup, dag);
    for (k = 0; k < 64; k++) {
        memset(&ray, 0, sizeof ray);
        ray.origin[0] = -1;
        ray.origin[1] = (k % 8 + 0.5) * (double)(1u << info.levels) / 8;
        ray.origin[2] = (k / 8 + 0.5) * (double)(1u << info.levels) / 8;
        ray.dir[0] = 1;
        if (voxdag_raycast(dag, &ray, NULL, &hit) > 0) hits++;
    }
    printf("%llu voxels, %u hits\n", (unsigned long long)visited, hits);
    voxdag_free(dag);
    return visited == info.voxels ? 0 : 1;
}
