//! The shader's texture filters (glsl/lib/texfilter.glsl) on footprints given
//! directly, against analytic answers:
//!
//! - EWA (the reference lookup) and the trilinear probes (the default) over
//!   the mip chain of a checkerboard against the exact average of the
//!   (continuous) checkerboard under the same Gaussian footprint, computed
//!   on the CPU by quadrature, for isotropic, anisotropic and rotated
//!   footprints from a tenth of a texel to many checker cells;
//! - LEAN filtering of a normal map of random bumps: the roughness after
//!   filtering to the coarsest level against the one that the slope variance
//!   measured on the CPU (from the height field, in f64) predicts.

use crate::common;

use glam::{DVec2, DVec3, Vec3};
use quadray::model::geometry::{FunctionalObject, Quadric};
use quadray::model::scene::{Material, MaterialMaps};
use quadray::passes::gpu::{GpuTexQuery, GpuTexResult};
use quadray::passes::{GpuScene, TexProbePass};

use quadray::model::texture::{bump_heights, checker, lean, normals_from_heights, TextureImage};
use quadray::passes::LookupMode;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Checkerboard: `SIZE` texels, `CELLS` cells a side, values 1 and 0 (red).
const SIZE: u32 = 256;
const CELLS: u32 = 16;

/// EWA against the exact Gaussian average, |error| in units of the checker's
/// contrast (1), for isotropic footprints whose σ is at least one texel. EWA
/// asks each mip level for the footprint less the level's own box filter,
/// plus level 0's bilinear reconstruction (what `none` reads), with Gaussian
/// weights at least two texels of the level wide; against the continuous
/// checker that reconstruction remains (measured: at most 0.0071).
const EWA_TOLERANCE: f64 = 0.01;
/// Anisotropic footprints (measured: at most 0.0069): the tap budget
/// (MAX_TAPS = 1024 texels in the 3σ ellipse) would force a coarser level,
/// whose blur widens the minor axis, only for longer ellipses than these.
const EWA_ANISOTROPIC_TOLERANCE: f64 = 0.01;
/// Footprints below a texel: the filter reconstructs the texels (σ = ½
/// texel) instead of point sampling the continuous checker, so near the cell
/// edges the result differs by up to the texel's own blur.
const EWA_SUBTEXEL_TOLERANCE: f64 = 0.3;
/// Footprints of many cells: the average is ½.
const EWA_WIDE_TOLERANCE: f64 = 0.005;
/// The footprint classes of the EWA test: (minor σ in texels, anisotropy).
/// Anisotropy 4 and 8 take the fixed probes in a render as well.
const EWA_CLASSES: [(f64, f64); 10] = [
    (0.1, 1.0),
    (0.4, 1.0),
    (1.0, 1.0),
    (2.0, 1.0),
    (4.0, 1.0),
    (8.0, 1.0),
    (16.0, 1.0),
    (2.0, 4.0),
    (4.0, 8.0),
    (WIDE_SIGMA, 1.0),
];
/// Short footprints (at most about twice as long as wide), which a render
/// reads with one probe at a random place along the major axis
/// (texfilter.glsl, randomProbe); their cases come after the others', which
/// stay as they were.
const SHORT_CLASSES: [(f64, f64); 2] = [(2.0, 1.5), (4.0, 2.0)];

/// Every class of the lookup tests.
fn classes() -> Vec<(f64, f64)> {
    EWA_CLASSES.iter().chain(&SHORT_CLASSES).copied().collect()
}

/// σ (texels) of the wide class: many checker cells under the footprint.
const WIDE_SIGMA: f64 = 200.0;
/// LEAN at the coarsest level: relative error of the widened α.
const LEAN_ALPHA_TOLERANCE: f64 = 0.01;

/// The continuous checkerboard (1 in the cell at the origin).
fn checker_at(uv: DVec2) -> f64 {
    let c = (uv * CELLS as f64).floor();
    if (c.x as i64 + c.y as i64).rem_euclid(2) == 0 {
        1.0
    } else {
        0.0
    }
}

