/* voxdag_gpu.h - voxdag traversal for GLSL, HLSL and C from one text.      version 0.1.0

   Point lookups, ray casts (closest hit and any hit, with level of detail),
   colours, and cells (voxdag_gpu_cell: a level-of-detail cell's voxel count
   and first index; voxdag_gpu_cell_color: its voxels' mean colour, from the
   colours or the file's level-of-detail colours, FORMAT.md LOD_COLORS) on
   the bytes of a .vdag file (FORMAT.md) as they are: one storage buffer
   holding the file image, zero-padded to a multiple of 4 bytes. No tables, no per-file constants, no shader extension: every 64-bit
   quantity is a pair of 32-bit words, so it runs on any Vulkan 1.1 device.
   Validation stays on the CPU: upload only images that voxdag_load_memory
   (voxdag.h) accepted; on other bytes the functions still terminate, but
   their answers mean nothing.

   TARGETS (define one before including)
     VOXDAG_GPU_GLSL   GLSL 4.50 (Vulkan). Declare the file's storage buffer
                       first and name its uint array:
                         layout(std430, binding = 0) readonly buffer Dag { uint dag_words[]; };
                         #define VOXDAG_GPU_BUFFER dag_words
                         #include "voxdag_gpu.h"
     VOXDAG_GPU_HLSL   HLSL (shader model 6.0 subset; compiled by glslang's
                       HLSL front end in the tests, untested with DXC):
                         StructuredBuffer<uint> dag_words : register(t0);
                         #define VOXDAG_GPU_BUFFER dag_words
     (neither)         C99 or C++: the buffer is a voxdag_gpu_buf, the image
                       bytes and their size (voxdag_image gives both; bytes
                       past the size read as zero). Define VOXDAG_GPU_FUNC to
                       qualify the functions (default: static inline), e.g.
                       for CUDA: __device__ static inline.
   In GLSL and HLSL the buffer argument of every function is a placeholder
   (pass 0u); several files may share one buffer at 4-aligned byte offsets
   below 4 GiB (voxdag_gpu_open's BASE).

   QUICK START (GLSL; HLSL and C alike)
       voxdag_gpu_file f = voxdag_gpu_open(0u, 0u);  // the header, once
       voxdag_gpu_ray r;
       r.ox = ...; r.oy = ...; r.oz = ...;   // grid units: voxel (x, y, z) is
       r.dx = ...; r.dy = ...; r.dz = ...;   // [x, x+1) x [y, y+1) x [z, z+1)
       r.t_min = 0.0; r.t_max = 0.0;         // 0: no limit
       r.lod = 0.0; r.flags = VOXDAG_GPU_WANT_INDEX;
       voxdag_gpu_hit h = voxdag_gpu_raycast(0u, f, r);
       if (h.hit != 0u) { uint rgb = voxdag_gpu_color(0u, f, h.index_lo, h.index_hi); ... }
       // with r.lod > 0.0, a hit may be a cell (h.level < f.levels): its mean colour
       uint mean = voxdag_gpu_cell_color(0u, f, h);  // a voxel's own colour at level L

   PRECISION. Rays are traced in float32 with operations whose rounding is
   fixed (add, subtract, multiply, compare, int to float of integers below
   2^24), marked precise, never producing an infinity, a NaN or a denormal:
   the C build and a conforming GPU give the same bits (the tests check it on
   Mesa's lavapipe). The reciprocal of each direction component comes from
   bit operations and four Newton steps, the same everywhere. Domain: finite
   inputs; a direction component below 2^-64 in magnitude counts as 0, a ray
   with one above 2^32, or an origin coordinate beyond 2^30, misses, and an
   origin coordinate below 2^-32 in magnitude counts as 0; t_min below
   2^-64 in magnitude counts as 0, and so does t_max with
   VOXDAG_GPU_T_MAX_EXCLUSIVE; t limits beyond 2^100 count as 2^100. Against
   voxdag_raycast's exact double-precision answers a hit is the same voxel,
   normal and index except at near-ties: where two planes' t differ by about
   float32 rounding at the grid's scale (2^-24 relative: at 65536^3 about
   0.004 voxel near the far side). Cells and colours are integers only:
   voxdag_gpu_cell and voxdag_gpu_cell_color give voxdag_cell_count's and
   voxdag_cell_color's answers exactly.

   C mode rounds every float operation to float as a GPU does: it sets
   #pragma STDC FP_CONTRACT OFF (clang), keeps products that feed a sum
   apart (GCC contracts under -ffp-contract=fast on FMA targets), and where
   floats are evaluated wider (FLT_EVAL_METHOD 1 or 2: s390x, x87) stores
   every result; it stops with #error where FLT_EVAL_METHOD is negative.
*/
#ifndef VOXDAG_GPU_H
#define VOXDAG_GPU_H

// -- Target layer: types, casts, bit operations, buffer reads

#if defined(VOXDAG_GPU_GLSL)
#define voxdag_gpu_u32 uint
#define voxdag_gpu_i32 int
#define voxdag_gpu_f32 float
#define voxdag_gpu_bool bool
#define voxdag_gpu_buf uint
#define VOXDAG_GPU_FUNC
#define VOXDAG_GPU_PRECISE precise
#define VOXDAG_GPU_U32(x) uint(x)
#define VOXDAG_GPU_F32(x) float(x)
#define VOXDAG_GPU_I32(x) int(x)
#define VOXDAG_GPU_FLOAT_BITS(x) floatBitsToUint(x)
#define VOXDAG_GPU_BITS_FLOAT(x) uintBitsToFloat(x)
#define voxdag_gpui_popcount(x) uint(bitCount(x))
#define voxdag_gpui_msb(x) uint(findMSB(x))
#define voxdag_gpui_word(buf, i) VOXDAG_GPU_BUFFER[i]
#define VOXDAG_GPUI_FALSE false
#define VOXDAG_GPUI_TRUE true
#elif defined(VOXDAG_GPU_HLSL)
#define voxdag_gpu_u32 uint
#define voxdag_gpu_i32 int
#define voxdag_gpu_f32 float
#define voxdag_gpu_bool bool
#define voxdag_gpu_buf uint
#define VOXDAG_GPU_FUNC
#define VOXDAG_GPU_PRECISE precise
#define VOXDAG_GPU_U32(x) ((uint)(x))
#define VOXDAG_GPU_F32(x) ((float)(x))
#define VOXDAG_GPU_I32(x) ((int)(x))
#define VOXDAG_GPU_FLOAT_BITS(x) asuint(x)
#define VOXDAG_GPU_BITS_FLOAT(x) asfloat(x)
#define voxdag_gpui_popcount(x) countbits(x)
#define voxdag_gpui_msb(x) firstbithigh(x)
#define voxdag_gpui_word(buf, i) VOXDAG_GPU_BUFFER[i]
#define VOXDAG_GPUI_FALSE false
#define VOXDAG_GPUI_TRUE true
#else
#define VOXDAG_GPU_C 1
#include <float.h>
#include <stdint.h>
#include <string.h>
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD < 0
#error "voxdag_gpu.h: float arithmetic of unknown precision (FLT_EVAL_METHOD < 0): the traversal's bits could differ from a GPU's"
#endif
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
typedef uint32_t voxdag_gpu_u32;
typedef int32_t voxdag_gpu_i32;
typedef float voxdag_gpu_f32;
typedef int voxdag_gpu_bool;
typedef struct voxdag_gpu_buf {
    const unsigned char *bytes; /* the file image (voxdag_image) */
    uint64_t size;
} voxdag_gpu_buf;
#ifndef VOXDAG_GPU_FUNC
#if defined(_MSC_VER) && !defined(__cplusplus)
#define VOXDAG_GPU_FUNC static __inline
#else
#define VOXDAG_GPU_FUNC static inline
#endif
#endif
#define VOXDAG_GPU_PRECISE
#define VOXDAG_GPUI_FALSE 0
#define VOXDAG_GPUI_TRUE 1
#define VOXDAG_GPU_U32(x) ((uint32_t)(x))
#define VOXDAG_GPU_F32(x) ((float)(x))
#define VOXDAG_GPU_I32(x) ((int32_t)(x))
#define VOXDAG_GPU_FLOAT_BITS(x) voxdag_gpui_float_bits(x)
#define VOXDAG_GPU_BITS_FLOAT(x) voxdag_gpui_bits_float(x)
VOXDAG_GPU_FUNC uint32_t voxdag_gpui_float_bits(float x) {
    uint32_t u;
    memcpy(&u, &x, 4);
    return u;
}
VOXDAG_GPU_FUNC float voxdag_gpui_bits_float(uint32_t u) {
    float x;
    memcpy(&x, &u, 4);
    return x;
}
VOXDAG_GPU_FUNC uint32_t voxdag_gpui_popcount(uint32_t x) {
    x = x - (x >> 1 & 0x55555555u);
    x = (x & 0x33333333u) + (x >> 2 & 0x33333333u);
    return ((x + (x >> 4)) & 0x0F0F0F0Fu) * 0x01010101u >> 24;
}
VOXDAG_GPU_FUNC uint32_t voxdag_gpui_msb(uint32_t x) { /* X > 0 */
    uint32_t n = 0;
    while (x >>= 1) n++;
    return n;
}
/* Word I of the image, little-endian on every host; zeros past its end. */
VOXDAG_GPU_FUNC uint32_t voxdag_gpui_word(voxdag_gpu_buf buf, uint32_t i) {
    uint64_t at = (uint64_t)i * 4;
    uint32_t v = 0, k;
    if (at + 4 <= buf.size) {
        const unsigned char *b = buf.bytes + at;
        return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    }
    for (k = 0; k < 4; k++)
        if (at + k < buf.size) v |= (uint32_t)buf.bytes[at + k] << (8 * k);
    return v;
}
/* Float arithmetic rounded to float after every operation, as on a GPU. A
   product that feeds a sum is stored first (never contracted into an FMA,
   whatever the compiler's default). Where float expressions are evaluated
   wider (FLT_EVAL_METHOD 1, s390x; 2, x87) every result is stored: one
   rounding of the wider result, which for a sum, difference or product of
   two floats is the float result (the wider format has over 2 * 24 + 2
   bits), and the traversal has no denormals or overflows. */
