/* The .vdag format pinned by golden files (tests/data/golden, written by
   tests/make_golden.c): byte-identical rebuilds, header fields at FORMAT.md's
   offsets, rejection of every truncation and single-byte change, allocation
   failure at every step of a load and of a build, load limits, and
   hand-crafted hostile files whose checksums are recomputed, so that the
   structural validation is what refuses them.

   Sweep sizes (all goldens together, 2248 bytes): 2248 truncations, about
   9k patched files (under --full every byte takes each of its 255 other
   values: about 570k), every allocation of each load with and without a
   copy, and of each build; about half a second of CPU with sanitizers (a
   few seconds under --full). FORMAT_VERBOSE=1 prints the message each
   hostile file is refused with. */

#if defined(__unix__) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L /* fork, setrlimit, waitpid for the failed-save test */
#endif
#include <errno.h>
#include <time.h>
#ifdef __unix__
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

/* This unit carries its own static copy of the implementation, for the file
   layout macros (VOXDAG_FILE_*) that only the implementation part defines. */
#include "static_impl.h"

#include "golden.h"
#include "test.h"
#include "count_alloc.h"

// -- Helpers

static uint8_t *read_golden(int kind, size_t *size) {
    char path[4096];
    FILE *f;
    long n;
    uint8_t *buf;
    snprintf(path, sizeof path, "%s/golden/%s.vdag", test_data_dir(), golden_names[kind]);
    f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "  cannot open %s\n", path);
        return NULL;
    }
    if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        fclose(f);
        return NULL;
    }
    buf = (uint8_t *)malloc(n ? (size_t)n : 1);
    if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(buf);
        return NULL;
    }
    fclose(f);
    *size = (size_t)n;
    return buf;
}

static void opts_with(voxdag_load_opts *o, count_alloc *ca, long fail_at) {
    memset(o, 0, sizeof *o);
    o->allocator = ca_start(ca, fail_at);
}

/* Loads an exact-size heap copy of DATA; returns the status, frees the DAG,
   and checks that nothing stays allocated. */
static voxdag_status load_copy(const uint8_t *data, size_t size, int copy, voxdag_error *err) {
    voxdag_load_opts o;
    count_alloc ca;
    voxdag *d = NULL;
    voxdag_status st;
    uint8_t *buf = size ? (uint8_t *)malloc(size) : NULL;
    if (size) memcpy(buf, data, size);
    opts_with(&o, &ca, -1);
    o.copy = copy;
    st = voxdag_load_memory(buf, size, &o, &d, err);
    CHECK(st == err->status);
    CHECK((st == VOXDAG_OK) == (d != NULL));
    CHECK(err->message != NULL);
    if (st != VOXDAG_OK) CHECK(err->byte_offset == UINT64_MAX || err->byte_offset <= size);
    voxdag_free(d);
    CHECK(ca.held == 0 && !ca.bad_free);
    free(buf);
    return st;
}

/* Every voxel with its index, in order (at most CAP), as Morton codes. */
typedef struct voxel_list {
    uint64_t n, cap, *morton;
} voxel_list;

static int collect(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    voxel_list *v = (voxel_list *)user;
    if (index != v->n || v->n >= v->cap) return 1;
    v->morton[v->n++] = voxdag_morton_encode(x, y, z);
    return 0;
}

static int same_voxels(const voxdag *a, const voxdag *b) {
    uint64_t ma[4096], mb[4096];
    voxel_list va = {0, 4096, ma}, vb = {0, 4096, mb};
    voxdag_for_each_voxel(a, collect, &va);
    voxdag_for_each_voxel(b, collect, &vb);
    return va.n == vb.n && !memcmp(ma, mb, va.n * sizeof *ma);
}

// -- (a) Rebuilding the scenes gives the committed bytes

static void test_golden_identical(void) {
    int kind;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        voxdag *d = NULL;
        size_t size = 0, built_size = 0;
        uint8_t *file = read_golden(kind, &size);
        const void *built;
        CHECK_MSG(file != NULL, "%s", golden_names[kind]);
        CHECK(golden_build(kind, NULL, &d) == VOXDAG_OK);
        if (file && d) {
            built = voxdag_image(d, &built_size);
            CHECK_MSG(built_size == size && !memcmp(built, file, size),
                      "%s: the format changed (rebuild with make_golden if intended, and bump the version)",
                      golden_names[kind]);
        }
        voxdag_free(d);
        free(file);
    }
}

// -- (b) Header fields at the documented offsets agree with voxdag_get_info

static void test_offsets_documented(void) {
    /* FORMAT.md's header table */
    CHECK(VOXDAG_FILE_OFF_MAGIC == 0 && VOXDAG_FILE_OFF_VERSION == 8 && VOXDAG_FILE_OFF_ENDIAN == 12);
    CHECK(VOXDAG_FILE_OFF_HEADER_SIZE == 16 && VOXDAG_FILE_OFF_FLAGS == 20 && VOXDAG_FILE_OFF_FILE_SIZE == 24);
    CHECK(VOXDAG_FILE_OFF_VOXELS == 32 && VOXDAG_FILE_OFF_LEVELS == 40 && VOXDAG_FILE_OFF_ROOT_TRANSFORM == 41);
    CHECK(VOXDAG_FILE_OFF_SYMMETRY == 42 && VOXDAG_FILE_OFF_VOXEL_BOX == 56 && VOXDAG_FILE_OFF_RESERVED == 80);
    CHECK(VOXDAG_FILE_OFF_SECTION_COUNT == 44 && VOXDAG_FILE_OFF_TABLE_CRC == 48);
    CHECK(VOXDAG_FILE_OFF_HEADER_CRC == 52 && VOXDAG_FILE_HEADER_SIZE == 96);
    CHECK(VOXDAG_FILE_SECTION_ENTRY_SIZE == 32 && VOXDAG_FILE_LEVEL_ENTRY_SIZE == 80);
    CHECK(VOXDAG_FILE_NODE_PADDING == 16 && VOXDAG_FILE_MAX_SECTIONS == 16);
    CHECK(VOXDAG_FILE_ENDIAN_TAG == 0x0A0B0C0Du && VOXDAG_FORMAT_VERSION == 3);
    /* FORMAT.md's LOD_COLORS table */
    CHECK(VOXDAG_SECTION_LOD_COLORS == 7 && VOXDAG_FILE_LOD_HEADER_SIZE == 16 && VOXDAG_FILE_LOD_OFF_KIND == 0);
    CHECK(VOXDAG_FILE_LOD_OFF_SLOT_SHIFT == 1 && VOXDAG_FILE_LOD_OFF_FIRST_LEVEL == 2 &&
          VOXDAG_FILE_LOD_OFF_LEVEL_COUNT == 3);
    CHECK(VOXDAG_FILE_LOD_OFF_RESERVED == 4 && VOXDAG_FILE_LOD_OFF_SLOTS == 8 && VOXDAG_FILE_LOD_SLOT_SHIFT == 6);
    /* the helpers of golden.h use the same numbers */
    CHECK(GOLDEN_OFF_SECTION_COUNT == VOXDAG_FILE_OFF_SECTION_COUNT && GOLDEN_OFF_TABLE_CRC == VOXDAG_FILE_OFF_TABLE_CRC);
    CHECK(GOLDEN_OFF_HEADER_CRC == VOXDAG_FILE_OFF_HEADER_CRC && GOLDEN_HEADER_SIZE == VOXDAG_FILE_HEADER_SIZE);
    CHECK(GOLDEN_SECTION_ENTRY_SIZE == VOXDAG_FILE_SECTION_ENTRY_SIZE);
    CHECK(GOLDEN_LEVEL_ENTRY_SIZE == VOXDAG_FILE_LEVEL_ENTRY_SIZE && GOLDEN_OFF_VOXEL_BOX == VOXDAG_FILE_OFF_VOXEL_BOX);
    CHECK(golden_crc32c((const uint8_t *)"123456789", 9) == 0xE3069283u); /* the CRC-32C check value */
}

