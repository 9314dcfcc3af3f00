//! Image error metrics for comparing a render with a reference: FLIP (via
//! the `nv-flip` crate: P. Andersson, J. Nilsson, T. Akenine-Möller et al.,
//! "FLIP: A Difference Evaluator for Alternating Images", HPG 2020) on the
//! tone-mapped 8-bit sRGB images, and the relative mean squared error on the
//! linear radiance.

use crate::jobs::output::tone_map;
use crate::passes::RenderOutput;

/// Pixels per degree of the FLIP observer: a 0.7 m viewing distance from a
/// 0.7 m wide monitor of 3840 pixels (FLIP's default).
pub const FLIP_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// The ε of [`relative_mse`], keeping dark pixels from dominating.
pub const RELATIVE_MSE_EPSILON: f64 = 1e-2;

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MetricError {
    /// The images differ in size.
    #[error("image sizes differ: {0}x{1} and {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// An image has no pixel.
    #[error("empty image")]
    Empty,
}

fn check_sizes(a: &RenderOutput, b: &RenderOutput) -> Result<(), MetricError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(MetricError::SizeMismatch(a.width, a.height, b.width, b.height));
    }
    if a.radiance.is_empty() {
        return Err(MetricError::Empty);
    }
    Ok(())
}

/// The FLIP error map of `test` against `reference`, both tone-mapped as the
/// PNG outputs are (radiance · 2^exposure, clamped, sRGB), one value in
/// [0, 1] per pixel.
pub fn flip_map(reference: &RenderOutput, test: &RenderOutput, exposure: f32) -> Result<Vec<f32>, MetricError> {
    check_sizes(reference, test)?;
    let r = nv_flip::FlipImageRgb8::with_data(reference.width, reference.height, &tone_map(reference, exposure));
    let t = nv_flip::FlipImageRgb8::with_data(test.width, test.height, &tone_map(test, exposure));
    Ok(nv_flip::flip(r, t, FLIP_PIXELS_PER_DEGREE).to_vec())
}

/// Mean FLIP error of `test` against `reference` (0: identical; see [`flip_map`]).
pub fn flip_mean(reference: &RenderOutput, test: &RenderOutput, exposure: f32) -> Result<f64, MetricError> {
    let map = flip_map(reference, test, exposure)?;
    Ok(map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len() as f64)
}

/// Relative mean squared error of the linear radiance: the mean over pixels
/// and channels of (test − ref)² / (ref² + ε), ε = [`RELATIVE_MSE_EPSILON`].
pub fn relative_mse(reference: &RenderOutput, test: &RenderOutput) -> Result<f64, MetricError> {
    check_sizes(reference, test)?;
    let sum: f64 = reference.radiance.iter().zip(&test.radiance).map(|(r, t)| relative_squared_error(r, t)).sum();
    Ok(sum / (3 * reference.radiance.len()) as f64)
}

/// One pixel's (test − ref)² / (ref² + ε), summed over its channels.
fn relative_squared_error(reference: &[f32; 3], test: &[f32; 3]) -> f64 {
    reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| (f64::from(r), f64::from(t)))
        .map(|(r, t)| (t - r) * (t - r) / (r * r + RELATIVE_MSE_EPSILON))
        .sum()
}

/// Relative MSE over the whole image and over its regions: the pixels that
/// see one object (or the background), by the reference's `object` AOV,
/// less those within `margin` pixels of another region (silhouettes). When
/// a handful of pixels dominate the error (outlier samples at silhouettes,
/// say) the whole image's error is far above the mean of the regions'; with
/// error spread evenly the two are close.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionErrors {
    /// Relative MSE of the whole image.
    pub whole: f64,
    /// Per region: the object index (`NO_HIT` for the background), its
    /// pixel count and its relative MSE.
    pub regions: Vec<(u32, usize, f64)>,
}

impl RegionErrors {
    /// The mean of the regions' relative MSEs (each region counted once).
    pub fn mean_of_regions(&self) -> f64 {
        self.regions.iter().map(|r| r.2).sum::<f64>() / self.regions.len().max(1) as f64
    }

    /// The whole image's error over the mean of the regions'.
    pub fn ratio(&self) -> f64 {
        self.whole / self.mean_of_regions()
    }
}

/// [`RegionErrors`] of `test` against `reference`, whose AOVs define the
/// regions; regions of fewer than `min_pixels` pixels are left out of the
/// mean (their error is noise).
pub fn region_relative_mse(
    reference: &RenderOutput,
    test: &RenderOutput,
    margin: u32,
    min_pixels: usize,
) -> Result<RegionErrors, MetricError> {
    check_sizes(reference, test)?;
    if reference.aov.len() != reference.radiance.len() {
        return Err(MetricError::Empty);
    }
    let (w, h) = (reference.width as i64, reference.height as i64);
    let m = margin as i64;
    let mut sums: std::collections::BTreeMap<u32, (usize, f64)> = Default::default();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let object = reference.aov[i].object;
            let interior = (-m..=m).all(|dy| {
                (-m..=m).all(|dx| {
                    let (xx, yy) = (x + dx, y + dy);
                    xx >= 0 && yy >= 0 && xx < w && yy < h && reference.aov[(yy * w + xx) as usize].object == object
                })
            });
            if interior {
                let e = sums.entry(object).or_default();
                e.0 += 1;
                e.1 += relative_squared_error(&reference.radiance[i], &test.radiance[i]) / 3.0;
            }
        }
    }
    let regions = sums
        .into_iter()
        .filter(|(_, (n, _))| *n >= min_pixels.max(1))
        .map(|(o, (n, e))| (o, n, e / n as f64))
        .collect();
    Ok(RegionErrors { whole: relative_mse(reference, test)?, regions })
}