VOXDAG_GPU_FUNC float voxdag_gpui_mul_apart(float a, float b) {
    volatile float r = a * b;
    return r;
}
#if FLT_EVAL_METHOD == 0
#define voxdag_gpui_add(a, b) ((a) + (b))
#define voxdag_gpui_sub(a, b) ((a) - (b))
#define voxdag_gpui_mul(a, b) ((a) * (b))
#else
VOXDAG_GPU_FUNC float voxdag_gpui_add(float a, float b) {
    volatile float r = a + b;
    return r;
}
VOXDAG_GPU_FUNC float voxdag_gpui_sub(float a, float b) {
    volatile float r = a - b;
    return r;
}
#define voxdag_gpui_mul voxdag_gpui_mul_apart
#endif
typedef struct voxdag_gpu_file voxdag_gpu_file;
typedef struct voxdag_gpu_ray voxdag_gpu_ray;
typedef struct voxdag_gpu_hit voxdag_gpu_hit;
typedef struct voxdag_gpu_lookup_result voxdag_gpu_lookup_result;
typedef struct voxdag_gpu_cell_result voxdag_gpu_cell_result;
typedef struct voxdag_gpu_frustum voxdag_gpu_frustum;
#endif

#ifndef VOXDAG_GPU_C /* precise: no contraction, no reassociation */
#define voxdag_gpui_mul_apart(a, b) ((a) * (b))
#define voxdag_gpui_add(a, b) ((a) + (b))
#define voxdag_gpui_sub(a, b) ((a) - (b))
#define voxdag_gpui_mul(a, b) ((a) * (b))
#endif

// -- Public types

#define VOXDAG_GPU_VERSION 1      /* of this header's interface */
#define VOXDAG_GPU_WANT_INDEX 1u  /* voxdag_gpu_ray.flags: fill the hit's voxel index */
#define VOXDAG_GPU_T_MAX_EXCLUSIVE 2u /* flags: the range is [t_min, t_max), t_max as given (0 too),
                                         as voxdag_ray_opts.t_max_exclusive */
#define VOXDAG_GPU_COLORS_NONE 0u /* voxdag_gpu_file.color_kind, as voxdag_color_kind */
#define VOXDAG_GPU_COLORS_RGB8 1u
#define VOXDAG_GPU_COLORS_VOXCOLOR 2u
#define VOXDAG_GPU_NO_COLOR 0xFF000000u /* voxdag_gpu_color without colours */

/* What the queries need of a file, read from its header and section table
   by voxdag_gpu_open (once per invocation). levels is 0 when the bytes are
   not a version-3 .vdag image: every query then misses. */
struct voxdag_gpu_file {
    voxdag_gpu_u32 base;        /* byte offset of the image in the buffer */
    voxdag_gpu_u32 levels;      /* L */
    voxdag_gpu_u32 root_inverse;/* the root transform's inverse */
    voxdag_gpu_u32 level_table; /* byte offsets in the buffer: LEVELS, */
    voxdag_gpu_u32 nodes;       /* NODES, */
    voxdag_gpu_u32 bricks;      /* BRICKS */
    voxdag_gpu_u32 colors;      /* and the colour section's payload */
    voxdag_gpu_u32 color_kind;  /* VOXDAG_GPU_COLORS_* */
    /* the level-of-detail colours (FORMAT.md, LOD_COLORS): where the slots
       start (after the section's header), their kind (VOXDAG_GPU_COLORS_*;
       NONE: no section), the first level covered q0, the level count K and
       the slots per level S */
    voxdag_gpu_u32 lod_slots, lod_kind, lod_first, lod_levels, lod_per_level_lo, lod_per_level_hi;
    voxdag_gpu_u32 voxels_lo, voxels_hi;
    voxdag_gpu_u32 box_lo_x, box_lo_y, box_lo_z, box_hi_x, box_hi_y, box_hi_z; /* half-open */
};

/* A ray in grid units: points o + t d for t in [t_min, t_max] (t_max 0: no
   limit), as voxdag_ray. lod: stop at a full cell whose side is below lod *
   t (voxdag_ray_opts' lod_factor * lod_pixels; 0: full detail). */
struct voxdag_gpu_ray {
    voxdag_gpu_f32 ox, oy, oz, dx, dy, dz, t_min, t_max, lod;
    voxdag_gpu_u32 flags; /* VOXDAG_GPU_WANT_INDEX, VOXDAG_GPU_T_MAX_EXCLUSIVE */
};

/* A ray's answer, as voxdag_hit: hit is 0 on a miss (the rest is then 0). */
struct voxdag_gpu_hit {
    voxdag_gpu_u32 hit;
    voxdag_gpu_f32 t;              /* where the ray enters the cell (t_min when it starts inside) */
    voxdag_gpu_u32 x, y, z;        /* the voxel, or the lowest voxel of the cell */
    voxdag_gpu_i32 nx, ny, nz;     /* entry face normal; 0 0 0 when starting inside */
    voxdag_gpu_u32 level;          /* L for a voxel, lower for a level-of-detail cell */
    voxdag_gpu_u32 index_lo, index_hi; /* voxel index (the cell's first voxel) with WANT_INDEX */
};

struct voxdag_gpu_lookup_result {
    voxdag_gpu_u32 found;
    voxdag_gpu_u32 index_lo, index_hi;
};

/* A cell's voxels, as voxdag_cell_count: their count and the first one's
   index (both 0 for an empty cell); its colours are [first, first + count). */
struct voxdag_gpu_cell_result {
    voxdag_gpu_u32 count_lo, count_hi;
    voxdag_gpu_u32 first_lo, first_hi;
};

// -- Byte and bit-field reads

/* Byte AT of the buffer. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_byte(voxdag_gpu_buf buf, voxdag_gpu_u32 at) {
    return voxdag_gpui_word(buf, at >> 2) >> (8u * (at & 3u)) & 0xFFu;
}

VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_u16(voxdag_gpu_buf buf, voxdag_gpu_u32 at) {
    return voxdag_gpui_byte(buf, at) | voxdag_gpui_byte(buf, at + 1u) << 8u;
}

/* N <= 32 bits from bit POS of the bytes at byte AT, least significant bit
   first; any AT, any POS (a field crosses at most two words). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_bits(voxdag_gpu_buf buf, voxdag_gpu_u32 at, voxdag_gpu_u32 pos,
                                                 voxdag_gpu_u32 n) {
    voxdag_gpu_u32 bit = (at & 3u) * 8u + (pos & 31u);
    voxdag_gpu_u32 word = (at >> 2) + (pos >> 5) + (bit >> 5), v;
    bit &= 31u;
    if (n == 0u) return 0u;
    v = voxdag_gpui_word(buf, word) >> bit;
    if (bit + n > 32u) v |= voxdag_gpui_word(buf, word + 1u) << (32u - bit);
    return n == 32u ? v : v & ((1u << n) - 1u);
}

// -- The 48 cube symmetries, computed (FORMAT.md, Transforms)
//
// T = perm * 8 + m. Permutations as the images of the three axes, two bits
// each, in FORMAT.md's numbering: (0,1,2) (0,2,1) (1,0,2) (1,2,0) (2,0,1) (2,1,0).

VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_perm_images(voxdag_gpu_u32 p) {
    return (p < 4u ? 0x09211824u >> (8u * p) : 0x0612u >> (8u * (p & 3u))) & 0x3Fu;
}

/* The octant I with bit a moved to bit perm[a], for permutation images IMG. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_permute(voxdag_gpu_u32 i, voxdag_gpu_u32 img) {
    return (i & 1u) << (img & 3u) | (i >> 1 & 1u) << (img >> 2 & 3u) | (i >> 2 & 1u) << (img >> 4 & 3u);
}

/* T(i): the octant transform T moves octant I to. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_act(voxdag_gpu_u32 t, voxdag_gpu_u32 i) {
    return voxdag_gpui_permute(i, voxdag_gpui_perm_images(t >> 3)) ^ (t & 7u);
}

/* A o B (B first), from the composed permutation's images. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_compose(voxdag_gpu_u32 a, voxdag_gpu_u32 b) {
    voxdag_gpu_u32 ia = voxdag_gpui_perm_images(a >> 3), ib = voxdag_gpui_perm_images(b >> 3);
    voxdag_gpu_u32 c0 = ia >> (2u * (ib & 3u)) & 3u, c1 = ia >> (2u * (ib >> 2 & 3u)) & 3u;
    /* the permutation from its first two images: key c0 * 3 + c1 in 1..7 */
    voxdag_gpu_u32 p = 0x00B18440u >> (3u * (c0 * 3u + c1)) & 7u;
    return p * 8u + (voxdag_gpui_permute(b & 7u, ia) ^ (a & 7u));
}

VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_inverse(voxdag_gpu_u32 t) {
    voxdag_gpu_u32 p = t >> 3, q = p == 3u ? 4u : p == 4u ? 3u : p; /* 3 and 4 are each other's inverse */
    return q * 8u + voxdag_gpui_permute(t & 7u, voxdag_gpui_perm_images(q));
}

/* Swaps the bit pairs (i, i + D) of X for the positions i in MASK. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_swap(voxdag_gpu_u32 x, voxdag_gpu_u32 mask, voxdag_gpu_u32 d) {
    voxdag_gpu_u32 t = (x >> d ^ x) & mask;
    return x ^ t ^ t << d;
}

/* Octant sets (bit w: octant w) seen through world-to-stored transform MI,
   four bytes at once: bit w of a result byte is bit MI(w) of the same byte.
   MI(w) = perm(w) ^ m: the bytes are reindexed by the mirrors, then by the
   permutation as at most two transpositions of index bits. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_bytes_to_world(voxdag_gpu_u32 x, voxdag_gpu_u32 mi) {
    voxdag_gpu_u32 p = mi >> 3;
    x = voxdag_gpui_swap(x, (mi & 1u) != 0u ? 0x55555555u : 0u, 1u);
    x = voxdag_gpui_swap(x, (mi & 2u) != 0u ? 0x33333333u : 0u, 2u);
    x = voxdag_gpui_swap(x, (mi & 4u) != 0u ? 0x0F0F0F0Fu : 0u, 4u);
    /* transpositions (0 1): positions 1, 5 by 1; (1 2): 2, 3 by 2; (0 2): 1, 3 by 3 */
    if (p == 2u || p == 3u) x = voxdag_gpui_swap(x, 0x22222222u, 1u);
    if (p == 1u || p == 3u || p == 4u) x = voxdag_gpui_swap(x, 0x0C0C0C0Cu, 2u);
    if (p == 4u) x = voxdag_gpui_swap(x, 0x22222222u, 1u);
    if (p == 5u) x = voxdag_gpui_swap(x, 0x0A0A0A0Au, 3u);
    return x;
}

