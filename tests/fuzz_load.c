/* Fuzz target for loading .vdag files (voxdag_load_memory) and querying what
   loaded. The first input byte selects the options, the rest is the file:
     bit 0     copy the bytes (opts.copy)
     bit 1     reseal: recompute every checksum before loading, so that the
               fuzzer reaches the structural validation behind them
     bits 2-3  a limit: 0 none, 1 max_nodes, 2 max_memory, 3 max_levels
     bit 4     the allocator fails at allocation 3 * P
     bits 5-7  P, the parameter of the limit and of the failing allocator
   Every load uses a counting allocator: after voxdag_free no byte may be held,
   and a load under max_memory never holds more. A loaded DAG must answer
   queries consistently: voxdag_for_each_voxel (stopped early) visits voxels
   in strictly increasing Morton order whose voxdag_lookup gives the same
   index; lookups at coordinates taken from the input stay within the voxel
   count; colours of either kind decode for every visited index and the last
   one; a ray aimed at a visited voxel from outside the grid hits it or a
   voxel before it, and every hit (of those rays and of rays taken from the
   input) is a full voxel with lookup's index, and voxdag_occluded agrees.
   Any violation aborts.

   Built with -DFUZZ_LIBFUZZER and -fsanitize=fuzzer this is a libFuzzer
   target (make fuzz-load). Otherwise main() replays the files and folders
   given on the command line (make test replays tests/data/fuzz/load) and
   prints "N passed, N failed". */
#define VOXCOLOR_IMPLEMENTATION /* voxdag_color then decodes voxcolor sections */
#include "voxcolor.h"
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "golden.h"
#include "count_alloc.h"
#include "fuzz_require.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FUZZ_MAX_VISIT 512 /* voxels walked by voxdag_for_each_voxel */
#define FUZZ_MAX_AIMED 64  /* of those, voxels that rays are aimed at */

/* Allocation failure sweeps of the replay main (fuzz_replay.h). */
#define FUZZ_ALLOC_SWEEP
static long fuzz_fail_at = -1, fuzz_alloc_calls;

// -- Queries on a loaded DAG

typedef struct walk {
    const voxdag *dag;
    uint32_t levels;
    uint64_t visited, last_morton;
    int color;
    const uint8_t *file; /* the input, for ray directions */
    size_t size;
} walk;

/* Checks HIT, a hit of RAY (R = voxdag_raycast's result): a full voxel whose
   index is lookup's, inside the grid, and occluded agrees. */
static void check_hit(const voxdag *d, uint32_t levels, const voxdag_ray *ray, int r, const voxdag_hit *hit) {
    uint64_t index = UINT64_MAX;
    require(r == 0 || r == 1, "raycast failed");
    require(voxdag_occluded(d, ray) == r, "occluded and raycast disagree");
    if (!r) return;
    require(hit->level == levels && ((hit->xyz[0] | hit->xyz[1] | hit->xyz[2]) >> levels) == 0, "hit outside");
    require(voxdag_lookup(d, hit->xyz[0], hit->xyz[1], hit->xyz[2], &index) == 1, "a ray hit an empty voxel");
    require(index == hit->index, "ray and lookup disagree on an index");
}

/* A ray from outside the grid at voxel (X, Y, Z)'s centre, its direction
   from the input (never zero): it must stop at that voxel or before. */
static void aim(walk *w, uint32_t x, uint32_t y, uint32_t z) {
    voxdag_ray ray;
    voxdag_ray_opts o;
    voxdag_hit hit;
    double side = (double)(1u << w->levels), far = 0, target[3];
    unsigned k;
    int r;
    memset(&ray, 0, sizeof ray);
    memset(&o, 0, sizeof o);
    o.want_index = 1;
    target[0] = x + 0.5, target[1] = y + 0.5, target[2] = z + 0.5;
    for (k = 0; k < 3; k++) {
        uint8_t b = w->file[(w->visited * 3 + k) % w->size];
        ray.dir[k] = (double)(int)(b % 7) - 3;
    }
    if (ray.dir[0] == 0 && ray.dir[1] == 0 && ray.dir[2] == 0) ray.dir[w->visited % 3] = 1;
    for (k = 0; k < 3; k++) far += ray.dir[k] * ray.dir[k];
    far = 2 * side / far; /* the origin lies 2 grid sides back along the ray */
    for (k = 0; k < 3; k++) ray.origin[k] = target[k] - far * ray.dir[k];
    r = voxdag_raycast(w->dag, &ray, &o, &hit);
    require(r == 1, "a ray aimed at a voxel missed");
    require(hit.t <= far + 1e-9 * far, "a ray passed the voxel it was aimed at");
    check_hit(w->dag, w->levels, &ray, r, &hit);
}

