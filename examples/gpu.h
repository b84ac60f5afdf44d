/* The GPU path of vdag rays and vdag render (examples/gpu.c): the kernel of
   examples/shaders/vdag_kernel.h run on Vulkan (examples/gpu_vulkan.c),
   compiled from GLSL or from HLSL, or its C build run on the CPU's threads
   (the same arithmetic: --gpu-emulate, and the tests' reference). */
#ifndef VDAG_GPU_H
#define VDAG_GPU_H

#include <stddef.h>
#include <stdint.h>

#include "voxdag.h"

typedef enum vdag_gpu_target {
    VDAG_GPU_GLSL,    /* Vulkan, the kernel compiled from GLSL */
    VDAG_GPU_HLSL,    /* Vulkan, the kernel compiled from HLSL */
    VDAG_GPU_EMULATE  /* the kernel's C build on the CPU */
} vdag_gpu_target;

/* Work for the kernel (vdag_kernel.h's records and picture model). */
typedef enum vdag_gpu_mode {
    VDAG_GPU_RAYS,     /* in 10 words a ray, out 12 a hit */
    VDAG_GPU_OCCLUDED, /* in 10 words a ray, out 1 */
    VDAG_GPU_LOOKUPS,  /* in 3 words a voxel, out 4 */
    VDAG_GPU_RENDER,   /* out one 0x00BBGGRR word a pixel (in: BEAM's depths with beam_start) */
    VDAG_GPU_BEAM,     /* out one depth (float bits) per 8x8 block of pixels */
    VDAG_GPU_CELLS     /* in 4 words a cell (level x y z), out 5: count, first index, colour */
} vdag_gpu_mode;

typedef struct vdag_gpu_work {
    vdag_gpu_mode mode;
    uint32_t count;          /* items (RENDER: width * height) */
    uint32_t width, height;  /* RENDER */
    int shadows;
    int beam_start;          /* RENDER: rays start at their block's BEAM depth */
    float eye[3], f[3], r[3], u[3], light[3]; /* RENDER: as vdag_kernel_params */
    float lod, ambient, inv_w, inv_h;
} vdag_gpu_work;

typedef struct vdag_gpu vdag_gpu;

/* Opens TARGET (THREADS: the emulation's threads, 0: one) for DAG's image,
   padded to whole words. Returns 0, or nonzero with one line in ERR: no
   Vulkan, a tool built without it, or a file the device cannot bind (above
   its storage-buffer limit, or 4 GiB and more). */
int vdag_gpu_open(vdag_gpu **out, vdag_gpu_target target, const voxdag *dag, unsigned threads, char *err,
                  size_t err_size);
/* Replaces the file (the device and its compiled kernel stay). */
int vdag_gpu_load(vdag_gpu *g, const voxdag *dag, char *err, size_t err_size);
void vdag_gpu_close(vdag_gpu *g);

/* The device's name, and whether it is a CPU (lavapipe or the emulation). */
const char *vdag_gpu_device(const vdag_gpu *g);
int vdag_gpu_is_cpu(const vdag_gpu *g);

/* Runs W on IN (IN_WORDS words) into OUT (OUT_WORDS words), REPEAT times;
   *SECONDS (when not NULL) gets the time of one run (GPU timestamps, or
   wall time when emulated). Returns 0 or nonzero with one line in ERR. */
int vdag_gpu_run(vdag_gpu *g, const vdag_gpu_work *w, const uint32_t *in, size_t in_words, uint32_t *out,
                 size_t out_words, uint32_t repeat, double *seconds, char *err, size_t err_size);

#endif