/* A 64-bit value as two words: brick masks, counts, voxel indices. */
struct voxdag_gpui_mask {
    voxdag_gpu_u32 lo, hi;
};
#ifdef VOXDAG_GPU_C
typedef struct voxdag_gpui_mask voxdag_gpui_mask;
#endif

/* The 64-bit swap of bit pairs (i, i + D) for i in the low word's MASK,
   when D is 16 or 24 (the pairs cross words). */
VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_swap_across(voxdag_gpui_mask m, voxdag_gpu_u32 mask, voxdag_gpu_u32 d) {
    voxdag_gpu_u32 t = ((m.lo >> d | m.hi << (32u - d)) ^ m.lo) & mask;
    m.lo ^= t ^ t << d;
    m.hi ^= t >> (32u - d);
    return m;
}

/* A brick mask in world order (FORMAT.md, Bricks): bit p of the result is
   stored bit MI(p), MI acting on both coordinate-bit triples. Bits within
   each byte as above, then the bytes themselves, the same way. */
VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_brick_to_world(voxdag_gpui_mask m, voxdag_gpu_u32 mi) {
    voxdag_gpu_u32 p = mi >> 3, t;
    m.lo = voxdag_gpui_bytes_to_world(m.lo, mi);
    m.hi = voxdag_gpui_bytes_to_world(m.hi, mi);
    /* the bytes: mirrors swap bytes by 1, halves by 2, words by 4 */
    m.lo = voxdag_gpui_swap(m.lo, (mi & 1u) != 0u ? 0x00FF00FFu : 0u, 8u);
    m.hi = voxdag_gpui_swap(m.hi, (mi & 1u) != 0u ? 0x00FF00FFu : 0u, 8u);
    m.lo = voxdag_gpui_swap(m.lo, (mi & 2u) != 0u ? 0x0000FFFFu : 0u, 16u);
    m.hi = voxdag_gpui_swap(m.hi, (mi & 2u) != 0u ? 0x0000FFFFu : 0u, 16u);
    if ((mi & 4u) != 0u) t = m.lo, m.lo = m.hi, m.hi = t;
    /* transpositions of byte-index bits: (0 1) bytes 1, 5 by one byte;
       (1 2) bytes 2, 3 by two; (0 2) bytes 1, 3 by three */
    if (p == 2u || p == 3u) m.lo = voxdag_gpui_swap(m.lo, 0x0000FF00u, 8u), m.hi = voxdag_gpui_swap(m.hi, 0x0000FF00u, 8u);
    if (p == 1u || p == 3u || p == 4u) m = voxdag_gpui_swap_across(m, 0xFFFF0000u, 16u);
    if (p == 4u) m.lo = voxdag_gpui_swap(m.lo, 0x0000FF00u, 8u), m.hi = voxdag_gpui_swap(m.hi, 0x0000FF00u, 8u);
    if (p == 5u) m = voxdag_gpui_swap_across(m, 0xFF00FF00u, 24u);
    return m;
}

// -- Opening a file image

VOXDAG_GPU_FUNC voxdag_gpu_file voxdag_gpu_open(voxdag_gpu_buf buf, voxdag_gpu_u32 base) {
    voxdag_gpu_file f;
    voxdag_gpu_u32 n, k, ok;
    f.base = base;
    f.level_table = 0u, f.nodes = 0u, f.bricks = 0u, f.colors = 0u, f.color_kind = 0u;
    f.lod_slots = 0u, f.lod_kind = 0u, f.lod_first = 0u, f.lod_levels = 0u, f.lod_per_level_lo = 0u, f.lod_per_level_hi = 0u;
    f.box_lo_x = voxdag_gpui_word(buf, (base >> 2) + 14u), f.box_lo_y = voxdag_gpui_word(buf, (base >> 2) + 15u);
    f.box_lo_z = voxdag_gpui_word(buf, (base >> 2) + 16u), f.box_hi_x = voxdag_gpui_word(buf, (base >> 2) + 17u);
    f.box_hi_y = voxdag_gpui_word(buf, (base >> 2) + 18u), f.box_hi_z = voxdag_gpui_word(buf, (base >> 2) + 19u);
    f.voxels_lo = voxdag_gpui_word(buf, (base >> 2) + 8u), f.voxels_hi = voxdag_gpui_word(buf, (base >> 2) + 9u);
    k = voxdag_gpui_word(buf, (base >> 2) + 10u);
    f.levels = k & 0xFFu;
    f.root_inverse = voxdag_gpui_inverse(k >> 8 & 63u);
    ok = voxdag_gpui_word(buf, base >> 2) == 0x41445689u && voxdag_gpui_word(buf, (base >> 2) + 2u) == 3u &&
                 f.levels >= 2u && f.levels <= 21u && (k >> 8 & 0xFFu) < 48u
             ? 1u
             : 0u;
    n = voxdag_gpui_word(buf, (base >> 2) + 11u);
    for (k = 0u; k < n && k < 16u; k++) { /* the section table: type, offset */
        voxdag_gpu_u32 e = (base >> 2) + 24u + 8u * k, type = voxdag_gpui_word(buf, e);
        voxdag_gpu_u32 at = base + voxdag_gpui_word(buf, e + 2u);
        if (type == 1u) f.level_table = at;
        if (type == 2u) f.nodes = at;
        if (type == 3u) f.bricks = at;
        if (type == 4u) f.colors = at, f.color_kind = VOXDAG_GPU_COLORS_RGB8;
        if (type == 5u) f.colors = at, f.color_kind = VOXDAG_GPU_COLORS_VOXCOLOR;
        if (type == 7u) { /* kind, slot shift, q0, K; S at byte 8 */
            voxdag_gpu_u32 head = voxdag_gpui_word(buf, at >> 2);
            f.lod_slots = at + 16u, f.lod_kind = head & 0xFFu, f.lod_first = head >> 16 & 0xFFu, f.lod_levels = head >> 24;
            f.lod_per_level_lo = voxdag_gpui_word(buf, (at >> 2) + 2u), f.lod_per_level_hi = voxdag_gpui_word(buf, (at >> 2) + 3u);
        }
    }
    if (ok == 0u || f.bricks == 0u) f.levels = 0u;
    return f;
}

// -- Node records (FORMAT.md, Node records)

/* A level's description, from its LEVELS entry: where its records start,
   C, P, whether tag 3 marks private children, the three pointer classes'
   code bits K and widths W, and its transform table's place. */
struct voxdag_gpui_level {
    voxdag_gpu_u32 data, count_bits, base_bits, private_children, k1, k2, k3, w1, w2, w3, table;
};
#ifdef VOXDAG_GPU_C
typedef struct voxdag_gpui_level voxdag_gpui_level;
#endif

VOXDAG_GPU_FUNC voxdag_gpui_level voxdag_gpui_level_at(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l) {
    voxdag_gpui_level lv;
    voxdag_gpu_u32 e = f.level_table + 80u * l, a = voxdag_gpui_word(buf, (e >> 2) + 5u);
    voxdag_gpu_u32 b = voxdag_gpui_word(buf, (e >> 2) + 6u), c = voxdag_gpui_word(buf, (e >> 2) + 7u);
    lv.data = f.nodes + voxdag_gpui_word(buf, e >> 2);
    lv.count_bits = a & 0xFFu;
    lv.k1 = b >> 8 & 0xFFu, lv.k2 = b >> 16 & 0xFFu, lv.k3 = b >> 24;
    lv.w1 = (a >> 16 & 0xFFu) + lv.k1, lv.w2 = (a >> 24) + lv.k2, lv.w3 = (b & 0xFFu) + lv.k3;
    lv.private_children = c & 0xFFu;
    lv.base_bits = c >> 8 & 0xFFu;
    lv.table = e + 32u;
    return lv;
}

/* Where level L's records start, and its count bits C: one word each. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_level_data(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l) {
    return f.nodes + voxdag_gpui_word(buf, (f.level_table + 80u * l) >> 2);
}
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_level_count_bits(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l) {
    return voxdag_gpui_word(buf, ((f.level_table + 80u * l) >> 2) + 5u) & 0xFFu;
}

/* The bit where the pointer of stored octant S starts in a record with
   HEADER (S = 8: the record's size in bits): count, base, then the lower
   octants' pointers. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_child_bit(voxdag_gpui_level lv, voxdag_gpu_u32 header, voxdag_gpu_u32 s) {
    voxdag_gpu_u32 h = s >= 8u ? header : header & ((1u << (2u * s)) - 1u);
    voxdag_gpu_u32 lo = h & 0x5555u, hi = h >> 1 & 0x5555u;
    voxdag_gpu_u32 base = (header & header >> 1 & 0x5555u) != 0u && lv.private_children != 0u ? lv.base_bits : 0u;
    return 16u + lv.count_bits + base + lv.w1 * voxdag_gpui_popcount(lo & ~hi) + lv.w2 * voxdag_gpui_popcount(hi & ~lo) +
           lv.w3 * voxdag_gpui_popcount(lo & hi);
}

/* The octants with a child (bit i: tag i non-zero). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_presence(voxdag_gpu_u32 header) {
    voxdag_gpu_u32 x = (header | header >> 1) & 0x5555u;
    x = (x | x >> 1) & 0x3333u;
    x = (x | x >> 2) & 0x0F0Fu;
    return (x | x >> 4) & 0xFFu;
}

/* The child of stored octant S (present) of the record at byte AT of level
   L: its offset in the next level (or its brick index) and the inverse of
   its pointer's transform, what traversals compose. */
