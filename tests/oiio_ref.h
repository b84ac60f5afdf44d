/* OpenImageIO as the reference decoder of the texture tests (oiio_ref.cpp). */
#ifndef VDAG_OIIO_REF_H
#define VDAG_OIIO_REF_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Decodes PATH to 8-bit RGBA (grey widened, alpha 255 when there is none),
   malloc'd in *RGBA. Returns 1 on success. */
int oiio_ref_load(const char *path, uint32_t *w, uint32_t *h, uint8_t **rgba);

/* Writes W x H pixels of CHANNELS 8-bit channels (2 and 4: the last is
   alpha) to PATH, in the format its extension names; COMPRESSION (may be
   NULL) as OpenImageIO's "compression" attribute ("jpeg:90", "rle"). */
int oiio_ref_write(const char *path, uint32_t w, uint32_t h, int channels, const uint8_t *pixels,
                   const char *compression);

#ifdef __cplusplus
}
#endif

#endif
