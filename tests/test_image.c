/* The tool's texture decoder (examples/image_stb.c) against OpenImageIO:
   images written here by OpenImageIO in every format the tool reads (PNG
   grey, grey + alpha, RGB, RGBA; TGA plain and RLE; BMP; JPEG; PPM) are
   decoded by both, directly and through the .obj importer, and must agree:
   exactly for the lossless formats, within a small bound for JPEG (two
   decoders may round the inverse DCT and the chroma upsampling apart).
   Corrupt and oversized images fail with a message. */
#define _POSIX_C_SOURCE 200809L
#include "test.h"
#include "examples/image.h"
#include "examples/import.h"
#include "oiio_ref.h"

#include <stdlib.h>
#include <unistd.h>

typedef struct image_case {
    const char *name; /* file name: its extension picks the format */
    int channels;
    const char *compression;
    int max_diff; /* per channel: 0 for lossless formats */
} image_case;

static const image_case cases[] = {
    {"grey.png", 1, NULL, 0}, {"grey_alpha.png", 2, NULL, 0}, {"rgb.png", 3, NULL, 0},
    {"rgba.png", 4, NULL, 0}, {"rgb.tga", 3, "none", 0},      {"rgba_rle.tga", 4, "rle", 0},
    {"rgb.bmp", 3, NULL, 0},  {"rgb.ppm", 3, NULL, 0},        {"photo.jpg", 3, "jpeg:92", 4},
    {"grey.jpg", 1, "jpeg:92", 2},
};

/* Smooth gradients plus a little noise (JPEG-friendly), alpha in stripes
   that cross 1/2. */
static void make_pixels(uint8_t *p, uint32_t w, uint32_t h, int channels, uint64_t *seed) {
    uint32_t x, y;
    int c;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++)
            for (c = 0; c < channels; c++) {
                uint8_t *v = &p[((size_t)y * w + x) * (size_t)channels + (size_t)c];
                if ((channels == 2 || channels == 4) && c == channels - 1) *v = (uint8_t)(x % 8 < 3 ? 0 : 40 * (x % 8));
                else *v = (uint8_t)((x * 5 + y * 3 + (uint32_t)c * 70 + test_rand_below(seed, 4)) & 255);
            }
}

/* Compares a decoded image with OpenImageIO's RGBA decode of the same file. */
static void compare(const char *what, const vdag_image *im, uint32_t w, uint32_t h, const uint8_t *ref, int max_diff) {
    size_t i, n = (size_t)w * h, opaque = 1;
    int worst = 0, c;
    CHECK_MSG(im->width == w && im->height == h, "%s: %ux%u, reference %ux%u", what, im->width, im->height, w, h);
    if (im->width != w || im->height != h) return;
    for (i = 0; i < n; i++) {
        for (c = 0; c < 3; c++) {
            int d = abs((int)im->rgb[3 * i + (size_t)c] - (int)ref[4 * i + (size_t)c]);
            if (d > worst) worst = d;
        }
        if (ref[4 * i + 3] != 255) opaque = 0;
        if (im->alpha) CHECK(im->alpha[i] == ref[4 * i + 3]);
    }
    CHECK_MSG(worst <= max_diff, "%s: a channel differs by %d (bound %d)", what, worst, max_diff);
    CHECK_MSG((im->alpha == NULL) == (opaque == 1), "%s: alpha %s, reference %s", what, im->alpha ? "kept" : "dropped",
              opaque ? "opaque" : "not opaque");
}

static int write_text(const char *path, const char *text) {
    FILE *f = fopen(path, "wb");
    int ok = f && fputs(text, f) >= 0;
    if (f && fclose(f)) ok = 0;
    return ok;
}

static void test_image_against_oiio(void) {
    char dir[] = "/tmp/vdag-image-XXXXXX", path[512], obj[512], mtl[512], err[600], text[600];
    uint64_t seed = 3;
    size_t k;
    CHECK(mkdtemp(dir) != NULL);
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const image_case *t = &cases[k];
        uint32_t w = 37 + (uint32_t)k, h = 21, rw, rh;
        uint8_t *pixels = (uint8_t *)malloc((size_t)w * h * (size_t)t->channels), *ref = NULL;
        vdag_image im;
        vdag_scene s;
        snprintf(path, sizeof path, "%s/%s", dir, t->name);
        make_pixels(pixels, w, h, t->channels, &seed);
        if (!oiio_ref_write(path, w, h, t->channels, pixels, t->compression) || !oiio_ref_load(path, &rw, &rh, &ref)) {
            CHECK_MSG(0, "%s: OpenImageIO cannot write and read it back", t->name);
            free(pixels);
            continue;
        }
        if (!vdag_image_load(path, &im, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            compare(t->name, &im, rw, rh, ref, t->max_diff);
            vdag_image_free(&im);
        }
        /* The same file as an .obj's texture, through the importer. */
        snprintf(obj, sizeof obj, "%s/scene.obj", dir);
        snprintf(mtl, sizeof mtl, "%s/scene.mtl", dir);
        snprintf(text, sizeof text, "newmtl t\nmap_Kd %s\n", t->name);
        CHECK(write_text(mtl, text));
        CHECK(write_text(obj, "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n"));
        if (!vdag_import_file(obj, NULL, &s, err, sizeof err)) {
            CHECK_MSG(0, "%s", err);
        } else {
            CHECK_MSG(s.image_count == 1 && s.materials[0].image == 0, "%s: not decoded by the importer", t->name);
            if (s.image_count == 1) compare(t->name, &s.images[0], rw, rh, ref, t->max_diff);
            vdag_scene_free(&s);
        }
        remove(obj);
        remove(mtl);
        remove(path);
        free(ref);
        free(pixels);
    }
    rmdir(dir);
}

/* Corrupt or oversized images fail with a one-line message. */
static void test_image_errors(void) {
    static const uint8_t huge_png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                       0, 1, 0, 0, 0, 1, 0, 0, 8, 2, 0, 0, 0, 0x2d, 0xd2, 0x1c, 0x43};
    char dir[] = "/tmp/vdag-image-XXXXXX", path[512], err[600];
    vdag_image im;
    FILE *f;
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/huge.png", dir); /* 65536 x 65536 declared: more than the pixel cap */
    f = fopen(path, "wb");
    CHECK(f && fwrite(huge_png, 1, sizeof huge_png, f) == sizeof huge_png && !fclose(f));
    CHECK(!vdag_image_load(path, &im, err, sizeof err) && im.rgb == NULL && !strchr(err, '\n'));
    remove(path);
    snprintf(path, sizeof path, "%s/junk.png", dir);
    f = fopen(path, "wb");
    CHECK(f && fputs("\x89PNG\r\n\x1a\nnot really", f) >= 0 && !fclose(f));
    CHECK(!vdag_image_load(path, &im, err, sizeof err) && im.rgb == NULL && err[0] && !strchr(err, '\n'));
    remove(path);
    snprintf(path, sizeof path, "%s/none.png", dir);
    CHECK(!vdag_image_load(path, &im, err, sizeof err) && strstr(err, "none.png: cannot open") != NULL);
    rmdir(dir);
}

const test_case test_image_cases[] = {
    {"image/decoder against OpenImageIO, directly and through the importer", test_image_against_oiio},
    {"image/corrupt and oversized images", test_image_errors},
    {NULL, NULL},
};
