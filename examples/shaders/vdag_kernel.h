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
   rgb is 0x00BBGGRR, white for a file without colours.

   The picture model is examples/render.c's in float32, with two
   differences: directions are f + sx r + sy u unnormalized (t is then the
   depth along the view axis), and level of detail compares a cell with the
   pixel size at that depth. */
#ifndef VDAG_KERNEL_H
#define VDAG_KERNEL_H

#define VDAG_KERNEL_RAYS 0u
#define VDAG_KERNEL_OCCLUDED 1u
#define VDAG_KERNEL_LOOKUPS 2u
#define VDAG_KERNEL_RENDER 3u
#define VDAG_KERNEL_BEAM 4u
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

VOXDAG_GPU_FUNC voxdag_gpu_u32 vdag_kernel_rgb(voxdag_gpu_buf buf, voxdag_gpu_file f, voxdag_gpu_u32 lo,
                                               voxdag_gpu_u32 hi) {
    voxdag_gpu_u32 c = voxdag_gpu_color(buf, f, lo, hi);
    return c == VOXDAG_GPU_NO_COLOR ? 0x00FFFFFFu : c;
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
    rgb = vdag_kernel_rgb(buf, f, h.index_lo, h.index_hi);
    if (h.nx != 0 || h.ny != 0 || h.nz != 0) {
        lit = h.nx != 0 ? VOXDAG_GPU_F32(h.nx) * p.l_x : h.ny != 0 ? VOXDAG_GPU_F32(h.ny) * p.l_y : VOXDAG_GPU_F32(h.nz) * p.l_z;
        factor = lit > 0.0f ? voxdag_gpui_add(p.ambient, voxdag_gpui_mul_apart(voxdag_gpui_sub(1.0f, p.ambient), lit)) : p.ambient;
        if ((p.flags & VDAG_KERNEL_SHADOWS) != 0u && lit > 0.0f) {
            /* from the hit point, exactly on the face plane (then it starts in
               the neighbouring voxel), towards the light */
            voxdag_gpu_ray s;
            voxdag_gpu_u32 side = 1u << (f.levels - h.level);
            sox = voxdag_gpui_add(ray.ox, voxdag_gpui_mul_apart(h.t, dx));
            soy = voxdag_gpui_add(ray.oy, voxdag_gpui_mul_apart(h.t, dy));
            soz = voxdag_gpui_add(ray.oz, voxdag_gpui_mul_apart(h.t, dz));
            s.ox = h.nx != 0 ? VOXDAG_GPU_F32(h.x + (h.nx > 0 ? side : 0u)) : sox;
            s.oy = h.ny != 0 ? VOXDAG_GPU_F32(h.y + (h.ny > 0 ? side : 0u)) : soy;
            s.oz = h.nz != 0 ? VOXDAG_GPU_F32(h.z + (h.nz > 0 ? side : 0u)) : soz;
            s.dx = p.l_x, s.dy = p.l_y, s.dz = p.l_z;
            s.t_min = 0.0f, s.t_max = 0.0f, s.lod = 0.0f, s.flags = 0u;
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
        VDAG_KERNEL_OUT(io, 12u * i + 11u, h.hit != 0u ? vdag_kernel_rgb(buf, f, h.index_lo, h.index_hi) : 0u);
    } else if (p.mode == VDAG_KERNEL_LOOKUPS) {
        voxdag_gpu_lookup_result l =
            voxdag_gpu_lookup(buf, f, VDAG_KERNEL_IN(io, 3u * i), VDAG_KERNEL_IN(io, 3u * i + 1u), VDAG_KERNEL_IN(io, 3u * i + 2u));
        VDAG_KERNEL_OUT(io, 4u * i, l.found);
        VDAG_KERNEL_OUT(io, 4u * i + 1u, l.index_lo);
        VDAG_KERNEL_OUT(io, 4u * i + 2u, l.index_hi);
        VDAG_KERNEL_OUT(io, 4u * i + 3u, l.found != 0u ? vdag_kernel_rgb(buf, f, l.index_lo, l.index_hi) : 0u);
    } else if (p.mode == VDAG_KERNEL_RENDER) {
        voxdag_gpu_u32 x = i % p.width, y = i / p.width;
        voxdag_gpu_f32 t_min = 0.0f;
        if ((p.flags & VDAG_KERNEL_BEAM_START) != 0u)
            t_min = vdag_kernel_start(f, VOXDAG_GPU_BITS_FLOAT(VDAG_KERNEL_IN(io, y / 8u * ((p.width + 7u) / 8u) + x / 8u)));
        VDAG_KERNEL_OUT(io, i, vdag_kernel_pixel(buf, f, p, x, y, t_min));
    } else if (p.mode == VDAG_KERNEL_BEAM) {
        VDAG_KERNEL_OUT(io, i, VOXDAG_GPU_FLOAT_BITS(voxdag_gpu_frustum_depth(buf, f, vdag_kernel_frustum(p, i))));
    }
}
#endif

#endif
