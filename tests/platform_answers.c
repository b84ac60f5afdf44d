/* Answers that must not depend on the platform: `make test` runs this program
   natively and on every foreign target of the matrix (32-bit x86 with x87
   maths, big-endian s390x, Windows under Wine; tests/matrix.sh) and compares
   the outputs line by line. It prints, one fact a line:
   - per golden file (tests/data/golden): its info, a hash of every lookup and
     of the voxel walk;
   - scenes built here (voxels with RGB8 colours, a voxelized mesh, on 1 and 3
     threads, with voxcolor colours): size and hash of the file bytes;
   - voxcolor streams at several settings: size, hash, and a hash of the
     decoded colours;
   - rays (full-precision random origins and directions, axis-aligned rays
     through faces, edges and corners, level of detail, tiny and huge
     coordinates): hit or miss, t as a hexadecimal float, voxel, normal,
     level, index, and the shadow query. Every t is printed bit for bit;
   - the same rays rounded to float through voxdag_gpu.h's C build (the GPU
     traversal), its t as the float's bits.
   Usage: platform_answers [DATA_DIR] (default tests/data). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#include "voxdag_gpu.h"

static const char *const goldens[] = {"brick_root_l2", "empty_l2", "empty_l5", "mirrored_blob_l5", "one_voxel",
                                      "svdag_l5"};

/* FNV-1a, 64 bits. */
static uint64_t fnv(uint64_t h, const void *p, size_t n) {
    const uint8_t *b = (const uint8_t *)p;
    size_t i;
    for (i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001B3ull;
    return h;
}
#define FNV0 0xCBF29CE484222325ull

static uint64_t fnv_u64(uint64_t h, uint64_t v) { /* byte order independent */
    uint8_t b[8];
    unsigned i;
    for (i = 0; i < 8; i++) b[i] = (uint8_t)(v >> (8 * i));
    return fnv(h, b, 8);
}

static uint64_t rng(uint64_t *s) { /* splitmix64 */
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* A double in [lo, hi) with all 53 bits random. */
static double rnd(uint64_t *s, double lo, double hi) {
    return lo + (hi - lo) * ((double)(rng(s) >> 11) * (1.0 / 9007199254740992.0));
}

static uint8_t *read_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    uint8_t *p = NULL;
    long n;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        p = (uint8_t *)malloc((size_t)n + 1);
        if (p && fread(p, 1, (size_t)n, f) != (size_t)n) {
            free(p);
            p = NULL;
        }
        *size = (size_t)n;
    }
    fclose(f);
    return p;
}

static void print_info(const char *name, const voxdag *d) {
    voxdag_info in;
    uint32_t l;
    uint64_t h = FNV0;
    voxdag_get_info(d, &in);
    for (l = 0; l + 1 < in.levels; l++) h = fnv_u64(fnv_u64(h, in.nodes[l]), in.level_bytes[l]);
    printf("%s info: L %u symmetry %d voxels %llu box %u %u %u %u %u %u bytes %llu %llu %llu %llu colors %d "
           "levels %016llx\n",
           name, in.levels, (int)in.symmetry, (unsigned long long)in.voxels, in.voxel_box[0], in.voxel_box[1],
           in.voxel_box[2], in.voxel_box[3], in.voxel_box[4], in.voxel_box[5], (unsigned long long)in.file_bytes,
           (unsigned long long)in.node_bytes, (unsigned long long)in.brick_bytes, (unsigned long long)in.color_bytes,
           (int)in.color_kind, (unsigned long long)h);
}

static int walk_fn(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    uint64_t *h = (uint64_t *)user;
    *h = fnv_u64(fnv_u64(*h, (uint64_t)x << 42 | (uint64_t)y << 21 | z), index);
    return 0;
}

/* Every voxel of grids up to 64^3, else 30k random ones, and the walk. */
static void print_queries(const char *name, const voxdag *d) {
    voxdag_info in;
    uint64_t h = FNV0, w = FNV0, seed = 3, full = 0, count;
    uint32_t n, x, y, z;
    voxdag_get_info(d, &in);
    n = 1u << in.levels;
    if (in.levels <= 6) {
        for (z = 0; z < n; z++)
            for (y = 0; y < n; y++)
                for (x = 0; x < n; x++) {
                    uint64_t idx = ~0ull;
                    int f = voxdag_lookup(d, x, y, z, &idx);
                    full += (uint64_t)f;
                    h = fnv_u64(h, f ? idx : ~0ull);
                }
    } else {
        for (count = 0; count < 30000; count++) {
            uint64_t idx = ~0ull;
            int f;
            x = (uint32_t)(rng(&seed) % n), y = (uint32_t)(rng(&seed) % n), z = (uint32_t)(rng(&seed) % n);
            f = voxdag_lookup(d, x, y, z, &idx);
            full += (uint64_t)f;
            h = fnv_u64(h, f ? idx : ~0ull);
        }
    }
    count = voxdag_for_each_voxel(d, walk_fn, &w);
    printf("%s queries: %llu full, lookups %016llx, walk %llu %016llx\n", name, (unsigned long long)full,
           (unsigned long long)h, (unsigned long long)count, (unsigned long long)w);
}

