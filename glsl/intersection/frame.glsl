// The per-frame parameters (Frame in gpu_structs.glsl; GpuFrame on the host), read
// by the render pass and the passes that feed it (G-buffer, caustics).
#ifndef FRAME_GLSL
#define FRAME_GLSL

#include "interface.glsl"
#include "media.glsl"

// Camera basis: ray direction = forward + x right + y up, x and y in [-1, 1].
layout(set = 0, binding = BINDING_FRAME, scalar) readonly buffer FrameBuffer { Frame frame; };

// The direction through image position `pixel` (in pixels, y down).
vec3 cameraRay(vec2 pixel) {
    vec2 ndc = vec2(2.0 * pixel.x / float(frame.width) - 1.0, 1.0 - 2.0 * pixel.y / float(frame.height));
    return normalize(frame.forward + ndc.x * frame.right + ndc.y * frame.up);
}

// The pixel filter (camera.glsl, cameraJitter): a point u of the unit
// square taken by the Box-Muller transform to an offset (pixels) from the
// pixel's centre with a Gaussian of standard deviation `sigma`.
vec2 gaussianPixelOffset(vec2 u, float sigma) {
    float r = sigma * sqrt(-2.0 * log(1.0 - u.x));
    float a = 6.2831853 * u.y;
    return r * vec2(cos(a), sin(a));
}

// Image position (pixels, y down) of p; false behind the camera.
bool project(vec3 p, out vec2 pixel) {
    vec3 r = p - frame.eye;
    float z = dot(r, frame.forward) / dot(frame.forward, frame.forward);
    if (z <= 0.0) return false;
    vec2 ndc = vec2(dot(r, frame.right) / dot(frame.right, frame.right), dot(r, frame.up) / dot(frame.up, frame.up)) / z;
    pixel = vec2((ndc.x + 1.0) * 0.5 * float(frame.width), (1.0 - ndc.y) * 0.5 * float(frame.height));
    return true;
}

// The fog as a local value (copied field by field: glslang mis-types a
// direct copy of structs between blocks of different layouts).
Medium fogMedium() {
    Medium m;
    m.density = frame.fog.density;
    m.albedo = frame.fog.albedo;
    m.anisotropy = frame.fog.anisotropy;
    return m;
}

#endif