struct voxdag_gpui_ref {
    voxdag_gpu_u32 at, inverse;
};
#ifdef VOXDAG_GPU_C
typedef struct voxdag_gpui_ref voxdag_gpui_ref;
#endif

VOXDAG_GPU_FUNC voxdag_gpui_ref voxdag_gpui_child(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l,
                                                  voxdag_gpu_u32 at, voxdag_gpu_u32 header, voxdag_gpu_u32 s) {
    voxdag_gpui_level lv = voxdag_gpui_level_at(buf, f, l);
    voxdag_gpu_u32 tag = header >> (2u * s) & 3u, rec = lv.data + at;
    voxdag_gpui_ref r;
    if (tag == 3u && lv.private_children != 0u) {
        /* the base, then one record (or brick) further per lower private child */
        voxdag_gpu_u32 k = voxdag_gpui_popcount(header & header >> 1 & 0x5555u & ((1u << (2u * s)) - 1u));
        r.at = voxdag_gpui_bits(buf, rec, 16u + lv.count_bits, lv.base_bits < 32u ? lv.base_bits : 32u);
        r.inverse = 0u;
        if (l + 3u < f.levels) {
            voxdag_gpui_level next = voxdag_gpui_level_at(buf, f, l + 1u);
            for (; k > 0u; k--)
                r.at += (voxdag_gpui_child_bit(next, voxdag_gpui_u16(buf, next.data + r.at), 8u) + 7u) >> 3;
        } else {
            r.at += k;
        }
    } else {
        voxdag_gpu_u32 pos = voxdag_gpui_child_bit(lv, header, s);
        voxdag_gpu_u32 kb = tag == 1u ? lv.k1 : tag == 2u ? lv.k2 : lv.k3;
        voxdag_gpu_u32 wb = (tag == 1u ? lv.w1 : tag == 2u ? lv.w2 : lv.w3) - kb;
        voxdag_gpu_u32 code = voxdag_gpui_bits(buf, rec, pos, kb);
        r.at = voxdag_gpui_bits(buf, rec, pos + kb, wb < 32u ? wb : 32u); /* targets of files below 4 GiB */
        r.inverse = voxdag_gpui_inverse(voxdag_gpui_byte(buf, lv.table + code));
    }
    return r;
}

VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_brick(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 index) {
    voxdag_gpui_mask m;
    m.lo = voxdag_gpui_word(buf, (f.bricks >> 2) + 2u * index);
    m.hi = voxdag_gpui_word(buf, (f.bricks >> 2) + 2u * index + 1u);
    return m;
}

// -- Voxel counts and indices (FORMAT.md, Voxel index)

VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_add64(voxdag_gpui_mask a, voxdag_gpu_u32 lo, voxdag_gpu_u32 hi) {
    voxdag_gpu_u32 s = a.lo + lo;
    a.hi += hi + (s < lo ? 1u : 0u);
    a.lo = s;
    return a;
}

/* Voxels below the node at byte AT of level L (brick AT when L = L-2) whose
   level stores its counts. */
VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_stored_count(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l,
                                                          voxdag_gpu_u32 at) {
    voxdag_gpui_mask c;
    if (l + 2u == f.levels) {
        voxdag_gpui_mask m = voxdag_gpui_brick(buf, f, at);
        c.lo = voxdag_gpui_popcount(m.lo) + voxdag_gpui_popcount(m.hi), c.hi = 0u;
    } else {
        voxdag_gpu_u32 n = voxdag_gpui_level_count_bits(buf, f, l), rec = voxdag_gpui_level_data(buf, f, l) + at;
        c.lo = voxdag_gpui_bits(buf, rec, 16u, n < 32u ? n : 32u);
        c.hi = n > 32u ? voxdag_gpui_bits(buf, rec, 48u, n - 32u) : 0u;
    }
    return c;
}

/* A pass over a record's children in stored octant order: each pointer
   starts where the previous one ends, each private child after the
   previous one, so every child costs one step. */
struct voxdag_gpui_walk {
    voxdag_gpu_u32 bit, priv, privs, child; /* child: the last step's offset (or brick index) */
};
#ifdef VOXDAG_GPU_C
typedef struct voxdag_gpui_walk voxdag_gpui_walk;
#endif

VOXDAG_GPU_FUNC voxdag_gpui_walk voxdag_gpui_walk_start(voxdag_gpu_buf buf, voxdag_gpui_level lv, voxdag_gpu_u32 rec,
                                                        voxdag_gpu_u32 header) {
    voxdag_gpui_walk w;
    w.bit = 16u + lv.count_bits, w.priv = 0u, w.privs = 0u, w.child = 0u;
    if ((header & header >> 1 & 0x5555u) != 0u && lv.private_children != 0u) {
        w.priv = voxdag_gpui_bits(buf, rec, w.bit, lv.base_bits < 32u ? lv.base_bits : 32u);
        w.bit += lv.base_bits;
    }
    return w;
}

/* The child of present stored octant S, after the walk's lower octants. */
VOXDAG_GPU_FUNC voxdag_gpui_walk voxdag_gpui_walk_step(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l,
                                                       voxdag_gpui_level lv, voxdag_gpu_u32 rec, voxdag_gpu_u32 header,
                                                       voxdag_gpu_u32 s, voxdag_gpui_walk w) {
    voxdag_gpu_u32 tag = header >> (2u * s) & 3u;
    if (tag == 3u && lv.private_children != 0u) {
        if (w.privs > 0u) {
            if (l + 3u < f.levels) {
                voxdag_gpui_level next = voxdag_gpui_level_at(buf, f, l + 1u);
                w.priv += (voxdag_gpui_child_bit(next, voxdag_gpui_u16(buf, next.data + w.priv), 8u) + 7u) >> 3;
            } else {
                w.priv++;
            }
        }
        w.privs++;
        w.child = w.priv;
    } else {
        voxdag_gpu_u32 k = tag == 1u ? lv.k1 : tag == 2u ? lv.k2 : lv.k3;
        voxdag_gpu_u32 width = tag == 1u ? lv.w1 : tag == 2u ? lv.w2 : lv.w3;
        w.child = voxdag_gpui_bits(buf, rec, w.bit + k, width - k < 32u ? width - k : 32u);
        w.bit += width;
    }
    return w;
}

/* Voxels below the node at byte AT of level L (or brick AT): stored, or the
   sum of its children's (C = 0), which their level stores. */
VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_count(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l,
                                                   voxdag_gpu_u32 at) {
    voxdag_gpui_mask sum;
    voxdag_gpui_level lv;
    voxdag_gpui_walk w;
    voxdag_gpu_u32 header, s;
    if (l + 2u == f.levels || voxdag_gpui_level_count_bits(buf, f, l) != 0u) return voxdag_gpui_stored_count(buf, f, l, at);
    lv = voxdag_gpui_level_at(buf, f, l);
    header = voxdag_gpui_u16(buf, lv.data + at);
    w = voxdag_gpui_walk_start(buf, lv, lv.data + at, header);
    sum.lo = 0u, sum.hi = 0u;
    for (s = 0u; s < 8u; s++)
        if ((header >> (2u * s) & 3u) != 0u) {
            voxdag_gpui_mask c;
            w = voxdag_gpui_walk_step(buf, f, l, lv, lv.data + at, header, s, w);
            c = voxdag_gpui_stored_count(buf, f, l + 1u, w.child);
            sum = voxdag_gpui_add64(sum, c.lo, c.hi);
        }
    return sum;
}

/* The voxels of the children of the record at AT (level L, HEADER, reached
   with world-to-stored transform MI) in world octants below W. */
VOXDAG_GPU_FUNC voxdag_gpui_mask voxdag_gpui_preceding(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 l,
                                                       voxdag_gpu_u32 at, voxdag_gpu_u32 header, voxdag_gpu_u32 mi,
                                                       voxdag_gpu_u32 w) {
    voxdag_gpui_level lv = voxdag_gpui_level_at(buf, f, l);
    voxdag_gpui_walk walk = voxdag_gpui_walk_start(buf, lv, lv.data + at, header);
    voxdag_gpui_mask sum;
    voxdag_gpu_u32 set = 0u, j, s;
    for (j = 0u; j < w; j++) set |= 1u << voxdag_gpui_act(mi, j); /* the stored octants before W */
    set &= voxdag_gpui_presence(header);
    sum.lo = 0u, sum.hi = 0u;
    for (s = 0u; (set >> s) != 0u; s++)
        if ((header >> (2u * s) & 3u) != 0u) {
            walk = voxdag_gpui_walk_step(buf, f, l, lv, lv.data + at, header, s, walk);
            if ((set >> s & 1u) != 0u) {
                voxdag_gpui_mask c = voxdag_gpui_count(buf, f, l + 1u, walk.child);
                sum = voxdag_gpui_add64(sum, c.lo, c.hi);
            }
        }
    return sum;
}

/* Voxels of world-order brick mask M before Morton position P (<= 64). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_before(voxdag_gpui_mask m, voxdag_gpu_u32 p) {
    if (p >= 64u) return voxdag_gpui_popcount(m.lo) + voxdag_gpui_popcount(m.hi);
    if (p >= 32u) return voxdag_gpui_popcount(m.lo) + voxdag_gpui_popcount(m.hi & ((1u << (p - 32u)) - 1u));
    return voxdag_gpui_popcount(m.lo & ((1u << p) - 1u));
}

/* Morton position in a brick of the voxel (X, Y, Z). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_brick_pos(voxdag_gpu_u32 x, voxdag_gpu_u32 y, voxdag_gpu_u32 z) {
    return (x & 1u) | (y & 1u) << 1 | (z & 1u) << 2 | (x & 2u) << 2 | (y & 2u) << 3 | (z & 2u) << 4;
}

// -- Cells and point lookup

/* The voxels of the level-Q cell (a cube 2^(L-Q) voxels a side; Q = L: one
   voxel) holding voxel (X, Y, Z), as voxdag_cell_count: a descent as
   voxdag_lookup's down to the cell's record, or into its brick for
   Q >= L-2. Count 0 for an empty cell, a point outside the grid or Q > L. */
