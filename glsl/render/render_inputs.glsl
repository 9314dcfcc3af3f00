// What every part of the render pass reads (render.glsl and its fragments,
// each of which includes this file first): the intersection code, the
// samplers, lights and textures, the pass's own bindings and push block,
// and the specialisation constants (MEDIA_ENABLED, FILTER_MODE,
// LOOKUP_MODE, SHADING_MODE, CAUSTICS_ENABLED, VOLUME_ENABLED,
// BEAMS_ENABLED, RECORD_PATH, SAMPLER: spec_constants.glsl, generated from
// src/gpu/shader_interface.rs).
#ifndef RENDER_INPUTS_GLSL
#define RENDER_INPUTS_GLSL

#include "intersect.glsl"
#include "random.glsl"
#include "sobol.glsl"
#include "lights.glsl"
#include "uv.glsl"
#include "materials.glsl"
#include "frame.glsl"
#include "texfilter.glsl"
#include "covariance.glsl"
#include "spec_constants.glsl"

// rgb: summed radiance, a: sample count.
layout(set = 0, binding = BINDING_ACCUM, rgba32f) uniform image2D accum;

// The pixel-centre ray's AOVs (first sample) and the denoiser's feature
// sums (every sample).
layout(set = 0, binding = BINDING_AOV, scalar) buffer Aovs { Aov aovs[]; };

layout(push_constant, scalar) uniform PushBlock { RenderPush pc; };

// The largest single sample per pixel: r its luminance, g the sample index
// that brought it (exact up to 2^24 samples). The outlier report
// (src/passes/outliers.rs) compares it with the bound the scene allows.
layout(set = 0, binding = BINDING_RENDER_MAX_SAMPLE, rg32f) uniform image2D maxSample;

#endif
