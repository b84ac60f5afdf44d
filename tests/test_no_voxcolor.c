/* Colours when the implementation was compiled without voxcolor.h: this unit
   carries its own static copy of voxdag.h's implementation, compiled before
   voxcolor.h is included (the include order that used to give a grey world
   without an error). voxcolor.h comes after it, for the encoder only
   (voxcolor's implementation is in tests/impl.c). A voxcolor colour section
   must then say so everywhere: voxdag_info.colors_decodable is 0, and every
   voxdag_color call fails with -1 and writes the marker colour. An RGB8
   section still decodes. tests/test_api.c checks the other way round (voxcolor.h
   first: the same file decodes). */
#include "static_impl.h"
#include "voxcolor.h"

#include "test.h"

#if defined(VOXDAGI_VOXCOLOR)
#error "tests/test_no_voxcolor.c needs an implementation compiled without voxcolor.h"
#endif

/* A small coloured scene (levels 5): N voxels along a diagonal band. */
static voxdag *colored_scene(size_t *count) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    uint32_t xyz[3 * 40];
    uint8_t rgb[3 * 40];
    size_t i;
    for (i = 0; i < 40; i++) {
        xyz[3 * i] = (uint32_t)i % 32, xyz[3 * i + 1] = (uint32_t)(i * 7) % 32, xyz[3 * i + 2] = (uint32_t)(i / 2);
        rgb[3 * i] = (uint8_t)(i * 5), rgb[3 * i + 1] = (uint8_t)(200 - i), rgb[3 * i + 2] = 17;
    }
    memset(&o, 0, sizeof o);
    o.levels = 5;
    o.colors = 1;
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK) return NULL;
    CHECK(voxdag_builder_add(b, xyz, rgb, 40, NULL) == VOXDAG_OK);
    CHECK(voxdag_builder_finish(b, &d, NULL, NULL) == VOXDAG_OK);
    *count = 40;
    return d;
}

static void test_undecodable(void) {
    size_t n = 0, cap, len, size, i;
    voxdag *d = colored_scene(&n), *v = NULL, *loaded = NULL;
    voxdag_info info;
    uint8_t raw[3 * 40], c[3], *stream;
    const void *img;
    int bad = 0;
    CHECK(d != NULL);
    if (!d) return;
    voxdag_get_info(d, &info);
    CHECK(info.voxels == n);
    /* RGB8 needs no codec: decodable here too. */
    CHECK(info.color_kind == VOXDAG_COLORS_RGB8 && info.colors_decodable == 1);
    for (i = 0; i < n; i++) CHECK(voxdag_color(d, i, raw + 3 * i) == 1);
    cap = voxcolor_encode_bound(n);
    stream = (uint8_t *)malloc(cap);
    len = voxcolor_encode(stream, cap, raw, n, NULL, NULL);
    CHECK(len > 0);
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, stream, len, &v, NULL) == VOXDAG_OK);
    img = voxdag_image(v, &size);
    CHECK(voxdag_load_memory(img, size, NULL, &loaded, NULL) == VOXDAG_OK);
    if (loaded) {
        voxdag_get_info(loaded, &info);
        CHECK(info.color_kind == VOXDAG_COLORS_VOXCOLOR && info.colors_decodable == 0);
        /* Every call fails the same documented way, and writes magenta. */
        for (i = 0; i < n; i++) {
            c[0] = c[1] = c[2] = 128;
            if (voxdag_color(loaded, i, c) != -1 || c[0] != 255 || c[1] != 0 || c[2] != 255) bad++;
        }
        CHECK_MSG(!bad, "%d voxels", bad);
        /* Past the last voxel: 0, RGB untouched, as for any DAG. */
        c[0] = c[1] = c[2] = 128;
        CHECK(voxdag_color(loaded, n, c) == 0 && c[0] == 128 && c[1] == 128 && c[2] == 128);
        CHECK(voxdag_color(loaded, 0, NULL) == 0);
        /* No level-of-detail means from colours this unit cannot decode; a
           cell's colour fails the same way. */
        CHECK(info.lod_color_bytes == 0);
        {
            voxdag_hit hit;
            memset(&hit, 0, sizeof hit);
            c[0] = c[1] = c[2] = 128;
            CHECK(voxdag_cell_color(loaded, &hit, c) == -1 && c[0] == 255 && c[1] == 0 && c[2] == 255);
        }
    }
    voxdag_free(loaded);
    voxdag_free(v);
    /* No colours at all: nothing to decode. */
    v = NULL;
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_NONE, NULL, 0, &v, NULL) == VOXDAG_OK);
    voxdag_get_info(v, &info);
    CHECK(info.color_kind == VOXDAG_COLORS_NONE && info.colors_decodable == 0);
    CHECK(voxdag_color(v, 0, c) == 0);
    voxdag_free(v);
    voxdag_free(d);
    free(stream);
}

const test_case test_no_voxcolor_cases[] = {
    {"no_voxcolor/undecodable", test_undecodable},
    {NULL, NULL},
};