static int visit(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    walk *w = (walk *)user;
    uint64_t morton = voxdag_morton_encode(x, y, z), found = UINT64_MAX;
    uint8_t rgb[3];
    require(index == w->visited, "voxel indices not consecutive");
    require(((x | y | z) >> w->levels) == 0, "voxel outside the grid");
    require(w->visited == 0 || morton > w->last_morton, "voxels not in Morton order");
    require(voxdag_lookup(w->dag, x, y, z, &found) == 1, "a visited voxel is empty to lookup");
    require(found == index, "lookup and for_each_voxel disagree on an index");
    if (w->color) require(voxdag_color(w->dag, index, rgb) == 1, "no colour for a visited voxel");
    { /* the mean colour of a cell holding the voxel, at a level from the input */
        voxdag_hit cell;
        uint32_t q = w->file[w->visited % w->size] % (w->levels + 1), sh = w->levels - q;
        memset(&cell, 0, sizeof cell);
        cell.xyz[0] = x >> sh << sh, cell.xyz[1] = y >> sh << sh, cell.xyz[2] = z >> sh << sh, cell.level = q;
        require(voxdag_cell_color(w->dag, &cell, rgb) == (w->color ? 1 : 0), "a cell's colour");
    }
    if (w->visited < FUZZ_MAX_AIMED) aim(w, x, y, z);
    w->last_morton = morton;
    w->visited++;
    return w->visited >= FUZZ_MAX_VISIT;
}

static void query(const voxdag *d, const uint8_t *file, size_t size) {
    voxdag_info info;
    walk w;
    uint64_t n, index;
    uint8_t rgb[3];
    size_t i, image_size;
    const void *payload;
    size_t payload_size;
    voxdag_color_kind kind;
    voxdag_get_info(d, &info);
    require(info.levels >= 2 && info.levels <= VOXDAG_MAX_LEVELS, "levels out of range");
    require(info.file_bytes == size, "file size differs from the input");
    require(voxdag_image(d, &image_size) != NULL && image_size == size, "image size");
    kind = voxdag_colors(d, &payload, &payload_size);
    require(kind == info.color_kind && payload_size == info.color_bytes, "colour section");
    require(kind != VOXDAG_COLORS_RGB8 || payload_size == 3 * info.voxels, "RGB8 size");
    /* Lookups at coordinates taken from the input (its last bytes). */
    for (i = 0; i < 4; i++) {
        uint32_t c[3], k, mask = (1u << info.levels) - 1;
        for (k = 0; k < 3; k++) {
            size_t at = size - 1 - ((3 * i + k) % size);
            c[k] = ((uint32_t)file[at] * 0x9E3779B1u >> 8) & mask;
        }
        if (voxdag_lookup(d, c[0], c[1], c[2], &index)) {
            require(index < info.voxels, "lookup index past the voxel count");
            require(voxdag_lookup(d, c[0], c[1], c[2], NULL) == 1, "lookup without index differs");
            if (kind != VOXDAG_COLORS_NONE) require(voxdag_color(d, index, rgb) == 1, "no colour");
        }
        require(voxdag_lookup(d, c[0] | (mask + 1), c[1], c[2], NULL) == 0, "voxel outside the grid");
    }
    require(voxdag_color(d, info.voxels, rgb) == 0, "colour past the last voxel");
    if (info.voxels && kind != VOXDAG_COLORS_NONE)
        require(voxdag_color(d, info.voxels - 1, rgb) == 1, "no colour for the last voxel");
    /* Rays from the input's first bytes: origins in and around the grid. */
    for (i = 0; i < 8 && size >= 6; i++) {
        voxdag_ray ray;
        voxdag_ray_opts o;
        voxdag_hit hit;
        double side = (double)(1u << info.levels);
        unsigned k;
        memset(&ray, 0, sizeof ray);
        memset(&o, 0, sizeof o);
        o.want_index = 1;
        for (k = 0; k < 3; k++) {
            ray.origin[k] = (file[(6 * i + k) % size] / 255.0) * 1.5 * side - 0.25 * side;
            ray.dir[k] = (double)file[(6 * i + 3 + k) % size] - 127.5;
        }
        check_hit(d, info.levels, &ray, voxdag_raycast(d, &ray, &o, &hit), &hit);
    }
    /* Walk the first voxels (all of them in small scenes). */
    memset(&w, 0, sizeof w);
    w.dag = d;
    w.levels = info.levels;
    w.color = kind != VOXDAG_COLORS_NONE;
    w.file = file;
    w.size = size;
    n = voxdag_for_each_voxel(d, visit, &w);
    require(n == w.visited, "for_each_voxel count");
    require(n == (info.voxels < FUZZ_MAX_VISIT ? info.voxels : FUZZ_MAX_VISIT), "voxel count differs from the walk");
}

