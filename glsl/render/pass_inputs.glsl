// What the passes that ran before the render leave for it (render.glsl): the
// caustic map and G-buffer, the volume pass's in-scattered light and the
// beams' volumetric caustics, each behind a specialisation constant
// (CAUSTICS_ENABLED, VOLUME_ENABLED, BEAMS_ENABLED) that compiles its use
// out when the pass did not run.
#ifndef PASS_INPUTS_GLSL
#define PASS_INPUTS_GLSL

#include "render_inputs.glsl"
#include "caustics.glsl"

// In-scattered radiance per pixel from the volume pass (volume.comp).
layout(set = 0, binding = BINDING_VOLUME, scalar) readonly buffer Volume { float volume[]; };

layout(set = 0, binding = BINDING_GBUFFER, scalar) readonly buffer Receivers { Receiver receivers[]; };
layout(set = 0, binding = BINDING_CAUSTIC_MAP, scalar) readonly buffer CausticMap { uint64_t causticMap[]; };
// Volumetric-caustic radiance per pixel (caustic_beams.comp), fixed point.
layout(set = 0, binding = BINDING_CAUSTIC_BEAMS, scalar) readonly buffer BeamMap { uint64_t beamMap[]; };

#endif
