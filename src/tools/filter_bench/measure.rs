//! The measurements of one scene: the cached reference, the renders of each
//! mode at each spp, the texture share and mask, the times to equal quality
//! and the temporal stability over a pan.

use std::path::Path;

use glam::DVec3;

use crate::jobs::output::write_png;
use crate::model::geometry::CellParams;
use crate::model::scene::{load_scene, Scene};
use crate::passes::render::PIXEL_FILTER_SIGMA;
use crate::passes::{render, GpuScene, RenderOutput, RenderVariant};
use crate::tools::metrics::{change_error, flip_mean, mean_display_change, RELATIVE_MSE_EPSILON};
use crate::util::files::write_all_or_nothing;
use crate::vk::{Commands, Context};

use super::*;
use crate::passes::ShadingMode;

/// The renderer state shared by a scene's renders.
pub(super) struct Bench<'a> {
    pub(super) ctx: &'a Context,
    pub(super) cmds: Commands,
    pub(super) gpu: GpuScene,
    pub(super) scene: Scene,
    pub(super) size: (u32, u32),
    pub(super) shading: ShadingMode,
    pub(super) lookup: LookupMode,
}

impl Bench<'_> {
    /// Renders with `filter` at `spp`, the camera moved by `offset` along its
    /// right vector.
    pub(super) fn render(
        &mut self,
        filter: FilterMode,
        spp: u32,
        seed: u32,
        offset: f64,
    ) -> Result<RenderOutput, BenchError> {
        let mut scene = self.scene.clone();
        scene.image.seed = seed;
        scene.image.filter = filter;
        let c = &mut scene.camera;
        let right = (c.look_at - c.position).cross(c.up).normalize_or(DVec3::X);
        c.position += right * offset;
        c.look_at += right * offset;
        (scene.image.width, scene.image.height, scene.image.spp) = (self.size.0, self.size.1, spp);
        let variant = self.variant();
        Ok(render(&self.ctx.device, &mut self.cmds, &self.gpu, &scene, variant, &mut |_, _| {})?)
    }

    /// Uploads `scene` in place of the bench's scene, and returns that one.
    pub(super) fn replace_scene(&mut self, scene: Scene) -> Result<Scene, BenchError> {
        let origin = scene.camera.position;
        self.gpu = GpuScene::with_origin(&self.ctx.device, &mut self.cmds, &scene, &CellParams::default(), origin)?;
        Ok(std::mem::replace(&mut self.scene, scene))
    }

    /// The render shader variant with the bench's shading and lookup.
    pub(super) fn variant(&self) -> RenderVariant {
        RenderVariant { shading: self.shading, lookup: self.lookup, ..Default::default() }
    }

    /// An untimed 8x8 render that makes lavapipe compile `filter`'s shader
    /// variant (it does so at the first dispatch) before the timed renders.
    pub(super) fn warm_up(&mut self, filter: FilterMode) -> Result<(), BenchError> {
        let variant = self.variant();
        let previous = std::mem::replace(&mut self.scene.image.filter, filter);
        let warmed =
            crate::passes::Renderer::warm_up(&self.ctx.device, &mut self.cmds, &self.gpu, &self.scene, variant);
        self.scene.image.filter = previous;
        warmed?;
        Ok(())
    }
}

pub(super) fn stem_of(path: &Path) -> String {
    path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}

/// `scene` with every texture map replaced by its mean: albedo and
/// roughness maps by their mean texel (the coarsest mip level), normal and
/// displacement maps by a flat surface. What `none` renders then is the
/// lighting's own noise, without the textures' detail.
pub fn with_mean_maps(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    let mean = |t: usize| -> [f32; 4] {
        let tex = &scene.textures[t];
        tex.levels.last().and_then(|l| l.first()).copied().unwrap_or([1.0; 4])
    };
    for m in &mut s.materials {
        if let Some(t) = m.maps.albedo.take() {
            let c = mean(t);
            m.albedo *= glam::Vec3::new(c[0], c[1], c[2]);
        }
        if let Some(t) = m.maps.roughness.take() {
            let r = mean(t)[0].clamp(0.0, 1.0);
            match &mut m.kind {
                crate::model::scene::MaterialKind::Conductor { roughness, .. }
                | crate::model::scene::MaterialKind::Dielectric { roughness, .. } => *roughness = r,
                _ => {}
            }
        }
        m.maps.normal = None;
        m.maps.displacement = None;
    }
    s
}

