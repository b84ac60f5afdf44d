/* The golden .vdag scenes (tests/data/golden) and small helpers to craft
   files: CRC-32C, little-endian access, and resealing an edited image (every
   section checksum, the section table checksum and the header checksum
   recomputed) so that what rejects a crafted file is the structural
   validation, not a checksum. Shared by tests/make_golden.c (which writes the
   files), tests/test_format.c and tests/fuzz_load.c. Needs voxdag.h with its
   implementation in some translation unit. */
#ifndef VOXDAG_GOLDEN_H
#define VOXDAG_GOLDEN_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "voxdag.h"

/* The offsets below are FORMAT.md's; the library's own macros live in its
   implementation part, so the tests spell them out and check them against
   the files. */
#define GOLDEN_OFF_MAGIC 0
#define GOLDEN_OFF_VERSION 8
#define GOLDEN_OFF_ENDIAN 12
#define GOLDEN_OFF_HEADER_SIZE 16
#define GOLDEN_OFF_FLAGS 20
#define GOLDEN_OFF_FILE_SIZE 24
#define GOLDEN_OFF_VOXELS 32
#define GOLDEN_OFF_LEVELS 40
#define GOLDEN_OFF_ROOT_TRANSFORM 41
#define GOLDEN_OFF_SYMMETRY 42
#define GOLDEN_OFF_SECTION_COUNT 44
#define GOLDEN_OFF_TABLE_CRC 48
#define GOLDEN_OFF_HEADER_CRC 52
#define GOLDEN_OFF_VOXEL_BOX 56
#define GOLDEN_HEADER_SIZE 96
#define GOLDEN_SECTION_ENTRY_SIZE 32
#define GOLDEN_LEVEL_ENTRY_SIZE 80

static inline uint64_t golden_le(const uint8_t *p, unsigned n) {
    uint64_t v = 0;
    while (n--) v = v << 8 | p[n];
    return v;
}

static inline void golden_put_le(uint8_t *p, uint64_t v, unsigned n) {
    unsigned i;
    for (i = 0; i < n; i++) p[i] = (uint8_t)(v >> (8 * i));
}

/* CRC-32C (Castagnoli polynomial, reflected 0x82F63B78, init and final xor
   0xFFFFFFFF), bit by bit: independent of the library's table version. */
static inline uint32_t golden_crc32c(const uint8_t *p, size_t n) {
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    unsigned k;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        for (k = 0; k < 8; k++) crc = (crc >> 1) ^ (0x82F63B78u & (0u - (crc & 1)));
    }
    return ~crc;
}

/* Recomputes every checksum of IMG (SIZE bytes, any content): each section
   entry whose range lies inside the image gets its section's CRC, then the
   section table CRC and the header CRC. Safe on arbitrary bytes. */
static inline void golden_reseal(uint8_t *img, size_t size) {
    uint64_t count, i;
    if (size < GOLDEN_HEADER_SIZE) return;
    count = golden_le(img + GOLDEN_OFF_SECTION_COUNT, 4);
    if (count <= (size - GOLDEN_HEADER_SIZE) / GOLDEN_SECTION_ENTRY_SIZE) {
        for (i = 0; i < count; i++) {
            uint8_t *e = img + GOLDEN_HEADER_SIZE + i * GOLDEN_SECTION_ENTRY_SIZE;
            uint64_t off = golden_le(e + 8, 8), sz = golden_le(e + 16, 8);
            if (off <= size && sz <= size - off)
                golden_put_le(e + 24, golden_crc32c(img + off, (size_t)sz), 4);
        }
        golden_put_le(img + GOLDEN_OFF_TABLE_CRC,
                      golden_crc32c(img + GOLDEN_HEADER_SIZE, (size_t)count * GOLDEN_SECTION_ENTRY_SIZE), 4);
    }
    golden_put_le(img + GOLDEN_OFF_HEADER_CRC, 0, 4);
    golden_put_le(img + GOLDEN_OFF_HEADER_CRC, golden_crc32c(img, GOLDEN_HEADER_SIZE), 4);
}

/* The section entry of TYPE in IMG, or NULL. */
static inline uint8_t *golden_section(uint8_t *img, size_t size, uint32_t type) {
    uint64_t count, i;
    if (size < GOLDEN_HEADER_SIZE) return NULL;
    count = golden_le(img + GOLDEN_OFF_SECTION_COUNT, 4);
    for (i = 0; i < count && GOLDEN_HEADER_SIZE + (i + 1) * GOLDEN_SECTION_ENTRY_SIZE <= size; i++) {
        uint8_t *e = img + GOLDEN_HEADER_SIZE + i * GOLDEN_SECTION_ENTRY_SIZE;
        if (golden_le(e, 4) == type) return e;
    }
    return NULL;
}

// -- The scenes

