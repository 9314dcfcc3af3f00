// The wavefront render pass (ray queries): the path of render.glsl split
// into stage kernels over queues in device memory (Laine, Karras and Aila,
// "Megakernels Considered Harmful: Wavefront Path Tracing on GPUs", HPG
// 2013; pbrt-v4's wavefront integrator). One wave holds one sample of every
// pixel of a tile, a path per slot; each iteration runs two kernels over the
// queue of live paths:
//
//   wavefront_start.comp   camera rays: a path per pixel, all in queue 0
//   wavefront_trace.comp   the ray each queued path traces next (its segment
//                          or a waiting shadow ray): closest or any hit
//   wavefront_shade.comp   what the path does with the hit (render.glsl,
//                          pathEvent); a path that goes on joins the other
//                          queue, one that ends adds its sample
//   wavefront_centre.comp  the pixel-centre rays' AOVs (first sample)
//
// Every path runs the megakernel's code (pathGoesOn, nextRay, pathEvent) in
// the same order with the same random numbers, so both passes make the same
// image; what changes is that every SIMD batch of a kernel holds live paths
// doing one thing, and that the tracing code and the shading code are
// separate, smaller functions.
#ifndef WAVEFRONT_GLSL
#define WAVEFRONT_GLSL
#extension GL_KHR_shader_subgroup_ballot : require

#include "render.glsl"
#include "pixel.glsl"

// Slots in a wave: one per pixel of the largest tile.
const uint WAVE_SLOTS = RENDER_TILE * RENDER_TILE;
// Invocations per workgroup of the queue kernels (trace, shade).
const uint WAVE_GROUP = 64u;

// A path between two kernels: its state, its sampler, and the shadow-ray
// queue of shadow_queue.glsl (global variables in the megakernel).
struct WavePath {
    PathState s;
    PathSampler rng;
    ShadowRay shadow0;
    ShadowRay shadow1;
    vec3 shadowRadiance0;
    vec3 shadowRadiance1;
    uint shadowCount;
};

layout(set = 0, binding = BINDING_WAVE_PATHS, scalar) buffer WavePaths { WavePath wavePaths[]; };
// The ray each path traces next (nextRay), and what it hit. A shadow ray's
// hit keeps only its object (NO_HIT: unblocked).
layout(set = 0, binding = BINDING_WAVE_RAYS, scalar) buffer WaveRays { NextRay waveRays[]; };
layout(set = 0, binding = BINDING_WAVE_HITS, scalar) buffer WaveHits { SceneHit waveHits[]; };
// Two queues of slots, read and written in turn (pc.wave: the one read this
// iteration): the indirect dispatch arguments of each (workgroups x, y, z),
// its length, and its slots. The host sets the next queue's header to empty
// before each shade stage.
layout(set = 0, binding = BINDING_WAVE_QUEUE, scalar) buffer WaveQueue {
    uint waveArgs[6];
    uint waveCounts[2];
    uint waveItems[];
};

// Stores path `slot` with the shadow-ray queue's globals.
void storePath(uint slot, PathState s, PathSampler rng) {
    wavePaths[slot] = WavePath(s, rng, shadowRay0, shadowRay1, shadowRadiance0, shadowRadiance1, shadowRayCount);
}

// Loads path `slot`, its shadow-ray queue into the globals.
void loadPath(uint slot, out PathState s, out PathSampler rng) {
    WavePath w = wavePaths[slot];
    s = w.s;
    rng = w.rng;
    shadowRay0 = w.shadow0;
    shadowRay1 = w.shadow1;
    shadowRadiance0 = w.shadowRadiance0;
    shadowRadiance1 = w.shadowRadiance1;
    shadowRayCount = w.shadowCount;
}

// The pixel of slot `slot` (slots run over the tile row by row).
uvec2 slotPixel(uint slot) { return pc.tileOrigin + uvec2(slot % pc.tileSize.x, slot / pc.tileSize.x); }

// The slot at position `i` of the queue read this iteration, or false past
// its end.
bool queuedSlot(uint i, out uint slot) {
    if (i >= waveCounts[pc.wave]) return false;
    slot = waveItems[pc.wave * WAVE_SLOTS + i];
    return true;
}

// Appends `slot` to the other queue where `goesOn`: one atomic per subgroup,
// and the queue's workgroup count raised to cover it.
void enqueueNext(uint slot, bool goesOn) {
    uint next = 1u - pc.wave;
    uvec4 ballot = subgroupBallot(goesOn);
    uint n = subgroupBallotBitCount(ballot);
    if (n == 0u) return;
    uint base = 0u;
    if (subgroupElect()) {
        base = atomicAdd(waveCounts[next], n);
        atomicMax(waveArgs[3u * next], (base + n + WAVE_GROUP - 1u) / WAVE_GROUP);
    }
    // The elected lane's count, once the subgroup has left the branch
    // (structured control flow reconverges at its merge; the usual pattern
    // of stream compaction, e.g. in pbrt-v4's GPU queues).
    base = subgroupBroadcastFirst(base);
    if (goesOn) waveItems[next * WAVE_SLOTS + base + subgroupBallotExclusiveBitCount(ballot)] = slot;
}

#endif
