// Filtered texture lookups over a footprint: an elliptical Gaussian in
// (u, v), given by its two semi-axes (1σ), integrated by elliptical weighted
// averaging (P. Heckbert, "Fundamentals of Texture Mapping and Image
// Warping", 1989) over the mip level where the ellipse spans a few texels,
// with a bounded number of taps and a bounded anisotropy. The including
// shader declares `sampler2D textures[]` first.
#ifndef TEXFILTER_GLSL
#define TEXFILTER_GLSL

struct Footprint {
    vec2 uv;
    vec2 axis1;   // semi-axes (1σ) of the Gaussian footprint in (u, v)
    vec2 axis2;
};

// A footprint meeting a surface at grazing incidence stretches along it by
// 1 / |cos θ|, bounded at 1 / MIN_FOOTPRINT_COS (beyond 89.94°); the
// anisotropy bound below then widens the minor axis to match.
const float MIN_FOOTPRINT_COS = 1e-3;

// The longest axis of the footprint may be at most this many times the shortest.
const float MAX_ANISOTROPY = 16.0;
// A lookup reads at most about this many texels (the level rises until it does).
const float MAX_TAPS = 64.0;

vec4 texelWrapped(uint index, ivec2 t, int level, ivec2 size) {
    ivec2 w = ((t % size) + size) % size;
    return texelFetch(textures[nonuniformEXT(index)], w, level);
}

vec4 ewaLookup(uint index, Footprint fp) {
    ivec2 size0 = textureSize(textures[nonuniformEXT(index)], 0);
    int levels = textureQueryLevels(textures[nonuniformEXT(index)]);
    vec2 s0 = vec2(size0);
    // Covariance of the footprint in level-0 texels.
    vec2 a1 = fp.axis1 * s0, a2 = fp.axis2 * s0;
    mat2 c = outerProduct(a1, a1) + outerProduct(a2, a2);
    // Eigen-decomposition of the symmetric 2x2 matrix.
    float tr = c[0][0] + c[1][1];
    float det = c[0][0] * c[1][1] - c[0][1] * c[1][0];
    float disc = sqrt(max(0.0, 0.25 * tr * tr - det));
    float l1 = 0.5 * tr + disc, l2 = max(0.5 * tr - disc, 0.0);
    vec2 e1 = abs(c[0][1]) > 1e-20 ? normalize(vec2(l1 - c[1][1], c[0][1])) : (c[0][0] >= c[1][1] ? vec2(1, 0) : vec2(0, 1));
    vec2 e2 = vec2(-e1.y, e1.x);
    // Bound the anisotropy by widening the minor axis.
    l2 = max(l2, l1 / (MAX_ANISOTROPY * MAX_ANISOTROPY));
    float sigmaMinor = sqrt(l2), sigmaMajor = sqrt(l1);
    // The level where the minor axis spans about two texels (one more would
    // add the level's own blur, a box of 2^level texels and the σ = ½ texel
    // reconstruction, in a proportion that visibly over-blurs), raised until
    // the 3σ ellipse holds at most MAX_TAPS texels; at most the last level.
    float last = float(levels - 1);
    float level = clamp(floor(log2(max(sigmaMinor, 1e-8))) - 1.0, 0.0, last);
    while (level < last && 28.3 * sigmaMajor * sigmaMinor / exp2(2.0 * level) > MAX_TAPS) level += 1.0;
    int li = int(level);
    ivec2 size = max(size0 >> li, ivec2(1));
    if (size == ivec2(1)) return texelFetch(textures[nonuniformEXT(index)], ivec2(0), li);
    float scale = float(size.x) / s0.x;  // level texels per level-0 texel (square levels)
    // Covariance at this level, plus the reconstruction filter (σ = 1/2 texel).
    mat2 cl = (l1 * outerProduct(e1, e1) + l2 * outerProduct(e2, e2)) * (scale * scale) + mat2(0.25);
    mat2 inv = inverse(cl);
    vec2 centre = fp.uv * vec2(size) - 0.5;
    vec2 radius = 3.0 * sqrt(vec2(cl[0][0], cl[1][1]));
    ivec2 lo = ivec2(floor(centre - radius)), hi = ivec2(ceil(centre + radius));
    vec4 sum = vec4(0.0);
    float weights = 0.0;
    for (int y = lo.y; y <= hi.y; ++y) {
        for (int x = lo.x; x <= hi.x; ++x) {
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
// src/texture/lean.rs.
float slopeVariance(vec4 m) { return max(0.5 * (m.z - m.x * m.x + m.w - m.y * m.y), 0.0); }

// GGX α widened by a per-axis slope variance: √(α² + 2σ²) (a Beckmann lobe
// of roughness α has slope variance α²/2 per axis; variances add).
float widenedAlpha(float alpha, float variance) { return sqrt(alpha * alpha + 2.0 * max(variance, 0.0)); }

float leanAlpha(float alpha, vec4 moments) { return widenedAlpha(alpha, slopeVariance(moments)); }

#endif
