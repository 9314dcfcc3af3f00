#ifndef VOLUME_GLSL
#define VOLUME_GLSL
// Shared by volume.comp (ray queries) and volume.rgen (pipeline backend).
// The volumetric-lighting pass (paper section 3): light scattered once by
// the fog toward the camera from each positional light (point, sphere,
// rect), with shadows: light shafts. For each pixel, camera rays jittered
// over the pixel filter (the render pass's Gaussian) run from the camera to the first surface (or to a sphere or
// rect light in front of it, or on to infinity); on each, per light, one
// point by equiangular sampling (media.glsl: its density follows the
// light's 1/r², so the noise does not grow near a small bright light,
// unlike distance sampling) and one by distance sampling (for large lights),
// weighted by multiple importance sampling; at each, a direction toward the
// light and one from the phase function (again weighted by multiple
// importance sampling), each with a shadow ray through the ray queries. The render pass adds the pixel's mean
// on the camera ray's first segment and leaves single scattering toward
// positional lights there out of its own estimate.
#extension GL_EXT_nonuniform_qualifier : require

#include "intersect.glsl"
#include "random.glsl"
#include "lights.glsl"


layout(set = 0, binding = BINDING_MATERIALS, scalar) readonly buffer Materials { Material materials[]; };
layout(set = 0, binding = BINDING_LIGHTS, scalar) readonly buffer Lights { Light lights[]; };

#include "frame.glsl"
#include "light_queries.glsl"

// Mean in-scattered radiance per pixel (RGB), accumulated over dispatches.
layout(set = 0, binding = BINDING_VOLUME, scalar) buffer Volume { float volume[]; };

layout(push_constant, scalar) uniform PushBlock { VolumePush pc; };

// The light from light i scattered at o + t d toward the camera, before the
// point's density: σ_s T(t) × the in-scattered radiance, whose direction
// integral is estimated by multiple importance sampling (power heuristic)
// of a direction toward the light (the light's sampler) and one from the
// phase function (area lights only; they also find the parts of a large
// light that its sampler reaches at grazing angles, with high variance).
//
// Both directions are tested in one loop, so that the shadow-ray query
// appears once in the compiled shader (Mesa inlines every call site; see
// render.comp), with the random numbers drawn in the same order.
vec3 scatteredAt(Medium fog, vec3 o, vec3 d, float t, uint i, inout uint rng) {
    vec3 x = o + t * d;
    vec3 sum = vec3(0.0);
    bool area = lights[i].kind == LIGHT_SPHERE || lights[i].kind == LIGHT_RECT;
    [[dont_unroll]] for (uint strategy = 0u; strategy < (area ? 2u : 1u); ++strategy) { LOOP_EDGE();
        vec3 wi;
        float dist;
        vec3 contribution = vec3(0.0);
        if (strategy == 0u) {
            // The light's sampler.
            LightSample ls = sampleLight(lights[i], x, rand2(rng));
            wi = ls.wi;
            dist = ls.dist;
            if (ls.valid) {
                float phase = hgPdf(fog.anisotropy, dot(d, ls.wi));
                vec3 f = transmittance(fog, ls.dist) * phase * ls.radiance;
                contribution = ls.pdf == 0.0 ? f : f * (powerHeuristic(ls.pdf, phase) / ls.pdf);
            }
        } else {
            // The phase function's sample, which weighs phase / pdf = 1.
            wi = sampleHg(fog.anisotropy, d, rand2(rng));
            dist = lightHit(lights[i], x, wi);
            if (dist != NO_ROOT) {
                float phase = hgPdf(fog.anisotropy, dot(d, wi));
                float w = powerHeuristic(phase, lightPdf(lights[i], x, wi));
                contribution = transmittance(fog, dist) * w * v3(lights[i].color);
            }
        }
        if (any(notEqual(contribution, vec3(0.0))) && lightVisible(x, wi, dist, i)) sum += contribution;
    }
    return sum * (exp(-fog.density * t) * fog.density) * v3(fog.albedo);
}

// Single scattering toward light i along the fog segment o + t d, t < tEnd,
// from two points combined by multiple importance sampling (power
// heuristic): one by equiangular sampling toward the light's centre (best
// for small lights: it follows their 1/r²) and one by distance sampling,
// density σ_t T(t) (best for large lights such as a lit wall, whose
// contribution along the ray is nearly flat).
vec3 inScattered(Medium fog, vec3 o, vec3 d, float tEnd, uint i, inout uint rng) {
    Equiangular e = equiangularSetup(o, d, tEnd, lightCentre(i));
    vec3 sum = vec3(0.0);
    // The two points in one loop: one call site of scatteredAt (above).
    [[dont_unroll]] for (uint strategy = 0u; strategy < 2u; ++strategy) { LOOP_EDGE();
        float t, weight;
        bool valid;
        if (strategy == 0u) {
            t = equiangularSample(e, rand(rng));
            float pe = equiangularPdf(e, t);
            float pd = fog.density * exp(-fog.density * t);
            valid = t >= 0.0 && t < tEnd && pe > 0.0;
            weight = powerHeuristic(pe, pd) / pe;
        } else {
            t = -log(1.0 - rand(rng)) / fog.density;
            float pd = fog.density * exp(-fog.density * t);
            valid = t < tEnd && pd > 0.0;
            weight = powerHeuristic(pd, equiangularPdf(e, t)) / pd;
        }
        if (valid) sum += scatteredAt(fog, o, d, t, i, rng) * weight;
    }
    return sum;
}

void volumePixel(uvec2 pix) {
    if (pix.x >= frame.width || pix.y >= frame.height) return;
    Medium fog = fogMedium();
    uint rng = seedRandom(pix, 0x5eed0000u + pc.firstSample, frame.seed);
    vec3 sum = vec3(0.0);
    uint side = max(uint(sqrt(float(pc.samples))), 1u);
    for (uint s = 0u; s < pc.samples; ++s) { LOOP_EDGE();
        // Stratified within a dispatch (side x side strata, then random),
        // taken to the pixel filter (the render pass's Gaussian).
        vec2 u = s < side * side ? (vec2(s % side, s / side) + rand2(rng)) / float(side) : rand2(rng);
        vec3 d = cameraRay(vec2(pix) + 0.5 + gaussianPixelOffset(u, frame.pixelSigma));
        SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
        float tl;
        firstLightHit(frame.eye, d, h.object == NO_HIT ? 1e30 : h.t, frame.lightCount, tl);
        for (uint i = 0u; i < frame.lightCount; ++i) { LOOP_EDGE();
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

#endif
