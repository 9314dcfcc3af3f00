// Quadrics along rays: F and the perturbations' Q_i evaluated at a point and
// restricted to a ray (quadratics in t), and the pieces of a segment on which
// a perturbation is active (Q_i > 0). Part of the intersection (intersect.glsl).
#ifndef QUADRIC_GLSL
#define QUADRIC_GLSL

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

// First root of x + y s + z s² in [lo, hi] (closed form), or NO_ROOT.
float quadraticFirstRoot(vec3 q, float lo, float hi) {
    vec2 r = quadraticRoots(q);
    if (r.x >= lo && r.x <= hi) return r.x;
    if (r.y >= lo && r.y <= hi) return r.y;
    return NO_ROOT;
}

// The range (min, max) of x + y s + z s² over [lo, hi].
vec2 quadraticRange(vec3 q, float lo, float hi) {
    float a = q.x + lo * (q.y + lo * q.z), b = q.x + hi * (q.y + hi * q.z);
    vec2 r = vec2(min(a, b), max(a, b));
    if (q.z != 0.0) {
        float v = -q.y / (2.0 * q.z);
        if (v > lo && v < hi) {
            float m = q.x + v * (q.y + v * q.z);
            r = vec2(min(r.x, m), max(r.y, m));
        }
    }
    return r;
}

// True when x + y s + z s² > 0 somewhere in [lo, hi].
bool positiveSomewhere(vec3 q, float lo, float hi) {
    if (q.x + lo * (q.y + lo * q.z) > 0.0 || q.x + hi * (q.y + hi * q.z) > 0.0) return true;
    if (q.z >= 0.0) return false;
    float v = -q.y / (2.0 * q.z);
    return v > lo && v < hi && q.x + v * (q.y + v * q.z) > 0.0;
}

// Perturbation k's quadric about its centre (gpu_structs.glsl, Perturbation):
// Q(p) = quadricAt(perturbationQuadric(k), p - perturbationCentre(k)).
Quadric perturbationQuadric(uint k) {
    bool bounded = perturbations[k].radius >= 0.0;
    vec3 linear = bounded ? vec3(0.0) : v3(perturbations[k].centreOrLinear);
    return Quadric(perturbations[k].a, float[3](linear.x, linear.y, linear.z), perturbations[k].c);
}

vec3 perturbationCentre(uint k) {
    return perturbations[k].radius >= 0.0 ? v3(perturbations[k].centreOrLinear) : vec3(0.0);
}

// True when perturbation k is non-zero somewhere on p + s d, s in [lo, hi]:
// first a cheap test against its bounding sphere, then its quadric, whose
// restriction to the ray it returns in `q`.
bool perturbationOnSegment(uint k, vec3 p, vec3 d, float lo, float hi, out vec3 q) {
    vec3 h = p - perturbationCentre(k);
    float radius = perturbations[k].radius;
    q = vec3(0.0);
    if (radius >= 0.0) {
        float dd = dot(d, d), b = dot(h, d);
        float disc = b * b - dd * (dot(h, h) - radius * radius);
        if (disc < 0.0) return false;
        float sq = sqrt(disc);
        if ((-b + sq) < lo * dd || (-b - sq) > hi * dd) return false;
    }
    q = quadricAlongRay(perturbationQuadric(k), h, d);
    return positiveSomewhere(q, lo, hi);
}

// Perturbations of one cell that are positive somewhere on the ray segment;
// only they cut the segment into pieces and add terms to F'. Their
// restrictions to the ray are kept in registers.
const uint MAX_RELEVANT = 8u;

// q(s) re-expanded around s = m: q(m + u) as a quadratic in u.
vec3 shiftQuadratic(vec3 q, float m) {
    return vec3(q.x + m * (q.y + m * q.z), q.y + 2.0 * m * q.z, q.z);
}

// Restriction of perturbation k to p + s d.
vec3 perturbationAlongRay(uint k, vec3 p, vec3 d) {
    return quadricAlongRay(perturbationQuadric(k), p - perturbationCentre(k), d);
}

#endif
