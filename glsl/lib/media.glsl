// Homogeneous participating media with the Henyey–Greenstein phase function
// (CPU twin: src/model/sampling/phase.rs). A path travelling along d scatters into
// w with density p(d · w); distances to the next interaction are sampled
// exactly from the transmittance exp(−σ_t t) (σ_t is grey, so the weight of
// a scattering event is the single-scattering albedo and that of passing
// through is 1).
#ifndef MEDIA_GLSL
#define MEDIA_GLSL

#include "common.glsl"
#include "gpu_structs.glsl"


const float HG_ISOTROPIC = 1e-3;
const float HG_MAX_G = 0.99;

float hgPdf(float g, float cosTheta) {
    g = clamp(g, -HG_MAX_G, HG_MAX_G);
    float denom = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(denom));
}

// A scattered direction for a path travelling along d, from u in [0, 1)².
vec3 sampleHg(float g, vec3 d, vec2 u) {
    g = clamp(g, -HG_MAX_G, HG_MAX_G);
    float cosTheta;
    if (abs(g) < HG_ISOTROPIC) {
        cosTheta = 1.0 - 2.0 * u.x;
    } else {
        float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
        cosTheta = clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
    }
    float sinTheta = sqrt(max(0.0, 1.0 - cosTheta * cosTheta));
    float phi = 2.0 * PI * u.y;
    mat3 f = frameAround(d);
    return normalize(f[0] * (sinTheta * cos(phi)) + f[1] * (sinTheta * sin(phi)) + d * cosTheta);
}

// The halo strategy of a scattering event in a medium (nee.glsl,
// sampleScatter; CPU twin: sampling::phase::sample_halo, halo_pdf,
// HALO_SHARE, the largest share of the mixture): θ, the angle to
// the axis a toward a light's centre, with density ∝ π − θ, φ uniform; its
// solid-angle density (π − θ) / (π³ sin θ) has the shape of a small light's
// single-scattering halo seen from the point (the airlight integral
// (π − θ) / (D sin θ); Sun et al. 2005), so directions whose segment passes
// close to the light, where that segment's equiangular estimate is large,
// are sampled as often as they matter (the fireflies of multiple
// scattering in haze).
const float HALO_SHARE = 0.5;

vec3 sampleHalo(vec3 a, vec2 u) {
    float theta = PI * (1.0 - sqrt(max(0.0, 1.0 - u.x)));
    float phi = 2.0 * PI * u.y;
    mat3 f = frameAround(a);
    return normalize(f[0] * (sin(theta) * cos(phi)) + f[1] * (sin(theta) * sin(phi)) + a * cos(theta));
}

float haloPdf(vec3 a, vec3 w) {
    float sinTheta = length(cross(a, w));
    float theta = atan(sinTheta, dot(a, w));
    return (PI - theta) / (PI * PI * PI * max(sinTheta, 1e-12));
}

// Transmittance over a distance (grey).
float transmittance(Medium m, float dist) { return m.density > 0.0 ? exp(-m.density * dist) : 1.0; }

// Equiangular sampling of a point on the segment o + t d, t in [0, tMax],
// toward a point c (a light's centre): density ∝ 1 / (h² + (t − Δ)²), the
// inverse squared distance to c, which cancels the 1/r² falloff of a small
// light's contribution (C. Kulla, M. Fajardo, "Importance Sampling
// Techniques for Path Tracing in Participating Media", EGSR 2012). Chosen
// over distance sampling for single scattering toward positional lights:
// its noise does not grow near a bright light. The distance h is bounded
// below (a light on the ray's line) so that the density stays finite; the
// sampler and its density use the same h, so the estimate stays unbiased.
struct Equiangular {
    float delta;   // Δ: t of the point of the line closest to c
    float h;       // distance from c to the line
    float thetaA;  // angles, seen from c, of the segment's ends
    float thetaB;
};

Equiangular equiangularSetup(vec3 o, vec3 d, float tMax, vec3 c) {
    Equiangular e;
    e.delta = dot(c - o, d);
    e.h = max(length(c - o - e.delta * d), 1e-4 * max(1.0, abs(e.delta)));
    e.thetaA = atan(-e.delta, e.h);
    e.thetaB = atan(tMax - e.delta, e.h);
    return e;
}

float equiangularSample(Equiangular e, float u) { return e.delta + e.h * tan(mix(e.thetaA, e.thetaB, u)); }

float equiangularPdf(Equiangular e, float t) {
    float x = t - e.delta;
    float span = e.thetaB - e.thetaA;
    return span > 0.0 ? e.h / (span * (e.h * e.h + x * x)) : 0.0;
}

#endif