/// Per-pixel, per-channel sums over the seeds of one point.
pub(super) struct Accumulation {
    pub(super) sum: Vec<f64>,
    pub(super) sum_sq: Vec<f64>,
    pub(super) count: u32,
    pub(super) seconds: f64,
    pub(super) flip: f64,
}

impl Accumulation {
    pub(super) fn new(n: usize) -> Self {
        Self { sum: vec![0.0; 3 * n], sum_sq: vec![0.0; 3 * n], count: 0, seconds: 0.0, flip: 0.0 }
    }

    pub(super) fn add(&mut self, out: &RenderOutput) {
        for (k, v) in out.radiance.iter().flatten().enumerate() {
            let v = f64::from(*v);
            self.sum[k] += v;
            self.sum_sq[k] += v * v;
        }
        self.count += 1;
        self.seconds += out.seconds;
    }

    /// The unbiased variance of one render at value index k.
    pub(super) fn variance(&self, k: usize) -> f64 {
        let n = f64::from(self.count);
        let mean = self.sum[k] / n;
        ((self.sum_sq[k] - n * mean * mean) / (n - 1.0)).max(0.0)
    }
}

/// The reference: the mean of two halves, and its variance per value.
pub(super) struct Reference {
    pub(super) image: RenderOutput,
    pub(super) values: Vec<f64>,
    pub(super) variance: Vec<f64>,
}

impl Reference {
    pub(super) fn new(a: &RenderOutput, b: &RenderOutput) -> Self {
        let values: Vec<f64> =
            a.radiance.iter().flatten().zip(b.radiance.iter().flatten()).map(|(x, y)| 0.5 * f64::from(x + y)).collect();
        let variance = a
            .radiance
            .iter()
            .flatten()
            .zip(b.radiance.iter().flatten())
            .map(|(x, y)| 0.25 * f64::from(x - y).powi(2))
            .collect();
        let radiance = values.chunks_exact(3).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]).collect();
        let mut image = RenderOutput::from_radiance(a.width, a.height, radiance);
        image.spp = a.spp + b.spp;
        Self { image, values, variance }
    }

    pub(super) fn weight(&self, k: usize) -> f64 {
        1.0 / (self.values[k] * self.values[k] + RELATIVE_MSE_EPSILON)
    }

    /// The reference's own relative variance over `pixels`.
    pub(super) fn relative_variance(&self, pixels: &[usize]) -> f64 {
        let sum: f64 = pixels.iter().flat_map(|&p| 3 * p..3 * p + 3).map(|k| self.variance[k] * self.weight(k)).sum();
        sum / (3 * pixels.len().max(1)) as f64
    }

    /// Error statistics of `acc` over `pixels`.
    pub(super) fn stats(&self, acc: &Accumulation, pixels: &[usize]) -> ErrorStats {
        let n = f64::from(acc.count);
        let (mut error, mut variance) = (0.0, 0.0);
        for k in pixels.iter().flat_map(|&p| 3 * p..3 * p + 3) {
            let r = self.values[k];
            let w = self.weight(k);
            // Mean over the seeds of (x − r)², less the reference's variance.
            let mse = acc.sum_sq[k] / n - 2.0 * r * acc.sum[k] / n + r * r - self.variance[k];
            error += mse * w;
            variance += acc.variance(k) * w;
        }
        let m = (3 * pixels.len().max(1)) as f64;
        ErrorStats { error: error / m, bias2: (error - variance) / m, variance: variance / m }
    }
}