/// ∫ checker(uv + a1 s + a2 t) N(s) N(t) ds dt by the midpoint rule over ±4σ
/// on an n x n grid (the standard normal's mass beyond 4σ is 6e-5).
fn exact_average(uv: DVec2, a1: DVec2, a2: DVec2) -> f64 {
    let n = 240;
    let (mut sum, mut weights) = (0.0, 0.0);
    for i in 0..n {
        let s = -4.0 + 8.0 * (i as f64 + 0.5) / n as f64;
        for j in 0..n {
            let t = -4.0 + 8.0 * (j as f64 + 0.5) / n as f64;
            let w = (-0.5 * (s * s + t * t)).exp();
            sum += w * checker_at(uv + a1 * s + a2 * t);
            weights += w;
        }
    }
    sum / weights
}

/// A scene that holds the given textures (the object is never traced).
fn texture_scene(textures: Vec<TextureImage>, maps: MaterialMaps) -> quadray::model::scene::Scene {
    let sphere =
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
    let mut scene = common::scene_with(vec![common::object("sphere", sphere, glam::DAffine3::IDENTITY)]);
    let mut m = Material::diffuse("mapped", Vec3::ONE);
    m.maps = maps;
    scene.materials = vec![m];
    scene.textures = textures;
    scene
}

fn query(texture: u32, uv: DVec2, a1: DVec2, a2: DVec2, alpha: f32) -> GpuTexQuery {
    GpuTexQuery {
        texture,
        alpha,
        uv: uv.as_vec2().to_array(),
        axis1: a1.as_vec2().to_array(),
        axis2: a2.as_vec2().to_array(),
        xi: [-1.0, -1.0],
    }
}

/// Runs `queries` on the textures of `scene` with `lookup` (validation on).
fn run_lookups(scene: &quadray::model::scene::Scene, queries: &[GpuTexQuery], lookup: LookupMode) -> Vec<GpuTexResult> {
    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = GpuScene::new(&ctx.device, &mut cmds, scene, &Default::default()).unwrap();
    let results = TexProbePass::with_lookup(&ctx.device, &gpu, queries, lookup).unwrap().run(&mut cmds).unwrap();
    drop(gpu);
    drop(cmds);
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    results
}

/// The checker cases of the lookup tests: (minor σ, anisotropy, uv, axes).
fn checker_cases() -> Vec<(f64, f64, DVec2, DVec2, DVec2)> {
    let texel = 1.0 / SIZE as f64;
    // Random centres and angles in each class but the wide one.
    let mut rng = Pcg64::seed_from_u64(11);
    let mut cases = Vec::new();
    for &(sigma, aniso) in EWA_CLASSES.iter().filter(|&&(sigma, _)| sigma < WIDE_SIGMA) {
        for _ in 0..24 {
            let uv = DVec2::new(rng.gen(), rng.gen());
            let angle: f64 = rng.gen_range(0.0..std::f64::consts::PI);
            let (c, s) = (angle.cos(), angle.sin());
            let a1 = DVec2::new(c, s) * sigma * aniso * texel;
            let a2 = DVec2::new(-s, c) * sigma * texel;
            cases.push((sigma, aniso, uv, a1, a2));
        }
    }
    // Wide footprints: many cells under the 1σ ellipse.
    for _ in 0..24 {
        let uv = DVec2::new(rng.gen(), rng.gen());
        let a = WIDE_SIGMA * texel;
        cases.push((WIDE_SIGMA, 1.0, uv, DVec2::new(a, 0.0), DVec2::new(0.0, a)));
    }
    for &(sigma, aniso) in &SHORT_CLASSES {
        for _ in 0..24 {
            let uv = DVec2::new(rng.gen(), rng.gen());
            let angle: f64 = rng.gen_range(0.0..std::f64::consts::PI);
            let (c, s) = (angle.cos(), angle.sin());
            cases.push((sigma, aniso, uv, DVec2::new(c, s) * sigma * aniso * texel, DVec2::new(-s, c) * sigma * texel));
        }
    }
    cases
}

