//! The host/shader interface (issue 18), checked against the compiled
//! SPIR-V: every struct the host shares with a shader has the shader's
//! member names, order, offsets and sizes (`passes::gpu::host_layouts`);
//! every struct with a layout in a shader has a host twin; bindings and
//! specialisation constants are found by number and kind. The negative
//! cases (a swapped field, a binding of the wrong kind, a missing binding,
//! an unknown constant id) show that the checks fail where they should.
//! No GPU needed.

use quadray::gpu::shader_interface::*;
use quadray::passes::gpu::host_layouts;
use quadray::vk::reflect::{check_layout, InterfaceError, ShaderInterface};
use quadray::vk::BindingKind;

/// Every compiled shader by name: the compute shaders by file stem
/// (`render`), the ray-tracing pipeline's stages by file name
/// (`render.rgen`, `intersect.rint`, `closest_hit.rchit`, `miss.rmiss`).
fn interfaces() -> Vec<(&'static str, ShaderInterface)> {
    quadray::gpu::shaders::all()
        .into_iter()
        .chain(quadray::gpu::shaders::pipeline_all())
        .map(|(name, spirv)| (name, ShaderInterface::reflect(&spirv).unwrap_or_else(|e| panic!("{name}: {e}"))))
        .collect()
}

/// A shader's file stem: `render` for `render.comp` and `render.rgen`.
fn stem(shader: &str) -> &str {
    shader.split('.').next().unwrap_or(shader)
}

/// The blocks that hold one struct of `gpu_structs.glsl`: the push
/// constants and the frame, path-record and loop-budget buffers.
const WRAPPERS: [&str; 4] = ["PushBlock", "FrameBuffer", "PathRecordBuffer", "LoopBudgetBuffer"];

/// Structs in buffers that only the GPU reads and writes: the wavefront
/// pass's paths between its kernels (glsl/render/wavefront.glsl), which the
/// host allocates by the stride it reflects and never reads, so they have
/// no host twin. Allowed in the `wavefront_*` kernels only.
const GPU_PRIVATE: [&str; 15] = [
    "WavePath",
    "WaveQueue",
    "NextRay",
    "SceneHit",
    "PathState",
    "PathSampler",
    "SobolSampler",
    "ShadowRay",
    "MediumScatter",
    "MediaStack",
    "PathFootprint",
    "PathCovariance",
    "DenoiseFeatures",
    "WaveRays",
    "WaveHits",
];

#[test]
fn host_structs_match_the_shaders_member_by_member() {
    let shaders = interfaces();
    let layouts = host_layouts();
    for layout in &layouts {
        let mut checked = Vec::new();
        for (name, iface) in &shaders {
            if let Some(s) = iface.structs.get(layout.glsl) {
                check_layout(layout, s).unwrap_or_else(|e| panic!("{name}: {e}"));
                checked.push(*name);
            }
        }
        assert!(!checked.is_empty(), "no shader has a struct {} for {}", layout.glsl, layout.name);
        eprintln!("{} = {} ({} fields) in {}", layout.name, layout.glsl, layout.fields.len(), checked.join(", "));
    }
    for (name, iface) in &shaders {
        for (glsl, s) in &iface.structs {
            // A block around one runtime array is checked through the
            // array's element (its stride is the element's size), a block
            // around one struct through that struct.
            let array = s.members.len() == 1 && s.members[0].size == 0;
            let wrapper = s.members.len() == 1
                && WRAPPERS.contains(&glsl.as_str())
                && layouts.iter().any(|l| l.size == s.members[0].size && l.size == s.size());
            let twin = layouts.iter().any(|l| l.glsl == glsl);
            let private = name.starts_with("wavefront_") && GPU_PRIVATE.contains(&glsl.as_str());
            assert!(
                array || wrapper || twin || private,
                "struct {glsl} of {name} has no host twin in passes::gpu::host_layouts"
            );
        }
    }
}

/// A binding number names one resource: every shader that declares it
/// declares it under the same name and kind (the scene's tables, the
/// G-buffer, the caustic, beam and volume buffers that one pass writes and
/// the render pass reads).
#[test]
fn one_binding_number_per_resource() {
    let mut seen: std::collections::BTreeMap<u32, (String, BindingKind, &str)> = Default::default();
    for (shader, iface) in &interfaces() {
        for (&number, b) in &iface.bindings {
            let (name, kind, first) = seen.entry(number).or_insert((b.name.clone(), b.kind, shader));
            assert_eq!(
                (name.as_str(), *kind),
                (b.name.as_str(), b.kind),
                "binding {number} is {name} ({kind:?}) in {first} but {} ({:?}) in {shader}",
                b.name,
                b.kind
            );
        }
    }
    let names: Vec<_> = seen.iter().map(|(n, (name, _, _))| format!("{n} {name}")).collect();
    eprintln!("{} resources: {}", seen.len(), names.join(", "));
    let mut unique: Vec<_> = seen.values().map(|(name, _, _)| name.clone()).collect();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), seen.len(), "one resource under two binding numbers");
}

