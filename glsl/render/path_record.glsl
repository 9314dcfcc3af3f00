// Recording one pixel's path event by event (render.glsl, specialised with
// SPEC_RECORD_PATH; src/passes/outliers.rs reads it): record() compiles out
// of every other render.
#ifndef PATH_RECORD_GLSL
#define PATH_RECORD_GLSL

#include "render_inputs.glsl"

// RECORD_PATH (spec_constants.glsl): 1 records every event of the path
// into `path`; 0 compiles the recording out.
layout(set = 0, binding = BINDING_RENDER_PATH, scalar) buffer PathRecordBuffer { PathRecord path; };

// The footprint that the next record() stores (a surface event's, set by
// surfaceVertex; PathVertex.footprint), cleared by it.
vec3 recordFootprint = vec3(0.0);

void record(uint event, uint object, uint material, uint lobe, float t, float cosO, float cosI, float pdf, vec3 position,
            vec3 weight, vec3 throughput, vec3 radiance) {
    if (RECORD_PATH == 0u) return;
    vec3 footprint = recordFootprint;
    recordFootprint = vec3(0.0);
    // `count` counts every event; the last slot is kept for EVENT_END, so
    // that a path longer than the record still shows how it ended (the host
    // reports the events left out).
    uint i = path.count;
    path.count = i + 1u;
    if (event == EVENT_END) {
        i = min(i, PATH_RECORD_VERTICES - 1u);
    } else if (i >= PATH_RECORD_VERTICES - 1u) {
        return;
    }
    path.vertices[i] = PathVertex(event, object, material, lobe, t, cosO, cosI, pdf, float[3](position.x, position.y,
        position.z), float[3](weight.x, weight.y, weight.z), float[3](throughput.x, throughput.y, throughput.z),
        float[3](radiance.x, radiance.y, radiance.z), float[3](footprint.x, footprint.y, footprint.z));
}

#endif
