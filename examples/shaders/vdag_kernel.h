/* The vdag tool's GPU kernel, one text for GLSL, HLSL and C on top of
   voxdag_gpu.h (include that first, with its target macro): rays, shadow
   rays, lookups and pictures over arrays of 32-bit words. The shaders
   (vdag_kernel.comp, vdag_kernel.hlsl) call vdag_kernel_run once per
   invocation; the tool's --gpu-emulate and the tests call the same function
   in C, so both compute the same bits.

   For vdag_kernel_run the includer defines VDAG_KERNEL_IN(io, i) (input
   word I), VDAG_KERNEL_OUT(io, i, v) (store V as output word I) and the
   type vdag_kernel_io they take (in C a pair of pointers, on GPUs a
   placeholder uint).

   Records, per item I (words; floats as their bits):
     VDAG_KERNEL_RAYS      in 10 at 10 I: ox oy oz dx dy dz t_min t_max lod flags
                           out 12 at 12 I: hit t x y z nx ny nz level index_lo index_hi rgb
     VDAG_KERNEL_OCCLUDED  in as RAYS; out 1: 1 when blocked
     VDAG_KERNEL_LOOKUPS   in 3: x y z; out 4: found index_lo index_hi rgb
     VDAG_KERNEL_RENDER    out 1 per pixel (row-major): 0x00BBGGRR; with BEAM_START,
                           in 1 per 8x8 block (row-major): BEAM's depth
     VDAG_KERNEL_BEAM      out 1 per 8x8 block of pixels: a depth before which none of
                           the block's rays meets a voxel (voxdag_gpu_frustum_depth)
     VDAG_KERNEL_CELLS     in 4: level x y z; out 5: count_lo count_hi first_lo first_hi
                           (voxdag_gpu_cell) rgb (voxdag_gpu_cell_color, as it returns)
   rgb is 0x00BBGGRR (a level-of-detail hit's: its cell's mean colour),
   white for a file without colours.

   The picture model is examples/render.c's with --lod-opaque in float32,
   level-of-detail cells included (their mean colour, their staircase's
   lighting from the occupancy gradient, the shadow ray started past it;
   each cell covers its whole pixel), with two differences: directions are f +
   sx r + sy u unnormalized (t is then the depth along the view axis), and
   level of detail compares a cell with the pixel size at that depth. */
#ifndef VDAG_KERNEL_H
#define VDAG_KERNEL_H

#define VDAG_KERNEL_RAYS 0u
#define VDAG_KERNEL_OCCLUDED 1u
#define VDAG_KERNEL_LOOKUPS 2u
#define VDAG_KERNEL_RENDER 3u
#define VDAG_KERNEL_BEAM 4u
#define VDAG_KERNEL_CELLS 5u
#define VDAG_KERNEL_SHADOWS 1u    /* vdag_kernel_params.flags */
#define VDAG_KERNEL_BEAM_START 2u /* RENDER: each ray starts at its block's BEAM depth (the input) */
#define VDAG_KERNEL_BACKGROUND 0x00EBDACDu /* (205, 218, 235) */

/* The push constants (28 words): what to do, on how many items (item =
   x + y * row in the dispatch's invocations, row = 64 * its groups in x),
   where the file starts in its buffer, and the camera (f a unit vector, r
   and u perpendicular to it and to each other) in grid units (r scaled by tan(fov / 2) W / H, u by tan(fov / 2),
   light normalized, inv_w = 1 / W and inv_h = 1 / H rounded once). */
struct vdag_kernel_params {
    voxdag_gpu_u32 mode, count, width, height, base, flags, row, reserved0;
    voxdag_gpu_f32 eye_x, eye_y, eye_z, lod, f_x, f_y, f_z, inv_w, r_x, r_y, r_z, inv_h;
    voxdag_gpu_f32 u_x, u_y, u_z, ambient, l_x, l_y, l_z, reserved2;
};
#ifdef VOXDAG_GPU_C
typedef struct vdag_kernel_params vdag_kernel_params;
#endif

