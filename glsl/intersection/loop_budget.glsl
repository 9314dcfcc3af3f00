// The loop budget (issue 27; docs/stability.md, "Loop budget").
//
// Mesa 25.0's gallivm source gives each shader invocation (a vector of
// lanes) 65,535 loop back-edges in all its loops and then silently leaves
// them (lp_bld_ir_common.c, LP_MAX_TGSI_LOOP_ITERATIONS; Mesa 25.1 removed
// it): a wrong image and no error. With LOOP_BUDGET on, every loop of the
// tracing code counts its iterations (LOOP_EDGE(), one per pass through the
// body: a back-edge or the exit) into loopEdges, and the shader's last call,
// reportLoopBudget(), keeps the most any invocation counted. The count holds
// the project's loops (the path, the ray-query candidate loop, the root
// search, texture filtering, light loops); lavapipe's own BVH walk inside
// rayQueryProceedEXT is not visible from here. Off (the default: every
// normal render) the counting compiles to nothing.
//
// Tracing shaders include this file first; elsewhere LOOP_EDGE() is empty
// (common.glsl).
#ifndef LOOP_BUDGET_GLSL
#define LOOP_BUDGET_GLSL

#extension GL_EXT_scalar_block_layout : require

#include "gpu_structs.glsl"
#include "spec_constants.glsl"

layout(set = 0, binding = BINDING_LOOP_BUDGET, std430) buffer LoopBudgetBuffer { LoopBudget loopBudget; };

uint loopEdges = 0u;

#define LOOP_EDGE() if (LOOP_BUDGET != 0u) { loopEdges += 1u; }

// Reports the invocation's count; the last call of main.
void reportLoopBudget() {
    if (LOOP_BUDGET != 0u) {
        atomicMax(loopBudget.mostEdges, loopEdges);
        atomicAdd(loopBudget.invocations, 1u);
    }
}

#endif
