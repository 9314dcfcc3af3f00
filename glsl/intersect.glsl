// Ray intersection with functional objects through ray queries.
//
// F'(p) = F(p) + Σ f_i max(Q_i(p), 0)³ (NOTES.md eq. 1-2), inside where F' >= 0.
// Each candidate AABB is a cell of one object that lists the perturbations
// that can be non-zero in it. Along the ray inside the cell, F and each Q_i
// are quadratics in t; the roots of the Q_i cut the segment into pieces on
// which F' is a polynomial of degree <= 6, whose first root is isolated
// exactly (roots.glsl). The f64 twin is src/geometry/reference.rs.
#ifndef INTERSECT_GLSL
#define INTERSECT_GLSL

#include "interface.glsl"
#include "roots.glsl"

float quadricAt(Quadric q, vec3 p) {
    return q.a[0] * p.x * p.x + q.a[1] * p.y * p.y + q.a[2] * p.z * p.z
         + 2.0 * (q.a[3] * p.x * p.y + q.a[4] * p.y * p.z + q.a[5] * p.x * p.z)
         + q.b[0] * p.x + q.b[1] * p.y + q.b[2] * p.z + q.c;
}

vec3 quadricGradient(Quadric q, vec3 p) {
    return 2.0 * vec3(q.a[0] * p.x + q.a[3] * p.y + q.a[5] * p.z,
                      q.a[3] * p.x + q.a[1] * p.y + q.a[4] * p.z,
                      q.a[5] * p.x + q.a[4] * p.y + q.a[2] * p.z)
         + vec3(q.b[0], q.b[1], q.b[2]);
}

// q(p + s d) = x + y s + z s² as vec3(x, y, z).
vec3 quadricAlongRay(Quadric q, vec3 p, vec3 d) {
    vec3 ad = vec3(q.a[0] * d.x + q.a[3] * d.y + q.a[5] * d.z,
                   q.a[3] * d.x + q.a[1] * d.y + q.a[4] * d.z,
                   q.a[5] * d.x + q.a[4] * d.y + q.a[2] * d.z);
    return vec3(quadricAt(q, p), 2.0 * dot(p, ad) + dot(vec3(q.b[0], q.b[1], q.b[2]), d), dot(d, ad));
}

// Roots of x + y s + z s², without cancellation; NO_ROOT where absent.
vec2 quadraticRoots(vec3 q) {
    if (q.z == 0.0) return vec2(q.y != 0.0 ? -q.x / q.y : NO_ROOT, NO_ROOT);
    float disc = q.y * q.y - 4.0 * q.z * q.x;
    if (disc < 0.0) return vec2(NO_ROOT);
    float s = -0.5 * (q.y + (q.y >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
    if (s == 0.0) return vec2(0.0);
    float r0 = s / q.z, r1 = q.x / s;
    return vec2(min(r0, r1), max(r0, r1));
}

// Adds f · q³ to c, for a quadratic q = (x, y, z).
void addCube(inout float c[7], vec3 q, float f) {
    float s0 = q.x * q.x, s1 = 2.0 * q.x * q.y, s2 = q.y * q.y + 2.0 * q.x * q.z, s3 = 2.0 * q.y * q.z, s4 = q.z * q.z;
    c[0] += f * (s0 * q.x);
    c[1] += f * (s0 * q.y + s1 * q.x);
    c[2] += f * (s0 * q.z + s1 * q.y + s2 * q.x);
    c[3] += f * (s1 * q.z + s2 * q.y + s3 * q.x);
    c[4] += f * (s2 * q.z + s3 * q.y + s4 * q.x);
    c[5] += f * (s3 * q.z + s4 * q.y);
    c[6] += f * (s4 * q.z);
}

// First t in [tlo, thi] (and inside the cell) where F' = 0 along o + t d, in
// the object's frame; NO_ROOT if none.
float cellFirstRoot(uint cellIndex, vec3 o, vec3 d, float tlo, float thi) {
    Cell cell = cells[cellIndex];
    vec3 inv = 1.0 / d;
    vec3 ta = (vec3(cell.lo[0], cell.lo[1], cell.lo[2]) - o) * inv;
    vec3 tb = (vec3(cell.hi[0], cell.hi[1], cell.hi[2]) - o) * inv;
    vec3 tmn = min(ta, tb), tmx = max(ta, tb);
    float t0 = max(max(max(tmn.x, tmn.y), tmn.z), tlo);
    float t1 = min(min(min(tmx.x, tmx.y), tmx.z), thi);
    if (!(t0 <= t1)) return NO_ROOT;

    // Breakpoints are found in s = t - tc around the segment's middle; each
    // piece's polynomial is expanded around the piece's own middle, so that
    // its coefficients stay well conditioned in f32.
    float tc = 0.5 * (t0 + t1);
    vec3 p = o + tc * d;
    float s1 = t1 - tc;
    Quadric baseQ = objects[cell.object].base;

    float sa = t0 - tc;
    for (uint piece = 0; piece <= 2u * cell.count && sa < s1; ++piece) {
        // The next breakpoint after sa: the end of this polynomial piece.
        float sb = s1;
        for (uint i = 0; i < cell.count; ++i) {
            vec2 r = quadraticRoots(quadricAlongRay(perturbations[cellLists[cell.first + i]].q, p, d));
            if (r.x > sa && r.x < sb) sb = r.x;
            if (r.y > sa && r.y < sb) sb = r.y;
        }
        float sm = 0.5 * (sa + sb);
        vec3 pm = p + sm * d;
        vec3 base = quadricAlongRay(baseQ, pm, d);
        float c[7] = float[7](base.x, base.y, base.z, 0.0, 0.0, 0.0, 0.0);
        for (uint i = 0; i < cell.count; ++i) {
            Perturbation pt = perturbations[cellLists[cell.first + i]];
            vec3 q = quadricAlongRay(pt.q, pm, d);
            if (q.x > 0.0) addCube(c, q, pt.f);
        }
        float r = firstRoot(c, sa - sm, sb - sm);
        if (r != NO_ROOT) return tc + sm + r;
        sa = sb;
    }
    return NO_ROOT;
}

// ∇F' at p (object frame), with the perturbations listed by the cell.
vec3 cellGradient(uint cellIndex, vec3 p) {
    Cell cell = cells[cellIndex];
    vec3 g = quadricGradient(objects[cell.object].base, p);
    for (uint i = 0; i < cell.count; ++i) {
        Perturbation pt = perturbations[cellLists[cell.first + i]];
        float q = quadricAt(pt.q, p);
        if (q > 0.0) g += 3.0 * pt.f * q * q * quadricGradient(pt.q, p);
    }
    return g;
}

struct SceneHit {
    float t;        // NO_ROOT on a miss
    uint object;
    vec3 normal;    // world space, outward (-∇F'), unit length
};

// The cell (index into cells[]) of the candidate or committed intersection;
// `committed` must be a literal.
#define candidateCell(rq, committed) \
    (uint(rayQueryGetIntersectionInstanceCustomIndexEXT(rq, committed)) \
     + uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, committed)))