static void test_header_fields(void) {
    static const uint8_t magic[8] = {0x89, 'V', 'D', 'A', 'G', '\r', '\n', 0x1A};
    static const uint64_t voxels[GOLDEN_COUNT] = {0, 0, 1, 24, 184, 0, 0}; /* 0: not pinned here */
    int kind;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        size_t size = 0;
        uint8_t *f = read_golden(kind, &size), h[VOXDAG_FILE_HEADER_SIZE];
        voxdag *d = NULL;
        voxdag_info info;
        uint32_t count, i, seen = 0;
        if (!f) {
            CHECK_MSG(0, "%s missing", golden_names[kind]);
            continue;
        }
        CHECK(size >= VOXDAG_FILE_HEADER_SIZE && size % 8 == 0);
        CHECK(voxdag_load_memory(f, size, NULL, &d, NULL) == VOXDAG_OK);
        if (!d || size < VOXDAG_FILE_HEADER_SIZE) {
            free(f);
            continue;
        }
        voxdag_get_info(d, &info);
        CHECK(!memcmp(f + VOXDAG_FILE_OFF_MAGIC, magic, 8));
        CHECK(golden_le(f + VOXDAG_FILE_OFF_VERSION, 4) == VOXDAG_FORMAT_VERSION);
        CHECK(!memcmp(f + VOXDAG_FILE_OFF_ENDIAN, "\x0D\x0C\x0B\x0A", 4));
        CHECK(golden_le(f + VOXDAG_FILE_OFF_HEADER_SIZE, 4) == 96);
        CHECK(golden_le(f + VOXDAG_FILE_OFF_FLAGS, 4) == 0);
        CHECK(f[VOXDAG_FILE_OFF_SYMMETRY] == (unsigned)info.symmetry);
        CHECK(info.symmetry == (kind != GOLDEN_SVDAG ? VOXDAG_SYMMETRY_FULL : VOXDAG_SYMMETRY_NONE));
        CHECK(golden_le(f + VOXDAG_FILE_OFF_FILE_SIZE, 8) == size && info.file_bytes == size);
        CHECK(golden_le(f + VOXDAG_FILE_OFF_VOXELS, 8) == info.voxels);
        CHECK(!voxels[kind] || info.voxels == voxels[kind]);
        CHECK((info.voxels == 0) == (kind == GOLDEN_EMPTY_L2 || kind == GOLDEN_EMPTY_L5));
        CHECK(f[VOXDAG_FILE_OFF_LEVELS] == info.levels);
        CHECK(info.levels == (kind == GOLDEN_EMPTY_L2 || kind == GOLDEN_BRICK_ROOT_L2 ? 2u : kind == GOLDEN_PRIVATE ? 6u : 5u));
        CHECK(f[VOXDAG_FILE_OFF_ROOT_TRANSFORM] < 48 && !f[43]);
        for (i = 0; i < 6; i++) CHECK(golden_le(f + VOXDAG_FILE_OFF_VOXEL_BOX + 4 * i, 4) == info.voxel_box[i]);
        for (i = VOXDAG_FILE_OFF_RESERVED; i < VOXDAG_FILE_HEADER_SIZE; i++) CHECK(f[i] == 0);
        memcpy(h, f, sizeof h);
        golden_put_le(h + VOXDAG_FILE_OFF_HEADER_CRC, 0, 4);
        CHECK(golden_le(f + VOXDAG_FILE_OFF_HEADER_CRC, 4) == golden_crc32c(h, sizeof h));
        count = (uint32_t)golden_le(f + VOXDAG_FILE_OFF_SECTION_COUNT, 4);
        CHECK(count == 3u + (kind == GOLDEN_MIRRORED_BLOB ? 3u : 0u)); /* colours, their level-of-detail means, bounds */
        CHECK(96 + (size_t)count * 32 <= size);
        if (96 + (size_t)count * 32 > size) count = 0;
        CHECK(golden_le(f + VOXDAG_FILE_OFF_TABLE_CRC, 4) == golden_crc32c(f + 96, (size_t)count * 32));
        for (i = 0; i < count; i++) {
            const uint8_t *e = f + 96 + 32 * i;
            uint32_t type = (uint32_t)golden_le(e, 4);
            uint64_t off = golden_le(e + 8, 8), sz = golden_le(e + 16, 8);
            /* the optional flag on LOD_COLORS only, which older readers skip */
            CHECK(golden_le(e + 4, 4) == (type == VOXDAG_SECTION_LOD_COLORS) && golden_le(e + 28, 4) == 0 && off % 8 == 0);
            CHECK(off <= size && sz <= size - off);
            if (off > size || sz > size - off) continue;
            CHECK(golden_le(e + 24, 4) == golden_crc32c(f + off, (size_t)sz));
            CHECK(type >= 1 && type <= 7 && !(seen >> type & 1));
            seen |= 1u << (type & 31);
            switch (type) {
            case VOXDAG_SECTION_LEVELS: {
                uint32_t l;
                uint64_t at = 0;
                CHECK(sz == 80 * (uint64_t)(info.levels - 2));
                for (l = 0; l + 2 < info.levels && 80 * (l + 1) <= sz; l++) {
                    const uint8_t *le = f + off + 80 * l;
                    unsigned t, k;
                    CHECK(golden_le(le, 8) == at);
                    CHECK(golden_le(le + 8, 8) == info.level_bytes[l]);
                    CHECK(golden_le(le + 16, 4) == info.nodes[l]);
                    CHECK(le[20] == (l + 3 < info.levels ? (info.voxels ? le[20] : 1) : 0) && le[20] <= 64);
                    CHECK(le[21] >= 1 && le[21] <= (info.symmetry == VOXDAG_SYMMETRY_NONE ? 1 : 48));
                    for (t = 1; t <= 3; t++) CHECK(le[24 + t] <= 6 && le[21 + t] + le[24 + t] <= 57);
                    for (k = 0; k < 48; k++) /* the transform table: used entries distinct, the rest zero */
                        CHECK(k < le[21] ? le[32 + k] < 48 && (!k || le[32 + k] != le[31 + k]) : le[32 + k] == 0);
                    CHECK(le[28] <= 1 && le[29] <= 57 && (le[28] ? !le[24] && !le[27] : !le[29])); /* private children */
                    CHECK(golden_le(le + 30, 2) == 0);
                    at += info.level_bytes[l];
                }
                CHECK(at == info.node_bytes);
                break;
            }
            case VOXDAG_SECTION_NODES: CHECK(sz == info.node_bytes + 16); break;
            case VOXDAG_SECTION_BRICKS:
                CHECK(sz == info.brick_bytes && sz == 8 * info.nodes[info.levels - 2]);
                break;
            case VOXDAG_SECTION_COLORS_RGB8:
                CHECK(info.color_kind == VOXDAG_COLORS_RGB8 && sz == info.color_bytes && sz == 3 * info.voxels);
                break;
            case VOXDAG_SECTION_LOD_COLORS: { /* levels 0..L-3, ceil(N / 64) RGB8 slots each */
                uint64_t slots = (info.voxels + 63) / 64;
                CHECK(sz == info.lod_color_bytes && sz >= VOXDAG_FILE_LOD_HEADER_SIZE);
                if (sz < VOXDAG_FILE_LOD_HEADER_SIZE) break;
                CHECK(f[off + VOXDAG_FILE_LOD_OFF_KIND] == VOXDAG_COLORS_RGB8 &&
                      f[off + VOXDAG_FILE_LOD_OFF_SLOT_SHIFT] == 6 && f[off + VOXDAG_FILE_LOD_OFF_FIRST_LEVEL] == 0 &&
                      f[off + VOXDAG_FILE_LOD_OFF_LEVEL_COUNT] == info.levels - 2 &&
                      golden_le(f + off + VOXDAG_FILE_LOD_OFF_RESERVED, 4) == 0 &&
                      golden_le(f + off + VOXDAG_FILE_LOD_OFF_SLOTS, 8) == slots);
                CHECK(sz == VOXDAG_FILE_LOD_HEADER_SIZE + 3 * slots * (info.levels - 2));
                break;
            }
            case VOXDAG_SECTION_BOUNDS: {
                unsigned k;
                CHECK(sz == 48 && info.has_bounds);
                for (k = 0; k < 6 && sz == 48; k++) {
                    uint64_t bits = golden_le(f + off + 8 * k, 8);
                    double v;
                    memcpy(&v, &bits, 8);
                    CHECK(v == info.bounds[k]);
                }
                break;
            }
            default: break;
            }
        }
        CHECK((seen & 0xE) == 0xE); /* levels, nodes, bricks */
        CHECK(!!(seen & 0x10) == (info.color_kind == VOXDAG_COLORS_RGB8));
        CHECK(!!(seen & 0x40) == info.has_bounds);
        CHECK(!!(seen & 0x80) == (info.lod_color_bytes > 0) && (info.lod_color_bytes > 0) == (info.color_kind != 0));
        if (kind == GOLDEN_ONE_VOXEL) {
            uint64_t index = 7;
            CHECK(voxdag_lookup(d, 9, 20, 3, &index) == 1 && index == 0);
            CHECK(voxdag_lookup(d, 9, 20, 4, NULL) == 0);
        }
        if (kind == GOLDEN_MIRRORED_BLOB) CHECK(info.bounds[0] == -1.5 && info.bounds[5] == 8.25);
        voxdag_free(d);
        free(f);
    }
}

// -- (c) Every truncation and every single-byte patch is rejected

static void test_mutations(void) {
    int kind;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        size_t size = 0, i;
        uint8_t *f = read_golden(kind, &size), *m;
        voxdag_error err;
        long accepted = 0, cut_accepted = 0;
        if (!f) {
            CHECK_MSG(0, "%s missing", golden_names[kind]);
            continue;
        }
        CHECK(load_copy(f, size, 0, &err) == VOXDAG_OK);
        for (i = 0; i < size; i++) /* exact-size copies: ASan sees any over-read */
            if (load_copy(f, i, (int)(i & 1), &err) == VOXDAG_OK) cut_accepted++;
        m = (uint8_t *)malloc(size);
        for (i = 0; i < size; i++) {
            int k;
            for (k = 0; k < test_patch_count(); k++) {
                uint8_t v = test_patch(f[i], k);
                if (v == f[i]) continue; /* unchanged bytes load, of course */
                memcpy(m, f, size);
                m[i] = v;
                if (load_copy(m, size, k & 1, &err) == VOXDAG_OK) accepted++;
            }
        }
        CHECK_MSG(cut_accepted == 0, "%s: %ld truncations accepted", golden_names[kind], cut_accepted);
        CHECK_MSG(accepted == 0, "%s: %ld patched files accepted", golden_names[kind], accepted);
        free(m);
        free(f);
    }
}

