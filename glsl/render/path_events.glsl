// The events of a path (render.glsl, tracePath) other than a surface
// vertex (surface_vertex.glsl): a shadow ray's answer, a scattering event
// in a medium, an emitter found by the path, and the last vertex's
// continuation.
#ifndef PATH_EVENTS_GLSL
#define PATH_EVENTS_GLSL

#include "render_inputs.glsl"
#include "pass_inputs.glsl"
#include "path_state.glsl"
#include "shadow_queue.glsl"
#include "nee.glsl"
#include "roulette.glsl"
#include "surface.glsl"

// Shadow ray `sr`, queued by next-event estimation, came back with hit `h`:
// what it brings counts if nothing blocks it.
void shadowRayAnswered(inout PathState s, ShadowRay sr, SceneHit h) {
    vec3 brings = shadowRayCount == 2u ? shadowRadiance1 : shadowRadiance0;
    --shadowRayCount;
    // lightVisible, with the geometry test done by the query.
    bool visible = h.object == NO_HIT && noOtherLightInFront(sr.origin, sr.dir, sr.dist, sr.light);
    if (visible) s.radiance += brings;
    record(EVENT_SHADOW, sr.light, NO_TEXTURE, visible ? 1u : 0u, sr.dist, 0.0, 0.0, visible ? 1.0 : 0.0,
           sr.origin + sr.dist * sr.dir, brings, vec3(0.0), s.radiance);
}

// Participating media: the medium `med` the segment travels in (the
// innermost dielectric's interior, else the fog) may scatter or absorb the
// path before it reaches the surface or light at tl (distance sampling: the
// event's weight is the albedo; passing through weighs 1). Single
// scattering toward one light is estimated over the whole segment first.
// True when the segment ends in the medium (scattered, or ended there).
bool mediumEvent(inout PathState s, Medium med, float tl, uint segment, bool volumeSegment, bool emitterOnly,
                 inout PathSampler rng) {
    // One light for this segment's single scattering: a positional light
    // gets the equiangular estimate over the whole segment; the environment
    // and directional lights get next-event estimation at the
    // distance-sampled scattering point below.
    uint choices = lightChoices();
    uint li = choices > 0u ? min(uint(sample1(rng) * float(choices)), choices - 1u) : frame.lightCount;
    float select = 1.0 / float(max(choices, 1u));
    bool positional = choices > 0u && positionalLight(li);
    ShadowRay sr;
    if (positional && !volumeSegment && !emitterOnly) {
        // The halo share a scattering event on this segment would take
        // (after its albedo and Russian roulette, below): its continuation
        // competes with this estimate.
        vec3 after = s.throughput * v3(med.albedo);
        after /= lastVertex(s) ? 1.0 : survival(after, s.etaScale, s.bounce);
        float share = haloShare(after, s.etaScale);
        vec3 c = equiangularNextEvent(med, s.o, s.d, tl, share, li, select, rng, sr);
        queueShadowRay(sr, s.throughput * c);
    }
    float ts = -log(1.0 - sample1(rng)) / med.density;
    if (!(ts < tl)) return false;
    if (emitterOnly) {
        // Scattered before reaching an emitter: that light would take one
        // bounce more than the path may have.
        s.alive = false;
        return true;
    }
    vec3 p = s.o + ts * s.d;
    takeFeatures(s, v3(med.albedo), vec3(0.0));
    s.throughput *= v3(med.albedo);
    // Russian roulette before the direction is chosen: after it, a halo
    // direction's small weight (phase / mixture, for a segment that passes
    // close to a light) would be divided by as small a survival probability
    // at the next vertex, before that segment's estimate.
    if (!lastVertex(s) && !survives(s.throughput, s.etaScale, s.bounce, rng)) {
        s.alive = false;
        return true;
    }
    float share = haloShare(s.throughput, s.etaScale);
    if (choices > 0u && !positional) {
        vec3 c = mediumNextEvent(med, s.d, p, share, li, select, rng, sr);
        queueShadowRay(sr, s.throughput * c);
    }
    vec3 wi = sampleScatter(med, s.d, p, share, rng, s.lastPdf);
    // The phase function over the density it was sampled with: 1, or at
    // most 1 / (1 − share) after the halo mixture.
    s.throughput *= hgPdf(med.anisotropy, dot(s.d, wi)) / s.lastPdf;
    record(EVENT_MEDIUM, NO_HIT, NO_TEXTURE, LOBE_REFLECT, ts, 0.0, dot(s.d, wi), s.lastPdf, p, v3(med.albedo),
           s.throughput, s.radiance);
    s.lastPoint = p;
    // For the weight of a positional light this direction may hit.
    s.scatter = MediumScatter(vec4(s.o, tl), s.d, ts, med.density * exp(-med.density * ts));
    footprintScatter(s.foot, ts, wi);
    s.d = wi;
    s.o = p;
    // A scattering event on the camera ray's first segment is a receiver of
    // the beam map's volumetric caustics.
    s.causticPath = BEAMS_ENABLED != 0u && segment == 0u;
    s.causticSpeculars = 0u;
    s.causticReflected = false;
    s.scatteredOnVolumeSegment = volumeSegment;
    ++s.bounce;
    return true;
}

