//! Leaf value types of the scene format that check themselves while they are
//! deserialized (finite, positive, triples, coefficients, powers of two,
//! colours, maps), so that a bad value is reported at its own token.

use std::fmt;
use std::marker::PhantomData;

use glam::{DVec2, DVec3};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;

use crate::model::geometry::Quadric;
use crate::model::texture::MAX_TEXTURE_SIZE;

use super::*;

pub(super) struct NumberVisitor<T>(pub(super) PhantomData<T>);

impl<'de, T: Number> Visitor<'de> for NumberVisitor<T> {
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<T, E> {
        T::parse(v).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<T, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<T, E> {
        self.visit_f64(v as f64)
    }
}

/// Largest accepted colour component (they become f32 on the GPU).
pub(super) const MAX_COLOUR: f64 = 1e30;

macro_rules! number_type {
    ($(#[$meta:meta])* $name:ident, |$v:ident| $check:expr) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, serde::Serialize)]
        pub(super) struct $name(f64);

        impl Number for $name {
            fn check($v: f64) -> Result<(), String> {
                $check
            }
            fn new(v: f64) -> Self {
                Self(v)
            }
            fn get(self) -> f64 {
                self.0
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                d.deserialize_any(NumberVisitor::<$name>(PhantomData))
            }
        }
    };
}

pub(super) fn require(ok: bool, message: impl FnOnce() -> String) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(message())
    }
}

number_type!(
    /// Any finite number.
    Finite,
    |_v| Ok(())
);
number_type!(
    /// A finite number > 0.
    Positive,
    |v| require(v > 0.0, || format!("must be positive (got {v})"))
);
number_type!(
    /// A finite number != 0.
    NonZero,
    |v| require(v != 0.0, || "must not be zero".to_owned())
);
number_type!(
    /// A colour component: >= 0 and small enough for f32.
    NonNegative,
    |v| {
        require(v >= 0.0, || format!("must not be negative (got {v})"))?;
        require(v <= MAX_COLOUR, || format!("must be at most {MAX_COLOUR:e} (got {v})"))
    }
);
number_type!(
    /// An index of refraction (or its real part): > 0 and small enough for f32.
    Ior,
    |v| {
        require(v > 0.0, || format!("must be positive (got {v})"))?;
        require(v <= MAX_COLOUR, || format!("must be at most {MAX_COLOUR:e} (got {v})"))
    }
);
number_type!(
    /// A Henyey–Greenstein asymmetry, in [−0.99, 0.99].
    Anisotropy,
    |v| require((-0.99..=0.99).contains(&v), || format!("must be between -0.99 and 0.99 (got {v})"))
);
number_type!(
    /// A number in [0, 1].
    UnitInterval,
    |v| require((0.0..=1.0).contains(&v), || format!("must be between 0 and 1 (got {v})"))
);
number_type!(
    /// A vertical field of view in degrees, in (0, 180).
    Fov,
    |v| require(v > 0.0 && v < 180.0, || format!("must be between 0 and 180 degrees, exclusive (got {v})"))
);
number_type!(
    /// A cone's half-angle in degrees, in (0, 90).
    HalfAngle,
    |v| require(v > 0.0 && v < 90.0, || format!("must be between 0 and 90 degrees, exclusive (got {v})"))
);
number_type!(
    /// Exposure in stops.
    Exposure,
    |v| require(v.abs() <= 100.0, || format!("must be between -100 and 100 stops (got {v})"))
);

/// An integer in `LO..=HI`.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct Int<const LO: i64, const HI: i64>(pub(super) i64);

pub(super) type Dimension = Int<1, MAX_IMAGE_SIZE>;
pub(super) type Samples = Int<1, MAX_SPP>;
pub(super) type Seed = Int<0, { u32::MAX as i64 }>;
pub(super) type Depth = Int<1, MAX_DEPTH>;
pub(super) type CausticRays = Int<0, MAX_CAUSTIC_RAYS>;
pub(super) type LightSamples = Int<1, MAX_CAUSTIC_LIGHT_SAMPLES>;
pub(super) type VolumeSamples = Int<0, MAX_VOLUME_SAMPLES>;
pub(super) type Count = Int<1, MAX_SCATTER_COUNT>;
pub(super) type Sheets = Int<1, 2>;

pub(super) struct IntVisitor<const LO: i64, const HI: i64>;

