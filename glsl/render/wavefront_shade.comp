#version 460
// The wavefront pass's shading stage (wavefront.glsl): every queued path
// takes its hit (render.glsl, pathEvent); one that goes on queues its next
// ray, one that ends adds its sample to the pixel.
#include "loop_budget.glsl"
#include "wavefront.glsl"

layout(local_size_x = WAVE_GROUP) in;

void main() {
    uint slot;
    if (!queuedSlot(gl_GlobalInvocationID.x, slot)) return;
    uvec2 pix = slotPixel(slot);
    PathState s;
    PathSampler rng;
    loadPath(slot, s, rng);
    pathEvent(s, waveHits[slot], waveRays[slot].shadow != 0u, pix.y * frame.width + pix.x, rng);
    bool goesOn = pathGoesOn(s);
    if (goesOn) {
        storePath(slot, s, rng);
        waveRays[slot] = nextRay(s);
    } else {
        finishSample(pix, s.radiance, s.features, false);
    }
    enqueueNext(slot, goesOn);
    reportLoopBudget();
}
