#version 460
// Filtered texture lookups on footprints given by the host (EWA or the
// trilinear probes): the GPU side of the lookup and LEAN tests (tests/render/texfilter_gpu.rs), which compare them with
// analytic averages and with the slope variance measured on the CPU.
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_nonuniform_qualifier : require

#include "common.glsl"
#include "gpu_structs.glsl"

layout(local_size_x = PROBE_GROUP) in;

#include "spec_constants.glsl"
#include "texfilter.glsl"

layout(set = 0, binding = BINDING_TEXPROBE_QUERIES, scalar) readonly buffer TexQueries { TexQuery queries[]; };
layout(set = 0, binding = BINDING_TEXPROBE_RESULTS, scalar) writeonly buffer TexResults { TexResult results[]; };

layout(push_constant, scalar) uniform PushBlock { ProbePush pc; };

void main() {
    if (gl_GlobalInvocationID.x >= pc.count) return;
    uint i = pc.first + gl_GlobalInvocationID.x;
    TexQuery q = queries[i];
    Footprint fp;
    fp.uv = q.uv;
    fp.axis1 = q.axis1;
    fp.axis2 = q.axis2;
    fp.xi = q.xi;
    TexResult r;
    r.value = LOOKUP_MODE == LOOKUP_EWA ? ewaLookup(q.texture, fp) : probeLookup(q.texture, fp);
    r.alpha = leanAlpha(q.alpha, r.value);
    r.pad = uint[3](0u, 0u, 0u);
    results[i] = r;
}
