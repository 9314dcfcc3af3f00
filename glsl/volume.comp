#version 460
// The volumetric-lighting pass (paper section 3): light scattered once by
// the fog toward the camera from each positional light (point, sphere,
// rect), with shadows: light shafts. For each pixel, camera rays jittered
// over the pixel run from the camera to the first surface (or to a sphere or
// rect light in front of it, or on to infinity); on each, one point per
// light by equiangular sampling (media.glsl: its density follows the
// light's 1/r², so the noise does not grow near a bright light, unlike
// distance sampling), a point on the light by the light's sampler, and a
// shadow ray through the ray queries. The render pass adds the pixel's mean
// on the camera ray's first segment and leaves single scattering toward
// positional lights there out of its own estimate.
#extension GL_EXT_nonuniform_qualifier : require

#include "intersect.glsl"
#include "random.glsl"
#include "lights.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

layout(set = 0, binding = BINDING_MATERIALS, scalar) readonly buffer Materials { Material materials[]; };
layout(set = 0, binding = BINDING_LIGHTS, scalar) readonly buffer Lights { Light lights[]; };

#include "frame.glsl"
#include "light_queries.glsl"

// Mean in-scattered radiance per pixel (RGB), accumulated over dispatches.
layout(set = 0, binding = BINDING_VOLUME, scalar) buffer Volume { float volume[]; };

layout(push_constant, scalar) uniform Push {
    uint firstSample;  // index of this dispatch's first camera ray per pixel
    uint samples;      // camera rays per pixel in this dispatch
    uint total;        // camera rays per pixel over all dispatches
} pc;

// Single scattering toward light i along the fog segment o + t d, t < tEnd:
// σ_s p T(t) T(light) L / (pdf of the point × pdf of the light sample).
vec3 inScattered(Medium fog, vec3 o, vec3 d, float tEnd, uint i, inout uint rng) {
    Equiangular e = equiangularSetup(o, d, tEnd, lightCentre(i));
    float t = equiangularSample(e, rand(rng));
    float pt = equiangularPdf(e, t);
    if (!(t >= 0.0 && t < tEnd) || !(pt > 0.0)) return vec3(0.0);
    vec3 x = o + t * d;
    LightSample ls = sampleLight(lights[i], x, rand2(rng));
    if (!ls.valid || !lightVisible(x, ls.wi, ls.dist, i)) return vec3(0.0);
    float phase = hgPdf(fog.anisotropy, dot(d, ls.wi));
    vec3 f = (exp(-fog.density * t) * transmittance(fog, ls.dist) * fog.density * phase) * v3(fog.albedo)
        * ls.radiance;
    return f / (pt * (ls.pdf == 0.0 ? 1.0 : ls.pdf));
}

void main() {
    uvec2 pix = gl_GlobalInvocationID.xy;
    if (pix.x >= frame.width || pix.y >= frame.height) return;
    Medium fog = fogMedium();
    uint rng = seedRandom(pix, 0x5eed0000u + pc.firstSample, frame.seed);
    vec3 sum = vec3(0.0);
    uint side = max(uint(sqrt(float(pc.samples))), 1u);
    for (uint s = 0u; s < pc.samples; ++s) {
        // Stratified over the pixel within a dispatch (side x side strata, then random).
        vec2 jitter = s < side * side ? (vec2(s % side, s / side) + rand2(rng)) / float(side) : rand2(rng);
        vec3 d = cameraRay(vec2(pix) + jitter);
        SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
        float tl;
        firstLightHit(frame.eye, d, h.object == NO_HIT ? 1e30 : h.t, frame.lightCount, tl);
        for (uint i = 0u; i < frame.lightCount; ++i) {
            if (positionalLight(i)) sum += inScattered(fog, frame.eye, d, tl, i, rng);
        }
    }
    vec3 part = sum / float(max(pc.total, 1u));
    if (any(isnan(part)) || any(isinf(part))) part = vec3(0.0);
    uint idx = pix.y * frame.width + pix.x;
    volume[3u * idx] += part.x;
    volume[3u * idx + 1u] += part.y;
    volume[3u * idx + 2u] += part.z;
}
