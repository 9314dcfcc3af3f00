// The path tracer, shared by both backends (render.comp with ray queries,
// render.rgen through a ray-tracing pipeline): one sample per pixel of a
// tile, a path traced from the camera with next-event estimation and
// multiple importance sampling (power heuristic) at every non-specular
// vertex, Russian roulette after RR_DEPTH bounces, and at most `maxDepth`
// bounces (1 = direct lighting only). Here: the pass's bindings and the
// path loop (tracePath); around it, one idea a file: pass_inputs.glsl (the
// caustic, volume and beam passes' results), environment.glsl, surface.glsl
// (textured materials), path_record.glsl, camera.glsl (pixel filter),
// shadow_queue.glsl, nee.glsl (light sampling), roulette.glsl and pixel.glsl
// (one sample).
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

#include "pass_inputs.glsl"

// Specialisation constant: FILTER_NONE, FILTER_RAY_CONES or FILTER_COVARIANCE.
layout(constant_id = SPEC_FILTER_MODE) const uint FILTER_MODE = FILTER_NONE;
// Specialisation constant: LOOKUP_PROBES (trilinear probes, the default) or
// LOOKUP_EWA (the reference lookup), for the filtered modes.
layout(constant_id = SPEC_LOOKUP_MODE) const uint LOOKUP_MODE = LOOKUP_PROBES;

#include "path_footprint.glsl"

#include "environment.glsl"
#include "surface.glsl"
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

#include "path_record.glsl"
// Specialisation constant: SHADING_FULL, SHADING_NONE (the first hit's
// albedo: no light sampling, no bounces; benchmark breakdowns) or
// SHADING_MIRRORED_ALBEDO (the albedo seen through perfect mirrors; tests).
layout(constant_id = SPEC_SHADING_MODE) const uint SHADING_MODE = SHADING_FULL;

#include "camera.glsl"
#include "shadow_queue.glsl"
#include "nee.glsl"
#include "roulette.glsl"
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

#include "pixel.glsl"

#endif