/* Colour C as drawn: white for a file without colours. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 vdag_kernel_rgb(voxdag_gpu_u32 c) {
    return c == VOXDAG_GPU_NO_COLOR ? 0x00FFFFFFu : c;
}

/* The colour of hit H (with its index): a voxel's, or a level-of-detail
   cell's mean. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 vdag_kernel_hit_rgb(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_hit h) {
    return vdag_kernel_rgb(h.level == f.levels ? voxdag_gpu_color(buf, f, h.index_lo, h.index_hi) : voxdag_gpu_cell_color(buf, f, h));
}

VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_abs(voxdag_gpu_f32 x) {
    return x < 0.0f ? -x : x;
}

/* Voxel count LO + 2^32 HI as a float, the same bits everywhere: 16-bit
   pieces convert exactly, and each sum rounds once. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_count(voxdag_gpu_u32 lo, voxdag_gpu_u32 hi) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 h = voxdag_gpui_add(voxdag_gpui_mul_apart(VOXDAG_GPU_F32(hi >> 16), 65536.0f), VOXDAG_GPU_F32(hi & 0xFFFFu));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 l = voxdag_gpui_add(voxdag_gpui_mul_apart(VOXDAG_GPU_F32(lo >> 16), 65536.0f), VOXDAG_GPU_F32(lo & 0xFFFFu));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 v = voxdag_gpui_add(voxdag_gpui_mul_apart(h, 4294967296.0f), l);
    return v;
}

/* Axis K's component of the occupancy gradient at the level-of-detail
   cell of H (side SIDE): the voxels of the neighbouring cell below along
   K less those of the one above (outside the grid: none). */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_gradient(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_hit h,
                                                    voxdag_gpu_u32 side, voxdag_gpu_u32 k) {
    voxdag_gpu_u32 sx = k == 0u ? side : 0u, sy = k == 1u ? side : 0u, sz = k == 2u ? side : 0u;
    voxdag_gpu_cell_result below = voxdag_gpu_cell(buf, f, h.level, h.x - sx, h.y - sy, h.z - sz);
    voxdag_gpu_cell_result above = voxdag_gpu_cell(buf, f, h.level, h.x + sx, h.y + sy, h.z + sz);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 m =
        voxdag_gpui_sub(vdag_kernel_count(below.count_lo, below.count_hi), vdag_kernel_count(above.count_lo, above.count_hi));
    return m;
}

/* The staircase's faces of one axis, whose gradient component is M (their
   normal is sign(M) along the axis): their weight seen along direction
   component D, |M| SCALE max(0, -D sign(M)), and their lighting by light
   component L, max(0, L sign(M)). */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_seen(voxdag_gpu_f32 m, voxdag_gpu_f32 scale, voxdag_gpu_f32 d) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 facing = m < 0.0f ? d : -d;
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 seen = voxdag_gpui_mul_apart(voxdag_gpui_mul(vdag_kernel_abs(m), scale), facing);
    return facing > 0.0f ? seen : 0.0f;
}
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_lit_by(voxdag_gpu_f32 m, voxdag_gpu_f32 l) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 lit = m < 0.0f ? -l : l;
    return lit > 0.0f ? lit : 0.0f;
}