/// Mean absolute difference of the tone-mapped images (values in [0, 1]
/// per channel): the frame-to-frame change of an animation as a viewer sees it.
pub fn mean_display_change(a: &RenderOutput, b: &RenderOutput, exposure: f32) -> Result<f64, MetricError> {
    check_sizes(a, b)?;
    let (ta, tb) = (tone_map(a, exposure), tone_map(b, exposure));
    let sum: u64 = ta.iter().zip(&tb).map(|(&x, &y)| u64::from(x.abs_diff(y))).sum();
    Ok(sum as f64 / (255.0 * ta.len() as f64))
}

/// Temporal error of an animation pair: the mean over pixels and channels
/// of |(b − a) − (b_ref − a_ref)| on the tone-mapped images (values in
/// [0, 1]): the frame-to-frame change that the reference's change (the
/// motion itself) does not explain, i.e. flicker (noise, aliasing) and lost
/// motion (blur).
pub fn change_error(
    a: &RenderOutput,
    b: &RenderOutput,
    a_ref: &RenderOutput,
    b_ref: &RenderOutput,
    exposure: f32,
) -> Result<f64, MetricError> {
    check_sizes(a, b)?;
    check_sizes(a, a_ref)?;
    check_sizes(a, b_ref)?;
    let [ta, tb, ra, rb] = [a, b, a_ref, b_ref].map(|o| tone_map(o, exposure));
    let sum: f64 = (0..ta.len())
        .map(|i| {
            let change = f64::from(tb[i]) - f64::from(ta[i]);
            let reference = f64::from(rb[i]) - f64::from(ra[i]);
            (change - reference).abs()
        })
        .sum();
    Ok(sum / (255.0 * ta.len() as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> RenderOutput {
        let radiance = (0..width * height).map(|i| f(i % width, i / width)).collect();
        RenderOutput::from_radiance(width, height, radiance)
    }

    #[test]
    fn identical_images_have_no_error() {
        let a = image(32, 24, |x, y| [x as f32 / 32.0, y as f32 / 24.0, 0.5]);
        assert_eq!(flip_mean(&a, &a, 0.0).unwrap(), 0.0);
        assert_eq!(relative_mse(&a, &a).unwrap(), 0.0);
        assert_eq!(mean_display_change(&a, &a, 0.0).unwrap(), 0.0);
    }

    #[test]
    fn errors_grow_with_the_difference() {
        let a = image(64, 64, |_, _| [0.5; 3]);
        let noisy = |amp: f32| {
            image(64, 64, |x, y| {
                let s = if (x * 7 + y * 13) % 2 == 0 { amp } else { -amp };
                [0.5 + s; 3]
            })
        };
        let (small, large) = (noisy(0.05), noisy(0.2));
        assert!(flip_mean(&a, &small, 0.0).unwrap() > 0.0);
        assert!(flip_mean(&a, &large, 0.0).unwrap() > flip_mean(&a, &small, 0.0).unwrap());
        // (0.05)² / (0.25 + 0.01) per channel.
        assert!((relative_mse(&a, &small).unwrap() - 0.0025 / 0.26).abs() < 1e-6);
        assert!(relative_mse(&a, &large).unwrap() > relative_mse(&a, &small).unwrap());
    }

    #[test]
    fn display_change_of_a_shift_is_the_contrast_fraction() {
        // Black and white halves; shifting the edge by 4 of 64 columns changes
        // 4/64 of the pixels by the full range.
        let a = image(64, 8, |x, _| if x < 32 { [0.0; 3] } else { [1.0; 3] });
        let b = image(64, 8, |x, _| if x < 36 { [0.0; 3] } else { [1.0; 3] });
        assert!((mean_display_change(&a, &b, 0.0).unwrap() - 4.0 / 64.0).abs() < 1e-12);
    }

    #[test]
    fn change_error_ignores_the_motion_the_reference_shows() {
        let a = image(64, 8, |x, _| if x < 32 { [0.0; 3] } else { [1.0; 3] });
        let b = image(64, 8, |x, _| if x < 36 { [0.0; 3] } else { [1.0; 3] });
        assert_eq!(change_error(&a, &b, &a, &b, 0.0).unwrap(), 0.0);
        // A render that does not move at all misses the whole change.
        assert!((change_error(&a, &a, &a, &b, 0.0).unwrap() - 4.0 / 64.0).abs() < 1e-12);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let a = image(4, 4, |_, _| [0.0; 3]);
        let b = image(4, 5, |_, _| [0.0; 3]);
        assert_eq!(flip_mean(&a, &b, 0.0), Err(MetricError::SizeMismatch(4, 4, 4, 5)));
    }
}
