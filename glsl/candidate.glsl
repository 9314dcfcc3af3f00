// One candidate box of a closest-hit search, shared by the backends that
// run the candidate loop in the shader (traverse.glsl with ray queries,
// traverse_compute.glsl with the project's own BVH): the first root in the
// cell (candidateFirstRoot), kept when it is closer than the closest so far.
// The closest root of far rays is kept in f64 too, so that roots closer
// together than one f32 step of t keep their order.
#ifndef CANDIDATE_GLSL
#define CANDIDATE_GLSL

#include "root_search.glsl"

// Searches cell `cell` of `object` for a root closer than `best` (`best64`
// in f64): (o, d) is the object-frame ray, (worldOrigin, worldDir) the
// world ray. Returns true when it found one and moved `best`, `best64` and
// `bestPoint` (the root's object-space point) to it.
bool closerRoot(uint object, uint cell, vec3 o, vec3 d, vec3 worldOrigin, vec3 worldDir, float tmin,
                inout float best, inout double best64, inout vec3 bestPoint) {
    vec3 point;
    bool far;
    double tref;
    float s = candidateFirstRoot(object, cell, o, d, worldOrigin, worldDir, tmin, best, best64, far, tref, point);
    if (s == NO_ROOT) return false;
    if (!far) {
        if (s > best) return false;
        best = s;
        best64 = double(s);
    } else {
        // The bounds, rounded to f32 in s, may admit a root a hair
        // outside them.
        double t = max(tref + double(s), double(tmin));
        if (t > best64) return false;
        best64 = t;
        best = float(t);
    }
    bestPoint = point;
    return true;
}

#endif