/* The lighting of the level-of-detail cell that H stopped at, seen along
   (DX, DY, DZ): examples/render.c's cell_lit with --lod-opaque in float32, its voxels'
   staircase from the occupancy gradient m of the six neighbouring cells,
   faces of axis k weighted by |m_k| max(0, -d . n_k) and lit by
   max(0, n_k . l); FACE_LIT where none is seen. m is scaled by a power of
   two (exactly) into [1, 2) at its largest, and the weighted mean divides
   by the header's reciprocal: the same bits everywhere. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_cell_lit(voxdag_gpu_buf buf, voxdag_gpu_file f, vdag_kernel_params p,
                                                    voxdag_gpu_hit h, voxdag_gpu_f32 dx, voxdag_gpu_f32 dy,
                                                    voxdag_gpu_f32 dz, voxdag_gpu_f32 face_lit) {
    voxdag_gpu_u32 side = 1u << (f.levels - h.level);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 mx = vdag_kernel_gradient(buf, f, h, side, 0u);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 my = vdag_kernel_gradient(buf, f, h, side, 1u);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 mz = vdag_kernel_gradient(buf, f, h, side, 2u);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 top, scale, wx, wy, wz, num, den;
    top = vdag_kernel_abs(mx);
    top = vdag_kernel_abs(my) > top ? vdag_kernel_abs(my) : top;
    top = vdag_kernel_abs(mz) > top ? vdag_kernel_abs(mz) : top;
    if (!(top > 0.0f)) return face_lit;
    scale = VOXDAG_GPU_BITS_FLOAT(0x7F000000u - (VOXDAG_GPU_FLOAT_BITS(top) & 0x7F800000u)); /* 2^-e for top's exponent e */
    wx = vdag_kernel_seen(mx, scale, dx), wy = vdag_kernel_seen(my, scale, dy), wz = vdag_kernel_seen(mz, scale, dz);
    den = voxdag_gpui_add(voxdag_gpui_add(wx, wy), wz);
    num = voxdag_gpui_add(voxdag_gpui_add(voxdag_gpui_mul_apart(wx, vdag_kernel_lit_by(mx, p.l_x)),
                                          voxdag_gpui_mul_apart(wy, vdag_kernel_lit_by(my, p.l_y))),
                          voxdag_gpui_mul_apart(wz, vdag_kernel_lit_by(mz, p.l_z)));
    if (!(den > 2.3283064e-10f)) return face_lit; /* below 2^-32: nothing seen (and the reciprocal's domain) */
    num = voxdag_gpui_mul(num, voxdag_gpui_recip(den));
    return num;
}

/* Channel C of RGB times FACTOR, rounded and clamped. */
VOXDAG_GPU_FUNC voxdag_gpu_u32 vdag_kernel_shade(voxdag_gpu_u32 rgb, voxdag_gpu_u32 c, voxdag_gpu_f32 factor) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 v = voxdag_gpui_add(voxdag_gpui_mul_apart(VOXDAG_GPU_F32(rgb >> (8u * c) & 0xFFu), factor), 0.5f);
    return v >= 255.0f ? 255u : VOXDAG_GPU_U32(v);
}

/* The direction of pixel (X, Y)'s ray is f + sx r + sy u. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_sx(vdag_kernel_params p, voxdag_gpu_u32 x) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 sx = voxdag_gpui_sub(voxdag_gpui_mul_apart(VOXDAG_GPU_F32(2u * x + 1u), p.inv_w), 1.0f);
    return sx;
}
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_sy(vdag_kernel_params p, voxdag_gpu_u32 y) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 sy = voxdag_gpui_sub(1.0f, voxdag_gpui_mul_apart(VOXDAG_GPU_F32(2u * y + 1u), p.inv_h));
    return sy;
}

/* The 8x8 block of pixels B's frustum: side planes through the eye at the
   extreme pixels' directions (n . (p - eye) >= 0 inside: for a point at
   depth t on pixel (sx, sy)'s ray, r's plane gives t |r|^2 (sx - sx0)). */