impl<'de, const LO: i64, const HI: i64> Visitor<'de> for IntVisitor<LO, HI> {
    type Value = Int<LO, HI>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an integer from {LO} to {HI}")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        if (LO..=HI).contains(&v) {
            Ok(Int(v))
        } else {
            Err(E::custom(format!("must be an integer from {LO} to {HI} (got {v})")))
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.visit_i64(i64::try_from(v).unwrap_or(i64::MAX))
    }
}

impl<'de, const LO: i64, const HI: i64> Deserialize<'de> for Int<LO, HI> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(IntVisitor::<LO, HI>)
    }
}

impl<const LO: i64, const HI: i64> Int<LO, HI> {
    pub(super) fn get(self) -> i64 {
        self.0
    }
}

/// Reads exactly `N` numbers of type `T` from an array.
pub(super) fn read_numbers<'de, T, A, const N: usize>(mut seq: A) -> Result<[f64; N], A::Error>
where
    T: Number + Deserialize<'de>,
    A: SeqAccess<'de>,
{
    let mut out = [0.0; N];
    let mut n = 0;
    while let Some(x) = seq.next_element::<T>()? {
        if n < N {
            out[n] = x.get();
        }
        n += 1;
    }
    if n != N {
        return Err(de::Error::custom(format!("must be an array of {N} numbers (got {n})")));
    }
    Ok(out)
}

/// An array of three numbers, each checked as a `T`.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct Triple<T>(pub(super) DVec3, pub(super) PhantomData<T>);

impl<T> Triple<T> {
    pub(super) fn get(self) -> DVec3 {
        self.0
    }
}

pub(super) struct TripleVisitor<T>(pub(super) PhantomData<T>);

impl<'de, T: Number + Deserialize<'de>> Visitor<'de> for TripleVisitor<T> {
    type Value = Triple<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 3 numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        read_numbers::<T, A, 3>(seq).map(|v| Triple(DVec3::from_array(v), PhantomData))
    }
}

impl<'de, T: Number + Deserialize<'de>> Deserialize<'de> for Triple<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor::<T>(PhantomData))
    }
}

/// A positive number (the same on every axis) or an array of three.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct PositiveVec(pub(super) DVec3);

pub(super) struct PositiveVecVisitor;

impl<'de> Visitor<'de> for PositiveVecVisitor {
    type Value = PositiveVec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a positive number or an array of 3 positive numbers")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PositiveVec, E> {
        Positive::parse(v).map(|p| PositiveVec(DVec3::splat(p.get()))).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PositiveVec, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PositiveVec, E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<PositiveVec, A::Error> {
        read_numbers::<Positive, A, 3>(seq).map(|v| PositiveVec(DVec3::from_array(v)))
    }
}

impl<'de> Deserialize<'de> for PositiveVec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PositiveVecVisitor)
    }
}

/// The ten coefficients of a non-degenerate quadric, in the order of
/// [`Quadric::from_coefficients`].
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct Coefficients(pub(super) Quadric);

pub(super) struct CoefficientsVisitor;

impl<'de> Visitor<'de> for CoefficientsVisitor {
    type Value = Coefficients;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 10 numbers [xx, yy, zz, xy, yz, xz, x, y, z, k]")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Coefficients, A::Error> {
        let k = read_numbers::<Finite, A, 10>(seq)?;
        let q = Quadric::from_coefficients(k);
        if q.is_degenerate() {
            return Err(de::Error::custom(
                "the quadric is degenerate: its quadratic and linear coefficients (the first 9) are all zero, \
                 so it has no surface",
            ));
        }
        Ok(Coefficients(q))
    }
}

impl<'de> Deserialize<'de> for Coefficients {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(CoefficientsVisitor)
    }
}

/// A power of two in `LO..=HI`: the side of a generated texture.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct PowerOfTwo<const LO: u32, const HI: u32>(pub(super) u32);

/// The side of a generated material map.
pub(super) type TextureSize = PowerOfTwo<1, MAX_TEXTURE_SIZE>;
/// The width of the generated sky.
pub(super) type SkyWidth = PowerOfTwo<2, MAX_SKY_WIDTH>;
/// The height of the generated sky.
pub(super) type SkyHeight = PowerOfTwo<1, { MAX_SKY_WIDTH / 2 }>;

pub(super) struct PowerOfTwoVisitor<const LO: u32, const HI: u32>;