/* Rewrites the colour section of a loaded DAG; the result must load. */
static void recolor(const voxdag *d, count_alloc *fa) {
    voxdag_info info;
    voxdag *e = NULL, *f = NULL;
    uint8_t *rgb;
    voxdag_status st;
    voxdag_get_info(d, &info);
    if (info.voxels > 4096) return;
    rgb = (uint8_t *)calloc(3 * (size_t)info.voxels + 1, 1);
    st = voxdag_with_colors(d, VOXDAG_COLORS_RGB8, rgb, 3 * (size_t)info.voxels, &e, NULL);
    require(st == VOXDAG_OK || (st == VOXDAG_ERR_OUT_OF_MEMORY && fa->fail_at >= 0), "with_colors failed");
    if (e) {
        size_t size;
        const void *img = voxdag_image(e, &size);
        require(voxdag_load_memory(img, size, NULL, &f, NULL) == VOXDAG_OK, "recoloured file rejected");
        voxdag_free(f);
        voxdag_free(e);
    }
    free(rgb);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    voxdag_load_opts o;
    count_alloc fa;
    voxdag *d = NULL;
    voxdag_error err;
    voxdag_status st;
    uint8_t *file;
    unsigned sel, p;
    if (size == 0) return 0;
    sel = data[0];
    p = sel >> 5;
    size--;
    /* An exact-size copy (the input itself stays read-only). */
    file = (uint8_t *)malloc(size ? size : 1);
    if (size) memcpy(file, data + 1, size);
    if (sel & 2) golden_reseal(file, size);
    memset(&o, 0, sizeof o);
    o.copy = sel & 1;
    o.allocator = ca_start(&fa, fuzz_fail_at >= 0 ? fuzz_fail_at : sel & 16 ? 3 * (long)p : -1);
    switch (sel >> 2 & 3) {
    case 1: o.max_nodes = 1 + p * p; break;
    case 2: o.max_memory = (uint64_t)256 << p; break;
    case 3: o.max_levels = 2 + p; break;
    default: break;
    }
    st = voxdag_load_memory(file, size, &o, &d, &err);
    require(st == err.status, "status and error disagree");
    require(err.message != NULL, "no error message");
    if (st == VOXDAG_OK) {
        require(d != NULL, "no DAG");
        require(!o.max_memory || fa.peak <= o.max_memory, "load held more than max_memory");
        query(d, file, size);
        recolor(d, &fa);
        if (o.max_levels) {
            voxdag_info info;
            voxdag_get_info(d, &info);
            require(info.levels <= o.max_levels, "levels above max_levels accepted");
        }
    } else {
        require(d == NULL, "a DAG returned with an error");
        require(st != VOXDAG_ERR_OUT_OF_MEMORY || fa.fail_at >= 0 || o.max_memory, "out of memory");
    }
    voxdag_free(d);
    fuzz_alloc_calls = fa.calls;
    require(fa.held == 0, "bytes held after voxdag_free");
    require(!fa.bad_free, "a free with a size other than the allocation's");
    free(file);
    return 0;
}

#ifndef FUZZ_LIBFUZZER
#include "fuzz_replay.h"
#endif