/// Runs `lookup` (LookupMode::Ewa or LookupMode::Probes) on the checker cases and
/// checks each class's largest |error| against `bound(σ, anisotropy)`.
fn check_lookup_on_the_checker(name: &str, lookup: LookupMode, bound: impl Fn(f64, f64) -> f64) {
    let scene = texture_scene(
        vec![checker(SIZE, CELLS, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0])],
        MaterialMaps { albedo: Some(0), ..Default::default() },
    );
    let cases = checker_cases();
    let queries: Vec<_> = cases.iter().map(|&(_, _, uv, a1, a2)| query(0, uv, a1, a2, 0.0)).collect();

    let results = run_lookups(&scene, &queries, lookup);

    println!(
        "{name}: {:>12} {:>8} {:>6} {:>12} {:>12} {:>10}",
        "minor σ (tx)", "aniso", "cases", "max |error|", "mean |err|", "bound"
    );
    let mut failures = Vec::new();
    for (sigma, aniso) in classes() {
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0);
        for (k, &(s, a, uv, a1, a2)) in cases.iter().enumerate() {
            if s != sigma || a != aniso {
                continue;
            }
            let exact = exact_average(uv, a1, a2);
            let got = results[k].value[0] as f64;
            assert!(got.is_finite(), "non-finite lookup");
            let err = (got - exact).abs();
            max = max.max(err);
            sum += err;
            n += 1;
        }
        let bound = bound(sigma, aniso);
        println!("{name}: {sigma:>12} {aniso:>8} {n:>6} {max:>12.4} {:>12.4} {bound:>10}", sum / n as f64);
        if max > bound {
            failures.push(format!("σ {sigma} texels, anisotropy {aniso}: {max:.4} > {bound}"));
        }
    }
    assert!(failures.is_empty(), "{name} beyond its bounds: {failures:?}");
}

#[test]
fn ewa_matches_the_exact_gaussian_average_of_a_checkerboard() {
    check_lookup_on_the_checker("EWA", LookupMode::Ewa, |sigma, aniso| {
        if sigma >= WIDE_SIGMA {
            EWA_WIDE_TOLERANCE
        } else if sigma < 1.0 {
            EWA_SUBTEXEL_TOLERANCE
        } else if aniso > 1.0 {
            EWA_ANISOTROPIC_TOLERANCE
        } else {
            EWA_TOLERANCE
        }
    });
}

/// Jitter points per axis of the probes test: a midpoint grid over ±4σ.
const JITTER_GRID: usize = 12;
/// The same for the stochastic probes.
const STOCHASTIC_JITTER_GRID: usize = 36;
/// Trilinear probes averaged over the jitter, against the exact Gaussian
/// average of the checker under jitter ⊛ footprint, |error| in units of the
/// contrast, for footprints of 16 texels or more and for the anisotropic
/// classes (measured: at most 0.044).
const PROBE_TOLERANCE: f64 = 0.05;
/// The same for isotropic footprints of 1 to 8 texels: a **known residual
/// bias** of the probe lookup (measured 0.045 – 0.11, mean 0.012 – 0.047).
/// It is a bias of the minor axis, so the short classes (`SHORT_CLASSES`,
/// minor σ 2 and 4 texels) have it as well: the fixed probes measured 0.050
/// and 0.053 there (means 0.032, 0.020), the renderer's one random probe
/// 0.049 and 0.052 (means 0.031, 0.019); the longer classes (anisotropy 4
/// and 8, within `PROBE_TOLERANCE`) measured 0.033 and 0.044.
/// The level is chosen as if its bilinear tent were a convolution, which it
/// is in expectation only under jitter wider than a texel of that level;
/// here the jitter is as wide as the footprint, a fraction of such a texel,
/// and the checker's edges fall on the level's texel boundaries (the worst
/// case), so the expectation is blurred less than asked. Bounded here so
/// that it cannot grow unnoticed; removing it (a finer level and more
/// probes) is an open item of the prefiltering issue.
const PROBE_SMALL_FOOTPRINT_BIAS: f64 = 0.12;

