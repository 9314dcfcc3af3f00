// The path tracer, shared by both backends (render.comp with ray queries,
// render.rgen through a ray-tracing pipeline): one sample per pixel of a
// tile, a path traced from the camera with next-event estimation and
// multiple importance sampling (power heuristic) at every non-specular
// vertex, Russian roulette after RR_DEPTH bounces, and at most `maxDepth`
// bounces (1 = direct lighting only).
#ifndef RENDER_GLSL
#define RENDER_GLSL
#extension GL_EXT_nonuniform_qualifier : require

#include "intersect.glsl"
#include "random.glsl"
#include "sobol.glsl"
#include "lights.glsl"
#include "uv.glsl"


layout(set = 0, binding = BINDING_MATERIALS, scalar) readonly buffer Materials { Material materials[]; };
layout(set = 0, binding = BINDING_LIGHTS, scalar) readonly buffer Lights { Light lights[]; };

#include "frame.glsl"

// rgb: summed radiance, a: sample count.
layout(set = 0, binding = BINDING_ACCUM, rgba32f) uniform image2D accum;

struct Aov {
    float depth;
    float normal[3];
    float albedo[3];
    uint object;    // the object hit (NO_HIT on a miss)
};
layout(set = 0, binding = BINDING_AOV, scalar) writeonly buffer Aovs { Aov aovs[]; };

// Texture maps with their mip chains (unused slots hold a white texel).
layout(set = 0, binding = BINDING_TEXTURES) uniform sampler2D textures[MAX_TEXTURES];

vec4 mapAt(uint index, vec2 uv) { return textureLod(textures[nonuniformEXT(index)], uv, 0.0); }

#include "texfilter.glsl"

#include "covariance.glsl"

// Specialisation constant: 1 when the scene has a participating medium (the
// fog or a dielectric's interior); 0 compiles the media code out.
layout(constant_id = SPEC_MEDIA_ENABLED) const uint MEDIA_ENABLED = 0u;

// Specialisation constant: 1 when the caustic passes ran: the primary
// diffuse vertex reads the caustic map, and the paths it covers are left out
// (see "caustic paths" in tracePath); 0 compiles this out.
layout(constant_id = SPEC_CAUSTICS_ENABLED) const uint CAUSTICS_ENABLED = 0u;

// Specialisation constant: 1 when the volume pass ran: the camera ray's
// first segment gets its in-scattered light from it, and leaves single
// scattering toward positional lights out of its own estimate; 0 compiles
// this out.
layout(constant_id = SPEC_VOLUME_ENABLED) const uint VOLUME_ENABLED = 0u;

// Specialisation constant: 1 when the caustic beam pass ran (caustics in
// fog): the camera ray's first segment gets the volumetric caustics from the
// beam map, and a path that scatters on it and reaches a sphere light
// through the specular vertices the caustic rays follow is left out.
layout(constant_id = SPEC_BEAMS_ENABLED) const uint BEAMS_ENABLED = 0u;

// In-scattered radiance per pixel from the volume pass (volume.comp).
layout(set = 0, binding = BINDING_RENDER_VOLUME, scalar) readonly buffer Volume { float volume[]; };

#include "caustics.glsl"
layout(set = 0, binding = BINDING_RENDER_GBUFFER, scalar) readonly buffer Receivers { Receiver receivers[]; };
layout(set = 0, binding = BINDING_RENDER_CAUSTICS, scalar) readonly buffer CausticMap { uint64_t causticMap[]; };
// Volumetric-caustic radiance per pixel (caustic_beams.comp), fixed point.
layout(set = 0, binding = BINDING_RENDER_BEAMS, scalar) readonly buffer BeamMap { uint64_t beamMap[]; };

// Specialisation constant: FILTER_NONE, FILTER_RAY_CONES or FILTER_COVARIANCE.
layout(constant_id = SPEC_FILTER_MODE) const uint FILTER_MODE = FILTER_NONE;
// Specialisation constant: LOOKUP_PROBES (trilinear probes, the default) or
// LOOKUP_EWA (the reference lookup), for the filtered modes.
layout(constant_id = SPEC_LOOKUP_MODE) const uint LOOKUP_MODE = LOOKUP_PROBES;

#include "path_footprint.glsl"

// A texture lookup over a footprint; FILTER_NONE ignores the footprint.
vec4 lookup(uint index, Footprint fp) {
    if (FILTER_MODE == FILTER_NONE) return mapAt(index, fp.uv);
    return LOOKUP_MODE == LOOKUP_EWA ? ewaLookup(index, fp) : probeLookup(index, fp);
}

// ---- The environment map --------------------------------------------------
layout(set = 0, binding = BINDING_ENV_CDF, scalar) readonly buffer EnvCdf { float envCdf[]; };