// -- (d) Allocation N fails, for every N of a load or a build

static void test_allocation_failures(void) {
    int kind, copy;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        size_t size = 0;
        uint8_t *f = read_golden(kind, &size);
        if (!f) continue;
        for (copy = 0; copy < 2; copy++) {
            long n;
            int done = 0;
            for (n = 0; !done && n < 1000; n++) {
                voxdag_load_opts o;
                count_alloc ca;
                voxdag *d = NULL;
                voxdag_status st;
                opts_with(&o, &ca, n);
                o.copy = copy;
                st = voxdag_load_memory(f, size, &o, &d, NULL);
                CHECK_MSG(st == VOXDAG_OK || st == VOXDAG_ERR_OUT_OF_MEMORY, "%s: status %d at allocation %ld",
                          golden_names[kind], (int)st, n);
                if (st == VOXDAG_OK) {
                    CHECK(ca.calls <= n); /* succeeded only without reaching the failure */
                    done = 1;
                } else {
                    CHECK(d == NULL && ca.calls > n);
                }
                voxdag_free(d);
                CHECK_MSG(ca.held == 0 && !ca.bad_free, "%s: %llu bytes held after failing allocation %ld",
                          golden_names[kind], (unsigned long long)ca.held, n);
            }
            CHECK(done);
        }
        free(f);
    }
}

/* ... and of every build of a golden scene: each failure ends in
   VOXDAG_ERR_OUT_OF_MEMORY with nothing held, and a build that succeeds (also
   past a failed optional allocation, such as a cache) gives the committed
   bytes. */
static void test_build_allocation_failures(void) {
    int kind;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        size_t size = 0;
        uint8_t *f = read_golden(kind, &size);
        long n;
        int done = 0;
        for (n = 0; f && !done && n < 100000; n++) {
            voxdag_load_opts o; /* for its allocator */
            count_alloc ca;
            voxdag *d = NULL;
            voxdag_status st;
            opts_with(&o, &ca, n);
            st = golden_build(kind, &o.allocator, &d);
            CHECK_MSG(st == VOXDAG_OK || st == VOXDAG_ERR_OUT_OF_MEMORY, "%s: status %d at allocation %ld",
                      golden_names[kind], (int)st, n);
            if (st == VOXDAG_OK) {
                size_t built_size;
                const void *built = voxdag_image(d, &built_size);
                CHECK(built_size == size && !memcmp(built, f, size));
            } else {
                CHECK(d == NULL && ca.calls > n);
            }
            done = ca.calls <= n; /* the failure was never reached */
            voxdag_free(d);
            CHECK_MSG(ca.held == 0 && !ca.bad_free, "%s: %llu bytes held after failing build allocation %ld",
                      golden_names[kind], (unsigned long long)ca.held, n);
        }
        CHECK_MSG(done, "%s", golden_names[kind]);
        free(f);
    }
}

/* voxdag_load_file reads the header before the rest: a large file that is
   not a .vdag, or whose header declares another size, is refused having
   allocated nothing near its size (a counting allocator watches; the files
   are sparse, so they take no disk space). */
static void test_load_file_header_first(void) {
    static const uint64_t big = (uint64_t)64 << 20;
    size_t size = 0;
    uint8_t *g = read_golden(GOLDEN_MIRRORED_BLOB, &size), h[VOXDAG_FILE_HEADER_SIZE];
    char path[256];
    int k;
    if (!g) {
        CHECK_MSG(0, "mirrored blob golden missing");
        return;
    }
    snprintf(path, sizeof path, "build/test_header_first_%u.bin", (unsigned)time(NULL) % 100000u);
    for (k = 0; k < 3; k++) {
        voxdag_load_opts o;
        count_alloc ca;
        voxdag *d = NULL;
        voxdag_error err;
        voxdag_status want = k == 0 ? VOXDAG_ERR_BAD_MAGIC : k == 1 ? VOXDAG_ERR_CORRUPT : VOXDAG_ERR_VERSION;
        FILE *fp = fopen(path, "wb");
        memcpy(h, g, sizeof h);
        if (k == 0) memcpy(h, "not a voxdag file", 8);
        if (k == 2) golden_put_le(h + VOXDAG_FILE_OFF_VERSION, 2, 4);
        CHECK(fp && fwrite(h, 1, sizeof h, fp) == sizeof h && fseek(fp, (long)big - 1, SEEK_SET) == 0 &&
              fputc(0, fp) == 0 && fclose(fp) == 0);
        opts_with(&o, &ca, -1);
        CHECK_MSG(voxdag_load_file(path, &o, &d, &err) == want && !d, "case %d: status %d (%s)", k,
                  (int)err.status, err.message);
        CHECK_MSG(ca.peak < 65536, "case %d: %llu bytes allocated before the header was refused", k,
                  (unsigned long long)ca.peak);
    }
    remove(path);
    free(g);
}

// -- (e) Load limits refuse what exceeds them

static void test_limits(void) {
    int kind;
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        size_t size = 0;
        uint8_t *f = read_golden(kind, &size);
        voxdag_load_opts o;
        count_alloc ca;
        voxdag *d = NULL;
        voxdag_info info;
        uint64_t nodes = 0, peak;
        uint32_t l;
        voxdag_status st;
        if (!f) continue;
        opts_with(&o, &ca, -1);
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        if (!d) {
            free(f);
            continue;
        }
        voxdag_get_info(d, &info);
        voxdag_free(d);
        d = NULL;
        peak = ca.peak;
        for (l = 0; l + 1 < info.levels; l++) nodes += info.nodes[l];
        /* max_levels */
        opts_with(&o, &ca, -1);
        o.max_levels = info.levels;
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        voxdag_free(d);
        if (info.levels > 2) {
            o.max_levels = info.levels - 1;
            CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_ERR_LIMIT && !d);
        }
        /* max_nodes: all nodes and bricks together */
        opts_with(&o, &ca, -1);
        o.max_nodes = nodes ? nodes : 1;
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        voxdag_free(d);
        if (nodes > 1) {
            o.max_nodes = nodes - 1;
            CHECK_MSG(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_ERR_LIMIT && !d, "%s max_nodes",
                      golden_names[kind]);
        }
        /* max_input_bytes */
        opts_with(&o, &ca, -1);
        o.max_input_bytes = size;
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        voxdag_free(d);
        o.max_input_bytes = size - 1;
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_ERR_LIMIT && !d);
        /* max_memory: the measured peak passes, one byte less fails, with and without a copy */
        opts_with(&o, &ca, -1);
        o.max_memory = peak;
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        voxdag_free(d);
        o.max_memory = peak - 1;
        st = voxdag_load_memory(f, size, &o, &d, NULL);
        CHECK_MSG(st == VOXDAG_ERR_LIMIT && !d, "%s max_memory: %d", golden_names[kind], (int)st);
        o.copy = 1;
        o.max_memory = peak + size - 1;
        st = voxdag_load_memory(f, size, &o, &d, NULL);
        CHECK(st == VOXDAG_ERR_LIMIT && !d);
        CHECK(ca.held == 0 && !ca.bad_free);
        free(f);
    }
}

// -- (f) Hand-crafted hostile files

/* A file taken apart into its sections, to be changed and written again with
   the layout FORMAT.md gives (8-byte aligned, zero gaps, fresh checksums). */
typedef struct parts {
    uint8_t header[GOLDEN_HEADER_SIZE];
    uint32_t count;
    uint32_t type[16], flags[16];
    uint8_t *data[16];
    size_t size[16];
} parts;

static int parts_read(parts *p, const uint8_t *f, size_t size) {
    uint32_t i;
    memset(p, 0, sizeof *p);
    if (size < GOLDEN_HEADER_SIZE) return 0;
    memcpy(p->header, f, GOLDEN_HEADER_SIZE);
    p->count = (uint32_t)golden_le(f + 44, 4);
    if (p->count > 16 || GOLDEN_HEADER_SIZE + 32 * (size_t)p->count > size) return 0;
    for (i = 0; i < p->count; i++) {
        const uint8_t *e = f + GOLDEN_HEADER_SIZE + 32 * i;
        uint64_t off = golden_le(e + 8, 8), sz = golden_le(e + 16, 8);
        if (off > size || sz > size - off) return 0;
        p->type[i] = (uint32_t)golden_le(e, 4);
        p->flags[i] = (uint32_t)golden_le(e + 4, 4);
        p->size[i] = (size_t)sz;
        p->data[i] = (uint8_t *)malloc(sz + 64); /* room to grow a section a little */
        memcpy(p->data[i], f + off, (size_t)sz);
    }
    return 1;
}

static void parts_free(parts *p) {
    uint32_t i;
    for (i = 0; i < p->count; i++) free(p->data[i]);
}

static int parts_find(const parts *p, uint32_t type) {
    uint32_t i;
    for (i = 0; i < p->count; i++)
        if (p->type[i] == type) return (int)i;
    return -1;
}