/// The trilinear probes (the default lookup) are not shift invariant: a
/// bilinear lookup reads a texel's own value at its centre and a blend
/// between texels, so each lookup differs from the Gaussian average by up
/// to the kernel's shape. What the renderer relies on is their expectation
/// under the camera jitter: the mean of the lookups over jitter positions
/// with the footprint's own Gaussian (a `JITTER_GRID`² midpoint grid over
/// ±4σ) must be the exact average of the checker under the Gaussian of twice
/// that covariance (jitter ⊛ footprint), within `PROBE_TOLERANCE`, on the
/// footprint classes of the EWA test, but for the known residual bias at
/// isotropic footprints of 1 to 8 texels (`PROBE_SMALL_FOOTPRINT_BIAS`).
#[test]
fn trilinear_probes_average_to_the_exact_gaussian_under_jitter() {
    check_probes_under_jitter("fixed probes", false);
}

/// The renderer's lookup: the mip level chosen at random and a footprint up
/// to about twice as long as wide read by one probe at a random place
/// along its major axis (`Footprint.xi`; the classes of anisotropy 1.5 and
/// 2), with numbers of a 2D low-discrepancy sequence over the jitter
/// points, held to the same bounds as the fixed probes. Its expectation is
/// estimated over a finer jitter grid (`STOCHASTIC_JITTER_GRID`², each
/// point with its own numbers), since the lookup's own noise adds to the
/// estimate's.
#[test]
fn stochastic_probes_average_to_the_exact_gaussian_under_jitter() {
    check_probes_under_jitter("stochastic probes", true);
}

/// The jitter test of the probe lookup, fixed (`stochastic` false) or with
/// random level and positions.
fn check_probes_under_jitter(name: &str, stochastic: bool) {
    let scene = texture_scene(
        vec![checker(SIZE, CELLS, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0])],
        MaterialMaps { albedo: Some(0), ..Default::default() },
    );
    let cases = checker_cases();
    let side = if stochastic { STOCHASTIC_JITTER_GRID } else { JITTER_GRID };
    let grid: Vec<(f64, f64, f64)> = (0..side)
        .flat_map(|i| {
            (0..side).map(move |j| {
                let s = -4.0 + 8.0 * (i as f64 + 0.5) / side as f64;
                let t = -4.0 + 8.0 * (j as f64 + 0.5) / side as f64;
                (s, t, (-0.5 * (s * s + t * t)).exp())
            })
        })
        .collect();
    let queries: Vec<_> = cases
        .iter()
        .flat_map(|&(_, _, uv, a1, a2)| {
            grid.iter().enumerate().map(move |(g, &(s, t, _))| {
                let mut q = query(0, uv + a1 * s + a2 * t, a1, a2, 0.0);
                if stochastic {
                    // The R2 sequence (a 2D Kronecker sequence of the plastic number).
                    let f = |a: f64| ((0.5 + g as f64 * a).fract()) as f32;
                    q.xi = [f(0.754_877_666_246_692_7), f(0.569_840_290_998_053_3)];
                }
                q
            })
        })
        .collect();
    let results = run_lookups(&scene, &queries, LookupMode::Probes);

    let weights: f64 = grid.iter().map(|g| g.2).sum();
    let root2 = std::f64::consts::SQRT_2;
    let mut failures = Vec::new();
    println!(
        "{name}: {:>12} {:>8} {:>6} {:>12} {:>12} {:>10}",
        "minor σ (tx)", "aniso", "cases", "max |error|", "mean |err|", "bound"
    );
    for (sigma, aniso) in classes() {
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0);
        for (k, &(s, a, uv, a1, a2)) in cases.iter().enumerate() {
            if s != sigma || a != aniso {
                continue;
            }
            let mean: f64 = grid
                .iter()
                .enumerate()
                .map(|(g, &(_, _, w))| {
                    let v = results[k * grid.len() + g].value[0] as f64;
                    assert!(v.is_finite(), "non-finite lookup");
                    w * v
                })
                .sum::<f64>()
                / weights;
            let err = (mean - exact_average(uv, a1 * root2, a2 * root2)).abs();
            max = max.max(err);
            sum += err;
            n += 1;
        }
        let bound = if sigma < 1.0 {
            EWA_SUBTEXEL_TOLERANCE
        } else if (aniso == 1.0 || SHORT_CLASSES.contains(&(sigma, aniso))) && sigma <= 8.0 {
            PROBE_SMALL_FOOTPRINT_BIAS
        } else {
            PROBE_TOLERANCE
        };
        println!("{name}: {sigma:>12} {aniso:>8} {n:>6} {max:>12.4} {:>12.4} {bound:>10}", sum / n as f64);
        if max > bound {
            failures.push(format!("σ {sigma} texels, anisotropy {aniso}: {max:.4} > {bound}"));
        }
    }
    assert!(failures.is_empty(), "{name} under jitter beyond their bounds: {failures:?}");
}

