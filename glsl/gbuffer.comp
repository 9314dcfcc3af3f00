#version 460
// The G-buffer of the caustic passes: for each pixel, the first surface the
// ray through the pixel centre meets (position and object), where the
// caustic splat pass deposits irradiance and the render pass reads it.
#include "intersect.glsl"
#include "frame.glsl"
#include "caustics.glsl"
#include "balance.glsl"

layout(set = 0, binding = BINDING_GBUFFER, scalar) buffer Receivers { Receiver receivers[]; };

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    uvec2 pix = balancedPixel(RENDER_GROUP);
    if (pix.x >= frame.width || pix.y >= frame.height) return;
    SceneHit h = traceScene(frame.eye, cameraRay(vec2(pix) + 0.5), 0.0, 1e30);
    Receiver r;
    vec3 p = frame.eye + (h.object == NO_HIT ? 0.0 : h.t) * cameraRay(vec2(pix) + 0.5);
    r.position = float[3](p.x, p.y, p.z);
    r.object = h.object;
    receivers[pix.y * frame.width + pix.x] = r;
}
