#version 460
// The probe pass with ray queries (probe.glsl).
#include "loop_budget.glsl"
#include "probe.glsl"

layout(local_size_x = PROBE_GROUP) in;

void main() {
    probeRay(gl_GlobalInvocationID.x);
    reportLoopBudget();
}