enum {
    GOLDEN_EMPTY_L2,
    GOLDEN_EMPTY_L5,
    GOLDEN_ONE_VOXEL,
    GOLDEN_BRICK_ROOT_L2,
    GOLDEN_MIRRORED_BLOB,
    GOLDEN_SVDAG,
    GOLDEN_PRIVATE,
    GOLDEN_COUNT
};

static const char *const golden_names[GOLDEN_COUNT] = {
    "empty_l2", "empty_l5", "one_voxel", "brick_root_l2", "mirrored_blob_l5", "svdag_l5", "private_l6",
};

static inline uint64_t golden_rand(uint64_t *state) { /* splitmix64 */
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Builds golden scene KIND (deterministic) with ALLOCATOR (NULL: default).
   Returns the builder's status; *out holds the DAG on success. */
static inline voxdag_status golden_build(int kind, const voxdag_allocator *allocator, voxdag **out) {
    static const double bounds[6] = {-1.5, -2.0, 0.25, 6.5, 14.0, 8.25};
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    uint32_t xyz[3 * 4096];
    uint8_t rgb[3 * 4096];
    size_t n = 0;
    uint64_t r = 0x5EEDu + (uint64_t)kind;
    uint32_t x, y, z, i, m;
    voxdag_status st;
    *out = NULL;
    memset(&o, 0, sizeof o);
    if (allocator) o.allocator = *allocator;
    switch (kind) {
    case GOLDEN_EMPTY_L2: o.levels = 2; break;
    case GOLDEN_EMPTY_L5: o.levels = 5; break;
    case GOLDEN_ONE_VOXEL:
        o.levels = 5;
        xyz[0] = 9, xyz[1] = 20, xyz[2] = 3, n = 1;
        break;
    case GOLDEN_BRICK_ROOT_L2:
        o.levels = 2;
        for (z = 0; z < 4; z++)
            for (y = 0; y < 4; y++)
                for (x = 0; x < 4; x++)
                    if ((x + 2 * y + 3 * z) % 3 == 0) xyz[3 * n] = x, xyz[3 * n + 1] = y, xyz[3 * n + 2] = z, n++;
        break;
    case GOLDEN_MIRRORED_BLOB: /* a blob in the lower octant, reflected into all 8 */
        o.levels = 5;
        o.colors = 1;
        o.bounds = bounds;
        for (i = 0; i < 24; i++) {
            uint32_t bx = 4 + (uint32_t)(golden_rand(&r) % 8), by = 4 + (uint32_t)(golden_rand(&r) % 8);
            uint32_t bz = 4 + (uint32_t)(golden_rand(&r) % 8);
            for (m = 0; m < 8; m++) {
                x = m & 1 ? 31 - bx : bx, y = m & 2 ? 31 - by : by, z = m & 4 ? 31 - bz : bz;
                xyz[3 * n] = x, xyz[3 * n + 1] = y, xyz[3 * n + 2] = z;
                rgb[3 * n] = (uint8_t)(8 * x), rgb[3 * n + 1] = (uint8_t)(8 * y), rgb[3 * n + 2] = (uint8_t)(8 * z + m);
                n++;
            }
        }
        break;
    case GOLDEN_SVDAG: /* a terrain with repeated columns, no reflections */
        o.levels = 5;
        o.symmetry = VOXDAG_SYMMETRY_NONE;
        for (y = 0; y < 32; y++)
            for (x = 0; x < 32; x++) {
                uint32_t h = 2 + (x / 4 * 3 + y / 4 * 5) % 5;
                for (z = 0; z < h; z += 1 + (x & 1))
                    if (n < 4096) xyz[3 * n] = x, xyz[3 * n + 1] = y, xyz[3 * n + 2] = z, n++;
            }
        break;
    case GOLDEN_PRIVATE: /* sparse random clumps: nodes referenced once (private children) */
        o.levels = 6;
        for (i = 0; i < 12; i++) {
            uint32_t cx = (uint32_t)(golden_rand(&r) % 56), cy = (uint32_t)(golden_rand(&r) % 56);
            uint32_t cz = (uint32_t)(golden_rand(&r) % 56);
            for (m = 0; m < 40; m++) {
                uint64_t v = golden_rand(&r);
                xyz[3 * n] = cx + (uint32_t)(v & 7), xyz[3 * n + 1] = cy + (uint32_t)(v >> 3 & 7);
                xyz[3 * n + 2] = cz + (uint32_t)(v >> 6 & 7);
                n++;
            }
        }
        break;
    default: return VOXDAG_ERR_INVALID_ARGUMENT;
    }
    st = voxdag_builder_create(&o, &b, NULL);
    if (st != VOXDAG_OK) return st;
    if (n) st = voxdag_builder_add(b, xyz, o.colors ? rgb : NULL, n, NULL);
    if (st != VOXDAG_OK) {
        voxdag_builder_free(b);
        return st;
    }
    return voxdag_builder_finish(b, out, NULL, NULL);
}

#endif
