// Light sampling for next-event estimation, and the densities that multiple
// importance sampling needs when a BSDF-sampled ray finds a light
// (Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo
// Rendering", SIGGRAPH 1995; power heuristic). Light index `lightCount`
// stands for the uniform environment (the background radiance) when it is
// not black. The f64 CPU twin is src/model/sampling/.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL

#include "common.glsl"
#include "bsdf.glsl"



struct LightSample {
    vec3 wi;
    float dist;       // distance to the light along wi (1e30 for distant lights)
    vec3 radiance;    // radiance, or intensity / dist² for a point light, or irradiance for a directional one
    float pdf;        // solid-angle density; 0 for delta lights
    bool valid;
};

// An invalid sample, to be filled in.
LightSample noLightSample() {
    LightSample s;
    s.valid = false;
    s.pdf = 0.0;
    s.dist = 1e30;
    s.radiance = vec3(0.0);
    s.wi = vec3(0.0, 0.0, 1.0);
    return s;
}

float powerHeuristic(float a, float b) {
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

// Distance to the first intersection of o + t d (d unit) with a sphere, or NO_ROOT.
float sphereHit(vec3 o, vec3 d, vec3 c, float r) {
    vec3 oc = o - c;
    float b = dot(oc, d);
    float disc = b * b - (dot(oc, oc) - r * r);
    if (disc < 0.0) return NO_ROOT;
    float s = sqrt(disc);
    float t = -b - s;
    if (t > 0.0) return t;
    t = -b + s;
    return t > 0.0 ? t : NO_ROOT;
}

// Distance to the front (emitting) side of a rect light along o + t d, or NO_ROOT.
float rectHit(vec3 o, vec3 d, Light l) {
    vec3 c = v3(l.position), eu = v3(l.edgeU), ev = v3(l.edgeV);
    vec3 n = cross(eu, ev);
    float dn = dot(d, n);
    if (dn >= 0.0) return NO_ROOT;  // parallel, or seeing the back
    float t = dot(c - o, n) / dn;
    if (t <= 0.0) return NO_ROOT;
    vec3 q = o + t * d - c;
    float uu = dot(eu, eu), uv = dot(eu, ev), vv = dot(ev, ev);
    float qu = dot(q, eu), qv = dot(q, ev);
    float det = uu * vv - uv * uv;
    float a = (qu * vv - qv * uv) / det, b = (qv * uu - qu * uv) / det;
    return (a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0) ? t : NO_ROOT;
}

// Samples a direction toward the uniform environment of radiance `background`.
LightSample sampleEnvironment(vec3 background, vec2 u) {
    LightSample s;
    s.wi = sampleUniformSphere(u);
    s.dist = 1e30;
    s.radiance = background;
    s.pdf = 1.0 / (4.0 * PI);
    s.valid = true;
    return s;
}

// Samples a direction toward light l from x.
LightSample sampleLight(Light l, vec3 x, vec2 u) {
    LightSample s = noLightSample();
    vec3 p = v3(l.position);
    if (l.kind == LIGHT_POINT) {
        vec3 toL = p - x;
        s.dist = length(toL);
        s.wi = toL / s.dist;
        s.radiance = v3(l.color) / (s.dist * s.dist);
        s.valid = s.dist > 0.0;
    } else if (l.kind == LIGHT_DIRECTIONAL) {
        s.wi = p;
        s.radiance = v3(l.color);
        s.valid = true;
    } else if (l.kind == LIGHT_SPHERE) {
        vec3 toC = p - x;
        float d = length(toC);
        if (d <= l.radius) return s;
        // 1 − cos θmax = sin²θmax / (1 + cos θmax): no cancellation for small lights.
        float sin2Max = (l.radius * l.radius) / (d * d);
        float cosMax = sqrt(max(0.0, 1.0 - sin2Max));
        float oneMinusCosMax = sin2Max / (1.0 + cosMax);
        float v = u.x * oneMinusCosMax;  // 1 − cos α
        float cosA = 1.0 - v;
        float sinA = sqrt(max(0.0, v * (2.0 - v)));
        float phi = 2.0 * PI * u.y;
        vec3 w = toC / d;
        vec3 a = abs(w.x) > 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
        vec3 tu = normalize(cross(a, w));
        vec3 tv = cross(w, tu);
        s.wi = normalize(cosA * w + sinA * (cos(phi) * tu + sin(phi) * tv));
        s.dist = sphereHit(x, s.wi, p, l.radius);
        if (s.dist == NO_ROOT) {
            // A direction on the rim of the cone grazes the sphere: its tangent point.
            vec3 oc = x - p;
            s.dist = max(-dot(oc, s.wi), 0.0);
        }
        s.radiance = v3(l.color);
        s.pdf = 1.0 / (2.0 * PI * oneMinusCosMax);
        s.valid = true;
    } else if (l.kind == LIGHT_RECT) {
        vec3 eu = v3(l.edgeU), ev = v3(l.edgeV);
        vec3 nA = cross(eu, ev);
        float area = length(nA);
        vec3 q = p + u.x * eu + u.y * ev;
        vec3 toQ = q - x;
        s.dist = length(toQ);
        s.wi = toQ / s.dist;
        float cosL = -dot(nA / area, s.wi);
        if (cosL <= 0.0 || s.dist <= 0.0) return s;
        s.radiance = v3(l.color);
        s.pdf = s.dist * s.dist / (area * cosL);
        s.valid = true;
    }
    return s;
}

// Solid-angle density with which sampleLight(l) picks wi from x (area
// lights; 0 for delta lights).
float lightPdf(Light l, vec3 x, vec3 wi) {
    vec3 p = v3(l.position);
    if (l.kind == LIGHT_SPHERE) {
        vec3 toC = p - x;
        float d2 = dot(toC, toC);
        if (d2 <= l.radius * l.radius) return 0.0;
        float sin2Max = (l.radius * l.radius) / d2;
        float cosMax = sqrt(max(0.0, 1.0 - sin2Max));
        // Inside the cone when the ray's line passes within the radius of the
        // centre, in front: |wi × toC| <= r (precise in f32 even for tiny cones,
        // where cos θmax rounds to 1).
        vec3 c = cross(wi, toC);
        bool inside = dot(wi, toC) > 0.0 && dot(c, c) <= l.radius * l.radius;
        return inside ? 1.0 / (2.0 * PI * (sin2Max / (1.0 + cosMax))) : 0.0;
    }
    if (l.kind == LIGHT_RECT) {
        float t = rectHit(x, wi, l);
        if (t == NO_ROOT) return 0.0;
        vec3 nA = cross(v3(l.edgeU), v3(l.edgeV));
        float area = length(nA);
        return t * t / (area * -dot(nA / area, wi));
    }
    return 0.0;
}

// Distance along o + t d (d unit) to the emitting side of an area light, or
// NO_ROOT (also for point and directional lights).
float lightHit(Light l, vec3 o, vec3 d) {
    if (l.kind == LIGHT_SPHERE) return sphereHit(o, d, v3(l.position), l.radius);
    if (l.kind == LIGHT_RECT) return rectHit(o, d, l);
    return NO_ROOT;
}

#endif
