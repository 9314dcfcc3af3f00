//! Power-of-two resampling and mip chains.

/// Resamples a `width` x `height` image (row-major RGBA, row 0 at the top) up
/// to the next power of two on each axis, returning the new size and texels.
///
/// Each axis is resampled separately by linear interpolation with wrap-around
/// (textures repeat): output texel i of m, whose centre lies at (i + ½)/m of
/// the image, takes the source value at x = (i + ½)·n/m − ½ texels, linearly
/// interpolated between the texels ⌊x⌋ and ⌊x⌋ + 1 taken modulo n. Together
/// this is bilinear filtering. A constant image stays constant, and an axis
/// that is already a power of two is returned unchanged.
///
/// # Panics
///
/// If `texels.len() != width * height` or a side is 0 or above 2³¹.
pub fn resample_to_power_of_two(width: u32, height: u32, texels: Vec<[f32; 4]>) -> (u32, u32, Vec<[f32; 4]>) {
    assert!(width > 0 && height > 0, "empty image {width} x {height}");
    assert_eq!(texels.len(), width as usize * height as usize, "texel count of a {width} x {height} image");
    let (w2, h2) = (width.next_power_of_two(), height.next_power_of_two());
    let mut texels = texels;
    if w2 != width {
        let (w, w2) = (width as usize, w2 as usize);
        let weights = axis_weights(w, w2);
        let mut out = Vec::with_capacity(w2 * height as usize);
        for row in texels.chunks_exact(w) {
            out.extend(weights.iter().map(|&(a, b, t)| lerp(row[a], row[b], t)));
        }
        texels = out;
    }
    if h2 != height {
        let (h, h2, w) = (height as usize, h2 as usize, w2 as usize);
        let weights = axis_weights(h, h2);
        let mut out = Vec::with_capacity(w * h2);
        for &(a, b, t) in &weights {
            let (ra, rb) = (&texels[a * w..(a + 1) * w], &texels[b * w..(b + 1) * w]);
            out.extend(ra.iter().zip(rb).map(|(&p, &q)| lerp(p, q, t)));
        }
        texels = out;
    }
    (w2, h2, texels)
}

/// For each of `m` output texels along an axis of `n` source texels: the two
/// source texels and the weight of the second.
fn axis_weights(n: usize, m: usize) -> Vec<(usize, usize, f32)> {
    (0..m)
        .map(|i| {
            let x = (i as f64 + 0.5) * n as f64 / m as f64 - 0.5;
            let x0 = x.floor();
            let t = (x - x0) as f32;
            let a = (x0 as i64).rem_euclid(n as i64) as usize;
            (a, (a + 1) % n, t)
        })
        .collect()
}

fn lerp(p: [f32; 4], q: [f32; 4], t: f32) -> [f32; 4] {
    std::array::from_fn(|k| p[k] + (q[k] - p[k]) * t)
}

/// The mip chain of a power-of-two `width` x `height` image: level 0 is
/// `level0` itself, and each next level halves each side (down to 1) by
/// averaging 2 x 2 blocks of texels (2 x 1 or 1 x 2 once one side is 1), in
/// linear space, down to 1 x 1. A 1 x 1 image has a single level.
///
/// # Panics
///
/// If a side is not a power of two or `level0.len() != width * height`.
pub fn build_mips(width: u32, height: u32, level0: Vec<[f32; 4]>) -> Vec<Vec<[f32; 4]>> {
    assert!(width.is_power_of_two() && height.is_power_of_two(), "{width} x {height} is not a power of two");
    assert_eq!(level0.len(), width as usize * height as usize, "texel count of a {width} x {height} image");
    let (mut w, mut h) = (width as usize, height as usize);
    let mut levels = vec![level0];
    while w > 1 || h > 1 {
        let prev = levels.last().expect("level 0 exists");
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let (dx, dy) = (w / nw, h / nh);
        let scale = 1.0 / (dx * dy) as f32;
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let mut sum = [0.0f32; 4];
                for j in 0..dy {
                    for i in 0..dx {
                        let p = prev[(y * dy + j) * w + x * dx + i];
                        for k in 0..4 {
                            sum[k] += p[k];
                        }
                    }
                }
                next.push(sum.map(|s| s * scale));
            }
        }
        levels.push(next);
        (w, h) = (nw, nh);
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f32) -> [f32; 4] {
        [v, v, v, 1.0]
    }

    #[test]
    fn weights_of_an_upsampled_axis() {
        // 3 -> 4: centres at 0.375, 1.125, 1.875, 2.625 source texels (minus ½).
        let w = axis_weights(3, 4);
        assert_eq!(w.len(), 4);
        assert_eq!((w[0].0, w[0].1), (2, 0)); // x = -0.125 wraps to between the last and the first
        assert!((w[0].2 - 0.875).abs() < 1e-6);
        assert_eq!((w[3].0, w[3].1), (2, 0));
        assert!((w[3].2 - 0.125).abs() < 1e-6);
        // Identity when n == m.
        for (i, &(a, _, t)) in axis_weights(8, 8).iter().enumerate() {
            assert_eq!((a, t), (i, 0.0));
        }
    }

    #[test]
    fn power_of_two_images_are_unchanged() {
        let texels: Vec<_> = (0..8).map(|i| grey(i as f32)).collect();
        assert_eq!(resample_to_power_of_two(4, 2, texels.clone()), (4, 2, texels));
    }

    #[test]
    fn mip_levels_of_a_wide_image() {
        let levels = build_mips(8, 2, (0..16).map(|i| grey(i as f32)).collect());
        let sizes: Vec<usize> = levels.iter().map(Vec::len).collect();
        assert_eq!(sizes, [16, 4, 2, 1]);
        // Level 1 averages 2 x 2 blocks: (0 + 1 + 8 + 9) / 4.
        assert_eq!(levels[1][0], grey(4.5));
        // Level 2 (2 x 1) averages pairs along x.
        assert_eq!(levels[2], [grey(5.5), grey(9.5)]);
        assert_eq!(levels[3], [grey(7.5)]);
    }
}