#ifndef VOXDAG_NO_RAYTRACE
static void print_ray(const char *name, unsigned i, const voxdag *d, const voxdag_ray *r, const voxdag_ray_opts *o) {
    voxdag_hit hit;
    int got, occ = voxdag_occluded(d, r);
    memset(&hit, 0, sizeof hit);
    got = voxdag_raycast(d, r, o, &hit);
    if (got)
        printf("%s ray %u: hit t %a voxel %u %u %u normal %d %d %d level %u index %llu occluded %d\n", name, i, hit.t,
               hit.xyz[0], hit.xyz[1], hit.xyz[2], hit.normal[0], hit.normal[1], hit.normal[2], hit.level,
               (unsigned long long)hit.index, occ);
    else
        printf("%s ray %u: miss occluded %d\n", name, i, occ);
    {
        size_t size;
        voxdag_gpu_buf buf;
        voxdag_gpu_file f;
        voxdag_gpu_ray g;
        voxdag_gpu_hit h;
        uint32_t t;
        buf.bytes = (const unsigned char *)voxdag_image(d, &size), buf.size = size;
        f = voxdag_gpu_open(buf, 0);
        g.ox = (float)r->origin[0], g.oy = (float)r->origin[1], g.oz = (float)r->origin[2];
        g.dx = (float)r->dir[0], g.dy = (float)r->dir[1], g.dz = (float)r->dir[2];
        g.t_min = (float)r->t_min, g.t_max = (float)r->t_max;
        g.lod = o ? (float)(o->lod_factor * o->lod_pixels) : 0, g.flags = VOXDAG_GPU_WANT_INDEX;
        h = voxdag_gpu_raycast(buf, f, g);
        memcpy(&t, &h.t, 4);
        printf("%s gpu ray %u: hit %u t %08lx voxel %u %u %u normal %d %d %d level %u index %llu occluded %u\n", name,
               i, h.hit, (unsigned long)t, h.x, h.y, h.z, (int)h.nx, (int)h.ny, (int)h.nz, h.level,
               (unsigned long long)((uint64_t)h.index_hi << 32 | h.index_lo), voxdag_gpu_occluded(buf, f, g));
    }
}

/* COUNT random rays into DAG, then axis-aligned rays from integer and
   half-integer origins (faces, edges, corners), then extreme values. */
static void print_rays(const char *name, const voxdag *d, unsigned count, uint64_t seed) {
    voxdag_info in;
    voxdag_ray r;
    voxdag_ray_opts o;
    double n;
    unsigned i, a;
    voxdag_get_info(d, &in);
    n = (double)(1u << in.levels);
    for (i = 0; i < count; i++) {
        memset(&r, 0, sizeof r);
        memset(&o, 0, sizeof o);
        for (a = 0; a < 3; a++) {
            r.origin[a] = i % 3 ? rnd(&seed, -0.5 * n, 1.5 * n) : rnd(&seed, 0, n);
            r.dir[a] = rnd(&seed, -1, 1);
        }
        if (i % 7 == 0) r.dir[i / 7 % 3] = 0;
        if (i % 5 == 0) r.t_min = rnd(&seed, 0, n / 4);
        if (i % 11 == 0) r.t_max = rnd(&seed, 0, 2 * n);
        o.want_index = 1;
        if (i % 4 == 1) {
            o.lod_factor = rnd(&seed, 0.001, 0.05);
            o.lod_pixels = rnd(&seed, 0.5, 4);
        }
        print_ray(name, i, d, &r, &o);
    }
    for (i = 0; i < 64; i++) { /* through lattice points, along diagonals */
        memset(&r, 0, sizeof r);
        for (a = 0; a < 3; a++) {
            r.origin[a] = (double)(rng(&seed) % (uint64_t)(2 * n)) / 2 - (a == i % 3 ? 1 : 0);
            r.dir[a] = (double)((int)(rng(&seed) % 5) - 2);
        }
        print_ray(name, count + i, d, &r, NULL);
    }
    {
        /* subnormal and huge values: t near the underflow threshold, 1/dir
           subnormal or overflowing */
        static const double tiny[] = {4.9406564584124654e-324, 2.2250738585072014e-308, 1e-310, 3e-300};
        static const double huge[] = {1e300, 8.9884656743115795e307, 1.7976931348623157e308};
        for (i = 0; i < 48; i++) {
            memset(&r, 0, sizeof r);
            for (a = 0; a < 3; a++) {
                r.origin[a] = i & 1 ? tiny[(i / 2 + a) % 4] : rnd(&seed, 0, n);
                r.dir[a] = i & 2 ? huge[(i / 4 + a) % 3] * (a == 1 ? -1 : 1) : tiny[(i / 4 + a) % 4];
            }
            if (i & 4) r.dir[i % 3] = 1;
            print_ray(name, count + 64 + i, d, &r, NULL);
        }
    }
}
#endif

