/* voxdag.h's option and argument checks in a release build: compiled with
   -DNDEBUG (asserts gone) under AddressSanitizer and UndefinedBehaviorSanitizer
   (make test). The fields of every options struct (build, load, ray) are
   swept over valid and invalid values; what is valid is decided here from
   the documentation of the structs, not by the library. Valid options must
   work; invalid ones must fail with VOXDAG_ERR_INVALID_ARGUMENT (levels:
   VOXDAG_ERR_LIMIT) and a message, or -1 from the ray calls, allocating and
   writing nothing. Every entry point is also called with NULL pointers.
   Prints "N passed, N failed". */
#ifndef NDEBUG
#error "tests/test_voxdag_ndebug.c is built with -DNDEBUG"
#endif
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tally.h"

static long allocs;
static void *counting_alloc(void *user, size_t size) {
    (void)user;
    allocs++;
    return malloc(size);
}
static void counting_free(void *user, void *p, size_t size) {
    (void)user, (void)size;
    free(p);
}
static int sink(void *user, const uint8_t *rgb, size_t n) {
    (void)user, (void)rgb, (void)n;
    return 0;
}

/* The documented ranges of voxdag_build_opts (levels separately: LIMIT). */
static int build_valid(const voxdag_build_opts *o) {
    int k, bounds_ok = 1;
    if (o->bounds)
        for (k = 0; k < 3; k++)
            bounds_ok &= o->bounds[k] < o->bounds[k + 3] && isfinite(o->bounds[k]) && isfinite(o->bounds[k + 3]) &&
                         o->bounds[k + 3] - o->bounds[k] <= 1e300;
    return o->zero_begin == 0 && o->zero_end == 0 && (uint32_t)o->symmetry <= VOXDAG_SYMMETRY_FULL &&
           (o->chunk_levels == 0 || (o->chunk_levels >= 2 && o->chunk_levels <= 8)) &&
           !(o->color_sink && !o->colors) && (o->allocator.alloc == NULL) == (o->allocator.free == NULL) &&
           bounds_ok;
}

static voxdag *small_scene(void) {
    static const uint32_t xyz[] = {1, 2, 3, 4, 5, 6, 7, 7, 7, 0, 0, 0};
    static const uint8_t rgb[] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 9, 9, 9};
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    memset(&o, 0, sizeof o);
    o.levels = 3;
    o.colors = 1;
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK || voxdag_builder_add(b, xyz, rgb, 4, NULL) != VOXDAG_OK ||
        voxdag_builder_finish(b, &d, NULL, NULL) != VOXDAG_OK)
        return NULL;
    return d;
}

static void sweep_build(void) {
    static const uint32_t levels[] = {0, 1, 2, 10, 21, 22, 0xffffffffu};
    static const int32_t symmetries[] = {0, 1, 3, 4, -1, 0x7fffffff};
    static const uint32_t chunks[] = {0, 1, 2, 8, 9, 0xffffffffu};
    static const uint32_t guards[] = {0, 1, 0xa5a5a5a5u};
    static const double good_bounds[6] = {0, 0, 0, 1, 2, 3}, bad_bounds[4][6] = {
        {0, 0, 0, 0, 1, 1}, {1, 0, 0, 0, 1, 1}, {0, 0, 0, 1, 1, INFINITY}, {0, 0, 0, 1, NAN, 1}};
    unsigned long long count = 0;
    size_t l, s, c, g, x;
    for (l = 0; l < sizeof levels / sizeof levels[0]; l++)
        for (s = 0; s < sizeof symmetries / sizeof symmetries[0]; s++)
            for (c = 0; c < sizeof chunks / sizeof chunks[0]; c++)
                for (g = 0; g < 5; g++)
                    for (x = 0; x < 9; x++, count++) {
                        voxdag_build_opts o;
                        voxdag_builder *b = (voxdag_builder *)&o; /* must become NULL on failure */
                        voxdag_error err;
                        voxdag_status st;
                        int valid, lim;
                        /* sparse: every value of each field meets the others' valid ones */
                        if ((l && s && c) || (g && (s || c)) || (x && (s || c || g))) continue;
                        memset(&o, 0, sizeof o);
                        o.levels = levels[l];
                        o.symmetry = (voxdag_symmetry)symmetries[s];
                        o.chunk_levels = chunks[c];
                        o.zero_begin = g == 1 || g == 2 ? guards[g] : 0;
                        o.zero_end = g >= 3 ? guards[g - 2] : 0;
                        o.allocator.alloc = counting_alloc;
                        o.allocator.free = counting_free;
                        if (x == 1) o.allocator.free = NULL;
                        if (x == 2) o.allocator.alloc = NULL;
                        if (x == 3) o.color_sink = sink; /* without colors */
                        if (x == 4) o.bounds = good_bounds;
                        if (x >= 5) o.bounds = bad_bounds[x - 5];
                        o.threads = (uint32_t)(count % 3) * 40; /* 0, 40, 80: clamped, not an error */
                        valid = build_valid(&o);
                        lim = o.levels != 0 && (o.levels < 2 || o.levels > 21);
                        allocs = 0;
                        memset(&err, 0, sizeof err);
                        st = voxdag_builder_create(&o, &b, &err);
                        if (valid && !lim) {
                            check(st == VOXDAG_OK && b && err.status == VOXDAG_OK, "valid build options accepted", count);
                            voxdag_builder_free(st == VOXDAG_OK ? b : NULL);
                        } else {
                            check(st != VOXDAG_OK && b == NULL && err.status == st && err.message && allocs == 0 &&
                                      (valid ? st == VOXDAG_ERR_LIMIT
                                             : st == VOXDAG_ERR_INVALID_ARGUMENT || st == VOXDAG_ERR_LIMIT),
                                  "invalid build options rejected, nothing allocated", count);
                        }
                    }
}

