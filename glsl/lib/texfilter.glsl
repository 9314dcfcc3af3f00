// Filtered texture lookups over a footprint: an elliptical Gaussian in
// (u, v), given by its two semi-axes (1σ). Two lookups: probes along the
// major axis (probeLookup, the default: Feline's fixed probes, or one at a
// random place for a short footprint in a render) and elliptical weighted
// averaging (ewaLookup, the reference), both with a bounded anisotropy.
#ifndef TEXFILTER_GLSL
#define TEXFILTER_GLSL

#include "common.glsl"
#include "texture_maps.glsl"

struct Footprint {
    vec2 uv;
    vec2 axis1;   // semi-axes (1σ) of the Gaussian footprint in (u, v)
    vec2 axis2;
    // Random numbers in [0, 1) of the stochastic lookup: x chooses the mip
    // level (levelChoice; x < 0: the trilinear blend), y places a short
    // footprint's probe along its major axis (randomProbe; y < 0: fixed probes).
    vec2 xi;
};

// A footprint meeting a surface at grazing incidence stretches along it by
// 1 / |cos θ|, bounded at 1 / MIN_FOOTPRINT_COS (beyond 89.94°); the
// anisotropy bound below then widens the minor axis to match.
const float MIN_FOOTPRINT_COS = 1e-3;

// The longest axis of the footprint may be at most this many times the shortest.
const float MAX_ANISOTROPY = 16.0;
// An EWA lookup (the reference lookup, not the renderer's default) reads at
// most about this many texels (the level rises until it does).
const float MAX_TAPS = 1024.0;

vec4 texelWrapped(uint index, ivec2 t, int level, ivec2 size) {
    ivec2 w = ((t % size) + size) % size;
    return texelFetch(textures[nonuniformEXT(index)], w, level);
}

// What every lookup below is asked for: the bilinear reconstruction of mip
// level 0 (what `none` reads, and the reference) convolved with the
// footprint's Gaussian. Filtering a coarser level L already applies a
// kernel: level L's texels are box averages of 2^L x 2^L texels of level 0
// (resample.rs, build_mips: variance (4^L - 1)/12 per axis, in level-0
// texels), and its bilinear reconstruction is a tent of 2^L texels
// (variance 4^L / 6) where level 0's is a tent of one (1/6). A lookup
// therefore asks each level for the footprint's covariance *less* the blur
// that the level itself adds, so that jitter ⊛ footprint stays the pixel
// filter (camera.glsl, cameraJitter).

// The footprint's covariance in level-0 texels: eigenvalues l1 >= l2
// (variances along e1 and e2 = perp(e1)), the anisotropy bounded by
// widening the minor axis.
struct TexelEllipse {
    vec2 e1;
    float l1;
    float l2;
};

TexelEllipse texelEllipse(Footprint fp, vec2 s0) {
    vec2 a1 = fp.axis1 * s0, a2 = fp.axis2 * s0;
    mat2 c = outerProduct(a1, a1) + outerProduct(a2, a2);
    float tr = c[0][0] + c[1][1];
    float det = c[0][0] * c[1][1] - c[0][1] * c[1][0];
    float disc = sqrt(max(0.0, 0.25 * tr * tr - det));
    TexelEllipse el;
    el.l1 = 0.5 * tr + disc;
    el.l2 = max(0.5 * tr - disc, 0.0);
    el.e1 = abs(c[0][1]) > 1e-20 ? normalize(vec2(el.l1 - c[1][1], c[0][1]))
                                  : (c[0][0] >= c[1][1] ? vec2(1, 0) : vec2(0, 1));
    el.l2 = max(el.l2, el.l1 / (MAX_ANISOTROPY * MAX_ANISOTROPY));
    return el;
}

// The variance per axis (level-0 texels²) that a trilinear lookup at
// fractional level λ = L + w adds to level 0's bilinear one: the mixture of
// the two levels' kernels, (1 - w) V(L) + w V(L + 1), with V(L) = (4^L - 1)/4
// (box (4^L - 1)/12 plus tent 4^L/6, less level 0's tent 1/6). Its inverse
// gives the level whose kernel has variance v.
float trilinearLevel(float v) {
    float x = 4.0 * max(v, 0.0) + 1.0;  // 4^L (1 + 3w)
    float l = floor(0.5 * log2(x));
    return l + clamp((x / exp2(2.0 * l) - 1.0) / 3.0, 0.0, 1.0);
}

// Stochastic texture filtering (M. Pharr, B. Wronski, M. Salvi, M. Fajardo,
// "Filtering After Shading With Stochastic Texture Filtering", I3D 2024):
// a trilinear lookup at λ = L + w blends levels L and L + 1 with weights
// 1 - w and w; reading level L + 1 with probability w and L otherwise (xi
// uniform in [0, 1)) has the same expectation with one level's fetches.
// Every sample of a pixel draws its own xi, so the choice averages out with
// the rest of the path's noise. xi < 0 keeps the deterministic blend (the
// pixel-centre AOVs, some lookup tests).
float levelChoice(float lod, float xi) {
    if (xi < 0.0) return lod;
    float l = floor(lod);
    return xi < lod - l ? l + 1.0 : l;
}

