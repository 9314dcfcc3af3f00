#version 460
// The miss shader of the pipeline backend.
#include "intersect.glsl"

layout(location = 0) rayPayloadInEXT HitPayload payload;

void main() {
    payload.object = NO_HIT;
    payload.t = NO_ROOT;
}
