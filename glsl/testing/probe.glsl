// Traces a list of world-space rays and writes the closest hit of each:
// the GPU side of the GPU-vs-CPU geometry tests and of the ray benchmark.
// Both backends run it: probe.comp (ray queries) and probe.rgen (pipeline).
#ifndef PROBE_GLSL
#define PROBE_GLSL

#include "intersect.glsl"

layout(set = 0, binding = BINDING_PROBE_RAYS, scalar) readonly buffer Rays { Ray rays[]; };
layout(set = 0, binding = BINDING_PROBE_HITS, scalar) writeonly buffer Hits { Hit hits[]; };

// PROBE_CURVATURE: 1 to write the curvatures (the geometry tests), 0 to
// skip their Hessian (the ray benchmark times intersection alone).
#include "spec_constants.glsl"

layout(push_constant, scalar) uniform PushBlock { ProbePush pc; };

// Probes ray `pc.first + local`, if `local` < `pc.count`.
void probeRay(uint local) {
    uint i = pc.first + local;
    if (local >= pc.count) return;
    Ray r = rays[i];
    vec3 o = vec3(r.origin[0], r.origin[1], r.origin[2]);
    vec3 d = vec3(r.dir[0], r.dir[1], r.dir[2]);
    SceneHit h = traceScene(o, d, r.tmin, r.tmax);
    Hit outHit;
    outHit.t = h.t;
    outHit.normal = float[3](h.normal.x, h.normal.y, h.normal.z);
    outHit.object = h.object;
    outHit.meanCurvature = 0.0;
    outHit.gaussCurvature = 0.0;
    if (PROBE_CURVATURE != 0u && h.object != NO_HIT) {
        mat3 f = frameAround(h.normal);
        mat2 s = shapeOperator(h, f[0], f[1]);
        outHit.meanCurvature = 0.5 * (s[0][0] + s[1][1]);
        outHit.gaussCurvature = determinant(s);
    }
    outHit.objectPoint = float[3](h.objectPoint.x, h.objectPoint.y, h.objectPoint.z);
    hits[i] = outHit;
}

#endif
