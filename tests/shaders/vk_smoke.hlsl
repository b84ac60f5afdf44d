// The smoke test's shader in HLSL (tests/test_vk.c), the same computation as
// vk_smoke.comp: out[i] = in[i] * 3 + add over ROW x N workgroups of 64.
struct Push { uint add; uint count; uint row; };
[[vk::push_constant]] Push pc;
[[vk::binding(0, 0)]] StructuredBuffer<uint> data_in;
[[vk::binding(1, 0)]] RWStructuredBuffer<uint> data_out;
[numthreads(64, 1, 1)]
void main(uint3 group : SV_GroupID, uint3 local : SV_GroupThreadID) {
    uint i = (group.y * pc.row + group.x) * 64u + local.x;
    if (i < pc.count) data_out[i] = data_in[i] * 3u + pc.add;
}
