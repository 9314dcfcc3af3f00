//! Samples that gain energy: the bound a single sample's radiance cannot
//! exceed in a scene, the pixels whose largest sample (the render's
//! `max_sample` AOV) exceeds it, and a readable account of the path that
//! brought such a sample (recorded by [`super::Renderer::trace_path`]).
//!
//! # The bound
//!
//! A sample is the sum, over the vertices of its path, of the throughput
//! times what the vertex gathers: the emission of an emitter the path finds
//! (weighted by multiple importance sampling, w ≤ 1) and next-event
//! estimation. With the power heuristic, light sampling's contribution is
//! `f cos L w_l / p_l = (f cos / p_b) · L · p_l p_b / (p_l² + p_b²)`, at most
//! `a L / 2` where `a = f cos / p_b` is the BSDF's weight in that direction,
//! at most 1 (the albedo for Lambert; tests/sampling/sampling_gpu.rs checks it at
//! every angle), and `L` the largest emitted radiance. Every vertex, the last included, uses
//! multiple importance sampling (render.glsl: the last vertex still samples
//! its BSDF and looks for an emitter in that direction), so each vertex adds
//! at most `1.5 L` times a throughput of at most 1 (smooth interfaces scale
//! radiance by η², and the product of those factors is 1 for a path from a
//! camera in vacuum to an emitter in vacuum; Russian roulette divides by the
//! survival probability only up to a throughput of 1). With the emitter a
//! camera ray may see directly, a sample of a path of at most `D` bounces is
//! at most `L (1 + 1.5 D)`.
//!
//! In a scene with participating media, each segment of the path may also
//! add an equiangular estimate of its single scattering toward a light, at
//! most `L / 2` by the same argument (its competing strategy is distance
//! sampling and the phase function, whose weight is the medium's albedo ≤ 1),
//! and a scattering event in a medium is a bounce like a surface vertex. A
//! path has at most `4 D + 8` segments (index-matched interfaces split a
//! bounce's segment), so the bound grows by `L (2 D + 4)` there. The
//! scattering events in a medium sample their directions from a mixture of
//! the phase function and a light's halo, whose weight phase / mixture can
//! exceed 1; their share of the halo
//! ([`crate::model::sampling::phase::halo_share`]) keeps the throughput at most 2,
//! so the bound of a scene with media is multiplied by 2.
//!
//! The bound needs area emitters: point and directional lights have no
//! radiance, and a sharp glossy lobe can legitimately turn one into an
//! arbitrarily bright single sample. The caustic and volume passes add a
//! per-pixel estimate that is not a single sample, so the bound speaks of the
//! path tracer's samples: check it on brute-force renders.

use std::fmt::Write as _;

use super::{RecordedPath, RenderOutput};
use crate::gpu::shader_interface::{
    EVENT_EMITTER, EVENT_END, EVENT_LIGHT_SAMPLE, EVENT_MEDIUM, EVENT_PASS_THROUGH, EVENT_ROULETTE, EVENT_SHADOW,
    EVENT_SURFACE, LOBE_INVALID, LOBE_REFLECT, LOBE_TRANSMIT, NO_HIT, NO_TEXTURE,
};
use crate::model::scene::{Light, Scene};

/// Rec. 709 luminance of linear RGB (the weights pixel.glsl uses).
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Why a scene's samples have no bound.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("no bound on a single sample: {0}")]
pub struct Unbounded(pub String);

/// The largest luminance a single sample of `scene` may have (see the
/// module's documentation), with the largest emitted luminance it is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleBound {
    /// The bound on one sample's luminance.
    pub luminance: f32,
    /// The largest luminance any emitter emits.
    pub emitted: f32,
    /// Path length in bounces.
    pub max_depth: u32,
    /// True when the scene has participating media (the bound then counts
    /// an equiangular estimate per segment).
    pub media: bool,
}

impl SampleBound {
    /// The bound of `scene`'s samples at its `max_depth`.
    pub fn of(scene: &Scene) -> Result<Self, Unbounded> {
        let mut emitted = luminance(scene.background.to_array());
        for (i, light) in scene.lights.iter().enumerate() {
            match light {
                Light::Sphere { radiance, .. } | Light::Rect { radiance, .. } => {
                    emitted = emitted.max(luminance(radiance.to_array()))
                }
                Light::Point { .. } | Light::Directional { .. } => {
                    return Err(Unbounded(format!(
                        "lights[{i}] is a point or directional light (no radiance to bound a sample by)"
                    )))
                }
            }
        }
        for m in &scene.materials {
            emitted = emitted.max(luminance(m.emission.to_array()));
        }
        if let Some(env) = &scene.environment {
            let texels = &scene.textures[env.texture].levels[0];
            let brightest = texels.iter().map(|t| luminance([t[0], t[1], t[2]])).fold(0.0, f32::max);
            emitted = emitted.max(brightest * env.scale);
        }
        let max_depth = scene.image.max_depth.max(1);
        let media = scene.has_media();
        let d = max_depth as f32;
        let per_segment = if media { 0.5 * (4.0 * d + 8.0) } else { 0.0 };
        // The throughput's largest value with the halo mixture in media.
        let halo = if media { 2.0 } else { 1.0 };
        Ok(Self { luminance: emitted * (1.0 + 1.5 * d + per_segment) * halo, emitted, max_depth, media })
    }
}

