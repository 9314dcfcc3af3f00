// Ray queries over the scene's acceleration structure: each candidate box is
// a cell whose first root is searched (root_search.glsl); closest hits and
// occlusion.
#ifndef TRAVERSE_GLSL
#define TRAVERSE_GLSL

#include "root_search.glsl"
#include "hit.glsl"

// The object (instance custom index) and its cell (index into cells[]) of
// the candidate or committed intersection; `committed` must be a literal.
#define candidateObject(rq, committed) uint(rayQueryGetIntersectionInstanceCustomIndexEXT(rq, committed))
#define candidateCell(rq, object, committed) \
    (objects[object].firstCell + uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, committed)))

// Runs the candidate loop: for each AABB, the first root in the cell
// (candidateFirstRoot). The closest root of far rays is kept in f64 too,
// so that roots closer together than one f32 step of t keep their order.
// Returns the object-space point of the closest root found.
vec3 proceedFunctional(rayQueryEXT rq, float tmin, float tmax) {
    float best = tmax;
    double best64 = double(tmax);
    vec3 bestPoint = vec3(0.0);
    while (rayQueryProceedEXT(rq)) { LOOP_EDGE();
        if (rayQueryGetIntersectionTypeEXT(rq, false) != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        uint object = candidateObject(rq, false);
        vec3 point;
        bool far;
        double tref;
        float s = candidateFirstRoot(object, candidateCell(rq, object, false),
                                     rayQueryGetIntersectionObjectRayOriginEXT(rq, false),
                                     rayQueryGetIntersectionObjectRayDirectionEXT(rq, false),
                                     rayQueryGetWorldRayOriginEXT(rq), rayQueryGetWorldRayDirectionEXT(rq), tmin, best,
                                     best64, far, tref, point);
        if (s == NO_ROOT) continue;
        if (!far) {
            if (s <= best) {
                best = s;
                best64 = double(s);
                bestPoint = point;
                rayQueryGenerateIntersectionEXT(rq, s);
            }
        } else {
            // The bounds, rounded to f32 in s, may admit a root a hair
            // outside them.
            double t = max(tref + double(s), double(tmin));
            if (t <= best64) {
                best64 = t;
                best = float(t);
                bestPoint = point;
                rayQueryGenerateIntersectionEXT(rq, best);
            }
        }
    }
    return bestPoint;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space); with
// `anyHit`, any hit, with only its t and object (a shadow ray).
SceneHit traceSceneWith(vec3 o, vec3 d, float tmin, float tmax, bool anyHit) {
    rayQueryEXT rq;
    uint flags = anyHit ? gl_RayFlagsTerminateOnFirstHitEXT : gl_RayFlagsNoneEXT;
    rayQueryInitializeEXT(rq, tlas, flags, 0xFF, o, tmin, d, tmax);
    vec3 point = proceedFunctional(rq, tmin, tmax);
    SceneHit h = noHit();
    if (rayQueryGetIntersectionTypeEXT(rq, true) == gl_RayQueryCommittedIntersectionGeneratedEXT) {
        h.t = rayQueryGetIntersectionTEXT(rq, true);
        h.object = candidateObject(rq, true);
        if (anyHit) return h;
        h.cell = candidateCell(rq, h.object, true);
        h.objectPoint = point;
        completeHit(h, o, d, mat3(rayQueryGetIntersectionWorldToObjectEXT(rq, true)));
    }
    return h;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space).
SceneHit traceScene(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, false); }

// True when something blocks o + t d for t in [tmin, tmax].
bool occluded(vec3 o, vec3 d, float tmin, float tmax) {
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, tlas, gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, tmin, d, tmax);
    proceedFunctional(rq, tmin, tmax);
    return rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}

#endif
