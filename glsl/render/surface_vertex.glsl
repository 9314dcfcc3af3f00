// A path's vertex on a surface (render.glsl, tracePath): the textured
// material, emission, the caustic map at the primary receiver, next-event
// estimation (nee.glsl, sampleLd), and the BSDF-sampled continuation.
#ifndef SURFACE_VERTEX_GLSL
#define SURFACE_VERTEX_GLSL

#include "render_inputs.glsl"
#include "pass_inputs.glsl"
#include "path_state.glsl"
#include "path_events.glsl"
#include "surface.glsl"
#include "nee.glsl"
#include "roulette.glsl"

// The test and benchmark shading modes (SPEC_SHADING_MODE), which end a
// path at a surface with an albedo instead of shading it: SHADING_ALBEDO at
// the first hit, SHADING_MIRRORED_ALBEDO at the first surface that is not a
// perfect mirror, SHADING_GLOSSY_ALBEDO at the first diffuse one. True when
// the path ends here (its result in s.radiance).
bool albedoModeEnds(inout PathState s, Material mat) {
    bool ends = SHADING_MODE == SHADING_ALBEDO || (SHADING_MODE == SHADING_MIRRORED_ALBEDO && mat.kind != MATERIAL_MIRROR)
        || (SHADING_MODE == SHADING_GLOSSY_ALBEDO && mat.kind == MATERIAL_DIFFUSE);
    if (ends) s.radiance = SHADING_MODE == SHADING_ALBEDO ? v3(mat.albedo) : s.throughput * v3(mat.albedo);
    if (ends) s.alive = false;
    return ends;
}

// Caustic paths (CAUSTICS_ENABLED): the caustic rays pass dielectrics by
// refraction (reflection only under total internal reflection) and reflect
// off mirrors and smooth conductors, and those of the reflecting grids
// reflect off the first glass they meet (caustic_trace.glsl); a path that
// leaves a receiver the map covers (causticPixel) through such vertices only
// (a reflection off glass, seen from the camera's side, only as the last
// vertex before the light) is one the caustic map covers.
void followCausticPath(inout PathState s, Material mat, bool receiver, vec3 wo, vec3 wi) {
    bool reflectedOffGlass = mat.kind == MATERIAL_DIELECTRIC && wi.z * wo.z > 0.0 && fresnelDielectric(wo.z, mat.ior) < 1.0;
    if (receiver) {
        s.causticPath = true;
        s.causticReflected = false;
    } else if (s.causticPath && isDelta(mat) && !s.causticReflected) {
        ++s.causticSpeculars;
        s.causticReflected = reflectedOffGlass;
    } else {
        s.causticPath = false;
    }
}

// The caustic map's pixel that covers a diffuse vertex at p on `object`, or
// NO_HIT: the primary vertex's own pixel when its receiver (the first
// surface through the pixel centre) is this object; for a later vertex (seen
// through the fog, or after a bounce) the pixel p projects to, when that
// pixel's receiver is the same object within one pixel's width of p (the
// map's own kernel). A vertex the map covers takes the light that reaches it
// through specular objects from the map, and the paths that find that light
// are left out (followCausticPath): so the floor under a glass seen through
// haze gets its caustic from the caustic passes too, where brute force finds
// it only by chance.
uint causticPixel(uint object, vec3 p, uint bounce, uint pixel) {
    if (bounce == 0u) return receivers[pixel].object == object ? pixel : NO_HIT;
    vec2 px;
    if (!project(p, px)) return NO_HIT;
    ivec2 q = ivec2(floor(px));
    if (any(lessThan(q, ivec2(0))) || q.x >= int(frame.width) || q.y >= int(frame.height)) return NO_HIT;
    uint i = uint(q.y) * frame.width + uint(q.x);
    Receiver r = receivers[i];
    float pixelWidth = dot(p - frame.eye, frame.forward) * 2.0 * length(frame.up) / float(frame.height);
    return r.object == object && distance(v3(r.position), p) < pixelWidth ? i : NO_HIT;
}