/* Writes P as a file (resealed) of *SIZE bytes; the caller frees it. */
static uint8_t *parts_write(const parts *p, size_t *size) {
    size_t at = GOLDEN_HEADER_SIZE + 32 * (size_t)p->count, total;
    size_t off[16];
    uint32_t i;
    uint8_t *f;
    for (i = 0; i < p->count; i++) {
        at = (at + 7) & ~(size_t)7;
        off[i] = at;
        at += p->size[i];
    }
    total = at;
    f = (uint8_t *)calloc(total, 1);
    memcpy(f, p->header, GOLDEN_HEADER_SIZE);
    golden_put_le(f + 24, total, 8);
    golden_put_le(f + 44, p->count, 4);
    for (i = 0; i < p->count; i++) {
        uint8_t *e = f + GOLDEN_HEADER_SIZE + 32 * i;
        golden_put_le(e, p->type[i], 4);
        golden_put_le(e + 4, p->flags[i], 4);
        golden_put_le(e + 8, off[i], 8);
        golden_put_le(e + 16, p->size[i], 8);
        golden_put_le(e + 28, 0, 4);
        memcpy(f + off[i], p->data[i], p->size[i]);
    }
    golden_reseal(f, total);
    *size = total;
    return f;
}

/* The records of inner level L of a parsed file (FORMAT.md, read here bit
   by bit): start offsets inside NODES and the offset of the level. */
typedef struct level_view {
    uint64_t offset, size;
    unsigned count_bits;
    unsigned width[4], code_bits[4]; /* pointer bits and code bits of tags 1..3 */
    unsigned private_children, base_bits; /* tag 3 marks a private child; P */
} level_view;

static uint64_t bits_get(const uint8_t *p, uint64_t pos, unsigned n) {
    uint64_t v = 0;
    unsigned k;
    for (k = 0; k < n; k++) v |= (uint64_t)(p[(pos + k) >> 3] >> ((pos + k) & 7) & 1) << k;
    return v;
}

static void bits_put(uint8_t *p, uint64_t pos, uint64_t v, unsigned n) {
    unsigned k;
    for (k = 0; k < n; k++) {
        uint8_t bit = (uint8_t)(1u << ((pos + k) & 7));
        if (v >> k & 1) p[(pos + k) >> 3] |= bit;
        else p[(pos + k) >> 3] &= (uint8_t)~bit;
    }
}

static level_view level_of(const parts *p, uint32_t l) {
    level_view v;
    const uint8_t *e = p->data[parts_find(p, 1)] + GOLDEN_LEVEL_ENTRY_SIZE * l;
    unsigned t;
    v.offset = golden_le(e, 8);
    v.size = golden_le(e + 8, 8);
    v.count_bits = e[20];
    v.private_children = e[28];
    v.base_bits = e[29];
    v.width[0] = v.code_bits[0] = 0;
    for (t = 1; t <= 3; t++) {
        v.width[t] = (unsigned)e[21 + t] + e[24 + t];
        v.code_bits[t] = e[24 + t];
    }
    return v;
}

static int is_private(const level_view *v, unsigned tag) { return tag == 3 && v->private_children; }

/* Bits before the first pointer of a record with HEADER: the header, the
   count, and the base field when some child is private. */
static unsigned pointers_bit(const level_view *v, unsigned header) {
    unsigned s, n = 16 + v->count_bits;
    for (s = 0; s < 8; s++)
        if (is_private(v, header >> (2 * s) & 3)) return n + v->base_bits;
    return n;
}

static unsigned record_bits(const uint8_t *rec, const level_view *v) {
    unsigned header = (unsigned)golden_le(rec, 2), s, n = pointers_bit(v, header);
    for (s = 0; s < 8; s++) n += v->width[header >> (2 * s) & 3];
    return n;
}

static unsigned record_size(const uint8_t *rec, const level_view *v) { return (record_bits(rec, v) + 7) / 8; }

static size_t record_starts(const parts *p, uint32_t l, uint64_t *starts, size_t cap) {
    level_view v = level_of(p, l);
    const uint8_t *nodes = p->data[parts_find(p, 2)] + v.offset;
    uint64_t at = 0;
    size_t n = 0;
    while (at < v.size && n < cap) {
        starts[n++] = at;
        at += record_size(nodes + at, &v);
    }
    return n;
}

/* A record offset of the next level where it moved to (others unchanged). */
static uint64_t moved_offset(uint64_t at, const uint64_t *starts, const uint64_t *moved, size_t n) {
    size_t j;
    for (j = 0; j < n; j++)
        if (starts[j] == at) return moved[j];
    return at;
}

/* Writes NODES again with every pointer class EXTRA target bits wider (an
   independent writer of FORMAT.md's records): the same DAG, with room in
   every pointer for the hostile targets below. */
static void parts_widen(parts *p, unsigned extra) {
    int li = parts_find(p, 1), ni = parts_find(p, 2);
    uint32_t B = p->header[GOLDEN_OFF_LEVELS] - 2, l;
    uint64_t *starts[32], *moved[32], at = 0;
    size_t n[32], total = 0, k;
    uint8_t *out;
    level_view old[32];
    for (l = 0; l < B; l++) {
        old[l] = level_of(p, l);
        starts[l] = (uint64_t *)malloc(4096 * sizeof(uint64_t));
        moved[l] = (uint64_t *)malloc(4096 * sizeof(uint64_t));
        n[l] = record_starts(p, l, starts[l], 4096);
    }
    for (l = 0; l < B; l++) { /* the new classes, record offsets and sizes */
        uint8_t *e = p->data[li] + GOLDEN_LEVEL_ENTRY_SIZE * l;
        unsigned t;
        for (t = 1; t <= (e[28] ? 2u : 3u); t++) e[21 + t] = (uint8_t)(e[21 + t] + extra > 57u - e[24 + t] ? 57u - e[24 + t] : e[21 + t] + extra);
        if (e[28]) e[29] = (uint8_t)(e[29] + extra > 57u ? 57u : e[29] + extra);
        {
            level_view v = level_of(p, l);
            uint64_t size = 0;
            for (k = 0; k < n[l]; k++) {
                moved[l][k] = size;
                size += record_size(p->data[ni] + old[l].offset + starts[l][k], &v);
            }
            golden_put_le(e, at, 8);
            golden_put_le(e + 8, size, 8);
            at += size;
        }
    }
    total = (size_t)at + 16;
    out = (uint8_t *)calloc(total + 64, 1);
    for (l = 0; l < B; l++) {
        level_view v = level_of(p, l);
        for (k = 0; k < n[l]; k++) {
            const uint8_t *rec = p->data[ni] + old[l].offset + starts[l][k];
            uint8_t *w = out + v.offset + moved[l][k];
            unsigned header = (unsigned)golden_le(rec, 2), s;
            uint64_t from = pointers_bit(&old[l], header), to = pointers_bit(&v, header);
            memcpy(w, rec, 2);
            bits_put(w, 16, bits_get(rec, 16, v.count_bits), v.count_bits);
            if (to > 16 + v.count_bits) { /* the base field */
                uint64_t base = bits_get(rec, 16 + v.count_bits, old[l].base_bits);
                if (l + 1 < B) base = moved_offset(base, starts[l + 1], moved[l + 1], n[l + 1]);
                bits_put(w, 16 + v.count_bits, base, v.base_bits);
            }
            for (s = 0; s < 8; s++) {
                unsigned t = header >> (2 * s) & 3, kb = v.code_bits[t];
                uint64_t val, target;
                if (!t || is_private(&v, t)) continue;
                val = bits_get(rec, from, old[l].width[t]);
                target = val >> kb;
                if (l + 1 < B) target = moved_offset(target, starts[l + 1], moved[l + 1], n[l + 1]);
                bits_put(w, to, target << kb | (val & ((1ull << kb) - 1)), v.width[t]);
                from += old[l].width[t], to += v.width[t];
            }
        }
    }
    for (l = 0; l < B; l++) free(starts[l]), free(moved[l]);
    free(p->data[ni]);
    p->data[ni] = out;
    p->size[ni] = total;
}

/* Sets the target of a pointer of the record at START of level L (keeping
   its transform code) to TARGET, or to its own target + 1 when PLUS_ONE:
   the first pointer of the record whose class holds the new target, else
   its base field (the first private child) if it has one that holds it.
   Returns 0 (changing nothing) when none does. */
static int set_target(parts *p, uint32_t l, uint64_t start, int plus_one, uint64_t target) {
    level_view v = level_of(p, l);
    uint8_t *nodes = p->data[parts_find(p, 2)];
    unsigned header = (unsigned)golden_le(nodes + v.offset + start, 2), s;
    uint64_t rec = 8 * (v.offset + start), at = rec + pointers_bit(&v, header);
    for (s = 0; s <= 8; s++) {
        unsigned t = s < 8 ? header >> (2 * s) & 3 : 0, o = v.width[t] - v.code_bits[t];
        uint64_t cur, want;
        if (s == 8 && pointers_bit(&v, header) > 16 + v.count_bits) { /* the base field */
            at = rec + 16 + v.count_bits;
            cur = bits_get(nodes, at, v.base_bits);
            want = plus_one ? cur + 1 : target;
            if (want >> v.base_bits) return 0;
            bits_put(nodes, at, want, v.base_bits);
            return 1;
        }
        if (s == 8 || !t || is_private(&v, t)) continue;
        cur = bits_get(nodes, at, v.width[t]);
        want = plus_one ? (cur >> v.code_bits[t]) + 1 : target;
        if (!(want >> o)) {
            bits_put(nodes, at, want << v.code_bits[t] | (cur & ((1ull << v.code_bits[t]) - 1)), v.width[t]);
            return 1;
        }
        at += v.width[t];
    }
    return 0;
}