VOXDAG_GPU_FUNC voxdag_gpu_frustum vdag_kernel_frustum(vdag_kernel_params p, voxdag_gpu_u32 b) {
    voxdag_gpu_u32 bx = b % ((p.width + 7u) / 8u), by = b / ((p.width + 7u) / 8u);
    voxdag_gpu_u32 x1 = 8u * bx + 7u < p.width ? 8u * bx + 7u : p.width - 1u, y1 = 8u * by + 7u < p.height ? 8u * by + 7u : p.height - 1u;
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 sx0 = vdag_kernel_sx(p, 8u * bx), sx1 = vdag_kernel_sx(p, x1);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 sy0 = vdag_kernel_sy(p, y1), sy1 = vdag_kernel_sy(p, 8u * by);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 rr = voxdag_gpui_dot(p.r_x, p.r_y, p.r_z, p.r_x, p.r_y, p.r_z);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 uu = voxdag_gpui_dot(p.u_x, p.u_y, p.u_z, p.u_x, p.u_y, p.u_z);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 a0 = voxdag_gpui_mul(sx0, rr), a1 = voxdag_gpui_mul(sx1, rr);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 a2 = voxdag_gpui_mul(sy0, uu), a3 = voxdag_gpui_mul(sy1, uu);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 wx = voxdag_gpui_mul(voxdag_gpui_sub(sx1, sx0), voxdag_gpui_add(p.r_x < 0.0f ? -p.r_x : p.r_x,
        voxdag_gpui_add(p.r_y < 0.0f ? -p.r_y : p.r_y, p.r_z < 0.0f ? -p.r_z : p.r_z)));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 wy = voxdag_gpui_mul(voxdag_gpui_sub(sy1, sy0), voxdag_gpui_add(p.u_x < 0.0f ? -p.u_x : p.u_x,
        voxdag_gpui_add(p.u_y < 0.0f ? -p.u_y : p.u_y, p.u_z < 0.0f ? -p.u_z : p.u_z)));
    voxdag_gpu_frustum fr;
    fr.ox = p.eye_x, fr.oy = p.eye_y, fr.oz = p.eye_z, fr.fx = p.f_x, fr.fy = p.f_y, fr.fz = p.f_z;
    fr.lod = p.lod, fr.width = wx < wy ? wx : wy; /* a cell that narrow fits the block both ways */
    fr.n0x = voxdag_gpui_sub(p.r_x, voxdag_gpui_mul_apart(a0, p.f_x)), fr.n0y = voxdag_gpui_sub(p.r_y, voxdag_gpui_mul_apart(a0, p.f_y));
    fr.n0z = voxdag_gpui_sub(p.r_z, voxdag_gpui_mul_apart(a0, p.f_z));
    fr.n1x = voxdag_gpui_sub(voxdag_gpui_mul_apart(a1, p.f_x), p.r_x), fr.n1y = voxdag_gpui_sub(voxdag_gpui_mul_apart(a1, p.f_y), p.r_y);
    fr.n1z = voxdag_gpui_sub(voxdag_gpui_mul_apart(a1, p.f_z), p.r_z);
    fr.n2x = voxdag_gpui_sub(p.u_x, voxdag_gpui_mul_apart(a2, p.f_x)), fr.n2y = voxdag_gpui_sub(p.u_y, voxdag_gpui_mul_apart(a2, p.f_y));
    fr.n2z = voxdag_gpui_sub(p.u_z, voxdag_gpui_mul_apart(a2, p.f_z));
    fr.n3x = voxdag_gpui_sub(voxdag_gpui_mul_apart(a3, p.f_x), p.u_x), fr.n3y = voxdag_gpui_sub(voxdag_gpui_mul_apart(a3, p.f_y), p.u_y);
    fr.n3z = voxdag_gpui_sub(voxdag_gpui_mul_apart(a3, p.f_z), p.u_z);
    return fr;
}

/* A ray start from a block's frustum depth D: below it by the tests'
   margin (2^-12 of the grid) and by 2^-10 of it (the rays' f . d is 1 up
   to float rounding), never negative. */
VOXDAG_GPU_FUNC voxdag_gpu_f32 vdag_kernel_start(voxdag_gpu_file f, voxdag_gpu_f32 d) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 t = voxdag_gpui_mul(voxdag_gpui_sub(d, VOXDAG_GPU_F32(1u << f.levels) * 0.00024414062f), 0.99902344f);
    return t > 0.0f ? t : 0.0f;
}

