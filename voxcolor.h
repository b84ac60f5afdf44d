/* voxcolor.h - variable-bitrate block colour codec in one header.  version 0.1.0

   Compresses an array of RGB8 colours (the colours of a voxel DAG in
   voxel-index order, or any 1D colour array with spatial coherence) with a
   guaranteed maximum error per colour, and decodes any colour by index in
   near-constant time, in place, without allocation.

   The array is cut into blocks of any length (Dolonius et al. 2017, §4.2).
   Each block is one of: a single colour, two endpoints with a 1..4-bit weight
   per colour interpolating between them, or raw colours. Endpoints are RGB565
   or RGB888, chosen per block. Blocks never cross a page (2^page_shift
   colours); each page starts with a byte-aligned directory of its blocks
   (the last colour of each group of 8 blocks, then of the others, the
   modes, the payload offset of each group), and a page table gives each
   page's start. A lookup reads one table entry and compares the directory's
   bytes a word at a time, without data-dependent branches but one short
   walk (at most 7 blocks), and prefetches the likely payload meanwhile.
   voxcolor_view_get_many overlaps the memory accesses of many lookups. The
   encoder is a fast greedy heuristic with integer decisions: the same
   stream on every compiler and processor (RGB metric). Dolonius et al.'s
   Algorithm 1 and HashDAG's layout are reimplemented in bench/ to compare.

   QUICK START
       #define VOXCOLOR_IMPLEMENTATION   // in exactly one C or C++ file
       #include "voxcolor.h"

       voxcolor_encode_opts opts;
       memset(&opts, 0, sizeof opts);    // zero means default, for every field
       opts.max_error = 0.02;            // |decoded - original| / 255 <= 0.02
       opts.threads = 4;                 // optional: the same bytes, faster
       voxcolor_error err;
       size_t cap = voxcolor_encode_bound(count);
       uint8_t *buf = malloc(cap);
       size_t size = voxcolor_encode(buf, cap, rgb, count, &opts, &err);
       if (!size) printf("%s\n", err.message);

       voxcolor_view view;               // validates untrusted bytes once
       if (voxcolor_view_init(&view, buf, size, &err) == VOXCOLOR_OK) {
           uint8_t c[3];
           voxcolor_view_get(&view, 12345, c);
       }

   ERROR GUARANTEE
   Every colour c' returned by the decoder for an original colour c satisfies
   |c' - c|_2 / 255 <= max_error (Euclidean RGB distance, 8-bit units), or,
   with VOXCOLOR_METRIC_CIELAB, CIE76 delta E(c', c) <= max_error. The encoder
   checks each colour against what the decoder will return. max_error 0 is
   lossless (then mostly raw blocks: at most ~1% larger than 24 bits).
   The paper's settings are 0.025 .. 0.1.

   CONFIGURATION (define before including the implementation)
     VOXCOLOR_ASSERT(x)   internal invariants and lookup preconditions
                          (default: assert). Options, arguments and stream
                          bytes are checked in every build and get a status.
     VOXCOLOR_STATIC      give every function internal linkage
     VOXCOLOR_NO_THREADS  no built-in thread pool (no <pthread.h> or
                          <windows.h>): pages are encoded on the calling
                          thread unless the options bring a thread pool.
                          Public types are the same in every configuration.
   The codec never allocates: the caller owns every buffer. voxcolor_encode
   uses about 35 KiB of stack, and about 16 KiB on each worker thread;
   decoding a few hundred bytes. Arrays too large to hold in memory stream
   through voxcolor_encoder (colours in, stream out, chunk by chunk).

   ERRORS: calls that can fail return a voxcolor_status (voxcolor_encode: 0
   bytes) and fill an optional voxcolor_error with a static message and, for
   streams, the byte offset of the field at fault. No global error state.

   THREADS: no global state. A view is immutable after voxcolor_view_init: any
   number of threads may query one view at the same time. Encoding reads its
   input and writes only the caller's buffer; any number of encodes may run
   at once. Pages are independent, so with opts.threads > 1 an encode
   spreads them over threads (pthreads, or Win32 threads on Windows, created
   per call and reused for all its pages) or over the host's thread pool
   (opts.thread_pool: run N jobs, wait), with the same bytes as one thread.

   STREAM FORMAT: FORMAT.md, section "Colour section (voxcolor)", documents
   every byte; the VOXCOLOR_OFF_* macros mirror it.
*/
#ifndef VOXCOLOR_H
#define VOXCOLOR_H

#include <stddef.h>
#include <stdint.h>

#define VOXCOLOR_VERSION_MAJOR 0
#define VOXCOLOR_VERSION_MINOR 1
#define VOXCOLOR_VERSION_PATCH 0
#define VOXCOLOR_VERSION \
    (VOXCOLOR_VERSION_MAJOR * 10000 + VOXCOLOR_VERSION_MINOR * 100 + VOXCOLOR_VERSION_PATCH)

/* Stream layout version, stored in every stream (FORMAT.md). */
#define VOXCOLOR_FORMAT_VERSION 3

/* Byte offsets of the stream header fields (FORMAT.md). */
#define VOXCOLOR_OFF_MAGIC 0      /* 4 bytes "VXC1" */
#define VOXCOLOR_OFF_VERSION 4    /* u16 format version */
#define VOXCOLOR_OFF_PAGE_SHIFT 6 /* u8 log2 of colours per page */
#define VOXCOLOR_OFF_FLAGS 7      /* u8, bit 0: 8-byte page table entries */
#define VOXCOLOR_OFF_COUNT 8      /* u64 colour count */
#define VOXCOLOR_OFF_DATA_SIZE 16 /* u64 block data bytes */
#define VOXCOLOR_HEADER_SIZE 24   /* then the page table, then the block data */

#define VOXCOLOR_MIN_PAGE_SHIFT 4
#define VOXCOLOR_MAX_PAGE_SHIFT 10
#define VOXCOLOR_DEFAULT_PAGE_SHIFT 8

#ifndef VOXCOLOR_API
#if defined(VOXCOLOR_STATIC) && (defined(__GNUC__) || defined(__clang__))
#define VOXCOLOR_API static __attribute__((unused)) /* a unit may use only some */
#elif defined(VOXCOLOR_STATIC)
#define VOXCOLOR_API static
#else
#define VOXCOLOR_API extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

// -- Status

typedef enum voxcolor_status {
    VOXCOLOR_OK = 0,
    VOXCOLOR_ERR_TRUNCATED,        /* the stream ends before a part it declares */
    VOXCOLOR_ERR_BAD_MAGIC,        /* not a voxcolor stream */
    VOXCOLOR_ERR_VERSION,          /* a format version this reader does not know */
    VOXCOLOR_ERR_CORRUPT,          /* a field is out of range or inconsistent */
    VOXCOLOR_ERR_TRAILING,         /* bytes follow the end of the stream */
    VOXCOLOR_ERR_INVALID_ARGUMENT, /* a caller argument or option is out of its range */
    VOXCOLOR_ERR_BUFFER_TOO_SMALL, /* the output buffer cannot hold the stream */
    VOXCOLOR_ERR_WRITE,            /* the write callback failed */
    VOXCOLOR_ERR_INCOMPLETE,       /* fewer colours were pushed than declared */
    VOXCOLOR_STATUS_COUNT,
    VOXCOLOR_STATUS_FORCE_32BIT = 0x7fffffff
} voxcolor_status;

/* What went wrong, for the calls that take a voxcolor_error* (may be NULL).
   Filled on failure and on success (status VOXCOLOR_OK). */
typedef struct voxcolor_error {
    voxcolor_status status;
    const char *message;  /* static storage, never freed: what exactly failed */
    uint64_t byte_offset; /* offset in the stream of the field at fault (decoding),
                             UINT64_MAX when not stream-related */
} voxcolor_error;

/* Returns a static, human-readable name of a status. Thread-safe. */
VOXCOLOR_API const char *voxcolor_status_string(voxcolor_status status);

/* Returns VOXCOLOR_VERSION of the implementation that was compiled. */
VOXCOLOR_API uint32_t voxcolor_version(void);

// -- Encoding

typedef enum voxcolor_metric {
    VOXCOLOR_METRIC_RGB = 0,    /* Euclidean distance of RGB8 values / 255 */
    VOXCOLOR_METRIC_CIELAB = 1, /* CIE76 delta E, colours taken as sRGB (D65) */
    VOXCOLOR_METRIC_COUNT,
    VOXCOLOR_METRIC_FORCE_32BIT = 0x7fffffff
} voxcolor_metric;

/* How hard the encoder searches. Every level keeps the error bound. */
typedef enum voxcolor_effort {
    VOXCOLOR_EFFORT_SMALLEST = 0, /* the smallest stream this encoder can make */
    VOXCOLOR_EFFORT_FAST = 1,     /* one endpoint precision per stream (RGB565 or
                                     RGB888 by the bound) where the default tries
                                     both, i.e. for RGB bounds of about 0.012 ..
                                     0.039: at e_t 0.025, 1.2-1.4x faster and
                                     3-9 % larger on the bench sets; the same
                                     stream at other bounds (BENCHMARKS.md) */
    VOXCOLOR_EFFORT_COUNT,
    VOXCOLOR_EFFORT_FORCE_32BIT = 0x7fffffff
} voxcolor_effort;

/* Most threads an encoder uses (the calling one included). */
#define VOXCOLOR_MAX_THREADS 64

/* A job of a parallel encode: run it once for each INDEX the pool is given. */
typedef void (*voxcolor_job_fn)(void *job_user, uint32_t index);

/* The host's thread pool (optional). RUN must call JOB(JOB_USER, i) once for
   every i in [0, COUNT), on any threads (the calling one too), in any order
   or all at once, and return when all have returned. The encoder calls RUN
   from the thread that called it, once per batch of pages (a few hundred
   KiB of output), never from inside a job. */
typedef struct voxcolor_thread_pool {
    void (*run)(void *user, voxcolor_job_fn job, void *job_user, uint32_t count);
    void *user;
} voxcolor_thread_pool;

/* Encoder options. A NULL pointer or an all-zero struct means: lossless,
   RGB metric, weight width chosen per block, pages of 256 colours, smallest
   stream, the calling thread only. Every field is checked, in every build:
   out-of-range values make the call fail with VOXCOLOR_ERR_INVALID_ARGUMENT.
   Initialise with memset or = {0}: nonzero zero_begin / zero_end (a struct
   left uninitialised) is rejected too. */
typedef struct voxcolor_encode_opts {
    uint32_t zero_begin;     /* must be 0 */
    double max_error;        /* error bound e_t in units of the metric; >= 0
                                (not NaN); +infinity accepts any colour */
    voxcolor_metric metric;
    uint32_t weight_bits;    /* 0: 0..4 bits per block (best fit); 1..4: blocks
                                with weights all use this width (as in the
                                paper's fixed-width format) */
    uint32_t page_shift;     /* 0: 8; else 4..10. Larger: smaller stream,
                                slower random lookup */
    voxcolor_effort effort;  /* 0: VOXCOLOR_EFFORT_SMALLEST */
    uint32_t threads;        /* 0 or 1: the calling thread alone; T > 1: pages
                                encoded on T threads (at most
                                VOXCOLOR_MAX_THREADS) of the built-in pool, or
                                on THREAD_POOL. The stream is the same bytes
                                whatever the count. */
    voxcolor_thread_pool thread_pool; /* run NULL: the built-in pool (pthreads,
                                Win32 threads on Windows; none under
                                VOXCOLOR_NO_THREADS, where T > 1 without a
                                pool runs on the calling thread) */
    uint32_t zero_end;       /* must be 0 */
} voxcolor_encode_opts;

/* Returns the largest stream voxcolor_encode can produce for COUNT colours,
   whatever the options (about 3.7 bytes per colour), or 0 when that does not
   fit in a size_t. Thread-safe. */
VOXCOLOR_API size_t voxcolor_encode_bound(size_t count);

/* Encodes COUNT colours (RGB8, 3 bytes each) into DST. OPTS may be NULL.
   Returns the stream size in bytes (at least 32), or 0 on failure, with ERR
   (may be NULL) saying why: VOXCOLOR_ERR_BUFFER_TOO_SMALL when DST_SIZE is
   too small (a buffer of voxcolor_encode_bound(count) bytes is always large
   enough), VOXCOLOR_ERR_INVALID_ARGUMENT for invalid options or a NULL DST
   or RGB8 with a nonzero size. The caller owns both buffers; no memory is
   allocated. With threads, DST's unused end is the pages' scratch space:
   give it voxcolor_encode_bound bytes for the full parallel speed (a smaller
   buffer works, in smaller batches). Deterministic: the same input and
   options (whatever the thread count and effort) give the same bytes,
   whatever the compiler, processor or floating-point model (with the CIELAB
   metric: the same floating-point model). Thread-safe: calls share nothing. */
VOXCOLOR_API size_t voxcolor_encode(uint8_t *dst, size_t dst_size, const uint8_t *rgb8,
                                    size_t count, const voxcolor_encode_opts *opts,
                                    voxcolor_error *err);

// -- Streaming encoding

/* Stores SIZE bytes of the stream at byte OFFSET of the stream; returns 1, or
   0 to stop the encoder (a write error). */
typedef int (*voxcolor_write_fn)(void *user, uint64_t offset, const void *bytes, size_t size);

/* The error test and modes of an encoder (private to the implementation). */
typedef struct voxcolori_enc {
    uint32_t thr2;      /* RGB: largest squared distance allowed */
    int lab;            /* 1: CIELAB metric */
    double lab_thr2;    /* CIELAB: largest squared delta E allowed */
    uint64_t line64;    /* RGB: 64 (sqrt(thr2) + 1 / 4)^2 rounded up, or 16 */
    double linear[256]; /* CIELAB: sRGB channel value to linear light */
    unsigned page_shift;
    unsigned modes[5], mode_count;
    unsigned precisions[2], precision_count;
} voxcolori_enc;

/* The state of an encoder but its batch buffer (private). */
typedef struct voxcolori_stream {
    voxcolori_enc enc;
    voxcolor_write_fn write;
    void *user;
    voxcolor_thread_pool pool; /* the caller's, or run NULL */
    uint32_t threads;          /* 1: serial */
    uint64_t count, pushed;    /* colours declared, colours received */
    uint64_t data_offset;      /* stream offset of the block data */
    uint64_t data_size;        /* block data bytes made (written or in out) */
    uint64_t pages;            /* pages made */
    uint32_t entry, held, out_used, table_used;
    voxcolor_status status;    /* the first failure, sticky */
    const char *message;
    uint8_t *inplace;          /* voxcolor_encode: the destination buffer */
    size_t inplace_size;
    uint8_t rgb[3u << VOXCOLOR_MAX_PAGE_SHIFT]; /* the colours of the open page */
    uint8_t out[8192];                           /* block data not yet written */
    uint8_t table[2048];                         /* page table entries not yet written */
} voxcolori_stream;

/* Bytes of the streaming encoder's batch buffer: the output of the pages
   encoded in parallel, before it goes to the write callback. */
