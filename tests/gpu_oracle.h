/* What the GPU traversal's answers are checked with (tests/test_gpu.c, the
   C build; tests/test_gpu_vk.c, the shaders): rays as the GPU takes them,
   the library's exact answer, and the near-tie rule. */
#ifndef VOXDAG_TEST_GPU_ORACLE_H
#define VOXDAG_TEST_GPU_ORACLE_H

#include <math.h>
#include <string.h>

#include "rscene.h"
#include "voxcolor.h"
#include "voxdag.h"
#include "voxdag_gpu.h"

static inline voxdag_gpu_ray gpu_ray(const voxdag_ray *ray, double lod, int want_index) {
    voxdag_gpu_ray g;
    g.ox = (float)ray->origin[0], g.oy = (float)ray->origin[1], g.oz = (float)ray->origin[2];
    g.dx = (float)ray->dir[0], g.dy = (float)ray->dir[1], g.dz = (float)ray->dir[2];
    g.t_min = (float)ray->t_min, g.t_max = (float)ray->t_max, g.lod = (float)lod;
    g.flags = want_index ? VOXDAG_GPU_WANT_INDEX : 0u;
    return g;
}

/* Whether the exact answer to RAY is G's (voxel, level, normal, index);
   EXCLUSIVE: with t_max_exclusive. */
static inline int same_answer_opts(const voxdag *d, const voxdag_ray *ray, double lod, int exclusive,
                                   const voxdag_gpu_hit *g) {
    voxdag_ray_opts o;
    voxdag_hit h;
    int r;
    memset(&o, 0, sizeof o);
    o.want_index = 1, o.lod_factor = lod, o.lod_pixels = lod > 0 ? 1 : 0, o.t_max_exclusive = exclusive;
    r = voxdag_raycast(d, ray, &o, &h);
    if (r != (int)g->hit) return 0;
    return !r || (h.xyz[0] == g->x && h.xyz[1] == g->y && h.xyz[2] == g->z && h.level == g->level &&
                  h.normal[0] == g->nx && h.normal[1] == g->ny && h.normal[2] == g->nz &&
                  h.index == ((uint64_t)g->index_hi << 32 | g->index_lo));
}

static inline int same_answer(const voxdag *d, const voxdag_ray *ray, double lod, const voxdag_gpu_hit *g) {
    return same_answer_opts(d, ray, lod, 0, g);
}

/* A near-tie: the exact answer of RAY moved by EPS grid units along an axis,
   or with a limit moved by EPS, is G's. */
static inline int near_tie_opts(const voxdag *d, const voxdag_ray *ray, double lod, int exclusive,
                                const voxdag_gpu_hit *g, double eps) {
    double m = fmax(fabs(ray->dir[0]), fmax(fabs(ray->dir[1]), fabs(ray->dir[2])));
    int a, s;
    for (a = 0; a < 5; a++)
        for (s = -1; s <= 1; s += 2) {
            voxdag_ray p = *ray;
            if (a < 3) p.origin[a] += s * eps;
            else if (a == 3) p.t_min += s * eps / m;
            else if (p.t_max != HUGE_VAL) p.t_max += s * eps / m;
            if (same_answer_opts(d, &p, lod, exclusive, g)) return 1;
        }
    return 0;
}

static inline int near_tie(const voxdag *d, const voxdag_ray *ray, double lod, const voxdag_gpu_hit *g, double eps) {
    return near_tie_opts(d, ray, lod, 0, g, eps);
}

/* A ray from make_ray with every component rounded to float (the GPU's input). */
static inline voxdag_ray float_ray(uint64_t *r, uint32_t n) {
    voxdag_ray ray = make_ray(r, n);
    int a;
    for (a = 0; a < 3; a++) ray.origin[a] = (float)ray.origin[a], ray.dir[a] = (float)ray.dir[a];
    ray.t_min = (float)ray.t_min;
    if (ray.t_max != HUGE_VAL) ray.t_max = (float)ray.t_max;
    return ray;
}

/* EPS of near_tie for a ray from ORIGIN in a grid of 2^LEVELS: 2^-20 of
   the grid's size plus the origin's distance (a few float32 roundings). */
static inline double near_tie_eps(uint32_t levels, const double origin[3]) {
    return ldexp((double)(1u << levels) + fabs(origin[0]) + fabs(origin[1]) + fabs(origin[2]), -20);
}

/* D with a voxcolor section of its colours (max error E, page shift S). */
static inline voxdag *with_voxcolor(const voxdag *d, double e, unsigned s) {
    voxdag_info info;
    voxcolor_encode_opts eo;
    voxdag *v = NULL;
    uint8_t *rgb, *stream;
    size_t cap, len, i;
    voxdag_get_info(d, &info);
    rgb = (uint8_t *)malloc(3 * (size_t)info.voxels + 3);
    for (i = 0; i < info.voxels; i++) voxdag_color(d, i, rgb + 3 * i);
    cap = voxcolor_encode_bound((size_t)info.voxels);
    stream = (uint8_t *)malloc(cap);
    memset(&eo, 0, sizeof eo);
    eo.max_error = e, eo.page_shift = s;
    len = voxcolor_encode(stream, cap, rgb, (size_t)info.voxels, &eo, NULL);
    CHECK(len > 0);
    CHECK(voxdag_with_colors(d, VOXDAG_COLORS_VOXCOLOR, stream, len, &v, NULL) == VOXDAG_OK);
    free(rgb);
    free(stream);
    return v;
}

/* D's colours again, without the level-of-detail colour section. */
static inline voxdag *without_lod_colors(const voxdag *d) {
    voxdag_build_opts o;
    const void *payload;
    size_t size;
    voxdag_color_kind kind = voxdag_colors(d, &payload, &size);
    voxdag *out = NULL;
    memset(&o, 0, sizeof o);
    o.no_lod_colors = 1;
    CHECK(voxdag_with_colors_opts(d, kind, payload, size, &o, &out, NULL) == VOXDAG_OK);
    return out;
}

#endif
