//! The GLSL sampling routines (glsl/lib/bsdf.glsl, glsl/lib/lights.glsl, run by
//! glsl/testing/twins.comp) against their f64 CPU twins (src/model/sampling/), which the
//! chi-square tests (tests/sampling/sampling_chi2.rs) check against their pdfs. Same
//! inputs on both sides; the outputs must agree within f32 precision:
//! directions within `DIR_TOL`, weights, radiance and densities within
//! `REL_TOL` relative to max(|cpu|, |gpu|, `FLOOR`): values far below the
//! typical O(1) (deep in a lobe's tail, where f32 loses 1 − F or Λ at
//! grazing angles) are compared to within `REL_TOL` · `FLOOR` absolutely. Inputs within `EDGE` of a decision boundary (the
//! dielectric's reflect/refract choice at u = F, a direction on a lobe's or
//! a cone's rim, visible normals from u1 within `VNDF_RIM` of 1, where
//! sqrt(1 − r²) cancels in f32, sampled directions within `GRAZING` of the
//! tangent plane, where Λ ∝ 1/|cos θ| amplifies the f32 rounding of the
//! direction) may go either way and are counted, not compared; their share
//! must stay below `MAX_EDGE_SHARE`.

use crate::common;

use glam::{DVec3, Vec3};
use quadray::model::sampling::{self, Bsdf};
use quadray::model::scene::{ConductorFresnel, Light, Material, MaterialKind};
use quadray::passes::gpu::{GpuLight, GpuMaterial, TwinCase, TwinPush, TwinResult};
use quadray::vk::{vk, Binding, Buffer, Commands, ComputePipeline, MemoryLocation};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const DIR_TOL: f64 = 2e-4;
const REL_TOL: f64 = 2e-3;
const EDGE: f64 = 1e-4;
const FLOOR: f64 = 1e-3;
const GRAZING: f64 = 1e-3;
const MAX_EDGE_SHARE: f64 = 0.002;
const VNDF_RIM: f64 = 1e-3;

/// twins.comp's structs (from src/gpu_structs.toml) match the shader
/// member by member (names, offsets, sizes), as `tests/scene/interface.rs`
/// checks them in every shader.
#[test]
fn twin_structs_match_the_shader() {
    let iface = quadray::vk::reflect::ShaderInterface::reflect(&quadray::gpu::shaders::twins()).unwrap();
    let layouts = quadray::passes::gpu::host_layouts();
    let twins: Vec<_> = layouts.iter().filter(|l| l.glsl.starts_with("Twin")).collect();
    assert_eq!(twins.len(), 3);
    for layout in twins {
        quadray::vk::reflect::check_layout(layout, &iface.structs[layout.glsl]).unwrap();
    }
}

fn run_twins(cases: &[TwinCase]) -> Vec<TwinResult> {
    run_twins_with(cases, None)
}

/// An environment map for the twin shader: its CDF table, texels, width,
/// height and scale.
type TwinEnvironment<'a> = (&'a [f32], &'a [[f32; 4]], u32, u32, f32);

/// Runs the twin shader, with an environment map for the environment cases.
fn run_twins_with(cases: &[TwinCase], env: Option<TwinEnvironment<'_>>) -> Vec<TwinResult> {
    let ctx = common::context();
    let counters = ctx.counters();
    let results = {
        let device = &ctx.device;
        let pipeline = ComputePipeline::new(device, &quadray::gpu::shaders::twins(), &[]).unwrap();
        let input = Buffer::with_data(device, "twin cases", cases, vk::BufferUsageFlags::STORAGE_BUFFER).unwrap();
        let output = Buffer::storage(
            device,
            "twin results",
            (cases.len() * std::mem::size_of::<TwinResult>()) as u64,
            MemoryLocation::GpuToCpu,
        )
        .unwrap();
        let (table, texels, w, h, scale) = env.unwrap_or((&[0.0], &[[0.0; 4]], 1, 1, 0.0));
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let table = Buffer::with_data(device, "environment table", table, usage).unwrap();
        let texels = Buffer::with_data(device, "environment texels", texels, usage).unwrap();
        use quadray::gpu::shader_interface::*;
        pipeline
            .bind(&[
                (BINDING_TWIN_CASES, Binding::Buffer(&input)),
                (BINDING_TWIN_RESULTS, Binding::Buffer(&output)),
                (BINDING_TWIN_ENV_TABLE, Binding::Buffer(&table)),
                (BINDING_TWIN_ENV_TEXELS, Binding::Buffer(&texels)),
            ])
            .unwrap();
        let mut cmds = Commands::new(device).unwrap();
        let count = cases.len() as u32;
        let push = TwinPush { count, env_width: w, env_height: h, env_scale: scale };
        cmds.run(|rec| pipeline.dispatch(rec.cmd, bytemuck::bytes_of(&push), [count.div_ceil(64), 1, 1])).unwrap();
        let mut r: Vec<TwinResult> = output.read();
        r.truncate(cases.len());
        r
    };
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    results
}

