// Spreading a dispatch's work evenly over the threads that run it.
//
// lavapipe (llvmpipe's compute thread pool, lp_cs_tpool.c) splits the
// workgroups of a dispatch statically: each of its T threads takes one
// contiguous range of N/T workgroups, in the order x fastest, then y. When
// one range costs more than the others (the objects in the lower half of a
// tile, the sky above them), the threads that drew cheap ranges wait at the
// end of every dispatch: renders of the default scene used 124 % of two
// cores.
//
// Workgroup k therefore works on block (k · s) mod N, with s coprime to N
// and near N/φ (a golden-ratio stride, the rank-1 lattice of the Fibonacci
// point sets): every contiguous range of k visits blocks spread evenly over
// the whole grid, so every thread's range costs about the same. A block is
// still the same group of neighbouring pixels (or rays), so SIMD lanes keep
// their coherence; GPUs, which schedule workgroups dynamically, lose
// nothing but the order in which blocks start.
#ifndef BALANCE_GLSL
#define BALANCE_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "common.glsl"

uint gcdOf(uint a, uint b) {
    while (b != 0u) { LOOP_EDGE();
        uint r = a % b;
        a = b;
        b = r;
    }
    return a;
}

// The stride: the first integer from N/φ up that is coprime to N (a few
// steps at most for the grids here), so that k -> (k · s) mod N is a
// permutation of 0 .. N-1.
uint balancedStride(uint n) {
    uint s = max(uint(float(n) * 0.618034), 1u);
    while (gcdOf(s, n) != 1u) { LOOP_EDGE(); ++s; }
    return s;
}

// The block that workgroup `k` of `n` works on.
uint balancedBlock(uint k, uint n) {
    if (n <= 2u) return k;
    return uint((uint64_t(k) * uint64_t(balancedStride(n))) % uint64_t(n));
}

// The invocation's pixel in a 2D dispatch of square blocks of `group`
// pixels a side (one workgroup each, gl_NumWorkGroups.x across).
uvec2 balancedPixel(uint group) {
    uvec2 grid = gl_NumWorkGroups.xy;
    uint b = balancedBlock(gl_WorkGroupID.y * grid.x + gl_WorkGroupID.x, grid.x * grid.y);
    return uvec2(b % grid.x, b / grid.x) * group + gl_LocalInvocationID.xy;
}

// The invocation's index in a 1D dispatch of workgroups of `group` invocations.
uint balancedIndex(uint group) {
    return balancedBlock(gl_WorkGroupID.x, gl_NumWorkGroups.x) * group + gl_LocalInvocationID.x;
}

#endif
