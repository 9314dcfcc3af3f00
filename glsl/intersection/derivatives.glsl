// Derivatives of F' in one cell: gradient (normals) and Hessian (curvature).
#ifndef DERIVATIVES_GLSL
#define DERIVATIVES_GLSL

#include "quadric.glsl"

// Whether perturbation k is active (Q > 0) at p (object frame): false
// outside its bounding sphere; else its quadric about its centre `pq`,
// h = p - centre, and q = Q(p).
bool perturbationActiveAt(uint k, vec3 p, out Quadric pq, out vec3 h, out float q) {
    h = p - perturbationCentre(k);
    float radius = perturbations[k].radius;
    if (radius >= 0.0 && dot(h, h) > radius * radius) return false;
    pq = perturbationQuadric(k);
    q = quadricAt(pq, h);
    return q > 0.0;
}

// ∇F' at p (object frame), with the perturbations listed by the cell.
vec3 cellGradient(uint object, uint cellIndex, vec3 p) {
    Cell cell = cells[cellIndex];
    vec3 g = quadricGradient(objects[object].base, p);
    for (uint i = 0; i < cell.count; ++i) { LOOP_EDGE();
        uint k = cellLists[cell.first + i];
        Quadric pq;
        vec3 h;
        float q;
        if (perturbationActiveAt(k, p, pq, h, q)) g += 3.0 * perturbations[k].f * q * q * quadricGradient(pq, h);
    }
    return g;
}

// Hessian of F' at p (object frame): H_F + Σ 3 f q (2 ∇q ∇qᵀ + q H_q) over
// the cell's perturbations with q > 0. Twin: FunctionalObject::hessian.
mat3 quadricHessian(Quadric q) {
    return 2.0 * mat3(q.a[0], q.a[3], q.a[5], q.a[3], q.a[1], q.a[4], q.a[5], q.a[4], q.a[2]);
}

mat3 cellHessian(uint object, uint cellIndex, vec3 p) {
    Cell cell = cells[cellIndex];
    mat3 hess = quadricHessian(objects[object].base);
    for (uint i = 0; i < cell.count; ++i) { LOOP_EDGE();
        uint k = cellLists[cell.first + i];
        Quadric pq;
        vec3 h;
        float q;
        if (perturbationActiveAt(k, p, pq, h, q)) {
            vec3 g = quadricGradient(pq, h);
            hess += (3.0 * perturbations[k].f * q) * (2.0 * outerProduct(g, g) + q * quadricHessian(pq));
        }
    }
    return hess;
}

#endif
