/* Prints the triangles the vdag importers read from a file, for comparison
   with an independent reader (tests/third_party.sh): a first line
   "triangles N points P", then one line per triangle with its 9 corner
   coordinates (the importer's axes, %.9g). Textures are not decoded.
   Usage: import_dump FILE */
#include <stdio.h>
#include <string.h>

#include "examples/import.h"

int main(int argc, char **argv) {
    vdag_import_limits limits;
    vdag_scene sc;
    char err[256];
    size_t t;
    int c;
    if (argc != 2) {
        fprintf(stderr, "usage: import_dump FILE\n");
        return 2;
    }
    memset(&limits, 0, sizeof limits);
    limits.skip_textures = 1;
    limits.quiet = 1;
    if (!vdag_import_file(argv[1], &limits, &sc, err, sizeof err)) {
        fprintf(stderr, "import_dump: %s\n", err);
        return 1;
    }
    printf("triangles %zu points %zu\n", sc.triangle_count, sc.point_count);
    for (t = 0; t < sc.triangle_count; t++)
        for (c = 0; c < 3; c++) {
            const double *p = sc.positions + 3 * (size_t)sc.indices[3 * t + c];
            printf("%.9g %.9g %.9g%c", p[0], p[1], p[2], c == 2 ? '\n' : ' ');
        }
    vdag_scene_free(&sc);
    return 0;
}
