/* Texture decoding for the vdag tool with stb_image (PNG, JPEG, TGA, BMP and
   PNM), from Debian's libstb-dev header: compiled into the tool, so nothing
   is needed at run time (the Makefile installs the package when the header
   is missing). */
#include "image.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_TGA
#define STBI_ONLY_BMP
#define STBI_ONLY_PNM
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

static int image_fail(const char *path, const char *why, char *err, size_t err_size) {
    if (err_size) snprintf(err, err_size, "%s: %s", path, why);
    return 0;
}

int vdag_image_load_file(FILE *f, const char *path, uint64_t max_pixels, vdag_image *out, char *err,
                         size_t err_size) {
    int w, h, channels;
    size_t i, n;
    uint8_t *rgba, *rgb, *alpha = NULL;
    memset(out, 0, sizeof *out);
    /* The size comes first, so that a small file cannot force a large allocation. */
    if (!stbi_info_from_file(f, &w, &h, &channels))
        return image_fail(path, "not a PNG, JPEG, TGA, BMP or PNM image, or a corrupt one", err, err_size);
    if (w <= 0 || h <= 0 || (uint64_t)w * (uint64_t)h > VDAG_IMAGE_MAX_PIXELS)
        return image_fail(path, "image too large", err, err_size);
    if ((uint64_t)w * (uint64_t)h > max_pixels) {
        out->width = (uint32_t)w;
        out->height = (uint32_t)h;
        return -1;
    }
    rgba = stbi_load_from_file(f, &w, &h, &channels, 4);
    if (!rgba) return image_fail(path, stbi_failure_reason(), err, err_size);
    n = (size_t)w * (size_t)h;
    rgb = (uint8_t *)malloc(3 * n);
    for (i = 0; rgb && i < n; i++) {
        memcpy(rgb + 3 * i, rgba + 4 * i, 3);
        if (rgba[4 * i + 3] != 255 && !alpha && !(alpha = (uint8_t *)malloc(n))) break;
    }
    if (!rgb || (alpha == NULL && i < n)) {
        stbi_image_free(rgba);
        free(rgb);
        return image_fail(path, "out of memory", err, err_size);
    }
    for (i = 0; alpha && i < n; i++) alpha[i] = rgba[4 * i + 3];
    stbi_image_free(rgba);
    out->width = (uint32_t)w;
    out->height = (uint32_t)h;
    out->rgb = rgb;
    out->alpha = alpha;
    return 1;
}

int vdag_image_load(const char *path, vdag_image *out, char *err, size_t err_size) {
    FILE *f;
    int ok;
    memset(out, 0, sizeof *out);
    if (!(f = fopen(path, "rb"))) return image_fail(path, "cannot open the file", err, err_size);
    ok = vdag_image_load_file(f, path, VDAG_IMAGE_MAX_PIXELS, out, err, err_size);
    fclose(f);
    return ok;
}

void vdag_image_free(vdag_image *image) {
    if (!image) return;
    free(image->rgb);
    free(image->alpha);
    memset(image, 0, sizeof *image);
}