#define VOXCOLOR_ENCODER_BATCH_BYTES (256u << 10)

/* A streaming encoder: takes the colours in index order, in chunks of any
   size, and hands the stream to a write callback as it goes, holding at most
   one page of colours and a few hundred KiB of output (about 280 KiB in all,
   no allocation). Its fields are private. The stream is byte for byte the one
   voxcolor_encode makes from the same colours and options.

       voxcolor_encoder *enc = malloc(sizeof *enc);   // or static
       if (voxcolor_encoder_init(enc, count, &opts, write, file, &err) != VOXCOLOR_OK)
           ...;                                        // err.message says why
       while (more colours)
           voxcolor_encoder_push(enc, chunk, chunk_count);   // stops at the first failure
       uint64_t size = voxcolor_encoder_finish(enc, &err);  // 0: failed, see err

   The colour count is given up front: it fixes where the block data starts.
   WRITE receives the block data in order (offsets growing from
   voxcolor_encoder_data_offset), the page table in pieces as pages complete
   (in order), and the 24-byte header at offset 0 last, in finish. The pieces
   never overlap and tile [0, size) exactly, so WRITE may pwrite to a file,
   fill a buffer it grows, or keep the small header and table apart and
   append only the block data. WRITE is called from the thread that called
   push or finish. With threads, the whole pages of each chunk pushed are
   encoded in parallel (push chunks of many pages, e.g. 2^20 colours); the
   built-in pool's threads live for one push call. */
typedef struct voxcolor_encoder {
    voxcolori_stream s;
    uint8_t batch[VOXCOLOR_ENCODER_BATCH_BYTES];
} voxcolor_encoder;

/* Sets up ENC to encode COUNT colours with OPTS (may be NULL; as for
   voxcolor_encode) and to hand the stream to WRITE with USER. Writes
   nothing yet. Returns VOXCOLOR_OK, or VOXCOLOR_ERR_INVALID_ARGUMENT (ENC or
   WRITE NULL, invalid options; details in ERR, may be NULL), after which
   every push and finish on ENC fails. */
VOXCOLOR_API voxcolor_status voxcolor_encoder_init(voxcolor_encoder *enc, uint64_t count,
                                                   const voxcolor_encode_opts *opts,
                                                   voxcolor_write_fn write, void *user,
                                                   voxcolor_error *err);

/* Byte offset in the stream where the block data starts (24 plus the page
   table): known from the colour count alone. 0 when ENC is NULL. */
VOXCOLOR_API uint64_t voxcolor_encoder_data_offset(const voxcolor_encoder *enc);

/* Encodes the next N colours (RGB8) in index order; at most the count given
   to init in all. Returns VOXCOLOR_OK, or the encoder's first failure (then
   every later call fails too): VOXCOLOR_ERR_WRITE when a write failed,
   VOXCOLOR_ERR_INVALID_ARGUMENT when RGB8 is NULL with N > 0, N is more than
   the colours left, or init failed. RGB8 may be reused as soon as this
   returns. */
VOXCOLOR_API voxcolor_status voxcolor_encoder_push(voxcolor_encoder *enc, const uint8_t *rgb8,
                                                   size_t n);

/* Writes the rest of the stream. Returns its size in bytes, or 0 when the
   encoder failed (ERR, may be NULL, says why: also
   VOXCOLOR_ERR_INCOMPLETE when fewer colours than declared were pushed). */
VOXCOLOR_API uint64_t voxcolor_encoder_finish(voxcolor_encoder *enc, voxcolor_error *err);

// -- Decoding

/* A validated, read-only window on a stream. The stream bytes are not copied:
   they must stay valid and unchanged while the view is used. */
typedef struct voxcolor_view {
    const uint8_t *table; /* page table */
    const uint8_t *data;  /* block data */
    uint64_t count;       /* number of colours */
    uint32_t page_shift;
    uint32_t wide;        /* 1: 8-byte page table entries, 0: 4-byte */
    uint64_t data_size;   /* bytes of block data */
} voxcolor_view;

/* Validates SIZE bytes at SRC completely (header, version, page table, every
   block header, padding, no trailing bytes) and sets up VIEW. Returns
   VOXCOLOR_OK, or an error and leaves VIEW zeroed (when not NULL); ERR (may
   be NULL) then gives a message and the byte offset in the stream of the
   field at fault. VOXCOLOR_ERR_INVALID_ARGUMENT: VIEW is NULL, or SRC is
   NULL with SIZE > 0. Never reads outside [SRC, SRC + SIZE); runs in time
   linear in SIZE. Thread-safe. */
VOXCOLOR_API voxcolor_status voxcolor_view_init(voxcolor_view *view, const void *src,
                                                size_t size, voxcolor_error *err);

/* Writes the colour at INDEX (< view->count) to RGB_OUT[0..2]. Reads two page
   table entries, counts the page's directory bytes below the colour's a
   word at a time and walks at most 7 block entries. Thread-safe. */
VOXCOLOR_API void voxcolor_view_get(const voxcolor_view *view, uint64_t index,
                                    uint8_t rgb_out[3]);

/* Writes N colours starting at FIRST (FIRST + N <= view->count) to RGB_OUT
   (3 * N bytes), decoding sequentially. Same result as N calls of
   voxcolor_view_get, faster. Thread-safe. */
VOXCOLOR_API void voxcolor_view_get_range(const voxcolor_view *view, uint64_t first,
                                          size_t n, uint8_t *rgb_out);

/* Writes the colours at INDICES[0..n) (each < view->count) to RGB_OUT
   (3 * N bytes). Same result as N calls of voxcolor_view_get; faster for
   scattered indices, as the memory accesses of successive lookups overlap.
   Thread-safe. */
VOXCOLOR_API void voxcolor_view_get_many(const voxcolor_view *view, const uint64_t *indices,
                                         size_t n, uint8_t *rgb_out);

// -- 2D mapping (Dolonius §4.1)

/* Pixel of array element INDEX along a 2D Morton curve: the bits of INDEX
   alternate x (bit 0), y (bit 1), x, y, ... Thread-safe. */
VOXCOLOR_API void voxcolor_morton2d_decode(uint64_t index, uint32_t *x, uint32_t *y);

/* Inverse of voxcolor_morton2d_decode. */
VOXCOLOR_API uint64_t voxcolor_morton2d_encode(uint32_t x, uint32_t y);

/* Smallest image whose Morton curve holds COUNT elements: WIDTH a power of
   two, WIDTH >= HEIGHT, HEIGHT the number of rows the curve actually visits.
   COUNT must be at most 2^62. */
VOXCOLOR_API void voxcolor_image_size(uint64_t count, uint32_t *width, uint32_t *height);

/* Writes COUNT colours into IMAGE (WIDTH x HEIGHT RGB8 pixels, rows top to
   bottom, sizes from voxcolor_image_size) along the Morton curve. Pixels the
   curve does not reach get the colour of the element before them on the
   curve, which image codecs compress to almost nothing. */
VOXCOLOR_API void voxcolor_to_image(uint8_t *image, uint32_t width, uint32_t height,
                                    const uint8_t *rgb8, size_t count);

/* Reads COUNT colours back from an image written by voxcolor_to_image. */
VOXCOLOR_API void voxcolor_from_image(uint8_t *rgb8, size_t count, const uint8_t *image,
                                      uint32_t width, uint32_t height);

#ifdef __cplusplus
}
#endif

#endif /* VOXCOLOR_H */

/* ==========================================================================
   Implementation
   ========================================================================== */
#ifdef VOXCOLOR_IMPLEMENTATION
#ifndef VOXCOLOR_IMPLEMENTATION_DONE
#define VOXCOLOR_IMPLEMENTATION_DONE

#include <string.h>

/* With the RGB metric every decision of the encoder is integer arithmetic.
   The CIELAB metric's error checks use floating point: fused multiply-adds
   would change them between compilers, so contraction is off where the
   compiler honours the standard pragma (GCC: compile with -ffp-contract=off). */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

#ifndef VOXCOLOR_ASSERT
#include <assert.h>
#define VOXCOLOR_ASSERT(x) assert(x)
#endif

// -- Block modes
/* A page is its block count - 1, then per block the index in the page of its
   last colour (these indices are 1 byte each for pages of up to 256 colours,
   else 2), then per block MODE (3 bits) and PRECISION (1 bit: 0 RGB565, 1
   RGB888 endpoints) in a nibble, two per byte, then a checkpoint per group of
   8 blocks but the first: the payload bit offset of the group's first block
   (u16), then the payloads from the next byte on: each block's endpoints and
   a field per colour. Modes 0..4: weight width in bits (0 = one colour); mode
   5: raw RGB888 colours. The byte-aligned directory makes a lookup a binary
   search over bytes and a walk of at most 7 entries. */
#define VOXCOLORI_MODE_RAW 5u
#define VOXCOLORI_GROUP_SHIFT 3u /* groups of 8 blocks */
#define VOXCOLORI_MAX_WEIGHT_BITS 4u

/* Interpolation weights in 64ths for weight k of width w: round(64 k / (2^w - 1)).
   A channel decodes as (e0 * (64 - t) + e1 * t + 32) >> 6 (as in BC7). */
static const uint8_t voxcolori_weights[8][16] = {
    {0},
    {0, 64},
    {0, 21, 43, 64},
    {0, 9, 18, 27, 37, 46, 55, 64},
    {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64},
};

/* Endpoint bits of a block by mode | precision << 3: one colour for mode 0,
   two for modes 1..4, none for raw. */
static const uint8_t voxcolori_endpoint_table[16] = {16, 32, 32, 32, 32, 0, 0, 0,
                                                     24, 48, 48, 48, 48, 0, 0, 0};

/* Bits per colour of each mode: the weight width, or 24 for raw. */
static const uint8_t voxcolori_colour_table[8] = {0, 1, 2, 3, 4, 24, 0, 0};

static unsigned voxcolori_payload_bits(unsigned mode) { return voxcolori_colour_table[mode & 7]; }

static unsigned voxcolori_endpoint_bits(unsigned mode, unsigned precision) {
    return voxcolori_endpoint_table[(mode & 7) | (precision & 1) << 3];
}

/* 8-bit value of a quantized channel with BITS bits (bit replication). */
static unsigned voxcolori_expand(unsigned q, unsigned bits) {
    if (bits == 8) return q;
    return (q << (8 - bits)) | (q >> (2 * bits - 8));
}

/* Channel bit widths of an endpoint: 5/6/5 or 8/8/8. */
static unsigned voxcolori_channel_bits(unsigned channel, unsigned precision) {
    if (precision) return 8;
    return channel == 1 ? 6u : 5u;
}

/* Position of a channel in a packed endpoint (red lowest). */
static unsigned voxcolori_channel_shift(unsigned channel, unsigned precision) {
    static const uint8_t shift565[3] = {0, 5, 11};
    return precision ? 8 * channel : shift565[channel];
}

#if defined(__cplusplus) || (defined(__STDC_VERSION__) && __STDC_VERSION__ >= 199901L)
#define VOXCOLORI_INLINE inline
#elif defined(_MSC_VER)
#define VOXCOLORI_INLINE __inline
#else
#define VOXCOLORI_INLINE
#endif

#if defined(__GNUC__) || defined(__clang__)
#define VOXCOLORI_ALWAYS_INLINE __attribute__((always_inline)) VOXCOLORI_INLINE
#else
#define VOXCOLORI_ALWAYS_INLINE VOXCOLORI_INLINE
#endif

#if defined(__GNUC__) || defined(__clang__)
#define VOXCOLORI_PREFETCH(p) __builtin_prefetch(p)
#else
#define VOXCOLORI_PREFETCH(p) ((void)(p))
#endif

// -- Little-endian bytes

static uint64_t voxcolori_load_le(const uint8_t *p, unsigned n) {
    uint64_t v = 0;
    while (n--) v = v << 8 | p[n];
    return v;
}

static void voxcolori_store_le(uint8_t *p, uint64_t v, unsigned n) {
    unsigned i;
    for (i = 0; i < n; i++) p[i] = (uint8_t)(v >> (8 * i));
}

/* Written out so that compilers turn it into one load. */
static VOXCOLORI_INLINE uint64_t voxcolori_load64(const uint8_t *p) {
    return (uint64_t)p[0] | (uint64_t)p[1] << 8 | (uint64_t)p[2] << 16 | (uint64_t)p[3] << 24 |
           (uint64_t)p[4] << 32 | (uint64_t)p[5] << 40 | (uint64_t)p[6] << 48 |
           (uint64_t)p[7] << 56;
}

/* N (<= 56) bits at bit position POS of DATA, least significant bit first.
   The stream ends with 8 zero bytes, so the 8-byte load stays inside it. */
static VOXCOLORI_INLINE uint64_t voxcolori_bits(const uint8_t *data, uint64_t pos, unsigned n) {
    uint64_t w = voxcolori_load64(data + (size_t)(pos >> 3)) >> (pos & 7);
    return w & ((1ull << n) - 1);
}

// -- Decoding one block

/* Channels of an endpoint in the low bits of V (PRECISION 0: RGB565, 1:
   RGB888), widened to 8 bits, in the 16-bit lanes 0, 1 and 2. */
static VOXCOLORI_ALWAYS_INLINE uint64_t voxcolori_lanes(uint64_t v, unsigned precision) {
    uint64_t wide = (v & 255) | (v & 0xff00) << 8 | (v & 0xff0000) << 16;
    /* 5 and 6 bits in the lanes, widened by (x * 132) >> 4 = x << 3 | x >> 2
       and (x * 65) >> 4 = x << 2 | x >> 4, all lanes at once. */
    uint64_t narrow = (v & 31) | (v & 0xf800) << 21, g = (v & 0x7e0) << 11;
    narrow = ((narrow * 132 + g * 65) >> 4) & 0x00ff00ff00ffull;
    return precision ? wide : narrow;
}

/* Bits of a block's payload: endpoints, then a weight or raw colour per colour. */
static uint64_t voxcolori_block_bits(unsigned mode, unsigned precision, uint64_t length) {
    return voxcolori_endpoint_bits(mode, precision) + length * voxcolori_payload_bits(mode);
}

/* Colour number I, as 0xBBGGRR, of the block with nibble H (mode | precision
   << 3) whose payload starts at bit POS. Without branches: every mode reads
   the same fields and keeps the ones it needs. */
static VOXCOLORI_ALWAYS_INLINE uint32_t voxcolori_block_color(const uint8_t *data, uint64_t pos,
                                                       unsigned h, uint64_t i) {
    unsigned mode = h & 7, precision = (h >> 3) & 1, bits = voxcolori_colour_table[mode];
    uint64_t v = voxcolori_bits(data, pos + voxcolori_endpoint_table[h & 15] + i * bits, bits);
    uint64_t e = voxcolori_bits(data, pos, 48);
    uint64_t e0 = voxcolori_lanes(e, precision), e1 = voxcolori_lanes(e >> (16 + 8 * precision), precision);
    uint64_t t = voxcolori_weights[mode][v & 15], c;
    /* (e0 (64 - t) + e1 t + 32) >> 6 in the three lanes at once; mode 0 has
       t = 0. */
    c = ((e0 * (64 - t) + e1 * t + 0x002000200020ull) >> 6) & 0x00ff00ff00ffull;
    c = (c & 0xff) | (c >> 8 & 0xff00) | (c >> 16 & 0xff0000);
    return (uint32_t)(mode == VOXCOLORI_MODE_RAW ? v : c);
}