VOXDAG_GPU_FUNC voxdag_gpu_u32 vdag_kernel_pixel(voxdag_gpu_buf buf, voxdag_gpu_file f, vdag_kernel_params p,
                                                 voxdag_gpu_u32 x, voxdag_gpu_u32 y, voxdag_gpu_f32 t_min) {
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 sx = vdag_kernel_sx(p, x), sy = vdag_kernel_sy(p, y);
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 dx = voxdag_gpui_add(voxdag_gpui_add(p.f_x, voxdag_gpui_mul_apart(sx, p.r_x)), voxdag_gpui_mul_apart(sy, p.u_x));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 dy = voxdag_gpui_add(voxdag_gpui_add(p.f_y, voxdag_gpui_mul_apart(sx, p.r_y)), voxdag_gpui_mul_apart(sy, p.u_y));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 dz = voxdag_gpui_add(voxdag_gpui_add(p.f_z, voxdag_gpui_mul_apart(sx, p.r_z)), voxdag_gpui_mul_apart(sy, p.u_z));
    VOXDAG_GPU_PRECISE voxdag_gpu_f32 factor = 1.0f, lit = 0.0f, sox, soy, soz;
    voxdag_gpu_ray ray;
    voxdag_gpu_hit h;
    voxdag_gpu_u32 rgb;
    ray.ox = p.eye_x, ray.oy = p.eye_y, ray.oz = p.eye_z;
    ray.dx = dx, ray.dy = dy, ray.dz = dz;
    ray.t_min = t_min, ray.t_max = 0.0f, ray.lod = p.lod, ray.flags = VOXDAG_GPU_WANT_INDEX;
    h = voxdag_gpu_raycast(buf, f, ray);
    if (h.hit == 0u) return VDAG_KERNEL_BACKGROUND;
    rgb = vdag_kernel_hit_rgb(buf, f, h);
    if (h.nx != 0 || h.ny != 0 || h.nz != 0) {
        lit = h.nx != 0 ? VOXDAG_GPU_F32(h.nx) * p.l_x : h.ny != 0 ? VOXDAG_GPU_F32(h.ny) * p.l_y : VOXDAG_GPU_F32(h.nz) * p.l_z;
        if (h.level < f.levels) lit = vdag_kernel_cell_lit(buf, f, p, h, dx, dy, dz, lit);
        factor = lit > 0.0f ? voxdag_gpui_add(p.ambient, voxdag_gpui_mul_apart(voxdag_gpui_sub(1.0f, p.ambient), lit)) : p.ambient;
        if ((p.flags & VDAG_KERNEL_SHADOWS) != 0u && lit > 0.0f) {
            /* from the hit point, exactly on the face plane (then it starts in
               the neighbouring voxel), towards the light; from a
               level-of-detail cell, past its own staircase (lit above) */
            voxdag_gpu_ray s;
            voxdag_gpu_u32 side = 1u << (f.levels - h.level);
            sox = voxdag_gpui_add(ray.ox, voxdag_gpui_mul_apart(h.t, dx));
            soy = voxdag_gpui_add(ray.oy, voxdag_gpui_mul_apart(h.t, dy));
            soz = voxdag_gpui_add(ray.oz, voxdag_gpui_mul_apart(h.t, dz));
            s.ox = h.nx != 0 ? VOXDAG_GPU_F32(h.x + (h.nx > 0 ? side : 0u)) : sox;
            s.oy = h.ny != 0 ? VOXDAG_GPU_F32(h.y + (h.ny > 0 ? side : 0u)) : soy;
            s.oz = h.nz != 0 ? VOXDAG_GPU_F32(h.z + (h.nz > 0 ? side : 0u)) : soz;
            s.dx = p.l_x, s.dy = p.l_y, s.dz = p.l_z;
            s.t_min = h.level < f.levels ? VOXDAG_GPU_F32(side) : 0.0f, s.t_max = 0.0f, s.lod = 0.0f, s.flags = 0u;
            if (voxdag_gpu_occluded(buf, f, s) != 0u) factor = p.ambient;
        }
    }
    return vdag_kernel_shade(rgb, 0u, factor) | vdag_kernel_shade(rgb, 1u, factor) << 8 |
           vdag_kernel_shade(rgb, 2u, factor) << 16;
}