/* Scenes built here: a noisy shell with colours from its coordinates. */
static voxdag *build_voxels(uint32_t levels, uint32_t threads, int colors, uint64_t seed) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    uint32_t n = 1u << levels, *xyz = (uint32_t *)malloc(3 * sizeof(uint32_t) * 200000);
    uint8_t *rgb = (uint8_t *)malloc(3 * 200000);
    size_t k = 0;
    double c = n / 2.0 - 0.3, rad = n * 0.37;
    uint32_t x, y, z;
    for (z = 0; z < n && k < 200000; z++)
        for (y = 0; y < n && k < 200000; y++)
            for (x = 0; x < n && k < 200000; x++) {
                double dx = x + 0.5 - c, dy = y + 0.5 - c, dz = z + 0.5 - c, dd = dx * dx + dy * dy + dz * dz;
                if ((dd <= rad * rad && dd >= (rad - 2) * (rad - 2)) || rng(&seed) % 97 == 0) {
                    xyz[3 * k] = x, xyz[3 * k + 1] = y, xyz[3 * k + 2] = z;
                    rgb[3 * k] = (uint8_t)(x * 4), rgb[3 * k + 1] = (uint8_t)(y * 4 + (rng(&seed) & 3));
                    rgb[3 * k + 2] = (uint8_t)(z * 4);
                    k++;
                }
            }
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.colors = colors;
    o.threads = threads;
    o.compare_structures = 1;
    if (voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK && voxdag_builder_add(b, xyz, rgb, k, NULL) == VOXDAG_OK)
        voxdag_builder_finish(b, &d, NULL, NULL);
    else
        voxdag_builder_free(b);
    free(xyz);
    free(rgb);
    return d;
}

/* From the triangle only: the barycentric coordinates are floating-point
   values handed to the host, which may differ in their last bits under x87
   maths (the voxels they colour do not). */
static void mesh_color(void *user, size_t tri, const double bary[3], uint8_t rgb[3]) {
    (void)user;
    (void)bary;
    rgb[0] = (uint8_t)(tri * 53);
    rgb[1] = (uint8_t)(tri * 7 + 1);
    rgb[2] = (uint8_t)(tri >> 3);
}

static voxdag *build_mesh(uint32_t levels, uint32_t threads) {
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_mesh m;
    double pos[3 * 90];
    uint32_t idx[3 * 30], i;
    uint64_t seed = 21;
    double n = (double)(1u << levels);
    for (i = 0; i < 3 * 90; i++) pos[i] = rnd(&seed, -0.1 * n, 1.1 * n); /* full-precision vertices */
    for (i = 0; i < 3 * 30; i++) idx[i] = i;
    memset(&m, 0, sizeof m);
    m.positions = pos, m.vertex_count = 90, m.indices = idx, m.triangle_count = 30, m.color = mesh_color;
    memset(&o, 0, sizeof o);
    o.levels = levels;
    o.colors = 1;
    o.threads = threads;
    o.chunk_levels = 3;
    if (voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK && voxdag_builder_add_mesh(b, &m, NULL) == VOXDAG_OK)
        voxdag_builder_finish(b, &d, NULL, NULL);
    else
        voxdag_builder_free(b);
    return d;
}

static void print_image(const char *name, const voxdag *d) {
    size_t size = 0;
    const void *img = d ? voxdag_image(d, &size) : NULL;
    printf("%s file: %lu bytes %016llx\n", name, (unsigned long)size,
           (unsigned long long)(img ? fnv(FNV0, img, size) : 0));
}

