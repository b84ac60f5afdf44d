/* Texture images for the vdag tool: decodes a file (PNG, JPEG, TGA, BMP,
   PNM) to 8-bit RGB and alpha. Two implementations: image_stb.c (the tool's,
   with stb_image) and image_none.c (programs that read no texture: the
   importer fuzz target and benchmarks), which always fails with "texture
   decoding not built in". */
#ifndef VDAG_IMAGE_H
#define VDAG_IMAGE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Largest image accepted, in pixels (width * height). */
#define VDAG_IMAGE_MAX_PIXELS ((uint64_t)1 << 28)

typedef struct vdag_image {
    uint32_t width, height;
    uint8_t *rgb;   /* width*height*3 bytes, rows top to bottom */
    uint8_t *alpha; /* width*height bytes, or NULL when every texel is opaque */
} vdag_image;

/* Reads the image at PATH into OUT (grey images become RGB; alpha is kept
   when some texel is not opaque; 16-bit channels are cut to 8 bits). Returns 1 on success; 0 with a one-line reason in
   ERR (when err_size > 0) and OUT zeroed otherwise. Release with
   vdag_image_free. Thread-safe. */
int vdag_image_load(const char *path, vdag_image *out, char *err, size_t err_size);

/* Like vdag_image_load, from F (open for reading at the image's first byte;
   left open) with NAME in messages, refusing an image of more than
   MAX_PIXELS pixels before decoding it. Returns 1 on success; 0 with a
   reason in ERR when the image cannot be decoded (or is larger than
   VDAG_IMAGE_MAX_PIXELS); -1 when it holds more than MAX_PIXELS pixels
   (but at most VDAG_IMAGE_MAX_PIXELS): OUT then has only its width and
   height set. Thread-safe. */
int vdag_image_load_file(FILE *f, const char *name, uint64_t max_pixels, vdag_image *out, char *err,
                         size_t err_size);

/* Frees the pixels of IMAGE (NULL-safe) and zeroes it. */
void vdag_image_free(vdag_image *image);

#ifdef __cplusplus
}
#endif

#endif
