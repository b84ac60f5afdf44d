/* Fuzz target for the scene importers: the first input byte picks the format
   (modulo 9: xyz ply obj off vox mtl spm ac stl), the rest is the file. Built with
   -DFUZZ_LIBFUZZER it is a libFuzzer target (`make fuzz-import`); otherwise
   main replays the files and directories given as arguments and prints
   "N passed, N failed". Broken invariants abort, as sanitizer errors do. */
#define _POSIX_C_SOURCE 200809L
#include "examples/import.h"
#include "fuzz_require.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Allocation failure sweeps of the replay main (fuzz_replay.h): the
   importers allocate through this (VDAG_IMPORT_REALLOC in the Makefile). */
#define FUZZ_ALLOC_SWEEP
static long fuzz_fail_at = -1, fuzz_alloc_calls;

void *fuzz_import_realloc(void *ptr, size_t size);
void *fuzz_import_realloc(void *ptr, size_t size) {
    if (fuzz_alloc_calls++ == fuzz_fail_at) return NULL;
    return realloc(ptr, size);
}

#define REQUIRE(cond) require(cond, "invariant broken: " #cond)

/* What every imported scene promises (import.h). */
static void check_scene(const vdag_scene *s) {
    size_t i;
    for (i = 0; i < 3 * s->point_count; i++) {
        REQUIRE(isfinite(s->points[i]));
        if (s->points_are_voxels) REQUIRE(s->points[i] >= 0 && s->points[i] == floor(s->points[i]));
    }
    for (i = 0; i < 3 * s->vertex_count; i++) REQUIRE(isfinite(s->positions[i]));
    for (i = 0; s->uv && i < 2 * s->vertex_count; i++) REQUIRE(isfinite(s->uv[i]));
    for (i = 0; i < 3 * s->triangle_count; i++) REQUIRE(s->indices[i] < s->vertex_count);
    for (i = 0; s->triangle_material && i < s->triangle_count; i++)
        REQUIRE(s->triangle_material[i] >= -1 && s->triangle_material[i] < (int64_t)s->material_count);
    for (i = 0; i < s->material_count; i++)
        REQUIRE(s->materials[i].image >= -1 && s->materials[i].image < (int64_t)s->image_count);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const char *const formats[] = {"xyz", "ply", "obj", "off", "vox", "mtl", "spm", "ac", "stl"};
    vdag_import_limits limits;
    vdag_scene scene;
    char err[256];
    if (!size) return 0;
    memset(&limits, 0, sizeof limits);
    limits.max_points = 65536; /* .vox instancing: small scenes keep the runs fast */
    limits.max_vox_voxels = (uint64_t)1 << 20;
    limits.quiet = 1;
    if (vdag_import_memory(formats[data[0] % 9], data + 1, size - 1, NULL, &limits, &scene, err, sizeof err)) {
        check_scene(&scene);
        vdag_scene_free(&scene);
    } else {
        REQUIRE(err[0] && !strchr(err, '\n'));
    }
    return 0;
}

#ifndef FUZZ_LIBFUZZER
#include "fuzz_replay.h"
#endif
