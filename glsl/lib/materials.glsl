// The scene's materials (Material in gpu_structs.glsl, indexed by an
// object's or a light's material), read by every pass that shades: the
// render pass, the caustic rays, the volume and light-map passes.
#ifndef MATERIALS_GLSL
#define MATERIALS_GLSL

#include "interface.glsl"

layout(set = 0, binding = BINDING_MATERIALS, scalar) readonly buffer Materials { Material materials[]; };

#endif