// Runs the candidate loop: for each AABB, the first root in the cell.
void proceedFunctional(rayQueryEXT rq, float tmin, float tmax) {
    float best = tmax;
    while (rayQueryProceedEXT(rq)) {
        if (rayQueryGetIntersectionTypeEXT(rq, false) != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        vec3 oo = rayQueryGetIntersectionObjectRayOriginEXT(rq, false);
        vec3 od = rayQueryGetIntersectionObjectRayDirectionEXT(rq, false);
        float t = cellFirstRoot(candidateCell(rq, false), oo, od, tmin, best);
        if (t != NO_ROOT && t <= best) {
            best = t;
            rayQueryGenerateIntersectionEXT(rq, t);
        }
    }
}

// The closest hit of o + t d, t in [tmin, tmax] (world space).
SceneHit traceScene(vec3 o, vec3 d, float tmin, float tmax) {
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, tlas, gl_RayFlagsNoneEXT, 0xFF, o, tmin, d, tmax);
    proceedFunctional(rq, tmin, tmax);
    SceneHit h;
    h.t = NO_ROOT;
    h.object = NO_HIT;
    h.normal = vec3(0.0);
    if (rayQueryGetIntersectionTypeEXT(rq, true) == gl_RayQueryCommittedIntersectionGeneratedEXT) {
        h.t = rayQueryGetIntersectionTEXT(rq, true);
        uint cell = candidateCell(rq, true);
        h.object = cells[cell].object;
        vec3 oo = rayQueryGetIntersectionObjectRayOriginEXT(rq, true);
        vec3 od = rayQueryGetIntersectionObjectRayDirectionEXT(rq, true);
        vec3 g = cellGradient(cell, oo + h.t * od);
        mat4x3 w2o = rayQueryGetIntersectionWorldToObjectEXT(rq, true);
        vec3 n = -(transpose(mat3(w2o)) * g);
        float len = length(n);
        h.normal = len > 0.0 ? n / len : -d;
    }
    return h;
}

// True when something blocks o + t d for t in [tmin, tmax].
bool occluded(vec3 o, vec3 d, float tmin, float tmax) {
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, tlas, gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, tmin, d, tmax);
    proceedFunctional(rq, tmin, tmax);
    return rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}

#endif
