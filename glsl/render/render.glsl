// The path tracer, shared by both backends (render.comp with ray queries,
// render.rgen through a ray-tracing pipeline): one sample per pixel of a
// tile, a path traced from the camera with next-event estimation and
// multiple importance sampling (power heuristic) at every non-specular
// vertex, Russian roulette after RR_DEPTH bounces, and at most `maxDepth`
// bounces (1 = direct lighting only). Here: the path loop (tracePath); the
// pass's bindings and push block in render_inputs.glsl, which each part
// includes first; around it, one idea a file: pass_inputs.glsl (the
// caustic, volume and beam passes' results), environment.glsl, surface.glsl
// (textured materials), path_record.glsl, camera.glsl (pixel filter),
// shadow_queue.glsl, nee.glsl (light sampling), roulette.glsl,
// path_state.glsl (what a path carries), path_events.glsl (shadow rays,
// media, emitters), surface_vertex.glsl, and pixel.glsl (one sample; it
// includes this file, and the entry points include it).
#ifndef RENDER_GLSL
#define RENDER_GLSL
#include "render_inputs.glsl"
#include "pass_inputs.glsl"
#include "path_state.glsl"
#include "path_events.glsl"
#include "surface_vertex.glsl"

// The path loop (as pbrt-v4's PathIntegrator::Li and Mitsuba 3's path
// integrator): trace the next segment, or a waiting shadow ray, and hand
// what it found to the event's function: a shadow ray's answer, a
// scattering event in a medium, an emitter, or a surface vertex.
//
// The last vertex: the path's vertex at bounce maxDepth - 1 still samples
// its BSDF, and the segment that follows (bounce == maxDepth) looks only for
// an emitter (a light, the environment, an emissive surface), so that
// next-event estimation at every vertex is weighted against BSDF sampling.
// Without it the last vertex's light sample is unweighted, and on a sharp
// glossy lobe one such sample is many times the light's radiance (Veach
// 1997, ch. 9; pbrt-v4 and Mitsuba 3 end paths the same way). Crossing an
// index-matched interface (relative index 1: the same medium on both sides)
// is not a bounce; the segment count bounds the path all the same.
//
// Caustic paths: with CAUSTICS_ENABLED, the caustic map gives the light that
// reaches a diffuse vertex the map covers (the primary vertex when it is the
// receiver seen through the pixel centre, or a later vertex within a pixel
// of the receiver it projects to: causticPixel, surface_vertex.glsl) from
// point, sphere and directional lights through one or more specular
// vertices of the kinds caustic_trace.comp follows. The path therefore
// ignores a sphere light it finds after leaving that vertex through such
// vertices only; every other path is estimated as usual.
//
// The loop's steps are functions (pathGoesOn, nextRay, pathEvent), so that
// the megakernel (tracePath) and the wavefront pass's stage kernels
// (wavefront.glsl) run the same code.

// The segment after the last vertex: one past maxDepth (the test shading
// modes end where they always did, without it).
uint lastBounce() { return frame.maxDepth + (SHADING_MODE == SHADING_FULL ? 1u : 0u); }

// True while path `s` has a ray to trace: a waiting shadow ray, or its next
// segment.
bool pathGoesOn(PathState s) {
    return shadowRayCount > 0u || (s.alive && s.bounce < lastBounce() && s.step < 4u * frame.maxDepth + 8u);
}

// The ray the path traces next: a waiting shadow ray first (to its light:
// any hit up to `dist`), else the path's next segment.
struct NextRay {
    vec3 origin;
    float dist;
    vec3 dir;
    uint shadow;  // 1: a shadow ray (any hit), 0: the path's segment
};

NextRay nextRay(PathState s) {
    bool shadow = shadowRayCount > 0u;
    ShadowRay sr = shadowRayCount == 2u ? shadowRay1 : shadowRay0;
    return NextRay(shadow ? sr.origin : s.o, shadow ? sr.dist : 1e30, shadow ? sr.dir : s.d, shadow ? 1u : 0u);
}

// What the path does with the hit `h` of the ray nextRay gave: a shadow
// ray's answer, or the segment's event (a scattering event in a medium, an
// emitter, or a surface vertex). The megakernel (tracePath) and the
// wavefront pass's shade stage (wavefront.glsl) share it.
void pathEvent(inout PathState s, SceneHit h, bool shadow, uint pixel, inout PathSampler rng) {
    if (shadow) {
        shadowRayAnswered(s, shadowRayCount == 2u ? shadowRay1 : shadowRay0, h);
        return;
    }
    uint segment = s.step++;
    bool emitterOnly = s.bounce == frame.maxDepth;
    // The camera ray's first segment: the volume pass has its single
    // scattering toward positional lights, the beam pass its
    // volumetric caustics.
    bool volumeSegment = VOLUME_ENABLED != 0u && segment == 0u;
    if (volumeSegment) s.radiance += vec3(volume[3u * pixel], volume[3u * pixel + 1u], volume[3u * pixel + 2u]);
    if (BEAMS_ENABLED != 0u && segment == 0u) s.radiance += FIXED_POINT_RGB(beamMap, pixel);
    bool afterVolumeScatter = s.scatteredOnVolumeSegment;
    s.scatteredOnVolumeSegment = false;
    float tl;
    uint which = firstLightHit(s.o, s.d, h.object == NO_HIT ? 1e30 : h.t, frame.lightCount, tl);
    Medium med = Medium(0.0, float[3](0.0, 0.0, 0.0), 0.0);
    if (MEDIA_ENABLED != 0u) med = mediumOf(s.media);
    if (MEDIA_ENABLED != 0u && SHADING_MODE == SHADING_FULL && med.density > 0.0
        && mediumEvent(s, med, tl, segment, volumeSegment, emitterOnly, rng)) {
        return;
    }
    if (which != frame.lightCount || h.object == NO_HIT) {
        emitterFound(s, which, tl, afterVolumeScatter);
    } else if (emitterOnly) {
        lastSegmentReached(s, h);
    } else {
        surfaceVertex(s, h, med, pixel, rng);
    }
}

// The megakernel's path: every segment and shadow ray in one loop, one ray
// query per iteration at this one call site (shadow_queue.glsl).
vec3 tracePath(vec3 o, vec3 d, uint pixel, inout PathSampler rng, out DenoiseFeatures features) {
    PathState s = pathStart(o, d);
    for (;;) { LOOP_EDGE();
        if (!pathGoesOn(s)) break;
        NextRay r = nextRay(s);
        SceneHit h = traceSceneWith(r.origin, r.dir, 0.0, r.dist, r.shadow != 0u);
        pathEvent(s, h, r.shadow != 0u, pixel, rng);
    }
    features = s.features;
    return s.radiance;
}


#endif
