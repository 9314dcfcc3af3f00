// Data of the caustic passes (structs in gpu_structs.glsl): caustic rays
// traced from the lights through specular objects land on diffuse receivers
// (caustic_trace.comp); neighbouring rays on the emission grid form caustic
// cells whose landing area gives the irradiance (caustic_splat.comp), which
// is splatted into a per-pixel caustic map that the render pass reads.
#ifndef CAUSTICS_GLSL
#define CAUSTICS_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "interface.glsl"

// A fixed-point RGB value of the caustic or beam map (one 64-bit integer per channel).
#define FIXED_POINT_RGB(map, pixel) \
    (vec3(float(map[3u * (pixel)]), float(map[3u * (pixel) + 1u]), float(map[3u * (pixel) + 2u])) \
     / float(CAUSTIC_FIXED_POINT))




#endif
