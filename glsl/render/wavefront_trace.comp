#version 460
// The wavefront pass's tracing stage (wavefront.glsl): the next ray of every
// queued path, its closest hit (a segment) or any hit (a shadow ray).
#include "loop_budget.glsl"
#include "wavefront.glsl"

layout(local_size_x = WAVE_GROUP) in;

void main() {
    uint slot;
    if (!queuedSlot(gl_GlobalInvocationID.x, slot)) return;
    NextRay r = waveRays[slot];
    SceneHit h = traceSceneWith(r.origin, r.dir, 0.0, r.dist, r.shadow != 0u);
    if (r.shadow != 0u) {
        waveHits[slot].object = h.object;
    } else {
        waveHits[slot] = h;
    }
    reportLoopBudget();
}