/// A 3 x 3 box average of a per-pixel quantity (edges clamp).
pub(super) fn box3(values: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![0.0; values.len()];
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut count) = (0.0, 0.0);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    sum += values[yy * w + xx];
                    count += 1.0;
                }
            }
            out[y * w + x] = sum / count;
        }
    }
    out
}

pub(super) fn bench_scene(ctx: &Context, config: &Config, path: &Path) -> Result<SceneReport, BenchError> {
    let scene = load_scene(path)?;
    let text = std::fs::read(path).map_err(io_error(path))?;
    let hash = fnv1a_hex(&text);
    let stem = stem_of(path);
    let exposure = scene.image.exposure;
    let mut cmds = Commands::new(&ctx.device)?;
    let gpu = GpuScene::for_render(&ctx.device, &mut cmds, &scene)?;
    let size = (config.width, config.height);
    let mut bench = Bench { ctx, cmds, gpu, scene, size, shading: config.shading, lookup: config.lookup };
    let seed = bench.scene.image.seed;
    let cache = config.out_dir.join("cache");
    if config.shading != ShadingMode::Full {
        eprintln!("{stem}: shading variant {:?}: texture transport alone, no lighting", config.shading);
    }
    std::fs::create_dir_all(&cache).map_err(io_error(&cache))?;
    let pixels = (config.width * config.height) as usize;
    let all: Vec<usize> = (0..pixels).collect();

    let key = |spp: u32, seed: u32, offset: f64| ReferenceInfo {
        scene_hash: hash.clone(),
        width: config.width,
        height: config.height,
        spp,
        seed,
        camera_offset: offset,
        shading: config.shading.constant(),
        pixel_sigma: PIXEL_FILTER_SIGMA,
        version: env!("CARGO_PKG_VERSION").into(),
        seconds: 0.0,
    };
    let half = config.reference_spp / 2;
    let (a, reference_info) = cached_reference(
        &mut bench,
        &cache.join(format!("{stem}-s{}-reference-a", config.shading.constant())),
        key(half, seed.wrapping_add(1_000_003), 0.0),
    )?;
    let (b, _) = cached_reference(
        &mut bench,
        &cache.join(format!("{stem}-s{}-reference-b", config.shading.constant())),
        key(half, seed.wrapping_add(2_000_003), 0.0),
    )?;
    let reference = Reference::new(&a, &b);
    drop((a, b));
    let png = config.out_dir.join(format!("{stem}-reference.png"));
    write_png(&reference.image, exposure, &png).map_err(io_error(&png))?;

    let ladder = spp_ladder(config.max_spp);
    let targets: Vec<u32> = config.targets.iter().copied().filter(|t| ladder.contains(t)).collect();
    if targets.is_empty() {
        return Err(BenchError::Settings(format!(
            "no target spp ({:?}) is on the ladder 1, 2, 4, … {}",
            config.targets, config.max_spp
        )));
    }
    // Every mode's accumulations, by mode then spp. The modes take turns
    // render by render (after every mode's warm-up), so that a drift of the
    // machine's speed over the run falls on all of them alike and their cost
    // per sample compares like with like.
    for (name, filter) in MODES {
        eprintln!("{stem}: {name}: warming up");
        bench.warm_up(filter)?;
    }
    let mut grid: Vec<Vec<Accumulation>> =
        MODES.iter().map(|_| ladder.iter().map(|_| Accumulation::new(pixels)).collect()).collect();
    for (k, &spp) in ladder.iter().enumerate() {
        for s in 0..config.seeds {
            // A different seed per render: independent noise (the same seeds for every mode).
            let render_seed = seed.wrapping_add(1 + k as u32 * 1009 + s * 7919);
            for (m, (name, filter)) in MODES.iter().enumerate() {
                let out = bench.render(*filter, spp, render_seed, 0.0)?;
                let acc = &mut grid[m][k];
                acc.flip += flip_mean(&reference.image, &out, exposure)?;
                acc.add(&out);
                if s == 0 && (k == 0 || spp == config.max_spp) {
                    let png = config.out_dir.join(format!("{stem}-{name}-{spp}spp.png"));
                    write_png(&out, exposure, &png).map_err(io_error(&png))?;
                }
            }
        }
        for (m, (name, _)) in MODES.iter().enumerate() {
            let acc = &grid[m][k];
            let st = reference.stats(acc, &all);
            eprintln!(
                "{stem}: {name:>10} {spp:>5} spp {:>8.3} s  rel MSE {:.5} (bias² {:.5}, variance {:.5})  FLIP {:.4}",
                acc.seconds / f64::from(acc.count),
                st.error,
                st.bias2,
                st.variance,
                acc.flip / f64::from(acc.count)
            );
        }
    }
    let accumulations: Vec<(String, u32, Accumulation)> = MODES
        .iter()
        .zip(grid)
        .flat_map(|((name, _), accs)| ladder.iter().zip(accs).map(move |(&spp, acc)| (name.to_string(), spp, acc)))
        .collect();

    // The maps' share of none's error, and the texture mask, at each target.
    let textured = bench.replace_scene(with_mean_maps(&bench.scene))?;
    bench.warm_up(FilterMode::None)?;
    let mut shares = Vec::new();
    let mut mask = vec![false; pixels];
    for (i, &t) in targets.iter().enumerate() {
        let mut acc = Accumulation::new(pixels);
        for s in 0..config.seeds {
            acc.add(&bench.render(FilterMode::None, t, seed.wrapping_add(3_000_017 + s * 7919), 0.0)?);
        }
        let none = &accumulations.iter().find(|(m, spp, _)| m == "none" && *spp == t).expect("none ran").2;
        let lighting: f64 =
            (0..3 * pixels).map(|k| acc.variance(k) * reference.weight(k)).sum::<f64>() / (3 * pixels) as f64;
        let none_error = reference.stats(none, &all).error;
        let share = 1.0 - lighting / none_error.max(1e-30);
        eprintln!(
            "{stem}: texture share at {t} spp: {share:.3} (none's error {none_error:.5}, with mean maps {lighting:.5})"
        );
        shares.push(share);
        if i + 1 == targets.len() {
            let per_pixel = |a: &Accumulation| -> Vec<f64> {
                (0..pixels).map(|p| (3 * p..3 * p + 3).map(|k| a.variance(k) * reference.weight(k)).sum()).collect()
            };
            let (w, h) = (config.width as usize, config.height as usize);
            let (vn, vm) = (box3(&per_pixel(none), w, h), box3(&per_pixel(&acc), w, h));
            for p in 0..pixels {
                mask[p] = vn[p] > MASK_VARIANCE_RATIO * vm[p];
            }
        }
    }
    bench.replace_scene(textured)?;
    let masked: Vec<usize> = (0..pixels).filter(|&p| mask[p]).collect();
    let mask_fraction = masked.len() as f64 / pixels as f64;
    eprintln!("{stem}: texture mask: {:.1} % of the pixels", 100.0 * mask_fraction);

    let points: Vec<Point> = accumulations
        .iter()
        .map(|(mode, spp, acc)| Point {
            mode: mode.clone(),
            spp: *spp,
            seconds: acc.seconds / f64::from(acc.count),
            whole: reference.stats(acc, &all),
            masked: if masked.is_empty() { ErrorStats::default() } else { reference.stats(acc, &masked) },
            flip: acc.flip / f64::from(acc.count),
        })
        .collect();
    let mut target_rows = Vec::new();
    for masked_target in [false, true] {
        if masked_target && masked.is_empty() {
            continue;
        }
        for (i, &t) in targets.iter().enumerate() {
            target_rows.push(target_times(&points, t, masked_target, shares[i]));
        }
    }
    let none_seconds: f64 = points.iter().filter(|p| p.mode == "none").map(|p| p.seconds).sum();
    let cost_per_sample = MODES
        .iter()
        .map(|(name, _)| {
            let s: f64 = points.iter().filter(|p| p.mode == *name).map(|p| p.seconds).sum();
            (name.to_string(), s / none_seconds.max(1e-30))
        })
        .collect();

    let stability =
        if config.frames >= 2 { temporal_stability(&mut bench, config, &stem, &cache, &key)? } else { vec![] };

    let report = SceneReport {
        scene: path.display().to_string(),
        command: config.command.clone(),
        device: ctx.device.name.clone(),
        width: config.width,
        height: config.height,
        seeds: config.seeds,
        pixel_sigma: PIXEL_FILTER_SIGMA,
        reference: ReferenceInfo { spp: config.reference_spp, ..reference_info },
        reference_variance: reference.relative_variance(&all),
        mask_fraction,
        points,
        targets: target_rows,
        cost_per_sample,
        stability,
    };
    write_scene_outputs(config, &stem, &report)?;
    Ok(report)
}

