/* The previous colour encoder (bench/color_previous.c). */
#ifndef BENCH_COLOR_PREVIOUS_H
#define BENCH_COLOR_PREVIOUS_H
#include <stddef.h>
#include <stdint.h>

/* Encodes with the default options but MAX_ERROR; returns the stream size,
   or 0 when the previous encoder is not built in. */
size_t previous_voxcolor_encode(uint8_t *dst, size_t dst_size, const uint8_t *rgb8, size_t count,
                                double max_error);
#endif
