//! Procedural textures, generated at load time so that scenes need no image
//! files. Every generator is deterministic and returns a full mip chain.

use super::{from_texels, TextureImage, MAX_TEXTURE_SIZE};

fn check_size(size: u32) {
    assert!(
        size.is_power_of_two() && size <= MAX_TEXTURE_SIZE,
        "texture size {size} is not a power of two from 1 to {MAX_TEXTURE_SIZE}"
    );
}

/// A `size` x `size` checkerboard of `cells` x `cells` squares in the linear
/// colours `a` and `b`; the top-left cell is `a`. Texel (x, y) lies in cell
/// (⌊x·cells/size⌋, ⌊y·cells/size⌋), so the cells are equal when `cells`
/// divides `size`.
///
/// # Panics
///
/// If `size` is not a power of two from 1 to [`MAX_TEXTURE_SIZE`], or `cells`
/// is 0.
pub fn checker(size: u32, cells: u32, a: [f32; 3], b: [f32; 3]) -> TextureImage {
    check_size(size);
    assert!(cells > 0, "a checkerboard needs at least one cell");
    let n = size as u64;
    let cell = |i: u64| i * u64::from(cells) / n;
    let [a, b] = [a, b].map(|c| [c[0], c[1], c[2], 1.0]);
    let texels = (0..n * n).map(|k| if (cell(k % n) + cell(k / n)) % 2 == 0 { a } else { b }).collect();
    from_texels(format!("checker(size = {size}, cells = {cells}, colors = [{a:?}, {b:?}])"), size, size, texels)
}

/// A `size` x `size` height field of `bumps` random smooth bumps on a
/// periodic domain (the texture tiles seamlessly), in all of R, G and B (alpha
/// 1), scaled so that the highest texel is 1; values are in [0, 1].
///
/// Each bump is a raised cosine h·(1 + cos(π d/r))/2 for d < r (zero beyond,
/// with a continuous slope), where d is the periodic distance from its centre.
/// The centres are uniform over the unit square, the radii r uniform in
/// [0.6, 1.4]·r₀ with r₀ = 1/(2√bumps) (so together the bumps cover about
/// 80 % of the area), the amplitudes h uniform in [0.5, 1]. The same
/// arguments always give the same texture.
///
/// # Panics
///
/// If `size` is not a power of two from 1 to [`MAX_TEXTURE_SIZE`].
pub fn bump_heights(size: u32, bumps: u32, seed: u32) -> TextureImage {
    check_size(size);
    let n = size as usize;
    let mut heights = vec![0.0f64; n * n];
    let r0 = 0.5 / f64::from(bumps.max(1)).sqrt();
    for i in 0..bumps {
        let cx = hash_unit(seed, i, 0);
        let cy = hash_unit(seed, i, 1);
        let r = r0 * (0.6 + 0.8 * hash_unit(seed, i, 2));
        let amplitude = 0.5 + 0.5 * hash_unit(seed, i, 3);
        // Texel centres at ((x + ½)/size, (y + ½)/size) within r of the centre,
        // each periodic image of the bump counted.
        let s = n as f64;
        let range = |c: f64| (((c - r) * s - 0.5).ceil() as i64)..=(((c + r) * s - 0.5).floor() as i64);
        for y in range(cy) {
            let dy = (y as f64 + 0.5) / s - cy;
            for x in range(cx) {
                let dx = (x as f64 + 0.5) / s - cx;
                let d = (dx * dx + dy * dy).sqrt();
                if d < r {
                    let k = y.rem_euclid(n as i64) as usize * n + x.rem_euclid(n as i64) as usize;
                    heights[k] += amplitude * 0.5 * (1.0 + (std::f64::consts::PI * d / r).cos());
                }
            }
        }
    }
    let max = heights.iter().copied().fold(0.0, f64::max);
    let scale = if max > 0.0 { 1.0 / max } else { 0.0 };
    let texels = heights
        .iter()
        .map(|&h| {
            let h = (h * scale) as f32;
            [h, h, h, 1.0]
        })
        .collect();
    from_texels(format!("bumps(size = {size}, count = {bumps}, seed = {seed})"), size, size, texels)
}