VOXDAG_GPU_FUNC voxdag_gpu_cell_result voxdag_gpu_cell(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 q,
                                                       voxdag_gpu_u32 x, voxdag_gpu_u32 y, voxdag_gpu_u32 z) {
    voxdag_gpu_cell_result r;
    voxdag_gpui_mask idx, n;
    voxdag_gpu_u32 l, at = 0u, mi = f.root_inverse;
    r.count_lo = 0u, r.count_hi = 0u, r.first_lo = 0u, r.first_hi = 0u;
    idx.lo = 0u, idx.hi = 0u;
    if (f.levels == 0u || (f.voxels_lo | f.voxels_hi) == 0u || q > f.levels || ((x | y | z) >> f.levels) != 0u) return r;
    for (l = 0u; l < q && l + 2u < f.levels; l++) {
        voxdag_gpu_u32 sh = f.levels - 1u - l, w = (x >> sh & 1u) | (y >> sh & 1u) << 1 | (z >> sh & 1u) << 2;
        voxdag_gpu_u32 header = voxdag_gpui_u16(buf, voxdag_gpui_level_data(buf, f, l) + at), s = voxdag_gpui_act(mi, w);
        voxdag_gpui_mask m;
        voxdag_gpui_ref ref;
        if ((header >> (2u * s) & 3u) == 0u) return r;
        m = voxdag_gpui_preceding(buf, f, l, at, header, mi, w);
        idx = voxdag_gpui_add64(idx, m.lo, m.hi);
        ref = voxdag_gpui_child(buf, f, l, at, header, s);
        mi = voxdag_gpui_compose(ref.inverse, mi);
        at = ref.at;
    }
    if (q + 2u < f.levels) {
        n = voxdag_gpui_count(buf, f, q, at);
    } else { /* in the brick: the cell's 8^(L-Q) Morton positions from P */
        voxdag_gpui_mask m = voxdag_gpui_brick_to_world(voxdag_gpui_brick(buf, f, at), mi);
        voxdag_gpu_u32 size = 1u << (3u * (f.levels - q)), p = voxdag_gpui_brick_pos(x, y, z) & (64u - size);
        idx = voxdag_gpui_add64(idx, voxdag_gpui_before(m, p), 0u);
        n.lo = voxdag_gpui_before(m, p + size) - voxdag_gpui_before(m, p), n.hi = 0u;
    }
    if ((n.lo | n.hi) == 0u) return r;
    r.count_lo = n.lo, r.count_hi = n.hi, r.first_lo = idx.lo, r.first_hi = idx.hi;
    return r;
}

/* Whether voxel (X, Y, Z) is full, and its index. */
VOXDAG_GPU_FUNC voxdag_gpu_lookup_result voxdag_gpu_lookup(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 x,
                                                           voxdag_gpu_u32 y, voxdag_gpu_u32 z) {
    voxdag_gpu_cell_result c = voxdag_gpu_cell(buf, f, f.levels, x, y, z);
    voxdag_gpu_lookup_result r;
    r.found = c.count_lo, r.index_lo = c.first_lo, r.index_hi = c.first_hi;
    return r;
}

// -- Ray casting
//
// The hierarchical integer DDA of voxdag_raycast in float32 (voxdag.h, Ray
// casting): cells c at cell level q, the ray's entry event (te, ae), every t
// from a plane as (plane - origin) * reciprocal, so a plane has one t at
// every level; after a step the highest changed bit of c names the level to
// return to. Levels 0 .. L-3 are records; a brick is walked as a node of
// 2^3 cells (a byte of its world-order mask each), and each cell as a node
// of 8 voxels. Per level the walk keeps the record, header, transform and
// world occupancy to return to, which also give the voxel index at the hit.

#define VOXDAG_GPU_MAX_LEVELS 21
#define VOXDAG_GPUI_FAR VOXDAG_GPU_BITS_FLOAT(0x7B800000u)   /* 2^120: the t of a plane never met */
#define VOXDAG_GPUI_LIMIT VOXDAG_GPU_BITS_FLOAT(0x71800000u) /* 2^100: t limits are clamped to it */

/* The reciprocal of D (2^-64 <= |D| <= 2^32): a first guess from the bits,
   then four Newton steps (relative error 12 %, 1.4e-2, 2e-4, 4e-8, then
   rounding), the same bits on every target. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_recip(voxdag_gpu_f32 d) {
    voxdag_gpu_u32 bits = VOXDAG_GPU_FLOAT_BITS(d), k;
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 a = VOXDAG_GPU_BITS_FLOAT(bits & 0x7FFFFFFFu);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 r = VOXDAG_GPU_BITS_FLOAT(0x7EF311C3u - (bits & 0x7FFFFFFFu));
    for (k = 0u; k < 4u; k++) {
        VOXDAG_GPU_PRECISE voxdag_gpu_f32 e = voxdag_gpui_sub(2.0f, voxdag_gpui_mul_apart(a, r));
        r = voxdag_gpui_mul(r, e);
    }
    return VOXDAG_GPU_BITS_FLOAT(VOXDAG_GPU_FLOAT_BITS(r) | (bits & 0x80000000u));
}

/* X with magnitudes below 2^-E2 flushed to 0 (E2 as a biased exponent
   bound), for the domain rules. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_flush(voxdag_gpu_f32 x, voxdag_gpu_u32 min_bits) {
    return (VOXDAG_GPU_FLOAT_BITS(x) & 0x7FFFFFFFu) < min_bits ? 0.0f : x;
}

/* X clamped to [-2^100, 2^100] (infinities too). */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_clamp_t(voxdag_gpu_f32 x) {
    voxdag_gpu_u32 bits = VOXDAG_GPU_FLOAT_BITS(x);
    return (bits & 0x7FFFFFFFu) >= 0x71800000u ? VOXDAG_GPU_BITS_FLOAT((bits & 0x80000000u) | 0x71800000u) : x;
}

/* The largest float below X, for X within the domain (0 or of magnitude at
   least 2^-64): a plane's t is 0 or at least 2^-87 in magnitude (|o| at
   least 2^-32 or 0, |d| at most 2^32), so below 0 the largest negative
   normal float, -2^-126, serves: no t lies between it and 0. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_below(voxdag_gpu_f32 x) {
    voxdag_gpu_u32 bits = VOXDAG_GPU_FLOAT_BITS(x);
    return x > 0.0f ? VOXDAG_GPU_BITS_FLOAT(bits - 1u) : x < 0.0f ? VOXDAG_GPU_BITS_FLOAT(bits + 1u) : VOXDAG_GPU_BITS_FLOAT(0x80800000u);
}

VOXDAG_GPU_FUNC voxdag_gpu_bool voxdag_gpui_is_nan(voxdag_gpu_f32 x) {
    return (VOXDAG_GPU_FLOAT_BITS(x) & 0x7FFFFFFFu) > 0x7F800000u;
}

/* One axis of a ray: origin, reciprocal direction, sign (0: the ray does not
   move along it), and the t where it enters and leaves [LO, HI]; bad when
   the input is outside the domain. */
struct voxdag_gpui_axis {
    voxdag_gpu_f32 o, ix, t0, t1;
    voxdag_gpu_i32 sgn;
    voxdag_gpu_u32 bad;
};
#ifdef VOXDAG_GPU_C
typedef struct voxdag_gpui_axis voxdag_gpui_axis;
#endif

VOXDAG_GPU_FUNC voxdag_gpui_axis voxdag_gpui_axis_setup(voxdag_gpu_f32 o, voxdag_gpu_f32 d, voxdag_gpu_f32 lo,
                                                        voxdag_gpu_f32 hi) {
    voxdag_gpui_axis x;
    voxdag_gpu_u32 ob = VOXDAG_GPU_FLOAT_BITS(o) & 0x7FFFFFFFu, db = VOXDAG_GPU_FLOAT_BITS(d) & 0x7FFFFFFFu;
    x.bad = ob >= 0x4E800000u || db > 0x4F800000u ? 1u : 0u; /* |o| >= 2^30, |d| > 2^32, NaN, infinite */
    x.o = voxdag_gpui_flush(o, 0x2F800000u);                 /* |o| < 2^-32: 0 */
    d = voxdag_gpui_flush(d, 0x1F800000u);                   /* |d| < 2^-64: 0 */
    x.ix = 0.0f, x.t0 = -VOXDAG_GPUI_FAR, x.t1 = VOXDAG_GPUI_FAR, x.sgn = 0;
    if (d == 0.0f) {
        if (!(x.o >= lo && x.o < hi)) x.bad = 1u;
    } else {
        VOXDAG_GPU_PRECISE voxdag_gpu_f32 t0, t1;
        x.sgn = d > 0.0f ? 1 : -1;
        x.ix = voxdag_gpui_recip(d);
        t0 = voxdag_gpui_mul(voxdag_gpui_sub(d > 0.0f ? lo : hi, x.o), x.ix);
        t1 = voxdag_gpui_mul(voxdag_gpui_sub(d > 0.0f ? hi : lo, x.o), x.ix);
        x.t0 = t0, x.t1 = t1;
    }
    return x;
}

/* The t at which axis X meets the plane at integer coordinate PLANE (FAR
   when it does not move along it). */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_plane_t(voxdag_gpui_axis x, voxdag_gpu_u32 plane) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 t = voxdag_gpui_mul(voxdag_gpui_sub(VOXDAG_GPU_F32(plane), x.o), x.ix);
    return x.sgn == 0 ? VOXDAG_GPUI_FAR : t;
}

/* The child cell along axis X (number B) of cell coordinate C, entering at
   (TE, AE): 1 when the ray is past the mid plane MID by then. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_upper(voxdag_gpui_axis x, voxdag_gpu_u32 mid, voxdag_gpu_f32 te,
                                                 voxdag_gpu_u32 ae, voxdag_gpu_u32 b) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 tm = voxdag_gpui_mul(voxdag_gpui_sub(VOXDAG_GPU_F32(mid), x.o), x.ix);
    voxdag_gpu_bool crossed = tm < te || (tm == te && b <= ae); /* b = ae: the box entered there */
    if (x.sgn == 0) return x.o >= VOXDAG_GPU_F32(mid) ? 1u : 0u;
    return (x.sgn > 0) == crossed ? 1u : 0u;
}

VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_octant(voxdag_gpu_u32 cx, voxdag_gpu_u32 cy, voxdag_gpu_u32 cz) {
    return (cx & 1u) | (cy & 1u) << 1 | (cz & 1u) << 2;
}

VOXDAG_GPU_FUNC voxdag_gpu_hit voxdag_gpui_trace(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_ray ray,
                                                 voxdag_gpu_bool any_hit) {
    voxdag_gpu_hit h;
    voxdag_gpui_axis x0, x1, x2;
    voxdag_gpu_u32 fr_at[VOXDAG_GPU_MAX_LEVELS], fr_info[VOXDAG_GPU_MAX_LEVELS];
    voxdag_gpu_u32 nl = f.levels, bl = nl - 2u, q = 0u, l = 0u, a, b, ae = 0u, ax = 0u, mi = f.root_inverse;
    voxdag_gpu_u32 cx = 0u, cy = 0u, cz = 0u, at = 0u, header = 0u, occ = 0u;
    voxdag_gpui_mask mask;
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 te = -VOXDAG_GPUI_FAR, tx = VOXDAG_GPUI_FAR, t_stop, t_min, t_max, lod;
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 hi;
    h.hit = 0u, h.t = 0.0f, h.x = 0u, h.y = 0u, h.z = 0u, h.nx = 0, h.ny = 0, h.nz = 0, h.level = 0u;
    h.index_lo = 0u, h.index_hi = 0u;
    mask.lo = 0u, mask.hi = 0u;
    if (nl == 0u || (f.voxels_lo | f.voxels_hi) == 0u) return h;
    if (voxdag_gpui_is_nan(ray.t_min) || voxdag_gpui_is_nan(ray.t_max) || voxdag_gpui_is_nan(ray.lod)) return h;
    /* the domain: t limits within 2^100, t_min (and an exclusive t_max)
       below 2^-64 zero, t_max 0 none unless exclusive, lod 0 or within
       [2^-20, 2^20] */
    t_min = voxdag_gpui_flush(voxdag_gpui_clamp_t(ray.t_min), 0x1F800000u);
    if ((ray.flags & VOXDAG_GPU_T_MAX_EXCLUSIVE) != 0u) { /* t < t_max: t <= the float below it */
        t_max = voxdag_gpui_flush(voxdag_gpui_clamp_t(ray.t_max), 0x1F800000u);
        if (!(t_min < t_max)) return h;
        t_max = voxdag_gpui_below(t_max);
    } else {
        t_max = (VOXDAG_GPU_FLOAT_BITS(ray.t_max) & 0x7FFFFFFFu) == 0u ? VOXDAG_GPUI_LIMIT : voxdag_gpui_clamp_t(ray.t_max);
    }
    lod = !(ray.lod > 0.0f) ? 0.0f : voxdag_gpui_flush(ray.lod < 1048576.0f ? ray.lod : 1048576.0f, 0x35800000u);
    /* the voxel box without level of detail (a hit is a voxel, inside it),
       else the grid (a coarse cell may reach outside the box) */
    hi = VOXDAG_GPU_F32(1u << nl);
    x0 = voxdag_gpui_axis_setup(ray.ox, ray.dx, lod > 0.0f ? 0.0f : VOXDAG_GPU_F32(f.box_lo_x), lod > 0.0f ? hi : VOXDAG_GPU_F32(f.box_hi_x));
    x1 = voxdag_gpui_axis_setup(ray.oy, ray.dy, lod > 0.0f ? 0.0f : VOXDAG_GPU_F32(f.box_lo_y), lod > 0.0f ? hi : VOXDAG_GPU_F32(f.box_hi_y));
    x2 = voxdag_gpui_axis_setup(ray.oz, ray.dz, lod > 0.0f ? 0.0f : VOXDAG_GPU_F32(f.box_lo_z), lod > 0.0f ? hi : VOXDAG_GPU_F32(f.box_hi_z));
    if ((x0.bad | x1.bad | x2.bad) != 0u) return h;
    /* on ties the last axis enters last and the first leaves first */
    if (x0.sgn != 0 && x0.t0 >= te) te = x0.t0, ae = 0u;
    if (x1.sgn != 0 && x1.t0 >= te) te = x1.t0, ae = 1u;
    if (x2.sgn != 0 && x2.t0 >= te) te = x2.t0, ae = 2u;
    if (x0.t1 < tx) tx = x0.t1, ax = 0u;
    if (x1.t1 < tx) tx = x1.t1, ax = 1u;
    if (x2.t1 < tx) tx = x2.t1, ax = 2u;
    if (t_min >= te) te = t_min, ae = 3u;
    if (tx < te || (tx == te && ax < ae) || te > t_max) return h;
    t_stop = tx == VOXDAG_GPUI_FAR ? te : t_max < tx ? t_max : tx;

    for (;;) {
        /* Enter node l, cell c of level q = l: its occupancy in world order. */
        voxdag_gpu_u32 sh = nl - q - 1u;
        if (l < bl) {
            header = voxdag_gpui_u16(buf, voxdag_gpui_level_data(buf, f, l) + at);
            occ = voxdag_gpui_bytes_to_world(voxdag_gpui_presence(header), mi) & 0xFFu;
            fr_at[l] = at;
            fr_info[l] = header | mi << 16 | occ << 24;
        } else {
            if (l == bl) { /* the brick: its 2^3 cells, full when a byte is */
                mask = voxdag_gpui_brick_to_world(voxdag_gpui_brick(buf, f, at), mi);
                occ = 0u;
                for (b = 0u; b < 8u; b++) occ |= ((b < 4u ? mask.lo : mask.hi) >> (8u * (b & 3u)) & 0xFFu) != 0u ? 1u << b : 0u;
            } else { /* a 2^3 cell: its byte */
                b = voxdag_gpui_octant(cx, cy, cz);
                occ = (b < 4u ? mask.lo : mask.hi) >> (8u * (b & 3u)) & 0xFFu;
            }
            fr_info[l] = occ << 24;
        }
        /* The child cell: which mid planes (te, ae) has crossed. */
        cx = 2u * cx + voxdag_gpui_upper(x0, (2u * cx + 1u) << sh, te, ae, 0u);
        cy = 2u * cy + voxdag_gpui_upper(x1, (2u * cy + 1u) << sh, te, ae, 1u);
        cz = 2u * cz + voxdag_gpui_upper(x2, (2u * cz + 1u) << sh, te, ae, 2u);
        q++;
        /* Step through the node's cells until a full one. */
        for (;;) {
            VOXDAG_GPU_PRECISE voxdag_gpu_f32 t, t1, t2;
            voxdag_gpu_u32 old, moved;
            voxdag_gpu_i32 k;
            if ((occ >> voxdag_gpui_octant(cx, cy, cz) & 1u) != 0u) break;
            sh = nl - q;
            t = voxdag_gpui_plane_t(x0, (cx + (x0.sgn > 0 ? 1u : 0u)) << sh);
            t1 = voxdag_gpui_plane_t(x1, (cy + (x1.sgn > 0 ? 1u : 0u)) << sh);
            t2 = voxdag_gpui_plane_t(x2, (cz + (x2.sgn > 0 ? 1u : 0u)) << sh);
            a = 0u;
            if (t1 < t) t = t1, a = 1u;
            if (t2 < t) t = t2, a = 2u;
            if (!(t <= t_stop)) return h;
            old = a == 0u ? cx : a == 1u ? cy : cz;
            moved = (a == 0u ? x0.sgn : a == 1u ? x1.sgn : x2.sgn) > 0 ? old + 1u : old - 1u;
            if (a == 0u) cx = moved;
            if (a == 1u) cy = moved;
            if (a == 2u) cz = moved;
            te = t, ae = a;
            sh = voxdag_gpui_msb(old ^ moved);
            k = VOXDAG_GPU_I32(q) - 1 - VOXDAG_GPU_I32(sh); /* the node level whose child changed */
            if (k < VOXDAG_GPU_I32(l)) {
                if (k < 0) return h; /* left the grid */
                cx >>= sh, cy >>= sh, cz >>= sh;
                q -= sh, l = VOXDAG_GPU_U32(k);
                occ = fr_info[l] >> 24;
                if (l < bl) at = fr_at[l], header = fr_info[l] & 0xFFFFu, mi = fr_info[l] >> 16 & 63u;
            }
        }
        /* Cell c of level q is full: a hit, or go down into it. */
        if (q == nl || VOXDAG_GPU_F32(1u << (nl - q)) < voxdag_gpui_mul(lod, te)) {
            h.hit = 1u;
            if (any_hit) return h;
            h.t = te;
            h.x = cx << (nl - q), h.y = cy << (nl - q), h.z = cz << (nl - q);
            h.nx = ae == 0u ? -x0.sgn : 0, h.ny = ae == 1u ? -x1.sgn : 0, h.nz = ae == 2u ? -x2.sgn : 0;
            h.level = q;
            if ((ray.flags & VOXDAG_GPU_WANT_INDEX) != 0u) {
                /* the voxels of all preceding siblings on the path */
                voxdag_gpui_mask idx;
                voxdag_gpu_u32 top = q < bl ? q : bl, j;
                idx.lo = 0u, idx.hi = 0u;
                for (j = 0u; j < top; j++) {
                    voxdag_gpu_u32 s = q - 1u - j;
                    voxdag_gpui_mask m = voxdag_gpui_preceding(buf, f, j, fr_at[j], fr_info[j] & 0xFFFFu, fr_info[j] >> 16 & 63u,
                                                               voxdag_gpui_octant(cx >> s, cy >> s, cz >> s));
                    idx = voxdag_gpui_add64(idx, m.lo, m.hi);
                }
                if (q > bl) idx = voxdag_gpui_add64(idx, voxdag_gpui_before(mask, voxdag_gpui_brick_pos(h.x, h.y, h.z)), 0u);
                h.index_lo = idx.lo, h.index_hi = idx.hi;
            }
            return h;
        }
        if (l < bl) {
            voxdag_gpui_ref ref = voxdag_gpui_child(buf, f, l, at, header, voxdag_gpui_act(mi, voxdag_gpui_octant(cx, cy, cz)));
            mi = voxdag_gpui_compose(ref.inverse, mi);
            at = ref.at;
        }
        l++;
    }
}

