// Data layouts shared with the host (src/passes/gpu.rs: host_layouts, which
// tests/scene/interface.rs checks member by member against the SPIR-V). Binding numbers come from src/shader_interface.rs through
// build.rs as #defines. All blocks use the scalar layout.
#ifndef INTERFACE_GLSL
#define INTERFACE_GLSL

#extension GL_EXT_scalar_block_layout : require
// Compute passes trace with ray queries; the ray-tracing-pipeline backend's
// shaders (built with RAY_TRACING_PIPELINE defined) with traceRayEXT.
// Passes that trace nothing (NO_TRACING defined) declare neither, nor the
// acceleration structure, so that they run on a device with either.
#if defined(RAY_TRACING_PIPELINE)
#extension GL_EXT_ray_tracing : require
#elif !defined(NO_TRACING)
#extension GL_EXT_ray_query : require
#endif
#extension GL_EXT_control_flow_attributes : require

#include "common.glsl"

// q(p) = pᵀAp + b·p + c with A symmetric: a0=Axx a1=Ayy a2=Azz a3=Axy a4=Ayz a5=Axz,
// b = (b0,b1,b2), c.
struct Quadric {
    float a[6];
    float b[3];
    float c;
};

struct Object {
    Quadric base;
    uint material;
    uint firstCell;    // cell of primitive 0 of the object's bottom level
    uint uvMapping;    // UV_*
    float uAxis[3];    // planar mapping: gradients of u and v (object frame)
    float vAxis[3];
    vec2 uvScale;
    vec2 uvOffset;
    // Rays whose object-frame origin is farther than this from the object's
    // origin are formed in f64 and searched in a parameter local to each
    // cell (root_search.glsl, candidateFirstRoot).
    float rebaseDistance;
    // The map from the GPU's world frame to the object's, in f64 (columns:
    // x, y, z, translation): the hardware's f32 instance transform places an
    // object D away only to ~6e-8 · D.
    double worldToObject[12];
};

// A perturbation f · max(Q, 0)³ (48 bytes). A bounded support {Q >= 0} (an
// ellipsoid) is stored about its centre, where Q has no linear term:
// Q(p) = hᵀAh + c with h = p - centre, inside a sphere of `radius` about
// `centre`. An unbounded support (radius < 0) is stored in the object frame
// with its linear part b in the same three floats: Q(p) = pᵀAp + b·p + c.
// perturbationQuadric and perturbationCentre (quadric.glsl) read either.
struct Perturbation {
    float a[6];
    float c;
    float f;
    float centreOrLinear[3];
    float radius;
};

struct Cell {
    float lo[3];
    float hi[3];
    uint first;   // into the cell lists
    uint count;
};

#ifndef NO_TRACING
layout(set = 0, binding = BINDING_TLAS) uniform accelerationStructureEXT tlas;
#endif
layout(set = 0, binding = BINDING_OBJECTS, scalar) readonly buffer Objects { Object objects[]; };
layout(set = 0, binding = BINDING_CELLS, scalar) readonly buffer Cells { Cell cells[]; };
layout(set = 0, binding = BINDING_PERTURBATIONS, scalar) readonly buffer Perturbations { Perturbation perturbations[]; };
layout(set = 0, binding = BINDING_CELL_LISTS, scalar) readonly buffer CellLists { uint cellLists[]; };

#endif
