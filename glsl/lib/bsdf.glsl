// Surface scattering in a local frame whose +z is the shading normal. `wo`
// points toward the viewer (or the previous path vertex), `wi` toward the next
// vertex; both unit length. The f64 CPU twin is src/model/sampling/, and the GPU
// test of the twins is tests/sampling/sampling_gpu.rs.
#ifndef BSDF_GLSL
#define BSDF_GLSL

#include "common.glsl"
#include "media.glsl"

// Below this GGX α a lobe is treated as a perfect specular (delta) lobe.
const float ALPHA_DELTA = 1e-3;


vec3 sampleCosineHemisphere(vec2 u) {
    float r = sqrt(u.x), phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

vec3 sampleUniformSphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x;
    float r = sqrt(max(0.0, 1.0 - z * z)), phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// ---- GGX (Trowbridge-Reitz), isotropic ------------------------------------
// Walter et al., "Microfacet Models for Refraction through Rough Surfaces",
// EGSR 2007; Heitz, "Understanding the Masking-Shadowing Function in
// Microfacet-Based BRDFs", JCGT 2014 (height-correlated G2).

// D(m) = α² / (π (m.z² (α² − 1) + 1)²), with the denominator written as
// (m.x² + m.y²) + α² m.z² (equal for unit m), which does not cancel near the
// peak of a sharp lobe in f32.
float ggxD(vec3 m, float a) {
    if (m.z <= 0.0) return 0.0;
    float a2 = a * a;
    float t = (m.x * m.x + m.y * m.y) + a2 * m.z * m.z;
    return a2 / (PI * t * t);
}

// Λ(w) = (sqrt(1 + q) − 1) / 2 with q = α² tan²θ, as q / (2 (sqrt(1 + q) + 1)).
float ggxLambda(vec3 w, float a) {
    float z2 = w.z * w.z;
    if (z2 <= 0.0) return 1e30;
    // Capped: a denormal cos² would overflow q to +inf, and inf / inf is NaN.
    float q = min(a * a * (w.x * w.x + w.y * w.y) / z2, 1e30);
    return q / (2.0 * (sqrt(1.0 + q) + 1.0));
}

float ggxG1(vec3 w, float a) { return 1.0 / (1.0 + ggxLambda(w, a)); }
float ggxG2(vec3 wo, vec3 wi, float a) { return 1.0 / (1.0 + ggxLambda(wo, a) + ggxLambda(wi, a)); }

// G2(wo, wi) / G1(wo) = (1 + Λ(wo)) / (1 + Λ(wo) + Λ(wi)), the weight of a
// visible-normal sample before Fresnel. Written as one quotient it is at
// most 1 in f32 too (the denominator rounds to at least the numerator, as
// Λ ≥ 0), so a sample's weight never exceeds its bound; G2 / G1 computed
// apart can exceed 1 by a rounding step at grazing angles.
float ggxG2OverG1(vec3 wo, vec3 wi, float a) {
    float n = 1.0 + ggxLambda(wo, a);
    return n / (n + ggxLambda(wi, a));
}

// Visible normals: E. Heitz, "Sampling the GGX Distribution of Visible
// Normals", JCGT 2018. Requires wo.z > 0.
vec3 ggxSampleVisibleNormal(vec3 wo, float a, vec2 u) {
    vec3 vh = normalize(vec3(a * wo.x, a * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) / sqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x), phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi), p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(a * nh.x, a * nh.y, max(0.0, nh.z)));
}

// Density of visible normals: G1(wo) max(0, wo·m) D(m) / wo.z.
float ggxVisiblePdf(vec3 wo, vec3 m, float a) {
    return ggxG1(wo, a) * max(0.0, dot(wo, m)) * ggxD(m, a) / wo.z;
}

// ---- Fresnel ----------------------------------------------------------------

// Unpolarised dielectric Fresnel reflectance; eta = n_inside / n_outside,
// cosI < 0 when the incident direction is inside.
float fresnelDielectric(float cosI, float eta) {
    if (cosI < 0.0) {
        eta = 1.0 / eta;
        cosI = -cosI;
    }
    float sin2T = (1.0 - cosI * cosI) / (eta * eta);
    if (sin2T >= 1.0) return 1.0;
    float cosT = sqrt(1.0 - sin2T);
    float rPar = (eta * cosI - cosT) / (eta * cosI + cosT);
    float rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
    return 0.5 * (rPar * rPar + rPerp * rPerp);
}