fn d3(a: [f32; 3]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(FLOOR)
}

fn rel3(a: DVec3, b: DVec3) -> f64 {
    (a - b).abs().max_element() / a.abs().max(b.abs()).max_element().max(FLOOR)
}

fn random_materials() -> Vec<Material> {
    let mut out = vec![Material::diffuse("diffuse", Vec3::new(0.8, 0.5, 0.2))];
    for &r in &[0.05f32, 0.2, 0.5, 0.8, 1.0, 0.0] {
        for fresnel in [
            ConductorFresnel::Schlick { f0: Vec3::new(0.95, 0.64, 0.54) },
            ConductorFresnel::Complex { eta: Vec3::new(0.18, 0.42, 1.37), k: Vec3::new(3.42, 2.35, 1.77) },
        ] {
            out.push(Material {
                kind: MaterialKind::Conductor { roughness: r, fresnel },
                ..Material::diffuse("conductor", Vec3::ONE)
            });
        }
    }
    out.push(Material { kind: MaterialKind::Mirror, ..Material::diffuse("mirror", Vec3::new(0.9, 0.8, 0.7)) });
    for ior in [1.33f32, 1.5, 2.4] {
        for roughness in [0.0f32, 0.1, 0.4, 0.8] {
            out.push(Material {
                kind: MaterialKind::Dielectric { roughness, ior },
                ..Material::diffuse(if roughness == 0.0 { "glass" } else { "rough glass" }, Vec3::ONE)
            });
        }
    }
    out
}

fn random_dir(rng: &mut Pcg64, upper: bool) -> DVec3 {
    loop {
        let v = DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
        let l = v.length();
        if l > 1e-3 && l <= 1.0 && (!upper || v.z > 1e-3) {
            return v / l;
        }
    }
}

