// The material at a hit with its texture maps applied (render.glsl):
// colour, roughness, normal and displacement maps looked up over the
// path's footprint (texfilter.glsl; LEAN on glossy lobes), and the shading
// normal they give.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

#include "render_inputs.glsl"
#include "path_footprint.glsl"

// A texture lookup over a footprint; FILTER_NONE ignores the footprint.
vec4 lookup(uint index, Footprint fp) {
    if (FILTER_MODE == FILTER_NONE) return mapAt(index, fp.uv);
    return LOOKUP_MODE == LOOKUP_EWA ? ewaLookup(index, fp) : probeLookup(index, fp);
}

// Height of a displacement map and its derivatives in (u, v), by central
// differences one texel apart.
vec3 heightAndSlopes(uint index, vec2 uv) {
    vec2 texel = 1.0 / vec2(textureSize(textures[nonuniformEXT(index)], 0));
    float h = mapAt(index, uv).r;
    float dhdu = (mapAt(index, uv + vec2(texel.x, 0.0)).r - mapAt(index, uv - vec2(texel.x, 0.0)).r) / (2.0 * texel.x);
    float dhdv = (mapAt(index, uv + vec2(0.0, texel.y)).r - mapAt(index, uv - vec2(0.0, texel.y)).r) / (2.0 * texel.y);
    return vec3(h, dhdu, dhdv);
}

// The material at a hit with its texture maps applied, and the shading normal
// (outward, tilted by the normal and displacement maps). `d` is the ray's
// direction and `hf` the ray's footprint on the surface (its covariance in
// world units, in the basis hf.t1, hf.t2): texture lookups average over it.
Material surfaceAt(SceneHit h, vec3 d, HitFootprint hf, out vec3 shadingNormal) {
    Object obj = objects[h.object];
    Material mat = materials[obj.material];
    shadingNormal = h.normal;
    if (mat.albedoMap == NO_TEXTURE && mat.normalMap == NO_TEXTURE && mat.roughnessMap == NO_TEXTURE
        && mat.displacementMap == NO_TEXTURE) {
        return mat;
    }
    SurfaceUv s = objectUv(obj, h.objectPoint);
    // World-space gradients of u and v.
    vec3 n = h.normal;
    vec3 gu = transpose(h.worldToObject) * s.gradU;
    vec3 gv = transpose(h.worldToObject) * s.gradV;
    // The footprint mapped to (u, v): with footprint = L Lᵀ (Cholesky), the
    // columns of L, taken through the Jacobian [∇u; ∇v] on (t1, t2), are
    // semi-axes whose outer products sum to the footprint's covariance in (u, v).
    Footprint fp;
    fp.uv = s.uv;
    mat2 footprint = hf.footprint;
    vec3 t1 = hf.t1, t2 = hf.t2;
    float l11 = sqrt(max(footprint[0][0], 0.0));
    float l21 = l11 > 0.0 ? footprint[0][1] / l11 : 0.0;
    float l22 = sqrt(max(footprint[1][1] - l21 * l21, 0.0));
    vec3 w1 = t1 * l11 + t2 * l21, w2 = t2 * l22;
    fp.axis1 = vec2(dot(gu, w1), dot(gv, w1));
    fp.axis2 = vec2(dot(gu, w2), dot(gv, w2));
    if (mat.albedoMap != NO_TEXTURE) {
        fp.xi = nextLookupXi(hf);
        vec3 a = v3(mat.albedo) * lookup(mat.albedoMap, fp).rgb;
        mat.albedo = float[3](a.x, a.y, a.z);
    }
    fp.xi = nextLookupXi(hf);
    if (mat.roughnessMap != NO_TEXTURE) mat.roughness = clamp(lookup(mat.roughnessMap, fp).r, 0.0, 1.0);
    if (mat.normalMap == NO_TEXTURE && mat.displacementMap == NO_TEXTURE) return mat;
    vec3 dpdu, dpdv;
    tangentsFromGradients(gu, gv, n, dpdu, dpdv);
    // Filtered modes read the maps' slope moments over the footprint (LEAN)
    // on glossy lobes: the mean slope bends the normal, the variance widens
    // the lobe, which is how a glossy lobe averages over the normals in the
    // footprint. A Lambert or mirror lobe has no roughness to take the
    // variance, and shading with the mean normal would filter before the
    // (nonlinear) shading: it reads the normal at the footprint's centre.
    bool lean = FILTER_MODE != FILTER_NONE && (mat.kind == MATERIAL_CONDUCTOR || mat.kind == MATERIAL_DIELECTRIC);
    float slopeVar = 0.0;
    if (mat.displacementMap != NO_TEXTURE) {
        // Bump mapping: the normal of p + scale · height(u, v) · n.
        vec2 slopes;
        if (lean) {
            fp.xi = nextLookupXi(hf);
            vec4 m = lookup(mat.displacementMoments, fp);
            slopes = m.xy * mat.displacementScale;
            // World slopes are uv slopes over |∂p/∂u|, |∂p/∂v|.
            float su = dot(dpdu, dpdu), sv = dot(dpdv, dpdv);
            float vu = su > 0.0 ? max(m.z - m.x * m.x, 0.0) / su : 0.0;
            float vv = sv > 0.0 ? max(m.w - m.y * m.y, 0.0) / sv : 0.0;
            slopeVar += 0.5 * (vu + vv) * mat.displacementScale * mat.displacementScale;
        } else {
            slopes = heightAndSlopes(mat.displacementMap, s.uv).yz * mat.displacementScale;
        }
        vec3 bent = cross(dpdu + slopes.x * n, dpdv + slopes.y * n);
        float len = length(bent);
        if (len > 0.0) n = dot(bent, n) >= 0.0 ? bent / len : -bent / len;
    }
    if (mat.normalMap != NO_TEXTURE) {
        vec3 c;
        if (lean) {
            fp.xi = nextLookupXi(hf);
            vec4 m = lookup(mat.normalMoments, fp);
            c = normalize(vec3(-m.x, -m.y, 1.0));
            slopeVar += slopeVariance(m);
        } else {
            c = mapAt(mat.normalMap, fp.uv).rgb * 2.0 - 1.0;
        }
        vec3 t = dpdu - n * dot(n, dpdu);
        float tl = length(t);
        mat3 f = frameAround(n);
        t = tl > 0.0 ? t / tl : f[0];
        vec3 b = cross(n, t);
        if (dot(b, dpdv) < 0.0) b = -b;
        vec3 m = c.x * t + c.y * b + c.z * n;
        float ml = length(m);
        if (ml > 0.0) n = m / ml;
    }
    // The normals that filtering averaged away widen a glossy lobe (Lambert
    // is unchanged; a perfect mirror stays a delta lobe).
    if (slopeVar > 0.0 && (mat.kind == MATERIAL_CONDUCTOR || mat.kind == MATERIAL_DIELECTRIC)) {
        mat.roughness = sqrt(min(widenedAlpha(materialAlpha(mat), slopeVar), 1.0));
    }
    shadingNormal = n;
    return mat;
}

#endif