/// The time each mode takes to reach `none`'s error at `spp` (over the mask
/// when `masked`) at equal quality: error at most the target and bias² at
/// most [`MAX_BIAS_SHARE`] of it.
pub fn target_times(points: &[Point], spp: u32, masked: bool, texture_share: f64) -> Target {
    let stats = |p: &Point| if masked { p.masked } else { p.whole };
    let none = points.iter().find(|p| p.mode == "none" && p.spp == spp).expect("the target's none point");
    let target = stats(none).error;
    let modes = MODES
        .iter()
        .map(|(name, _)| {
            let curve: Vec<(f64, f64, f64)> = points
                .iter()
                .filter(|p| p.mode == *name)
                .map(|p| (p.seconds, stats(p).error, stats(p).bias2))
                .collect();
            let t = time_to_equal_quality(&curve, target, MAX_BIAS_SHARE * target);
            ModeTime {
                mode: name.to_string(),
                seconds_to_target: t,
                speedup_over_none: t.map(|t| none.seconds / t),
                reached_at_first_point: curve
                    .first()
                    .is_some_and(|&(_, e, b)| e <= target && b <= MAX_BIAS_SHARE * target),
            }
        })
        .collect();
    Target { name: format!("none@{spp}"), spp, masked, error: target, seconds: none.seconds, texture_share, modes }
}