// Exact unpolarised Fresnel reflectance of a conductor of complex index
// η + iκ (per channel), cosI in [0, 1].
vec3 fresnelConductor(float cosI, vec3 eta, vec3 k) {
    float c2 = cosI * cosI, s2 = max(0.0, 1.0 - c2);
    vec3 e2 = eta * eta, k2 = k * k;
    vec3 t0 = e2 - k2 - vec3(s2);
    vec3 a2b2 = sqrt(max(t0 * t0 + 4.0 * e2 * k2, vec3(0.0)));
    vec3 a = sqrt(max(0.5 * (a2b2 + t0), vec3(0.0)));
    vec3 t1 = a2b2 + vec3(c2);
    vec3 t2 = 2.0 * cosI * a;
    vec3 rs = (t1 - t2) / max(t1 + t2, vec3(1e-30));
    vec3 t3 = c2 * a2b2 + vec3(s2 * s2);
    vec3 t4 = t2 * s2;
    vec3 rp = rs * (t3 - t4) / max(t3 + t4, vec3(1e-30));
    return clamp(0.5 * (rp + rs), 0.0, 1.0);
}

vec3 fresnelSchlick(float cosI, vec3 f0) {
    float m = clamp(1.0 - cosI, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (vec3(1.0) - f0) * (m2 * m2 * m);
}

vec3 conductorFresnel(Material mat, float cosI) {
    return mat.fresnel == FRESNEL_SCHLICK ? fresnelSchlick(cosI, v3(mat.eta)) : fresnelConductor(cosI, v3(mat.eta), v3(mat.k));
}

// ---- BSDFs --------------------------------------------------------------------

float materialAlpha(Material mat) { return mat.roughness * mat.roughness; }

// A dielectric is rough when its α reaches ALPHA_DELTA and its index is not
// 1 (an index-matched interface is a delta transmission).
bool isRoughDielectric(Material mat) {
    return mat.kind == MATERIAL_DIELECTRIC && materialAlpha(mat) >= ALPHA_DELTA && mat.ior != 1.0;
}

// True when the material scatters only into isolated directions (no NEE).
bool isDelta(Material mat) {
    if (mat.kind == MATERIAL_MIRROR) return true;
    if (mat.kind == MATERIAL_DIELECTRIC) return !isRoughDielectric(mat);
    if (mat.kind == MATERIAL_CONDUCTOR) return materialAlpha(mat) < ALPHA_DELTA;
    return false;
}

// ---- Rough dielectric --------------------------------------------------------
// Walter, Marschner, Li, Torrance, "Microfacet Models for Refraction through
// Rough Surfaces", EGSR 2007, with visible-normal sampling. Computed in the
// "up" frame: directions mirrored through the tangent plane when wo.z < 0,
// eta = n_t / n_i (the far side's index over wo's side's). The f64 twin,
// whose documentation states every formula, is sampling::RoughDielectric.

// f (radiance convention: transmission scaled by 1 / eta²) and pdf of the
// pair (wo, wi); x: f, y: pdf.
vec2 roughDielectricEvalPdf(Material mat, vec3 wo, vec3 wi) {
    if (wo.z == 0.0 || wi.z == 0.0) return vec2(0.0);
    float s = wo.z > 0.0 ? 1.0 : -1.0;
    vec3 o = vec3(wo.xy, abs(wo.z));
    vec3 i = vec3(wi.xy, s * wi.z);
    float eta = s > 0.0 ? mat.ior : 1.0 / mat.ior;
    float a = materialAlpha(mat);
    if (i.z > 0.0) {
        vec3 h = normalize(o + i);
        float c = dot(o, h);
        if (h.z <= 0.0 || c <= 0.0) return vec2(0.0);
        float f = fresnelDielectric(c, eta);
        return vec2(f * ggxD(h, a) * ggxG2(o, i, a) / (4.0 * o.z * i.z), f * ggxVisiblePdf(o, h, a) / (4.0 * c));
    }
    vec3 hv = o + eta * i;
    float hl = length(hv);
    if (hl == 0.0) return vec2(0.0);
    vec3 h = hv / hl;
    if (h.z < 0.0) h = -h;
    float c = dot(o, h), ci = dot(i, h);
    if (h.z <= 0.0 || c <= 0.0 || ci >= 0.0) return vec2(0.0);
    float f = fresnelDielectric(c, eta);
    float den = c + eta * ci;
    float value = c * abs(ci) * (1.0 - f) * ggxG2(o, i, a) * ggxD(h, a) / (o.z * abs(i.z) * den * den);
    float pdf = (1.0 - f) * ggxVisiblePdf(o, h, a) * eta * eta * abs(ci) / (den * den);
    return vec2(value, pdf);
}

struct BsdfSample {
    vec3 wi;
    vec3 weight;   // f |cos θi| / pdf
    float pdf;     // solid angle; 0 for a delta lobe
    bool valid;
};

// No sample (valid false): what a lobe returns where it cannot sample.
BsdfSample noSample() { return BsdfSample(vec3(0.0, 0.0, 1.0), vec3(0.0), 0.0, false); }

// One function per lobe and per operation (evaluation, pdf, sampling), as the
// f64 twins in src/model/sampling/bsdf.rs have one type per lobe; bsdfEval,
// bsdfPdf and bsdfSample below pick the material's lobe.

// ---- Rough dielectric, sampling (f and pdf: roughDielectricEvalPdf above) ----
BsdfSample roughDielectricSample(Material mat, vec3 wo, vec3 u) {
    BsdfSample s = noSample();
    if (wo.z == 0.0) return s;
    float sgn = wo.z > 0.0 ? 1.0 : -1.0;
    vec3 o = vec3(wo.xy, abs(wo.z));
    float eta = sgn > 0.0 ? mat.ior : 1.0 / mat.ior;
    float a = materialAlpha(mat);
    vec3 m = ggxSampleVisibleNormal(o, a, u.xy);
    float c = dot(o, m);
    if (c <= 0.0) return s;
    float f = fresnelDielectric(c, eta);
    vec3 i;
    if (u.z < f) {
        i = 2.0 * c * m - o;
        if (i.z <= 0.0) return s;
        s.pdf = f * ggxVisiblePdf(o, m, a) / (4.0 * c);
        s.weight = vec3(ggxG2OverG1(o, i, a));
    } else {
        float sin2T = (1.0 - c * c) / (eta * eta);
        if (sin2T >= 1.0) return s;
        float cosT = sqrt(1.0 - sin2T);
        i = -o / eta + (c / eta - cosT) * m;
        if (i.z >= 0.0) return s;
        float den = c - eta * cosT;
        s.pdf = (1.0 - f) * ggxVisiblePdf(o, m, a) * eta * eta * cosT / (den * den);
        s.weight = vec3(ggxG2OverG1(o, i, a) / (eta * eta));
    }
    s.wi = vec3(i.xy, sgn * i.z);
    s.valid = s.pdf > 0.0 && !isinf(s.pdf) && !isnan(s.pdf);
    return s;
}

// ---- Smooth dielectric (sampling::SmoothDielectric): a delta lobe ------------
BsdfSample smoothDielectricSample(Material mat, vec3 wo, vec3 u) {
    BsdfSample s = noSample();
    if (wo.z == 0.0) return s;
    float f = fresnelDielectric(wo.z, mat.ior);
    if (u.z < f) {
        s.wi = vec3(-wo.x, -wo.y, wo.z);
        s.weight = vec3(1.0);
    } else {
        float etaRel = wo.z > 0.0 ? mat.ior : 1.0 / mat.ior;  // n_t / n_i
        float cosI = abs(wo.z);
        float cosT = sqrt(max(0.0, 1.0 - (1.0 - cosI * cosI) / (etaRel * etaRel)));
        float side = wo.z > 0.0 ? 1.0 : -1.0;
        s.wi = normalize(-wo / etaRel + (cosI / etaRel - cosT) * vec3(0.0, 0.0, side));
        s.weight = vec3(1.0 / (etaRel * etaRel));
    }
    s.valid = true;
    return s;
}

// ---- Mirror (sampling::Mirror): a delta lobe ---------------------------------
BsdfSample mirrorSample(Material mat, vec3 wo) {
    BsdfSample s = noSample();
    if (wo.z <= 0.0) return s;
    s.wi = vec3(-wo.x, -wo.y, wo.z);
    s.weight = v3(mat.albedo);
    s.valid = true;
    return s;
}

// ---- Conductor (sampling::Conductor): GGX, a delta lobe below ALPHA_DELTA ----
vec3 conductorEval(Material mat, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    float a = materialAlpha(mat);
    vec3 m = normalize(wo + wi);
    return conductorFresnel(mat, dot(wo, m)) * (ggxD(m, a) * ggxG2(wo, wi, a) / (4.0 * wo.z * wi.z));
}

float conductorPdf(Material mat, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
    vec3 m = normalize(wo + wi);
    return ggxVisiblePdf(wo, m, materialAlpha(mat)) / (4.0 * dot(wo, m));
}

BsdfSample conductorSample(Material mat, vec3 wo, vec3 u) {
    BsdfSample s = noSample();
    if (wo.z <= 0.0) return s;
    float a = materialAlpha(mat);
    if (a < ALPHA_DELTA) {
        s.wi = vec3(-wo.x, -wo.y, wo.z);
        s.weight = conductorFresnel(mat, wo.z);
        s.valid = true;
        return s;
    }
    vec3 m = ggxSampleVisibleNormal(wo, a, u.xy);
    float om = dot(wo, m);
    s.wi = 2.0 * om * m - wo;
    if (s.wi.z <= 0.0 || om <= 0.0) return s;
    s.pdf = ggxVisiblePdf(wo, m, a) / (4.0 * om);
    s.weight = conductorFresnel(mat, om) * ggxG2OverG1(wo, s.wi, a);
    s.valid = s.pdf > 0.0;
    return s;
}

// ---- Diffuse (sampling::Diffuse): Lambert, cosine-weighted sampling ----------
vec3 diffuseEval(Material mat, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    return v3(mat.albedo) / PI;
}

float diffusePdf(vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
    return wi.z / PI;
}

BsdfSample diffuseSample(Material mat, vec3 wo, vec3 u) {
    BsdfSample s = noSample();
    if (wo.z <= 0.0) return s;
    s.wi = sampleCosineHemisphere(u.xy);
    s.pdf = s.wi.z / PI;
    s.weight = v3(mat.albedo);
    s.valid = s.pdf > 0.0;
    return s;
}

// ---- The material's lobe -----------------------------------------------------
// f(wo, wi) (without the cosine) for non-delta lobes.
vec3 bsdfEval(Material mat, vec3 wo, vec3 wi) {
    if (isRoughDielectric(mat)) return vec3(roughDielectricEvalPdf(mat, wo, wi).x);
    if (mat.kind == MATERIAL_DIFFUSE) return diffuseEval(mat, wo, wi);
    if (mat.kind == MATERIAL_CONDUCTOR) return conductorEval(mat, wo, wi);
    return vec3(0.0);
}

// Solid-angle density of bsdfSample choosing wi (non-delta lobes).
float bsdfPdf(Material mat, vec3 wo, vec3 wi) {
    if (isRoughDielectric(mat)) return roughDielectricEvalPdf(mat, wo, wi).y;
    if (mat.kind == MATERIAL_DIFFUSE) return diffusePdf(wo, wi);
    if (mat.kind == MATERIAL_CONDUCTOR) return conductorPdf(mat, wo, wi);
    return 0.0;
}

// A direction wi for wo from the material's lobe, with its weight and pdf.
BsdfSample bsdfSample(Material mat, vec3 wo, vec3 u) {
    if (isRoughDielectric(mat)) return roughDielectricSample(mat, wo, u);
    if (mat.kind == MATERIAL_DIELECTRIC) return smoothDielectricSample(mat, wo, u);
    if (mat.kind == MATERIAL_MIRROR) return mirrorSample(mat, wo);
    if (mat.kind == MATERIAL_CONDUCTOR) return conductorSample(mat, wo, u);
    return diffuseSample(mat, wo, u);
}

#endif
