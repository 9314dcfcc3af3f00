// Lat-long environment maps, piecewise constant per texel, importance-
// sampled by luminance × sin θ with marginal and conditional CDFs built on
// the CPU; the f64 twin, src/model/sampling/envmap.rs, documents every convention:
// u = atan2(z, x) / 2π + 1/2, v = θ / π from +y; the table holds the marginal
// CDF (H + 1 entries) then each row's conditional CDF (W + 1 entries).
//
// The including shader defines the two functions declared below (where the
// table and the texels live differ by pass: the render pass's buffer and
// texture array, the CPU-twin test's buffers).
#ifndef ENVMAP_GLSL
#define ENVMAP_GLSL

#include "lights.glsl"

// Entry i of the sampling table.
float envCdfAt(uint i);
// The radiance of texel t (scale applied).
vec3 envTexelRadiance(ivec2 t);

// θ from atan(sin θ, cos θ): GLSL's acos is far less accurate (errors
// near 1e-4 rad were measured on lavapipe).
vec2 directionToUv(vec3 d) {
    return vec2(atan(d.z, d.x) / (2.0 * PI) + 0.5, atan(length(d.xz), d.y) / PI);
}

vec3 uvToDirection(vec2 uv) {
    float phi = 2.0 * PI * (uv.x - 0.5), theta = PI * uv.y;
    return vec3(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
}

ivec2 envTexelAt(vec2 uv, uint w, uint h) {
    return clamp(ivec2(floor(uv * vec2(w, h))), ivec2(0), ivec2(w, h) - 1);
}

// Probability of texel t: its row's, times its column's within the row.
float envTexelProbability(ivec2 t, uint w, uint h) {
    uint row = h + 1u + uint(t.y) * (w + 1u);
    return (envCdfAt(uint(t.y) + 1u) - envCdfAt(uint(t.y))) * (envCdfAt(row + uint(t.x) + 1u) - envCdfAt(row + uint(t.x)));
}

// The largest k in [0, n - 1] with the table's entry base + k <= u.
uint searchCdf(uint base, uint n, float u) {
    uint lo = 0u, hi = n - 1u;
    while (lo < hi) { LOOP_EDGE();
        uint mid = (lo + hi + 1u) / 2u;
        if (envCdfAt(base + mid) <= u) lo = mid; else hi = mid - 1u;
    }
    return lo;
}

// Solid-angle density of sampleEnvMap producing the unit direction d.
float envMapPdf(vec3 d, uint w, uint h) {
    float sinTheta = sqrt(d.x * d.x + d.z * d.z);  // accurate near the poles, unlike sqrt(1 - y²)
    if (sinTheta <= 0.0) return 0.0;
    return envTexelProbability(envTexelAt(directionToUv(d), w, h), w, h) * float(w * h) / (2.0 * PI * PI * sinTheta);
}

LightSample sampleEnvMap(vec2 u, uint w, uint h) {
    LightSample s = noLightSample();
    uint j = searchCdf(0u, h, u.x);
    float pRow = envCdfAt(j + 1u) - envCdfAt(j);
    uint row = h + 1u + j * (w + 1u);
    uint i = searchCdf(row, w, u.y);
    float pCol = envCdfAt(row + i + 1u) - envCdfAt(row + i);
    if (pRow <= 0.0 || pCol <= 0.0) return s;
    float fv = clamp((u.x - envCdfAt(j)) / pRow, 0.0, 1.0);
    float fu = clamp((u.y - envCdfAt(row + i)) / pCol, 0.0, 1.0);
    vec2 uv = vec2((float(i) + fu) / float(w), (float(j) + fv) / float(h));
    float sinTheta = sin(PI * uv.y);
    if (sinTheta <= 0.0) return s;
    s.wi = uvToDirection(uv);
    s.pdf = pRow * pCol * float(w * h) / (2.0 * PI * PI * sinTheta);
    s.radiance = envTexelRadiance(ivec2(i, j));
    s.valid = true;
    return s;
}

#endif
