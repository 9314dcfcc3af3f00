#version 460
// Runs the GLSL sampling routines (bsdf.glsl, lights.glsl) on inputs given
// by the host, so that tests/sampling/sampling_gpu.rs can compare them with their f64
// CPU twins (src/model/sampling/).
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_control_flow_attributes : require

#include "lights.glsl"
#include "media.glsl"
#include "sobol.glsl"

layout(set = 0, binding = BINDING_TWIN_ENV_TABLE, scalar) readonly buffer EnvTable { float envTable[]; };
layout(set = 0, binding = BINDING_TWIN_ENV_TEXELS, scalar) readonly buffer EnvTexels { vec4 envTexels[]; };
layout(push_constant, scalar) uniform PushBlock { TwinPush pc; };

float envCdfAt(uint i) { return envTable[i]; }
vec3 envTexelRadiance(ivec2 t) { return envTexels[uint(t.y) * pc.envWidth + uint(t.x)].rgb * pc.envScale; }
#include "envmap.glsl"

layout(local_size_x = 64) in;

const uint OP_BSDF = 0u;
const uint OP_LIGHT = 1u;
const uint OP_ENVIRONMENT = 2u;
const uint OP_SOBOL = 3u;  // u: the pixel seed's bits, the sample index, the dimension
const uint OP_HALO = 4u;   // wo: the axis; u: the direction's two numbers; wi: a direction for haloPdf



layout(set = 0, binding = BINDING_TWIN_CASES, scalar) readonly buffer TwinCases { TwinCase cases[]; };
layout(set = 0, binding = BINDING_TWIN_RESULTS, scalar) writeonly buffer TwinResults { TwinResult results[]; };

float[3] f3(vec3 v) { return float[3](v.x, v.y, v.z); }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    TwinCase c = cases[i];
    TwinResult r;
    r.eval = f3(vec3(0.0));
    r.pdfOf = 0.0;
    r.dist = 0.0;
    if (c.op == OP_SOBOL) {
        SobolSampler s = SobolSampler(floatBitsToUint(c.u[0]), uint(c.u[1]), uint(c.u[2]));
        vec2 p = sobolSample2(s);
        r.wi = float[3](p.x, p.y, float(s.dimension));
        r.weight = f3(vec3(0.0));
        r.pdf = 0.0;
        r.valid = 1u;
    } else if (c.op == OP_HALO) {
        vec3 a = normalize(v3(c.wo));
        vec3 w = sampleHalo(a, vec2(c.u[0], c.u[1]));
        r.wi = f3(w);
        r.weight = f3(vec3(0.0));
        r.pdf = haloPdf(a, w);
        r.valid = 1u;
        r.pdfOf = haloPdf(a, v3(c.wi));
    } else if (c.op == OP_BSDF) {
        vec3 wo = v3(c.wo), wi = v3(c.wi);
        BsdfSample s = bsdfSample(c.mat, wo, v3(c.u));
        r.wi = f3(s.wi);
        r.weight = f3(s.weight);
        r.pdf = s.pdf;
        r.valid = s.valid ? 1u : 0u;
        r.eval = f3(bsdfEval(c.mat, wo, wi));
        r.pdfOf = bsdfPdf(c.mat, wo, wi);
    } else if (c.op == OP_ENVIRONMENT) {
        LightSample s = sampleEnvMap(vec2(c.u[0], c.u[1]), pc.envWidth, pc.envHeight);
        r.wi = f3(s.wi);
        r.weight = f3(s.radiance);
        r.pdf = s.pdf;
        r.valid = s.valid ? 1u : 0u;
        r.pdfOf = envMapPdf(v3(c.wi), pc.envWidth, pc.envHeight);
    } else {
        vec3 x = v3(c.x);
        LightSample s = sampleLight(c.light, x, vec2(c.u[0], c.u[1]));
        r.wi = f3(s.wi);
        r.weight = f3(s.radiance);
        r.pdf = s.pdf;
        r.valid = s.valid ? 1u : 0u;
        r.dist = s.dist;
        r.pdfOf = lightPdf(c.light, x, v3(c.wi));
    }
    results[i] = r;
}