float envCdfAt(uint i) { return envCdf[i]; }
vec3 envTexelRadiance(ivec2 t) {
    return texelFetch(textures[nonuniformEXT(frame.envMap)], t, 0).rgb * frame.envScale;
}
#include "envmap.glsl"

bool envMapped() { return frame.envMap != NO_TEXTURE; }

vec3 environmentRadiance(vec3 d) {
    return envMapped() ? envTexelRadiance(envTexelAt(directionToUv(d), frame.envWidth, frame.envHeight))
                       : frame.background;
}

float environmentPdf(vec3 d) {
    return envMapped() ? envMapPdf(d, frame.envWidth, frame.envHeight) : 1.0 / (4.0 * PI);
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
        vec3 a = v3(mat.albedo) * lookup(mat.albedoMap, fp).rgb;
        mat.albedo = float[3](a.x, a.y, a.z);
    }
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

layout(push_constant, scalar) uniform Push {
    uvec2 tileOrigin;
    uvec2 tileSize;
    uint sampleIndex;
    uint writeAov;
} pc;

// The largest single sample per pixel: r its luminance, g the sample index
// that brought it (exact up to 2^24 samples). The outlier report
// (src/passes/outliers.rs) compares it with the bound the scene allows.
layout(set = 0, binding = BINDING_RENDER_MAX_SAMPLE, rg32f) uniform image2D maxSample;

// Specialisation constant: 1 records every event of the path into `path`
// (one pixel and one sample per dispatch: the outlier report's); 0 compiles
// the recording out.
layout(constant_id = SPEC_RECORD_PATH) const uint RECORD_PATH = 0u;

// One recorded event (host twin: GpuPathVertex in src/passes/gpu.rs).
struct PathVertex {
    uint event;         // EVENT_*
    uint object;        // object index, or the light index for emitters and light samples
    uint material;      // material index (NO_TEXTURE when none)
    uint lobe;          // LOBE_* (surface events), or the light kind
    float t;            // ray parameter of the hit, or the shadow ray's length
    float cosO;         // cosine of wo with the shading normal (signed)
    float cosI;         // cosine of wi with the shading normal (signed)
    float pdf;          // solid-angle pdf of the sample (0: delta), or the MIS weight for emitters
    float position[3];
    float weight[3];    // the sample's weight, or the contribution an emitter or shadow ray brings
    float throughput[3];
    float radiance[3];  // the sample's radiance so far
};
layout(set = 0, binding = BINDING_RENDER_PATH, scalar) buffer PathRecord {
    uint count;
    PathVertex vertices[PATH_RECORD_VERTICES];
} path;

void record(uint event, uint object, uint material, uint lobe, float t, float cosO, float cosI, float pdf, vec3 position,
            vec3 weight, vec3 throughput, vec3 radiance) {
    if (RECORD_PATH == 0u) return;
    // `count` counts every event; the last slot is kept for EVENT_END, so
    // that a path longer than the record still shows how it ended (the host
    // reports the events left out).
    uint i = path.count;
    path.count = i + 1u;
    if (event == EVENT_END) {
        i = min(i, PATH_RECORD_VERTICES - 1u);
    } else if (i >= PATH_RECORD_VERTICES - 1u) {
        return;
    }
    path.vertices[i] = PathVertex(event, object, material, lobe, t, cosO, cosI, pdf, float[3](position.x, position.y,
        position.z), float[3](weight.x, weight.y, weight.z), float[3](throughput.x, throughput.y, throughput.z),
        float[3](radiance.x, radiance.y, radiance.z));
}

// Specialisation constant: SHADING_FULL, SHADING_NONE (the first hit's
// albedo: no light sampling, no bounces; benchmark breakdowns) or
// SHADING_MIRRORED_ALBEDO (the albedo seen through perfect mirrors; tests).
layout(constant_id = SPEC_SHADING_MODE) const uint SHADING_MODE = SHADING_FULL;

// Bounces after which Russian roulette may end a path.
const uint RR_DEPTH = 3u;

bool environmentLit() { return frame.envMap != NO_TEXTURE || any(greaterThan(frame.background, vec3(0.0))); }

// Light index `frame.lightCount` stands for the uniform environment (the
// background radiance) when it is not black.
LightSample sampleLightOrEnvironment(uint i, vec3 x, vec2 u) {
    if (i != frame.lightCount) return sampleLight(lights[i], x, u);
    return envMapped() ? sampleEnvMap(u, frame.envWidth, frame.envHeight) : sampleEnvironment(frame.background, u);
}

float lightOrEnvironmentPdf(uint i, vec3 x, vec3 wi) {
    return i == frame.lightCount ? environmentPdf(wi) : lightPdf(lights[i], x, wi);
}

#include "light_queries.glsl"

// Number of light-sampling choices: the lights, plus the environment.
uint lightChoices() { return frame.lightCount + (environmentLit() ? 1u : 0u); }

