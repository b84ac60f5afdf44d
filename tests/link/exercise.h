/* Calls into both libraries (declarations must be visible) and returns the
   number of wrong results. Every link test runs it, so a unit whose
   IMPLEMENTATION macro is misspelt fails to link. */
#include <stdio.h>
#include <string.h>

static int check_exercise(const char *unit) {
    int failed = 0;
    voxdag_build_opts opts;
    voxdag_builder *b = NULL;
    voxdag *dag = NULL;
    voxdag_error err;
    uint32_t xyz[6] = {1, 2, 3, 14, 5, 6};
    uint8_t rgb[6] = {255, 0, 0, 0, 255, 0};
    uint8_t c[3] = {0, 0, 0};
    uint64_t index = 0;
    uint8_t stream[512];
    size_t size;
    voxcolor_encode_opts copts;
    voxcolor_view view;

    memset(&opts, 0, sizeof opts);
    opts.levels = 4;
    opts.colors = 1;
    if (voxdag_version() != VOXDAG_VERSION) failed++;
    if (voxdag_builder_create(&opts, &b, &err) != VOXDAG_OK ||
        voxdag_builder_add(b, xyz, rgb, 2, &err) != VOXDAG_OK ||
        voxdag_builder_finish(b, &dag, NULL, &err) != VOXDAG_OK) {
        fprintf(stderr, "%s: build: %s\n", unit, voxdag_status_string(err.status));
        return failed + 1;
    }
    if (!voxdag_lookup(dag, 14, 5, 6, &index) || index != 1 || !voxdag_color(dag, index, c) ||
        c[0] != 0 || c[1] != 255 || c[2] != 0)
        failed++;
    if (voxdag_lookup(dag, 0, 0, 0, &index)) failed++;
    voxdag_free(dag);

    memset(&copts, 0, sizeof copts);
    if (voxcolor_version() != VOXCOLOR_VERSION) failed++;
    if (voxcolor_encode_bound(2) > sizeof stream) return failed + 1;
    size = voxcolor_encode(stream, sizeof stream, rgb, 2, &copts);
    if (!size || voxcolor_view_init(&view, stream, size) != VOXCOLOR_OK) return failed + 1;
    voxcolor_view_get(&view, 0, c);
    if (c[0] != 255 || c[1] != 0 || c[2] != 0) failed++;
    if (failed) fprintf(stderr, "%s: %d wrong results\n", unit, failed);
    return failed;
}