/// The time at which a curve of (seconds, error, bias²) points, in the
/// order of increasing effort, first has error ≤ `target` and bias² ≤
/// `max_bias2`: log-log interpolation of the error between the point before
/// and that point; `None` when no point qualifies.
pub fn time_to_equal_quality(points: &[(f64, f64, f64)], target: f64, max_bias2: f64) -> Option<f64> {
    let first = points.iter().position(|&(_, e, b)| e <= target && b <= max_bias2)?;
    if first == 0 {
        return Some(points[0].0);
    }
    let ((t0, e0, _), (t1, e1, _)) = (points[first - 1], points[first]);
    if e0 <= target {
        // The point before had the error but too much bias.
        return Some(t1);
    }
    time_to_reach(&[(t0, e0), (t1, e1)], target)
}

/// The pan's frames: camera offsets k · step · distance, k = 0..frames.
pub(super) fn pan_offsets(scene: &Scene, config: &Config) -> Vec<f64> {
    let distance = (scene.camera.look_at - scene.camera.position).length();
    (0..config.frames).map(|k| k as f64 * config.pan_step * distance).collect()
}

pub(super) fn temporal_stability(
    bench: &mut Bench<'_>,
    config: &Config,
    stem: &str,
    cache: &Path,
    key: &dyn Fn(u32, u32, f64) -> ReferenceInfo,
) -> Result<Vec<Stability>, BenchError> {
    let exposure = bench.scene.image.exposure;
    let offsets = pan_offsets(&bench.scene, config);
    let mean_change = |frames: &[RenderOutput]| -> Result<f64, BenchError> {
        let mut sum = 0.0;
        for pair in frames.windows(2) {
            sum += mean_display_change(&pair[0], &pair[1], exposure)?;
        }
        Ok(sum / (frames.len() - 1) as f64)
    };
    let mut reference_frames = Vec::new();
    for (k, &offset) in offsets.iter().enumerate() {
        let path = cache.join(format!("{stem}-s{}-pan{k}", config.shading.constant()));
        reference_frames
            .push(cached_reference(bench, &path, key(config.reference_frame_spp, bench.scene.image.seed, offset))?.0);
    }
    let reference_change = mean_change(&reference_frames)?;
    let mut rows = vec![Stability {
        mode: "reference".into(),
        spp: config.reference_frame_spp,
        mean_change: reference_change,
        ratio_to_reference: 1.0,
        change_error: 0.0,
    }];
    let seed = bench.scene.image.seed;
    for (name, filter) in MODES {
        let mut frames = Vec::new();
        for &offset in &offsets {
            // The same seed every frame, as a viewer re-rendering a moving
            // camera would use.
            frames.push(bench.render(filter, config.frame_spp, seed, offset)?);
        }
        let change = mean_change(&frames)?;
        let mut error = 0.0;
        for k in 1..frames.len() {
            let (a, b) = (&frames[k - 1], &frames[k]);
            error += change_error(a, b, &reference_frames[k - 1], &reference_frames[k], exposure)?;
        }
        error /= (frames.len() - 1) as f64;
        eprintln!(
            "{stem}: pan, {name:>10} {} spp: mean change {change:.4} (reference {reference_change:.4}), change error \
             {error:.4}",
            config.frame_spp
        );
        rows.push(Stability {
            mode: name.into(),
            spp: config.frame_spp,
            mean_change: change,
            ratio_to_reference: change / reference_change.max(1e-12),
            change_error: error,
        });
    }
    Ok(rows)
}

