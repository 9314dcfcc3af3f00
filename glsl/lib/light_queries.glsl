// Queries about the scene's lights that need the `lights` buffer and the
// frame: which area light a ray meets first, whether a shadow ray reaches a
// light, where a positional light is. Shared by the render and volume passes.
#ifndef LIGHT_QUERIES_GLSL
#define LIGHT_QUERIES_GLSL

#include "intersect.glsl"
#include "lights.glsl"
#include "frame.glsl"

// The scene's lights (Light in gpu_structs.glsl; frame.lightCount of them).
layout(set = 0, binding = BINDING_LIGHTS, scalar) readonly buffer Lights { Light lights[]; };

// The first area light other than `except` that o + t d meets before tmax:
// its index (or frame.lightCount when none) and distance.
uint firstLightHit(vec3 o, vec3 d, float tmax, uint except, out float tHit) {
    uint which = frame.lightCount;
    tHit = tmax;
    for (uint i = 0; i < frame.lightCount; ++i) { LOOP_EDGE();
        if (i == except) continue;
        float t = lightHit(lights[i], o, d);
        if (t < tHit) {
            tHit = t;
            which = i;
        }
    }
    return which;
}

// True when no sphere or rect light other than `i` lies on the shadow ray
// before `dist` (lights are not in the acceleration structure).
bool noOtherLightInFront(vec3 origin, vec3 wi, float dist, uint i) {
    float tl;
    return firstLightHit(origin, wi, dist, i, tl) == frame.lightCount;
}

// True when nothing blocks the shadow ray from `origin` along wi over
// `dist` toward light `i`: no geometry, and no other sphere or rect light in
// front (lights are not in the acceleration structure, so they may hide
// each other).
bool lightVisible(vec3 origin, vec3 wi, float dist, uint i) {
    return !occluded(origin, wi, 0.0, dist) && noOtherLightInFront(origin, wi, dist, i);
}

// True for lights with a position (point, sphere, rect): the ones the
// equiangular estimate aims at.
bool positionalLight(uint i) { return i < frame.lightCount && lights[i].kind != LIGHT_DIRECTIONAL; }

vec3 lightCentre(uint i) {
    Light l = lights[i];
    vec3 c = v3(l.position);
    return l.kind == LIGHT_RECT ? c + 0.5 * (v3(l.edgeU) + v3(l.edgeV)) : c;
}

#endif