fn f3(v: DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// A BSDF case of the twin shader: sample `m` from `wo` with `u`, and
/// evaluate it at (`wo`, `wi`).
fn bsdf_case(m: &Material, wo: DVec3, wi: DVec3, u: [f32; 3]) -> TwinCase {
    TwinCase { op: 0, mat: GpuMaterial::from(m), light: GpuLight::default(), wo: f3(wo), wi: f3(wi), u, x: [0.0; 3] }
}

#[test]
fn gpu_bsdf_sampling_matches_the_cpu_twin() {
    let mut rng = Pcg64::seed_from_u64(5);
    let materials = random_materials();
    let mut cases = Vec::new();
    let mut inputs = Vec::new();
    for _ in 0..4000 {
        for m in &materials {
            let dielectric = matches!(m.kind, MaterialKind::Dielectric { .. });
            let wo = random_dir(&mut rng, !dielectric);
            let wi = random_dir(&mut rng, !dielectric);
            let u = [rng.gen::<f32>(), rng.gen::<f32>(), rng.gen::<f32>()];
            // Round the inputs to f32 first so both sides see the same numbers.
            let (wo, wi) = (d3(f3(wo)), d3(f3(wi)));
            cases.push(bsdf_case(m, wo, wi, u));
            inputs.push((m.clone(), wo, wi, u.map(|v| v as f64)));
        }
    }
    let results = run_twins(&cases);
    let (mut compared, mut edge, mut worst_dir, mut worst_weight, mut worst_pdf, mut worst_eval) =
        (0, 0, 0f64, 0f64, 0f64, 0f64);
    let mut failures = Vec::new();
    for ((m, wo, wi, u), r) in inputs.iter().zip(&results) {
        let bsdf = Bsdf::from_material(m);
        // eval and pdf at a given pair.
        let (e, p) = (bsdf.eval(*wo, *wi), bsdf.pdf(*wo, *wi));
        worst_eval = worst_eval.max(rel3(e, d3(r.eval)));
        worst_pdf = worst_pdf.max(rel(p, r.pdf_of as f64));
        if rel3(e, d3(r.eval)) > REL_TOL || rel(p, r.pdf_of as f64) > REL_TOL {
            failures.push(format!(
                "{}: eval/pdf at wo={wo:?} wi={wi:?}: cpu {e:?} {p}, gpu {:?} {}",
                m.name, r.eval, r.pdf_of
            ));
        }
        // Sampling.
        if matches!(m.kind, MaterialKind::Conductor { .. }) && 1.0 - u[0] < VNDF_RIM {
            edge += 1;
            continue;
        }
        if let MaterialKind::Dielectric { ior, roughness } = m.kind {
            // The lobe choice compares u3 with F at the (micro)facet.
            let alpha = (roughness as f64).powi(2);
            let rough = alpha >= sampling::ggx::DELTA_ALPHA;
            let eta = if wo.z > 0.0 { ior as f64 } else { 1.0 / ior as f64 };
            let f = if rough {
                let o = DVec3::new(wo.x, wo.y, wo.z.abs());
                let m = sampling::ggx::sample_vndf(alpha, o, u[0], u[1]);
                sampling::fresnel_dielectric(o.dot(m), eta)
            } else {
                sampling::fresnel_dielectric(wo.z, ior as f64)
            };
            if (u[2] - f).abs() < EDGE || (rough && 1.0 - u[0] < VNDF_RIM) {
                edge += 1;
                continue;
            }
        }
        let cpu = bsdf.sample(*wo, u[0], u[1], u[2]);
        match (cpu, r.valid != 0) {
            (None, false) => compared += 1,
            (Some(s), true) if s.wi.z.abs() < GRAZING => edge += 1,
            (Some(s), true) => {
                compared += 1;
                let dd = (s.wi - d3(r.wi)).length();
                let dw = rel3(s.weight, d3(r.weight));
                let dp = rel(s.pdf.unwrap_or(0.0), r.pdf as f64);
                worst_dir = worst_dir.max(dd);
                worst_weight = worst_weight.max(dw);
                worst_pdf = worst_pdf.max(dp);
                if dd > DIR_TOL || dw > REL_TOL || dp > REL_TOL {
                    failures.push(format!("{}: sample wo={wo:?} u={u:?}: cpu {s:?}, gpu {r:?}", m.name));
                }
            }
            (cpu, _) => {
                // Validity differs: only acceptable right at a rim (wi.z ≈ 0).
                let z = cpu.map_or(r.wi[2] as f64, |s| s.wi.z);
                if z.abs() < 10.0 * EDGE {
                    edge += 1;
                } else {
                    failures.push(format!("{}: validity wo={wo:?} u={u:?}: cpu {cpu:?}, gpu {r:?}", m.name));
                }
            }
        }
    }
    let share = edge as f64 / inputs.len() as f64;
    println!(
        "BSDF twins: {} cases ({} materials), {compared} samples compared, {edge} at an edge ({:.4}%); worst: direction \
         {worst_dir:.2e} (bound {DIR_TOL:e}), weight {worst_weight:.2e}, pdf {worst_pdf:.2e}, eval {worst_eval:.2e} \
         (bound {REL_TOL:e} relative)",
        inputs.len(),
        materials.len(),
        100.0 * share
    );
    for f in failures.iter().take(5) {
        println!("  {f}");
    }
    assert!(failures.is_empty(), "{} disagreements", failures.len());
    assert!(share <= MAX_EDGE_SHARE, "too many edge cases: {share}");
}

/// A direction at angle θ with cos θ = `z` (signed) from the normal, at a
/// random azimuth.
fn dir_with_z(rng: &mut Pcg64, z: f64) -> DVec3 {
    let phi = rng.gen_range(0.0..std::f64::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Every sampled weight on the GPU is at most its bound, at every angle and
/// for every random number, with nothing set aside: grazing directions down
/// to cos θ = 1e-7, visible normals with u1 one f32 step below 1, the
/// dielectrics' lobe choice at u3 = F ± 1e-7, and random inputs. The bound:
/// the albedo for diffuse and mirror lobes, 1 for conductors (Fresnel ≤ 1)
/// and dielectric reflection, 1/η² for refraction (the radiance scaling
/// across an interface; η = n_t / n_i): `weight · η²` ≤ 1. The GLSL writes
/// the visible-normal weight G2/G1 as one quotient (bsdf.glsl,
/// ggxG2OverG1) so that it cannot round above 1; the only slack in the check
/// is the f32 rounding of η² that the GPU divides by (2⁻²¹ relative).
///
/// Light sampling's bound (src/passes/outliers.rs) also needs
/// f(wo, wi) |cos θi| / pdf(wo, wi) ≤ the same bound for directions the
/// BSDF did not choose: checked on random and grazing pairs. There f and
/// the pdf are rounded apart (D(m) appears in both), so the check allows
/// 1e-5 relative: far below the bound's own slack.
#[test]
fn gpu_bsdf_weights_never_exceed_their_bound() {
    const ROUNDING: f64 = 1.0 / (1 << 21) as f64;
    const EVAL_ROUNDING: f64 = 1e-5;
    let mut rng = Pcg64::seed_from_u64(14);
    let materials = random_materials();
    let grazing = [1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1];
    let rims = [1.0 - f32::EPSILON as f64 / 2.0, 1.0 - 1e-6, 1.0 - 1e-4, 0.0];
    let mut cases = Vec::new();
    let mut inputs = Vec::new();
    for m in &materials {
        let dielectric = matches!(m.kind, MaterialKind::Dielectric { .. });
        let mut push = |wo: DVec3, wi: DVec3, u: [f64; 3]| {
            let (wo, wi) = (d3(f3(wo)), d3(f3(wi)));
            let u = u.map(|v| (v as f32).min(1.0 - f32::EPSILON / 2.0));
            cases.push(bsdf_case(m, wo, wi, u));
            inputs.push((m.clone(), wo, wi));
        };
        for _ in 0..300 {
            // Random directions and numbers.
            let wo = random_dir(&mut rng, !dielectric);
            let wi = random_dir(&mut rng, !dielectric);
            push(wo, wi, [rng.gen(), rng.gen(), rng.gen()]);
            for &z in &grazing {
                let sides: &[f64] = if dielectric { &[1.0, -1.0] } else { &[1.0] };
                for &side in sides {
                    let wo = dir_with_z(&mut rng, side * z);
                    // wi grazing too, on either side, and random.
                    let zi = if rng.gen() { z } else { -z };
                    let wi = dir_with_z(&mut rng, zi);
                    push(wo, wi, [rng.gen(), rng.gen(), rng.gen()]);
                    push(wo, random_dir(&mut rng, !dielectric), [rng.gen(), rng.gen(), rng.gen()]);
                    let u1 = rims[rng.gen_range(0..rims.len())];
                    push(wo, wi, [u1, rng.gen(), rng.gen()]);
                    // The lobe choice right at F (smooth: F at wo.z).
                    if let MaterialKind::Dielectric { ior, .. } = m.kind {
                        let f = sampling::fresnel_dielectric(d3(f3(wo)).z, ior as f64);
                        let e = if rng.gen() { 1e-7 } else { -1e-7 };
                        push(wo, wi, [rng.gen(), rng.gen(), (f + e).clamp(0.0, 1.0)]);
                    }
                }
            }
        }
    }
    let results = run_twins(&cases);
    let (mut samples, mut pairs, mut worst_sample, mut worst_pair) = (0usize, 0usize, 0f64, 0f64);
    let mut failures = Vec::new();
    for ((m, wo, wi), r) in inputs.iter().zip(&results) {
        let bound = match m.kind {
            MaterialKind::Diffuse | MaterialKind::Mirror => m.albedo.as_dvec3(),
            _ => DVec3::ONE,
        };
        let eta_rel = match m.kind {
            MaterialKind::Dielectric { ior, .. } => {
                if wo.z > 0.0 {
                    ior as f64
                } else {
                    1.0 / ior as f64
                }
            }
            _ => 1.0,
        };
        let values =
            d3(r.weight).to_array().into_iter().chain(d3(r.eval).to_array()).chain([r.pdf as f64, r.pdf_of as f64]);
        if values.clone().any(|v| !v.is_finite() || v < 0.0) {
            failures.push(format!("{}: non-finite or negative output at wo={wo:?}: {r:?}", m.name));
            continue;
        }
        if r.valid != 0 {
            samples += 1;
            let transmitted = r.wi[2] as f64 * wo.z < 0.0;
            let scale = if transmitted { eta_rel * eta_rel } else { 1.0 };
            let ratio = (d3(r.weight) * scale / bound).max_element();
            worst_sample = worst_sample.max(ratio);
            if ratio > 1.0 + ROUNDING {
                failures.push(format!(
                    "{}: sampled weight {:?} x {scale} over {bound:?} at wo={wo:?}: {r:?}",
                    m.name, r.weight
                ));
            }
        }
        if r.pdf_of > 0.0 {
            pairs += 1;
            let transmitted = wi.z * wo.z < 0.0;
            let scale = if transmitted { eta_rel * eta_rel } else { 1.0 };
            let ratio = (d3(r.eval) * wi.z.abs() * scale / r.pdf_of as f64 / bound).max_element();
            worst_pair = worst_pair.max(ratio);
            if ratio > 1.0 + EVAL_ROUNDING {
                failures.push(format!("{}: f cos / pdf = {ratio} of the bound at wo={wo:?} wi={wi:?}: {r:?}", m.name));
            }
        }
    }
    println!(
        "BSDF weight bounds: {} cases ({} materials), nothing set aside: {samples} samples, largest weight {worst_sample:.9} \
         of its bound (allowed 1 + {ROUNDING:.1e}); {pairs} evaluated pairs, largest f cos / pdf {worst_pair:.9} of \
         the bound (allowed 1 + {EVAL_ROUNDING:e})",
        inputs.len(),
        materials.len()
    );
    for f in failures.iter().take(8) {
        println!("  {f}");
    }
    assert!(failures.is_empty(), "{} weights over their bound", failures.len());
    assert!(samples > 100_000, "too few valid samples: {samples}");
}

#[test]
fn gpu_light_sampling_matches_the_cpu_twin() {
    let mut rng = Pcg64::seed_from_u64(9);
    let lights = [
        Light::Sphere { centre: DVec3::new(0.5, 3.0, -1.0), radius: 0.6, radiance: Vec3::new(5.0, 4.0, 3.0) },
        Light::Sphere { centre: DVec3::new(-2.0, 1.0, 4.0), radius: 0.01, radiance: Vec3::splat(100.0) },
        Light::Rect {
            corner: DVec3::new(-1.0, 2.0, -1.5),
            edge_u: DVec3::new(2.0, 0.0, 0.5),
            edge_v: DVec3::new(0.0, 0.3, 2.0),
            radiance: Vec3::new(2.0, 3.0, 4.0),
        },
    ];
    let mut cases = Vec::new();
    let mut inputs = Vec::new();
    for _ in 0..5000 {
        for l in &lights {
            let x = d3(f3(DVec3::new(rng.gen_range(-2.0..2.0), rng.gen_range(-1.0..0.5), rng.gen_range(-2.0..2.0))));
            let u = [rng.gen::<f32>(), rng.gen::<f32>(), 0.0];
            // A direction for the density: toward a random point near the light.
            let target = match l {
                Light::Sphere { centre, radius, .. } => *centre + random_dir(&mut rng, false) * radius * 1.2,
                Light::Rect { corner, edge_u, edge_v, .. } => {
                    *corner + *edge_u * rng.gen_range(-0.1..1.1) + *edge_v * rng.gen_range(-0.1..1.1)
                }
                _ => unreachable!(),
            };
            let wi = d3(f3((target - x).normalize()));
            cases.push(TwinCase {
                op: 1,
                mat: GpuMaterial::default(),
                light: GpuLight::from(l),
                wo: [0.0; 3],
                wi: f3(wi),
                u,
                x: f3(x),
            });
            inputs.push((l.clone(), x, wi, u.map(|v| v as f64)));
        }
    }
    let results = run_twins(&cases);
    let (mut compared, mut edge, mut worst_dir, mut worst_pdf, mut worst_dist) = (0, 0, 0f64, 0f64, 0f64);
    let mut failures = Vec::new();
    for ((l, x, wi, u), r) in inputs.iter().zip(&results) {
        // The f32 direction is unit only to ~2e-8, which moves the rim of a
        // tiny cone (1 - cos θmax ~ 1e-6) in a cos-based test: normalise it.
        let wi = &wi.normalize();
        let (cpu, pdf_of) = match *l {
            Light::Sphere { centre, radius, radiance } => (
                sampling::sample_sphere_light(*x, centre, radius, radiance.as_dvec3(), u[0], u[1]),
                sampling::pdf_sphere_light(*x, centre, radius, *wi),
            ),
            Light::Rect { corner, edge_u, edge_v, radiance } => (
                sampling::sample_rect_light(*x, corner, edge_u, edge_v, radiance.as_dvec3(), u[0], u[1]),
                sampling::pdf_rect_light(*x, corner, edge_u, edge_v, *wi),
            ),
            _ => unreachable!(),
        };
        // The density at a given direction: 0 outside the light, so a
        // direction on its rim may go either way.
        if (pdf_of == 0.0) != (r.pdf_of == 0.0) {
            edge += 1;
        } else {
            worst_pdf = worst_pdf.max(rel(pdf_of, r.pdf_of as f64));
            if rel(pdf_of, r.pdf_of as f64) > REL_TOL {
                failures.push(format!("{l:?}: pdf at x={x:?} wi={wi:?}: cpu {pdf_of}, gpu {}", r.pdf_of));
            }
        }
        match (cpu, r.valid != 0) {
            (None, false) => compared += 1,
            (Some(s), true) => {
                compared += 1;
                let dd = (s.wi - d3(r.wi)).length();
                let dp = rel(s.pdf.unwrap_or(0.0), r.pdf as f64);
                let dl = rel(s.dist, r.dist as f64);
                worst_dir = worst_dir.max(dd);
                worst_pdf = worst_pdf.max(dp);
                worst_dist = worst_dist.max(dl);
                if dd > DIR_TOL || dp > REL_TOL || dl > REL_TOL || rel3(s.emitted, d3(r.weight)) > REL_TOL {
                    failures.push(format!("{l:?}: sample x={x:?} u={u:?}: cpu {s:?}, gpu {r:?}"));
                }
            }
            (cpu, _) => failures.push(format!("{l:?}: validity x={x:?} u={u:?}: cpu {cpu:?}, gpu {r:?}")),
        }
    }
    let share = edge as f64 / inputs.len() as f64;
    println!(
        "light twins: {} cases, {compared} samples compared, {edge} densities on a rim ({:.4}%); worst: direction \
         {worst_dir:.2e} (bound {DIR_TOL:e}), pdf {worst_pdf:.2e}, distance {worst_dist:.2e} (bound {REL_TOL:e})",
        inputs.len(),
        100.0 * share
    );
    for f in failures.iter().take(5) {
        println!("  {f}");
    }
    assert!(failures.is_empty(), "{} disagreements", failures.len());
    assert!(share <= MAX_EDGE_SHARE, "too many rim cases: {share}");
}

#[test]
fn gpu_environment_map_sampling_matches_the_cpu_twin() {
    use quadray::model::sampling::envmap::{procedural_sky, EnvironmentMap};
    let sky = procedural_sky(64, 32);
    let map = EnvironmentMap::from_texture(&sky, 0.5);
    let table = map.cdf_buffer();
    let texels: Vec<[f32; 4]> = map.texels.iter().map(|t| [t[0], t[1], t[2], 1.0]).collect();
    let mut rng = Pcg64::seed_from_u64(13);
    let mut cases = Vec::new();
    for _ in 0..20_000 {
        let wi = d3(f3(random_dir(&mut rng, false)));
        cases.push(TwinCase {
            op: 2,
            mat: GpuMaterial::default(),
            light: GpuLight::default(),
            wo: [0.0; 3],
            wi: f3(wi),
            u: [rng.gen::<f32>(), rng.gen::<f32>(), 0.0],
            x: [0.0; 3],
        });
    }
    let results = run_twins_with(&cases, Some((&table, &texels, map.width, map.height, map.scale)));
    let (mut compared, mut edge, mut worst_dir, mut worst_pdf) = (0, 0, 0f64, 0f64);
    let mut failures = Vec::new();
    for (c, r) in cases.iter().zip(&results) {
        let (u1, u2) = (c.u[0] as f64, c.u[1] as f64);
        let wi = d3(c.wi).normalize();
        // Densities at given directions: a direction within 1e-4 texel of a
        // texel border may fall in either texel in f32.
        let uv = quadray::model::sampling::envmap::direction_to_uv(wi);
        let border = |x: f64, n: u32| ((x * n as f64) - (x * n as f64).round()).abs() < 1e-4;
        if border(uv.x, map.width) || border(uv.y, map.height) {
            edge += 1;
        } else {
            let p = map.pdf(wi);
            worst_pdf = worst_pdf.max(rel(p, r.pdf_of as f64));
            if rel(p, r.pdf_of as f64) > REL_TOL {
                failures.push(format!("pdf at {wi:?}: cpu {p}, gpu {}", r.pdf_of));
            }
        }
        match (map.sample(u1, u2), r.valid != 0) {
            (None, false) => compared += 1,
            (Some((dir, pdf, radiance)), true) => {
                // A sample at the boundary between two CDF entries may pick
                // the neighbouring texel in f32.
                if rel3(radiance, d3(r.weight)) > REL_TOL && (dir - d3(r.wi)).length() < 0.2 {
                    edge += 1;
                    continue;
                }
                compared += 1;
                let dd = (dir - d3(r.wi)).length();
                worst_dir = worst_dir.max(dd);
                worst_pdf = worst_pdf.max(rel(pdf, r.pdf as f64));
                if dd > DIR_TOL || rel(pdf, r.pdf as f64) > REL_TOL || rel3(radiance, d3(r.weight)) > REL_TOL {
                    failures.push(format!("sample u=({u1}, {u2}): cpu {dir:?} {pdf} {radiance:?}, gpu {r:?}"));
                }
            }
            (cpu, _) => failures.push(format!("validity u=({u1}, {u2}): cpu {cpu:?}, gpu {r:?}")),
        }
    }
    let share = edge as f64 / cases.len() as f64;
    println!(
        "environment map twins: {} cases, {compared} samples compared, {edge} on a texel or CDF border \
         ({:.4}%); worst: direction {worst_dir:.2e} (bound {DIR_TOL:e}), pdf {worst_pdf:.2e} (bound {REL_TOL:e})",
        cases.len(),
        100.0 * share
    );
    for f in failures.iter().take(5) {
        println!("  {f}");
    }
    assert!(failures.is_empty(), "{} disagreements", failures.len());
    assert!(share <= MAX_EDGE_SHARE, "too many border cases: {share}");
}

/// The path tracer's Owen-scrambled Sobol samples (glsl/lib/sobol.glsl) equal
/// their CPU twin (quadray::model::sampling::sobol) to the bit, for pixel seeds,
/// sample indices and decisions over their ranges.
#[test]
fn gpu_sobol_samples_match_the_cpu_twin_to_the_bit() {
    use quadray::model::sampling::sobol;
    let mut rng = Pcg64::seed_from_u64(28);
    let mut cases = Vec::new();
    while cases.len() < 20_000 {
        // The seed travels as a float's bits: keep to normal floats (no NaN,
        // infinity or denormal, which a device may not pass through intact).
        let seed: u32 = rng.gen();
        let exponent = (seed >> 23) & 0xff;
        if exponent == 0 || exponent == 0xff {
            continue;
        }
        let index = if cases.len() % 2 == 0 { rng.gen_range(0..64u32) } else { rng.gen_range(0..1u32 << 24) };
        let dimension = rng.gen_range(0..64u32);
        cases.push(TwinCase {
            op: 3,
            mat: GpuMaterial::default(),
            light: GpuLight::default(),
            wo: [0.0; 3],
            wi: [0.0; 3],
            u: [f32::from_bits(seed), index as f32, dimension as f32],
            x: [0.0; 3],
        });
    }
    let results = run_twins(&cases);
    let mut failures = Vec::new();
    for (c, r) in cases.iter().zip(&results) {
        let (seed, index, dimension) = (c.u[0].to_bits(), c.u[1] as u32, c.u[2] as u32);
        let cpu = sobol::sample2(seed, index, dimension);
        if cpu != [r.wi[0], r.wi[1]] || r.wi[2] != (dimension + 1) as f32 {
            failures.push(format!("seed {seed:#x} index {index} dimension {dimension}: cpu {cpu:?}, gpu {:?}", r.wi));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} differ, e.g. {:?}",
        failures.len(),
        cases.len(),
        &failures[..failures.len().min(5)]
    );
}

#[test]
fn gpu_halo_sampling_matches_the_cpu_twin() {
    use quadray::model::sampling::phase::{halo_pdf, sample_halo};
    // The GPU builds its frame around the axis differently from glam's
    // orthonormal pair, so a sample is compared by its angle to the axis
    // (which carries the density; φ is uniform in both) and by the density
    // there; the density at a given direction is compared directly, at
    // directions of every angle (near the axis, where it has its pole, too).
    let mut rng = Pcg64::seed_from_u64(31);
    let mut cases = Vec::new();
    for i in 0..20_000 {
        let a = d3(f3(random_dir(&mut rng, false)));
        let wi = if i % 4 == 0 {
            // Within a few degrees of the axis.
            d3(f3((a + random_dir(&mut rng, false) * rng.gen_range(0.001..0.1)).normalize()))
        } else {
            d3(f3(random_dir(&mut rng, false)))
        };
        let u = [rng.gen::<f32>(), rng.gen::<f32>(), 0.0];
        cases.push(TwinCase {
            op: 4,
            mat: GpuMaterial::default(),
            light: GpuLight::default(),
            wo: f3(a),
            wi: f3(wi),
            u,
            x: [0.0; 3],
        });
    }
    let results = run_twins(&cases);
    let (mut worst_angle, mut worst_pdf) = (0f64, 0f64);
    let mut failures = Vec::new();
    for (c, r) in cases.iter().zip(&results) {
        let a = d3(c.wo).normalize();
        let (wi, u) = (d3(c.wi).normalize(), c.u.map(f64::from));
        let cpu = sample_halo(a, u[0], u[1]);
        let gpu = d3(r.wi).normalize();
        let angle = (a.dot(cpu).clamp(-1.0, 1.0).acos() - a.dot(gpu).clamp(-1.0, 1.0).acos()).abs();
        let (dp, dq) = (rel(halo_pdf(a, gpu), r.pdf as f64), rel(halo_pdf(a, wi), r.pdf_of as f64));
        worst_angle = worst_angle.max(angle);
        worst_pdf = worst_pdf.max(dp).max(dq);
        if angle > DIR_TOL || dp > REL_TOL || dq > REL_TOL || r.valid != 1 {
            failures.push(format!("axis {a:?} u {u:?} wi {wi:?}: cpu {cpu:?}, gpu {r:?}"));
        }
    }
    println!(
        "halo twins: {} cases; worst: angle to the axis {worst_angle:.2e} (bound {DIR_TOL:e}), density {worst_pdf:.2e} \
         (bound {REL_TOL:e})",
        cases.len()
    );
    assert!(failures.is_empty(), "{} disagreements, e.g. {:?}", failures.len(), &failures[..failures.len().min(5)]);
}
