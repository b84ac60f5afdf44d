/* Texture images for the vdag tool: decodes a file (PNG, JPEG, ... as the
   build supports) to 8-bit RGB. Two implementations: image_oiio.cpp uses
   OpenImageIO; image_none.c, used when OpenImageIO is not installed, always
   fails with "texture decoding not built in". */
#ifndef VDAG_IMAGE_H
#define VDAG_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Largest image accepted, in pixels (width * height). */
#define VDAG_IMAGE_MAX_PIXELS ((uint64_t)1 << 28)

typedef struct vdag_image {
    uint32_t width, height;
    uint8_t *rgb; /* width*height*3 bytes, rows top to bottom */
} vdag_image;

/* Reads the image at PATH into OUT (grey images become RGB; alpha and extra
   channels are dropped). Returns 1 on success; 0 with a one-line reason in
   ERR (when err_size > 0) and OUT zeroed otherwise. Release with
   vdag_image_free. Thread-safe. */
int vdag_image_load(const char *path, vdag_image *out, char *err, size_t err_size);

/* Frees the pixels of IMAGE (NULL-safe) and zeroes it. */
void vdag_image_free(vdag_image *image);

#ifdef __cplusplus
}
#endif

#endif
