/* voxdag_gpu.h in one translation unit in its C mode (no implementation
   macro: every function is static inline). tests/check_all.sh compiles it
   with every compiler and target. On Windows <windows.h> comes first: its
   macros (near, far, small, ...) must not break the header. */
#ifdef _WIN32
#include <windows.h>
#endif
#include "voxdag_gpu.h"
#include "voxdag_gpu.h" /* the guard makes a second inclusion harmless */

int check_header_voxdag_gpu(const unsigned char *bytes, unsigned long size);
int check_header_voxdag_gpu(const unsigned char *bytes, unsigned long size) {
    voxdag_gpu_buf buf;
    voxdag_gpu_file f;
    voxdag_gpu_ray r;
    voxdag_gpu_hit h;
    voxdag_gpu_lookup_result l;
    buf.bytes = bytes, buf.size = size;
    f = voxdag_gpu_open(buf, 0);
    r.ox = 1, r.oy = 2, r.oz = 3, r.dx = 1, r.dy = 0.5f, r.dz = -0.25f;
    r.t_min = 0, r.t_max = 0, r.lod = 0, r.flags = VOXDAG_GPU_WANT_INDEX;
    h = voxdag_gpu_raycast(buf, f, r);
    l = voxdag_gpu_lookup(buf, f, 1, 2, 3);
    return (int)(h.hit + l.found + voxdag_gpu_occluded(buf, f, r) + voxdag_gpu_color(buf, f, l.index_lo, l.index_hi)) +
           VOXDAG_GPU_VERSION;
}