/// Level choices per case of the stochastic-level test: xi = (k + ½) / n.
const LEVEL_CHOICES: usize = 256;
/// The mean of the stochastic level choices against the blend: the
/// stratified xi put level L + 1's weight within 1 / (2 n) of w (at most
/// 0.002 of the contrast for n = 256), plus float rounding.
const LEVEL_CHOICE_TOLERANCE: f64 = 0.5 / LEVEL_CHOICES as f64 + 1e-4;

/// The stochastic mip level (texfilter.glsl, levelChoice: level L + 1 with
/// probability w at λ = L + w, the renderer's paths draw xi per lookup) has
/// the trilinear blend's expectation: on every checker case of the lookup
/// tests, the mean over stratified xi of the probes equals the blended
/// probes (xi < 0).
#[test]
fn stochastic_level_choice_has_the_blends_expectation() {
    let scene = texture_scene(
        vec![checker(SIZE, CELLS, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0])],
        MaterialMaps { albedo: Some(0), ..Default::default() },
    );
    let cases = checker_cases();
    let per_case = LEVEL_CHOICES + 1;
    let queries: Vec<_> = cases
        .iter()
        .flat_map(|&(_, _, uv, a1, a2)| {
            (0..per_case).map(move |k| {
                let mut q = query(0, uv, a1, a2, 0.0);
                if k > 0 {
                    // The level at random, the probes at their fixed places.
                    q.xi = [((k - 1) as f32 + 0.5) / LEVEL_CHOICES as f32, -1.0];
                }
                q
            })
        })
        .collect();
    let results = run_lookups(&scene, &queries, LookupMode::Probes);
    let (mut worst, mut stochastic_cases) = (0.0f64, 0);
    for (c, case) in results.chunks_exact(per_case).enumerate() {
        let blend = case[0].value[0] as f64;
        let values: Vec<f64> = case[1..].iter().map(|r| r.value[0] as f64).collect();
        assert!(values.iter().all(|v| v.is_finite()), "non-finite lookup");
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        if values.iter().any(|&v| (v - values[0]).abs() > 1e-6) {
            stochastic_cases += 1;
        }
        let err = (mean - blend).abs();
        assert!(
            err <= LEVEL_CHOICE_TOLERANCE,
            "case {c} (σ {} texels, anisotropy {}): mean of the level choices {mean:.5}, blend {blend:.5}",
            cases[c].0,
            cases[c].1
        );
        worst = worst.max(err);
    }
    println!(
        "{} cases, {stochastic_cases} with two different levels to choose from: largest |mean of choices − blend| {worst:.2e} \
         (bound {LEVEL_CHOICE_TOLERANCE:.2e})",
        cases.len()
    );
    // The test means something only if many cases fall between two levels
    // that read different values (not the sub-texel and wide classes, whose
    // λ is a whole level, nor the middle of a cell, where both levels read
    // its value: 105 of the 240 cases as measured).
    assert!(stochastic_cases * 3 > cases.len(), "only {stochastic_cases} cases chose between two levels");
}

