// The camera rays' pixel filter (render.glsl): the jitter of each sample
// and the share of the filter a filtered mode's footprint carries.
#ifndef CAMERA_GLSL
#define CAMERA_GLSL

#include "render_inputs.glsl"

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

#endif