static void voxcolori_store_rgb(uint8_t *out, uint32_t c) {
    out[0] = (uint8_t)c;
    out[1] = (uint8_t)(c >> 8);
    out[2] = (uint8_t)(c >> 16);
}

// -- Views

VOXCOLOR_API const char *voxcolor_status_string(voxcolor_status status) {
    switch (status) {
    case VOXCOLOR_OK: return "ok";
    case VOXCOLOR_ERR_TRUNCATED: return "stream truncated";
    case VOXCOLOR_ERR_BAD_MAGIC: return "not a voxcolor stream";
    case VOXCOLOR_ERR_VERSION: return "unsupported voxcolor format version";
    case VOXCOLOR_ERR_CORRUPT: return "corrupt voxcolor stream";
    case VOXCOLOR_ERR_TRAILING: return "bytes after the end of the voxcolor stream";
    case VOXCOLOR_ERR_INVALID_ARGUMENT: return "invalid argument";
    case VOXCOLOR_ERR_BUFFER_TOO_SMALL: return "output buffer too small";
    case VOXCOLOR_ERR_WRITE: return "write failed";
    case VOXCOLOR_ERR_INCOMPLETE: return "fewer colours pushed than declared";
    default: return "unknown status";
    }
}

/* Fills ERR (may be NULL) and returns ST. MESSAGE is static. */
static voxcolor_status voxcolori_report(voxcolor_error *err, voxcolor_status st, const char *message,
                                        uint64_t offset) {
    if (err) {
        err->status = st;
        err->message = message;
        err->byte_offset = offset;
    }
    return st;
}

VOXCOLOR_API uint32_t voxcolor_version(void) { return VOXCOLOR_VERSION; }

static VOXCOLORI_ALWAYS_INLINE uint64_t voxcolori_page_offset(const voxcolor_view *v, uint64_t page) {
    const uint8_t *p;
    if (v->wide) return voxcolori_load64(v->table + (size_t)(page * 8));
    p = v->table + (size_t)(page * 4);
    return (uint64_t)p[0] | (uint64_t)p[1] << 8 | (uint64_t)p[2] << 16 | (uint64_t)p[3] << 24;
}

/* The directory of one page. Colour indices (block count - 1, ends) are 1
   byte each, 2 when WIDE (pages over 256 colours). */
typedef struct voxcolori_page {
    const uint8_t *group_ends;  /* per group of 8 blocks, the index of its last colour */
    const uint8_t *block_ends;  /* per group, the last colours of its blocks but the last */
    const uint8_t *modes;       /* per block, mode | precision << 3, low nibble first */
    const uint8_t *checkpoints; /* u16 payload offsets of groups 1, 2, ... */
    uint64_t payload;           /* bit position of block 0's payload */
    uint64_t last;              /* block count - 1 */
    unsigned wide;
} voxcolori_page;

/* Bytes of the block count and directory of a page of BLOCKS blocks. */
static uint64_t voxcolori_directory_bytes(uint64_t blocks, unsigned wide) {
    uint64_t groups = ((blocks - 1) >> VOXCOLORI_GROUP_SHIFT) + 1;
    return (blocks + 1) * (1 + wide) + (blocks + 1) / 2 + 2 * (groups - 1);
}

/* Bytes of a colour index in a page of 2^PAGE_SHIFT colours. */
static unsigned voxcolori_index_bytes(unsigned page_shift) { return page_shift > 8 ? 2u : 1u; }

static VOXCOLORI_ALWAYS_INLINE uint64_t voxcolori_index(const uint8_t *p, unsigned wide) {
    return wide ? (uint64_t)p[0] | (uint64_t)p[1] << 8 : p[0];
}

/* Opens the page at byte AT of DATA (its block count must be readable). */
static VOXCOLORI_ALWAYS_INLINE void voxcolori_page_open(const uint8_t *data, uint64_t at,
                                                        unsigned wide, voxcolori_page *p) {
    uint64_t groups;
    p->wide = wide;
    p->last = voxcolori_index(data + at, wide);
    groups = (p->last >> VOXCOLORI_GROUP_SHIFT) + 1;
    p->group_ends = data + at + 1 + wide;
    p->block_ends = p->group_ends + (groups << wide);
    p->modes = p->block_ends + ((p->last + 1 - groups) << wide);
    p->checkpoints = p->modes + (p->last + 2) / 2;
    p->payload = 8 * (at + voxcolori_directory_bytes(p->last + 1, wide));
}

/* Index in the page of block K's last colour. */
static uint64_t voxcolori_end(const voxcolori_page *p, uint64_t k) {
    uint64_t g = k >> VOXCOLORI_GROUP_SHIFT, i = k & ((1u << VOXCOLORI_GROUP_SHIFT) - 1);
    if (i == (1u << VOXCOLORI_GROUP_SHIFT) - 1 || k == p->last)
        return voxcolori_index(p->group_ends + (g << p->wide), p->wide);
    return voxcolori_index(p->block_ends + ((7 * g + i) << p->wide), p->wide);
}

/* Block K's mode | precision << 3. */
static VOXCOLORI_ALWAYS_INLINE unsigned voxcolori_nibble(const voxcolori_page *p, uint64_t k) {
    return (p->modes[k >> 1] >> (4 * (k & 1))) & 15;
}

/* Checks every page: its directory and blocks must tile it exactly, pages
   must follow each other without gaps where the page table says, and the
   data must end with the 8 zero bytes. DATA_SIZE >= 8. The data starts at
   byte BASE of the stream (for the offsets in ERR). */
static voxcolor_status voxcolori_check_pages(const voxcolor_view *v, uint64_t data_size, uint64_t base,
                                             voxcolor_error *err) {
    uint64_t limit = data_size - 8, at = 0, page, pages;
    uint64_t page_size = 1ull << v->page_shift, k;
    unsigned wide = v->page_shift > 8;
    size_t i;
    const voxcolor_status bad = VOXCOLOR_ERR_CORRUPT;
    pages = v->count ? ((v->count - 1) >> v->page_shift) + 1 : 0;
    for (page = 0; page < pages; page++) {
        uint64_t left = page + 1 < pages ? page_size : v->count - page * page_size;
        uint64_t start = 0, pos;
        voxcolori_page p;
        if (voxcolori_page_offset(v, page) != at)
            return voxcolori_report(err, bad, "page table entry is not where the previous page ends",
                                    VOXCOLOR_HEADER_SIZE + page * (v->wide ? 8u : 4u));
        if (limit - at < 1u + wide) return voxcolori_report(err, bad, "page past the block data", base + at);
        k = voxcolori_index(v->data + at, wide) + 1;
        if (k > left) return voxcolori_report(err, bad, "more blocks than colours in a page", base + at);
        if (voxcolori_directory_bytes(k, wide) > limit - at)
            return voxcolori_report(err, bad, "page directory past the block data", base + at);
        voxcolori_page_open(v->data, at, wide, &p);
        /* The nibble after the last block's is zero. */
        if (!(p.last & 1) && p.modes[p.last >> 1] >> 4)
            return voxcolori_report(err, bad, "nonzero padding nibble after the last block's mode",
                                    base + (uint64_t)(p.modes + (p.last >> 1) - v->data));
        for (k = 0, pos = p.payload; k <= p.last; k++) {
            unsigned h = voxcolori_nibble(&p, k);
            uint64_t end = voxcolori_end(&p, k) + 1;
            if (k && !(k & ((1u << VOXCOLORI_GROUP_SHIFT) - 1)) &&
                voxcolori_load_le(p.checkpoints + 2 * ((k >> VOXCOLORI_GROUP_SHIFT) - 1), 2) != pos - p.payload)
                return voxcolori_report(
                    err, bad, "checkpoint differs from the payload offset of its group",
                    base + (uint64_t)(p.checkpoints + 2 * ((k >> VOXCOLORI_GROUP_SHIFT) - 1) - v->data));
            /* Known modes; ends grow and stay inside the page. */
            if ((h & 7) > VOXCOLORI_MODE_RAW || h == (VOXCOLORI_MODE_RAW | 8))
                return voxcolori_report(err, bad, "unknown block mode",
                                        base + (uint64_t)(p.modes + (k >> 1) - v->data));
            if (end <= start || end > left)
                return voxcolori_report(err, bad, "block ends out of order or past the page", base + at);
            /* A block has at most 1024 * 24 + 48 bits: no overflow before this. */
            pos += voxcolori_block_bits(h & 7, h >> 3, end - start);
            if (pos > 8 * limit) return voxcolori_report(err, bad, "block payload past the block data", base + limit);
            start = end;
        }
        if (start != left) return voxcolori_report(err, bad, "blocks do not cover their page", base + at);
        /* Pages start on a byte; the bits up to it must be zero. */
        if ((pos & 7) && voxcolori_bits(v->data, pos, 8 - (unsigned)(pos & 7)))
            return voxcolori_report(err, bad, "nonzero padding bits after a page", base + pos / 8);
        at = (pos + 7) / 8;
    }
    if (at != limit) return voxcolori_report(err, bad, "block data size differs from the pages' size", base + at);
    for (i = 0; i < 8; i++)
        if (v->data[at + i]) return voxcolori_report(err, bad, "nonzero closing bytes", base + at + i);
    return voxcolori_report(err, VOXCOLOR_OK, "ok", UINT64_MAX);
}

VOXCOLOR_API voxcolor_status voxcolor_view_init(voxcolor_view *view, const void *src, size_t size,
                                                voxcolor_error *err) {
    const uint8_t *p = (const uint8_t *)src;
    voxcolor_view v;
    uint64_t pages, entry, rest, data_size;
    unsigned flags;
    voxcolor_status st;
    if (!view) return voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "view is NULL", UINT64_MAX);
    memset(view, 0, sizeof *view);
    if (!src && size)
        return voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "stream is NULL with a nonzero size", UINT64_MAX);
    if (size < VOXCOLOR_HEADER_SIZE)
        return voxcolori_report(err, VOXCOLOR_ERR_TRUNCATED, "stream shorter than its header", size);
    if (memcmp(p + VOXCOLOR_OFF_MAGIC, "VXC1", 4) != 0)
        return voxcolori_report(err, VOXCOLOR_ERR_BAD_MAGIC, "magic is not VXC1", VOXCOLOR_OFF_MAGIC);
    if (voxcolori_load_le(p + VOXCOLOR_OFF_VERSION, 2) != VOXCOLOR_FORMAT_VERSION)
        return voxcolori_report(err, VOXCOLOR_ERR_VERSION, "unknown stream format version", VOXCOLOR_OFF_VERSION);
    v.page_shift = p[VOXCOLOR_OFF_PAGE_SHIFT];
    flags = p[VOXCOLOR_OFF_FLAGS];
    if (v.page_shift < VOXCOLOR_MIN_PAGE_SHIFT || v.page_shift > VOXCOLOR_MAX_PAGE_SHIFT)
        return voxcolori_report(err, VOXCOLOR_ERR_CORRUPT, "page shift out of range", VOXCOLOR_OFF_PAGE_SHIFT);
    if (flags > 1) return voxcolori_report(err, VOXCOLOR_ERR_CORRUPT, "unknown flags", VOXCOLOR_OFF_FLAGS);
    v.wide = flags;
    v.count = voxcolori_load_le(p + VOXCOLOR_OFF_COUNT, 8);
    data_size = voxcolori_load_le(p + VOXCOLOR_OFF_DATA_SIZE, 8);
    pages = v.count ? ((v.count - 1) >> v.page_shift) + 1 : 0;
    entry = v.wide ? 8 : 4;
    rest = (uint64_t)size - VOXCOLOR_HEADER_SIZE;
    if (pages > rest / entry)
        return voxcolori_report(err, VOXCOLOR_ERR_TRUNCATED, "stream ends inside the page table", size);
    rest -= pages * entry;
    if (data_size > rest)
        return voxcolori_report(err, VOXCOLOR_ERR_TRUNCATED, "stream ends inside the block data", size);
    if (data_size < rest)
        return voxcolori_report(err, VOXCOLOR_ERR_TRAILING, "bytes after the block data",
                                VOXCOLOR_HEADER_SIZE + pages * entry + data_size);
    if (data_size < 8 || data_size > UINT64_MAX / 8)
        return voxcolori_report(err, VOXCOLOR_ERR_CORRUPT, "block data size out of range", VOXCOLOR_OFF_DATA_SIZE);
    v.table = p + VOXCOLOR_HEADER_SIZE;
    v.data = v.table + (size_t)(pages * entry);
    v.data_size = data_size;
    st = voxcolori_check_pages(&v, data_size, VOXCOLOR_HEADER_SIZE + pages * entry, err);
    if (st == VOXCOLOR_OK) *view = v;
    return st;
}

/* Prefetches the start of PAGE and the part where colour J's payload likely
   is (at its share of the page): two lines, for lookups issued well ahead. */
static VOXCOLORI_ALWAYS_INLINE void voxcolori_prefetch_guess(const voxcolor_view *view,
                                                             uint64_t page, uint64_t j) {
    uint64_t at = voxcolori_page_offset(view, page);
    VOXCOLORI_PREFETCH(view->data + at);
    if ((page + 1) << view->page_shift < view->count)
        VOXCOLORI_PREFETCH(view->data + at +
                           (((voxcolori_page_offset(view, page + 1) - at) * j) >> view->page_shift));
}

/* Prefetches the first VOXCOLORI_PREFETCH_LINES cache lines from PAGE's
   start (only the first near the end of the data), so that its directory and
   the payload a lookup needs arrive together: guessing the payload's line
   misses on pages with large directories. Lines past a short page cost a
   prefetch each, fewer instructions than stopping at its end. Returns the
   page's offset. */
#define VOXCOLORI_PREFETCH_LINES 8u
static VOXCOLORI_ALWAYS_INLINE uint64_t voxcolori_prefetch_page(const voxcolor_view *view,
                                                                uint64_t page) {
    uint64_t at = voxcolori_page_offset(view, page);
    unsigned k;
    VOXCOLORI_PREFETCH(view->data + at);
    if (at + 64 * VOXCOLORI_PREFETCH_LINES <= view->data_size)
        for (k = 1; k < VOXCOLORI_PREFETCH_LINES; k++) VOXCOLORI_PREFETCH(view->data + at + 64 * k);
    return at;
}

/* Number of the lowest N lanes of X (8 bits each, 16 when WIDE) whose
   value is below J, without branches: a lane-wise borrow of X - J. */
