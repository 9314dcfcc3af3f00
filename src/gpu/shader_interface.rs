// Constants shared by the host and the shaders. build.rs includes this file
// and passes every `pub const NAME: u32 = VALUE;` line to glslang as a
// `#define NAME VALUE`, so bindings and enums are defined once.
// Only such constant lines belong here.
//
// Every resource has one binding number, the same in every pass that
// declares it, and no two resources share one
// (tests/scene/interface.rs, one_binding_number_per_resource).

/// Descriptor binding of the top-level acceleration structure.
pub const BINDING_TLAS: u32 = 0;
/// Descriptor binding of the object table.
pub const BINDING_OBJECTS: u32 = 1;
/// Descriptor binding of the cell table (one entry per procedural AABB).
pub const BINDING_CELLS: u32 = 2;
/// Descriptor binding of the perturbation table.
pub const BINDING_PERTURBATIONS: u32 = 3;
/// Descriptor binding of the per-cell perturbation index lists.
pub const BINDING_CELL_LISTS: u32 = 4;
/// Descriptor binding of the materials.
pub const BINDING_MATERIALS: u32 = 5;
/// Descriptor binding of the lights.
pub const BINDING_LIGHTS: u32 = 6;
/// Descriptor binding of the per-frame parameters (render pass).
pub const BINDING_FRAME: u32 = 7;
/// Descriptor binding of the radiance accumulation buffer (render pass).
pub const BINDING_ACCUM: u32 = 8;
/// Descriptor binding of the AOV buffer (render pass).
pub const BINDING_AOV: u32 = 9;
/// Descriptor binding of the input rays (probe pass; it has no materials).
pub const BINDING_PROBE_RAYS: u32 = 19;
/// Descriptor binding of the output hits (probe pass; it has no lights).
pub const BINDING_PROBE_HITS: u32 = 20;
/// Descriptor binding of the texture queries (texture probe pass).
pub const BINDING_TEXPROBE_QUERIES: u32 = 21;
/// Descriptor binding of the texture probe results (texture probe pass).
pub const BINDING_TEXPROBE_RESULTS: u32 = 22;
/// Descriptor binding of the sampling test cases (CPU-twin pass).
pub const BINDING_TWIN_CASES: u32 = 23;
/// Descriptor binding of the sampling test results (CPU-twin pass).
pub const BINDING_TWIN_RESULTS: u32 = 24;
/// Descriptor binding of the environment sampling table (CPU-twin pass).
pub const BINDING_TWIN_ENV_TABLE: u32 = 25;
/// Descriptor binding of the environment texels (CPU-twin pass).
pub const BINDING_TWIN_ENV_TEXELS: u32 = 26;
/// Specialisation constant id: intersection mode, for cost breakdowns
/// (benchmarks): INTERSECT_FULL, INTERSECT_BOXES (each candidate box reports
/// a hit where the ray enters it: traversal cost only) or INTERSECT_BASE
/// (perturbations ignored: the base quadric's roots in each box).
/// Shaders' default: `INTERSECT_FULL`.
pub const SPEC_INTERSECT_MODE: u32 = 0;
/// Specialisation constant id: shading mode: SHADING_FULL, SHADING_ALBEDO
/// (the first hit's albedo: no light sampling, no bounces; benchmark
/// breakdowns) or SHADING_MIRRORED_ALBEDO (the albedo seen through perfect
/// mirrors; tests).
/// Shaders' default: `SHADING_FULL`.
pub const SPEC_SHADING_MODE: u32 = 1;
/// Specialisation constant id: texture filtering mode: FILTER_NONE,
/// FILTER_RAY_CONES or FILTER_COVARIANCE.
/// Shaders' default: `FILTER_NONE`.
pub const SPEC_FILTER_MODE: u32 = 2;
/// Specialisation constant id: 1 when the scene has a participating medium
/// (the fog or a dielectric's interior); 0 compiles the media code out.
/// Shaders' default: `0u`.
pub const SPEC_MEDIA_ENABLED: u32 = 3;
/// Specialisation constant id: 1 when the caustic passes ran: the diffuse
/// vertices the caustic map covers read it, and the paths it covers are left
/// out (see "caustic paths" in render.glsl); 0 compiles this out.
/// Shaders' default: `0u`.
pub const SPEC_CAUSTICS_ENABLED: u32 = 4;
/// Specialisation constant id: 1 when the volume pass ran: the camera ray's
/// first segment gets its in-scattered light from it, and leaves single
/// scattering toward positional lights out of its own estimate; 0 compiles
/// this out.
/// Shaders' default: `0u`.
pub const SPEC_VOLUME_ENABLED: u32 = 5;
/// Specialisation constant id: 1 when the caustic beam pass ran (caustics in
/// fog): the camera ray's first segment gets the volumetric caustics from the
/// beam map, and a path that scatters on it and reaches a sphere light
/// through the specular vertices the caustic rays follow is left out.
/// Shaders' default: `0u`.
pub const SPEC_BEAMS_ENABLED: u32 = 6;
/// Specialisation constant id: 1 records every event of one pixel's path
/// (one pixel and one sample per dispatch: the outlier report's); 0 compiles
/// the recording out.
/// Shaders' default: `0u`.
pub const SPEC_RECORD_PATH: u32 = 7;
/// Specialisation constant id: texture lookup mode of the filtered modes:
/// LOOKUP_PROBES (trilinear probes, the default) or LOOKUP_EWA (the
/// reference lookup).
/// Shaders' default: `LOOKUP_PROBES`.
pub const SPEC_LOOKUP_MODE: u32 = 8;
/// Specialisation constant id: 1 when the probe pass computes curvatures
/// (the geometry tests), 0 to skip their Hessian (the ray benchmark times
/// intersection alone).
/// Shaders' default: `1u`.
pub const SPEC_PROBE_CURVATURE: u32 = 9;
/// Descriptor binding of the texture array (render pass).
pub const BINDING_TEXTURES: u32 = 10;
/// Descriptor binding of the environment map's sampling tables (render pass).
pub const BINDING_ENV_CDF: u32 = 11;
/// Size of the texture array: a scene may use at most this many texture maps.
pub const MAX_TEXTURES: u32 = 32;
/// Texture index meaning "no map".
pub const NO_TEXTURE: u32 = 4294967295;
/// UV mapping: planar.
pub const UV_PLANAR: u32 = 0;
/// UV mapping: spherical.
pub const UV_SPHERICAL: u32 = 1;
/// UV mapping: cylindrical.
pub const UV_CYLINDRICAL: u32 = 2;
/// Workgroup width and height of the render pass.
pub const RENDER_GROUP: u32 = 8;
/// Tile width and height of the render pass: one dispatch (megakernel) or
/// one wave (wavefront pass, a path per pixel) renders one sample of a tile.
pub const RENDER_TILE: u32 = 256;
/// Descriptor binding of the wavefront pass's paths between kernels
/// (glsl/render/wavefront.glsl).
pub const BINDING_WAVE_PATHS: u32 = 31;
/// Descriptor binding of the wavefront pass's next ray of each path.
pub const BINDING_WAVE_RAYS: u32 = 32;
/// Descriptor binding of the wavefront pass's hit of each path's ray.
pub const BINDING_WAVE_HITS: u32 = 33;
/// Descriptor binding of the wavefront pass's two queues of live paths.
pub const BINDING_WAVE_QUEUE: u32 = 34;
/// Workgroup size of the probe pass.
pub const PROBE_GROUP: u32 = 64;
/// Light kind: point light.
pub const LIGHT_POINT: u32 = 0;
/// Light kind: sphere light.
pub const LIGHT_SPHERE: u32 = 1;
/// Light kind: one-sided parallelogram light.
pub const LIGHT_RECT: u32 = 2;
/// Light kind: directional (distant) light.
pub const LIGHT_DIRECTIONAL: u32 = 3;
/// Material kind: Lambertian.
pub const MATERIAL_DIFFUSE: u32 = 0;
/// Material kind: GGX conductor.
pub const MATERIAL_CONDUCTOR: u32 = 1;
/// Material kind: dielectric.
pub const MATERIAL_DIELECTRIC: u32 = 2;
/// Material kind: perfect mirror.
pub const MATERIAL_MIRROR: u32 = 3;
/// Conductor Fresnel: exact, from a complex index of refraction.
pub const FRESNEL_COMPLEX: u32 = 0;
/// Conductor Fresnel: Schlick's approximation from f0.
pub const FRESNEL_SCHLICK: u32 = 1;
/// Object index written for a ray that hits nothing.
pub const NO_HIT: u32 = 4294967295;
/// Intersection mode: exact first root of F' (the renderer's mode).
pub const INTERSECT_FULL: u32 = 0;
/// Intersection mode: every candidate box is a hit where the ray enters it.
pub const INTERSECT_BOXES: u32 = 1;
/// Intersection mode: perturbations ignored (base quadric only).
pub const INTERSECT_BASE: u32 = 2;
/// Shading mode: the path tracer (the renderer's mode).
pub const SHADING_FULL: u32 = 0;
/// Shading mode: the first hit's albedo only (benchmark breakdowns).
pub const SHADING_ALBEDO: u32 = 1;
/// Shading mode: the albedo of the first hit that is not a perfect mirror,
/// seen through perfect mirrors (times their reflectance); no lighting. With
/// many samples per pixel and no filtering it is the exact pixel average of
/// the textures seen directly and in mirrors (the filtering tests).
pub const SHADING_MIRRORED_ALBEDO: u32 = 2;
/// Shading mode: the albedo of the first diffuse hit, seen through mirrors,
/// glossy conductors and dielectrics (their lobes sampled, the path's weight
/// times that albedo); no lighting. Textures seen directly and in glossy
/// reflections: the prefiltering benchmark's `--shading glossy-albedo`.
pub const SHADING_GLOSSY_ALBEDO: u32 = 3;
/// Texture filtering: bilinear lookups of mip level 0 (with many samples per
/// pixel, the brute-force reference).
pub const FILTER_NONE: u32 = 0;
/// Texture filtering: ray cones (Akenine-Möller et al. 2021), a few
/// trilinear probes along the footprint (EWA is the reference lookup).
pub const FILTER_RAY_CONES: u32 = 1;
/// Texture filtering: covariance footprints carried along the path (the
/// paper's method), read by the same probes.
pub const FILTER_COVARIANCE: u32 = 2;
/// Texture lookup of the filtered modes: trilinear probes along the
/// footprint's major axis (texfilter.glsl, probeLookup; the default).
pub const LOOKUP_PROBES: u32 = 0;
/// Texture lookup of the filtered modes: elliptical weighted averaging over
/// one mip level (texfilter.glsl, ewaLookup; the reference lookup).
pub const LOOKUP_EWA: u32 = 1;
/// Descriptor binding of the caustic rays' landings (caustic passes).
pub const BINDING_CAUSTIC_RAYS: u32 = 18;
/// Descriptor binding of the G-buffer of pixel-centre receivers (written by
/// the G-buffer pass, read by the caustic and render passes).
pub const BINDING_GBUFFER: u32 = 12;
/// Descriptor binding of the caustic irradiance buffer (written by the
/// caustic splat pass, read by the render pass).
pub const BINDING_CAUSTIC_MAP: u32 = 13;
/// Workgroup size of the caustic passes.
pub const CAUSTIC_GROUP: u32 = 64;
/// Caustic emitter: rays from a point (point and sphere lights).
pub const EMITTER_POINT: u32 = 0;
/// Caustic emitter: parallel rays (directional lights).
pub const EMITTER_PARALLEL: u32 = 1;
/// Fixed-point scale of the caustic irradiance buffer (64-bit integer
/// atomics): irradiance × 2^20 is added per pixel and channel.
pub const CAUSTIC_FIXED_POINT: u32 = 1048576;
/// Descriptor binding of the in-scattered radiance per pixel (written by the
/// volume pass, read by the render pass).
pub const BINDING_VOLUME: u32 = 14;
/// Descriptor binding of the light maps (written by light_map.comp, read by
/// the volume pass): per positional light, the distance from the pass's
/// point on the light to the first surface in each direction.
pub const BINDING_LIGHT_MAPS: u32 = 27;
/// Points per camera ray and light at which the volume pass estimates single
/// scattering (volume.glsl).
pub const VOLUME_POINTS: u32 = 16;
/// Descriptor binding of the volumetric-caustic radiance buffer (written by
/// the caustic beam pass, read by the render pass).
pub const BINDING_CAUSTIC_BEAMS: u32 = 15;
/// Grid rays between the corners of a caustic beam (volumetric caustics use
/// coarser cells than surface caustics: a beam's cost grows with its size
/// on screen).
pub const BEAM_STRIDE: u32 = 8;
/// Descriptor binding of the largest single sample per pixel (render pass):
/// its luminance and the sample index that brought it.
pub const BINDING_RENDER_MAX_SAMPLE: u32 = 16;
/// Descriptor binding of the recorded path vertices (render pass, when
/// specialised to record one pixel's path).
pub const BINDING_RENDER_PATH: u32 = 17;
/// Descriptor binding of the loop-budget report (every tracing pass; see
/// glsl/intersection/loop_budget.glsl).
pub const BINDING_LOOP_BUDGET: u32 = 30;
/// Specialisation constant id: 1 to measure the loop budget each tracing
/// invocation leaves (glsl/intersection/loop_budget.glsl; off in renders).
/// Shaders' default: `0u`.
pub const SPEC_LOOP_BUDGET: u32 = 10;
/// Specialisation constant id: 0 when no ray of the scene can start beyond
/// an object's rebase distance (`GpuScene::far_rays`), which leaves the
/// far-ray search (glsl/intersection/root_search.glsl, candidateFirstRoot) and its
/// per-candidate test out of the shaders; 1 (the default) keeps them.
/// Shaders' default: `1u`.
pub const SPEC_FAR_RAYS: u32 = 11;
/// Specialisation constant id: the path tracer's samples (SAMPLER_*).
/// Shaders' default: `SAMPLER_SOBOL`.
pub const SPEC_SAMPLER: u32 = 12;
/// Sampler: independent random numbers per decision (glsl/lib/random.glsl).
pub const SAMPLER_INDEPENDENT: u32 = 0;
/// Sampler: Owen-scrambled Sobol points, one dimension pair per decision
/// (glsl/lib/sobol.glsl).
pub const SAMPLER_SOBOL: u32 = 1;
/// Vertices a recorded path holds at most.
pub const PATH_RECORD_VERTICES: u32 = 96;
/// Recorded path event: a surface scattering (a BSDF sample).
pub const EVENT_SURFACE: u32 = 0;
/// Recorded path event: an emitter found by the path (a light, the
/// environment, or an emissive surface), with its MIS weight.
pub const EVENT_EMITTER: u32 = 1;
/// Recorded path event: next-event estimation queued a shadow ray.
pub const EVENT_LIGHT_SAMPLE: u32 = 2;
/// Recorded path event: a queued shadow ray's result (pdf 1: unblocked).
pub const EVENT_SHADOW: u32 = 3;
/// Recorded path event: a scattering event in a medium.
pub const EVENT_MEDIUM: u32 = 4;
/// Recorded path event: an index-matched interface crossed straight on.
pub const EVENT_PASS_THROUGH: u32 = 5;
/// Recorded path event: the path ended (lobe: why; see `PATH_END_*`).
pub const EVENT_END: u32 = 6;
/// Recorded path event: Russian roulette survived (pdf: the survival probability).
pub const EVENT_ROULETTE: u32 = 7;
/// Recorded lobe: reflection.
pub const LOBE_REFLECT: u32 = 0;
/// Recorded lobe: transmission.
pub const LOBE_TRANSMIT: u32 = 1;
/// Recorded lobe: invalid sample (the path ends).
pub const LOBE_INVALID: u32 = 2;
