#version 460
// Calibrates the loop-budget counter (loop_budget.glsl) and asks the driver
// whether it limits loops: a counted loop of pc.spend iterations must
// report pc.spend, and a plain loop of as many iterations (its bound
// differs per lane, so the loop is divergent) writes how far it ran: a
// driver with the 65,535 limit stops it there.
#include "loop_budget.glsl"
#define NO_TRACING
#include "interface.glsl"

layout(local_size_x = 8) in;

layout(push_constant, scalar) uniform PushBlock { LoopBudgetPush pc; };

void main() {
    for (uint i = 0u; i < pc.spend; ++i) {
        LOOP_EDGE();
    }
    uint ran = 0u;
    while (ran < pc.spend + gl_LocalInvocationID.x) {
        ran += 1u;
    }
    atomicMax(loopBudget.spent, ran - gl_LocalInvocationID.x);
    reportLoopBudget();
}
