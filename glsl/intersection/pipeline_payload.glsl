// The payload a ray of the pipeline backend carries back from its closest
// hit (closest_hit.rchit) or miss (miss.rmiss): 72 bytes.
#ifndef PIPELINE_PAYLOAD_GLSL
#define PIPELINE_PAYLOAD_GLSL

struct HitPayload {
    float t;
    uint object;          // NO_HIT on a miss
    uint cell;            // index into cells[]
    vec3 objectPoint;     // the hit in the object's frame
    mat4x3 worldToObject;
};

#endif
