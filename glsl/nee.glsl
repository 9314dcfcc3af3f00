// Next-event estimation (render.glsl): the light (or environment) choice,
// and the estimates at a surface vertex, at a scattering event in a medium,
// and along a medium segment toward a positional light (equiangular).
#ifndef NEE_GLSL
#define NEE_GLSL

bool environmentLit() { return frame.envMap != NO_TEXTURE || any(greaterThan(frame.background, vec3(0.0))); }

// Light index `frame.lightCount` stands for the uniform environment (the
// background radiance) when it is not black.
LightSample sampleLightOrEnvironment(uint i, vec3 x, vec2 u) {
    if (i != frame.lightCount) return sampleLight(lights[i], x, u);
    return envMapped() ? sampleEnvMap(u, frame.envWidth, frame.envHeight) : sampleEnvironment(frame.background, u);
}

float lightOrEnvironmentPdf(uint i, vec3 x, vec3 wi) {
    return i == frame.lightCount ? environmentPdf(wi) : lightPdf(lights[i], x, wi);
}

#include "light_queries.glsl"

// Number of light-sampling choices: the lights, plus the environment.
uint lightChoices() { return frame.lightCount + (environmentLit() ? 1u : 0u); }

// Next-event estimation at a vertex with a non-delta material (pbrt-v4's
// SampleLd): one light
// chosen uniformly, weighted by multiple importance sampling against the
// BSDF-sampled continuation (which every vertex has, the last one included:
// see "the last vertex" in tracePath). Returns the light's contribution if
// its shadow ray `sr` is unblocked.
vec3 sampleLd(Material mat, mat3 frameW, vec3 wo, vec3 d, vec3 p, vec3 ng, float offset, Medium med, inout PathSampler rng,
              out ShadowRay sr) {
    uint choices = lightChoices();
    if (choices == 0u) return vec3(0.0);
    uint i = min(uint(sample1(rng) * float(choices)), choices - 1u);
    float select = 1.0 / float(choices);
    LightSample ls = sampleLightOrEnvironment(i, p, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    vec3 wiLocal = transpose(frameW) * ls.wi;
    // The light must lie on the side of the geometric surface that the
    // lobe scatters to (the viewer's side for reflection, the other for
    // transmission): a shading normal tilted by a normal or bump map would
    // otherwise let light leak through the surface.
    bool crosses = dot(ls.wi, ng) * dot(d, ng) > 0.0;
    if (crosses != (wiLocal.z * wo.z < 0.0)) return vec3(0.0);
    vec3 f = bsdfEval(mat, wo, wiLocal);
    if (all(equal(f, vec3(0.0)))) return vec3(0.0);
    // The shadow ray starts off the surface on the side of the light (either
    // side for a rough dielectric); the light's distance is shortened by the
    // part of the offset along the ray, so that the ray ends at the light.
    vec3 origin = offsetOrigin(p, ng, ls.wi, offset);
    float dist = ls.dist - dot(origin - p, ls.wi);
    sr = ShadowRay(origin, ls.wi, dist, i);
    // The medium around the vertex attenuates the shadow ray (a shadow ray
    // that would cross into another medium meets its boundary and is
    // occluded above).
    vec3 contribution = f * abs(wiLocal.z) * ls.radiance * (transmittance(med, dist) / select);
    if (ls.pdf == 0.0) return contribution;  // delta light
    float pl = ls.pdf * select;
    return contribution * (powerHeuristic(pl, bsdfPdf(mat, wo, wiLocal)) / ls.pdf);
}

// Next-event estimation at a scattering event in a medium, at p, for a path
// travelling along d, toward light (or environment) `i` chosen with
// probability `select`: the phase function replaces the BSDF and the
// cosine, the shadow ray is attenuated by the medium's transmittance. Used
// for the environment and directional lights; positional lights use the
// equiangular estimate over the whole segment instead.
vec3 mediumNextEvent(Medium med, vec3 d, vec3 p, uint i, float select, inout PathSampler rng, out ShadowRay sr) {
    LightSample ls = sampleLightOrEnvironment(i, p, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    float phase = hgPdf(med.anisotropy, dot(d, ls.wi));
    float tr = transmittance(med, ls.dist);
    if (tr == 0.0) return vec3(0.0);
    sr = ShadowRay(p, ls.wi, ls.dist, i);
    vec3 contribution = phase * tr * ls.radiance / select;
    if (ls.pdf == 0.0) return contribution;  // delta light
    return contribution * (powerHeuristic(ls.pdf * select, phase) / ls.pdf);
}

// Single scattering toward positional light `i` (chosen with probability
// `select`) along the medium segment o + t d, t in [0, tEnd): a point by
// equiangular sampling, a direction by the light's sampler, weighted by
// multiple importance sampling against the path's own strategy (distance
// sampling, density σ_t T(t), then the phase function). Returns the
// estimate before the segment's throughput (it includes σ_s and both
// transmittances).
vec3 equiangularNextEvent(Medium med, vec3 o, vec3 d, float tEnd, uint i, float select, inout PathSampler rng,
                          out ShadowRay sr) {
    Equiangular e = equiangularSetup(o, d, tEnd, lightCentre(i));
    float t = equiangularSample(e, sample1(rng));
    float pt = equiangularPdf(e, t);
    if (!(t >= 0.0 && t < tEnd) || !(pt > 0.0)) return vec3(0.0);
    vec3 x = o + t * d;
    LightSample ls = sampleLight(lights[i], x, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    float phase = hgPdf(med.anisotropy, dot(d, ls.wi));
    sr = ShadowRay(x, ls.wi, ls.dist, i);
    float tAlong = exp(-med.density * t);
    vec3 f = (tAlong * transmittance(med, ls.dist) * med.density * phase) * v3(med.albedo) * ls.radiance;
    if (ls.pdf == 0.0) return f / (select * pt);  // point light
    float pA = select * pt * ls.pdf;
    return f * (powerHeuristic(pA, med.density * tAlong * phase) / pA);
}

#endif