// ---- The pixel filter -----------------------------------------------------
// One pixel filter for every mode and for the reference: a Gaussian of
// σ = frame.pixelSigma pixels (PIXEL_FILTER_SIGMA, src/passes/render.rs),
// sampled by the camera rays' jitter (filter importance sampling, as in
// pbrt-v4), so that the pixel value is the plain mean of its samples.
// A filtered mode splits the filter's variance: the footprint carries the
// fraction f = frame.footprintFraction (σ√f, which shrinks with the sample
// count) and the jitter the rest (σ√(1 − f)). Gaussians convolve by adding
// variances, so jitter ⊛ footprint is the pixel filter, and a filtered
// sample's expectation is the supersampled pixel value wherever the texture
// mapping is locally affine; `none` jitters over the whole filter.
float footprintSigma() { return FILTER_MODE == FILTER_NONE ? 0.0 : frame.pixelSigma * sqrt(frame.footprintFraction); }


// The jitter of sample `sampleIndex` in pixel `pix`, in pixels from the
// pixel's centre: a stratified point (the R2 sequence, M. Roberts 2018, in
// 32-bit fixed point, rotated per pixel and seed by Cranley-Patterson)
// taken to the Gaussian by the Box-Muller transform.
vec2 cameraJitter(uvec2 pix, uint sampleIndex) {
    float f = FILTER_MODE == FILTER_NONE ? 0.0 : frame.footprintFraction;
    float sigma = frame.pixelSigma * sqrt(max(1.0 - f, 0.0));
    uint rx = pcgHash(pix.x ^ pcgHash(pix.y ^ pcgHash(frame.seed ^ 0x2545f491u)));
    uint ry = pcgHash(rx);
    // α = (0.7548776662, 0.5698402910) · 2^32.
    uint ux = sampleIndex * 3242174890u + rx, uy = sampleIndex * 2447445414u + ry;
    return gaussianPixelOffset(vec2(float(ux >> 8), float(uy >> 8)) * (1.0 / 16777216.0), sigma);
}

// Shadow rays are not traced where next-event estimation makes them: they
// wait in this queue and tracePath traces them at the same call site as
// its own rays. Every call site of the intersection code is a full copy of
// it in the compiled shader (Mesa inlines every function), so one site
// instead of four makes the render shader compile three times as fast on
// lavapipe (the glass vessel's: 105 s to 35 s). At most two wait at a time (an equiangular estimate in a medium
// and one at the surface behind it).
struct ShadowRay {
    vec3 origin;
    vec3 dir;
    float dist;
    uint light;        // the light it aims at (frame.lightCount: the environment)
};
// Two slots in named variables rather than an array: dynamically indexed
// arrays go to scratch memory on lavapipe.
ShadowRay shadowRay0, shadowRay1;
vec3 shadowRadiance0, shadowRadiance1;  // what each brings if nothing blocks it
uint shadowRayCount = 0u;

// Queues shadow ray `r`, which brings `radiance` if unblocked.
void queueShadowRay(ShadowRay r, vec3 radiance) {
    if (all(equal(radiance, vec3(0.0)))) return;
    record(EVENT_LIGHT_SAMPLE, r.light, NO_TEXTURE, r.light < frame.lightCount ? lights[r.light].kind : NO_HIT, r.dist,
           0.0, 0.0, 0.0, r.origin, radiance, vec3(0.0), vec3(0.0));
    if (shadowRayCount == 0u) {
        shadowRay0 = r;
        shadowRadiance0 = radiance;
    } else {
        shadowRay1 = r;
        shadowRadiance1 = radiance;
    }
    shadowRayCount = min(shadowRayCount + 1u, 2u);
}