impl<'de, const LO: u32, const HI: u32> Visitor<'de> for PowerOfTwoVisitor<LO, HI> {
    type Value = PowerOfTwo<LO, HI>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a power of two from {LO} to {HI}")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        match u32::try_from(v) {
            Ok(n) if n.is_power_of_two() && (LO..=HI).contains(&n) => Ok(PowerOfTwo(n)),
            _ => {
                Err(E::custom(format!("must be a power of two from {LO} to {HI}, such as 256, 512 or 1024 (got {v})")))
            }
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.visit_i64(i64::try_from(v).unwrap_or(i64::MAX))
    }
}

impl<'de, const LO: u32, const HI: u32> Deserialize<'de> for PowerOfTwo<LO, HI> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PowerOfTwoVisitor::<LO, HI>)
    }
}

/// An array of two numbers, each checked as a `T`.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct Pair<T>(pub(super) DVec2, pub(super) PhantomData<T>);

pub(super) struct PairVisitor<T>(pub(super) PhantomData<T>);

impl<'de, T: Number + Deserialize<'de>> Visitor<'de> for PairVisitor<T> {
    type Value = Pair<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 2 numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        read_numbers::<T, A, 2>(seq).map(|v| Pair(DVec2::from_array(v), PhantomData))
    }
}

impl<'de, T: Number + Deserialize<'de>> Deserialize<'de> for Pair<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PairVisitor::<T>(PhantomData))
    }
}

/// A colour with components in [0, 1], or one number in [0, 1] for a grey.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct UnitColour(pub(super) DVec3);

pub(super) struct UnitColourVisitor;

impl<'de> Visitor<'de> for UnitColourVisitor {
    type Value = UnitColour;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number in [0, 1] or an array of 3 numbers in [0, 1]")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<UnitColour, E> {
        UnitInterval::parse(v).map(|p| UnitColour(DVec3::splat(p.get()))).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<UnitColour, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<UnitColour, E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<UnitColour, A::Error> {
        read_numbers::<UnitInterval, A, 3>(seq).map(|v| UnitColour(DVec3::from_array(v)))
    }
}

impl<'de> Deserialize<'de> for UnitColour {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UnitColourVisitor)
    }
}

/// Exactly two [`UnitColour`]s: the colours of a checkerboard.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub(super) struct ColourPair(pub(super) [DVec3; 2]);

pub(super) struct ColourPairVisitor;

impl<'de> Visitor<'de> for ColourPairVisitor {
    type Value = ColourPair;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 2 colours, such as [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]]")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ColourPair, A::Error> {
        let mut out = [DVec3::ZERO; 2];
        let mut n = 0;
        while let Some(c) = seq.next_element::<UnitColour>()? {
            if n < 2 {
                out[n] = c.0;
            }
            n += 1;
        }
        if n != 2 {
            return Err(de::Error::custom(format!("must be an array of 2 colours (got {n})")));
        }
        Ok(ColourPair(out))
    }
}

impl<'de> Deserialize<'de> for ColourPair {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ColourPairVisitor)
    }
}

/// The table form of a map, as [`RawMap`] reads it.
pub(super) trait MapTable {
    /// What the map accepts, for type errors.
    const EXPECTING: &'static str;
}

impl MapTable for RawMapTable {
    const EXPECTING: &'static str =
        "a file path such as \"textures/wood.png\" or a table such as { file = \"wood.png\" }";
}

impl MapTable for RawEnvironmentMapTable {
    const EXPECTING: &'static str =
        "a file path such as \"sky.exr\" or a table such as { sky = { width = 512, height = 256 } }";
}

/// A texture map: a file path, or a table `T` naming a file or a generator.
pub(super) enum RawMap<T = RawMapTable> {
    Path(String),
    Table(Box<T>),
}

pub(super) struct RawMapVisitor<T>(pub(super) PhantomData<T>);

impl<'de, T: MapTable + Deserialize<'de>> Visitor<'de> for RawMapVisitor<T> {
    type Value = RawMap<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(T::EXPECTING)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawMap<T>, E> {
        Ok(RawMap::Path(v.to_owned()))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawMap<T>, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map)).map(|t| RawMap::Table(Box::new(t)))
    }
}

impl<'de, T: MapTable + Deserialize<'de>> Deserialize<'de> for RawMap<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(RawMapVisitor::<T>(PhantomData))
    }
}

// ---------------------------------------------------------------------------
// The raw tree
// ---------------------------------------------------------------------------
