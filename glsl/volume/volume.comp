#version 460
// The volume pass with ray queries (volume.glsl).
#include "loop_budget.glsl"
#include "volume.glsl"
#include "balance.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    volumePixel(balancedPixel(RENDER_GROUP));
    reportLoopBudget();
}
