#version 460
// Caustic rays with ray queries (caustic_trace.glsl).
#include "loop_budget.glsl"
#include "caustic_trace.glsl"
#include "balance.glsl"

layout(local_size_x = CAUSTIC_GROUP) in;

void main() {
    traceCausticRay(balancedIndex(CAUSTIC_GROUP));
    reportLoopBudget();
}