/* The same on any record of level L: the first that has such a pointer. */
static int set_any_target(parts *p, uint32_t l, int plus_one, uint64_t target) {
    uint64_t starts[512];
    size_t n = record_starts(p, l, starts, 512), k;
    for (k = 0; k < n; k++)
        if (set_target(p, l, starts[k], plus_one, target)) return 1;
    return 0;
}

static void expect(const parts *p, voxdag_status want, const char *what, const voxdag *original) {
    size_t size;
    uint8_t *f = parts_write(p, &size);
    voxdag_error err;
    voxdag_status st = load_copy(f, size, 0, &err);
    CHECK_MSG(st == want, "%s: status %d (%s), expected %d", what, (int)st, err.message, (int)want);
    if (getenv("FORMAT_VERBOSE")) fprintf(stderr, "  %s: %s\n", what, err.message);
    if (st == VOXDAG_OK && want == VOXDAG_OK && original) {
        voxdag *d = NULL;
        CHECK(voxdag_load_memory(f, size, NULL, &d, NULL) == VOXDAG_OK);
        if (d) CHECK_MSG(same_voxels(d, original), "%s: different voxels", what);
        voxdag_free(d);
    }
    free(f);
}

static void test_hostile_files(void) {
    size_t size = 0, n1, n2, i;
    uint8_t *f = read_golden(GOLDEN_MIRRORED_BLOB, &size), *w;
    parts p;
    voxdag *orig = NULL;
    uint64_t starts1[512], starts2[512];
    int nodes, bricks;
    if (!f || !parts_read(&p, f, size)) {
        CHECK_MSG(0, "mirrored blob golden missing or unreadable");
        free(f);
        return;
    }
    CHECK(voxdag_load_memory(f, size, NULL, &orig, NULL) == VOXDAG_OK);
    nodes = parts_find(&p, 2);
    bricks = parts_find(&p, 3);
    CHECK(nodes >= 0 && bricks >= 0 && f[40] == 5);
    if (!orig || nodes < 0 || bricks < 0) goto done;
    /* Writing the parts back gives the golden: this writer follows FORMAT.md. */
    w = parts_write(&p, &i);
    CHECK(i == size && !memcmp(w, f, size));
    free(w);
    n1 = record_starts(&p, 1, starts1, 512);
    n2 = record_starts(&p, 2, starts2, 512);
    CHECK(n1 >= 1 && n2 >= 2);

    { /* a pointer to a byte inside a record of the next level */
        parts q;
        parts_read(&q, f, size);
        parts_widen(&q, 8);
        expect(&q, VOXDAG_OK, "the same DAG with wider pointers", orig);
        CHECK(set_any_target(&q, 0, 1, 0));
        expect(&q, VOXDAG_ERR_CORRUPT, "pointer to a non-start byte", NULL);
        parts_free(&q);
    }
    { /* a pointer past the end of the next level; and a brick index past the bricks */
        parts q;
        parts_read(&q, f, size);
        parts_widen(&q, 8);
        CHECK(set_any_target(&q, 1, 0, level_of(&q, 2).size));
        expect(&q, VOXDAG_ERR_CORRUPT, "pointer past the level", NULL);
        parts_free(&q);
        parts_read(&q, f, size);
        parts_widen(&q, 8);
        CHECK(set_any_target(&q, 2, 0, (uint64_t)(q.size[bricks] / 8)));
        expect(&q, VOXDAG_ERR_CORRUPT, "brick index past the bricks", NULL);
        parts_free(&q);
    }
    { /* a count that differs from the sum of the children's (the level-1 node's) */
        parts q;
        level_view v;
        parts_read(&q, f, size);
        v = level_of(&q, 1);
        CHECK(v.count_bits >= 1);
        q.data[nodes][v.offset + starts1[0] + 2] ^= 1;
        expect(&q, VOXDAG_ERR_CORRUPT, "count differs from the children's sum", NULL);
        parts_free(&q);
        /* the root's count and the header's voxel count both one higher */
        parts_read(&q, f, size);
        v = level_of(&q, 0);
        bits_put(q.data[nodes], 16, bits_get(q.data[nodes], 16, v.count_bits) + 1, v.count_bits);
        golden_put_le(q.header + 32, golden_le(q.header + 32, 8) + 1, 8);
        q.size[parts_find(&q, 4)] += 3; /* one more colour (zero), so that only the counts disagree */
        memset(q.data[parts_find(&q, 4)] + q.size[parts_find(&q, 4)] - 3, 0, 3);
        expect(&q, VOXDAG_ERR_CORRUPT, "root count above its children's", NULL);
        parts_free(&q);
        /* level 1 without counts above level 2 (L-3), which has none either:
           a derived count must sum stored ones */
        parts_read(&q, f, size);
        q.data[parts_find(&q, 1)][GOLDEN_LEVEL_ENTRY_SIZE + 20] = 0;
        expect(&q, VOXDAG_ERR_CORRUPT, "two levels in a row without counts", NULL);
        parts_free(&q);
        /* only the header's voxel count */
        parts_read(&q, f, size);
        golden_put_le(q.header + 32, golden_le(q.header + 32, 8) - 1, 8);
        q.size[parts_find(&q, 4)] -= 3;
        expect(&q, VOXDAG_ERR_CORRUPT, "header voxel count", NULL);
        parts_free(&q);
    }
    { /* cycle-like: a node whose pointer holds its own offset (a pointer only
         reaches the next level, so this lands elsewhere, never on itself);
         on the widened file, where every such target fits */
        int tried = 0;
        for (i = 0; i < n1 + n2; i++) {
            parts q;
            size_t k, m1, m2;
            uint64_t w1[512], w2[512], own;
            uint32_t l = i < n1 ? 1 : 2;
            int lands = 0;
            parts_read(&q, f, size);
            parts_widen(&q, 8);
            m1 = record_starts(&q, 1, w1, 512);
            m2 = record_starts(&q, 2, w2, 512);
            CHECK(m1 == n1 && m2 == n2);
            own = i < n1 ? w1[i] : w2[i - n1];
            if (l == 1)
                for (k = 0; k < m2; k++) lands |= w2[k] == own;
            else
                lands = own < p.size[bricks] / 8;
            if (!lands && set_target(&q, l, own, 0, own)) { /* landing: a real node of the next level */
                expect(&q, VOXDAG_ERR_CORRUPT, "self pointer", NULL);
                tried++;
            }
            parts_free(&q);
        }
        CHECK(tried > 0);
        /* the root pointing at its own offset 0: the first node of level 1 */
        {
            parts q;
            parts_read(&q, f, size);
            CHECK(set_target(&q, 0, 0, 0, 0));
            w = parts_write(&q, &i);
            {
                voxdag_error err;
                voxdag_status st = load_copy(w, i, 0, &err);
                /* the same target as before can only be accepted unchanged */
                CHECK(st != VOXDAG_OK || (i == size && !memcmp(w, f, size)));
            }
            free(w);
            parts_free(&q);
        }
    }
    { /* a node without children */
        parts q;
        parts_read(&q, f, size);
        golden_put_le(q.data[nodes] + level_of(&q, 2).offset + starts2[1], 0, 2);
        expect(&q, VOXDAG_ERR_CORRUPT, "node without children", NULL);
        parts_free(&q);
    }
    { /* an unreferenced node: a copy of brick 0 appended to the bricks */
        parts q;
        parts_read(&q, f, size);
        memcpy(q.data[bricks] + q.size[bricks], q.data[bricks], 8);
        q.size[bricks] += 8;
        expect(&q, VOXDAG_ERR_CORRUPT, "unreferenced brick", NULL);
        parts_free(&q);
        /* an empty brick */
        parts_read(&q, f, size);
        memset(q.data[bricks] + q.size[bricks], 0, 8);
        q.size[bricks] += 8;
        expect(&q, VOXDAG_ERR_CORRUPT, "empty brick", NULL);
        parts_free(&q);
    }
    { /* trailing bytes, inside and outside the declared size */
        parts q;
        uint8_t *g;
        size_t gs;
        parts_read(&q, f, size);
        w = parts_write(&q, &i);
        g = (uint8_t *)calloc(i + 8, 1);
        memcpy(g, w, i);
        gs = i + 8;
        {
            voxdag_error err;
            CHECK(load_copy(g, gs, 0, &err) == VOXDAG_ERR_CORRUPT); /* past the declared size */
            golden_put_le(g + 24, gs, 8);
            golden_reseal(g, gs);
            CHECK(load_copy(g, gs, 0, &err) == VOXDAG_ERR_CORRUPT); /* after the last section */
        }
        free(g);
        free(w);
        parts_free(&q);
    }
    { /* unknown sections: required refused, optional skipped */
        parts q;
        parts_read(&q, f, size);
        q.type[q.count] = 0x7F;
        q.flags[q.count] = 0;
        q.size[q.count] = 5;
        q.data[q.count] = (uint8_t *)calloc(8, 1);
        q.count++;
        expect(&q, VOXDAG_ERR_VERSION, "unknown required section", NULL);
        q.flags[q.count - 1] = 1;
        expect(&q, VOXDAG_OK, "unknown optional section", orig);
        /* also first in the file */
        {
            uint32_t t = q.type[0], fl = q.flags[0];
            uint8_t *dp = q.data[0];
            size_t sz = q.size[0];
            q.type[0] = q.type[q.count - 1], q.flags[0] = 1, q.data[0] = q.data[q.count - 1], q.size[0] = 5;
            q.type[q.count - 1] = t, q.flags[q.count - 1] = fl, q.data[q.count - 1] = dp, q.size[q.count - 1] = sz;
            expect(&q, VOXDAG_OK, "unknown optional section first", orig);
        }
        /* a known section twice */
        q.type[0] = 2;
        q.flags[0] = 0;
        expect(&q, VOXDAG_ERR_CORRUPT, "duplicate section", NULL);
        parts_free(&q);
    }
    { /* overlapping sections: the bricks entry starts inside the nodes */
        parts q;
        uint8_t *e;
        parts_read(&q, f, size);
        w = parts_write(&q, &i);
        e = w + GOLDEN_HEADER_SIZE + 32 * (size_t)bricks;
        golden_put_le(e + 8, golden_le(e + 8, 8) - 8, 8);
        golden_put_le(e + 16, golden_le(e + 16, 8) + 8, 8);
        golden_reseal(w, i);
        {
            voxdag_error err;
            CHECK(load_copy(w, i, 0, &err) == VOXDAG_ERR_CORRUPT);
        }
        /* and the nodes section reaching into the bricks */
        free(w);
        w = parts_write(&q, &i);
        e = w + GOLDEN_HEADER_SIZE + 32 * (size_t)nodes;
        golden_put_le(e + 16, golden_le(e + 16, 8) + 16, 8);
        golden_reseal(w, i);
        {
            voxdag_error err;
            CHECK(load_copy(w, i, 0, &err) == VOXDAG_ERR_CORRUPT);
        }
        free(w);
        parts_free(&q);
    }
done:
    voxdag_free(orig);
    parts_free(&p);
    free(f);
}

