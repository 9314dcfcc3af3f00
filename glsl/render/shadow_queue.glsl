// The shadow-ray queue (render.glsl): next-event estimation queues its
// shadow rays, and tracePath traces them at its single tracing call site.
#ifndef SHADOW_QUEUE_GLSL
#define SHADOW_QUEUE_GLSL

#include "render_inputs.glsl"
#include "light_queries.glsl"
#include "path_record.glsl"

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

#endif