// The path reached surface hit `h` through medium `med` (pixel `pixel`'s
// path): it shades the vertex and continues by sampling the BSDF, or ends.
void surfaceVertex(inout PathState s, SceneHit h, Medium med, uint pixel, inout PathSampler rng) {
    vec3 ns;
    // The footprint at this hit, built once: the texture lookups and the
    // bounce below share it.
    HitFootprint hitFoot = footprintAtHit(s.foot, s.d, h.normal, h.t);
    // The lookups choose their mip levels and probe positions at random
    // (texfilter.glsl), from numbers outside the sampler's sequence.
    hitFoot.seed = sideSeed(rng, s.bounce);
    hitFoot.stochastic = true;
    Material mat = surfaceAt(h, s.d, hitFoot, ns);
    if (SHADING_MODE != SHADING_FULL && albedoModeEnds(s, mat)) return;
    uint matIndex = objects[h.object].material;
    bool entering = dot(s.d, h.normal) < 0.0;
    if (mat.kind == MATERIAL_DIELECTRIC) {
        mat.ior /= farSideIor(s.media, matIndex, entering);
        if (abs(mat.ior - 1.0) < 1e-6) {
            // Invisible interface: continue straight on, into or out of this medium.
            crossInterface(s.media, matIndex, entering);
            record(EVENT_PASS_THROUGH, h.object, matIndex, entering ? LOBE_TRANSMIT : LOBE_REFLECT, h.t, 0.0, 0.0, 0.0,
                   s.o + h.t * s.d, vec3(1.0), s.throughput, s.radiance);
            s.o = offsetOrigin(s.o + h.t * s.d, h.normal, s.d, h.offset);
            return;
        }
    }
    vec3 p = s.o + h.t * s.d;
    s.radiance += s.throughput * v3(mat.emission);
    if (any(greaterThan(v3(mat.emission), vec3(0.0)))) {
        record(EVENT_EMITTER, h.object, matIndex, NO_HIT, h.t, 0.0, 0.0, 1.0, p, s.throughput * v3(mat.emission),
               s.throughput, s.radiance);
    }
    // A dielectric's shading normal must agree with the geometric one on
    // which side the ray comes from (the media stack follows the geometric
    // side, the refraction's η the shading side); where a normal or bump map
    // tilts it past the ray, the geometric normal shades this vertex.
    if (mat.kind == MATERIAL_DIELECTRIC && (dot(ns, s.d) < 0.0) != entering) ns = h.normal;
    // Two-sided shading; dielectrics keep the outward normal to tell inside from outside.
    vec3 n = mat.kind == MATERIAL_DIELECTRIC || dot(h.normal, s.d) < 0.0 ? ns : -ns;
    if (!isDelta(mat)) takeFeatures(s, v3(mat.albedo), n);
    mat3 frameW = frameAround(n);
    vec3 wo = transpose(frameW) * -s.d;
    uint mapPixel = CAUSTICS_ENABLED != 0u && mat.kind == MATERIAL_DIFFUSE ? causticPixel(h.object, p, s.bounce, pixel)
                                                                             : NO_HIT;
    bool receiver = mapPixel != NO_HIT;
    if (receiver) s.radiance += s.throughput * v3(mat.albedo) / PI * FIXED_POINT_RGB(causticMap, mapPixel);
    if (SHADING_MODE == SHADING_FULL && !isDelta(mat)) {
        ShadowRay sr;
        vec3 c = sampleLd(mat, frameW, wo, s.d, p, h.normal, h.offset, med, rng, sr);
        queueShadowRay(sr, s.throughput * c);
    }

    BsdfSample bs = bsdfSample(mat, wo, vec3(sample2(rng), sample1(rng)));
    vec3 next = normalize(frameW * bs.wi);
    // The sampled direction must leave on the side of the geometric surface
    // that its lobe belongs to (reflection: the side it came from;
    // transmission: the other). A shading normal (normal and bump maps), or
    // f32 rounding of a grazing direction, can put it on the other side;
    // such a ray would start on the wrong side of the surface (offsetOrigin
    // follows the geometric normal) with the media stack unchanged, and
    // leave glass it never entered with an η² gain. The path ends there.
    bool transmits = bs.wi.z * wo.z < 0.0;
    if (!bs.valid || (dot(next, h.normal) * dot(s.d, h.normal) > 0.0) != transmits) {
        recordFootprint = vec3(hitFoot.footprint[0][0], hitFoot.footprint[0][1], hitFoot.footprint[1][1]);
        record(EVENT_SURFACE, h.object, matIndex, LOBE_INVALID, h.t, wo.z, bs.wi.z, bs.pdf, p, bs.weight, s.throughput,
               s.radiance);
        s.alive = false;
        return;
    }
    recordFootprint = vec3(hitFoot.footprint[0][0], hitFoot.footprint[0][1], hitFoot.footprint[1][1]);
    record(EVENT_SURFACE, h.object, matIndex, transmits ? LOBE_TRANSMIT : LOBE_REFLECT, h.t, wo.z, bs.wi.z, bs.pdf, p,
           bs.weight, s.throughput * bs.weight, s.radiance);
    if (CAUSTICS_ENABLED != 0u) followCausticPath(s, mat, receiver, wo, bs.wi);
    if (FILTER_MODE != FILTER_NONE && !lastVertex(s)) {
        footprintBounce(s.foot, hitFoot, h, s.d, normalize(frameW * bs.wi), wo, bs.wi, mat.kind, mat.ior);
    }
    // Transmitted: update the stack of media, and the η² factor the weight
    // divided the throughput by (mat.ior is n_inside / n_outside).
    float etaSquared = 1.0;
    if (mat.kind == MATERIAL_DIELECTRIC && transmits) {
        crossInterface(s.media, matIndex, entering);
        float etaRel = wo.z > 0.0 ? mat.ior : 1.0 / mat.ior;
        etaSquared = etaRel * etaRel;
        s.etaScale *= etaSquared;
    }
    // A specular vertex tints the features the path takes later (its weight
    // without the η² of radiance compression: the colour of the glass).
    if (isDelta(mat) && s.features.open) s.features.tint *= min(bs.weight * etaSquared, vec3(1.0));
    s.throughput *= bs.weight;
    // The albedo modes weigh no emitter against light sampling.
    s.lastPdf = SHADING_MODE == SHADING_FULL ? bs.pdf : 0.0;
    s.scatter.density = 0.0;
    s.lastPoint = p;
    s.d = next;
    s.o = offsetOrigin(p, h.normal, s.d, h.offset);
    nextBounce(s, rng);
}

#endif
