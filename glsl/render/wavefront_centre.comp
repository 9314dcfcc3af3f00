#version 460
// The wavefront pass's AOVs (wavefront.glsl): on the first sample, the
// pixel-centre ray's depth, normal, albedo and object of every pixel of the
// tile, before its paths add the denoiser's features.
#include "loop_budget.glsl"
#include "wavefront.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    uvec2 local = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(local, pc.tileSize))) return;
    uvec2 pix = pc.tileOrigin + local;
    aovs[pix.y * frame.width + pix.x] = pixelCentreAov(pix);
    reportLoopBudget();
}
