//! Deterministic pseudo-random numbers from integers, for generated content
//! (scattered bumps, procedural textures) that must not depend on a random
//! number generator's state.

/// A number in [0, 1) from a seed, an index and a stream: the seed and the
/// index packed into 64 bits, mixed with the stream, then the SplitMix64
/// finaliser (Steele, Lea and Flood, "Fast Splittable Pseudorandom Number
/// Generators", OOPSLA 2014).
pub fn hash_unit(seed: u32, index: u64, stream: u64) -> f64 {
    let mut z = (u64::from(seed) << 32 ^ index)
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(stream.wrapping_mul(0xD1B5_4A32_D192_ED03));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}
