//! The CPU twin of the path tracer's sampler (`glsl/lib/sobol.glsl`):
//! Owen-scrambled Sobol points, one dimension pair per decision along a
//! path (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//! The same integer arithmetic as the shader, so the GPU must match it to
//! the bit (`tests/sampling/sampling_gpu.rs`).

/// PCG hash (Jarzynski & Olano 2020), as `pcgHash` in `glsl/lib/random.glsl`.
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// Laine and Karras' hash-based Owen scramble of bit-reversed `x`.
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50b47c);
    x ^= x.wrapping_mul(0xb82f1e52);
    x ^= x.wrapping_mul(0xc7afe638);
    x ^= x.wrapping_mul(0x8d22f6e6);
    x
}

/// A nested uniform (Owen) scramble in base 2 of a 32-bit fixed-point `x`.
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The second Sobol dimension of `index` (direction numbers
/// v_{k+1} = v_k ^ (v_k >> 1)); the first is `index.reverse_bits()`.
pub fn sobol_second(index: u32) -> u32 {
    let (mut result, mut v) = (0u32, 1u32 << 31);
    for k in 0..32 {
        if (index >> k) & 1 != 0 {
            result ^= v;
        }
        v ^= v >> 1;
    }
    result
}

/// The scrambling seed of a pixel (`pathSampler`).
pub fn pixel_seed(x: u32, y: u32, seed: u32) -> u32 {
    pcg_hash(x ^ pcg_hash(y ^ pcg_hash(seed ^ 0x68bc21eb)))
}

/// The 2D point of sample `index` of decision `dimension` for a pixel of
/// scrambling seed `seed` (`sample2`), 24-bit, in [0, 1)².
pub fn sample2(seed: u32, index: u32, dimension: u32) -> [f32; 2] {
    let s = pcg_hash(seed ^ pcg_hash(dimension));
    let i = owen_scramble(index, s);
    let x = owen_scramble(i.reverse_bits(), pcg_hash(s ^ 0x9e3779b9));
    let y = owen_scramble(sobol_second(i), pcg_hash(s ^ 0x85ebca6b));
    [(x >> 8) as f32 / 16777216.0, (y >> 8) as f32 / 16777216.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 2^m samples of every decision of a pixel form a (0, m, 2)-net:
    /// each of the 2^m elementary intervals of every shape 2^-a x 2^-(m-a)
    /// holds exactly one point (what makes the estimates stratified).
    #[test]
    fn every_decision_is_a_scrambled_0_2_sequence() {
        for m in [2u32, 4, 6, 8] {
            let n = 1u32 << m;
            for (pixel, dimension) in [(0u32, 0u32), (pixel_seed(3, 7, 1), 1), (pixel_seed(200, 11, 9), 13)] {
                let points: Vec<[f32; 2]> = (0..n).map(|i| sample2(pixel, i, dimension)).collect();
                for a in 0..=m {
                    let (cols, rows) = (1u32 << a, 1u32 << (m - a));
                    let mut hits = vec![0u32; n as usize];
                    for p in &points {
                        let (c, r) = ((p[0] * cols as f32) as u32, (p[1] * rows as f32) as u32);
                        hits[(r * cols + c) as usize] += 1;
                    }
                    assert!(hits.iter().all(|&h| h == 1), "m {m}, interval 2^-{a} x 2^-{}: {hits:?}", m - a);
                }
            }
        }
    }

    /// Decisions and pixels are scrambled independently: pairs of decisions'
    /// first coordinates are uncorrelated over many samples, and two pixels
    /// differ.
    #[test]
    fn decisions_and_pixels_are_decorrelated() {
        let n = 4096;
        let seed = pixel_seed(5, 5, 0);
        for (d1, d2) in [(0u32, 1u32), (1, 2), (2, 7)] {
            let (mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
            for i in 0..n {
                let (x, y) = (sample2(seed, i, d1)[0] as f64, sample2(seed, i, d2)[0] as f64);
                sx += x;
                sy += y;
                sxy += x * y;
                sxx += x * x;
                syy += y * y;
            }
            let nf = n as f64;
            let cov = sxy / nf - sx * sy / (nf * nf);
            let corr = cov / ((sxx / nf - (sx / nf).powi(2)) * (syy / nf - (sy / nf).powi(2))).sqrt();
            // Independent uniform pairs: |corr| ~ 1/sqrt(n) = 0.016.
            assert!(corr.abs() < 0.06, "decisions {d1} and {d2}: correlation {corr}");
        }
        assert_ne!(sample2(pixel_seed(0, 0, 0), 0, 0), sample2(pixel_seed(1, 0, 0), 0, 0));
    }

    #[test]
    fn sobol_second_dimension_starts_as_published() {
        // Joe and Kuo's dimension 2 in index order (not Gray-code order):
        // direction numbers 1/2, 3/4, 5/8.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(sobol_second(i as u32) as f64 / 4294967296.0, *e);
        }
    }
}
