// Russian roulette (render.glsl): after RR_DEPTH bounces a path goes on with
// a probability from its throughput, which then divides its weight.
#ifndef ROULETTE_GLSL
#define ROULETTE_GLSL

#include "render_inputs.glsl"
#include "path_record.glsl"

// Bounces after which Russian roulette may end a path.
const uint RR_DEPTH = 3u;

// The survival probability of Russian roulette at a vertex of bounce
// `bounce` whose throughput is `throughput` (1: no roulette there; see
// survives).
float survival(vec3 throughput, float etaScale, uint bounce) {
    if (bounce + 1u < RR_DEPTH) return 1.0;
    return clamp(max(throughput.x, max(throughput.y, throughput.z)) * etaScale, 0.05, 1.0);
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
    float q = survival(throughput, etaScale, bounce);
    if (q >= 1.0) return true;
    if (sample1(rng) > q) return false;
    throughput /= q;
    record(EVENT_ROULETTE, NO_HIT, NO_TEXTURE, 0u, 0.0, 0.0, 0.0, q, vec3(0.0), vec3(1.0 / q), throughput, vec3(0.0));
    return true;
}

#endif
