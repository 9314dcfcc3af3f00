// One sample of one pixel (render.glsl, called by render.comp and
// render.rgen): the AOVs of the pixel-centre ray, the path through the
// jittered camera ray, and the accumulation with its largest sample.
#ifndef PIXEL_GLSL
#define PIXEL_GLSL

#include "render.glsl"
#include "camera.glsl"

// The AOVs of the ray through the pixel centre (depth, normal, albedo,
// object), with no denoiser features yet.
Aov pixelCentreAov(uvec2 pix) {
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
    aov.denoiseAlbedo = float[3](0.0, 0.0, 0.0);
    aov.denoiseNormal = float[3](0.0, 0.0, 0.0);
    return aov;
}

// Adds the sample `radiance` (with the denoiser's features `f`) that the
// path through pixel `pix` brought to the accumulation, its largest sample
// and the AOVs: with `centreAov`, the pixel-centre ray's AOVs are taken
// first (the first sample of the megakernel), else the AOVs there are kept.
void finishSample(uvec2 pix, vec3 radiance, DenoiseFeatures f, bool centreAov) {
    uint idx = pix.y * frame.width + pix.x;
    // The pixel-centre ray's AOVs on the first sample; the denoiser's
    // features summed over all samples (the host divides by their count),
    // so that they are filtered by the pixel filter as the radiance is.
    Aov aov;
    if (centreAov) {
        aov = pixelCentreAov(pix);
    } else {
        aov = aovs[idx];
    }
    for (uint k = 0u; k < 3u; ++k) {
        aov.denoiseAlbedo[k] += f.albedo[k];
        aov.denoiseNormal[k] += f.normal[k];
    }
    aovs[idx] = aov;
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

// The camera ray of pixel `pix` for this sample (its jitter from the pixel
// filter).
vec3 sampleRay(uvec2 pix) { return cameraRay(vec2(pix) + 0.5 + cameraJitter(pix, pc.sampleIndex)); }

// One sample of the pixel at `local` in the tile (nothing outside it), the
// whole path in this invocation (the megakernel).
void renderPixel(uvec2 local) {
    if (any(greaterThanEqual(local, pc.tileSize))) return;
    uvec2 pix = pc.tileOrigin + local;
    uint idx = pix.y * frame.width + pix.x;
    PathSampler rng = pathSampler(pix, pc.sampleIndex, frame.seed);
    DenoiseFeatures f;
    vec3 radiance = tracePath(frame.eye, sampleRay(pix), idx, rng, f);
    finishSample(pix, radiance, f, pc.writeAov != 0u);
}

#endif
