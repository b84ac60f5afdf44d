/* Fuzz target for the scene importers: the first input byte picks the format
   (modulo 8: xyz ply obj off vox mtl spm ac), the rest is the file. Built with
   -DVDAG_LIBFUZZER it is a libFuzzer target (`make fuzz-import`); otherwise
   main replays the files and directories given as arguments and prints
   "N passed, N failed". Broken invariants abort, as sanitizer errors do. */
#define _POSIX_C_SOURCE 200809L
#include "examples/import.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define REQUIRE(cond)                                                                      \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "fuzz_import: %s:%d: invariant broken: %s\n", __FILE__, __LINE__, #cond); \
            abort();                                                                       \
        }                                                                                  \
    } while (0)

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
    static const char *const formats[] = {"xyz", "ply", "obj", "off", "vox", "mtl", "spm", "ac"};
    vdag_scene scene;
    char err[256];
    if (!size) return 0;
    if (vdag_import_memory(formats[data[0] % 8], data + 1, size - 1, NULL, &scene, err, sizeof err)) {
        check_scene(&scene);
        vdag_scene_free(&scene);
    } else {
        REQUIRE(err[0] && !strchr(err, '\n'));
    }
    return 0;
}

#ifndef VDAG_LIBFUZZER
/* Runs one input file; 0 if it cannot be read. */
static int replay_file(const char *path) {
    FILE *f = fopen(path, "rb");
    uint8_t *data = NULL;
    size_t size = 0, cap = 0, got;
    if (!f) return 0;
    do {
        if (size == cap) {
            cap = cap ? 2 * cap : 4096;
            data = (uint8_t *)realloc(data, cap);
            REQUIRE(data != NULL);
        }
        got = fread(data + size, 1, cap - size, f);
        size += got;
    } while (got);
    fclose(f);
    LLVMFuzzerTestOneInput(data, size);
    free(data);
    return 1;
}

int main(int argc, char **argv) {
    int i, passed = 0, failed = 0;
    for (i = 1; i < argc; i++) {
        struct stat st;
        DIR *dir;
        struct dirent *e;
        if (stat(argv[i], &st) == 0 && !S_ISDIR(st.st_mode)) {
            if (replay_file(argv[i])) passed++;
            else failed++, fprintf(stderr, "fuzz_import: cannot read %s\n", argv[i]);
            continue;
        }
        if (!(dir = opendir(argv[i]))) {
            fprintf(stderr, "fuzz_import: cannot open %s\n", argv[i]);
            failed++;
            continue;
        }
        while ((e = readdir(dir)) != NULL) {
            char path[4096];
            if (e->d_name[0] == '.') continue;
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            if (replay_file(path)) passed++;
            else failed++, fprintf(stderr, "fuzz_import: cannot read %s\n", path);
        }
        closedir(dir);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
#endif
