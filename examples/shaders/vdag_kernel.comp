#version 450
/* The vdag tool's compute kernel in GLSL (vdag_kernel.h): binding 0 the
   .vdag image, 1 the input words, 2 the output words; 64 items a group. */
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Dag { uint dag_words[]; };
layout(std430, binding = 1) readonly buffer In { uint in_words[]; };
layout(std430, binding = 2) writeonly buffer Out { uint out_words[]; };
#define VOXDAG_GPU_GLSL
#define VOXDAG_GPU_BUFFER dag_words
#include "../../voxdag_gpu.h"
#define vdag_kernel_io uint
#define VDAG_KERNEL_IN(io, i) in_words[i]
#define VDAG_KERNEL_OUT(io, i, v) out_words[i] = (v)
#include "vdag_kernel.h"
layout(push_constant) uniform Push { vdag_kernel_params p; } push;

void main() {
    vdag_kernel_run(0u, 0u, push.p, gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * push.p.row);
}