#[test]
fn bindings_and_constants_are_declared_by_name() {
    let shaders = interfaces();
    let render = &shaders.iter().find(|(n, _)| *n == "render").unwrap().1;
    let expect = [
        (BINDING_TLAS, "tlas", BindingKind::AccelerationStructure),
        (BINDING_OBJECTS, "Objects", BindingKind::StorageBuffer),
        (BINDING_MATERIALS, "Materials", BindingKind::StorageBuffer),
        (BINDING_FRAME, "FrameBuffer", BindingKind::StorageBuffer),
        (BINDING_ACCUM, "accum", BindingKind::StorageImage),
        (BINDING_TEXTURES, "textures", BindingKind::SampledImages(MAX_TEXTURES)),
        (BINDING_RENDER_MAX_SAMPLE, "maxSample", BindingKind::StorageImage),
        (BINDING_RENDER_PATH, "PathRecordBuffer", BindingKind::StorageBuffer),
        (BINDING_LOOP_BUDGET, "LoopBudgetBuffer", BindingKind::StorageBuffer),
    ];
    for (binding, name, kind) in expect {
        let b = &render.bindings[&binding];
        assert_eq!((b.name.as_str(), b.kind), (name, kind), "render binding {binding}");
    }
    assert_eq!(render.bindings.len(), 19);
    assert_eq!(render.spec_constants[&SPEC_LOOKUP_MODE], "LOOKUP_MODE");
    assert_eq!(render.spec_constants[&SPEC_RECORD_PATH], "RECORD_PATH");
    assert_eq!(render.spec_constants[&SPEC_FAR_RAYS], "FAR_RAYS");
    assert_eq!(render.spec_constants[&SPEC_SAMPLER], "SAMPLER");
    assert_eq!(render.push_constant_size as usize, std::mem::size_of::<quadray::passes::gpu::RenderPush>());
    // Within a shader every binding number is one declaration, and every
    // shader's constants use the SPEC_* ids.
    let spec_ids = [
        SPEC_INTERSECT_MODE,
        SPEC_SHADING_MODE,
        SPEC_FILTER_MODE,
        SPEC_MEDIA_ENABLED,
        SPEC_CAUSTICS_ENABLED,
        SPEC_VOLUME_ENABLED,
        SPEC_BEAMS_ENABLED,
        SPEC_RECORD_PATH,
        SPEC_LOOKUP_MODE,
        SPEC_PROBE_CURVATURE,
        SPEC_LOOP_BUDGET,
        SPEC_FAR_RAYS,
        SPEC_SAMPLER,
    ];
    for (name, iface) in &shaders {
        for id in iface.spec_constants.keys() {
            assert!(spec_ids.contains(id), "{name}: constant_id {id} is not a SPEC_* of shader_interface.rs");
        }
    }
    let texprobe = &shaders.iter().find(|(n, _)| *n == "texprobe").unwrap().1;
    assert_eq!(texprobe.bindings[&BINDING_TEXTURES].kind, BindingKind::SampledImages(MAX_TEXTURES));
    assert!(texprobe.bindings.contains_key(&BINDING_TEXPROBE_QUERIES));
}

