// The smoke test's shader (tests/test_vk.c): out[i] = in[i] * 3 + add over
// a grid of ROW x N workgroups of 64.
#version 450
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer In { uint data_in[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Out { uint data_out[]; };
layout(push_constant) uniform Push { uint add; uint count; uint row; } pc;
void main() {
    uint i = (gl_WorkGroupID.y * pc.row + gl_WorkGroupID.x) * 64u + gl_LocalInvocationID.x;
    if (i < pc.count) data_out[i] = data_in[i] * 3u + pc.add;
}