// Next-event estimation at a vertex with a non-delta material: one light
// chosen uniformly, weighted by multiple importance sampling against the
// BSDF-sampled continuation (which every vertex has, the last one included:
// see "the last vertex" in tracePath). Returns the light's contribution if
// its shadow ray `sr` is unblocked.
vec3 nextEvent(Material mat, mat3 frameW, vec3 wo, vec3 d, vec3 p, vec3 ng, float offset, Medium med, inout PathSampler rng,
               out ShadowRay sr) {
    uint choices = lightChoices();
    if (choices == 0u) return vec3(0.0);
    uint i = min(uint(sample1(rng) * float(choices)), choices - 1u);
    float select = 1.0 / float(choices);
    LightSample ls = sampleLightOrEnvironment(i, p, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    vec3 wiLocal = transpose(frameW) * ls.wi;
    // The light must lie on the side of the geometric surface that the
    // lobe scatters to (the viewer's side for reflection, the other for
    // transmission): a shading normal tilted by a normal or bump map would
    // otherwise let light leak through the surface.
    bool crosses = dot(ls.wi, ng) * dot(d, ng) > 0.0;
    if (crosses != (wiLocal.z * wo.z < 0.0)) return vec3(0.0);
    vec3 f = bsdfEval(mat, wo, wiLocal);
    if (all(equal(f, vec3(0.0)))) return vec3(0.0);
    // The shadow ray starts off the surface on the side of the light (either
    // side for a rough dielectric); the light's distance is shortened by the
    // part of the offset along the ray, so that the ray ends at the light.
    vec3 origin = offsetOrigin(p, ng, ls.wi, offset);
    float dist = ls.dist - dot(origin - p, ls.wi);
    sr = ShadowRay(origin, ls.wi, dist, i);
    // The medium around the vertex attenuates the shadow ray (a shadow ray
    // that would cross into another medium meets its boundary and is
    // occluded above).
    vec3 contribution = f * abs(wiLocal.z) * ls.radiance * (transmittance(med, dist) / select);
    if (ls.pdf == 0.0) return contribution;  // delta light
    float pl = ls.pdf * select;
    return contribution * (powerHeuristic(pl, bsdfPdf(mat, wo, wiLocal)) / ls.pdf);
}

// Next-event estimation at a scattering event in a medium, at p, for a path
// travelling along d, toward light (or environment) `i` chosen with
// probability `select`: the phase function replaces the BSDF and the
// cosine, the shadow ray is attenuated by the medium's transmittance. Used
// for the environment and directional lights; positional lights use the
// equiangular estimate over the whole segment instead.
vec3 mediumNextEvent(Medium med, vec3 d, vec3 p, uint i, float select, inout PathSampler rng, out ShadowRay sr) {
    LightSample ls = sampleLightOrEnvironment(i, p, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    float phase = hgPdf(med.anisotropy, dot(d, ls.wi));
    float tr = transmittance(med, ls.dist);
    if (tr == 0.0) return vec3(0.0);
    sr = ShadowRay(p, ls.wi, ls.dist, i);
    vec3 contribution = phase * tr * ls.radiance / select;
    if (ls.pdf == 0.0) return contribution;  // delta light
    return contribution * (powerHeuristic(ls.pdf * select, phase) / ls.pdf);
}

// Single scattering toward positional light `i` (chosen with probability
// `select`) along the medium segment o + t d, t in [0, tEnd): a point by
// equiangular sampling, a direction by the light's sampler, weighted by
// multiple importance sampling against the path's own strategy (distance
// sampling, density σ_t T(t), then the phase function). Returns the
// estimate before the segment's throughput (it includes σ_s and both
// transmittances).
vec3 equiangularNextEvent(Medium med, vec3 o, vec3 d, float tEnd, uint i, float select, inout PathSampler rng,
                          out ShadowRay sr) {
    Equiangular e = equiangularSetup(o, d, tEnd, lightCentre(i));
    float t = equiangularSample(e, sample1(rng));
    float pt = equiangularPdf(e, t);
    if (!(t >= 0.0 && t < tEnd) || !(pt > 0.0)) return vec3(0.0);
    vec3 x = o + t * d;
    LightSample ls = sampleLight(lights[i], x, sample2(rng));
    if (!ls.valid) return vec3(0.0);
    float phase = hgPdf(med.anisotropy, dot(d, ls.wi));
    sr = ShadowRay(x, ls.wi, ls.dist, i);
    float tAlong = exp(-med.density * t);
    vec3 f = (tAlong * transmittance(med, ls.dist) * med.density * phase) * v3(med.albedo) * ls.radiance;
    if (ls.pdf == 0.0) return f / (select * pt);  // point light
    float pA = select * pt * ls.pdf;
    return f * (powerHeuristic(pA, med.density * tAlong * phase) / pA);
}

// Russian roulette after RR_DEPTH bounces: false when the path ends. The
// survival probability is the throughput times `etaScale`, the product of
// the η² factors that refractions divided the throughput by (radiance
// scales by η² across an interface; Mitsuba 3 does the same), at most 1:
// inside glass the throughput is 1/η² of what will leave it, and dividing
// by that smaller probability would push the throughput above 1 when the
// path leaves (a sample that gains energy). So the η-corrected throughput
// never exceeds 1 (outliers.rs states the bound this gives).
bool survives(inout vec3 throughput, float etaScale, uint bounce, inout PathSampler rng) {
    if (bounce + 1u < RR_DEPTH) return true;
    float q = clamp(max(throughput.x, max(throughput.y, throughput.z)) * etaScale, 0.05, 1.0);
    if (q >= 1.0) return true;
    if (sample1(rng) > q) return false;
    throughput /= q;
    record(EVENT_ROULETTE, NO_HIT, NO_TEXTURE, 0u, 0.0, 0.0, 0.0, q, vec3(0.0), vec3(1.0 / q), throughput, vec3(0.0));
    return true;
}

#include "stack.glsl"

// A scattering event in a medium, for the weight of a positional light that
// the sampled direction reaches: the segment it was on (origin, end
// distance; direction), where on it, and the density σ_t T(t) there.
struct MediumScatter {
    vec4 segment;
    vec3 dir;
    float t;
    float density;
};

// Caustic paths: with CAUSTICS_ENABLED, the caustic map gives the light that
// reaches the primary vertex (when it is the diffuse receiver seen through
// the pixel centre) from point, sphere and directional lights through one or
// more specular vertices of the kinds caustic_trace.comp follows. The path
// therefore ignores a sphere light it finds after leaving that vertex
// through such vertices only; every other path is estimated as usual.
vec3 tracePath(vec3 o, vec3 d, uint pixel, inout PathSampler rng) {
    MediaStack media = emptyStack();
    // The footprint (ray cone or covariance, path_footprint.glsl) starts as
    // its share of the pixel filter (cameraJitter).
    float pixelAngle = 2.0 * length(frame.up) / float(frame.height);
    PathFootprint foot = footprintAtCamera(d, footprintSigma() * pixelAngle);
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    // The product of the η² factors refractions divided the throughput by
    // (Russian roulette's survival probability uses throughput × etaScale).
    float etaScale = 1.0;
    float lastPdf = 0.0;      // solid-angle pdf of the last BSDF sample; 0 after a delta lobe or the camera
    vec3 lastPoint = o;
    // After a scattering event in a medium: where it was (0 density after
    // any other vertex).
    MediumScatter scatter = MediumScatter(vec4(0.0), vec3(0.0), 0.0, 0.0);
    uint choices = lightChoices();
    // Caustic paths: true while the path has gone from the primary receiver
    // through the specular vertices that the caustic map covers; their count.
    bool causticPath = false;
    uint causticSpeculars = 0u;
    // True when the last scattering event was on the camera ray's first
    // segment and the volume pass covers it (VOLUME_ENABLED).
    bool scatteredOnVolumeSegment = false;
    // Crossing an index-matched interface (relative index 1: the same medium
    // on both sides) is not a bounce; `step` bounds the path all the same.
    // The last vertex: the path's vertex at bounce maxDepth - 1 still samples
    // its BSDF, and the segment that follows (bounce == maxDepth) looks only
    // for an emitter (a light, the environment, an emissive surface), so
    // that next-event estimation at every vertex is weighted against BSDF
    // sampling. Without it the last vertex's light sample is unweighted, and
    // on a sharp glossy lobe one such sample is many times the light's
    // radiance (Veach 1997, ch. 9; pbrt-v4 and Mitsuba 3 end paths the
    // same way).
    uint bounce = 0u;
    uint step = 0u;
    bool alive = true;
    // One past the last segment: the emitter-only one after the last vertex
    // (the test shading modes end where they always did, without it).
    uint lastBounce = frame.maxDepth + (SHADING_MODE == SHADING_FULL ? 1u : 0u);
    ShadowRay sr;
    // One ray query per iteration, at this one call site: a waiting shadow
    // ray first, else the path's next segment.
    for (;;) { LOOP_EDGE();
        bool shadow = shadowRayCount > 0u;
        if (!shadow && !(alive && bounce < lastBounce && step < 4u * frame.maxDepth + 8u)) break;
        if (shadow) sr = shadowRayCount == 2u ? shadowRay1 : shadowRay0;
        SceneHit h = traceSceneWith(shadow ? sr.origin : o, shadow ? sr.dir : d, 0.0, shadow ? sr.dist : 1e30, shadow);
        if (shadow) {
            vec3 brings = shadowRayCount == 2u ? shadowRadiance1 : shadowRadiance0;
            --shadowRayCount;
            // lightVisible, with the geometry test done by the query above.
            bool visible = h.object == NO_HIT && noOtherLightInFront(sr.origin, sr.dir, sr.dist, sr.light);
            if (visible) radiance += brings;
            record(EVENT_SHADOW, sr.light, NO_TEXTURE, visible ? 1u : 0u, sr.dist, 0.0, 0.0, visible ? 1.0 : 0.0,
                   sr.origin + sr.dist * sr.dir, brings, vec3(0.0), radiance);
            continue;
        }
        uint segment = step++;
        bool emitterOnly = bounce == frame.maxDepth;
        // The camera ray's first segment: the volume pass has its single
        // scattering toward positional lights.
        bool volumeSegment = VOLUME_ENABLED != 0u && segment == 0u;
        if (volumeSegment) radiance += vec3(volume[3u * pixel], volume[3u * pixel + 1u], volume[3u * pixel + 2u]);
        if (BEAMS_ENABLED != 0u && segment == 0u) radiance += FIXED_POINT_RGB(beamMap, pixel);
        bool afterVolumeScatter = scatteredOnVolumeSegment;
        scatteredOnVolumeSegment = false;
        float tl;
        uint which = firstLightHit(o, d, h.object == NO_HIT ? 1e30 : h.t, frame.lightCount, tl);
        // Participating media: the medium the ray travels in (the innermost
        // dielectric's interior, else the fog) may scatter or absorb it
        // before it reaches the surface or light at tl (distance sampling:
        // the event's weight is the albedo; passing through weighs 1).
        Medium med = Medium(0.0, float[3](0.0, 0.0, 0.0), 0.0);
        if (MEDIA_ENABLED != 0u) med = mediumOf(media);
        if (MEDIA_ENABLED != 0u && SHADING_MODE == SHADING_FULL && med.density > 0.0) {
            // One light for this segment's single scattering: a positional
            // light gets the equiangular estimate over the whole segment;
            // the environment and directional lights get next-event
            // estimation at the distance-sampled scattering point below.
            uint choices = lightChoices();
            uint li = choices > 0u ? min(uint(sample1(rng) * float(choices)), choices - 1u) : frame.lightCount;
            float select = 1.0 / float(max(choices, 1u));
            bool last = bounce + 1u == frame.maxDepth;
            bool positional = choices > 0u && positionalLight(li);
            if (positional && !volumeSegment && !emitterOnly) {
                vec3 c = equiangularNextEvent(med, o, d, tl, li, select, rng, sr);
                queueShadowRay(sr, throughput * c);
            }
            float ts = -log(1.0 - sample1(rng)) / med.density;
            if (ts < tl && emitterOnly) {
                // Scattered before reaching an emitter: that light would
                // take one bounce more than the path may have.
                alive = false;
                continue;
            }
            if (ts < tl) {
                vec3 p = o + ts * d;
                throughput *= v3(med.albedo);
                if (choices > 0u && !positional) {
                    vec3 c = mediumNextEvent(med, d, p, li, select, rng, sr);
                    queueShadowRay(sr, throughput * c);
                }
                vec3 wi = sampleHg(med.anisotropy, d, sample2(rng));
                lastPdf = hgPdf(med.anisotropy, dot(d, wi));
                record(EVENT_MEDIUM, NO_HIT, NO_TEXTURE, LOBE_REFLECT, ts, 0.0, dot(d, wi), lastPdf, p, v3(med.albedo),
                       throughput, radiance);
                lastPoint = p;
                // For the weight of a positional light this direction may hit.
                scatter = MediumScatter(vec4(o, tl), d, ts, med.density * exp(-med.density * ts));
                footprintScatter(foot, ts, wi);
                d = wi;
                o = p;
                // A scattering event on the camera ray's first segment is a
                // receiver of the beam map's volumetric caustics.
                causticPath = BEAMS_ENABLED != 0u && segment == 0u;
                causticSpeculars = 0u;
                scatteredOnVolumeSegment = volumeSegment;
                if (!last && !survives(throughput, etaScale, bounce, rng)) alive = false;
                ++bounce;
                continue;
            }
        }
        if (which != frame.lightCount || h.object == NO_HIT) {
            // An emitter: a sphere or rect light, or the environment.
            vec3 le = which != frame.lightCount ? v3(lights[which].color) : environmentRadiance(d);
            float w = 1.0;
            if (lastPdf > 0.0 && scatter.density > 0.0 && which != frame.lightCount) {
                // After a scattering event in a medium, a positional light
                // competes with the equiangular estimate of that segment.
                Equiangular e = equiangularSetup(scatter.segment.xyz, scatter.dir, scatter.segment.w, lightCentre(which));
                float pA = equiangularPdf(e, scatter.t) * lightPdf(lights[which], lastPoint, d) / float(choices);
                w = powerHeuristic(scatter.density * lastPdf, pA);
            } else if (lastPdf > 0.0 && (which != frame.lightCount || environmentLit())) {
                w = powerHeuristic(lastPdf, lightOrEnvironmentPdf(which, lastPoint, d) / float(choices));
            }
            bool coveredByCaustics = causticPath && causticSpeculars > 0u && which != frame.lightCount
                && lights[which].kind == LIGHT_SPHERE;
            // Single scattering on the camera ray's first segment toward a
            // sphere or rect light is the volume pass's.
            bool coveredByVolume = afterVolumeScatter && which != frame.lightCount;
            if (!coveredByCaustics && !coveredByVolume) radiance += throughput * le * w;
            record(EVENT_EMITTER, which == frame.lightCount ? NO_HIT : which, NO_TEXTURE,
                   which == frame.lightCount ? NO_HIT : lights[which].kind, tl, 0.0, 0.0, w, o + min(tl, 1e30) * d,
                   throughput * le * w, throughput, radiance);
            alive = false;
            continue;
        }
        if (emitterOnly) {
            // The last vertex's continuation: only a surface's emission
            // counts (emissive surfaces are found by BSDF sampling alone);
            // an index-matched interface is passed straight on.
            uint mi = objects[h.object].material;
            Material m = materials[mi];
            bool entering = dot(d, h.normal) < 0.0;
            if (m.kind == MATERIAL_DIELECTRIC && abs(m.ior / farSideIor(media, mi, entering) - 1.0) < 1e-6) {
                crossInterface(media, mi, entering);
                o = offsetOrigin(o + h.t * d, h.normal, d, h.offset);
                continue;
            }
            radiance += throughput * v3(m.emission);
            record(EVENT_EMITTER, h.object, mi, NO_HIT, h.t, 0.0, 0.0, 1.0, o + h.t * d, throughput * v3(m.emission),
                   throughput, radiance);
            alive = false;
            continue;
        }

        vec3 ns;
        // The footprint at this hit, built once: the texture lookups and the
        // bounce below share it.
        HitFootprint hitFoot = footprintAtHit(foot, d, h.normal, h.t);
        Material mat = surfaceAt(h, d, hitFoot, ns);
        if (SHADING_MODE == SHADING_NONE) return v3(mat.albedo);
        if (SHADING_MODE == SHADING_MIRRORED_ALBEDO && mat.kind != MATERIAL_MIRROR) {
            return throughput * v3(mat.albedo);
        }
        if (SHADING_MODE == SHADING_GLOSSY_ALBEDO && mat.kind == MATERIAL_DIFFUSE) return throughput * v3(mat.albedo);
        uint matIndex = objects[h.object].material;
        bool entering = dot(d, h.normal) < 0.0;
        if (mat.kind == MATERIAL_DIELECTRIC) {
            mat.ior /= farSideIor(media, matIndex, entering);
            if (abs(mat.ior - 1.0) < 1e-6) {
                // Invisible interface: continue straight on, into or out of this medium.
                crossInterface(media, matIndex, entering);
                record(EVENT_PASS_THROUGH, h.object, matIndex, entering ? LOBE_TRANSMIT : LOBE_REFLECT, h.t, 0.0, 0.0,
                       0.0, o + h.t * d, vec3(1.0), throughput, radiance);
                o = offsetOrigin(o + h.t * d, h.normal, d, h.offset);
                continue;
            }
        }
        vec3 p = o + h.t * d;
        radiance += throughput * v3(mat.emission);
        if (any(greaterThan(v3(mat.emission), vec3(0.0)))) {
            record(EVENT_EMITTER, h.object, matIndex, NO_HIT, h.t, 0.0, 0.0, 1.0, p, throughput * v3(mat.emission),
                   throughput, radiance);
        }
        // A dielectric's shading normal must agree with the geometric one on
        // which side the ray comes from (the media stack follows the
        // geometric side, the refraction's η the shading side); where a
        // normal or bump map tilts it past the ray, the geometric normal
        // shades this vertex.
        if (mat.kind == MATERIAL_DIELECTRIC && (dot(ns, d) < 0.0) != entering) ns = h.normal;
        // Two-sided shading; dielectrics keep the outward normal to tell inside from outside.
        vec3 n = mat.kind == MATERIAL_DIELECTRIC || dot(h.normal, d) < 0.0 ? ns : -ns;
        mat3 frameW = frameAround(n);
        vec3 wo = transpose(frameW) * -d;
        bool last = bounce + 1u == frame.maxDepth;
        bool primaryReceiver = CAUSTICS_ENABLED != 0u && bounce == 0u && mat.kind == MATERIAL_DIFFUSE
            && receivers[pixel].object == h.object;
        if (primaryReceiver) radiance += throughput * v3(mat.albedo) / PI * FIXED_POINT_RGB(causticMap, pixel);
        if (SHADING_MODE == SHADING_FULL && !isDelta(mat)) {
            vec3 c = nextEvent(mat, frameW, wo, d, p, h.normal, h.offset, med, rng, sr);
            queueShadowRay(sr, throughput * c);
        }

        BsdfSample bs = bsdfSample(mat, wo, vec3(sample2(rng), sample1(rng)));
        if (!bs.valid) {
            record(EVENT_SURFACE, h.object, matIndex, LOBE_INVALID, h.t, wo.z, bs.wi.z, bs.pdf, p, bs.weight, throughput,
                   radiance);
            alive = false;
            continue;
        }
        vec3 next = normalize(frameW * bs.wi);
        // The sampled direction must leave on the side of the geometric
        // surface that its lobe belongs to (reflection: the side it came
        // from; transmission: the other). A shading normal (normal and bump
        // maps), or f32 rounding of a grazing direction, can put it on the
        // other side; such a ray would start on the wrong side of the
        // surface (offsetOrigin follows the geometric normal) with the media
        // stack unchanged, and leave glass it never entered with an η² gain.
        // The path ends there instead.
        if ((dot(next, h.normal) * dot(d, h.normal) > 0.0) != (bs.wi.z * wo.z < 0.0)) {
            record(EVENT_SURFACE, h.object, matIndex, LOBE_INVALID, h.t, wo.z, bs.wi.z, bs.pdf, p, bs.weight, throughput,
                   radiance);
            alive = false;
            continue;
        }
        record(EVENT_SURFACE, h.object, matIndex, bs.wi.z * wo.z < 0.0 ? LOBE_TRANSMIT : LOBE_REFLECT, h.t, wo.z,
               bs.wi.z, bs.pdf, p, bs.weight, throughput * bs.weight, radiance);
        if (CAUSTICS_ENABLED != 0u) {
            // The caustic rays pass dielectrics by refraction (reflection
            // only under total internal reflection) and reflect off mirrors
            // and smooth conductors.
            bool reflectedOffGlass = mat.kind == MATERIAL_DIELECTRIC && bs.wi.z * wo.z > 0.0
                && fresnelDielectric(wo.z, mat.ior) < 1.0;
            if (primaryReceiver) {
                causticPath = true;
            } else if (causticPath && isDelta(mat) && !reflectedOffGlass) {
                ++causticSpeculars;
            } else {
                causticPath = false;
            }
        }
        if (FILTER_MODE != FILTER_NONE && !last) {
            footprintBounce(foot, hitFoot, h, d, normalize(frameW * bs.wi), wo, bs.wi, mat.kind, mat.ior);
        }
        // Transmitted: update the stack of media, and the η² factor the
        // weight divided the throughput by (mat.ior is n_inside / n_outside).
        if (mat.kind == MATERIAL_DIELECTRIC && bs.wi.z * wo.z < 0.0) {
            crossInterface(media, matIndex, entering);
            float etaRel = wo.z > 0.0 ? mat.ior : 1.0 / mat.ior;
            etaScale *= etaRel * etaRel;
        }
        throughput *= bs.weight;
        // The albedo modes weigh no emitter against light sampling.
        lastPdf = SHADING_MODE == SHADING_FULL ? bs.pdf : 0.0;
        scatter.density = 0.0;
        lastPoint = p;
        d = next;
        o = offsetOrigin(p, h.normal, d, h.offset);

        if (!last && !survives(throughput, etaScale, bounce, rng)) alive = false;
        ++bounce;
    }
    return radiance;
}

// One sample of the pixel at `local` in the tile (nothing outside it).
void renderPixel(uvec2 local) {
    if (any(greaterThanEqual(local, pc.tileSize))) return;
    uvec2 pix = pc.tileOrigin + local;
    uint idx = pix.y * frame.width + pix.x;
    PathSampler rng = pathSampler(pix, pc.sampleIndex, frame.seed);

    if (pc.writeAov != 0u) {
        // AOVs from the ray through the pixel centre.
        vec3 d = cameraRay(vec2(pix) + 0.5);
        SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
        Aov aov;
        aov.depth = h.object == NO_HIT ? 1.0 / 0.0 : h.t;
        vec3 n = h.normal;
        aov.normal = float[3](n.x, n.y, n.z);
        vec3 ns;
        // The whole pixel filter, as the footprint of the centre ray.
        float sigma = 2.0 * length(frame.up) / float(frame.height) * h.t * frame.pixelSigma;
        vec3 alb = h.object == NO_HIT ? vec3(0.0) : v3(surfaceAt(h, d, coneHitFootprint(d, h.normal, sigma), ns).albedo);
        aov.albedo = float[3](alb.x, alb.y, alb.z);
        aov.object = h.object;
        aovs[idx] = aov;
    }

    vec3 radiance = tracePath(frame.eye, cameraRay(vec2(pix) + 0.5 + cameraJitter(pix, pc.sampleIndex)), idx, rng);
    // No NaN or Inf ever leaves the renderer: such a sample counts as black,
    // and the accumulation's fourth channel counts only the finite samples,
    // so that the host can report how many were dropped.
    bool finite = !any(isnan(radiance)) && !any(isinf(radiance));
    ivec2 at = ivec2(pix);
    imageStore(accum, at, imageLoad(accum, at) + (finite ? vec4(radiance, 1.0) : vec4(0.0)));
    float luminance = finite ? dot(radiance, vec3(0.2126, 0.7152, 0.0722)) : 0.0;
    vec2 largest = imageLoad(maxSample, at).rg;
    if (luminance > largest.r) imageStore(maxSample, at, vec4(luminance, float(pc.sampleIndex), 0.0, 0.0));
    record(EVENT_END, NO_HIT, NO_TEXTURE, finite ? 0u : 1u, 0.0, 0.0, 0.0, 0.0, vec3(0.0), vec3(0.0), vec3(0.0), radiance);
}

#endif