static VOXCOLORI_ALWAYS_INLINE uint64_t voxcolori_count_below(uint64_t x, uint64_t j, unsigned n,
                                                              unsigned wide) {
    unsigned bits = 8u << wide;
    uint64_t ones = wide ? 0x0001000100010001ull : 0x0101010101010101ull, high = ones << (bits - 1);
    uint64_t jj = j * ones, d = (x | high) - (jj & ~high);
    uint64_t below = ((~x & jj) | (~(x ^ jj) & ~d)) & high;
    below &= n * bits >= 64 ? ~0ull : (1ull << (n * bits)) - 1;
    return ((below >> (bits - 1)) * ones) >> (64 - bits);
}

/* voxcolor_view_get for pages with WIDE indices, a constant in each call so
   that every index read compiles to one load. Prefetches the page unless
   PREFETCHED (done well ahead by the caller). */
static VOXCOLORI_ALWAYS_INLINE uint32_t voxcolori_get(const voxcolor_view *view, uint64_t index,
                                                      unsigned wide, int prefetched) {
    const uint8_t *data = view->data, *ends;
    unsigned s = view->page_shift, lanes = 8u >> wide, n;
    uint64_t j = index & ((1ull << s) - 1), page = index >> s, at, groups, g, w, r, start, pos, modes;
    voxcolori_page p;
    at = prefetched ? voxcolori_page_offset(view, page) : voxcolori_prefetch_page(view, page);
    voxcolori_page_open(data, at, wide, &p);
    groups = (p.last >> VOXCOLORI_GROUP_SHIFT) + 1;
    /* Group g holding colour j: the number of groups ending before j,
       counted a word of ends at a time. */
    for (g = 0, w = 0; w < groups; w += lanes) {
        n = groups - w < lanes ? (unsigned)(groups - w) : lanes;
        g += voxcolori_count_below(voxcolori_load64(p.group_ends + (w << wide)), j, n, wide);
    }
    /* Block k holding j: the group's first block plus the number of its
       other blocks ending before j. */
    ends = p.block_ends + ((7 * g) << wide);
    n = p.last - (g << VOXCOLORI_GROUP_SHIFT) < 7 ? (unsigned)(p.last - (g << VOXCOLORI_GROUP_SHIFT)) : 7;
    r = voxcolori_count_below(voxcolori_load64(ends), j, n, wide);
    /* Wide ends take two words; the second is read only when the group has
       more than 4 of them, since a short page may end with the first (the 8
       closing zero bytes cover one word past a directory entry, not two). */
    if (wide && n > 4) r += voxcolori_count_below(voxcolori_load64(ends + 8), j, n - 4, wide);
    /* Its payload: the group's checkpoint plus the payloads of the r blocks
       before it in the group. */
    pos = p.payload;
    start = 0;
    if (g) {
        pos += voxcolori_load_le(p.checkpoints + 2 * (g - 1), 2);
        start = voxcolori_index(p.group_ends + ((g - 1) << wide), wide) + 1;
    }
    modes = voxcolori_load64(p.modes + 4 * g); /* the group's 8 nibbles */
    for (w = 0; w < r; w++, modes >>= 4) {
        unsigned h = (unsigned)modes & 15;
        uint64_t end = voxcolori_index(ends + (w << wide), wide) + 1;
        pos += voxcolori_endpoint_table[h] + (end - start) * voxcolori_colour_table[h & 7];
        start = end;
    }
    return voxcolori_block_color(data, pos, (unsigned)modes & 15, j - start);
}

/* Colour INDEX to RGB_OUT (see voxcolori_get). */
static VOXCOLORI_ALWAYS_INLINE void voxcolori_lookup(const voxcolor_view *view, uint64_t index,
                                                     uint8_t *rgb_out, int prefetched) {
    voxcolori_store_rgb(rgb_out, view->page_shift > 8 ? voxcolori_get(view, index, 1, prefetched)
                                                      : voxcolori_get(view, index, 0, prefetched));
}

VOXCOLOR_API void voxcolor_view_get(const voxcolor_view *view, uint64_t index,
                                    uint8_t rgb_out[3]) {
    VOXCOLOR_ASSERT(view && rgb_out && index < view->count);
    voxcolori_lookup(view, index, rgb_out, 0);
}

VOXCOLOR_API void voxcolor_view_get_many(const voxcolor_view *view, const uint64_t *indices,
                                         size_t n, uint8_t *rgb_out) {
    /* Software pipeline: the page table entries 16 lookups ahead, the page
       and the likely place of the colour's payload 8 lookups ahead (the
       entries are in cache by then). */
    size_t i, entry = view->wide ? 8u : 4u;
    unsigned s = view->page_shift;
    VOXCOLOR_ASSERT(view && (indices || !n) && (rgb_out || !n));
    for (i = 0; i < n; i++) {
        if (i + 16 < n) VOXCOLORI_PREFETCH(view->table + (size_t)(indices[i + 16] >> s) * entry);
        if (i + 8 < n) {
            uint64_t ahead = indices[i + 8];
            VOXCOLOR_ASSERT(ahead < view->count);
            voxcolori_prefetch_guess(view, ahead >> s, ahead & ((1ull << s) - 1));
        }
        VOXCOLOR_ASSERT(indices[i] < view->count);
        voxcolori_lookup(view, indices[i], rgb_out + 3 * i, 1);
    }
}

VOXCOLOR_API void voxcolor_view_get_range(const voxcolor_view *view, uint64_t first,
                                          size_t n, uint8_t *rgb_out) {
    uint64_t page, i;
    VOXCOLOR_ASSERT(view && (rgb_out || !n) && first <= view->count &&
                    n <= view->count - first);
    page = first >> view->page_shift;
    i = first & ((1ull << view->page_shift) - 1);
    while (n) {
        voxcolori_page p;
        uint64_t k, start = 0, pos;
        voxcolori_page_open(view->data, voxcolori_page_offset(view, page++), view->page_shift > 8, &p);
        for (k = 0, pos = p.payload; k <= p.last && n; k++) {
            unsigned h = voxcolori_nibble(&p, k);
            uint64_t end = voxcolori_end(&p, k) + 1;
            for (; i < end && n; i++, n--, rgb_out += 3)
                voxcolori_store_rgb(rgb_out, voxcolori_block_color(view->data, pos, h, i - start));
            pos += voxcolori_block_bits(h & 7, h >> 3, end - start);
            start = end;
        }
        i = 0;
    }
}

// -- Encoding: error metric


/* X^(1/N) for X in [0, 2] by Newton's method from above (no libm needed). */
static double voxcolori_root(double x, unsigned n) {
    double y = x > 1 ? x : 1;
    unsigned i;
    if (x <= 0) return 0;
    for (i = 0; i < 64; i++) {
        double p = 1, next;
        unsigned k;
        for (k = 1; k < n; k++) p *= y;
        next = ((n - 1) * y + x / p) / n;
        if (next >= y) break;
        y = next;
    }
    return y;
}

/* Cube root of X > 0: an exponent-thirding first guess (within 4 %), then
   three Halley steps (to the last bit). */
static double voxcolori_cbrt(double x) {
    uint64_t b;
    double y;
    unsigned i;
    memcpy(&b, &x, sizeof b);
    b = b / 3 + 0x2A9F7893782DA1CEull;
    memcpy(&y, &b, sizeof y);
    for (i = 0; i < 3; i++) y = y * (y * y * y + 2 * x) / (2 * y * y * y + x);
    return y;
}

static double voxcolori_lab_f(double t) {
    const double d = 6.0 / 29.0;
    return t > d * d * d ? voxcolori_cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
}

/* CIELAB (D65 white) of an sRGB colour. */
static void voxcolori_lab(const voxcolori_enc *e, const uint8_t c[3], double lab[3]) {
    double r = e->linear[c[0]], g = e->linear[c[1]], b = e->linear[c[2]];
    double fx = voxcolori_lab_f((0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047);
    double fy = voxcolori_lab_f(0.2126729 * r + 0.7151522 * g + 0.0721750 * b);
    double fz = voxcolori_lab_f((0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883);
    lab[0] = 116 * fy - 16;
    lab[1] = 500 * (fx - fy);
    lab[2] = 200 * (fy - fz);
}

static uint32_t voxcolori_dist2(const uint8_t a[3], const uint8_t b[3]) {
    int d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return (uint32_t)(d0 * d0 + d1 * d1 + d2 * d2);
}

/* 1 when decoded colour D is within the bound of original colour C. */
static int voxcolori_close(const voxcolori_enc *e, const uint8_t c[3], const uint8_t d[3]) {
    double a[3], b[3], s = 0;
    unsigned i;
    if (!e->lab) return voxcolori_dist2(c, d) <= e->thr2;
    voxcolori_lab(e, c, a);
    voxcolori_lab(e, d, b);
    for (i = 0; i < 3; i++) s += (a[i] - b[i]) * (a[i] - b[i]);
    return s <= e->lab_thr2;
}

/* The high and low 64 bits of A * B. */
static void voxcolori_mul128(uint64_t a, uint64_t b, uint64_t *hi, uint64_t *lo) {
    uint64_t al = a & 0xffffffffu, ah = a >> 32, bl = b & 0xffffffffu, bh = b >> 32;
    uint64_t ll = al * bl, lh = al * bh, hl = ah * bl, hh = ah * bh;
    uint64_t mid = (ll >> 32) + (lh & 0xffffffffu) + (hl & 0xffffffffu);
    *lo = (mid << 32) | (ll & 0xffffffffu);
    *hi = hh + (lh >> 32) + (hl >> 32) + (mid >> 32);
}

/* 1 when D <= (255 E)^2 exactly (E >= 0, D < 2^18), from E's bits: no
   floating-point rounding, so every compiler agrees. */
static int voxcolori_within(uint32_t d, double e) {
    uint64_t bits, m, hi, lo, dh, dl;
    int shift;
    memcpy(&bits, &e, sizeof bits);
    bits &= ~(1ull << 63); /* -0 is 0 */
    if ((bits >> 52) >= 0x7ff) return 1; /* infinity */
    m = bits & ((1ull << 52) - 1);
    /* e = m 2^shift, then (255 e)^2 = 65025 m^2 2^(2 shift). */
    if (bits >> 52) {
        m |= 1ull << 52;
        shift = (int)(bits >> 52) - 1075;
    } else {
        shift = -1074;
    }
    if (!m || !d) return !d;
    voxcolori_mul128(m, m, &hi, &lo); /* below 2^106 */
    voxcolori_mul128(lo, 65025, &dh, &dl);
    hi = hi * 65025 + dh;
    lo = dl; /* 65025 m^2, below 2^122 */
    shift *= 2;
    if (shift >= 0) return 1; /* 65025 m^2 2^shift >= 65025 > d's bound */
    shift = -shift;
    /* d 2^shift <= hi:lo? d has at most 18 bits. */
    if (shift >= 122 || (shift > 104 && d >> (122 - shift))) return 0; /* d 2^shift >= 2^122 */
    dh = shift >= 64 ? (uint64_t)d << (shift - 64) : shift ? (uint64_t)d >> (64 - shift) : 0;
    dl = shift >= 64 ? 0 : (uint64_t)d << shift;
    return dh < hi || (dh == hi && dl <= lo);
}

/* Smallest integer r with r^2 >= X. */
static uint64_t voxcolori_isqrt_up(uint64_t x) {
    uint64_t r = 0, bit;
    for (bit = 1ull << 31; bit; bit >>= 1)
        if ((r + bit) * (r + bit) <= x) r += bit;
    return r * r < x ? r + 1 : r;
}

/* Effort VOXCOLOR_EFFORT_FAST: RGB565 endpoints from this squared RGB
   bound up (else RGB888), or from this delta E up (CIELAB). */
#define VOXCOLORI_FAST_565_THR2 49u
#define VOXCOLORI_FAST_565_LAB 1.0

/* Sets up the metric and the modes to try from the options. */
static void voxcolori_enc_init(voxcolori_enc *e, const voxcolor_encode_opts *o) {
    uint32_t lo = 0, hi = 3 * 255 * 255;
    unsigned i;
    memset(e, 0, sizeof *e);
    e->page_shift = o->page_shift ? o->page_shift : VOXCOLOR_DEFAULT_PAGE_SHIFT;
    e->lab = o->metric == VOXCOLOR_METRIC_CIELAB && o->max_error > 0;
    e->lab_thr2 = o->max_error * o->max_error;
    /* Largest integer d2 with sqrt(d2) <= 255 max_error, found with exact
       comparisons; 3 * 255^2 covers every colour. */
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo + 1) / 2;
        if (voxcolori_within(mid, o->max_error)) lo = mid;
        else hi = mid - 1;
    }
    e->thr2 = lo;
    /* An interpolated colour lies within sqrt(3) / 2 of its endpoints' line
       (each channel rounded), but blocks that need more than 1 / 2 there
       (lossless), or 1 / 4 (with any room in the bound), are next to none on
       the bench sets: the tests on lines allow that much and reject far more
       windows early. 64 (r + 1 / 4)^2 <= 64 r^2 + sqrt(1024 r^2) + 4 for
       r^2 = thr2, and 64 (1 / 2)^2 = 16. */
    e->line64 = e->thr2 ? 64 * (uint64_t)e->thr2 + voxcolori_isqrt_up(1024 * (uint64_t)e->thr2) + 4 : 16;
    if (e->lab)
        for (i = 0; i < 256; i++) {
            double c = i / 255.0, s = (c + 0.055) / 1.055;
            e->linear[i] = c <= 0.04045 ? c / 12.92 : s * s * voxcolori_root(s * s, 5);
        }
    e->modes[e->mode_count++] = 0;
    for (i = 1; i <= VOXCOLORI_MAX_WEIGHT_BITS; i++)
        if (o->weight_bits ? i == o->weight_bits : 1) e->modes[e->mode_count++] = i;
    /* RGB565 endpoints cannot meet small bounds (rounding alone errs by up to
       6 units); RGB888 endpoints rarely pay off at large ones. */
    if (e->lab || e->thr2 >= 9) e->precisions[e->precision_count++] = 0;
    if (e->lab || e->thr2 < 100) e->precisions[e->precision_count++] = 1;
    /* Fast: the one that pays off more often at this bound. */
    if (o->effort == VOXCOLOR_EFFORT_FAST && e->precision_count == 2) {
        e->precision_count = 1;
        e->precisions[0] = e->lab ? (o->max_error >= VOXCOLORI_FAST_565_LAB ? 0u : 1u)
                                  : (e->thr2 >= VOXCOLORI_FAST_565_THR2 ? 0u : 1u);
    }
}

// -- Encoding: fitting one block

typedef struct voxcolori_fit {
    unsigned mode, precision;
    unsigned q0[3], q1[3]; /* quantized endpoints as stored */
    unsigned e0[3], e1[3]; /* the same, expanded to 8 bits */
    int d[3], dd;          /* e1 - e0 and its squared length */
    uint64_t inverse;      /* 2^40 / (2 dd), for projections without division */
} voxcolori_fit;

