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

// Object-frame distance of a ray's origin beyond which the object ray is
// formed in f64.
const float REBASE_DISTANCE = 64.0;

// The ray in the candidate's object frame, in f64: the world-to-object
// transform applied in f64 to the f32 world origin and direction (the
// hardware's f32 transform loses ~1e-7 of the origin's distance, 1e-3 at
// 1e4, and turns the direction by ~1e-7 rad, as much again 1e4 away).
void candidateObjectRay64(rayQueryEXT rq, out dvec3 o, out dvec3 d) {
    mat4x3 m = rayQueryGetIntersectionWorldToObjectEXT(rq, false);
    dmat3 l = dmat3(dvec3(m[0]), dvec3(m[1]), dvec3(m[2]));
    o = l * dvec3(rayQueryGetWorldRayOriginEXT(rq)) + dvec3(m[3]);
    d = l * dvec3(rayQueryGetWorldRayDirectionEXT(rq));
}

// Runs the candidate loop: for each AABB, the first root in the cell.
// Returns the object-space point of the closest root found.
vec3 proceedFunctional(rayQueryEXT rq, float tmin, float tmax) {
    float best = tmax;
    vec3 bestPoint = vec3(0.0);
    // Rays from far away (object-frame origin beyond REBASE_DISTANCE) form
    // their object ray in f64; nearer rays use the hardware's f32 object
    // ray, whose error (~1e-7 of the distance) is then below 1e-5. Cost
    // measured on lavapipe (`make bench`, one run each, alternated): 0 – 10 %
    // more time for near rays (the f64 path present in the shader).
    while (rayQueryProceedEXT(rq)) {
        if (rayQueryGetIntersectionTypeEXT(rq, false) != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        uint object = candidateObject(rq, false);
        vec3 o = rayQueryGetIntersectionObjectRayOriginEXT(rq, false);
        vec3 d = rayQueryGetIntersectionObjectRayDirectionEXT(rq, false);
        bool rebased = dot(o, o) > REBASE_DISTANCE * REBASE_DISTANCE;
        dvec3 o64 = dvec3(0.0), d64 = dvec3(0.0);
        if (rebased) {
            candidateObjectRay64(rq, o64, d64);
            o = vec3(o64);
            d = vec3(d64);
        }
        vec3 point;
        float t = cellFirstRoot(object, candidateCell(rq, object, false), o, d, rebased, o64, d64, tmin, best, point);
        if (t != NO_ROOT && t <= best) {
            best = t;
            bestPoint = point;
            rayQueryGenerateIntersectionEXT(rq, t);
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
    SceneHit h;
    h.t = NO_ROOT;
    h.object = NO_HIT;
    h.cell = 0u;
    h.normal = vec3(0.0);
    h.gradientLength = 0.0;
    h.objectPoint = vec3(0.0);
    h.worldToObject = mat3(1.0);
    h.offset = 0.0;
    if (rayQueryGetIntersectionTypeEXT(rq, true) == gl_RayQueryCommittedIntersectionGeneratedEXT) {
        h.t = rayQueryGetIntersectionTEXT(rq, true);
        h.object = candidateObject(rq, true);
        if (anyHit) return h;
        uint cell = candidateCell(rq, h.object, true);
        h.cell = cell;
        h.objectPoint = point;
        vec3 g = cellGradient(h.object, cell, h.objectPoint);
        h.worldToObject = mat3(rayQueryGetIntersectionWorldToObjectEXT(rq, true));
        vec3 n = -(transpose(h.worldToObject) * g);
        float len = length(n);
        h.normal = len > 0.0 ? n / len : -d;
        h.gradientLength = len;
        h.offset = hitOffset(o + h.t * d, cell, g, h.worldToObject);
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
