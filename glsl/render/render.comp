#version 460
// The render pass with ray queries: the path tracer of render.glsl, one
// workgroup per RENDER_GROUP² block of the tile, blocks in a balanced order
// (balance.glsl).
#include "loop_budget.glsl"
#include "pixel.glsl"
#include "balance.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    renderPixel(balancedPixel(RENDER_GROUP));
    reportLoopBudget();
}
