// Texture coordinates on implicit surfaces. Each object maps its own frame
// to (u, v) (planar, spherical or cylindrical, then scale and offset), with
// the analytic gradients ∇u, ∇v that the tangent frame (normal and bump
// mapping) and the filter footprints need. The CPU twin is src/model/geometry/uv.rs.
#ifndef UV_GLSL
#define UV_GLSL

#include "interface.glsl"
#include "bsdf.glsl"

const float UV_PI = 3.14159265358979;

struct SurfaceUv {
    vec2 uv;
    vec3 gradU;   // ∇u in the object frame
    vec3 gradV;   // ∇v in the object frame
};

// (u, v) and their gradients at p (object frame) for an object's mapping.
SurfaceUv objectUv(Object obj, vec3 p) {
    SurfaceUv s;
    if (obj.uvMapping == UV_PLANAR) {
        s.gradU = v3(obj.uAxis);
        s.gradV = v3(obj.vAxis);
        s.uv = vec2(dot(p, s.gradU), dot(p, s.gradV));
    } else {
        // Azimuth around +y, 0 along +x, turning toward +z.
        float rho2 = max(p.x * p.x + p.z * p.z, 1e-30);
        float rho = sqrt(rho2);
        s.uv.x = atan(p.z, p.x) / (2.0 * UV_PI) + 0.5;
        s.gradU = vec3(-p.z, 0.0, p.x) / (2.0 * UV_PI * rho2);
        if (obj.uvMapping == UV_SPHERICAL) {
            // Polar angle from +y: v = acos(y / r) / π.
            float r2 = max(dot(p, p), 1e-30);
            s.uv.y = atan(rho, p.y) / UV_PI;  // more accurate in f32 than acos(y / r)
            s.gradV = -(vec3(0.0, 1.0, 0.0) - p * (p.y / r2)) / (UV_PI * rho);
        } else {
            s.uv.y = p.y;
            s.gradV = vec3(0.0, 1.0, 0.0);
        }
    }
    s.uv = s.uv * obj.uvScale + obj.uvOffset;
    s.gradU *= obj.uvScale.x;
    s.gradV *= obj.uvScale.y;
    return s;
}

// Tangents ∂p/∂u and ∂p/∂v in the tangent plane of unit normal n, from the
// world-space gradients of u and v: the solution of [∇u; ∇v; n] X = [I; 0].
void tangentsFromGradients(vec3 gu, vec3 gv, vec3 n, out vec3 dpdu, out vec3 dpdv) {
    mat3 m = transpose(mat3(gu, gv, n));  // rows ∇u, ∇v, n
    float det = determinant(m);
    if (abs(det) < 1e-20) {
        // Degenerate mapping (a pole, or a planar mapping seen edge on).
        mat3 f = frameAround(n);
        dpdu = f[0];
        dpdv = f[1];
        return;
    }
    mat3 inv = inverse(m);
    dpdu = inv[0];
    dpdv = inv[1];
}

#endif