/* Sets the segment fields of F from its endpoints. */
static void voxcolori_fit_segment(voxcolori_fit *f) {
    unsigned i;
    for (i = 0, f->dd = 0; i < 3; i++) {
        f->d[i] = (int)f->e1[i] - (int)f->e0[i];
        f->dd += f->d[i] * f->d[i];
    }
    f->inverse = f->dd ? (1ull << 40) / (2 * (uint64_t)f->dd) : 0;
}

/* The code of B bits whose expansion is nearest to X (in 256ths, 0 .. 255 *
   256). */
static VOXCOLORI_ALWAYS_INLINE unsigned voxcolori_quantize_channel(int64_t x, unsigned b) {
    unsigned top = (1u << b) - 1, k = (unsigned)((x * top + 255 * 128) / (255 * 256));
    /* Bit replication is not uniform: the next code may be nearer. */
    if (k < top && 256 * (int64_t)voxcolori_expand(k + 1, b) - x < x - 256 * (int64_t)voxcolori_expand(k, b)) k++;
    else if (k && x - 256 * (int64_t)voxcolori_expand(k - 1, b) < 256 * (int64_t)voxcolori_expand(k, b) - x) k--;
    return k;
}

/* Rounds V (channels in 256ths, 0 .. 255 * 256) to the nearest endpoint of
   PRECISION. */
static void voxcolori_quantize(const int64_t v[3], unsigned precision, unsigned q[3],
                               unsigned e[3]) {
    unsigned c;
    if (precision) {
        /* 8 bits: round(x / 256). */
        for (c = 0; c < 3; c++) q[c] = e[c] = (unsigned)((v[c] + 128) >> 8);
        return;
    }
    q[0] = voxcolori_quantize_channel(v[0], 5);
    q[1] = voxcolori_quantize_channel(v[1], 6);
    q[2] = voxcolori_quantize_channel(v[2], 5);
    e[0] = voxcolori_expand(q[0], 5);
    e[1] = voxcolori_expand(q[1], 6);
    e[2] = voxcolori_expand(q[2], 5);
}

/* Interpolated colour for weight index K of a width-W block. */
static void voxcolori_mix(const unsigned e0[3], const unsigned e1[3], unsigned w, unsigned k,
                          uint8_t out[3]) {
    unsigned t = voxcolori_weights[w][k], c;
    for (c = 0; c < 3; c++) out[c] = (uint8_t)((e0[c] * (64 - t) + e1[c] * t + 32) >> 6);
}

/* The weight index whose interpolation point is nearest to C's projection
   onto the endpoint segment. */
static VOXCOLORI_ALWAYS_INLINE unsigned voxcolori_project(const voxcolori_fit *f, const uint8_t c[3]) {
    unsigned top = (1u << f->mode) - 1, k;
    int dot = ((int)c[0] - (int)f->e0[0]) * f->d[0] + ((int)c[1] - (int)f->e0[1]) * f->d[1] +
              ((int)c[2] - (int)f->e0[2]) * f->d[2];
    uint64_t num, den = 2 * (uint64_t)f->dd;
    if (f->dd == 0 || dot <= 0) return 0;
    if (dot >= f->dd) return top;
    /* k = floor(num / den) for num = 2 dot top + dd, from the inverse (never
       above: it is rounded down, and at most 1 below), then corrected to the
       exact quotient. */
    num = 2 * (uint64_t)dot * top + (uint64_t)f->dd;
    k = (unsigned)((num * f->inverse) >> 40);
    if ((k + 1) * den <= num) k++;
    return k;
}

/* Squared RGB distance from C of the colour weight index K of F (mode > 0)
   decodes to: voxcolori_mix with the channels written out. */
static VOXCOLORI_ALWAYS_INLINE uint32_t voxcolori_mix_dist2(const voxcolori_fit *f, unsigned k,
                                                            const uint8_t c[3]) {
    int t = voxcolori_weights[f->mode][k];
    int d0 = ((64 * (int)f->e0[0] + f->d[0] * t + 32) >> 6) - c[0];
    int d1 = ((64 * (int)f->e0[1] + f->d[1] * t + 32) >> 6) - c[1];
    int d2 = ((64 * (int)f->e0[2] + f->d[2] * t + 32) >> 6) - c[2];
    return (uint32_t)(d0 * d0 + d1 * d1 + d2 * d2);
}

/* The weight index decoding closest (in RGB) to C: the projection or a
   neighbour (the 64ths are not evenly spaced). */
static VOXCOLORI_ALWAYS_INLINE unsigned voxcolori_pick(const voxcolori_fit *f, const uint8_t c[3]) {
    unsigned top = (1u << f->mode) - 1, k = voxcolori_project(f, c), best = k;
    uint32_t err = voxcolori_mix_dist2(f, k, c), lower;
    /* Ties go to the lower index. */
    if (k && (lower = voxcolori_mix_dist2(f, k - 1, c)) <= err) best = k - 1, err = lower;
    if (k < top && err && voxcolori_mix_dist2(f, k + 1, c) < err) best = k + 1;
    return best;
}

/* 1 when colour C decodes within the bound under fit F. */
static VOXCOLORI_ALWAYS_INLINE int voxcolori_fits(const voxcolori_enc *e, const voxcolori_fit *f,
                                                  const uint8_t c[3]) {
    uint8_t d[3];
    if (!e->lab) {
        unsigned k, top = (1u << f->mode) - 1;
        int d0 = (int)f->e0[0] - c[0], d1 = (int)f->e0[1] - c[1], d2 = (int)f->e0[2] - c[2];
        if (f->mode == 0) return (uint32_t)(d0 * d0 + d1 * d1 + d2 * d2) <= e->thr2;
        /* The pick (the nearest of the projection's weight and its two
           neighbours) fits when any of the three does: the projection first. */
        k = voxcolori_project(f, c);
        if (voxcolori_mix_dist2(f, k, c) <= e->thr2) return 1;
        if (k && voxcolori_mix_dist2(f, k - 1, c) <= e->thr2) return 1;
        return k < top && voxcolori_mix_dist2(f, k + 1, c) <= e->thr2;
    }
    if (f->mode == 0) {
        d[0] = (uint8_t)f->e0[0];
        d[1] = (uint8_t)f->e0[1];
        d[2] = (uint8_t)f->e0[2];
    } else {
        voxcolori_mix(f->e0, f->e1, f->mode, voxcolori_pick(f, c), d);
    }
    return voxcolori_close(e, c, d);
}

/* 1 when no line passes within R of the three colours P (R^2 = line64 / 64,
   RGB metric): when their triangle's area A and longest side L have
   A / L > R, i.e. |cross|^2 > 4 R^2 L^2. No block with weights then holds
   all three (but for rounding: see line64). */
static int voxcolori_off_line(const voxcolori_enc *e, const uint8_t *p) {
    int64_t u0 = p[3] - p[0], u1 = p[4] - p[1], u2 = p[5] - p[2];
    int64_t v0 = p[6] - p[0], v1 = p[7] - p[1], v2 = p[8] - p[2];
    int64_t w0 = v0 - u0, w1 = v1 - u1, w2 = v2 - u2;
    int64_t x0 = u1 * v2 - u2 * v1, x1 = u2 * v0 - u0 * v2, x2 = u0 * v1 - u1 * v0;
    int64_t l2 = u0 * u0 + u1 * u1 + u2 * u2, m2 = v0 * v0 + v1 * v1 + v2 * v2;
    if (m2 > l2) l2 = m2;
    m2 = w0 * w0 + w1 * w1 + w2 * w2;
    if (m2 > l2) l2 = m2;
    return 16 * (x0 * x0 + x1 * x1 + x2 * x2) > (int64_t)e->line64 * l2;
}

/* 1 when no block of MODE can hold N colours whose covariance times N^2 is
   C (RGB metric): their root-mean-square distance from the mean (mode 0), or
   from any line (the sum of the covariance's two smaller eigenvalues, at
   least its trace minus its Frobenius norm), exceeds what the bound allows.
   Rejects most failing windows before any endpoint is fitted. Integer
   arithmetic: the same answer on every compiler and processor. */
static int voxcolori_hopeless(const voxcolori_enc *e, int64_t c[3][3], size_t n, unsigned mode) {
    int64_t n2 = (int64_t)n * (int64_t)n, tr = c[0][0] + c[1][1] + c[2][2], big, fro = 0, x[6];
    unsigned a, shift = 0;
    if (mode == 0) return tr > (int64_t)e->thr2 * n2;
    if (n <= 2) return 0;
    /* trace - R^2 > Frobenius norm, in 64 N^2 units, squares taken after
       dropping low bits (of magnitudes: shifts, no division) so that nothing
       overflows. */
    tr = 64 * tr - (int64_t)e->line64 * n2;
    if (tr <= 0) return 0;
    x[0] = c[0][0], x[1] = c[1][1], x[2] = c[2][2], x[3] = c[0][1], x[4] = c[0][2], x[5] = c[1][2];
    for (big = tr, a = 0; a < 6; a++) {
        x[a] = 64 * (x[a] < 0 ? -x[a] : x[a]);
        big = x[a] > big ? x[a] : big;
    }
    while (big >> shift >= (1ll << 29)) shift++;
    /* Each off-diagonal entry appears twice. */
    for (a = 0; a < 6; a++) fro += (a < 3 ? 1 : 2) * (x[a] >> shift) * (x[a] >> shift);
    tr >>= shift;
    return tr * tr > fro;
}

/* Scales direction V (not all zero) so that its largest component has 15
   bits: the power iteration's products then stay below 2^53. Inlined: as a
   call it costs gcc about 5 % of the encoder's time. */
static VOXCOLORI_ALWAYS_INLINE void voxcolori_normalize(int64_t v[3]) {
    int64_t a0 = v[0] < 0 ? -v[0] : v[0], a1 = v[1] < 0 ? -v[1] : v[1], a2 = v[2] < 0 ? -v[2] : v[2];
    int64_t m = a0 | a1 | a2; /* the largest's top bit */
    unsigned bits = 0, k;
    if (!m) {
        v[0] = v[1] = v[2] = 1 << 14;
        return;
    }
#if defined(__GNUC__) || defined(__clang__)
    bits = 63u - (unsigned)__builtin_clzll((unsigned long long)m);
    (void)k;
#else
    for (k = 32; k; k >>= 1)
        if (m >> (bits + k)) bits += k;
#endif
    /* m has bits + 1 bits. */
    if (bits > 14) {
        a0 >>= bits - 14, a1 >>= bits - 14, a2 >>= bits - 14;
    } else {
        a0 <<= 14 - bits, a1 <<= 14 - bits, a2 <<= 14 - bits;
    }
    v[0] = v[0] < 0 ? -a0 : a0;
    v[1] = v[1] < 0 ? -a1 : a1;
    v[2] = v[2] < 0 ? -a2 : a2;
}

/* NUM / DEN rounded to the nearest integer, DEN > 0. */
static int64_t voxcolori_div_round(int64_t num, int64_t den) {
    return num >= 0 ? (num + den / 2) / den : -((den / 2 - num) / den);
}

/* The channel sums S of the N colours RGB and N^2 times their covariance C
   (below 2^37). The sums fit 32 bits: at most 1024 colours of 255^2. */
static void voxcolori_moments(const uint8_t *rgb, size_t n, int64_t s[3], int64_t c[3][3]) {
    uint32_t s0 = 0, s1 = 0, s2 = 0, q00 = 0, q01 = 0, q02 = 0, q11 = 0, q12 = 0, q22 = 0;
    int64_t nn = (int64_t)n;
    size_t i;
    for (i = 0; i < n; i++, rgb += 3) {
        uint32_t r = rgb[0], g = rgb[1], b = rgb[2];
        s0 += r, s1 += g, s2 += b;
        q00 += r * r, q01 += r * g, q02 += r * b;
        q11 += g * g, q12 += g * b, q22 += b * b;
    }
    s[0] = s0, s[1] = s1, s[2] = s2;
    c[0][0] = nn * q00 - s[0] * s[0];
    c[1][1] = nn * q11 - s[1] * s[1];
    c[2][2] = nn * q22 - s[2] * s[2];
    c[0][1] = c[1][0] = nn * q01 - s[0] * s[1];
    c[0][2] = c[2][0] = nn * q02 - s[0] * s[2];
    c[1][2] = c[2][1] = nn * q12 - s[1] * s[2];
}

/* Chooses a segment for the N colours RGB, its ends LO and HI in 256ths of
   a channel unit; returns 0 when no block of MODE can hold them
   (voxcolori_hopeless), else 1. Mode 0: the centre of their bounding box
   (in LO). Else the extreme projections on their principal axis (power
   iteration on the covariance; two colours are their own extremes). All in
   integers, so that the stream does not depend on floating point. */
static int voxcolori_fit_line(const voxcolori_enc *e, const uint8_t *rgb, size_t n,
                              unsigned mode, int64_t lo[3], int64_t hi[3]) {
    int64_t s[3], c[3][3], v[3], w[3], tmin, tmax, vv;
    int64_t nn = (int64_t)n;
    int32_t pmin, pmax;
    unsigned a, it, mn[3] = {255, 255, 255}, mx[3] = {0, 0, 0};
    size_t i;
    voxcolori_moments(rgb, n, s, c);
    if (!e->lab && n > 1 && voxcolori_hopeless(e, c, n, mode)) return 0;
    if (mode == 0) {
        for (i = 0; i < n; i++)
            for (a = 0; a < 3; a++) {
                mn[a] = rgb[3 * i + a] < mn[a] ? rgb[3 * i + a] : mn[a];
                mx[a] = rgb[3 * i + a] > mx[a] ? rgb[3 * i + a] : mx[a];
            }
        for (a = 0; a < 3; a++) lo[a] = 128 * (int64_t)(mn[a] + mx[a]);
        return 1;
    }
    if (n <= 2) {
        /* The principal axis of two colours runs through both. */
        for (a = 0; a < 3; a++) {
            lo[a] = 256 * (int64_t)rgb[a];
            hi[a] = 256 * (int64_t)rgb[3 * (n - 1) + a];
        }
        return 1;
    }
    /* Start from the widest channel's column (one iteration); two more
       settle the axis well enough for the extremes. */
    it = c[1][1] > c[0][0] ? 1u : 0u;
    if (c[2][2] > c[it][it]) it = 2;
    for (a = 0; a < 3; a++) v[a] = c[a][it] + (a == it);
    for (it = 0; it < 2; it++) {
        voxcolori_normalize(v);
        for (a = 0; a < 3; a++) w[a] = c[a][0] * v[0] + c[a][1] * v[1] + c[a][2] * v[2];
        if (!w[0] && !w[1] && !w[2]) break;
        memcpy(v, w, sizeof v);
    }
    voxcolori_normalize(v);
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    /* Extreme projections c . v (below 2^25: v has 15 bits), then centred
       and times N: (N c - S) . v. */
    for (i = 0, pmin = INT32_MAX, pmax = INT32_MIN; i < n; i++) {
        const uint8_t *p = rgb + 3 * i;
        int32_t t = p[0] * (int32_t)v[0] + p[1] * (int32_t)v[1] + p[2] * (int32_t)v[2];
        pmin = t < pmin ? t : pmin;
        pmax = t > pmax ? t : pmax;
    }
    tmin = nn * pmin - (s[0] * v[0] + s[1] * v[1] + s[2] * v[2]);
    tmax = nn * pmax - (s[0] * v[0] + s[1] * v[1] + s[2] * v[2]);
    /* Ends mean + t v / (N vv), in 256ths (below 2^59), in the colour cube. */
    for (a = 0; a < 3; a++) {
        lo[a] = voxcolori_div_round(256 * (s[a] * vv + tmin * v[a]), nn * vv);
        hi[a] = voxcolori_div_round(256 * (s[a] * vv + tmax * v[a]), nn * vv);
        lo[a] = lo[a] < 0 ? 0 : lo[a] > 255 * 256 ? 255 * 256 : lo[a];
        hi[a] = hi[a] < 0 ? 0 : hi[a] > 255 * 256 ? 255 * 256 : hi[a];
    }
    return 1;
}

