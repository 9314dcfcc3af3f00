// A hit on the scene: what shading needs, the offset of secondary rays off
// the surface, and the surface's shape operator.
#ifndef HIT_GLSL
#define HIT_GLSL

#include "derivatives.glsl"

struct SceneHit {
    float t;             // NO_ROOT on a miss
    uint object;
    uint cell;           // index into cells[] of the hit's cell
    vec3 normal;         // world space, outward (-∇F'), unit length
    float gradientLength;  // |∇F'| in world units (0 on a miss)
    vec3 objectPoint;    // the hit in the object's frame
    mat3 worldToObject;  // linear part of the world-to-object transform
    float offset;        // how far secondary rays start off the surface (world units)
};

// How far along the normal a secondary ray must start from a hit at `p`
// (world, camera-relative) to stay off its own surface: more than the hit
// point's error along the normal, which has two parts (docs/stability.md,
// "Secondary-ray offsets"):
// - the f32 world position: a few ulps of its largest coordinate
//   (OFFSET_WORLD = 1e-6 is about 8 ulps);
// - the root found in the object frame: a small fraction of the cell's
//   width along the normal, since the root's error along the ray is a
//   fraction of the chord through the cell, whose component along the
//   normal is at most that width (OFFSET_CELL = 1e-4).
// A fixed 2e-4 · max(|p|, 1) before lost contact shadows of objects smaller
// than ~1e-3 of their distance, or of objects smaller than 1e-3 units.
const float OFFSET_WORLD = 1e-6;
const float OFFSET_CELL = 1e-4;

float hitOffset(vec3 p, uint cellIndex, vec3 objectNormal, mat3 worldToObject) {
    Cell cell = cells[cellIndex];
    vec3 extent = vec3(cell.hi[0], cell.hi[1], cell.hi[2]) - vec3(cell.lo[0], cell.lo[1], cell.lo[2]);
    // The cell's width along the normal in the object frame (its diagonal
    // where the gradient vanishes), in world units through the
    // object-to-world map's largest stretch (an upper bound).
    float g = length(objectNormal);
    float width = g > 0.0 ? dot(abs(objectNormal / g), extent) : length(extent);
    mat3 objectToWorld = inverse(worldToObject);
    float stretch = max(max(length(objectToWorld[0]), length(objectToWorld[1])), length(objectToWorld[2]));
    float far = max(max(abs(p.x), abs(p.y)), abs(p.z));
    return OFFSET_WORLD * far + OFFSET_CELL * width * stretch;
}

// Offset along the geometric normal by `offset` (`SceneHit::offset`), to the
// side of `dir`.
vec3 offsetOrigin(vec3 p, vec3 n, vec3 dir, float offset) {
    return p + (dot(dir, n) >= 0.0 ? n : -n) * offset;
}


// The shape operator of the surface at a hit (the derivative of the outward
// unit normal along the surface, positive on a convex bump) in the tangent
// basis (t1, t2), world units: S_ij = -t_iᵀ Mᵀ H M t_j / |Mᵀ ∇F'| with M the
// world-to-object map (F'(M p + c) in world space). Exact: the analytic
// Hessian of F'. Twin: FunctionalObject::curvatures.
mat2 shapeOperator(SceneHit h, vec3 t1, vec3 t2) {
    float len = h.gradientLength;
    if (len == 0.0) return mat2(0.0);
    mat3 hess = cellHessian(h.object, h.cell, h.objectPoint);
    vec3 a = h.worldToObject * t1, b = h.worldToObject * t2;
    float s11 = -dot(a, hess * a) / len, s12 = -dot(a, hess * b) / len, s22 = -dot(b, hess * b) / len;
    return mat2(s11, s12, s12, s22);
}

// A miss.
SceneHit noHit() {
    SceneHit h;
    h.t = NO_ROOT;
    h.object = NO_HIT;
    h.cell = 0u;
    h.normal = vec3(0.0);
    h.gradientLength = 0.0;
    h.objectPoint = vec3(0.0);
    h.worldToObject = mat3(1.0);
    h.offset = 0.0;
    return h;
}

// The rest of a closest hit of o + t d, given its t, object, cell and
// object-space point: the world normal from the gradient of F', and the
// secondary-ray offset. Both backends (traverse.glsl, traverse_pipeline.glsl)
// finish their hits here.
void completeHit(inout SceneHit h, vec3 o, vec3 d, mat3 worldToObject) {
    vec3 g = cellGradient(h.object, h.cell, h.objectPoint);
    h.worldToObject = worldToObject;
    vec3 n = -(transpose(h.worldToObject) * g);
    float len = length(n);
    h.normal = len > 0.0 ? n / len : -d;
    h.gradientLength = len;
    h.offset = hitOffset(o + h.t * d, h.cell, g, h.worldToObject);
}

#endif