#ifdef VDAG_KERNEL_IN
/* Item I of P's work. */
VOXDAG_GPU_FUNC void vdag_kernel_run(voxdag_gpu_buf buf, vdag_kernel_io io, vdag_kernel_params p, voxdag_gpu_u32 i) {
    voxdag_gpu_file f = voxdag_gpu_open(buf, p.base);
    if (i >= p.count) return;
    if (p.mode == VDAG_KERNEL_RAYS || p.mode == VDAG_KERNEL_OCCLUDED) {
        voxdag_gpu_ray r;
        voxdag_gpu_hit h;
        r.ox = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i)), r.oy = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 1u));
        r.oz = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 2u)), r.dx = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 3u));
        r.dy = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 4u)), r.dz = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 5u));
        r.t_min = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 6u));
        r.t_max = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 7u));
        r.lod = VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, 10u * i + 8u)), r.flags = VDAG_KERNEL_IN(io, 10u * i + 9u);
        if (p.mode == VDAG_KERNEL_OCCLUDED) {
            VDAG_KERNEL_OUT(io, i, voxdag_gpu_occluded(buf, f, r));
            return;
        }
        h = voxdag_gpu_raycast(buf, f, r);
        VDAG_KERNEL_OUT(io, 12u * i, h.hit);
        VDAG_KERNEL_OUT(io, 12u * i + 1u, VOXDAG_GPU_FLOAT_BITS(h.t));
        VDAG_KERNEL_OUT(io, 12u * i + 2u, h.x);
        VDAG_KERNEL_OUT(io, 12u * i + 3u, h.y);
        VDAG_KERNEL_OUT(io, 12u * i + 4u, h.z);
        VDAG_KERNEL_OUT(io, 12u * i + 5u, VOXDAG_GPU_U32(h.nx));
        VDAG_KERNEL_OUT(io, 12u * i + 6u, VOXDAG_GPU_U32(h.ny));
        VDAG_KERNEL_OUT(io, 12u * i + 7u, VOXDAG_GPU_U32(h.nz));
        VDAG_KERNEL_OUT(io, 12u * i + 8u, h.level);
        VDAG_KERNEL_OUT(io, 12u * i + 9u, h.index_lo);
        VDAG_KERNEL_OUT(io, 12u * i + 10u, h.index_hi);
        VDAG_KERNEL_OUT(io, 12u * i + 11u, h.hit != 0u ? vdag_kernel_hit_rgb(buf, f, h) : 0u);
    } else if (p.mode == VDAG_KERNEL_LOOKUPS) {
        voxdag_gpu_lookup_result l =
            voxdag_gpu_lookup(buf, f, VDAG_KERNEL_IN(io, 3u * i), VDAG_KERNEL_IN(io, 3u * i + 1u), VDAG_KERNEL_IN(io, 3u * i + 2u));
        VDAG_KERNEL_OUT(io, 4u * i, l.found);
        VDAG_KERNEL_OUT(io, 4u * i + 1u, l.index_lo);
        VDAG_KERNEL_OUT(io, 4u * i + 2u, l.index_hi);
        VDAG_KERNEL_OUT(io, 4u * i + 3u, l.found != 0u ? vdag_kernel_rgb(voxdag_gpu_color(buf, f, l.index_lo, l.index_hi)) : 0u);
    } else if (p.mode == VDAG_KERNEL_RENDER) {
        voxdag_gpu_u32 x = i % p.width, y = i / p.width;
        voxdag_gpu_f32 t_min = 0.0f;
        if ((p.flags & VDAG_KERNEL_BEAM_START) != 0u)
            t_min = vdag_kernel_start(f, VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, y / 8u * ((p.width + 7u) / 8u) + x / 8u)));
        VDAG_KERNEL_OUT(io, i, vdag_kernel_pixel(buf, f, p, x, y, t_min));
    } else if (p.mode == VDAG_KERNEL_BEAM) {
        VDAG_KERNEL_OUT(io, i, VOXDAG_GPU_FLOAT_BITS(voxdag_gpu_frustum_depth(buf, f, vdag_kernel_frustum(p, i))));
    } else if (p.mode == VDAG_KERNEL_CELLS) {
        voxdag_gpu_hit h;
        voxdag_gpu_cell_result c;
        h.hit = 1u, h.t = 0.0f, h.nx = 0, h.ny = 0, h.nz = 0, h.index_lo = 0u, h.index_hi = 0u;
        h.level = VDAG_KERNEL_IN(io, 4u * i), h.x = VDAG_KERNEL_IN(io, 4u * i + 1u);
        h.y = VDAG_KERNEL_IN(io, 4u * i + 2u), h.z = VDAG_KERNEL_IN(io, 4u * i + 3u);
        c = voxdag_gpu_cell(buf, f, h.level, h.x, h.y, h.z);
        VDAG_KERNEL_OUT(io, 5u * i, c.count_lo);
        VDAG_KERNEL_OUT(io, 5u * i + 1u, c.count_hi);
        VDAG_KERNEL_OUT(io, 5u * i + 2u, c.first_lo);
        VDAG_KERNEL_OUT(io, 5u * i + 3u, c.first_hi);
        VDAG_KERNEL_OUT(io, 5u * i + 4u, voxdag_gpu_cell_color(buf, f, h));
    }
}
#endif

#endif