/// The reference for `info`, from `<base>.json` + `<base>.f32` when their
/// settings match, else rendered (filtering `none`) and stored there.
pub(super) fn cached_reference(
    bench: &mut Bench<'_>,
    base: &Path,
    info: ReferenceInfo,
) -> Result<(RenderOutput, ReferenceInfo), BenchError> {
    let json_path = base.with_extension("json");
    let data_path = base.with_extension("f32");
    if let Ok(text) = std::fs::read_to_string(&json_path) {
        if let Ok(stored) = serde_json::from_str::<ReferenceInfo>(&text) {
            if stored.same_settings(&info) {
                let bytes = std::fs::read(&data_path).map_err(io_error(&data_path))?;
                let n = (info.width * info.height) as usize;
                if bytes.len() != n * 12 {
                    return Err(BenchError::CorruptCache(data_path));
                }
                let floats: Vec<f32> =
                    bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
                let radiance = floats.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                eprintln!("{}: cached reference ({} spp)", base.display(), info.spp);
                let mut out = RenderOutput::from_radiance(info.width, info.height, radiance);
                out.spp = info.spp;
                out.seconds = stored.seconds;
                out.render_seconds = stored.seconds;
                return Ok((out, stored));
            }
        }
    }
    eprintln!("{}: rendering the reference ({} spp, filtering none)...", base.display(), info.spp);
    let out = bench.render(FilterMode::None, info.spp, info.seed, info.camera_offset)?;
    eprintln!("{}: reference took {:.1} s", base.display(), out.seconds);
    let stored = ReferenceInfo { seconds: out.seconds, ..info };
    let bytes: Vec<u8> = out.radiance.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let json = serde_json::to_string_pretty(&stored).expect("serialisable");
    write_all_or_nothing(&[data_path.clone(), json_path], |i, p| {
        if i == 0 {
            std::fs::write(p, &bytes)
        } else {
            std::fs::write(p, &json)
        }
    })
    .map_err(io_error(&data_path))?;
    Ok((out, stored))
}
