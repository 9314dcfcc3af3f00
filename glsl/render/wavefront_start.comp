#version 460
// The wavefront pass's first stage (wavefront.glsl): one path per pixel of
// the tile from its camera ray, every one in queue 0 in slot order.
#include "loop_budget.glsl"
#include "wavefront.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

void main() {
    uvec2 local = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(local, pc.tileSize))) return;
    uint slot = local.y * pc.tileSize.x + local.x;
    uvec2 pix = pc.tileOrigin + local;
    PathSampler rng = pathSampler(pix, pc.sampleIndex, frame.seed);
    PathState s = pathStart(frame.eye, sampleRay(pix));
    storePath(slot, s, rng);
    waveRays[slot] = nextRay(s);
    waveItems[slot] = slot;
}
