// What the passes that ran before the render leave for it (render.glsl): the
// caustic map and G-buffer, the volume pass's in-scattered light and the
// beams' volumetric caustics, each behind a specialisation constant that
// compiles its use out when the pass did not run.
#ifndef PASS_INPUTS_GLSL
#define PASS_INPUTS_GLSL

// Specialisation constant: 1 when the caustic passes ran: the diffuse
// vertices the caustic map covers read it, and the paths it covers are left
// out (see "caustic paths" in tracePath); 0 compiles this out.
layout(constant_id = SPEC_CAUSTICS_ENABLED) const uint CAUSTICS_ENABLED = 0u;

// Specialisation constant: 1 when the volume pass ran: the camera ray's
// first segment gets its in-scattered light from it, and leaves single
// scattering toward positional lights out of its own estimate; 0 compiles
// this out.
layout(constant_id = SPEC_VOLUME_ENABLED) const uint VOLUME_ENABLED = 0u;

// Specialisation constant: 1 when the caustic beam pass ran (caustics in
// fog): the camera ray's first segment gets the volumetric caustics from the
// beam map, and a path that scatters on it and reaches a sphere light
// through the specular vertices the caustic rays follow is left out.
layout(constant_id = SPEC_BEAMS_ENABLED) const uint BEAMS_ENABLED = 0u;

// In-scattered radiance per pixel from the volume pass (volume.comp).
layout(set = 0, binding = BINDING_VOLUME, scalar) readonly buffer Volume { float volume[]; };

#include "caustics.glsl"
layout(set = 0, binding = BINDING_GBUFFER, scalar) readonly buffer Receivers { Receiver receivers[]; };
layout(set = 0, binding = BINDING_CAUSTIC_MAP, scalar) readonly buffer CausticMap { uint64_t causticMap[]; };
// Volumetric-caustic radiance per pixel (caustic_beams.comp), fixed point.
layout(set = 0, binding = BINDING_CAUSTIC_BEAMS, scalar) readonly buffer BeamMap { uint64_t beamMap[]; };

#endif
