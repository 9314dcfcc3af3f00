// The scene's buffers and the extensions every pass uses. The structs in
// them, like every struct shared with the host, come from
// gpu_structs.glsl, which build.rs generates from src/gpu_structs.toml (the
// Rust twins come from the same table; tests/scene/interface.rs checks
// them member by member against the SPIR-V). Binding numbers come from
// src/gpu/shader_interface.rs through build.rs as #defines. All blocks use the
// scalar layout.
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
#include "gpu_structs.glsl"





#ifndef NO_TRACING
layout(set = 0, binding = BINDING_TLAS) uniform accelerationStructureEXT tlas;
#endif
layout(set = 0, binding = BINDING_OBJECTS, scalar) readonly buffer Objects { Object objects[]; };
layout(set = 0, binding = BINDING_CELLS, scalar) readonly buffer Cells { Cell cells[]; };
layout(set = 0, binding = BINDING_PERTURBATIONS, scalar) readonly buffer Perturbations { Perturbation perturbations[]; };
layout(set = 0, binding = BINDING_CELL_LISTS, scalar) readonly buffer CellLists { uint cellLists[]; };

#endif