/// A tangent-space normal map from the height field in the R channel of
/// `heights`' level 0: RGB = (n + 1)/2 (alpha 1) with
/// n = normalize(−strength·∂h/∂u, −strength·∂h/∂v, 1), where the derivatives
/// are periodic central differences in texels, ∂h/∂u at (x, y) being
/// (h(x+1, y) − h(x−1, y))/2 and ∂h/∂v likewise along the rows (v grows down
/// the image). A flat field gives (0.5, 0.5, 1).
pub fn normals_from_heights(heights: &TextureImage, strength: f32) -> TextureImage {
    let (w, h) = (heights.width as usize, heights.height as usize);
    let level = &heights.levels[0];
    let at = |x: usize, y: usize| f64::from(level[y * w + x][0]);
    let s = f64::from(strength);
    let texels = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let du = (at((x + 1) % w, y) - at((x + w - 1) % w, y)) / 2.0;
            let dv = (at(x, (y + 1) % h) - at(x, (y + h - 1) % h)) / 2.0;
            let (nx, ny, nz) = (-s * du, -s * dv, 1.0);
            let len = (nx * nx + ny * ny + nz * nz).sqrt();
            let e = |c: f64| ((c / len + 1.0) / 2.0) as f32;
            [e(nx), e(ny), e(nz), 1.0]
        })
        .collect();
    from_texels(format!("normals({}, strength = {strength})", heights.source), heights.width, heights.height, texels)
}

/// A deterministic number in [0, 1) from a seed, an index and a stream: a
/// A number in [0, 1) from (seed, index, stream); see [`crate::util::hash::hash_unit`].
fn hash_unit(seed: u32, index: u32, stream: u32) -> f64 {
    crate::util::hash::hash_unit(seed, u64::from(index), u64::from(stream) + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_layout() {
        let t = checker(8, 2, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!((t.width, t.height, t.levels.len()), (8, 8, 4));
        let at = |x: usize, y: usize| t.levels[0][y * 8 + x];
        assert_eq!(at(0, 0), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(3, 3), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(4, 0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(0, 4), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(7, 7), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(t.levels[3], [[0.5, 0.0, 0.5, 1.0]]);
    }

    #[test]
    fn bumps_are_deterministic_periodic_and_in_range() {
        let a = bump_heights(64, 20, 3);
        assert_eq!(a, bump_heights(64, 20, 3));
        assert_ne!(a.levels[0], bump_heights(64, 20, 4).levels[0]);
        let l = &a.levels[0];
        assert!(l.iter().all(|t| (0.0..=1.0).contains(&t[0]) && t[0] == t[1] && t[1] == t[2] && t[3] == 1.0));
        assert_eq!(l.iter().map(|t| t[0]).fold(0.0, f32::max), 1.0);
        assert!(l.iter().filter(|t| t[0] > 0.0).count() > 64 * 64 / 2, "the bumps cover most of the square");
        // Smooth across the wrap-around: neighbouring texels differ about as
        // much across the seam as anywhere else.
        let step = |x0: usize, x1: usize| (0..64).map(|y| (l[y * 64 + x0][0] - l[y * 64 + x1][0]).abs()).sum::<f32>();
        let interior = (1..64).map(|x| step(x - 1, x)).fold(0.0, f32::max);
        assert!(step(63, 0) <= interior * 1.5 + 1e-6, "seam {} vs {interior}", step(63, 0));
    }

    #[test]
    fn one_bump_of_a_single_texel_texture() {
        let t = bump_heights(1, 1, 0);
        assert_eq!(t.levels.len(), 1);
        assert!((0.0..=1.0).contains(&t.levels[0][0][0]));
    }

    #[test]
    fn normals_of_a_ramp() {
        // h = x/8 along a row is not periodic, but the interior texels see a
        // constant slope of 1/8 per texel.
        let texels = (0..64).map(|k| [(k % 8) as f32 / 8.0, 0.0, 0.0, 1.0]).collect();
        let h = from_texels("ramp".into(), 8, 8, texels);
        let n = normals_from_heights(&h, 4.0);
        let t = n.levels[0][3 * 8 + 3];
        let expect = glam::DVec3::new(-0.5, 0.0, 1.0).normalize();
        for k in 0..3 {
            assert!((f64::from(t[k]) - (expect[k] + 1.0) / 2.0).abs() < 1e-6, "{t:?}");
        }
        // Flat field: straight up.
        let flat = normals_from_heights(&from_texels("flat".into(), 2, 2, vec![[0.3, 0.0, 0.0, 1.0]; 4]), 10.0);
        assert_eq!(flat.levels[0], vec![[0.5, 0.5, 1.0, 1.0]; 4]);
    }
}