static void sweep_load(const voxdag *d) {
    static const uint32_t guards[] = {0, 1, 0xffffffffu};
    size_t size, g, x;
    const void *img = voxdag_image(d, &size);
    unsigned long long count = 0;
    for (g = 0; g < 5; g++)
        for (x = 0; x < 6; x++, count++) {
            voxdag_load_opts o;
            voxdag *out = (voxdag *)&o;
            voxdag_error err;
            voxdag_status st;
            int valid;
            memset(&o, 0, sizeof o);
            o.zero_begin = g == 1 || g == 2 ? guards[g] : 0;
            o.zero_end = g >= 3 ? guards[g - 2] : 0;
            o.allocator.alloc = counting_alloc;
            o.allocator.free = counting_free;
            if (x == 1) o.allocator.free = NULL;
            if (x == 2) o.allocator.alloc = NULL;
            o.skip_checksums = x == 3;
            o.copy = x == 4;
            o.max_levels = x == 5 ? 99 : 0; /* more than supported: the supported maximum */
            valid = g == 0 && x != 1 && x != 2;
            allocs = 0;
            st = voxdag_load_memory(img, size, &o, &out, &err);
            if (valid) {
                check(st == VOXDAG_OK && out, "valid load options accepted", count);
                voxdag_free(st == VOXDAG_OK ? out : NULL);
            } else {
                check(st == VOXDAG_ERR_INVALID_ARGUMENT && out == NULL && err.message && allocs == 0,
                      "invalid load options rejected", count);
            }
        }
}

static void sweep_ray(const voxdag *d) {
    static const double lods[] = {0, 0.5, 1e300, -0.0, -1e-300, -1, NAN, INFINITY, -INFINITY};
    static const uint32_t guards[] = {0, 1, 0x80000000u};
    size_t f, p, g;
    unsigned long long count = 0;
    voxdag_ray ray;
    memset(&ray, 0, sizeof ray);
    ray.origin[0] = 1.5, ray.origin[1] = 2.5, ray.origin[2] = -1;
    ray.dir[2] = 1;
    for (f = 0; f < sizeof lods / sizeof lods[0]; f++)
        for (p = 0; p < sizeof lods / sizeof lods[0]; p++)
            for (g = 0; g < 5; g++, count++) {
                voxdag_ray_opts o;
                voxdag_hit hit, before;
                int r, valid;
                memset(&o, 0, sizeof o);
                o.lod_factor = lods[f];
                o.lod_pixels = lods[p];
                o.want_index = (int)(count % 2);
                o.zero_begin = g == 1 || g == 2 ? guards[g] : 0;
                o.zero_end = g >= 3 ? guards[g - 2] : 0;
                valid = g == 0 && isfinite(lods[f]) && lods[f] >= 0 && isfinite(lods[p]) && lods[p] >= 0;
                memset(&hit, 0x5a, sizeof hit);
                before = hit;
                r = voxdag_raycast(d, &ray, &o, &hit);
                if (valid)
                    check(r == 1 && hit.level <= 3 && hit.xyz[0] <= 1 && 1 < hit.xyz[0] + (8u >> hit.level) &&
                              hit.xyz[1] <= 2 && 2 < hit.xyz[1] + (8u >> hit.level),
                          "valid ray options trace (a cell holding the voxel hit)", count);
                else
                    check(r == -1 && !memcmp(&hit, &before, sizeof hit), "invalid ray options rejected", count);
            }
}

