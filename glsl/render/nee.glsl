// Next-event estimation (render.glsl): the light (or environment) choice,
// and the estimates at a surface vertex, at a scattering event in a medium,
// and along a medium segment toward a positional light (equiangular).
#ifndef NEE_GLSL
#define NEE_GLSL

#include "render_inputs.glsl"
#include "light_queries.glsl"
#include "environment.glsl"
#include "path_record.glsl"
#include "shadow_queue.glsl"

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


// Number of light-sampling choices: the lights, plus the environment.
uint lightChoices() { return frame.lightCount + (environmentLit() ? 1u : 0u); }

// The axis from p toward positional light i's centre (a fixed one when p is
// the centre, so that sampling and density agree).
vec3 haloAxis(uint i, vec3 p) {
    vec3 toC = lightCentre(i) - p;
    float len = length(toC);
    return len > 0.0 ? toC / len : vec3(0.0, 0.0, 1.0);
}

// Point and sphere lights: the small emitters whose halo in a medium is a
// bright secondary source, the halo strategy's choices (a rect light's
// halo is spread over its area).
bool haloLight(uint i) { return lights[i].kind == LIGHT_POINT || lights[i].kind == LIGHT_SPHERE; }

uint haloLights() {
    uint n = 0u;
    for (uint i = 0u; i < frame.lightCount; ++i) { LOOP_EDGE();
        if (haloLight(i)) ++n;
    }
    return n;
}

// The halo's share of the direction mixture at a scattering event in a
// medium, for a path whose η-corrected throughput (roulette.glsl) after the
// event's albedo and Russian roulette is `throughput`: HALO_SHARE, less
// where the weight phase / mixture, at most 1 / (1 − share), could lift it
// above 2, and 0 from 2 on. So no path's throughput exceeds 2 (surfaces and
// roulette keep it at most 1 otherwise; the sample bound counts the factor:
// passes/outliers.rs). CPU twin sampling::phase::halo_share.
float haloShare(vec3 throughput, float etaScale) {
    float t = max(throughput.r, max(throughput.g, throughput.b)) * etaScale;
    return clamp(1.0 - 0.5 * t, 0.0, HALO_SHARE);
}

// The density with which sampleScatter picks wi at p with halo share
// `share` (0: the phase function alone).
float scatterPdf(Medium med, vec3 d, vec3 p, float share, vec3 wi) {
    float phase = hgPdf(med.anisotropy, dot(d, wi));
    if (!(share > 0.0)) return phase;
    uint n = 0u;
    float halos = 0.0;
    for (uint i = 0u; i < frame.lightCount; ++i) { LOOP_EDGE();
        if (!haloLight(i)) continue;
        halos += haloPdf(haloAxis(i, p), wi);
        ++n;
    }
    return n == 0u ? phase : (1.0 - share) * phase + share * halos / float(n);
}

// The direction a path scattered at p in medium `med` while travelling along
// d takes: the phase function's sample, or with probability `share`
// (haloShare) one around a point or sphere light (sampleHalo, media.glsl;
// each light alike), so that light scattered by the haze around a small bright
// light, a secondary source the phase function finds only by chance, is
// found as often as it matters. Its density is scatterPdf's, the mixture
// (one-sample multiple importance sampling, balance heuristic; CPU twin
// sampling::phase::sample_scatter and scatter_pdf). Every estimate that
// competes with this continuation (the equiangular and medium next-event
// estimates) weighs it by that density.
vec3 sampleScatter(Medium med, vec3 d, vec3 p, float share, inout PathSampler rng, out float pdf) {
    uint n = share > 0.0 ? haloLights() : 0u;
    float pick = sample1(rng);
    vec2 u = sample2(rng);
    vec3 wi;
    if (n == 0u || pick >= share) {
        wi = sampleHg(med.anisotropy, d, u);
    } else {
        uint k = min(uint(pick / share * float(n)), n - 1u);
        uint light = 0u;
        for (uint i = 0u; i < frame.lightCount; ++i) { LOOP_EDGE();
            if (!haloLight(i)) continue;
            light = i;
            if (k-- == 0u) break;
        }
        wi = sampleHalo(haloAxis(light, p), u);
    }
    pdf = scatterPdf(med, d, p, share, wi);
    return wi;
}

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
// equiangular estimate over the whole segment instead. `share`: the halo's
// share of the continuation from p (haloShare, sampleScatter).
vec3 mediumNextEvent(Medium med, vec3 d, vec3 p, float share, uint i, float select, inout PathSampler rng,
                     out ShadowRay sr) {
    LightSample ls = sampleLightOrEnvironment(i, p, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    float phase = hgPdf(med.anisotropy, dot(d, ls.wi));
    float tr = transmittance(med, ls.dist);
    if (tr == 0.0) return vec3(0.0);
    sr = ShadowRay(p, ls.wi, ls.dist, i);
    vec3 contribution = phase * tr * ls.radiance / select;
    if (ls.pdf == 0.0) return contribution;  // delta light
    float continuation = scatterPdf(med, d, p, share, ls.wi);
    return contribution * (powerHeuristic(ls.pdf * select, continuation) / ls.pdf);
}

// Single scattering toward positional light `i` (chosen with probability
// `select`) along the medium segment o + t d, t in [0, tEnd): a point by
// equiangular sampling, a direction by the light's sampler, weighted by
// multiple importance sampling against the path's own strategy (distance
// sampling, density σ_t T(t), then sampleScatter's direction with halo
// share `share`, that of a scattering event on this segment). Returns the
// estimate before the segment's throughput (it includes σ_s and both
// transmittances).
vec3 equiangularNextEvent(Medium med, vec3 o, vec3 d, float tEnd, float share, uint i, float select,
                          inout PathSampler rng, out ShadowRay sr) {
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
    float continuation = scatterPdf(med, d, x, share, ls.wi);
    return f * (powerHeuristic(pA, med.density * tAlong * continuation) / pA);
}

#endif