#[test]
fn the_checks_fail_on_a_swapped_field_a_wrong_binding_and_an_unknown_constant() {
    let shaders = interfaces();
    let render = &shaders.iter().find(|(n, _)| *n == "render").unwrap().1;
    // Two f32 fields of the material swapped on the host: sizes agree, the
    // layout check does not.
    let mut swapped = host_layouts().into_iter().find(|l| l.name == "GpuMaterial").unwrap();
    let i = swapped.fields.iter().position(|f| f.0 == "roughness").unwrap();
    let j = swapped.fields.iter().position(|f| f.0 == "ior").unwrap();
    let (oi, oj) = (swapped.fields[i].1, swapped.fields[j].1);
    swapped.fields[i].1 = oj;
    swapped.fields[j].1 = oi;
    swapped.fields.sort_by_key(|f| f.1);
    let err = check_layout(&swapped, &render.structs["Material"]).unwrap_err();
    assert!(matches!(err, InterfaceError::Layout { .. }), "{err}");
    eprintln!("swapped fields: {err}");
    // A field renamed on one side.
    let mut renamed = host_layouts().into_iter().find(|l| l.name == "GpuLight").unwrap();
    renamed.fields[2].0 = "size";
    assert!(check_layout(&renamed, &render.structs["Light"]).is_err());

    // The render pass's host bindings, then faults in them.
    let host: Vec<(u32, BindingKind)> = render.bindings.iter().map(|(&n, b)| (n, b.kind)).collect();
    assert_eq!(render.check_bindings(&host), Ok(vec![]));
    let mut wrong = host.clone();
    let accum = wrong.iter().position(|b| b.0 == BINDING_ACCUM).unwrap();
    wrong[accum].1 = BindingKind::StorageBuffer;
    let err = render.check_bindings(&wrong).unwrap_err();
    assert!(matches!(err, InterfaceError::Mismatch { binding: BINDING_ACCUM, .. }), "{err}");
    eprintln!("wrong kind: {err}");
    let missing: Vec<_> = host.iter().copied().filter(|b| b.0 != BINDING_LIGHTS).collect();
    let err = render.check_bindings(&missing).unwrap_err();
    assert!(matches!(err, InterfaceError::Missing { binding: BINDING_LIGHTS, .. }), "{err}");
    let mut twice = host.clone();
    twice.push((BINDING_AOV, BindingKind::StorageBuffer));
    assert_eq!(render.check_bindings(&twice), Err(InterfaceError::Twice(BINDING_AOV)));
    // Resources at numbers the shader does not declare are left out.
    let mut extra = host;
    extra.push((40, BindingKind::StorageBuffer));
    assert_eq!(render.check_bindings(&extra), Ok(vec![40]));

    assert!(render.check_spec_constants([SPEC_FILTER_MODE]).is_ok());
    let err = render.check_spec_constants([SPEC_PROBE_CURVATURE]).unwrap_err();
    assert!(matches!(err, InterfaceError::UnknownSpecConstant { id: SPEC_PROBE_CURVATURE, .. }), "{err}");
}

#[test]
fn every_shader_in_glsl_is_compiled_and_listed() {
    let names = |suffixes: &[&str]| -> Vec<String> {
        let mut files: Vec<String> =
            crate::common::files_under(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/glsl")))
                .iter()
                .filter_map(|p| p.file_name()?.to_str().map(str::to_string))
                .filter(|n| suffixes.iter().any(|s| n.ends_with(s)))
                .collect();
        files.sort();
        files
    };
    let mut listed: Vec<String> = quadray::gpu::shaders::all().into_iter().map(|(n, _)| format!("{n}.comp")).collect();
    listed.sort();
    assert_eq!(names(&[".comp"]), listed);
    let mut stages: Vec<String> =
        quadray::gpu::shaders::pipeline_all().into_iter().map(|(n, _)| n.to_string()).collect();
    stages.sort();
    assert_eq!(names(&[".rgen", ".rint", ".rchit", ".rmiss"]), stages);
}

/// The stages every ray-tracing pipeline shares (`Tracer::new`).
const SHARED_STAGES: [&str; 3] = ["intersect.rint", "closest_hit.rchit", "miss.rmiss"];

/// Each pass's ray-tracing pipeline (its ray-generation shader with the
/// shared intersection, closest-hit and miss stages, merged as
/// `PipelineResources` merges them) declares exactly the bindings of its
/// compute twin, by number, name and kind: the host binds one list to
/// either backend. Push constants and specialisation constants agree too.
#[test]
fn every_pipeline_declares_the_interface_of_its_compute_twin() {
    let shaders = interfaces();
    let find = |name: &str| &shaders.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("{name}")).1;
    let shared = SHARED_STAGES.iter().fold(ShaderInterface::default(), |m, s| m.merge(find(s).clone()).unwrap());
    // The shared stages take the scene's geometry and nothing per pass.
    for (binding, b) in &shared.bindings {
        assert!(*binding <= BINDING_CELL_LISTS, "a shared stage declares pass binding {binding} ({})", b.name);
    }
    let mut checked = 0;
    for (name, rgen) in shaders.iter().filter(|(n, _)| n.ends_with(".rgen")) {
        let pipeline = rgen.clone().merge(shared.clone()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let twin = find(stem(name));
        assert_eq!(pipeline.bindings, twin.bindings, "{name} and {}.comp declare other bindings", stem(name));
        assert_eq!(pipeline.push_constant_size, twin.push_constant_size, "{name}: push constants");
        let ids = |i: &ShaderInterface| i.spec_constants.keys().copied().collect::<Vec<_>>();
        assert_eq!(ids(&pipeline), ids(twin), "{name}: specialisation constants");
        let host: Vec<(u32, BindingKind)> = twin.bindings.iter().map(|(&n, b)| (n, b.kind)).collect();
        assert_eq!(pipeline.check_bindings(&host), Ok(vec![]), "{name}");
        eprintln!("{name} + shared stages = {}.comp: {} bindings", stem(name), pipeline.bindings.len());
        checked += 1;
    }
    assert_eq!(checked, 6, "render, gbuffer, caustic_trace, volume, light_map and probe have pipelines");
}
