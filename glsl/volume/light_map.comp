#version 460
// The volume pass's light maps with ray queries (light_map_pass.glsl).
#include "loop_budget.glsl"
#include "light_map_pass.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    lightMapAt(gl_GlobalInvocationID.xy);
    reportLoopBudget();
}