// Most trilinear probes along the major axis of one lookup.
const int MAX_PROBES = 8;

// The fast lookup (after Feline, McCormack et al., "Feline: Fast Elliptical
// Lines for Anisotropic Texture Mapping", SIGGRAPH 1999): trilinear probes
// whose isotropic kernel has the ellipse's minor variance l2, spread along
// the major axis with Gaussian weights whose variance is the rest, l1 - l2,
// exactly (the offsets are rescaled to it). One probe for a near-isotropic
// footprint; two or more, spaced at most two probe σ apart (the sum's ripple
// stays near 1 %), up to MAX_PROBES; beyond that the minor axis widens (the
// probes' level rises) until MAX_PROBES cover the major axis. The probes
// match the Gaussian's mean and covariance, not its shape.
vec4 felineProbes(uint index, Footprint fp, TexelEllipse el, vec2 s0, float last) {
    float minor = el.l2;
    float rest = el.l1 - minor;
    // Probe σ (with the reconstruction's own) against the rest's σ: probes
    // spaced at most 2 probe σ apart over ±2 σ of the rest.
    float probeSigma = sqrt(minor + 1.0 / 6.0);
    int n = max(2, int(ceil(2.0 * sqrt(rest) / probeSigma)) + 1);
    if (n > MAX_PROBES) {
        // Widen the minor axis until MAX_PROBES suffice: 2 √(l1 - m) / √(m + 1/6) <= MAX_PROBES - 1.
        float k = 0.25 * float((MAX_PROBES - 1) * (MAX_PROBES - 1));
        minor = max(minor, (el.l1 - k / 6.0) / (1.0 + k));
        rest = el.l1 - minor;
        n = MAX_PROBES;
    }
    float lod = levelChoice(min(trilinearLevel(minor), last), fp.xi.x);
    float sigmaRest = sqrt(rest);
    float spacing = 4.0 * sigmaRest / float(n - 1);
    // Gaussian weights on the offsets, then the offsets scaled so that the
    // weighted variance is exactly `rest` (with two probes: ±σ, weights ½).
    float weights[MAX_PROBES];
    float sw = 0.0, sv = 0.0;
    for (int k = 0; k < n; ++k) { LOOP_EDGE();
        float o = (float(k) - 0.5 * float(n - 1)) * spacing;
        weights[k] = exp(-0.5 * o * o / rest);
        sw += weights[k];
        sv += weights[k] * o * o;
    }
    float stretch = sqrt(rest * sw / max(sv, 1e-30));
    vec2 step = el.e1 / s0 * (spacing * stretch);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < n; ++k) { LOOP_EDGE();
        sum += weights[k] * textureLod(textures[nonuniformEXT(index)], fp.uv + (float(k) - 0.5 * float(n - 1)) * step, lod);
    }
    return sum / sw;
}

// Φ⁻¹(p), the standard normal quantile (M. Abramowitz, I. Stegun, Handbook
// of Mathematical Functions, 26.2.23: |error| < 4.5e-4), p clamped to
// [1e-6, 1 - 1e-6] (±4.75).
float normalQuantile(float p) {
    p = clamp(p, 1e-6, 1.0 - 1e-6);
    float q = min(p, 1.0 - p);
    float t = sqrt(-2.0 * log(q));
    float x = t - (2.515517 + t * (0.802853 + t * 0.010328)) / (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308)));
    return p < 0.5 ? -x : x;
}

// One probe at a random place (stochastic texture filtering, Pharr et al.
// 2024, above) for a footprint at most about twice as long as wide (the
// rest's σ at most the probe's): the probe's isotropic kernel has the minor
// variance l2 and its offset along the major axis is drawn from the rest's
// Gaussian, Φ⁻¹(xi.y) σ_rest, so that its mean over xi is the footprint's
// exact convolution with one probe where the fixed probes take two or three.
vec4 randomProbe(uint index, Footprint fp, TexelEllipse el, vec2 s0, float last) {
    float lod = levelChoice(min(trilinearLevel(el.l2), last), fp.xi.x);
    vec2 offset = el.e1 / s0 * (sqrt(el.l1 - el.l2) * normalQuantile(fp.xi.y));
    return textureLod(textures[nonuniformEXT(index)], fp.uv + offset, lod);
}