/* Fields new in version 3, each broken in turn on the mirrored blob (built
   with all 48 symmetries); and a version-2 file refused by its version. */
static void test_version3_fields(void) {
    size_t size = 0, old_size = 0, n1;
    uint8_t *f = read_golden(GOLDEN_MIRRORED_BLOB, &size), *old = NULL;
    uint64_t starts1[512];
    parts p;
    int levels;
    if (!f || !parts_read(&p, f, size)) {
        CHECK_MSG(0, "mirrored blob golden missing or unreadable");
        free(f);
        return;
    }
    levels = parts_find(&p, 1);
    n1 = record_starts(&p, 1, starts1, 512);
    CHECK(levels >= 0 && n1 >= 1 && p.header[VOXDAG_FILE_OFF_SYMMETRY] == VOXDAG_SYMMETRY_FULL);
    { /* the symmetry group: unknown, or too small for the transforms used */
        parts q;
        parts_read(&q, f, size);
        q.header[VOXDAG_FILE_OFF_SYMMETRY] = 4;
        expect(&q, VOXDAG_ERR_CORRUPT, "unknown symmetry group", NULL);
        q.header[VOXDAG_FILE_OFF_SYMMETRY] = 0;
        expect(&q, VOXDAG_ERR_CORRUPT, "symmetry group 0", NULL);
        q.header[VOXDAG_FILE_OFF_SYMMETRY] = VOXDAG_SYMMETRY_NONE;
        expect(&q, VOXDAG_ERR_CORRUPT, "transforms outside the group none", NULL);
        q.header[VOXDAG_FILE_OFF_SYMMETRY] = VOXDAG_SYMMETRY_FULL;
        q.header[VOXDAG_FILE_OFF_ROOT_TRANSFORM] = 48;
        expect(&q, VOXDAG_ERR_CORRUPT, "root transform 48", NULL);
        parts_free(&q);
    }
    { /* the voxel box: outside the grid, empty, inverted */
        parts q;
        parts_read(&q, f, size);
        golden_put_le(q.header + VOXDAG_FILE_OFF_VOXEL_BOX + 12, 33, 4);
        expect(&q, VOXDAG_ERR_CORRUPT, "voxel box past the grid", NULL);
        golden_put_le(q.header + VOXDAG_FILE_OFF_VOXEL_BOX + 12, golden_le(q.header + VOXDAG_FILE_OFF_VOXEL_BOX, 4), 4);
        expect(&q, VOXDAG_ERR_CORRUPT, "empty voxel box", NULL);
        parts_free(&q);
    }
    { /* level entries: table length, table entries, classes, count width, reserved bytes */
        static const struct {
            unsigned at, value;
            const char *what;
        } bad[] = {{21, 0, "transform table length 0"}, {21, 49, "transform table length 49"},
                   {32, 48, "table entry 48"},           {25, 7, "7 code bits"},
                   {30, 1, "reserved level bytes"},      {20, 65, "count width 65"},
                   {28, 2, "private child flag 2"},      {29, 58, "58-bit base field"},
                   {24, 1, "a third class beside private children"}};
        parts q;
        uint8_t *e;
        size_t k;
        e = p.data[levels] + GOLDEN_LEVEL_ENTRY_SIZE;
        CHECK_MSG(e[28] == 1 && e[24] == 0, "level 1 of the golden has no private children");
        for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            parts_read(&q, f, size);
            e = q.data[levels] + GOLDEN_LEVEL_ENTRY_SIZE; /* level 1 of 0..2 */
            e[bad[k].at] = (uint8_t)bad[k].value;
            expect(&q, VOXDAG_ERR_CORRUPT, bad[k].what, NULL);
            parts_free(&q);
        }
        parts_read(&q, f, size);
        e = q.data[levels] + GOLDEN_LEVEL_ENTRY_SIZE;
        CHECK(e[21] >= 1);
        e[32 + e[21]] = 1;
        expect(&q, VOXDAG_ERR_CORRUPT, "table entry past the length", NULL);
        parts_free(&q);
        parts_read(&q, f, size);
        e = q.data[levels] + GOLDEN_LEVEL_ENTRY_SIZE;
        e[25] = 6, e[22] = 52;
        expect(&q, VOXDAG_ERR_CORRUPT, "58-bit pointer class", NULL);
        parts_free(&q);
    }
    { /* private children (on the golden made of them): two records with the
         same base (one private group twice, another not at all); a base
         one record further (the group runs past its parent's, or off the
         level); and a private flag on a level that has none */
        size_t psize = 0, m;
        uint8_t *pf = read_golden(GOLDEN_PRIVATE, &psize);
        parts q;
        uint64_t st[512];
        int ok = pf && parts_read(&q, pf, psize);
        CHECK_MSG(ok, "private golden missing or unreadable");
        if (ok) {
            level_view v = level_of(&q, 1);
            const uint8_t *nodes = q.data[parts_find(&q, 2)];
            uint64_t base0;
            m = record_starts(&q, 1, st, 512);
            CHECK(m >= 2 && v.private_children && pointers_bit(&v, (unsigned)golden_le(nodes + v.offset, 2)) > 16 + v.count_bits);
            base0 = bits_get(nodes, 8 * v.offset + 16 + v.count_bits, v.base_bits);
            CHECK_MSG(m >= 2 && set_target(&q, 1, st[1], 0, base0), "no second level-1 record with a base field");
            expect(&q, VOXDAG_ERR_CORRUPT, "a private group referenced twice", NULL);
            parts_free(&q);
            parts_read(&q, pf, psize);
            CHECK(set_target(&q, 1, st[m - 1], 1, 0));
            expect(&q, VOXDAG_ERR_CORRUPT, "the last private group one record further", NULL);
            parts_free(&q);
        }
        free(pf);
        parts_read(&q, f, size);
        q.data[levels][28] = 1; /* the blob's level 0: tag 3 now private, its pointers misread */
        expect(&q, VOXDAG_ERR_CORRUPT, "private flag on a level without private children", NULL);
        parts_free(&q);
    }
    { /* a pointer code at or past the table length: the level's table cut
         to end just before the code of a pointer that has a non-zero one */
        parts q;
        level_view v;
        unsigned found = 0;
        uint32_t l;
        parts_read(&q, f, size);
        for (l = 0; l < 3 && !found; l++) {
            uint64_t st[512];
            size_t m = record_starts(&q, l, st, 512), k;
            v = level_of(&q, l);
            for (k = 0; k < m && !found; k++) {
                const uint8_t *nodes = q.data[parts_find(&q, 2)];
                unsigned header = (unsigned)golden_le(nodes + v.offset + st[k], 2), s;
                uint64_t at = 8 * (v.offset + st[k]) + pointers_bit(&v, header);
                for (s = 0; s < 8 && !found; s++) {
                    unsigned t = header >> (2 * s) & 3;
                    unsigned code = (unsigned)(bits_get(nodes, at, v.width[t]) & ((1ull << v.code_bits[t]) - 1));
                    if (t && code) {
                        uint8_t *e = q.data[levels] + GOLDEN_LEVEL_ENTRY_SIZE * l;
                        e[21] = (uint8_t)code;
                        memset(e + 32 + code, 0, 48 - code);
                        found = 1;
                    }
                    at += v.width[t];
                }
            }
        }
        CHECK_MSG(found, "no pointer with a non-zero transform code in the golden");
        if (found) expect(&q, VOXDAG_ERR_CORRUPT, "code past the table", NULL);
        parts_free(&q);
    }
    { /* a padding bit set at the end of a level-1 record */
        parts q;
        level_view v;
        size_t k;
        parts_read(&q, f, size);
        v = level_of(&q, 1);
        for (k = 0; k < n1; k++) {
            uint8_t *rec = q.data[parts_find(&q, 2)] + v.offset + starts1[k];
            unsigned bits = record_bits(rec, &v);
            if (bits % 8) {
                rec[bits / 8] |= (uint8_t)(0x80u);
                expect(&q, VOXDAG_ERR_CORRUPT, "padding bit", NULL);
                break;
            }
        }
        CHECK_MSG(k < n1, "no level-1 record with padding bits in the golden");
        parts_free(&q);
    }
    { /* a version-2 file: refused by its version, the message naming it */
        FILE *fp = fopen("tests/data/version2/mirrored_blob_l5.vdag", "rb");
        voxdag_error err;
        voxdag *d = NULL;
        CHECK(fp != NULL);
        if (fp) {
            old = (uint8_t *)malloc(1 << 16);
            old_size = fread(old, 1, 1 << 16, fp);
            fclose(fp);
            CHECK(old_size > 64 && golden_le(old + VOXDAG_FILE_OFF_VERSION, 4) == 2);
            CHECK(voxdag_load_memory(old, old_size, NULL, &d, &err) == VOXDAG_ERR_VERSION);
            CHECK(err.message && strstr(err.message, "version 1 or 2") && err.byte_offset == VOXDAG_FILE_OFF_VERSION);
            voxdag_free(d);
            golden_put_le(old + VOXDAG_FILE_OFF_VERSION, 4, 4);
            CHECK(voxdag_load_memory(old, old_size, NULL, &d, &err) == VOXDAG_ERR_VERSION);
            CHECK(err.message && strstr(err.message, "newer"));
            free(old);
        }
    }
    parts_free(&p);
    free(f);
}

