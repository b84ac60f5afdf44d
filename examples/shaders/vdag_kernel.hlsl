/* The vdag tool's compute kernel in HLSL (vdag_kernel.h), bound as the GLSL
   one: t0 the .vdag image, t1 the input words, u2 the output words. */
StructuredBuffer<uint> dag_words : register(t0);
StructuredBuffer<uint> in_words : register(t1);
RWStructuredBuffer<uint> out_words : register(u2);
#define VOXDAG_GPU_HLSL
#define VOXDAG_GPU_BUFFER dag_words
#include "../../voxdag_gpu.h"
#define vdag_kernel_io uint
#define VDAG_KERNEL_IN(io, i) in_words[i]
#define VDAG_KERNEL_OUT(io, i, v) out_words[i] = (v)
#include "vdag_kernel.h"
[[vk::push_constant]] cbuffer Push { vdag_kernel_params push; };

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
    vdag_kernel_run(0u, 0u, push, id.x + id.y * push.row);
}
