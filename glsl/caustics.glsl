// Data of the caustic passes (host twins in src/passes/gpu.rs): caustic rays
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

// Where a caustic ray landed. `path` identifies its sequence of surfaces
// (objects and events, then the receiver); 0 marks a ray that landed on no
// diffuse receiver after at least one specular vertex.
struct CausticRay {
    float position[3];
    uint object;
    float flux[3];     // watts carried by the ray when it lands
    uint path;
    float beamStart[3];  // where its last segment began (its last specular vertex)
    uint inFog;          // 1 when that segment runs through the fog
};

// The first surface seen through a pixel's centre.
struct Receiver {
    float position[3];
    uint object;       // NO_HIT when the ray escapes
};

// One caustic emission grid: `grid` rays over the rectangle [lo, hi] of a
// plane. Point emitters: directions w + x u + y v from `origin` (x, y in the
// rectangle), each carrying intensity × its solid angle. Parallel emitters:
// origins `origin` + x u + y v along w, each carrying irradiance × its area.
struct Emitter {
    vec3 origin;
    uint kind;         // EMITTER_*
    vec3 u;
    uint firstRay;     // the grid's first ray in the ray buffer
    vec3 v;
    uint maxSpecular;  // specular vertices a ray may pass before it lands
    vec3 w;
    float pad;
    vec2 lo;
    vec2 hi;
    uvec2 grid;
    vec3 power;        // intensity (W/sr) or irradiance (W/m²), RGB
};

#endif