/* voxdag_save_file writes atomically: a save that fails part way (here: a
   file-size limit in a child process) or cannot start leaves the old file
   as it was and no temporary file; errors carry errno. */
static int file_equals(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "rb");
    size_t n;
    uint8_t *buf = (uint8_t *)malloc(size + 1);
    int same;
    if (!f) {
        free(buf);
        return 0;
    }
    n = fread(buf, 1, size + 1, f);
    fclose(f);
    same = n == size && !memcmp(buf, data, size);
    free(buf);
    return same;
}

/* 1 if a temporary file of a save of PATH is left: this process's name,
   or the names of earlier versions (PATH.tmp0, PATH.vdag-tmp). */
static int save_temp_left(const char *path) {
    char tmp[4200];
    const char *names[3];
    int k, left = 0;
    voxdag_save_temp_path(path, tmp, sizeof tmp);
    names[0] = tmp;
    names[1] = ".tmp0";
    names[2] = ".vdag-tmp";
    for (k = 0; k < 3; k++) {
        char name[4200];
        FILE *fp;
        if (k) snprintf(name, sizeof name, "%s%s", path, names[k]);
        else snprintf(name, sizeof name, "%s", tmp);
        if ((fp = fopen(name, "rb")) != NULL) {
            fclose(fp);
            left = 1;
        }
    }
    return left;
}

static void test_save_file(void) {
    size_t size = 0, small_size;
    uint8_t *f = read_golden(GOLDEN_MIRRORED_BLOB, &size);
    const void *small;
    voxdag *d = NULL, *e = NULL;
    voxdag_error err;
    char path[256], tmp[300];
    FILE *fp;
    if (!f) {
        CHECK_MSG(0, "mirrored blob golden missing");
        return;
    }
    snprintf(path, sizeof path, "build/test_save_%u.vdag", (unsigned)time(NULL) % 100000u);
    CHECK(voxdag_load_memory(f, size, NULL, &d, NULL) == VOXDAG_OK);
    if (!d) goto done;
    CHECK(voxdag_save_file(d, path, &err) == VOXDAG_OK && err.os_error == 0);
    CHECK(file_equals(path, f, size));
    CHECK(voxdag_load_file(path, NULL, &e, NULL) == VOXDAG_OK);
    voxdag_free(e);
    /* a failure before writing: a missing directory */
    CHECK(voxdag_save_file(d, "build/no such directory/x.vdag", &err) == VOXDAG_ERR_IO && err.os_error == ENOENT);
    CHECK(voxdag_load_file("build/no such file.vdag", NULL, &e, &err) == VOXDAG_ERR_IO && err.os_error == ENOENT && !e);
    CHECK(voxdag_load_file("build", NULL, &e, &err) == VOXDAG_ERR_IO && err.os_error != 0 && !e); /* a directory */
    /* a failure while writing, over an existing smaller file */
    {
        voxdag *one = NULL;
        size_t one_size = 0;
        uint8_t *g = read_golden(GOLDEN_ONE_VOXEL, &one_size);
        CHECK(g && voxdag_load_memory(g, one_size, NULL, &one, NULL) == VOXDAG_OK);
        if (one) {
            CHECK(voxdag_save_file(one, path, NULL) == VOXDAG_OK);
            small = voxdag_image(one, &small_size);
#ifdef __unix__
            {
                pid_t pid = fork();
                int status = 0;
                if (pid == 0) { /* the child may write at most 100 bytes per file */
                    struct rlimit rl;
                    signal(SIGXFSZ, SIG_IGN);
                    rl.rlim_cur = rl.rlim_max = 100;
                    setrlimit(RLIMIT_FSIZE, &rl);
                    _exit(voxdag_save_file(d, path, &err) == VOXDAG_ERR_IO && err.os_error == EFBIG ? 0 : 1);
                }
                CHECK(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0);
                CHECK_MSG(file_equals(path, small, small_size), "a failed save changed the existing file");
                snprintf(tmp, sizeof tmp, "%s.vdag-tmp-%lu", path, (unsigned long)pid); /* the child's */
                fp = fopen(tmp, "rb");
                CHECK_MSG(!fp, "a save that failed with EFBIG left its temporary file");
                if (fp) fclose(fp);
            }
#else
            (void)small; /* no file size limit to fail a write with */
#endif
            voxdag_free(one);
        }
        free(g);
    }
    CHECK_MSG(!save_temp_left(path), "a temporary file was left behind");
    /* a file at the temporary name is a stale temporary (a save that was
       killed): removed, and the save goes through */
    CHECK(voxdag_save_temp_path(path, tmp, sizeof tmp) == VOXDAG_OK);
    fp = fopen(tmp, "wb");
    if (fp) {
        fputs("a stale temporary", fp);
        fclose(fp);
    }
    fp = fopen(path, "wb");
    if (fp) {
        fputs("the old file", fp);
        fclose(fp);
    }
    CHECK(voxdag_save_file(d, path, &err) == VOXDAG_OK && file_equals(path, f, size));
    fp = fopen(tmp, "rb");
    CHECK_MSG(!fp, "a stale temporary was left");
    if (fp) fclose(fp);
    remove(path);
done:
    voxdag_free(d);
    free(f);
}

/* The temporary name: PATH + ".vdag-tmp-" + the process id; too small a
   buffer or a NULL is an invalid argument. */
static void test_save_temp_path(void) {
    char buf[64], want[64];
#if defined(_WIN32)
    snprintf(want, sizeof want, "a/b.vdag.vdag-tmp-%lu", (unsigned long)_getpid());
#elif defined(__unix__) || defined(__APPLE__)
    snprintf(want, sizeof want, "a/b.vdag.vdag-tmp-%lu", (unsigned long)getpid());
#else
    snprintf(want, sizeof want, "a/b.vdag.vdag-tmp");
#endif
    CHECK(voxdag_save_temp_path("a/b.vdag", buf, sizeof buf) == VOXDAG_OK && !strcmp(buf, want));
    CHECK(voxdag_save_temp_path("a/b.vdag", buf, 8 + 32) == VOXDAG_OK && !strcmp(buf, want));
    CHECK(voxdag_save_temp_path("a/b.vdag", buf, 8 + 31) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_save_temp_path(NULL, buf, sizeof buf) == VOXDAG_ERR_INVALID_ARGUMENT);
    CHECK(voxdag_save_temp_path("x", NULL, sizeof buf) == VOXDAG_ERR_INVALID_ARGUMENT);
}

#ifdef __unix__
/* A save when links are planted at every temporary name it might use (this
   version's, and the PATH.tmpN and PATH.vdag-tmp of earlier ones), each
   pointing at a file that does not exist: no link is followed (none of
   their targets is created), the target stays a regular file, and a link
   at its own temporary name is removed (the link, not its target). */
