#version 460
// The closest-hit shader of the pipeline backend: the hit's object, cell,
// t, object-space point (the intersection shader's attribute) and
// world-to-object transform, for the ray-generation shader to finish.
#include "intersect.glsl"

hitAttributeEXT vec3 hitPoint;
layout(location = 0) rayPayloadInEXT HitPayload payload;

void main() {
    payload.t = gl_HitTEXT;
    payload.object = gl_InstanceCustomIndexEXT;
    payload.cell = objects[gl_InstanceCustomIndexEXT].firstCell + gl_PrimitiveID;
    payload.objectPoint = hitPoint;
    payload.worldToObject = gl_WorldToObjectEXT;
}
