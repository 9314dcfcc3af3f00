#ifndef GBUFFER_GLSL
#define GBUFFER_GLSL
// Shared by gbuffer.comp (ray queries) and gbuffer.rgen (pipeline backend).
// The G-buffer of the caustic passes: for each pixel, the first surface the
// ray through the pixel centre meets (position and object), where the
// caustic splat pass deposits irradiance and the render pass reads it.
#include "intersect.glsl"
#include "frame.glsl"
#include "caustics.glsl"

layout(set = 0, binding = BINDING_GBUFFER, scalar) buffer Receivers { Receiver receivers[]; };


void gbufferPixel(uvec2 pix) {
    if (pix.x >= frame.width || pix.y >= frame.height) return;
    SceneHit h = traceScene(frame.eye, cameraRay(vec2(pix) + 0.5), 0.0, 1e30);
    Receiver r;
    vec3 p = frame.eye + (h.object == NO_HIT ? 0.0 : h.t) * cameraRay(vec2(pix) + 0.5);
    r.position = float[3](p.x, p.y, p.z);
    r.object = h.object;
    receivers[pix.y * frame.width + pix.x] = r;
}

#endif