/* The first full voxel (or level-of-detail cell) along RAY. */
VOXDAG_GPU_FUNC voxdag_gpu_hit voxdag_gpu_raycast(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_ray ray) {
    return voxdag_gpui_trace(buf, f, ray, VOXDAG_GPUI_FALSE);
}

/* Whether any full voxel (or level-of-detail cell, with ray.lod) lies along
   RAY, as voxdag_occluded_opts: 1 or 0. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpu_occluded(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_ray ray) {
    return voxdag_gpui_trace(buf, f, ray, VOXDAG_GPUI_TRUE).hit;
}

// -- Frustum depth (beams)
//
// A lower bound of the depth at which any ray of a frustum (a block of
// pixels) meets a full voxel: a depth-first walk, nearest octant first, of
// the cells that the frustum's four side planes do not exclude, pruned by
// the best depth so far. A full cell becomes a candidate at its nearest
// corner once it is no wider than the frustum (WIDTH times its far depth) or
// than a level-of-detail cell there, and bricks are tested voxel by voxel,
// so the bound never passes a voxel (or level-of-detail cell) that a ray of
// the frustum would hit. Rays started there (t_min) give the same answers.
// The bound is conservative, not bit-exact: its arithmetic is not marked
// precise (glslang's precise analysis of this walk takes minutes and
// gigabytes), and its margins cover any contraction.

#define VOXDAG_GPUI_STACK (7u * VOXDAG_GPU_MAX_LEVELS + 1u)

/* Apex o, unit view axis f (depth is f . (p - o)), and inward normals of
   the four side planes through o; width: the frustum's side per unit of
   depth; lod as voxdag_gpu_ray's. */
struct voxdag_gpu_frustum {
    voxdag_gpu_f32 ox, oy, oz, fx, fy, fz, lod, width;
    voxdag_gpu_f32 n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z, n3x, n3y, n3z;
};

/* A . B for (AX, AY, AZ) and a box corner chosen per axis. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_dot(voxdag_gpu_f32 ax, voxdag_gpu_f32 ay, voxdag_gpu_f32 az, voxdag_gpu_f32 bx,
                                               voxdag_gpu_f32 by, voxdag_gpu_f32 bz) {
    voxdag_gpu_f32 d =
        voxdag_gpui_add(voxdag_gpui_add(voxdag_gpui_mul_apart(ax, bx), voxdag_gpui_mul_apart(ay, by)), voxdag_gpui_mul_apart(az, bz));
    return d;
}

/* The largest N . (p - o) over the box [LO, LO + S)^3 (relative to o: X, Y, Z). */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_box_max(voxdag_gpu_f32 nx, voxdag_gpu_f32 ny, voxdag_gpu_f32 nz, voxdag_gpu_f32 x,
                                                   voxdag_gpu_f32 y, voxdag_gpu_f32 z, voxdag_gpu_f32 s) {
    return voxdag_gpui_dot(nx, ny, nz, nx > 0.0f ? voxdag_gpui_add(x, s) : x, ny > 0.0f ? voxdag_gpui_add(y, s) : y,
                           nz > 0.0f ? voxdag_gpui_add(z, s) : z);
}

/* Whether box (X, Y, Z) + [0, S)^3 relative to the apex may meet the
   frustum: on the inner side of every plane within MARGIN, not behind. */
VOXDAG_GPU_FUNC voxdag_gpu_bool voxdag_gpui_box_in(voxdag_gpu_frustum fr, voxdag_gpu_f32 x, voxdag_gpu_f32 y,
                                                   voxdag_gpu_f32 z, voxdag_gpu_f32 s, voxdag_gpu_f32 margin) {
    return voxdag_gpui_box_max(fr.n0x, fr.n0y, fr.n0z, x, y, z, s) >= -margin &&
           voxdag_gpui_box_max(fr.n1x, fr.n1y, fr.n1z, x, y, z, s) >= -margin &&
           voxdag_gpui_box_max(fr.n2x, fr.n2y, fr.n2z, x, y, z, s) >= -margin &&
           voxdag_gpui_box_max(fr.n3x, fr.n3y, fr.n3z, x, y, z, s) >= -margin &&
           voxdag_gpui_box_max(fr.fx, fr.fy, fr.fz, x, y, z, s) >= -margin;
}

/* The nearest depth of box (X, Y, Z) + [0, S)^3 relative to the apex. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpui_box_near(voxdag_gpu_frustum fr, voxdag_gpu_f32 x, voxdag_gpu_f32 y,
                                                    voxdag_gpu_f32 z, voxdag_gpu_f32 s) {
    return -voxdag_gpui_box_max(-fr.fx, -fr.fy, -fr.fz, x, y, z, s);
}

/* A depth below which no ray of FR meets a full voxel of F (0 when one may
   at once, 2^100 when none does); rays t = depth / (f . d) started a little
   before it (see the kernel) give the answers they would from 0. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 voxdag_gpu_frustum_depth(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_frustum fr) {
    voxdag_gpu_u32 st_at[VOXDAG_GPUI_STACK], st_info[VOXDAG_GPUI_STACK], st_x[VOXDAG_GPUI_STACK],
        st_y[VOXDAG_GPUI_STACK], st_z[VOXDAG_GPUI_STACK];
    voxdag_gpu_u32 sp = 1u, nl = f.levels, nearest = 0u;
    voxdag_gpu_f32 best = VOXDAG_GPUI_LIMIT, margin;
    if (nl == 0u || (f.voxels_lo | f.voxels_hi) == 0u) return best;
    margin = VOXDAG_GPU_F32(1u << nl) * 0.00024414062f; /* 2^-12 of the grid: float rounding of the tests */
    nearest |= fr.fx < 0.0f ? 1u : 0u, nearest |= fr.fy < 0.0f ? 2u : 0u, nearest |= fr.fz < 0.0f ? 4u : 0u;
    st_at[0] = 0u, st_info[0] = f.root_inverse << 8, st_x[0] = 0u, st_y[0] = 0u, st_z[0] = 0u;
    while (sp > 0u) {
        voxdag_gpu_u32 at, q, mi, cx, cy, cz, k;
        voxdag_gpu_f32 s, x, y, z, d_near, d_far;
        sp--;
        at = st_at[sp], q = st_info[sp] & 31u, mi = st_info[sp] >> 8, cx = st_x[sp], cy = st_y[sp], cz = st_z[sp];
        s = VOXDAG_GPU_F32(1u << (nl - q));
        x = voxdag_gpui_sub(voxdag_gpui_mul(VOXDAG_GPU_F32(cx), s), fr.ox);
        y = voxdag_gpui_sub(voxdag_gpui_mul(VOXDAG_GPU_F32(cy), s), fr.oy);
        z = voxdag_gpui_sub(voxdag_gpui_mul(VOXDAG_GPU_F32(cz), s), fr.oz);
        if (!voxdag_gpui_box_in(fr, x, y, z, s, margin)) continue;
        d_near = voxdag_gpui_box_near(fr, x, y, z, s);
        if (d_near >= best) continue;
        d_far = voxdag_gpui_box_max(fr.fx, fr.fy, fr.fz, x, y, z, s);
        /* a cell no wider than the frustum, or than a level-of-detail cell, there */
        if (s <= voxdag_gpui_mul(fr.width, d_far) || s < voxdag_gpui_mul(fr.lod, d_far)) {
            best = d_near;
            continue;
        }
        if (q + 2u == nl) { /* a brick: its 2^3 cells, then their voxels, the same way */
            voxdag_gpui_mask m = voxdag_gpui_brick_to_world(voxdag_gpui_brick(buf, f, at), mi);
            for (k = 0u; k < 8u; k++) {
                voxdag_gpu_u32 cell_bits = (k < 4u ? m.lo : m.hi) >> (8u * (k & 3u)) & 0xFFu, v;
                voxdag_gpu_f32 ex = voxdag_gpui_add(x, VOXDAG_GPU_F32(2u * (k & 1u)));
                voxdag_gpu_f32 ey = voxdag_gpui_add(y, VOXDAG_GPU_F32(k & 2u));
                voxdag_gpu_f32 ez = voxdag_gpui_add(z, VOXDAG_GPU_F32(k >> 1 & 2u));
                if (cell_bits == 0u || !voxdag_gpui_box_in(fr, ex, ey, ez, 2.0f, margin)) continue;
                d_near = voxdag_gpui_box_near(fr, ex, ey, ez, 2.0f);
                d_far = voxdag_gpui_box_max(fr.fx, fr.fy, fr.fz, ex, ey, ez, 2.0f);
                if (2.0f <= voxdag_gpui_mul(fr.width, d_far) || 2.0f < voxdag_gpui_mul(fr.lod, d_far)) {
                    if (d_near < best) best = d_near;
                    continue;
                }
                for (v = 0u; v < 8u; v++) {
                    voxdag_gpu_f32 vx = voxdag_gpui_add(ex, VOXDAG_GPU_F32(v & 1u));
                    voxdag_gpu_f32 vy = voxdag_gpui_add(ey, VOXDAG_GPU_F32(v >> 1 & 1u));
                    voxdag_gpu_f32 vz = voxdag_gpui_add(ez, VOXDAG_GPU_F32(v >> 2));
                    if ((cell_bits >> v & 1u) != 0u && voxdag_gpui_box_in(fr, vx, vy, vz, 1.0f, margin)) {
                        voxdag_gpu_f32 d = voxdag_gpui_box_near(fr, vx, vy, vz, 1.0f);
                        if (d < best) best = d;
                    }
                }
            }
            continue;
        }
        {
            voxdag_gpu_u32 header = voxdag_gpui_u16(buf, voxdag_gpui_level_data(buf, f, q) + at), j;
            for (j = 8u; j > 0u; j--) { /* the nearest octant popped first */
                voxdag_gpu_u32 w = nearest ^ (j - 1u), sw = voxdag_gpui_act(mi, w);
                if ((header >> (2u * sw) & 3u) != 0u) {
                    voxdag_gpui_ref ref = voxdag_gpui_child(buf, f, q, at, header, sw);
                    st_at[sp] = ref.at, st_info[sp] = (q + 1u) | voxdag_gpui_compose(ref.inverse, mi) << 8;
                    st_x[sp] = 2u * cx + (w & 1u), st_y[sp] = 2u * cy + (w >> 1 & 1u), st_z[sp] = 2u * cz + (w >> 2);
                    sp++;
                }
            }
        }
    }
    return best < 0.0f ? 0.0f : best;
}

