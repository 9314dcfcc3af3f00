// A path's vertex on a surface (render.glsl, tracePath): the textured
// material, emission, the caustic map at the primary receiver, next-event
// estimation (nee.glsl, sampleLd), and the BSDF-sampled continuation.
#ifndef SURFACE_VERTEX_GLSL
#define SURFACE_VERTEX_GLSL

// The test and benchmark shading modes (SPEC_SHADING_MODE), which end a
// path at a surface with an albedo instead of shading it: SHADING_NONE at
// the first hit, SHADING_MIRRORED_ALBEDO at the first surface that is not a
// perfect mirror, SHADING_GLOSSY_ALBEDO at the first diffuse one. True when
// the path ends here (its result in s.radiance).
bool albedoModeEnds(inout PathState s, Material mat) {
    bool ends = SHADING_MODE == SHADING_NONE || (SHADING_MODE == SHADING_MIRRORED_ALBEDO && mat.kind != MATERIAL_MIRROR)
        || (SHADING_MODE == SHADING_GLOSSY_ALBEDO && mat.kind == MATERIAL_DIFFUSE);
    if (ends) s.radiance = SHADING_MODE == SHADING_NONE ? v3(mat.albedo) : s.throughput * v3(mat.albedo);
    if (ends) s.alive = false;
    return ends;
}

// Caustic paths (CAUSTICS_ENABLED): the caustic rays pass dielectrics by
// refraction (reflection only under total internal reflection) and reflect
// off mirrors and smooth conductors; a path that leaves the primary
// receiver through such vertices only is one the caustic map covers.
void followCausticPath(inout PathState s, Material mat, bool primaryReceiver, vec3 wo, vec3 wi) {
    bool reflectedOffGlass = mat.kind == MATERIAL_DIELECTRIC && wi.z * wo.z > 0.0 && fresnelDielectric(wo.z, mat.ior) < 1.0;
    if (primaryReceiver) {
        s.causticPath = true;
    } else if (s.causticPath && isDelta(mat) && !reflectedOffGlass) {
        ++s.causticSpeculars;
    } else {
        s.causticPath = false;
    }
}

// The path reached surface hit `h` through medium `med` (pixel `pixel`'s
// path): it shades the vertex and continues by sampling the BSDF, or ends.
void surfaceVertex(inout PathState s, SceneHit h, Medium med, uint pixel, inout PathSampler rng) {
    vec3 ns;
    // The footprint at this hit, built once: the texture lookups and the
    // bounce below share it.
    HitFootprint hitFoot = footprintAtHit(s.foot, s.d, h.normal, h.t);
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
    mat3 frameW = frameAround(n);
    vec3 wo = transpose(frameW) * -s.d;
    bool primaryReceiver = CAUSTICS_ENABLED != 0u && s.bounce == 0u && mat.kind == MATERIAL_DIFFUSE
        && receivers[pixel].object == h.object;
    if (primaryReceiver) s.radiance += s.throughput * v3(mat.albedo) / PI * FIXED_POINT_RGB(causticMap, pixel);
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
        record(EVENT_SURFACE, h.object, matIndex, LOBE_INVALID, h.t, wo.z, bs.wi.z, bs.pdf, p, bs.weight, s.throughput,
               s.radiance);
        s.alive = false;
        return;
    }
    record(EVENT_SURFACE, h.object, matIndex, transmits ? LOBE_TRANSMIT : LOBE_REFLECT, h.t, wo.z, bs.wi.z, bs.pdf, p,
           bs.weight, s.throughput * bs.weight, s.radiance);
    if (CAUSTICS_ENABLED != 0u) followCausticPath(s, mat, primaryReceiver, wo, bs.wi);
    bool last = s.bounce + 1u == frame.maxDepth;
    if (FILTER_MODE != FILTER_NONE && !last) {
        footprintBounce(s.foot, hitFoot, h, s.d, normalize(frameW * bs.wi), wo, bs.wi, mat.kind, mat.ior);
    }
    // Transmitted: update the stack of media, and the η² factor the weight
    // divided the throughput by (mat.ior is n_inside / n_outside).
    if (mat.kind == MATERIAL_DIELECTRIC && transmits) {
        crossInterface(s.media, matIndex, entering);
        float etaRel = wo.z > 0.0 ? mat.ior : 1.0 / mat.ior;
        s.etaScale *= etaRel * etaRel;
    }
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
