// Owen-scrambled Sobol points (Burley 2020,
// "Practical Hash-based Owen Scrambling", JCGT 9(4); as Cycles'
// sobol-burley and pbrt-v4's ZSobolSampler use them), one dimension pair
// per decision along the path.
//
// Decision k of a pixel's path draws the 2D point of its sample index from
// the first two Sobol dimensions; the index is shuffled (a nested uniform
// scramble) and both coordinates Owen-scrambled with hashes of the pixel's
// seed and k, so that pairs are independent of each other and of other
// pixels while each pair's points over a pixel's samples stay a (0,2)-
// sequence: stratified in every power-of-two elementary interval. A 1D
// decision takes the first coordinate of its pair. The camera jitter
// keeps its own stratified sequence (render.glsl, cameraJitter).
#ifndef SOBOL_GLSL
#define SOBOL_GLSL

#extension GL_EXT_control_flow_attributes : require

#include "random.glsl"
#include "spec_constants.glsl"

struct SobolSampler {
    uint seed;       // the pixel's scrambling seed
    uint index;      // the sample's index in the pixel's sequence
    uint dimension;  // the next decision's dimension pair
};

SobolSampler sobolSampler(uvec2 pixel, uint sampleIndex, uint seed) {
    return SobolSampler(pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(seed ^ 0x68bc21ebu))), sampleIndex, 0u);
}

// Laine and Karras' hash-based Owen scramble of bit-reversed `x` (Burley,
// listing 5): each bit flipped by a hash of the bits below it.
uint laineKarras(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// A nested uniform (Owen) scramble in base 2 of a 32-bit fixed-point `x`.
uint owenScramble(uint x, uint seed) { return bitfieldReverse(laineKarras(bitfieldReverse(x), seed)); }

// The second Sobol dimension of `index` (the first is its bit reversal):
// direction numbers v_{k+1} = v_k ^ (v_k >> 1). Unrolled and branch-free
// (the shuffled index has all 32 bits).
uint sobolSecond(uint index) {
    uint result = 0u;
    uint v = 1u << 31;
    [[unroll]] for (uint k = 0u; k < 32u; ++k) {
        result ^= v & (0u - ((index >> k) & 1u));
        v ^= v >> 1;
    }
    return result;
}

// The next decision's 2D point in [0, 1)².
vec2 sobolSample2(inout SobolSampler s) {
    uint seed = pcgHash(s.seed ^ pcgHash(s.dimension));
    ++s.dimension;
    uint i = owenScramble(s.index, seed);
    uint x = owenScramble(bitfieldReverse(i), pcgHash(seed ^ 0x9e3779b9u));
    uint y = owenScramble(sobolSecond(i), pcgHash(seed ^ 0x85ebca6bu));
    // 24 bits, so that the float is below 1.
    return vec2(float(x >> 8), float(y >> 8)) * (1.0 / 16777216.0);
}

// The path tracer's samples (render.glsl): SAMPLER_SOBOL takes each
// decision's numbers from the Sobol points above, SAMPLER_INDEPENDENT from
// one random generator per pixel and sample (random.glsl), drawn in the
// order of the path's decisions (src/passes/variant.rs, SamplerMode), by
// SAMPLER (spec_constants.glsl).

struct PathSampler {
    uint rng;
    SobolSampler sobol;
};

PathSampler pathSampler(uvec2 pixel, uint sampleIndex, uint seed) {
    if (SAMPLER == SAMPLER_SOBOL) return PathSampler(0u, sobolSampler(pixel, sampleIndex, seed));
    return PathSampler(seedRandom(pixel, sampleIndex, seed), SobolSampler(0u, 0u, 0u));
}

vec2 sample2(inout PathSampler s) { return SAMPLER == SAMPLER_SOBOL ? sobolSample2(s.sobol) : rand2(s.rng); }

// A seed for random numbers outside the sampler's sequence (its decisions
// stay as they are), for choices that need no stratification (the mip
// level of a texture lookup): a hash of the pixel's sample, how far along
// its sequence it is, and `key`.
uint sideSeed(PathSampler s, uint key) {
    uint state = SAMPLER == SAMPLER_SOBOL ? pcgHash(s.sobol.seed ^ pcgHash(s.sobol.index ^ pcgHash(s.sobol.dimension))) : s.rng;
    return pcgHash(state ^ pcgHash(key + 0x68e31da4u));
}

// A 1D decision: the first coordinate of a Sobol pair, or one random number.
float sample1(inout PathSampler s) { return SAMPLER == SAMPLER_SOBOL ? sobolSample2(s.sobol).x : rand(s.rng); }

#endif
