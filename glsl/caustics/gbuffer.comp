#version 460
// The G-buffer pass with ray queries (gbuffer.glsl).
#include "loop_budget.glsl"
#include "gbuffer.glsl"
#include "balance.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    gbufferPixel(balancedPixel(RENDER_GROUP));
    reportLoopBudget();
}