/* Sets F's endpoints to the segment LO..HI (LO alone for mode 0) rounded to
   F's precision. */
static void voxcolori_fit_quantize(voxcolori_fit *f, const int64_t lo[3], const int64_t hi[3]) {
    voxcolori_quantize(lo, f->precision, f->q0, f->e0);
    if (!f->mode) return;
    voxcolori_quantize(hi, f->precision, f->q1, f->e1);
    voxcolori_fit_segment(f);
}

/* Segments for windows of colours of one page, by start and length, as
   fitted for modes 1..4 (they all get the same), and their endpoints for
   each precision: each mode's and precision's search reuses the fits of the
   others. Direct-mapped by length. */
#define VOXCOLORI_CACHE_SIZE 32u
typedef struct voxcolori_cache {
    size_t start;                     /* of the windows fitted now */
    size_t key[VOXCOLORI_CACHE_SIZE]; /* start * 2048 + length; 0: empty */
    int fitted[VOXCOLORI_CACHE_SIZE];
    int64_t lo[VOXCOLORI_CACHE_SIZE][3], hi[VOXCOLORI_CACHE_SIZE][3];
    size_t fit_key[2][VOXCOLORI_CACHE_SIZE]; /* by precision, as key */
    voxcolori_fit fit[2][VOXCOLORI_CACHE_SIZE];
    size_t line_ok; /* no three of the first LINE_OK colours lie off every line */
    size_t miss;    /* the colour that failed the last check, the likeliest next */
} voxcolori_cache;

/* 1 when three consecutive colours of the N from CACHE's start lie off every
   line (RGB metric), so that no block with weights holds them: checks only
   windows of up to 8 colours (longer ones are refits of blocks that mostly
   pass), and only colours past those known to pass. */
static int voxcolori_off_lines(const voxcolori_enc *e, const uint8_t *rgb, size_t n,
                               voxcolori_cache *cache) {
    if (e->lab || n > 8) return 0;
    for (; cache->line_ok < n; cache->line_ok++)
        if (voxcolori_off_line(e, rgb + 3 * (cache->line_ok - 2))) return 1;
    return 0;
}

/* Chooses endpoints of F's mode and precision for the N colours RGB, through
   CACHE when F has weights; returns 0 when no block of F's mode can hold
   them. */
static int voxcolori_fit_endpoints(const voxcolori_enc *e, const uint8_t *rgb, size_t n,
                                   voxcolori_fit *f, voxcolori_cache *cache) {
    unsigned slot = (unsigned)(n % VOXCOLORI_CACHE_SIZE), mode = f->mode, p = f->precision;
    size_t key = cache->start * 2048 + n;
    int64_t lo[3], hi[3];
    if (!mode) {
        if (!voxcolori_fit_line(e, rgb, n, 0, lo, hi)) return 0;
        voxcolori_fit_quantize(f, lo, hi);
        return 1;
    }
    if (cache->key[slot] != key) {
        cache->key[slot] = key;
        cache->fitted[slot] = !voxcolori_off_lines(e, rgb, n, cache) &&
                              voxcolori_fit_line(e, rgb, n, mode, cache->lo[slot], cache->hi[slot]);
    }
    if (!cache->fitted[slot]) return 0;
    if (cache->fit_key[p][slot] != key) {
        cache->fit_key[p][slot] = key;
        cache->fit[p][slot] = *f;
        voxcolori_fit_quantize(&cache->fit[p][slot], cache->lo[slot], cache->hi[slot]);
    }
    *f = cache->fit[p][slot];
    f->mode = mode;
    return 1;
}

/* Fits endpoints of F's mode and precision to the N colours RGB from
   CACHE's start; 1 when all of them decode within the bound. */
static int voxcolori_fit_block(const voxcolori_enc *e, const uint8_t *rgb, size_t n,
                               voxcolori_fit *f, voxcolori_cache *cache) {
    size_t i;
    if (!voxcolori_fit_endpoints(e, rgb, n, f, cache)) return 0;
    /* The likeliest misses first: the last one, then from the last colour
       (the one a refit was made for). */
    if (cache->miss < n && !voxcolori_fits(e, f, rgb + 3 * cache->miss)) return 0;
    for (i = n; i--;)
        if (!voxcolori_fits(e, f, rgb + 3 * i)) {
            cache->miss = i;
            return 0;
        }
    return 1;
}

/* Length of the longest prefix of RGB[0..n) that one block of F's mode and
   precision encodes within the bound, with its endpoints in F; 0 when not
   even the first MIN colours fit (shorter blocks would not pay). Colours
   that fit the current endpoints are accepted as they are; one that does
   not triggers a refit including it, and repeated refits a refit over twice
   the length (so gradients cost O(n log n)). */
static size_t voxcolori_extend(const voxcolori_enc *e, const uint8_t *rgb, size_t n, size_t min,
                               voxcolori_fit *f, voxcolori_cache *cache) {
    voxcolori_fit t = *f;
    size_t len = min < n ? min : n, streak = 0;
    if (!voxcolori_fit_block(e, rgb, len, f, cache)) return 0;
    while (len < n) {
        size_t guess = 2 * len + 1 < n ? 2 * len + 1 : n;
        if (voxcolori_fits(e, f, rgb + 3 * len)) {
            len++;
            continue;
        }
        if (!voxcolori_fit_block(e, rgb, len + 1, &t, cache)) break;
        *f = t;
        len++;
        /* Colours drifting out of every fit (a gradient): refit ahead. */
        if (++streak >= 2 && guess > len && voxcolori_fit_block(e, rgb, guess, &t, cache)) {
            *f = t;
            len = guess;
            streak = 0;
        }
    }
    return len;
}

// -- Encoding: bit writer and pages

typedef struct voxcolori_writer {
    uint8_t *p;
    uint64_t acc;
    unsigned n;
} voxcolori_writer;

static void voxcolori_put(voxcolori_writer *w, uint64_t v, unsigned bits) {
    w->acc |= v << w->n;
    w->n += bits;
    while (w->n >= 8) {
        *w->p++ = (uint8_t)w->acc;
        w->acc >>= 8;
        w->n -= 8;
    }
}

static void voxcolori_put_endpoint(voxcolori_writer *w, const unsigned q[3], unsigned precision) {
    unsigned k, v = 0;
    for (k = 0; k < 3; k++) v |= q[k] << voxcolori_channel_shift(k, precision);
    voxcolori_put(w, v, precision ? 24u : 16u);
}

/* A planned block: its directory entry (mode, precision, length - 1 from
   bit 4) in bits 0..15, its endpoints as stored in bits 16..39 and 40..63. */
static uint64_t voxcolori_plan(unsigned mode, const voxcolori_fit *f, size_t length) {
    uint64_t v = mode | (uint64_t)(length - 1) << 4, c;
    unsigned k;
    if (!f) return v;
    v |= (uint64_t)f->precision << 3;
    for (k = 0, c = 0; k < 3; k++) c |= (uint64_t)f->q0[k] << voxcolori_channel_shift(k, f->precision);
    v |= c << 16;
    for (k = 0, c = 0; k < 3; k++) c |= (uint64_t)f->q1[k] << voxcolori_channel_shift(k, f->precision);
    return v | c << 40;
}

/* Plans the N colours of one page greedily: at each position, the block (of
   every mode and precision tried, as long as it fits) with the fewest bits
   per colour; colours that no block stores in fewer than 24 bits go into raw
   blocks. Writes the plan to PLAN and returns the number of blocks. The page
   then takes at most as many bits as one raw block. */
static size_t voxcolori_plan_page(const voxcolori_enc *e, const uint8_t *rgb, size_t n,
                                  uint64_t *plan) {
    /* A block's directory entry and its share of the checkpoints (one per 8
       blocks, rounded up). */
    size_t pos = 0, raw_start = 0, blocks = 0, entry = 8 * voxcolori_index_bytes(e->page_shift) + 4 + 2;
    voxcolori_cache cache; /* 7 KiB */
    memset(cache.key, 0, sizeof cache.key);
    memset(cache.fit_key, 0, sizeof cache.fit_key);
    while (pos < n) {
        voxcolori_fit best, f;
        size_t best_len = 0, best_bits = 0, len;
        unsigned m, p;
        /* Blocks are at least 2 colours long, those with weights 3: these
           tests fail blocks starting here sooner than fitting them would. A
           single colour (mode 0) lies within R of the first two only if they
           lie within 2 R of each other; of three colours, two share one of
           the two colours of mode 1. */
        const uint8_t *c = rgb + 3 * pos;
        int no_single = !e->lab && n - pos >= 2 && voxcolori_dist2(c, c + 3) > 4 * e->thr2;
        int no_pair = no_single && n - pos >= 3 && voxcolori_dist2(c, c + 6) > 4 * e->thr2 &&
                      voxcolori_dist2(c + 3, c + 6) > 4 * e->thr2;
        int no_line = !e->lab && n - pos >= 3 && voxcolori_off_line(e, c);
        if (no_single && no_line) {
            pos++;
            continue;
        }
        memset(&best, 0, sizeof best);
        cache.start = pos;
        cache.line_ok = 3; /* the first three pass no_line */
        cache.miss = 0;
        for (m = 0; m < e->mode_count; m++) {
            f.mode = e->modes[m];
            if (f.mode == 0 ? no_single : no_line || (f.mode == 1 && no_pair)) continue;
            /* A wider mode costs more than f.mode bits per colour. */
            if (best_len && best_bits <= f.mode * best_len) break;
            for (p = 0; p < e->precision_count; p++) {
                size_t bits, fixed;
                f.precision = e->precisions[p];
                /* Blocks shorter than this cost more than raw colours. */
                fixed = 2 * entry + voxcolori_endpoint_bits(f.mode, f.precision);
                len = (fixed + 23 - f.mode) / (24 - f.mode);
                /* Only blocks of BEAT colours or more beat the best one yet:
                   the search starts there, or just past the best block if
                   that is sooner (a window the searches of every mode and
                   precision share, and growing a fit from there finds
                   blocks one fit over BEAT colours would miss). */
                if (best_len) {
                    size_t beat = (fixed - entry) * best_len / (best_bits - f.mode * best_len) + 1;
                    if (beat > n - pos) continue;
                    beat = beat < best_len + 1 ? beat : best_len + 1;
                    len = beat < len ? len : beat;
                }
                if (len > n - pos) len = n - pos;
                len = voxcolori_extend(e, rgb + 3 * pos, n - pos, len, &f, &cache);
                if (!len) continue;
                bits = entry + voxcolori_endpoint_bits(f.mode, f.precision) + f.mode * len;
                if (!best_len || bits * best_len < best_bits * len ||
                    (bits * best_len == best_bits * len && len > best_len))
                    best = f, best_len = len, best_bits = bits;
            }
            /* No wider block can be longer than one reaching the page end. */
            if (best_len == n - pos) break;
        }
        /* Worth it only if it also pays for the entry of the raw block it may
           interrupt. */
        if (!best_len || best_bits + entry > 24 * best_len) {
            pos++;
            continue;
        }
        if (raw_start < pos) plan[blocks++] = voxcolori_plan(VOXCOLORI_MODE_RAW, NULL, pos - raw_start);
        plan[blocks++] = voxcolori_plan(best.mode, &best, best_len);
        pos += best_len;
        raw_start = pos;
    }
    if (raw_start < n) plan[blocks++] = voxcolori_plan(VOXCOLORI_MODE_RAW, NULL, n - raw_start);
    return blocks;
}

/* Writes a planned page: block count, directory, payloads. */
static void voxcolori_write_page(voxcolori_writer *w, const uint8_t *rgb, const uint64_t *plan,
                                 size_t blocks, unsigned page_shift) {
    size_t b, i, end;
    unsigned index_bits = 8 * voxcolori_index_bytes(page_shift), pass;
    uint64_t payload = 0;
    voxcolori_put(w, blocks - 1, index_bits);
    /* Directory: the last colour of each group of 8 blocks, then of the
       other blocks of each group, then the nibbles. */
    for (pass = 0; pass < 2; pass++)
        for (b = 0, end = 0; b < blocks; b++) {
            end += (size_t)((plan[b] >> 4) & 0xfff) + 1;
            if ((b % 8 == 7 || b + 1 == blocks) == !pass) voxcolori_put(w, end - 1, index_bits);
        }
    for (b = 0; b < blocks; b++) voxcolori_put(w, plan[b] & 15, 4);
    if (blocks & 1) voxcolori_put(w, 0, 4);
    /* Checkpoints: the payload offset of every 8th block after the first. */
    for (b = 0; b < blocks; b++) {
        unsigned mode = (unsigned)(plan[b] & 7), precision = (unsigned)(plan[b] >> 3) & 1;
        if (b && !(b & ((1u << VOXCOLORI_GROUP_SHIFT) - 1))) voxcolori_put(w, payload, 16);
        payload += voxcolori_block_bits(mode, precision, ((plan[b] >> 4) & 0xfff) + 1);
    }
    for (b = 0; b < blocks; b++) {
        unsigned mode = (unsigned)(plan[b] & 7), k;
        size_t n = (size_t)((plan[b] >> 4) & 0xfff) + 1;
        voxcolori_fit f;
        if (mode == VOXCOLORI_MODE_RAW) {
            for (i = 0; i < n; i++)
                voxcolori_put(w, rgb[3 * i] | (unsigned)rgb[3 * i + 1] << 8 | (unsigned)rgb[3 * i + 2] << 16, 24);
            rgb += 3 * n;
            continue;
        }
        f.mode = mode;
        f.precision = (unsigned)(plan[b] >> 3) & 1;
        for (k = 0; k < 3; k++) {
            unsigned bits = voxcolori_channel_bits(k, f.precision);
            unsigned at = voxcolori_channel_shift(k, f.precision);
            f.q0[k] = (unsigned)(plan[b] >> (16 + at)) & ((1u << bits) - 1);
            f.q1[k] = (unsigned)(plan[b] >> (40 + at)) & ((1u << bits) - 1);
            f.e0[k] = voxcolori_expand(f.q0[k], bits);
            f.e1[k] = voxcolori_expand(f.q1[k], bits);
        }
        voxcolori_fit_segment(&f);
        voxcolori_put_endpoint(w, f.q0, f.precision);
        if (mode) voxcolori_put_endpoint(w, f.q1, f.precision);
        for (i = 0; i < n && mode; i++) voxcolori_put(w, voxcolori_pick(&f, rgb + 3 * i), mode);
        rgb += 3 * n;
    }
}