/// Per-axis slope variance of the normal map `normals_from_heights(h, k)`,
/// measured in f64 from the height field itself: slopes k·∂h (periodic
/// central differences in texels), variance of each axis, averaged.
fn measured_slope_variance(heights: &TextureImage, strength: f64) -> f64 {
    let (w, h) = (heights.width as usize, heights.height as usize);
    let at = |x: usize, y: usize| f64::from(heights.levels[0][y * w + x][0]);
    let (mut sx, mut sy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let dx = strength * (at((x + 1) % w, y) - at((x + w - 1) % w, y)) / 2.0;
            let dy = strength * (at(x, (y + 1) % h) - at(x, (y + h - 1) % h)) / 2.0;
            sx += dx;
            sy += dy;
            sxx += dx * dx;
            syy += dy * dy;
        }
    }
    let n = (w * h) as f64;
    0.5 * ((sxx / n - (sx / n).powi(2)) + (syy / n - (sy / n).powi(2)))
}

#[test]
fn lean_filtering_of_random_bumps_gives_the_predicted_roughness() {
    let heights = bump_heights(256, 64, 7);
    let alpha0 = 0.1f64;
    let cases = [2.0f64, 6.0, 12.0];
    let textures: Vec<_> = cases.iter().map(|&k| normals_from_heights(&heights, k as f32)).collect();
    // Three materials so that each normal map gets its slope moments.
    let mut scene = texture_scene(textures, MaterialMaps { normal: Some(0), ..Default::default() });
    for i in 1..cases.len() {
        let mut m = scene.materials[0].clone();
        m.maps.normal = Some(i);
        scene.materials.push(m);
    }

    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = GpuScene::new(&ctx.device, &mut cmds, &scene, &Default::default()).unwrap();
    // The moments follow the scene's textures, in material order.
    let moments: Vec<u32> = (0..cases.len()).map(|i| (cases.len() + i) as u32).collect();
    let huge = DVec2::new(50.0, 0.0);
    let queries: Vec<_> = moments
        .iter()
        .map(|&t| query(t, DVec2::new(0.3, 0.6), huge, DVec2::new(huge.y, huge.x), alpha0 as f32))
        .collect();
    let results = TexProbePass::new(&ctx.device, &gpu, &queries).unwrap().run(&mut cmds).unwrap();
    drop(gpu);
    drop(cmds);
    drop(ctx);
    common::assert_no_validation_errors(&counters);

    println!("{:>9} {:>14} {:>12} {:>12} {:>10}", "strength", "slope var", "predicted α", "GPU α", "rel error");
    for (k, (&strength, r)) in cases.iter().zip(&results).enumerate() {
        let variance = measured_slope_variance(&heights, strength);
        let predicted = lean::widened_alpha(alpha0, variance);
        let got = f64::from(r.alpha);
        let rel = (got - predicted).abs() / predicted;
        println!("{strength:>9} {variance:>14.5} {predicted:>12.5} {got:>12.5} {rel:>10.2e}");
        assert!(rel < LEAN_ALPHA_TOLERANCE, "case {k}: α {got} vs predicted {predicted}");
        // The mean slope of periodic bumps is zero: the filtered normal is the
        // surface normal.
        assert!(r.value[0].abs() < 1e-3 && r.value[1].abs() < 1e-3, "mean slope {:?}", r.value);
    }
}