static void test_save_planted_links(void) {
    size_t size = 0, one_size = 0;
    uint8_t *f = read_golden(GOLDEN_MIRRORED_BLOB, &size), *g = read_golden(GOLDEN_ONE_VOXEL, &one_size);
    voxdag *d = NULL;
    voxdag_error err;
    char path[256], link[320], target[320];
    struct stat st;
    int k, pass;
    snprintf(path, sizeof path, "build/test_save_links_%lu.vdag", (unsigned long)getpid());
    CHECK(f && g && voxdag_load_memory(f, size, NULL, &d, NULL) == VOXDAG_OK);
    if (!d) goto done;
    for (pass = 0; pass < 2; pass++) {
        FILE *fp = fopen(path, "wb"); /* the old file */
        CHECK(fp && fwrite(g, 1, one_size, fp) == one_size);
        if (fp) fclose(fp);
        for (k = -2; k < 10; k++) {
            if (k == -2) voxdag_save_temp_path(path, link, sizeof link);
            else if (k == -1) snprintf(link, sizeof link, "%s.vdag-tmp", path);
            else snprintf(link, sizeof link, "%s.tmp%d", path, k);
            snprintf(target, sizeof target, "%s.victim%d", path, k + 2);
            remove(target);
            remove(link);
            /* the second pass: no link at this version's own name */
            CHECK(k == -2 && pass == 1 ? 1 : symlink(target + 6, link) == 0); /* relative to build/ */
        }
        CHECK(voxdag_save_file(d, path, &err) == VOXDAG_OK);
        CHECK(file_equals(path, f, size));
        CHECK_MSG(lstat(path, &st) == 0 && S_ISREG(st.st_mode), "pass %d: the target is not a regular file", pass);
        for (k = -2; k < 10; k++) {
            snprintf(target, sizeof target, "%s.victim%d", path, k + 2);
            CHECK_MSG(lstat(target, &st) != 0, "pass %d: a planted link was followed (%s created)", pass, target);
            remove(target);
            if (k == -2) voxdag_save_temp_path(path, link, sizeof link);
            else if (k == -1) snprintf(link, sizeof link, "%s.vdag-tmp", path);
            else snprintf(link, sizeof link, "%s.tmp%d", path, k);
            /* our own name: its link removed (pass 0) or never there; the others kept */
            CHECK_MSG(k == -2 ? lstat(link, &st) != 0 : lstat(link, &st) == 0 && S_ISLNK(st.st_mode),
                      "pass %d: %s changed", pass, link);
            remove(link);
        }
    }
    remove(path);
done:
    voxdag_free(d);
    free(f);
    free(g);
}

/* A save onto a directory (here an empty one, which remove() would delete)
   is refused, and the directory stays; onto a file, the file's permission
   bits are kept, and a new file gets 0666 less the umask. */
static void test_save_directory_and_mode(void) {
    size_t size = 0;
    uint8_t *f = read_golden(GOLDEN_ONE_VOXEL, &size);
    voxdag *d = NULL;
    voxdag_error err;
    char path[256];
    struct stat st;
    mode_t old_mask;
    FILE *fp;
    CHECK(f && voxdag_load_memory(f, size, NULL, &d, NULL) == VOXDAG_OK);
    if (!d) goto done;
    snprintf(path, sizeof path, "build/test_save_dir_%lu", (unsigned long)getpid());
    rmdir(path);
    CHECK(mkdir(path, 0755) == 0);
    CHECK(voxdag_save_file(d, path, &err) == VOXDAG_ERR_IO && err.os_error == EISDIR);
    CHECK_MSG(stat(path, &st) == 0 && S_ISDIR(st.st_mode), "a save onto an empty directory removed it");
    CHECK_MSG(!save_temp_left(path), "a refused save left a temporary file");
    rmdir(path);
    snprintf(path, sizeof path, "build/test_save_mode_%lu.vdag", (unsigned long)getpid());
    remove(path);
    old_mask = umask(022);
    CHECK(voxdag_save_file(d, path, NULL) == VOXDAG_OK && stat(path, &st) == 0 && (st.st_mode & 0777) == 0644);
    CHECK(chmod(path, 0600) == 0);
    CHECK(voxdag_save_file(d, path, NULL) == VOXDAG_OK && file_equals(path, f, size));
    CHECK_MSG(stat(path, &st) == 0 && (st.st_mode & 0777) == 0600, "a 0600 file became %03o",
              (unsigned)(st.st_mode & 0777));
    CHECK(chmod(path, 0640) == 0);
    CHECK(voxdag_save_file(d, path, NULL) == VOXDAG_OK && stat(path, &st) == 0 && (st.st_mode & 0777) == 0640);
    umask(077); /* the umask does not narrow an existing file's bits */
    CHECK(chmod(path, 0644) == 0);
    CHECK(voxdag_save_file(d, path, NULL) == VOXDAG_OK && stat(path, &st) == 0 && (st.st_mode & 0777) == 0644);
    umask(old_mask);
    fp = fopen(path, "rb");
    CHECK(fp != NULL);
    if (fp) fclose(fp);
    remove(path);
    CHECK(!save_temp_left(path));
done:
    voxdag_free(d);
    free(f);
}
#endif

// -- Tables shared by every DAG, and what one DAG holds

/* The symmetry tables that every DAG and every build share (constants in
   the header) against their definition: transform T = perm * 8 + m moves
   axis a of a point to axis perm[a] (the permutations in lexicographic
   order), then mirrors the axes in m; octant i is the corner point with
   coordinate a equal to bit a of i. */
static void test_cube_tables(void) {
    const voxdagi_cube *c = &voxdagi_cube_tables;
    unsigned perm[6][3], n = 0, a, b, k, t, u, i, p;
    for (a = 0; a < 3; a++)
        for (b = 0; b < 3; b++)
            for (k = 0; k < 3; k++)
                if (a != b && b != k && a != k) perm[n][0] = a, perm[n][1] = b, perm[n][2] = k, n++;
    CHECK(n == 6);
    for (t = 0; t < 48; t++)
        for (i = 0; i < 8; i++) {
            unsigned v[3], w[3];
            for (a = 0; a < 3; a++) v[a] = i >> a & 1;
            for (a = 0; a < 3; a++) w[perm[t / 8][a]] = v[a];
            for (a = 0; a < 3; a++)
                if (t >> a & 1) w[a] = 1 - w[a];
            CHECK_MSG(c->act[t][i] == (w[0] | w[1] << 1 | w[2] << 2), "act[%u][%u]", t, i);
        }
    for (t = 0; t < 48; t++)
        for (u = 0; u < t; u++) CHECK(memcmp(c->act[t], c->act[u], 8)); /* the corners tell transforms apart */
    for (t = 0; t < 48; t++) {
        CHECK(c->inv[t] < 48 && c->comp[t][c->inv[t]] == 0 && c->comp[c->inv[t]][t] == 0);
        for (u = 0; u < 48; u++) {
            CHECK(c->comp[t][u] < 48);
            for (i = 0; i < 8; i++) /* comp[T][U]: U, then T */
                CHECK_MSG(c->act[c->comp[t][u]][i] == c->act[t][c->act[u][i]], "comp[%u][%u]", t, u);
        }
        for (p = 0; p < 256; p++) {
            unsigned want = 0;
            for (i = 0; i < 8; i++) want |= (p >> c->act[t][i] & 1) << i; /* world octant i: stored T(i) */
            CHECK_MSG(voxdagi_occupancy[t][p] == want, "occupancy[%u][%u]", t, p);
        }
    }
}

/* A loaded DAG holds what its file needs: the tables above are shared, and
   per inner level it keeps one entry, so a tiny file costs below 2 KB, not
   25 KB whatever the file (10,000 small props: 16 MB, not 250 MB). */
static void test_tiny_dag_memory(void) {
    size_t size = 0;
    uint8_t *f = read_golden(GOLDEN_ONE_VOXEL, &size);
    int kind;
    if (!f) return;
    {
        voxdag_load_opts o;
        count_alloc ca;
        voxdag *d = NULL;
        opts_with(&o, &ca, -1);
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        CHECK_MSG(ca.held <= 2048, "%llu bytes held by a DAG of %zu bytes", (unsigned long long)ca.held, size);
        voxdag_free(d);
        CHECK(ca.held == 0 && !ca.bad_free);
    }
    free(f);
    for (kind = 0; kind < GOLDEN_COUNT; kind++) { /* no more than its levels need */
        voxdag_load_opts o;
        count_alloc ca;
        voxdag *d = NULL;
        f = read_golden(kind, &size);
        if (!f) continue;
        opts_with(&o, &ca, -1);
        CHECK(voxdag_load_memory(f, size, &o, &d, NULL) == VOXDAG_OK);
        CHECK_MSG(d && ca.held == sizeof *d + (d->levels - 2) * sizeof *d->level, "%s: %llu bytes held",
                  golden_names[kind], (unsigned long long)ca.held);
        if (d && d->voxels <= 4096) { /* a DAG made from it (L = 2: no inner levels at all) */
            static uint8_t rgb[3 * 4096];
            voxdag *c = NULL;
            CHECK_MSG(voxdag_with_colors(d, VOXDAG_COLORS_RGB8, rgb, 3 * (size_t)d->voxels, &c, NULL) == VOXDAG_OK &&
                          c && c->levels == d->levels && c->level_count == d->level_count,
                      "%s: with colours", golden_names[kind]);
            voxdag_free(c);
        }
        voxdag_free(d);
        CHECK(ca.held == 0 && !ca.bad_free);
        free(f);
    }
}

const test_case test_format_cases[] = {
    {"format/golden_identical", test_golden_identical},
    {"format/offsets_documented", test_offsets_documented},
    {"format/header_fields", test_header_fields},
    {"format/mutations", test_mutations},
    {"format/allocation_failures", test_allocation_failures},
    {"format/build_allocation_failures", test_build_allocation_failures},
    {"format/limits", test_limits},
    {"format/load_file_header_first", test_load_file_header_first},
    {"format/hostile_files", test_hostile_files},
    {"format/version3_fields", test_version3_fields},
    {"format/save_file", test_save_file},
    {"format/save_temp_path", test_save_temp_path},
    {"format/cube_tables", test_cube_tables},
    {"format/tiny_dag_memory", test_tiny_dag_memory},
#ifdef __unix__
    {"format/save_planted_links", test_save_planted_links},
    {"format/save_directory_and_mode", test_save_directory_and_mode},
#endif
    {NULL, NULL},
};