VOXCOLOR_API size_t voxcolor_encode_bound(size_t count) {
    size_t pages = count / 16 + 1;
    /* Header, 8-byte page entries, a raw block per page (at most 24 bits of
       count and entry, one padding byte), 8 closing bytes. */
    if (count > ((size_t)-1 - 64) / 4) return 0;
    return VOXCOLOR_HEADER_SIZE + 8 + pages * 11 + 3 * count;
}

// -- Encoding: options

/* Checks every field of O, in every build. */
static voxcolor_status voxcolori_check_opts(const voxcolor_encode_opts *o, voxcolor_error *err) {
    const voxcolor_status bad = VOXCOLOR_ERR_INVALID_ARGUMENT;
    if (o->zero_begin || o->zero_end)
        return voxcolori_report(err, bad, "options not zero-initialised (zero_begin or zero_end is set)", UINT64_MAX);
    if (!(o->max_error >= 0)) return voxcolori_report(err, bad, "max_error is negative or NaN", UINT64_MAX);
    if ((uint32_t)o->metric >= VOXCOLOR_METRIC_COUNT)
        return voxcolori_report(err, bad, "metric is not a voxcolor_metric", UINT64_MAX);
    if (o->weight_bits > VOXCOLORI_MAX_WEIGHT_BITS)
        return voxcolori_report(err, bad, "weight_bits is not 0..4", UINT64_MAX);
    if (o->page_shift && (o->page_shift < VOXCOLOR_MIN_PAGE_SHIFT || o->page_shift > VOXCOLOR_MAX_PAGE_SHIFT))
        return voxcolori_report(err, bad, "page_shift is not 0 or 4..10", UINT64_MAX);
    if ((uint32_t)o->effort >= VOXCOLOR_EFFORT_COUNT)
        return voxcolori_report(err, bad, "effort is not a voxcolor_effort", UINT64_MAX);
    return VOXCOLOR_OK;
}

// -- Encoding: the built-in thread pool

/* Workers that live for one voxcolor_encode or voxcolor_encoder_push call
   and run every batch of it: created on the first batch, joined at the end
   of the call. On the stack of that call; nothing is allocated. */
#ifndef VOXCOLOR_NO_THREADS
#if defined(_WIN32)
/* Only what threads need, and no min/max macros in the includer's unit;
   an includer's own choice of these two macros is kept. */
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#define VOXCOLORI_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#define VOXCOLORI_NOMINMAX
#endif
#include <windows.h>
#ifdef VOXCOLORI_LEAN_AND_MEAN
#undef WIN32_LEAN_AND_MEAN
#undef VOXCOLORI_LEAN_AND_MEAN
#endif
#ifdef VOXCOLORI_NOMINMAX
#undef NOMINMAX
#undef VOXCOLORI_NOMINMAX
#endif
typedef CRITICAL_SECTION voxcolori_mutex;
typedef CONDITION_VARIABLE voxcolori_cond;
typedef HANDLE voxcolori_thread;
#define voxcolori_mutex_init(m) InitializeCriticalSection(m)
#define voxcolori_mutex_destroy(m) DeleteCriticalSection(m)
#define voxcolori_lock(m) EnterCriticalSection(m)
#define voxcolori_unlock(m) LeaveCriticalSection(m)
#define voxcolori_cond_init(c) InitializeConditionVariable(c)
#define voxcolori_cond_destroy(c) ((void)(c))
#define voxcolori_wait(c, m) SleepConditionVariableCS(c, m, INFINITE)
#define voxcolori_wake_all(c) WakeAllConditionVariable(c)
#else
#include <pthread.h>
typedef pthread_mutex_t voxcolori_mutex;
typedef pthread_cond_t voxcolori_cond;
typedef pthread_t voxcolori_thread;
#define voxcolori_mutex_init(m) pthread_mutex_init(m, NULL)
#define voxcolori_mutex_destroy(m) pthread_mutex_destroy(m)
#define voxcolori_lock(m) pthread_mutex_lock(m)
#define voxcolori_unlock(m) pthread_mutex_unlock(m)
#define voxcolori_cond_init(c) pthread_cond_init(c, NULL)
#define voxcolori_cond_destroy(c) pthread_cond_destroy(c)
#define voxcolori_wait(c, m) pthread_cond_wait(c, m)
#define voxcolori_wake_all(c) pthread_cond_broadcast(c)
#endif

typedef struct voxcolori_pool {
    voxcolori_mutex lock;
    voxcolori_cond wake, done;
    voxcolor_job_fn job;
    void *job_user;
    uint32_t count, next, finished, generation, started;
    int quit;
    voxcolori_thread tid[VOXCOLOR_MAX_THREADS - 1];
} voxcolori_pool;

/* Runs the current round's jobs until none is left. Called and returns with
   the lock held. */
static void voxcolori_pool_work(voxcolori_pool *p) {
    while (p->next < p->count) {
        uint32_t i = p->next++;
        voxcolor_job_fn job = p->job;
        void *user = p->job_user;
        voxcolori_unlock(&p->lock);
        job(user, i);
        voxcolori_lock(&p->lock);
        if (++p->finished == p->count) voxcolori_wake_all(&p->done);
    }
}

static void voxcolori_pool_worker(voxcolori_pool *p) {
    uint32_t seen = 0;
    voxcolori_lock(&p->lock);
    for (;;) {
        while (!p->quit && p->generation == seen) voxcolori_wait(&p->wake, &p->lock);
        if (p->quit) break;
        seen = p->generation;
        voxcolori_pool_work(p);
    }
    voxcolori_unlock(&p->lock);
}

#if defined(_WIN32)
static DWORD WINAPI voxcolori_pool_main(LPVOID p) {
    voxcolori_pool_worker((voxcolori_pool *)p);
    return 0;
}
#else
static void *voxcolori_pool_main(void *p) {
    voxcolori_pool_worker((voxcolori_pool *)p);
    return NULL;
}
#endif

/* Starts THREADS - 1 workers (fewer if the system refuses some: the calling
   thread runs what they do not). */
static void voxcolori_pool_start(voxcolori_pool *p, uint32_t threads) {
    memset(p, 0, sizeof *p);
    voxcolori_mutex_init(&p->lock);
    voxcolori_cond_init(&p->wake);
    voxcolori_cond_init(&p->done);
    for (; p->started + 1 < threads; p->started++) {
#if defined(_WIN32)
        p->tid[p->started] = CreateThread(NULL, 0, voxcolori_pool_main, p, 0, NULL);
        if (!p->tid[p->started]) break;
#else
        if (pthread_create(&p->tid[p->started], NULL, voxcolori_pool_main, p) != 0) break;
#endif
    }
}

/* voxcolor_thread_pool.run of the built-in pool: the calling thread works too. */
static void voxcolori_pool_run(void *user, voxcolor_job_fn job, void *job_user, uint32_t count) {
    voxcolori_pool *p = (voxcolori_pool *)user;
    voxcolori_lock(&p->lock);
    p->job = job;
    p->job_user = job_user;
    p->count = count;
    p->next = 0;
    p->finished = 0;
    p->generation++;
    voxcolori_wake_all(&p->wake);
    voxcolori_pool_work(p);
    while (p->finished < p->count) voxcolori_wait(&p->done, &p->lock);
    voxcolori_unlock(&p->lock);
}

static void voxcolori_pool_stop(voxcolori_pool *p) {
    uint32_t t;
    voxcolori_lock(&p->lock);
    p->quit = 1;
    voxcolori_wake_all(&p->wake);
    voxcolori_unlock(&p->lock);
    for (t = 0; t < p->started; t++) {
#if defined(_WIN32)
        WaitForSingleObject(p->tid[t], INFINITE);
        CloseHandle(p->tid[t]);
#else
        pthread_join(p->tid[t], NULL);
#endif
    }
    voxcolori_cond_destroy(&p->wake);
    voxcolori_cond_destroy(&p->done);
    voxcolori_mutex_destroy(&p->lock);
}
#endif /* VOXCOLOR_NO_THREADS */

// -- Encoding: streams

/* Hands the buffered block data to the write callback. */
static void voxcolori_flush_data(voxcolori_stream *s) {
    if (!s->status && s->out_used &&
        !s->write(s->user, s->data_offset + s->data_size - s->out_used, s->out, s->out_used)) {
        s->status = s->inplace ? VOXCOLOR_ERR_BUFFER_TOO_SMALL : VOXCOLOR_ERR_WRITE;
        s->message = s->inplace ? "the stream does not fit in the output buffer" : "the write callback failed";
    }
    s->out_used = 0;
}

/* Hands the buffered page table entries to the write callback. */
static void voxcolori_flush_table(voxcolori_stream *s) {
    uint64_t first = s->pages - s->table_used / s->entry;
    if (!s->status && s->table_used &&
        !s->write(s->user, VOXCOLOR_HEADER_SIZE + first * s->entry, s->table, s->table_used)) {
        s->status = s->inplace ? VOXCOLOR_ERR_BUFFER_TOO_SMALL : VOXCOLOR_ERR_WRITE;
        s->message = s->inplace ? "the stream does not fit in the output buffer" : "the write callback failed";
    }
    s->table_used = 0;
}

/* Most bytes a page of N colours takes: one raw block (count, end, nibble). */
static size_t voxcolori_page_most(unsigned page_shift, size_t n) {
    return 2 * voxcolori_index_bytes(page_shift) + 1 + 3 * n;
}

/* Encodes one page of N colours into DST (voxcolori_page_most bytes free);
   returns its size. Uses about 16 KiB of stack. */
static size_t voxcolori_page_encode(const voxcolori_enc *e, const uint8_t *rgb, size_t n, uint8_t *dst) {
    uint64_t plan[1u << VOXCOLOR_MAX_PAGE_SHIFT]; /* 8 KiB */
    voxcolori_writer w;
    size_t blocks;
    w.p = dst;
    w.acc = 0;
    w.n = 0;
    blocks = voxcolori_plan_page(e, rgb, n, plan);
    voxcolori_write_page(&w, rgb, plan, blocks, e->page_shift);
    if (w.n) voxcolori_put(&w, 0, 8 - w.n);
    VOXCOLOR_ASSERT((size_t)(w.p - dst) <= voxcolori_page_most(e->page_shift, n));
    return (size_t)(w.p - dst);
}

/* Encodes one page of N colours on the calling thread: its table entry,
   then its blocks. */
static void voxcolori_encode_page(voxcolori_stream *s, const uint8_t *rgb, size_t n) {
    size_t most = voxcolori_page_most(s->enc.page_shift, n), size;
    if (s->table_used + s->entry > sizeof s->table) voxcolori_flush_table(s);
    voxcolori_store_le(s->table + s->table_used, s->data_size, s->entry);
    s->table_used += s->entry;
    s->pages++;
    /* A page never takes more than one raw block would. */
    if (s->out_used + most > sizeof s->out) voxcolori_flush_data(s);
    size = voxcolori_page_encode(&s->enc, rgb, n, s->out + s->out_used);
    s->data_size += size;
    s->out_used += (uint32_t)size;
}

/* Pages of a batch per job: about 256 colours, so that the jobs even out. */
static uint32_t voxcolori_pages_per_job(unsigned page_shift) {
    return page_shift >= 8 ? 1u : 1u << (8 - page_shift);
}

/* Most pages in a batch: as many table entries as the stream buffers. */
#define VOXCOLORI_BATCH_PAGES (sizeof(((voxcolori_stream *)0)->table) / 4)

/* A batch of whole pages encoded in parallel: job J encodes pages
   J * per_job .. into AREA + J * slot and records each page's offset from
   there in the stream's table buffer. */
typedef struct voxcolori_batch {
    const voxcolori_stream *s;
    const uint8_t *rgb;   /* the batch's first colour */
    uint64_t colours;     /* colours in the batch */
    uint8_t *area;
    size_t slot;
    uint32_t pages, per_job;
    uint8_t *table;
    uint32_t size[VOXCOLORI_BATCH_PAGES]; /* bytes job J wrote */
} voxcolori_batch;

static void voxcolori_batch_job(void *user, uint32_t job) {
    voxcolori_batch *b = (voxcolori_batch *)user;
    const voxcolori_stream *s = b->s;
    size_t page = (size_t)1 << s->enc.page_shift;
    uint32_t k = job * b->per_job, end = k + b->per_job < b->pages ? k + b->per_job : b->pages;
    uint8_t *out = b->area + job * b->slot, *p = out;
    for (; k < end; k++) {
        uint64_t first = (uint64_t)k * page;
        size_t n = b->colours - first < page ? (size_t)(b->colours - first) : page;
        voxcolori_store_le(b->table + (size_t)k * s->entry, (uint64_t)(p - out), s->entry);
        p += voxcolori_page_encode(&s->enc, b->rgb + 3 * (size_t)first, n, p);
    }
    b->size[job] = (uint32_t)(p - out);
}

/* Runs COUNT jobs on the caller's pool, the built-in one (started on first
   use into *BUILTIN) or the calling thread. */
static void voxcolori_run(voxcolori_stream *s, void *builtin, int *started, voxcolor_job_fn job,
                          void *user, uint32_t count) {
    uint32_t i;
    if (s->pool.run) {
        s->pool.run(s->pool.user, job, user, count);
        return;
    }
#ifndef VOXCOLOR_NO_THREADS
    if (!*started) {
        voxcolori_pool_start((voxcolori_pool *)builtin, s->threads);
        *started = 1;
    }
    voxcolori_pool_run(builtin, job, user, count);
    return;
#else
    (void)builtin;
    (void)started;
#endif
    for (i = 0; i < count; i++) job(user, i);
}

/* Encodes the N colours at RGB, whole pages (the last page of the stream
   may be short), in batches run in parallel. The output of a batch goes to
   AREA (AREA_SIZE bytes), or in place into voxcolor_encode's buffer, then
   is written in order. Returns the colours encoded (fewer when a page does
   not fit in the space left, or on failure). */
