/* Texture decoding left out (programs that read no texture). */
#include "image.h"

#include <stdio.h>
#include <stdlib.h>

int vdag_image_load(const char *path, vdag_image *out, char *err, size_t err_size) {
    out->width = out->height = 0;
    out->rgb = out->alpha = NULL;
    if (err_size) snprintf(err, err_size, "%s: texture decoding not built in", path);
    return 0;
}

int vdag_image_load_file(FILE *f, const char *name, uint64_t max_pixels, vdag_image *out, char *err,
                         size_t err_size) {
    (void)f;
    (void)max_pixels;
    return vdag_image_load(name, out, err, err_size);
}

void vdag_image_free(vdag_image *image) {
    if (!image) return;
    free(image->rgb);
    free(image->alpha);
    image->rgb = image->alpha = NULL;
    image->width = image->height = 0;
}
