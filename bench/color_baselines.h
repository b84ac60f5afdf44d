/* Reimplementations of published colour-array codecs, measured against
   voxcolor.h by bench/bench_color.c on the same colour arrays:

   - color_alg1:  Dolonius et al. 2017, §4.2: blocks of any length with a
                  32-bit start index and two RGB565 endpoints, fixed 3-bit
                  weights, blocks found by Algorithm 1 (greedy pairwise
                  merging of a linked list of blocks, least-squares fits).
   - color_hdag:  the layout HashDAG (Careil et al. 2020) adopted for the same
                  codec: 64-bit block headers (14-bit start in a macro block
                  of 16,384 colours, 2-bit weight width 1..4 or a single-colour
                  flag, 16-bit weight offset, two RGB565 endpoints), a weight
                  bit stream, per macro block its first block and bit offset;
                  the encoder segments each macro block greedily for each
                  weight width 0..4 and keeps the cheapest.
   - color_dado:  Dado et al. 2016, §4.2-4.3: colours quantized to a global
                  material array (median cut here), blocks with local
                  palettes found by their Algorithm 1, a block directory
                  searched by binary search.

   Each codec owns its encoded form in memory; sizes are counted in bits as
   the papers define them. Lookups return the decoded colour of an index. */
#ifndef COLOR_BASELINES_H
#define COLOR_BASELINES_H

#include <stddef.h>
#include <stdint.h>

typedef struct color_codec color_codec;

/* Encoders. MAX_ERROR: Euclidean RGB distance / 255 each colour must stay
   below (as in the papers; a block of one colour is kept even when its
   quantized endpoints miss the bound). COLORS: palette size for Dado (0:
   lossless). Return NULL when out of memory. */
color_codec *color_alg1_encode(const uint8_t *rgb, size_t n, double max_error);
color_codec *color_hdag_encode(const uint8_t *rgb, size_t n, double max_error);
color_codec *color_dado_encode(const uint8_t *rgb, size_t n, uint32_t colors);

/* Compressed size in bits. */
uint64_t color_codec_bits(const color_codec *c);

/* Decoded colour of element I. */
void color_codec_get(const color_codec *c, size_t i, uint8_t out[3]);

void color_codec_free(color_codec *c);

#endif
