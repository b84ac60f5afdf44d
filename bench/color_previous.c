/* The previous colour encoder, for sizes side by side with the current one
   (bench_color's threads-and-effort table). The Makefile extracts voxcolor.h
   as of commit VOXCOLOR_PREV (the last before the parallel encoder) from this
   repository's history into the build folder; without git history it defines
   BENCH_NO_PREVIOUS and the column reads "-". Compiled in its own unit with
   VOXCOLOR_STATIC, so its names do not meet the current implementation's. */
#include "color_previous.h"

#ifndef BENCH_NO_PREVIOUS
#define VOXCOLOR_STATIC
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor_prev.h"
#include <string.h>

size_t previous_voxcolor_encode(uint8_t *dst, size_t dst_size, const uint8_t *rgb8, size_t count,
                                double max_error) {
    voxcolor_encode_opts o;
    memset(&o, 0, sizeof o);
    o.max_error = max_error;
    return voxcolor_encode(dst, dst_size, rgb8, count, &o);
}
#else
size_t previous_voxcolor_encode(uint8_t *dst, size_t dst_size, const uint8_t *rgb8, size_t count,
                                double max_error) {
    (void)dst, (void)dst_size, (void)rgb8, (void)count, (void)max_error;
    return 0;
}
#endif