/// A pixel whose largest single sample exceeds a bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outlier {
    /// Column.
    pub x: u32,
    /// Row (0 at the top).
    pub y: u32,
    /// The largest sample's luminance.
    pub luminance: f32,
    /// The index of the sample that brought it.
    pub sample: u32,
}

/// The pixels of `out` whose largest sample exceeds `bound`, the largest
/// first.
pub fn outliers(out: &RenderOutput, bound: f32) -> Vec<Outlier> {
    let mut found: Vec<Outlier> = out
        .max_sample
        .iter()
        .enumerate()
        .filter(|(_, m)| m[0] > bound)
        .map(|(i, m)| Outlier {
            x: (i % out.width as usize) as u32,
            y: (i / out.width as usize) as u32,
            luminance: m[0],
            sample: m[1] as u32,
        })
        .collect();
    found.sort_by(|a, b| b.luminance.total_cmp(&a.luminance));
    found
}

/// The largest single sample of the whole image.
pub fn largest_sample(out: &RenderOutput) -> Option<Outlier> {
    outliers(out, f32::NEG_INFINITY).into_iter().next()
}

fn name_of(names: &[String], i: u32) -> String {
    names.get(i as usize).cloned().unwrap_or_else(|| format!("#{i}"))
}

fn rgb(c: [f32; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

/// A readable account of a recorded path, one line per event: the object
/// and material, the event, the cosines, pdfs and weights, the throughput
/// and the radiance so far.
pub fn describe_path(scene: &Scene, path: &RecordedPath) -> String {
    let objects: Vec<String> = scene.objects.iter().map(|o| o.name.clone()).collect();
    let materials: Vec<String> = scene.materials.iter().map(|m| m.name.clone()).collect();
    let light = |i: u32| if i == NO_HIT { "environment".to_string() } else { format!("lights[{i}]") };
    let mut s = String::new();
    let end = path.events.len().saturating_sub(1);
    for (k, v) in path.events.iter().enumerate() {
        if k == end && path.left_out > 0 {
            let _ = writeln!(s, "      … {} events left out (the record holds {})", path.left_out, path.events.len());
        }
        let p = rgb(v.position);
        let line = match v.event {
            EVENT_SURFACE => format!(
                "surface  {} ({}): {} at t {:.6} {p}; cos wo {:+.6}, cos wi {:+.6}, pdf {:.5}, weight {}, throughput {}",
                name_of(&objects, v.object),
                if v.material == NO_TEXTURE { "-".into() } else { name_of(&materials, v.material) },
                match v.lobe {
                    LOBE_REFLECT => "reflect",
                    LOBE_TRANSMIT => "transmit",
                    LOBE_INVALID => "no valid sample (path ends)",
                    _ => "?",
                },
                v.t,
                v.cos_o,
                v.cos_i,
                v.pdf,
                rgb(v.weight),
                rgb(v.throughput)
            ),
            EVENT_EMITTER if v.material != NO_TEXTURE => format!(
                "emissive surface {} ({}): brings {}, throughput {}",
                name_of(&objects, v.object),
                name_of(&materials, v.material),
                rgb(v.weight),
                rgb(v.throughput)
            ),
            EVENT_EMITTER => format!(
                "emitter  {}: MIS weight {:.5}, brings {}, throughput {}",
                light(v.object),
                v.pdf,
                rgb(v.weight),
                rgb(v.throughput)
            ),
            EVENT_LIGHT_SAMPLE => format!(
                "light sample toward {} from {p}, distance {:.5}: would bring {}",
                light(v.object),
                v.t,
                rgb(v.weight)
            ),
            EVENT_SHADOW => format!(
                "shadow ray to {}: {}",
                light(v.object),
                if v.lobe == 1 { format!("unblocked, adds {}", rgb(v.weight)) } else { "blocked".into() }
            ),
            EVENT_MEDIUM => format!(
                "medium scattering at t {:.5} {p}: cos {:+.5}, phase pdf {:.5}, albedo {}, throughput {}",
                v.t,
                v.cos_i,
                v.pdf,
                rgb(v.weight),
                rgb(v.throughput)
            ),
            EVENT_PASS_THROUGH => format!(
                "index-matched interface of {} ({}) crossed at t {:.6}",
                name_of(&objects, v.object),
                if v.lobe == LOBE_TRANSMIT { "entering" } else { "leaving" },
                v.t
            ),
            EVENT_ROULETTE => {
                format!("Russian roulette survived (q {:.4}), throughput {}", v.pdf, rgb(v.throughput))
            }
            EVENT_END => format!("end{}", if v.lobe == 1 { " (not finite: dropped)" } else { "" }),
            e => format!("event {e}"),
        };
        if v.event == EVENT_LIGHT_SAMPLE || v.event == EVENT_ROULETTE {
            let _ = writeln!(s, "  {k:2}. {line}");
        } else {
            let _ = writeln!(s, "  {k:2}. {line}; radiance {}", rgb(v.radiance));
        }
    }
    s
}