/* The colours of D voxcolor-encoded (error E, page shift SHIFT, THREADS),
   the stream and its decode; a DAG with the stream as its colour section. */
static voxdag *print_voxcolor(const char *name, const voxdag *d, double e, uint32_t shift, uint32_t threads,
                              voxcolor_metric metric) {
    const void *payload;
    size_t size, cap, got;
    voxcolor_encode_opts o;
    uint8_t *dst, *back;
    voxcolor_view v;
    voxdag *out = NULL;
    uint64_t count;
    if (voxdag_colors(d, &payload, &size) != VOXDAG_COLORS_RGB8) {
        printf("%s voxcolor: no RGB8 colours\n", name);
        return NULL;
    }
    count = size / 3;
    cap = voxcolor_encode_bound((size_t)count);
    dst = (uint8_t *)malloc(cap);
    back = (uint8_t *)malloc(size + 1);
    memset(&o, 0, sizeof o);
    o.max_error = e;
    o.page_shift = shift;
    o.threads = threads;
    o.metric = metric;
    got = voxcolor_encode(dst, cap, (const uint8_t *)payload, (size_t)count, &o, NULL);
    if (got && voxcolor_view_init(&v, dst, got, NULL) == VOXCOLOR_OK) {
        voxcolor_view_get_range(&v, 0, (size_t)count, back);
        printf("%s voxcolor e %g shift %u metric %d: %lu bytes %016llx, decoded %016llx\n", name, e, shift,
               (int)metric, (unsigned long)got, (unsigned long long)fnv(FNV0, dst, got),
               (unsigned long long)fnv(FNV0, back, size));
        voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, dst, got, &out, NULL);
    } else {
        printf("%s voxcolor e %g shift %u: failed\n", name, e, shift);
    }
    free(dst);
    free(back);
    return out;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "tests/data";
    char path[512];
    size_t i;
    uint32_t threads;
    for (i = 0; i < sizeof goldens / sizeof goldens[0]; i++) {
        size_t size = 0;
        uint8_t *bytes;
        voxdag *d = NULL;
        voxdag_status st;
        snprintf(path, sizeof path, "%s/golden/%s.vdag", dir, goldens[i]);
        bytes = read_file(path, &size);
        if (!bytes) {
            printf("%s: cannot read %s\n", goldens[i], path);
            continue;
        }
        st = voxdag_load_memory(bytes, size, NULL, &d, NULL);
        printf("%s load: %s\n", goldens[i], voxdag_status_string(st));
        if (d) {
            print_info(goldens[i], d);
            print_queries(goldens[i], d);
#ifndef VOXDAG_NO_RAYTRACE
            print_rays(goldens[i], d, 300, 7 + i);
#endif
        }
        voxdag_free(d);
        free(bytes);
    }
    for (threads = 1; threads <= 3; threads += 2) {
        voxdag *v = build_voxels(7, threads, 1, 9), *m = build_mesh(6, threads), *g = build_voxels(6, threads, 0, 4);
        char name[64];
        snprintf(name, sizeof name, "shell-L7-t%u", threads);
        print_image(name, v);
        snprintf(name, sizeof name, "mesh-L6-t%u", threads);
        print_image(name, m);
        snprintf(name, sizeof name, "noise-L6-t%u", threads);
        print_image(name, g);
        if (threads == 1 && v && m && g) {
            voxdag *c = print_voxcolor("shell-L7", v, 0.03, 0, 3, VOXCOLOR_METRIC_RGB);
            voxdag *c2 = print_voxcolor("mesh-L6", m, 0, 6, 2, VOXCOLOR_METRIC_RGB);
            voxdag *c3 = print_voxcolor("shell-L7", v, 0.1, 10, 1, VOXCOLOR_METRIC_RGB);
            voxdag *c4 = print_voxcolor("mesh-L6", m, 2.0, 8, 1, VOXCOLOR_METRIC_CIELAB);
            print_image("shell-L7 with voxcolor", c);
            print_image("mesh-L6 with voxcolor", c2);
            print_queries("shell-L7", v);
            print_queries("mesh-L6", m);
#ifndef VOXDAG_NO_RAYTRACE
            print_rays("shell-L7", v, 4000, 100);
            print_rays("mesh-L6", m, 4000, 200);
            print_rays("noise-L6", g, 2000, 300);
#endif
            voxdag_free(c);
            voxdag_free(c2);
            voxdag_free(c3);
            voxdag_free(c4);
        }
        voxdag_free(v);
        voxdag_free(m);
        voxdag_free(g);
    }
    return 0;
}