static void nulls(voxdag *d) {
    voxdag_ray ray;
    voxdag_hit hit;
    voxdag_info info;
    voxdag_error err;
    voxdag_builder *b = NULL;
    voxdag *out = NULL;
    uint8_t c[3];
    uint64_t idx;
    double p[3] = {1, 2, 3};
    uint32_t xyz[3] = {1, 1, 1};
    uint64_t bricks[2] = {0, 1};
    const void *payload;
    size_t size;
    memset(&ray, 0, sizeof ray);
    ray.dir[0] = 1;
    check(voxdag_raycast(NULL, &ray, NULL, &hit) == -1, "raycast NULL dag", 0);
    check(voxdag_raycast(d, NULL, NULL, &hit) == -1, "raycast NULL ray", 0);
    check(voxdag_raycast(d, &ray, NULL, NULL) == -1, "raycast NULL hit", 0);
    check(voxdag_occluded(NULL, &ray) == -1, "occluded NULL dag", 0);
    check(voxdag_occluded(d, NULL) == -1, "occluded NULL ray", 0);
    check(voxdag_world_ray(NULL, &ray, &ray) == VOXDAG_ERR_INVALID_ARGUMENT, "world ray NULL dag", 0);
    check(voxdag_world_ray(d, &ray, NULL) == VOXDAG_ERR_INVALID_ARGUMENT, "world ray NULL out", 0);
    check(voxdag_world_to_grid(NULL, p, p) == VOXDAG_ERR_INVALID_ARGUMENT, "world_to_grid NULL", 0);
    check(voxdag_grid_to_world(d, NULL, p) == VOXDAG_ERR_INVALID_ARGUMENT, "grid_to_world NULL", 0);
    check(voxdag_lookup(NULL, 1, 2, 3, &idx) == 0, "lookup NULL", 0);
    check(voxdag_color(NULL, 0, c) == 0 && voxdag_color(d, 0, NULL) == 0, "color NULL", 0);
    check(voxdag_colors(NULL, &payload, &size) == VOXDAG_COLORS_NONE && !payload && !size, "colors NULL", 0);
    check(voxdag_for_each_voxel(NULL, NULL, NULL) == 0, "for_each_voxel NULL", 0);
    check(voxdag_image(NULL, &size) == NULL && size == 0, "image NULL", 0);
    memset(&info, 0x5a, sizeof info);
    voxdag_get_info(NULL, &info);
    voxdag_get_info(d, NULL);
    check(info.levels == 0 && info.voxels == 0 && info.file_bytes == 0, "get_info NULL zeroes the info", 0);
    voxdag_morton_decode(123, NULL, NULL, NULL);
    check(voxdag_builder_create(NULL, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "builder_create NULL out", 0);
    check(voxdag_builder_add(NULL, xyz, NULL, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "builder_add NULL", 0);
    check(voxdag_builder_add_bricks(NULL, bricks, NULL, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "add_bricks NULL", 0);
    check(voxdag_builder_add_mesh(NULL, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "add_mesh NULL", 0);
    check(voxdag_mesh_open_edges(NULL, NULL, NULL, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "open_edges NULL", 0);
    check(voxdag_builder_flush(NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "flush NULL", 0);
    check(voxdag_builder_finish(NULL, &out, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "finish NULL", 0);
    check(voxdag_builder_create(NULL, &b, NULL) == VOXDAG_OK, "builder", 0);
    check(voxdag_builder_add_bricks(b, NULL, NULL, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "add_bricks NULL bricks", 0);
    check(voxdag_builder_add(b, NULL, NULL, 1, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "add NULL xyz", 0);
    check(voxdag_builder_finish(b, NULL, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "finish NULL out", 0);
    voxdag_builder_free(NULL);
    check(voxdag_load_memory(NULL, 10, NULL, &out, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "load NULL data", 0);
    check(voxdag_load_memory(p, 10, NULL, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "load NULL out", 0);
    check(voxdag_with_colors(NULL, VOXDAG_COLORS_NONE, NULL, 0, &out, &err) == VOXDAG_ERR_INVALID_ARGUMENT,
          "with_colors NULL", 0);
    check(voxdag_with_colors(d, (voxdag_color_kind)7, NULL, 0, &out, &err) == VOXDAG_ERR_INVALID_ARGUMENT,
          "with_colors bad kind", 0);
    {
        voxdag_build_opts wo;
        memset(&wo, 0, sizeof wo);
        wo.zero_end = 1;
        check(voxdag_with_colors_opts(d, VOXDAG_COLORS_NONE, NULL, 0, &wo, &out, &err) == VOXDAG_ERR_INVALID_ARGUMENT,
              "with_colors_opts not zero-initialized", 0);
    }
    check(voxdag_cell_color(NULL, &hit, c) == 0 && voxdag_cell_color(d, NULL, c) == 0 &&
              voxdag_cell_color(d, &hit, NULL) == 0,
          "cell_color NULL", 0);
    check(voxdag_load_file(NULL, NULL, &out, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "load_file NULL", 0);
    check(voxdag_save_file(NULL, "x.vdag", &err) == VOXDAG_ERR_INVALID_ARGUMENT, "save NULL dag", 0);
    check(voxdag_save_file(d, NULL, &err) == VOXDAG_ERR_INVALID_ARGUMENT, "save NULL path", 0);
    voxdag_free(NULL);
}

int main(void) {
    voxdag *d = small_scene();
    check(d != NULL, "the scene builds", 0);
    if (!d) {
        printf("%d passed, %d failed\n", passed, failed);
        return 1;
    }
    sweep_build();
    sweep_load(d);
    sweep_ray(d);
    nulls(d);
    voxdag_free(d);
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