// The path found an emitter at distance tl: sphere or rect light `which`, or
// the environment (which == frame.lightCount), weighted by multiple
// importance sampling against the light sampling that could have found it,
// unless the caustic map or the volume pass has this light already.
void emitterFound(inout PathState s, uint which, float tl, bool afterVolumeScatter) {
    bool light = which != frame.lightCount;
    vec3 le = light ? v3(lights[which].color) : environmentRadiance(s.d);
    float w = 1.0;
    if (s.lastPdf > 0.0 && s.scatter.density > 0.0 && light) {
        // After a scattering event in a medium, a positional light competes
        // with the equiangular estimate of that segment.
        Equiangular e = equiangularSetup(s.scatter.segment.xyz, s.scatter.dir, s.scatter.segment.w, lightCentre(which));
        float pA = equiangularPdf(e, s.scatter.t) * lightPdf(lights[which], s.lastPoint, s.d) / float(lightChoices());
        w = powerHeuristic(s.scatter.density * s.lastPdf, pA);
    } else if (s.lastPdf > 0.0 && (light || environmentLit())) {
        w = powerHeuristic(s.lastPdf, lightOrEnvironmentPdf(which, s.lastPoint, s.d) / float(lightChoices()));
    }
    takeFeatures(s, min(le, vec3(1.0)), vec3(0.0));
    bool coveredByCaustics = s.causticPath && s.causticSpeculars > 0u && light && lights[which].kind == LIGHT_SPHERE;
    // Single scattering on the camera ray's first segment toward a sphere or
    // rect light is the volume pass's.
    bool coveredByVolume = afterVolumeScatter && light;
    if (!coveredByCaustics && !coveredByVolume) s.radiance += s.throughput * le * w;
    record(EVENT_EMITTER, light ? which : NO_HIT, NO_TEXTURE, light ? lights[which].kind : NO_HIT, tl, 0.0, 0.0, w,
           s.o + min(tl, 1e30) * s.d, s.throughput * le * w, s.throughput, s.radiance);
    s.alive = false;
}

// The last vertex's continuation reached surface hit `h`: only a surface's
// emission counts (emissive surfaces are found by BSDF sampling alone); an
// index-matched interface is passed straight on.
void lastSegmentReached(inout PathState s, SceneHit h) {
    uint mi = objects[h.object].material;
    Material m = materials[mi];
    bool entering = dot(s.d, h.normal) < 0.0;
    if (m.kind == MATERIAL_DIELECTRIC && abs(m.ior / farSideIor(s.media, mi, entering) - 1.0) < 1e-6) {
        crossInterface(s.media, mi, entering);
        s.o = offsetOrigin(s.o + h.t * s.d, h.normal, s.d, h.offset);
        return;
    }
    takeFeatures(s, v3(m.albedo), dot(h.normal, s.d) < 0.0 ? h.normal : -h.normal);
    s.radiance += s.throughput * v3(m.emission);
    record(EVENT_EMITTER, h.object, mi, NO_HIT, h.t, 0.0, 0.0, 1.0, s.o + h.t * s.d, s.throughput * v3(m.emission),
           s.throughput, s.radiance);
    s.alive = false;
}

#endif
