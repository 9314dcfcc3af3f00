// Deterministic per-pixel random numbers: a PCG hash seeds a PCG state
// (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020).
#ifndef RANDOM_GLSL
#define RANDOM_GLSL

uint pcgHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

uint seedRandom(uvec2 pixel, uint sampleIndex, uint seed) {
    return pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(sampleIndex ^ pcgHash(seed))));
}

float rand(inout uint state) {
    state = pcgHash(state);
    return float(state >> 8) * (1.0 / 16777216.0);
}

vec2 rand2(inout uint state) {
    float a = rand(state);
    return vec2(a, rand(state));
}

#endif
