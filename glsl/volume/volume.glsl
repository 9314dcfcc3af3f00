#ifndef VOLUME_GLSL
#define VOLUME_GLSL
// Shared by volume.comp (ray queries) and volume.rgen (pipeline backend).
// The volumetric-lighting pass (paper section 3): light scattered once by
// the fog toward the camera from each positional light (point, sphere,
// rect), with shadows: light shafts. Each pass casts one camera ray per
// pixel (jittered over the pixel filter, the render pass's Gaussian) to the
// first surface (or to a sphere or rect light in front of it, or on to
// infinity) and, per light, integrates single scattering from the pass's
// point y on the light (light_map.glsl) at VOLUME_POINTS points along it:
// stratified equiangular samples toward y (Kulla & Fajardo 2012: their
// density follows y's 1/r², so the noise does not grow near the light),
// whose visibility the pass's light map answers (a shadow ray only at a
// shadow's edge). Over the passes, the points y cover the light's surface
// by area (a Hammersley set), so soft shadows converge. The render pass adds
// the pixel's mean on the camera ray's first segment and leaves single
// scattering toward positional lights there out of its own estimate.
#extension GL_EXT_nonuniform_qualifier : require

#include "intersect.glsl"
#include "random.glsl"
#include "lights.glsl"

#include "materials.glsl"

#include "frame.glsl"
#include "light_queries.glsl"

#define LIGHT_MAPS_ACCESS readonly
#include "light_map.glsl"

// Mean in-scattered radiance per pixel (RGB), accumulated over the passes.
layout(set = 0, binding = BINDING_VOLUME, scalar) buffer Volume { float volume[]; };

layout(push_constant, scalar) uniform PushBlock { VolumePush pc; };

// True when nothing blocks the segment from x to the pass's point on light
// i, dist away along wi: from the map where the texel of x's direction and
// its eight neighbours agree, else (a shadow's edge, or the map's folded
// border) by a shadow ray.
bool sharedVisible(uint i, vec3 x, vec3 wi, float dist) {
    int size = int(pc.mapSize);
    ivec2 c = ivec2(floor(octEncode(-wi) * float(size)));
    if (any(lessThan(c, ivec2(1))) || any(greaterThanEqual(c, ivec2(size - 1)))) return lightVisible(x, wi, dist, i);
    uint beyond = 0u, before = 0u;
    for (int k = 0; k < 9; ++k) { LOOP_EDGE();
        float depth = lightMaps[lightMapTexel(i, c + ivec2(k % 3 - 1, k / 3 - 1), uint(size))];
        if (depth > dist * (1.0 + LIGHT_MAP_MARGIN)) ++beyond;
        if (depth < dist * (1.0 - LIGHT_MAP_MARGIN)) ++before;
    }
    if (beyond == 9u) return true;
    if (before == 9u) return false;
    return lightVisible(x, wi, dist, i);
}

// Single scattering from the point y on light i toward the camera along
// the fog segment o + t d, t < tEnd: VOLUME_POINTS stratified equiangular
// samples toward y. What y sends to a point x at distance r along wi is the
// light's radiance × cos θ_y × area / r² (an area sample of the light;
// its intensity / r² for a point light).
vec3 inScattered(Medium fog, vec3 o, vec3 d, float tEnd, uint i, LightPoint y, inout uint rng) {
    Equiangular e = equiangularSetup(o, d, tEnd, y.p);
    float shift = rand(rng);
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < VOLUME_POINTS; ++k) { LOOP_EDGE();
        float t = equiangularSample(e, (float(k) + shift) / float(VOLUME_POINTS));
        float pt = equiangularPdf(e, t);
        if (!(t >= 0.0 && t < tEnd && pt > 0.0)) continue;
        vec3 x = o + t * d;
        vec3 toY = y.p - x;
        float r = length(toY);
        vec3 wi = toY / r;
        float geometry = 1.0 / (r * r);
        if (y.area > 0.0) geometry *= max(-dot(y.n, wi), 0.0) * y.area;
        if (!(geometry > 0.0)) continue;
        float phase = hgPdf(fog.anisotropy, dot(d, wi));
        float weight = geometry * phase * transmittance(fog, r) * exp(-fog.density * t) * fog.density / pt;
        if (sharedVisible(i, x, wi, r)) sum += weight;
    }
    return sum * v3(lights[i].color) * v3(fog.albedo) / float(VOLUME_POINTS);
}

void volumePixel(uvec2 pix) {
    if (pix.x >= frame.width || pix.y >= frame.height) return;
    Medium fog = fogMedium();
    uint rng = seedRandom(pix, 0x5eed0000u + pc.pass, frame.seed);
    // The pass's camera ray: a Hammersley set over the passes, rotated per
    // pixel (Cranley–Patterson), taken to the pixel filter (the render
    // pass's Gaussian).
    uint pixelRng = seedRandom(pix, 0x5eedcafeu, frame.seed);
    vec2 u = fract(hammersley(pc.pass, pc.passes) + rand2(pixelRng));
    vec3 d = cameraRay(vec2(pix) + 0.5 + gaussianPixelOffset(u, frame.pixelSigma));
    SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
    float tl;
    firstLightHit(frame.eye, d, h.object == NO_HIT ? 1e30 : h.t, frame.lightCount, tl);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.lightCount; ++i) { LOOP_EDGE();
        if (positionalLight(i)) sum += inScattered(fog, frame.eye, d, tl, i, passLightPoint(i, pc.pass, pc.passes), rng);
    }
    vec3 part = sum / float(max(pc.passes, 1u));
    if (any(isnan(part)) || any(isinf(part))) part = vec3(0.0);
    uint idx = pix.y * frame.width + pix.x;
    volume[3u * idx] += part.x;
    volume[3u * idx + 1u] += part.y;
    volume[3u * idx + 2u] += part.z;
}

#endif
