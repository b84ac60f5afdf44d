/* Calls into both libraries (declarations must be visible) and returns the
   number of wrong results. Every link test runs it, so a unit whose
   IMPLEMENTATION macro is misspelt fails to link. */
#include <stdio.h>
#include <string.h>

/* voxcolor on 2 threads, one-shot and streamed (a voxcolor_encoder made in
   this unit, used by the implementation's: their layouts must agree, whatever
   VOXCOLOR_NO_THREADS says), gives the serial stream. Returns 0 or 1. */
static uint8_t exercise_stream[1 << 16];
static int exercise_write(void *user, uint64_t offset, const void *bytes, size_t size) {
    (void)user;
    if (offset + size > sizeof exercise_stream) return 0;
    memcpy(exercise_stream + offset, bytes, size);
    return 1;
}
static int check_exercise_threads(void) {
    static uint8_t rgb[3 * 5000], one[sizeof exercise_stream], two[sizeof exercise_stream];
    static voxcolor_encoder enc;
    voxcolor_encode_opts o;
    size_t i, a, b;
    for (i = 0; i < sizeof rgb; i++) rgb[i] = (uint8_t)(i / 3 % 97 + (i % 3) * 40);
    memset(&o, 0, sizeof o);
    o.max_error = 0.02;
    a = voxcolor_encode(one, sizeof one, rgb, 5000, &o, NULL);
    o.threads = 2;
    b = voxcolor_encode(two, sizeof two, rgb, 5000, &o, NULL);
    if (!a || a != b || memcmp(one, two, a)) return 1;
    if (voxcolor_encoder_init(&enc, 5000, &o, exercise_write, NULL, NULL) != VOXCOLOR_OK ||
        voxcolor_encoder_push(&enc, rgb, 5000) != VOXCOLOR_OK || voxcolor_encoder_finish(&enc, NULL) != a ||
        memcmp(one, exercise_stream, a))
        return 1;
    return 0;
}

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
    size = voxcolor_encode(stream, sizeof stream, rgb, 2, &copts, NULL);
    if (!size || voxcolor_view_init(&view, stream, size, NULL) != VOXCOLOR_OK) return failed + 1;
    voxcolor_view_get(&view, 0, c);
    if (c[0] != 255 || c[1] != 0 || c[2] != 0) failed++;
    failed += check_exercise_threads();
    if (failed) fprintf(stderr, "%s: %d wrong results\n", unit, failed);
    return failed;
}
