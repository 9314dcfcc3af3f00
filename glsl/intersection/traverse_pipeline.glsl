// Tracing through a ray-tracing pipeline (the `pipeline` backend): the
// ray-generation shader calls traceRayEXT; the intersection shader
// (intersect.rint) searches each candidate box's first root with the same
// code as the ray-query path (root_search.glsl, cellFirstRoot); the
// closest-hit shader (closest_hit.rchit) returns the hit's object, cell, t,
// object-space point and transform in the payload, and the raygen shader
// finishes the hit (hit.glsl, completeHit) as the ray-query path does.
// Recursion depth 1: paths loop in the ray-generation shader.
#ifndef TRAVERSE_PIPELINE_GLSL
#define TRAVERSE_PIPELINE_GLSL

#include "root_search.glsl"
#include "hit.glsl"
#include "pipeline_payload.glsl"

// The intersection, closest-hit and miss shaders include this file for the
// shared code and the payload's layout; the tracing functions are the
// ray-generation shaders' (which define RAYGEN_SHADER).
#ifdef RAYGEN_SHADER
layout(location = 0) rayPayloadEXT HitPayload payload;

// The closest hit of o + t d, t in [tmin, tmax] (world space); with
// `anyHit`, whether anything is hit (the closest-hit shader is skipped, so
// t and object are only known to be a hit: t = tmax, object 0).
SceneHit traceSceneWith(vec3 o, vec3 d, float tmin, float tmax, bool anyHit) {
    uint flags = anyHit ? gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT : gl_RayFlagsNoneEXT;
    payload.object = 0u;
    payload.t = tmax;
    traceRayEXT(tlas, flags, 0xFF, 0, 0, 0, o, tmin, d, tmax, 0);
    SceneHit h = noHit();
    if (payload.object == NO_HIT) return h;
    h.t = payload.t;
    h.object = payload.object;
    if (anyHit) return h;
    h.cell = payload.cell;
    h.objectPoint = payload.objectPoint;
    completeHit(h, o, d, mat3(payload.worldToObject));
    return h;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space).
SceneHit traceScene(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, false); }

// True when something blocks o + t d for t in [tmin, tmax].
bool occluded(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, true).object != NO_HIT; }
#endif

#endif