// -- Colours (FORMAT.md, Colour section)

/* A voxcolor endpoint at bit POS of the payload at byte AT: RGB565 widened,
   or RGB888 when PRECISE; as 0x00BBGGRR. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_endpoint(voxdag_gpu_buf buf, voxdag_gpu_u32 at, voxdag_gpu_u32 pos,
                                                    voxdag_gpu_u32 wide) {
    voxdag_gpu_u32 v, r, g, b;
    if (wide != 0u) return voxdag_gpui_bits(buf, at, pos, 24u);
    v = voxdag_gpui_bits(buf, at, pos, 16u);
    r = v & 31u, g = v >> 5 & 63u, b = v >> 11;
    return (r << 3 | r >> 2) | (g << 2 | g >> 4) << 8 | (b << 3 | b >> 2) << 16;
}

/* Colour INDEX (INDEX_LO + 2^32 INDEX_HI) of a voxcolor stream at byte S. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_voxcolor(voxdag_gpu_buf buf, voxdag_gpu_u32 s, voxdag_gpu_u32 index_lo,
                                                    voxdag_gpu_u32 index_hi) {
    voxdag_gpu_u32 shift = voxdag_gpui_byte(buf, s + 6u), wide_table = voxdag_gpui_byte(buf, s + 7u) & 1u;
    voxdag_gpu_u32 count_lo = voxdag_gpui_word(buf, (s >> 2) + 2u), count_hi = voxdag_gpui_word(buf, (s >> 2) + 3u);
    voxdag_gpu_u32 page = index_lo >> shift | index_hi << (32u - shift), j = index_lo & ((1u << shift) - 1u);
    voxdag_gpu_u32 pages = ((count_lo - 1u) >> shift | (count_hi - (count_lo == 0u ? 1u : 0u)) << (32u - shift)) + 1u;
    voxdag_gpu_u32 isz = shift > 8u ? 2u : 1u, data = s + 24u + pages * (4u << wide_table);
    voxdag_gpu_u32 at = data + voxdag_gpui_word(buf, (s + 24u) / 4u + (page << wide_table));
    voxdag_gpu_u32 blocks = voxdag_gpui_bits(buf, at, 0u, 8u * isz) + 1u, groups = ((blocks - 1u) >> 3) + 1u;
    voxdag_gpu_u32 ends = at + isz, block_ends = ends + groups * isz, nibbles = block_ends + (blocks - groups) * isz;
    voxdag_gpu_u32 payload = nibbles + (blocks + 1u) / 2u + (groups - 1u) * 2u;
    voxdag_gpu_u32 lo = 0u, hi = groups, g, n, r, k, b, pos = 0u, start = 0u, mode, nib, len, e0, e1, wbits, t;
    /* the group: the number of group ends below j, by bisection */
    while (lo < hi) {
        voxdag_gpu_u32 mid = (lo + hi) / 2u;
        if (voxdag_gpui_bits(buf, ends, mid * 8u * isz, 8u * isz) < j) lo = mid + 1u;
        else hi = mid;
    }
    g = lo;
    /* the block: the group's first plus the number of its other ends below j */
    n = blocks - 8u * g - 1u < 7u ? blocks - 8u * g - 1u : 7u;
    for (r = 0u; r < n; r++)
        if (!(voxdag_gpui_bits(buf, block_ends, (7u * g + r) * 8u * isz, 8u * isz) < j)) break;
    if (g > 0u) {
        pos = voxdag_gpui_u16(buf, payload - (groups - 1u) * 2u + (g - 1u) * 2u);
        start = voxdag_gpui_bits(buf, ends, (g - 1u) * 8u * isz, 8u * isz) + 1u;
    }
    /* the payloads of the blocks before it in the group */
    for (k = 0u; k < r; k++) {
        voxdag_gpu_u32 end = voxdag_gpui_bits(buf, block_ends, (7u * g + k) * 8u * isz, 8u * isz) + 1u;
        nib = voxdag_gpui_bits(buf, nibbles, (8u * g + k) * 4u, 4u);
        mode = nib & 7u;
        pos += (mode == 0u ? 16u : mode == 5u ? 0u : 32u) * ((nib & 8u) != 0u ? 3u : 2u) / 2u +
               (end - start) * (mode == 5u ? 24u : mode);
        start = end;
    }
    nib = voxdag_gpui_bits(buf, nibbles, (8u * g + r) * 4u, 4u);
    mode = nib & 7u, len = j - start;
    if (mode == 5u) return voxdag_gpui_bits(buf, payload, pos + 24u * len, 24u);
    e0 = voxdag_gpui_endpoint(buf, payload, pos, nib >> 3);
    if (mode == 0u) return e0;
    e1 = voxdag_gpui_endpoint(buf, payload, pos + ((nib & 8u) != 0u ? 24u : 16u), nib >> 3);
    wbits = ((nib & 8u) != 0u ? 48u : 32u) + len * mode;
    k = voxdag_gpui_bits(buf, payload, pos + wbits, mode);
    n = (1u << mode) - 1u;
    t = (128u * k + n) / (2u * n); /* round(64 k / (2^w - 1)) */
    r = 0u;
    for (b = 0u; b < 24u; b += 8u) /* per channel */
        r |= (((e0 >> b & 0xFFu) * (64u - t) + (e1 >> b & 0xFFu) * t + 32u) >> 6) << b;
    return r;
}

/* Colour INDEX of RGB8 colours at byte AT (below 4 GiB: INDEX_HI is 0). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpui_rgb8(voxdag_gpu_buf buf, voxdag_gpu_u32 at, voxdag_gpu_u32 index_lo) {
    at += 3u * index_lo;
    return voxdag_gpui_byte(buf, at) | voxdag_gpui_byte(buf, at + 1u) << 8 | voxdag_gpui_byte(buf, at + 2u) << 16;
}

/* The colour of voxel INDEX as 0x00BBGGRR, or VOXDAG_GPU_NO_COLOR when the
   file has none (INDEX must be below the voxel count). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpu_color(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 index_lo,
                                                voxdag_gpu_u32 index_hi) {
    if (f.color_kind == VOXDAG_GPU_COLORS_RGB8) return voxdag_gpui_rgb8(buf, f.colors, index_lo);
    if (f.color_kind == VOXDAG_GPU_COLORS_VOXCOLOR) return voxdag_gpui_voxcolor(buf, f.colors, index_lo, index_hi);
    return VOXDAG_GPU_NO_COLOR;
}

/* The colour of the cell hit H stopped at, as voxdag_cell_color, from
   h.level and h.x, h.y, h.z alone (WANT_INDEX is not needed): a voxel's
   own colour; the mean of the n <= 64 voxels of a smaller cell, decoded
   here (per channel (sum + n / 2) / n); for a larger cell its slot of the
   level-of-detail colours (FORMAT.md, LOD_COLORS), or its first voxel's
   colour where the file has none for its level. 0x00BBGGRR, or
   VOXDAG_GPU_NO_COLOR when the file has no colours, H is a miss or its
   cell is empty. The same bits as voxdag_cell_color (integers only). */
VOXDAG_GPU_FUNC voxdag_gpu_u32 voxdag_gpu_cell_color(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_hit h) {
    voxdag_gpu_cell_result c;
    voxdag_gpui_mask slot;
    voxdag_gpu_u32 k;
    if (f.color_kind == VOXDAG_GPU_COLORS_NONE || h.hit == 0u) return VOXDAG_GPU_NO_COLOR;
    c = voxdag_gpu_cell(buf, f, h.level, h.x, h.y, h.z);
    if ((c.count_lo | c.count_hi) == 0u) return VOXDAG_GPU_NO_COLOR;
    if (c.count_hi == 0u && c.count_lo <= 64u) { /* every 2^3 cell and brick: exact */
        voxdag_gpu_u32 r = 0u, g = 0u, b = 0u, n = c.count_lo;
        for (k = 0u; k < n; k++) {
            voxdag_gpui_mask i;
            voxdag_gpu_u32 rgb;
            i.lo = c.first_lo, i.hi = c.first_hi;
            i = voxdag_gpui_add64(i, k, 0u);
            rgb = voxdag_gpu_color(buf, f, i.lo, i.hi);
            r += rgb & 0xFFu, g += rgb >> 8 & 0xFFu, b += rgb >> 16;
        }
        return (r + n / 2u) / n | (g + n / 2u) / n << 8 | (b + n / 2u) / n << 16;
    }
    if (f.lod_kind == VOXDAG_GPU_COLORS_NONE || h.level < f.lod_first || h.level - f.lod_first >= f.lod_levels)
        return voxdag_gpu_color(buf, f, c.first_lo, c.first_hi);
    /* slot (q - q0) S + ceil(first / 64) */
    slot.lo = c.first_lo >> 6 | c.first_hi << 26, slot.hi = c.first_hi >> 6;
    slot = voxdag_gpui_add64(slot, (c.first_lo & 63u) != 0u ? 1u : 0u, 0u);
    for (k = f.lod_first; k < h.level; k++) slot = voxdag_gpui_add64(slot, f.lod_per_level_lo, f.lod_per_level_hi);
    if (f.lod_kind == VOXDAG_GPU_COLORS_RGB8) return voxdag_gpui_rgb8(buf, f.lod_slots, slot.lo);
    return voxdag_gpui_voxcolor(buf, f.lod_slots, slot.lo, slot.hi);
}

#endif /* VOXDAG_GPU_H */

/*
MIT License. Copyright (c) 2026 The voxdag authors.
Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies of
the Software, and to permit persons to whom the Software is furnished to do so,
subject to the following conditions: The above copyright notice and this
permission notice shall be included in all copies or substantial portions of
the Software. THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND,
EXPRESS OR IMPLIED. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE
FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY ARISING FROM THE SOFTWARE.
*/