// The renderer's lookup: one probe at the centre for a near-isotropic
// footprint (the major axis less than 5 % longer in variance), one probe at
// a random place along the major axis for one up to about twice as long as
// wide when random numbers are given (xi.y >= 0), else Feline's fixed
// probes.
vec4 probeLookup(uint index, Footprint fp) {
    vec2 s0 = vec2(textureSize(textures[nonuniformEXT(index)], 0));
    float last = float(textureQueryLevels(textures[nonuniformEXT(index)]) - 1);
    TexelEllipse el = texelEllipse(fp, s0);
    float rest = el.l1 - el.l2;
    if (rest <= 0.05 * (el.l2 + 1.0 / 6.0)) {
        return textureLod(textures[nonuniformEXT(index)], fp.uv, levelChoice(min(trilinearLevel(el.l1), last), fp.xi.x));
    }
    if (fp.xi.y >= 0.0 && rest <= el.l2 + 1.0 / 6.0) return randomProbe(index, fp, el, s0, last);
    return felineProbes(index, fp, el, s0, last);
}

// The reference lookup (`--lookup ewa`): elliptical weighted averaging
// (P. Heckbert, "Fundamentals of Texture Mapping and Image Warping", 1989)
// of the texels of one mip level with a Gaussian whose covariance is the
// footprint's, plus level 0's reconstruction (1/6), less the level's own box
// ((4^L - 1)/12): a weighted sum of a level's texels approximates the
// convolution of their box-filtered signal with the weights once the
// weights' σ is a few texels of that level (two, which picks the level). The
// level rises further until the 3σ ellipse holds at most MAX_TAPS texels
// (then the minor axis blurs more than asked); at most the last level.
vec4 ewaLookup(uint index, Footprint fp) {
    ivec2 size0 = textureSize(textures[nonuniformEXT(index)], 0);
    int levels = textureQueryLevels(textures[nonuniformEXT(index)]);
    vec2 s0 = vec2(size0);
    TexelEllipse el = texelEllipse(fp, s0);
    vec2 e2 = vec2(-el.e1.y, el.e1.x);
    float last = float(levels - 1);
    // 4^L · 49/12 <= l2 + 1/4: the weights' σ (l2 + 1/6 - (4^L - 1)/12) at
    // least two texels of the level, 2^(L+1).
    float level = clamp(floor(0.5 * log2(max((el.l2 + 0.25) * 12.0 / 49.0, 1e-8))), 0.0, last);
    while (level < last && 28.3 * sqrt((el.l1 + 0.25) * (el.l2 + 0.25)) / exp2(2.0 * level) > MAX_TAPS) { LOOP_EDGE(); level += 1.0; }
    int li = int(level);
    ivec2 size = max(size0 >> li, ivec2(1));
    if (size == ivec2(1)) return texelFetch(textures[nonuniformEXT(index)], ivec2(0), li);
    float scale = float(size.x) / s0.x;  // level texels per level-0 texel (square levels)
    float box = (exp2(2.0 * level) - 1.0) / 12.0;
    float floorVar = 0.25 * exp2(2.0 * level);  // at least ½ texel of the level
    float w1 = max(el.l1 + 1.0 / 6.0 - box, floorVar), w2 = max(el.l2 + 1.0 / 6.0 - box, floorVar);
    mat2 cl = (w1 * outerProduct(el.e1, el.e1) + w2 * outerProduct(e2, e2)) * (scale * scale);
    mat2 inv = inverse(cl);
    vec2 centre = fp.uv * vec2(size) - 0.5;
    vec2 radius = 3.0 * sqrt(vec2(cl[0][0], cl[1][1]));
    ivec2 lo = ivec2(floor(centre - radius)), hi = ivec2(ceil(centre + radius));
    vec4 sum = vec4(0.0);
    float weights = 0.0;
    for (int y = lo.y; y <= hi.y; ++y) { LOOP_EDGE();
        for (int x = lo.x; x <= hi.x; ++x) { LOOP_EDGE();
            vec2 dxy = vec2(x, y) - centre;
            float q = dot(dxy, inv * dxy);
            if (q > 9.0) continue;  // the Gaussian beyond 3σ (1% of its mass) is dropped
            float w = exp(-0.5 * q);
            sum += w * texelWrapped(index, ivec2(x, y), li, size);
            weights += w;
        }
    }
    return weights > 0.0 ? sum / weights : texelWrapped(index, ivec2(floor(centre + 0.5)), li, size);
}

// LEAN filtering of normal and displacement maps (M. Olano, D. Baker, "LEAN
// Mapping", I3D 2010): a slope-moment texel (E[sx], E[sy], E[sx²], E[sy²])
// filtered over a footprint gives the mean slope (the filtered normal) and
// the per-axis slope variance of the normals filtering averaged away. Twin:
// src/model/texture/lean.rs.
float slopeVariance(vec4 m) { return max(0.5 * (m.z - m.x * m.x + m.w - m.y * m.y), 0.0); }

// GGX α widened by a per-axis slope variance: √(α² + 2σ²) (a Beckmann lobe
// of roughness α has slope variance α²/2 per axis; variances add).
float widenedAlpha(float alpha, float variance) { return sqrt(alpha * alpha + 2.0 * max(variance, 0.0)); }

float leanAlpha(float alpha, vec4 moments) { return widenedAlpha(alpha, slopeVariance(moments)); }

#endif