static uint64_t voxcolori_encode_batches(voxcolori_stream *s, const uint8_t *rgb, uint64_t n, uint8_t *area,
                                         size_t area_size) {
#ifndef VOXCOLOR_NO_THREADS
    voxcolori_pool pool;
#else
    int pool;
#endif
    voxcolori_batch b;
    int started = 0;
    size_t page = (size_t)1 << s->enc.page_shift, most = voxcolori_page_most(s->enc.page_shift, page);
    uint64_t done = 0;
    b.s = s;
    b.table = s->table;
    b.per_job = voxcolori_pages_per_job(s->enc.page_shift);
    b.slot = b.per_job * most;
    while (done < n && !s->status) {
        uint64_t pages = (n - done + page - 1) >> s->enc.page_shift, limit = sizeof s->table / s->entry;
        uint32_t jobs, j;
        uint8_t *at = area, *to;
        size_t space = area_size, total;
        voxcolori_flush_data(s);
        voxcolori_flush_table(s);
        if (s->status) break;
        if (s->inplace) {
            uint64_t end = s->data_offset + s->data_size;
            at = s->inplace + (size_t)end;
            space = end + 8 <= s->inplace_size ? s->inplace_size - (size_t)end - 8 : 0;
        }
        if (pages > limit) pages = limit;
        if (pages > space / most) pages = space / most;
        jobs = (uint32_t)((pages + b.per_job - 1) / b.per_job);
        if (jobs < 2) break; /* the rest goes one page at a time */
        b.rgb = rgb + 3 * (size_t)done;
        b.pages = (uint32_t)pages;
        b.colours = n - done < pages * page ? n - done : pages * page;
        b.area = at;
        voxcolori_run(s, &pool, &started, voxcolori_batch_job, &b, jobs);
        /* The jobs' output, moved together; the table entries made absolute. */
        for (j = 0, to = at; j < jobs; j++) {
            uint32_t k, end = (j + 1) * b.per_job < b.pages ? (j + 1) * b.per_job : b.pages;
            uint64_t base = s->data_size + (uint64_t)(to - at);
            memmove(to, at + j * b.slot, b.size[j]);
            to += b.size[j];
            for (k = j * b.per_job; k < end; k++)
                voxcolori_store_le(s->table + (size_t)k * s->entry,
                                   base + voxcolori_load_le(s->table + (size_t)k * s->entry, s->entry), s->entry);
        }
        total = (size_t)(to - at);
        if (!s->inplace && !s->write(s->user, s->data_offset + s->data_size, at, total)) {
            s->status = VOXCOLOR_ERR_WRITE;
            s->message = "the write callback failed";
        }
        s->data_size += total;
        s->table_used = b.pages * s->entry;
        s->pages += b.pages;
        done += b.colours;
    }
#ifndef VOXCOLOR_NO_THREADS
    if (started) voxcolori_pool_stop(&pool);
#else
    (void)started;
#endif
    return done;
}

/* Sets up S; on failure S fails every later call. */
static voxcolor_status voxcolori_stream_init(voxcolori_stream *s, uint64_t count, const voxcolor_encode_opts *opts,
                                             voxcolor_write_fn write, void *user, voxcolor_error *err) {
    voxcolor_encode_opts defaults;
    voxcolor_status st;
    uint64_t pages;
    voxcolor_error e;
    memset(&defaults, 0, sizeof defaults);
    if (!opts) opts = &defaults;
    st = voxcolori_check_opts(opts, &e);
    if (!st && !write) st = voxcolori_report(&e, VOXCOLOR_ERR_INVALID_ARGUMENT, "write callback is NULL", UINT64_MAX);
    s->status = st;
    s->message = st ? e.message : "ok";
    if (st) {
        opts = &defaults; /* a valid state that fails every call */
        if (err) *err = e;
    }
    voxcolori_enc_init(&s->enc, opts);
    s->write = write;
    s->user = user;
    s->pool = opts->thread_pool;
    s->threads = opts->threads < 1 ? 1 : opts->threads > VOXCOLOR_MAX_THREADS ? VOXCOLOR_MAX_THREADS : opts->threads;
    s->count = count;
    s->pushed = 0;
    pages = count ? ((count - 1) >> s->enc.page_shift) + 1 : 0;
    /* 4-byte entries address 4 GiB of data: always enough below 2^30 colours. */
    s->entry = count > (1ull << 30) ? 8 : 4;
    s->data_offset = VOXCOLOR_HEADER_SIZE + pages * s->entry;
    s->data_size = 0;
    s->pages = 0;
    s->held = 0;
    s->out_used = 0;
    s->table_used = 0;
    s->inplace = NULL;
    s->inplace_size = 0;
    return st ? st : voxcolori_report(err, VOXCOLOR_OK, "ok", UINT64_MAX);
}

/* 1 when S encodes pages in parallel. */
static int voxcolori_parallel(const voxcolori_stream *s) {
#ifdef VOXCOLOR_NO_THREADS
    return s->pool.run != NULL;
#else
    return s->pool.run || s->threads > 1;
#endif
}

static voxcolor_status voxcolori_push(voxcolori_stream *s, const uint8_t *rgb8, size_t n, uint8_t *area,
                                      size_t area_size) {
    if (s->status) return s->status;
    if ((!rgb8 && n) || n > s->count - s->pushed) {
        s->status = VOXCOLOR_ERR_INVALID_ARGUMENT;
        s->message = !rgb8 && n ? "colours are NULL with a nonzero count" : "more colours pushed than declared";
        return s->status;
    }
    while (n && !s->status) {
        uint64_t left = s->count - s->pushed + s->held;
        size_t page = (size_t)1 << s->enc.page_shift, take;
        if (left < page) page = (size_t)left; /* the last page */
        if (!s->held && n >= page && voxcolori_parallel(s) && n - page >= page) {
            /* Several whole pages in the caller's colours: in parallel, no copy.
               The last page of the stream joins them when it is here. */
            uint64_t whole = n == left ? n : n - n % ((size_t)1 << s->enc.page_shift);
            take = (size_t)voxcolori_encode_batches(s, rgb8, whole, area, area_size);
            if (take) {
                s->pushed += take;
                rgb8 += 3 * take;
                n -= take;
                continue;
            }
        }
        if (!s->held && n >= page) {
            /* A whole page in the caller's colours: no copy. */
            voxcolori_encode_page(s, rgb8, page);
            take = page;
        } else {
            take = page - s->held < n ? page - s->held : n;
            memcpy(s->rgb + 3 * (size_t)s->held, rgb8, 3 * take);
            s->held += (uint32_t)take;
            if (s->held == page) {
                voxcolori_encode_page(s, s->rgb, page);
                s->held = 0;
            }
        }
        s->pushed += take;
        rgb8 += 3 * take;
        n -= take;
    }
    return s->status;
}

static uint64_t voxcolori_finish(voxcolori_stream *s, voxcolor_error *err) {
    uint8_t header[VOXCOLOR_HEADER_SIZE];
    if (!s->status && s->pushed != s->count) {
        s->status = VOXCOLOR_ERR_INCOMPLETE;
        s->message = "fewer colours pushed than declared";
    }
    /* The 8 closing zero bytes. */
    if (s->out_used + 8 > sizeof s->out) voxcolori_flush_data(s);
    memset(s->out + s->out_used, 0, 8);
    s->out_used += 8;
    s->data_size += 8;
    voxcolori_flush_data(s);
    voxcolori_flush_table(s);
    memcpy(header + VOXCOLOR_OFF_MAGIC, "VXC1", 4);
    voxcolori_store_le(header + VOXCOLOR_OFF_VERSION, VOXCOLOR_FORMAT_VERSION, 2);
    header[VOXCOLOR_OFF_PAGE_SHIFT] = (uint8_t)s->enc.page_shift;
    header[VOXCOLOR_OFF_FLAGS] = s->entry == 8 ? 1 : 0;
    voxcolori_store_le(header + VOXCOLOR_OFF_COUNT, s->count, 8);
    voxcolori_store_le(header + VOXCOLOR_OFF_DATA_SIZE, s->data_size, 8);
    if (!s->status && !s->write(s->user, 0, header, sizeof header)) {
        s->status = s->inplace ? VOXCOLOR_ERR_BUFFER_TOO_SMALL : VOXCOLOR_ERR_WRITE;
        s->message = s->inplace ? "the stream does not fit in the output buffer" : "the write callback failed";
    }
    if (s->status) {
        voxcolori_report(err, s->status, s->message, UINT64_MAX);
        return 0;
    }
    voxcolori_report(err, VOXCOLOR_OK, "ok", UINT64_MAX);
    return s->data_offset + s->data_size;
}

VOXCOLOR_API voxcolor_status voxcolor_encoder_init(voxcolor_encoder *enc, uint64_t count,
                                                   const voxcolor_encode_opts *opts,
                                                   voxcolor_write_fn write, void *user,
                                                   voxcolor_error *err) {
    if (!enc) return voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "encoder is NULL", UINT64_MAX);
    return voxcolori_stream_init(&enc->s, count, opts, write, user, err);
}

VOXCOLOR_API uint64_t voxcolor_encoder_data_offset(const voxcolor_encoder *enc) {
    return enc ? enc->s.data_offset : 0;
}

VOXCOLOR_API voxcolor_status voxcolor_encoder_push(voxcolor_encoder *enc, const uint8_t *rgb8, size_t n) {
    if (!enc) return VOXCOLOR_ERR_INVALID_ARGUMENT;
    return voxcolori_push(&enc->s, rgb8, n, enc->batch, sizeof enc->batch);
}

VOXCOLOR_API uint64_t voxcolor_encoder_finish(voxcolor_encoder *enc, voxcolor_error *err) {
    if (!enc) {
        voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "encoder is NULL", UINT64_MAX);
        return 0;
    }
    return voxcolori_finish(&enc->s, err);
}

/* voxcolor_encode's target: the caller's buffer. */
typedef struct voxcolori_buffer {
    uint8_t *p;
    size_t size;
} voxcolori_buffer;

static int voxcolori_write_buffer(void *user, uint64_t offset, const void *bytes, size_t size) {
    voxcolori_buffer *b = (voxcolori_buffer *)user;
    if (offset > b->size || size > b->size - offset) return 0;
    memcpy(b->p + (size_t)offset, bytes, size);
    return 1;
}

VOXCOLOR_API size_t voxcolor_encode(uint8_t *dst, size_t dst_size, const uint8_t *rgb8,
                                    size_t count, const voxcolor_encode_opts *opts,
                                    voxcolor_error *err) {
    voxcolori_stream s; /* 15 KiB */
    voxcolori_buffer b;
    if (!dst && dst_size) {
        voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "dst is NULL with a nonzero size", UINT64_MAX);
        return 0;
    }
    if (!rgb8 && count) {
        voxcolori_report(err, VOXCOLOR_ERR_INVALID_ARGUMENT, "colours are NULL with a nonzero count", UINT64_MAX);
        return 0;
    }
    b.p = dst;
    b.size = dst_size;
    if (voxcolori_stream_init(&s, count, opts, voxcolori_write_buffer, &b, err)) return 0;
    /* Fails early when not even the page table fits. */
    if (s.data_offset + 8 > dst_size) {
        voxcolori_report(err, VOXCOLOR_ERR_BUFFER_TOO_SMALL, "the page table does not fit in the output buffer",
                         UINT64_MAX);
        return 0;
    }
    s.inplace = dst;
    s.inplace_size = dst_size;
    voxcolori_push(&s, rgb8, count, NULL, 0);
    return (size_t)voxcolori_finish(&s, err);
}

// -- 2D mapping

/* Gathers the even bits of V into the low 32 bits. */
static uint32_t voxcolori_even_bits(uint64_t v) {
    v &= 0x5555555555555555ull;
    v = (v | v >> 1) & 0x3333333333333333ull;
    v = (v | v >> 2) & 0x0f0f0f0f0f0f0f0full;
    v = (v | v >> 4) & 0x00ff00ff00ff00ffull;
    v = (v | v >> 8) & 0x0000ffff0000ffffull;
    v = (v | v >> 16) & 0x00000000ffffffffull;
    return (uint32_t)v;
}

/* Spreads the bits of X to the even bit positions. */
static uint64_t voxcolori_spread(uint32_t x) {
    uint64_t v = x;
    v = (v | v << 16) & 0x0000ffff0000ffffull;
    v = (v | v << 8) & 0x00ff00ff00ff00ffull;
    v = (v | v << 4) & 0x0f0f0f0f0f0f0f0full;
    v = (v | v << 2) & 0x3333333333333333ull;
    v = (v | v << 1) & 0x5555555555555555ull;
    return v;
}

VOXCOLOR_API void voxcolor_morton2d_decode(uint64_t index, uint32_t *x, uint32_t *y) {
    VOXCOLOR_ASSERT(x && y);
    *x = voxcolori_even_bits(index);
    *y = voxcolori_even_bits(index >> 1);
}

VOXCOLOR_API uint64_t voxcolor_morton2d_encode(uint32_t x, uint32_t y) {
    return voxcolori_spread(x) | voxcolori_spread(y) << 1;
}

VOXCOLOR_API void voxcolor_image_size(uint64_t count, uint32_t *width, uint32_t *height) {
    uint64_t m = count ? count - 1 : 0, even = m & 0x5555555555555555ull;
    unsigned bits = 0;
    VOXCOLOR_ASSERT(width && height && count <= (1ull << 62));
    while (bits < 64 && (m >> bits)) bits++;
    *width = (uint32_t)1 << ((bits + 1) / 2);
    /* The largest y among indices <= m: clear m's highest even (x) bit and
       set every bit below it; without an even bit, m itself. */
    if (even) {
        unsigned e = 62;
        while (!(even >> e)) e -= 2;
        m = (m & ~((2ull << e) - 1)) | ((1ull << e) - 1);
    }
    *height = voxcolori_even_bits(m >> 1) + 1;
}

VOXCOLOR_API void voxcolor_to_image(uint8_t *image, uint32_t width, uint32_t height,
                                    const uint8_t *rgb8, size_t count) {
    uint32_t x, y;
    VOXCOLOR_ASSERT(image && (rgb8 || !count));
    if (!count) return;
    for (y = 0; y < height; y++)
        for (x = 0; x < width; x++) {
            uint64_t i = voxcolor_morton2d_encode(x, y);
            if (i >= count) i = count - 1;
            memcpy(image + 3 * ((size_t)y * width + x), rgb8 + 3 * (size_t)i, 3);
        }
}

VOXCOLOR_API void voxcolor_from_image(uint8_t *rgb8, size_t count, const uint8_t *image,
                                      uint32_t width, uint32_t height) {
    size_t i;
    VOXCOLOR_ASSERT((rgb8 && image) || !count);
    for (i = 0; i < count; i++) {
        uint32_t x, y;
        voxcolor_morton2d_decode(i, &x, &y);
        VOXCOLOR_ASSERT(x < width && y < height);
        memcpy(rgb8 + 3 * i, image + 3 * ((size_t)y * width + x), 3);
    }
    (void)height;
}

#endif /* VOXCOLOR_IMPLEMENTATION_DONE */
#endif /* VOXCOLOR_IMPLEMENTATION */

/*
MIT License

Copyright (c) 2026 The voxdag authors

Permission is hereby granted, free of charge, to any person obtaining a copy
of this software and associated documentation files (the "Software"), to deal
in the Software without restriction, including without limitation the rights
to use, copy, modify, merge, publish, distribute, sublicense, and/or sell
copies of the Software, and to permit persons to whom the Software is
furnished to do so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
*/
